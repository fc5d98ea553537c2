use super::*;

#[test]
fn colours_span_the_map_and_clamp() {
    assert_eq!(colour(0.0), (48, 18, 59));
    assert_eq!(colour(1.0), (250, 230, 40));
    assert_eq!(colour(2.0), colour(1.0));
    assert_eq!(colour(f64::NAN), colour(0.0));
}

#[test]
fn samples_sit_on_the_centres_of_their_grid_cells() {
    let (xs, ys) = ([0.0, 1.0, 2.0, 3.0], [10.0, 20.0]);
    let z = vec![vec![0.0, 1.0]; 4];
    // One sample on the first grid point, one on the last.
    let samples = [(0.0, 10.0, 0.0), (3.0, 20.0, 1.0)];
    let svg = samples_map("m", "x", "y", (&xs, &ys, &z), &samples);
    let (cw, ch) = ((W - LEFT - RIGHT) / 4.0, (H - BOTTOM - TOP) / 2.0);
    for (i, j) in [(0, 0), (3, 1)] {
        let (cx, cy) = (
            LEFT + (i as f64 + 0.5) * cw,
            H - BOTTOM - (j as f64 + 0.5) * ch,
        );
        assert!(
            svg.contains(&format!(r#"<circle cx="{cx:.2}" cy="{cy:.2}" r="4.5""#)),
            "no dot at cell ({i}, {j}) = ({cx:.2}, {cy:.2}): {svg}"
        );
    }
}

#[test]
fn charts_are_well_formed() {
    let svg = line_plot("a < b", "x", "y", &[0.0, 1.0, 2.0], &[-1.0, 0.5, 1.0]);
    assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
    assert!(svg.contains("a &lt; b") && svg.contains("stroke-dasharray"));
    let map = heatmap(
        "m",
        "x",
        "y",
        &[0.0, 1.0],
        &[0.0, 1.0, 2.0],
        &[vec![0.0, 1.0, 2.0], vec![3.0, 4.0, 5.0]],
    );
    assert_eq!(map.matches("<rect").count(), 1 + 6 + 1 + 50);
}
