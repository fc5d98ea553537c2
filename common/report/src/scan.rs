//! The files of a grid scan: `<out>/<object>-<metric>-<axes>.csv` for any number of axes,
//! and images for one axis (an SVG and a PNG line plot) or two (an SVG and a PNG heatmap).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::{ReportError, Result};
use graspopt_pictures::{chart, preview};
use graspopt_sim::ParamKind;
use graspopt_trial::{Evaluator, Metric, ReferenceFrame, ScanPoint};

/// The score of a grasp that touched something, `None` for one that touched nothing (drawn
/// grey, off every scale; the CSV keeps its defined no-contact score).
pub fn touched(p: &ScanPoint) -> Option<f64> {
    (p.score.contacts > 0).then_some(p.score.score)
}

/// The score for a map: NaN where the hand touched nothing, so the colour scale spans
/// the touching grasps (the CSV keeps the defined no-contact score).
pub fn touched_score(p: &ScanPoint) -> f64 {
    touched(p).unwrap_or(f64::NAN)
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

/// A scan as CSV: one column per parameter (`names`), then the score and what it came from:
/// the metrics of the metric table that scans show (`in_scan`: force_closure, epsilon,
/// distance...), the contacts and fingers in contact.
pub fn csv(names: &[&str], points: &[ScanPoint]) -> String {
    let metrics: Vec<Metric> = Metric::ALL
        .into_iter()
        .filter(|m| m.def().in_scan)
        .collect();
    let mut out = String::new();
    let keys: Vec<&str> = metrics.iter().map(|m| m.key()).collect();
    let _ = writeln!(
        out,
        "{},score,{},contacts,fingers_in_contact",
        names.join(","),
        keys.join(",")
    );
    for p in points {
        for v in &p.params {
            let _ = write!(out, "{v},");
        }
        // A grasp that touched nothing has no metrics: empty fields, as in trials.csv.
        let values: Vec<String> = metrics
            .iter()
            .map(|&m| {
                p.score
                    .metrics
                    .and_then(|v| v.get(m))
                    .map_or(String::new(), |v| v.to_string())
            })
            .collect();
        let _ = writeln!(
            out,
            "{},{},{},{}",
            p.score.score,
            values.join(","),
            p.score.contacts,
            p.score.fingers_in_contact
        );
    }
    out
}

/// A trial parameter's axis as figures name it: `approach offset (m)`, `rz rotation (rad)`.
pub fn axis_label(kind: ParamKind) -> String {
    match kind {
        ParamKind::Approach | ParamKind::Lateral | ParamKind::Vertical => {
            format!("{} offset (m)", kind.name())
        }
        ParamKind::RotX | ParamKind::RotY | ParamKind::RotZ => {
            format!("{} rotation (rad)", kind.name())
        }
    }
}

/// What the axes of a scan's figures are: the note under a PNG figure.
pub const AXES_NOTE: &str =
    "axes: the palm's offsets from its reference pose (reference palm frame)";

/// What a scan's figures are relative to, under the figure: the frame of the axes (the palm's
/// offsets from its reference pose) and the reference point of the torques with their scale.
pub fn frame_notes(ev: &Evaluator) -> [String; 2] {
    let about = match ev.score.frame {
        ReferenceFrame::Object => "the object's centre of mass".to_string(),
        ReferenceFrame::World => "the world origin".to_string(),
        ReferenceFrame::Palm => "the palm's origin".to_string(),
        ReferenceFrame::Point(p) => format!("the point ({}, {}, {})", p[0], p[1], p[2]),
    };
    let scale = ev.score.torque_scale.map_or_else(
        || {
            format!(
                "{:.4} m (the object's radius)",
                ev.object.bounding_sphere().1
            )
        },
        |s| format!("{s} m"),
    );
    [
        AXES_NOTE.into(),
        format!(
            "{} frame: torques about {about}; torque scale {scale}",
            ev.score.frame.name()
        ),
    ]
}

/// Writes the files of a scan of `ev` (scored with `metric`, as the user named it) over the
/// parameters `kinds`, on the grid `axes`, into `out` (created if missing): the CSV, then for
/// one axis an SVG and a PNG line plot, for two an SVG and a PNG heatmap; more axes get the
/// CSV alone. Grasps that touched nothing are grey in every figure and never set a scale.
/// Returns the paths written, in that order.
pub fn write_scan(
    out: &Path,
    ev: &Evaluator,
    metric: &str,
    kinds: &[ParamKind],
    axes: &[Vec<f64>],
    points: &[ScanPoint],
) -> Result<Vec<PathBuf>> {
    crate::create_dir(out)?;
    let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
    let stem = format!("{}-{}-{}", ev.object.name(), metric, names.join("-"));
    let csv_path = out.join(format!("{stem}.csv"));
    std::fs::write(&csv_path, csv(&names, points)).map_err(|source| ReportError::Write {
        path: csv_path.clone(),
        source,
    })?;
    let mut written = vec![csv_path];
    let value = metric.to_uppercase();
    let title = format!(
        "{value} on the {} ({} contacts, {} frame)",
        ev.object.name(),
        ev.score.contacts,
        ev.score.frame.name()
    );
    let notes = frame_notes(ev);
    let notes: Vec<&str> = notes.iter().map(String::as_str).collect();
    let labels: Vec<String> = kinds.iter().map(|&k| axis_label(k)).collect();
    let (svg, png) = match axes.len() {
        1 => {
            let ys: Vec<Option<f64>> = points.iter().map(touched).collect();
            let svg = chart::scan_plot(&title, &labels[0], &value, &axes[0], &[("", ys.clone())]);
            let png = preview::line_figure(&preview::LineFigure {
                title: &title,
                notes: &notes,
                x: preview::Axis {
                    label: &labels[0],
                    values: &axes[0],
                },
                y_label: &value,
                ys: &ys,
                missing: chart::MISS_TICK_LABEL,
            });
            (svg, png)
        }
        2 => {
            let z = touched_grid(axes, points);
            let svg_labels = (labels[0].as_str(), labels[1].as_str(), value.as_str());
            let svg = chart::heatmap(&title, svg_labels, &axes[0], &axes[1], &z);
            let png = preview::heatmap_figure(&preview::HeatmapFigure {
                title: &title,
                notes: &notes,
                x: preview::Axis {
                    label: &labels[0],
                    values: &axes[0],
                },
                y: preview::Axis {
                    label: &labels[1],
                    values: &axes[1],
                },
                z: &z,
                z_label: &value,
                missing: chart::MISSING_LABEL,
                cell: 8,
            });
            (svg, png)
        }
        _ => return Ok(written),
    };
    let svg_path = out.join(format!("{stem}.svg"));
    std::fs::write(&svg_path, svg).map_err(|source| ReportError::Write {
        path: svg_path.clone(),
        source,
    })?;
    let png_path = out.join(format!("{stem}.png"));
    png.save_png(&png_path).map_err(ReportError::picture)?;
    written.extend([svg_path, png_path]);
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
        let written = write_scan(&out, &ev, "bw", &[ParamKind::Approach], &axes, &points).unwrap();
        assert_eq!(
            written,
            [
                out.join("sphere-bw-approach.csv"),
                out.join("sphere-bw-approach.svg"),
                out.join("sphere-bw-approach.png")
            ]
        );
        let csv = std::fs::read_to_string(&written[0]).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        // The metrics of the table that scans show, in its order.
        let shown: Vec<&str> = Metric::ALL
            .into_iter()
            .filter(|m| m.def().in_scan)
            .map(Metric::key)
            .collect();
        assert_eq!(shown[..3], ["force_closure", "epsilon", "distance"]);
        assert_eq!(
            lines[0],
            format!(
                "approach,score,{},contacts,fingers_in_contact",
                shown.join(",")
            )
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
            &[ParamKind::Approach, ParamKind::Vertical],
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
        let written = write_scan(dir.path(), &ev, "bw", &kinds, &axes, &points).unwrap();
        assert_eq!(
            written,
            [dir.path().join("sphere-bw-approach-vertical-lateral.csv")]
        );
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

    /// The numbers of an SVG's text elements anchored at `anchor` (the y axis's values are
    /// anchored at their end).
    fn svg_numbers(svg: &str, anchor: &str) -> Vec<f64> {
        let key = format!("text-anchor=\"{anchor}\"");
        svg.split("<text")
            .filter(|t| t.contains(&key))
            .filter_map(|t| t.split_once('>')?.1.split('<').next()?.trim().parse().ok())
            .collect()
    }

    #[test]
    fn a_one_axis_scan_draws_its_misses_grey_below_a_scale_of_the_grasps() {
        // The sphere's approach axis, 9 points: the farthest miss it.
        let (ev, axes, points) = scanned(&[ParamKind::Approach], &[9]);
        let misses = points.iter().filter(|p| p.score.contacts == 0).count();
        assert!(misses > 0 && misses < 9, "{misses} misses");
        let lowest_hit = points
            .iter()
            .filter_map(touched)
            .fold(f64::INFINITY, f64::min);
        let penalty = points
            .iter()
            .filter(|p| p.score.contacts == 0)
            .map(|p| p.score.score)
            .fold(f64::INFINITY, f64::min);
        // A miss scores about -(B + 1) - min(d / rho, 1): far below every grasp.
        assert!(penalty < lowest_hit - 1.0, "{penalty} vs {lowest_hit}");
        let dir = tempfile::tempdir().unwrap();
        let written = write_scan(
            dir.path(),
            &ev,
            "bw",
            &[ParamKind::Approach],
            &axes,
            &points,
        )
        .unwrap();
        let svg = std::fs::read_to_string(&written[1]).unwrap();
        // The score axis's values stay near the grasps' scores, never down to the misses'.
        let y = svg_numbers(&svg, "end");
        assert!(y.len() >= 3, "{y:?}");
        let span = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(
            y.iter().all(|v| *v > lowest_hit - 0.5),
            "{y:?} reach {penalty}"
        );
        assert!(span < penalty.abs(), "{y:?}");
        // A grey tick per miss (2 px wide grey polylines) and the legend that says so.
        let ticks = svg
            .matches(&format!("stroke=\"{}\" stroke-width=\"2\"", chart::MISSING))
            .count();
        assert_eq!(ticks, misses, "{svg:.300}");
        assert!(svg.contains(chart::MISS_TICK_LABEL));
        // The PNG: grey ticks (2 x 8 pixels each, fewer where two overlap at a pixel column)
        // and the legend's 8 x 8 square.
        let png = std::fs::read(&written[2]).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }

    #[test]
    fn scan_figures_name_their_axes_frame_and_values() {
        let (ev, axes, points) = scanned(&[ParamKind::Approach, ParamKind::Vertical], &[3, 2]);
        let dir = tempfile::tempdir().unwrap();
        let kinds = [ParamKind::Approach, ParamKind::Vertical];
        let written = write_scan(dir.path(), &ev, "bw", &kinds, &axes, &points).unwrap();
        let svg = std::fs::read_to_string(&written[1]).unwrap();
        for text in [
            "BW on the sphere (surface contacts, object frame)",
            "approach offset (m)",
            "vertical offset (m)",
            "\nBW\n</text>",
        ] {
            assert!(svg.contains(text), "no {text} in the SVG");
        }
        assert_eq!(axis_label(ParamKind::RotZ), "rz rotation (rad)");
        let [axes_note, frame_note] = frame_notes(&ev);
        assert!(axes_note.contains("reference pose"), "{axes_note}");
        assert!(
            frame_note.starts_with("object frame: torques about the object's centre of mass"),
            "{frame_note}"
        );
    }
}
