//! The pictures `graspopt run` leaves in its results folder: the best grasp (`best.png`),
//! the trials on the parameter space (`trials.svg`) and the scores (`best.svg`), where trials
//! that touched nothing are grey and never set a scale.

use crate::support::{decode_png, graspopt, tempdir};

/// The grey of grasps that touched nothing.
const GREY: &str = "rgb(128,128,128)";

/// The numbers written as the y axis's tick labels of an SVG chart.
fn y_ticks(svg: &str) -> Vec<f64> {
    svg.split(r#"text-anchor="end">"#)
        .skip(1)
        .filter_map(|s| s.split('<').next()?.parse().ok())
        .collect()
}

#[test]
fn run_pictures_show_the_best_grasp_and_keep_misses_off_the_scale() {
    let dir = tempdir("run-pictures");
    let out = dir.join("r");
    let o = graspopt(&[
        "run",
        "--object",
        "mug",
        "--trials",
        "12",
        "--workers",
        "1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The trials: score and contacts per row, from the CSV.
    let csv = std::fs::read_to_string(out.join("trials.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<(f64, u64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[col("score")].parse().unwrap(),
                f[col("contacts")].parse().unwrap(),
            )
        })
        .collect();
    assert_eq!(rows.len(), 12);
    let misses = rows.iter().filter(|r| r.1 == 0).count();
    let hits: Vec<f64> = rows.iter().filter(|r| r.1 > 0).map(|r| r.0).collect();
    assert!(misses > 0 && !hits.is_empty(), "{csv}");
    let lowest_hit = hits.iter().copied().fold(f64::INFINITY, f64::min);
    let highest_miss = rows
        .iter()
        .filter(|r| r.1 == 0)
        .map(|r| r.0)
        .fold(f64::NEG_INFINITY, f64::max);

    // best.svg: the score axis spans the grasps, the misses are grey ticks below it.
    let best = std::fs::read_to_string(out.join("best.svg")).unwrap();
    let ticks = y_ticks(&best);
    assert_eq!(ticks.len(), 5, "{best}");
    let bottom = ticks.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        bottom > highest_miss,
        "axis from {bottom}: misses set the scale"
    );
    assert!(
        bottom <= lowest_hit && lowest_hit - bottom < 0.1,
        "{bottom} {lowest_hit}"
    );
    assert_eq!(best.matches(&format!(r#"stroke="{GREY}""#)).count(), misses);
    assert!(best.contains("no contact"), "{best}");

    // trials.svg: a dot per trial, grey for the misses, the best ringed, a legend.
    let map = std::fs::read_to_string(out.join("trials.svg")).unwrap();
    assert_eq!(map.matches(r#"r="4.5""#).count(), 12, "{map}");
    assert_eq!(
        map.matches(&format!(r#"r="4.5" fill="{GREY}""#)).count(),
        misses
    );
    assert!(map.contains(r#"stroke="red""#) && map.contains("grey: no contact"));
    assert!(map.contains("approach offset (m)") && map.contains("vertical offset (m)"));

    // best.png: the best grasp, titled, with its contacts.
    let (w, h, px) = decode_png(&out.join("best.png"));
    assert_eq!((w, h), (1200, 560));
    let title_text = (0..24 * w as usize)
        .filter(|&i| px[i] == [20, 20, 20])
        .count();
    assert!(title_text > 100, "no title: {title_text} text pixels");
    assert!(px.contains(&[230, 20, 20]), "no contact dots");
    std::fs::remove_dir_all(&dir).unwrap();
}
