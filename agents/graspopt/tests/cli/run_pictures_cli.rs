//! The pictures `graspopt run` leaves in its results folder: the best grasp (`best.png`),
//! the trials on the parameter space (`trials.svg`) and the scores (`best.svg`), where trials
//! that touched nothing are grey and never set a scale.

use crate::support::{decode_png, graspopt_ok, tempdir};

/// The grey of grasps that touched nothing, as the charts write it.
const GREY: &str = "#808080";

/// The SVG elements named `name` (`<name ...>`): their attributes and text.
fn elements<'a>(svg: &'a str, name: &str) -> Vec<(&'a str, &'a str)> {
    svg.split(&format!("<{name} "))
        .skip(1)
        .filter_map(|s| {
            let (attrs, rest) = s.split_once('>')?;
            let text = rest.split_once(&format!("</{name}>")).map_or("", |t| t.0);
            Some((attrs, text.trim()))
        })
        .collect()
}

/// The numbers written as the y axis's tick labels of an SVG chart (right-aligned text).
fn y_ticks(svg: &str) -> Vec<f64> {
    elements(svg, "text")
        .into_iter()
        .filter(|(attrs, _)| attrs.contains(r#"text-anchor="end""#))
        .filter_map(|(_, text)| text.parse().ok())
        .collect()
}

/// The filled dots of radius `r` in an SVG chart: their attributes.
fn dots<'a>(svg: &'a str, r: &str) -> Vec<&'a str> {
    elements(svg, "circle")
        .into_iter()
        .map(|(attrs, _)| attrs)
        .filter(|a| a.contains(&format!(r#"r="{r}""#)) && !a.contains(r#"fill="none""#))
        .collect()
}

#[test]
fn run_pictures_show_the_best_grasp_and_keep_misses_off_the_scale() {
    let dir = tempdir("run-pictures");
    let out = dir.join("r");
    graspopt_ok(&[
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

    // best.svg: the score axis spans the grasps (its lowest and highest ticks within a tick
    // step of them), the misses are grey ticks below it.
    let best = std::fs::read_to_string(out.join("best.svg")).unwrap();
    let mut ticks = y_ticks(&best);
    ticks.sort_by(f64::total_cmp);
    assert!(ticks.len() >= 3, "{best}");
    let step = ticks[1] - ticks[0];
    let (bottom, top) = (ticks[0], ticks[ticks.len() - 1]);
    let highest_hit = hits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        bottom > highest_miss,
        "axis from {bottom}: misses set the scale"
    );
    assert!(
        bottom - lowest_hit < step + 1e-12 && highest_hit - top < step + 1e-12,
        "ticks {ticks:?} for grasps from {lowest_hit} to {highest_hit}"
    );
    assert_eq!(best.matches(&format!(r#"stroke="{GREY}""#)).count(), misses);
    assert!(best.contains("no contact"), "{best}");

    // trials.svg: a dot per trial (and one in the legend), grey for the misses, the best
    // ringed in red, a legend.
    let map = std::fs::read_to_string(out.join("trials.svg")).unwrap();
    let placed = dots(&map, "4");
    assert_eq!(placed.len(), 12 + 1, "{map}");
    let grey = placed
        .iter()
        .filter(|a| a.contains(&format!(r#"fill="{GREY}""#)));
    assert_eq!(grey.count(), misses);
    let rings = elements(&map, "circle")
        .into_iter()
        .filter(|(a, _)| a.contains(r#"r="9""#) && a.contains(r##"stroke="#FF0000""##))
        .count();
    assert_eq!(rings, 1, "{map}");
    assert!(map.contains("grey: no contact"));
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
