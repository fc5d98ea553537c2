//! The files of a grid scan: `<out>/<object>-<metric>-<axes>.csv` for any number of axes,
//! and images for one axis (an SVG line plot) or two (an SVG and a PNG heatmap).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use graspopt_pictures::chart;
use graspopt_trial::{Evaluator, ScanPoint};

/// The score for a map: NaN where the hand touched nothing, so the colour scale spans
/// the touching grasps (the CSV keeps the defined no-contact score).
pub fn touched_score(p: &ScanPoint) -> f64 {
    if p.score.contacts == 0 {
        f64::NAN
    } else {
        p.score.score
    }
}

/// The scores of a 2D scan as `z[i][j]` (axis 0 index `i`, axis 1 index `j`), NaN where the
/// hand touched nothing (drawn grey), for the heatmaps.
pub fn touched_grid(axes: &[Vec<f64>], points: &[ScanPoint]) -> Vec<Vec<f64>> {
    let ny = axes.get(1).map_or(1, Vec::len);
    points
        .chunks(ny)
        .map(|column| column.iter().map(touched_score).collect())
        .collect()
}

/// A scan as CSV: one column per parameter (`names`), then the score and what it came from.
pub fn csv(names: &[&str], points: &[ScanPoint]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{},score,force_closure,epsilon,distance,contacts,fingers_in_contact",
        names.join(",")
    );
    for p in points {
        for v in &p.params {
            let _ = write!(out, "{v},");
        }
        // A grasp that touched nothing has no metrics: empty fields, as in trials.csv.
        let metrics = p.score.metrics.map_or_else(
            || ",,".to_string(),
            |m| format!("{},{},{}", m.force_closure, m.epsilon, m.distance),
        );
        let _ = writeln!(
            out,
            "{},{metrics},{},{}",
            p.score.score, p.score.contacts, p.score.fingers_in_contact
        );
    }
    out
}

/// Writes the files of a scan of `ev` (scored with `metric`, as the user named it) over the
/// parameters `names`, on the grid `axes`, into `out` (created if missing): the CSV, then for
/// one axis an SVG line plot, for two an SVG and a PNG heatmap; more axes get the CSV alone.
/// Returns the paths written, in that order.
pub fn write_scan(
    out: &Path,
    ev: &Evaluator,
    metric: &str,
    names: &[&str],
    axes: &[Vec<f64>],
    points: &[ScanPoint],
) -> Result<Vec<PathBuf>> {
    crate::create_dir(out)?;
    let stem = format!("{}-{}-{}", ev.object.name(), metric, names.join("-"));
    let csv_path = out.join(format!("{stem}.csv"));
    std::fs::write(&csv_path, csv(names, points))
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    let title = format!(
        "{} on the {} ({} contacts)",
        metric.to_uppercase(),
        ev.object.name(),
        ev.score.contacts
    );
    let mut extra = Vec::new();
    let chart = match axes.len() {
        1 => Some(chart::line_plot(
            &title,
            &format!("{} offset (m)", names[0]),
            metric,
            &axes[0],
            &points.iter().map(|p| p.score.score).collect::<Vec<_>>(),
        )),
        2 => {
            let z = touched_grid(axes, points);
            let png_path = out.join(format!("{stem}.png"));
            graspopt_pictures::preview::heatmap_figure(&z, 8, &title, chart::MISSING_LABEL)
                .save_png(&png_path)?;
            extra.push(png_path);
            Some(chart::heatmap(
                &title,
                &format!("{} offset (m)", names[0]),
                &format!("{} offset (m)", names[1]),
                &axes[0],
                &axes[1],
                &z,
            ))
        }
        _ => None,
    };
    let mut written = vec![csv_path];
    if let Some(chart) = chart {
        let svg_path = out.join(format!("{stem}.svg"));
        std::fs::write(&svg_path, chart)
            .with_context(|| format!("cannot write {}", svg_path.display()))?;
        written.push(svg_path);
    }
    written.extend(extra);
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_sim::hand::hand_by_name;
    use graspopt_sim::{Object, ParamKind, TrialSpace};
    use graspopt_trial::scan::{grid_axes, scan_grid};

    fn scanned(kinds: &[ParamKind], steps: &[usize]) -> (Evaluator, Vec<Vec<f64>>, Vec<ScanPoint>) {
        let object = Object::by_name("sphere").unwrap();
        let space = TrialSpace::with_params(&object, kinds).unwrap();
        let ev = Evaluator::new(object, hand_by_name("barrett").unwrap(), space);
        let axes = grid_axes(&ev.space.bounds(), steps);
        let points = scan_grid(&ev, &axes, 1, &|_| {}).unwrap();
        (ev, axes, points)
    }

    #[test]
    fn a_one_axis_scan_writes_its_csv_and_a_line_plot() {
        let (ev, axes, points) = scanned(&[ParamKind::Approach], &[5]);
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new");
        let written = write_scan(&out, &ev, "bw", &["approach"], &axes, &points).unwrap();
        assert_eq!(
            written,
            [
                out.join("sphere-bw-approach.csv"),
                out.join("sphere-bw-approach.svg")
            ]
        );
        let csv = std::fs::read_to_string(&written[0]).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines[0],
            "approach,score,force_closure,epsilon,distance,contacts,fingers_in_contact"
        );
        assert_eq!(lines.len(), 6);
        assert!(lines[1].starts_with(&format!("{},{},", axes[0][0], points[0].score.score)));
        let svg = std::fs::read_to_string(&written[1]).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains("BW on the sphere"),
            "{svg:.200}"
        );
    }

    #[test]
    fn a_two_axis_scan_adds_a_png_heatmap_and_more_axes_write_the_csv_alone() {
        let (ev, axes, points) = scanned(&[ParamKind::Approach, ParamKind::Vertical], &[3, 2]);
        let dir = tempfile::tempdir().unwrap();
        let written = write_scan(
            dir.path(),
            &ev,
            "bw",
            &["approach", "vertical"],
            &axes,
            &points,
        )
        .unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                "sphere-bw-approach-vertical.csv",
                "sphere-bw-approach-vertical.svg",
                "sphere-bw-approach-vertical.png"
            ]
        );
        let png = std::fs::read(&written[2]).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");

        let kinds = [ParamKind::Approach, ParamKind::Vertical, ParamKind::Lateral];
        let (ev, axes, points) = scanned(&kinds, &[2, 1, 1]);
        let written = write_scan(dir.path(), &ev, "bw", &["a", "v", "l"], &axes, &points).unwrap();
        assert_eq!(written, [dir.path().join("sphere-bw-a-v-l.csv")]);
    }

    #[test]
    fn maps_leave_out_the_grasps_that_touch_nothing() {
        let (_, axes, points) = scanned(&[ParamKind::Approach, ParamKind::Vertical], &[4, 3]);
        let z = touched_grid(&axes, &points);
        assert_eq!((z.len(), z[0].len()), (4, 3));
        let mut missed = 0;
        for (i, row) in z.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                let p = &points[i * 3 + j];
                if p.score.contacts == 0 {
                    missed += 1;
                    assert!(v.is_nan());
                } else {
                    assert_eq!(*v, p.score.score);
                }
            }
        }
        // The farthest row of the sphere's space is out of reach: some misses are tested.
        assert!(missed > 0 && missed < 12, "{missed} misses");
    }
}
