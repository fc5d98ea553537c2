//! The charts are read back as XML: what is drawn is counted and placed from the parsed
//! elements, not from the text of the SVG.

use super::*;
use quick_xml::Reader;
use quick_xml::events::Event;

/// One SVG element: its name, attributes and text.
#[derive(Debug)]
struct El {
    name: String,
    attrs: Vec<(String, String)>,
    text: String,
}

impl El {
    fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
    fn num(&self, key: &str) -> f64 {
        let v = self
            .attr(key)
            .unwrap_or_else(|| panic!("no {key} in {self:?}"));
        v.parse()
            .unwrap_or_else(|_| panic!("{key}={v} in {self:?}"))
    }
    /// The points of a polyline or polygon.
    fn points(&self) -> Vec<(f64, f64)> {
        self.attr("points")
            .unwrap_or_default()
            .split_whitespace()
            .map(|p| {
                let (x, y) = p.split_once(',').expect("x,y");
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect()
    }
    fn is(&self, name: &str, key: &str, value: &str) -> bool {
        self.name == name && self.attr(key) == Some(value)
    }
}

/// Parses `svg` as XML (panicking if it is not well formed) and returns its elements in
/// document order; checks that the root is an `svg` of the chart's size.
fn parse(svg: &str) -> Vec<El> {
    let mut reader = Reader::from_str(svg);
    reader.config_mut().check_end_names = true;
    let mut out: Vec<El> = Vec::new();
    // Indices in `out` of the open elements.
    let mut open: Vec<usize> = Vec::new();
    loop {
        let event = reader
            .read_event()
            .unwrap_or_else(|e| panic!("not XML: {e}\n{svg}"));
        match event {
            Event::Start(ref e) | Event::Empty(ref e) => {
                let attrs = e
                    .attributes()
                    .map(|a| {
                        let a = a.expect("attribute");
                        let key = String::from_utf8(a.key.as_ref().to_vec()).unwrap();
                        (key, a.unescape_value().expect("value").into_owned())
                    })
                    .collect();
                let name = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                out.push(El {
                    name,
                    attrs,
                    text: String::new(),
                });
                if matches!(event, Event::Start(_)) {
                    open.push(out.len() - 1);
                }
            }
            Event::End(_) => {
                open.pop().expect("an end tag without a start");
            }
            Event::Text(t) => {
                if let Some(&k) = open.last() {
                    out[k].text.push_str(&t.decode().unwrap());
                }
            }
            Event::GeneralRef(r) => {
                let c = match r.decode().unwrap().as_ref() {
                    "lt" => '<',
                    "gt" => '>',
                    "amp" => '&',
                    "quot" => '"',
                    "apos" => '\'',
                    other => panic!("unknown entity {other}"),
                };
                if let Some(&k) = open.last() {
                    out[k].text.push(c);
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(open.is_empty(), "unclosed elements");
    let root = &out[0];
    assert_eq!(root.name, "svg");
    assert!(root.num("width") > 0.0 && root.num("height") > 0.0);
    out
}

/// The trimmed texts of the `text` elements.
fn texts(els: &[El]) -> Vec<String> {
    els.iter()
        .filter(|e| e.name == "text")
        .map(|e| e.text.trim().to_string())
        .collect()
}

/// The hex colour plotters writes for `c`.
fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

fn hex3((r, g, b): (u8, u8, u8)) -> String {
    hex(RGBColor(r, g, b))
}

/// The solid lines of `colour` (dashed lines are many short polylines of one segment).
fn lines<'a>(els: &'a [El], colour: &str, width: &str) -> Vec<&'a El> {
    els.iter()
        .filter(|e| e.is("polyline", "stroke", colour) && e.attr("stroke-width") == Some(width))
        .collect()
}

/// The filled dots of radius `r`.
fn dots(els: &[El], r: i32) -> Vec<&El> {
    els.iter()
        .filter(|e| {
            e.name == "circle" && e.num("r") == f64::from(r) && e.attr("fill") != Some("none")
        })
        .collect()
}

#[test]
fn colours_span_the_map_and_clamp() {
    assert_eq!(colour(0.0), (48, 18, 59));
    assert_eq!(colour(1.0), (250, 230, 40));
    assert_eq!(colour(2.0), colour(1.0));
    assert_eq!(colour(f64::NAN), colour(0.0));
}

#[test]
fn a_line_plot_draws_every_point_with_title_labels_and_zero_line() {
    let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
    let ys = [-1.0, 0.5, 1.0, 2.0, 1.5];
    let els = parse(&line_plot("a < b & c", "offset (m)", "bw", &xs, &ys));
    let t = texts(&els);
    for want in ["a < b & c", "offset (m)", "bw"] {
        assert!(t.iter().any(|s| s == want), "no text {want:?} in {t:?}");
    }
    let series = lines(&els, &hex(PALETTE[0]), "2");
    assert_eq!(series.len(), 1);
    let pts = series[0].points();
    assert_eq!(pts.len(), 5);
    // Left to right, and higher values higher up (smaller pixel y).
    assert!(pts.windows(2).all(|w| w[1].0 > w[0].0), "{pts:?}");
    let order = |k: usize| pts[k].1;
    assert!(order(3) < order(4) && order(4) < order(2) && order(2) < order(1));
    assert!(order(1) < order(0));
    // The dashed zero line: grey segments at one height, between the pixels of -1 and 0.5.
    let zero: Vec<&El> = els
        .iter()
        .filter(|e| e.is("polyline", "stroke", MISSING))
        .collect();
    assert!(zero.len() > 10, "{} grey segments", zero.len());
    let y0 = zero[0].points()[0].1;
    assert!(zero.iter().all(|e| e.points().iter().all(|p| p.1 == y0)));
    assert!(y0 < pts[0].1 && y0 > pts[1].1, "zero at {y0}");
    // No legend without names, and no empty-state note.
    assert!(!t.iter().any(|s| s == NO_DATA));
}

#[test]
fn named_series_get_a_legend_and_their_own_colours() {
    let xs = [0.0, 1.0, 2.0];
    let series = [
        ("bw", vec![1.0, 2.0, 3.0]),
        ("ferrari", vec![3.0, 2.0, 1.0]),
    ];
    let els = parse(&lines_plot("m", "x", "y", &xs, &series));
    let t = texts(&els);
    assert!(t.contains(&"bw".to_string()) && t.contains(&"ferrari".to_string()));
    for (k, &c) in PALETTE[..2].iter().enumerate() {
        // The series and its legend sign.
        let drawn = lines(&els, &hex(c), "2");
        assert_eq!(drawn.len(), 2, "series {k}");
        assert_eq!(drawn.iter().map(|e| e.points().len()).max(), Some(3));
    }
}

#[test]
fn a_missing_value_breaks_the_line() {
    let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
    let ys = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY];
    let els = parse(&line_plot("gap", "x", "y", &xs, &ys));
    let parts: Vec<usize> = lines(&els, &hex(PALETTE[0]), "2")
        .iter()
        .map(|e| e.points().len())
        .collect();
    assert_eq!(parts, [1, 2]);
}

#[test]
fn bands_and_a_reference_line_are_drawn_with_their_label() {
    let xs = [0.0, 1.0, 2.0, 3.0];
    let mean = vec![1.0, 2.0, 3.0, 4.0];
    let low = vec![0.5, 1.5, f64::NAN, 3.5];
    let high = vec![1.5, 2.5, 3.5, 4.5];
    let svg = bands_plot(
        "b",
        "x",
        "y",
        &xs,
        &[("mean", mean)],
        &[(low, high)],
        Some((2.5, "target")),
    );
    let els = parse(&svg);
    // The band is cut at the missing low value: two polygons of 2 x 2 and 1 x 2 corners.
    let bands: Vec<usize> = els
        .iter()
        .filter(|e| e.is("polygon", "fill", &hex(PALETTE[0])))
        .map(|e| e.points().len())
        .collect();
    assert_eq!(bands, [4, 2]);
    assert!(texts(&els).contains(&"target".to_string()));
    let black = els
        .iter()
        .filter(|e| e.is("polyline", "stroke", "#000000"))
        .count();
    assert!(black > 10, "no dashed reference line: {black}");
}

#[test]
fn empty_or_non_finite_input_gives_an_empty_state_chart() {
    let nan = [f64::NAN; 3];
    let nan_grid = vec![vec![f64::NAN; 2]; 3];
    let model = |xs: &[f64]| {
        model_plot(&ModelPlot {
            title: "m",
            xlabel: "x",
            xs,
            mean: &[],
            sd: &[],
            ei: &[],
            truth: None,
            samples: &[],
            next: Some(f64::NAN),
        })
    };
    let charts = [
        ("line, no points", line_plot("e", "x", "y", &[], &[])),
        ("line, NaN", line_plot("e", "x", "y", &nan, &nan)),
        ("lines, none", lines_plot("e", "x", "y", &[1.0], &[])),
        (
            "bands, lengths differ",
            bands_plot(
                "e",
                "x",
                "y",
                &[],
                &[("a", vec![1.0])],
                &[(vec![1.0], vec![])],
                None,
            ),
        ),
        (
            "heatmap, empty",
            heatmap("e", ("x", "y", "bw"), &[], &[], &[]),
        ),
        (
            "heatmap, NaN",
            heatmap("e", ("x", "y", "bw"), &nan, &nan[..2], &nan_grid),
        ),
        (
            "samples, empty",
            samples_map("e", ("x", "y", "bw"), (&[], &[], &[]), &[]),
        ),
        ("progress, empty", progress_plot("e", &[])),
        (
            "progress, misses",
            progress_plot("e", &[None, Some(f64::NAN)]),
        ),
        ("trials 1D, none", trials_map("e", &[], &[], &[])),
        (
            "trials 2D, none",
            trials_map("e", &["a", "b"], &[(0.0, 1.0), (0.0, 1.0)], &[]),
        ),
        (
            "trials 2D, NaN bounds and parameters",
            trials_map(
                "e",
                &[],
                &[(f64::NAN, 1.0), (2.0, 2.0)],
                &[(vec![f64::NAN, 0.0], Some(1.0)), (vec![0.5], Some(1.0))],
            ),
        ),
        ("model, empty", model(&[])),
        ("model, NaN", model(&nan)),
    ];
    for (what, svg) in charts {
        let t = texts(&parse(&svg));
        assert!(t.iter().any(|s| s == NO_DATA), "{what}: {t:?}");
    }
}

/// The cell rectangles of a map: filled rects, not the background, the colour bar (beside
/// the map, right of `x_max`) or the legend.
fn cells_of<'a>(els: &'a [El], fill: &str) -> Vec<&'a El> {
    els.iter()
        .filter(|e| e.is("rect", "fill", fill) && e.num("width") > 20.0)
        .collect()
}

#[test]
fn a_heatmap_draws_one_cell_per_value_on_the_colour_scale() {
    let (xs, ys) = ([0.0, 1.0], [0.0, 10.0, 20.0]);
    let z = vec![vec![0.0, 1.0, 2.0], vec![3.0, 4.0, 5.0]];
    let els = parse(&heatmap("m", ("x", "y", "bw"), &xs, &ys, &z));
    let mut corners = Vec::new();
    for (i, column) in z.iter().enumerate() {
        for (j, v) in column.iter().enumerate() {
            let fill = hex3(colour(v / 5.0));
            let cell = cells_of(&els, &fill);
            assert_eq!(cell.len(), 1, "cell ({i}, {j}) {fill}");
            corners.push((i, j, cell[0].num("x"), cell[0].num("y")));
        }
    }
    // x grows with i, pixel y shrinks as j grows; cells of equal size.
    for &(i, j, x, y) in &corners {
        for &(i2, j2, x2, y2) in &corners {
            assert_eq!(i.cmp(&i2), x.total_cmp(&x2), "x of ({i},{j}) ({i2},{j2})");
            assert_eq!(j.cmp(&j2), y2.total_cmp(&y), "y of ({i},{j}) ({i2},{j2})");
        }
    }
    // The colour bar: 50 steps from the bottom colour of the map to the top one.
    let bar: Vec<&El> = els
        .iter()
        .filter(|e| e.name == "rect" && e.attr("stroke") == Some("none") && e.num("width") < 40.0)
        .collect();
    assert_eq!(bar.len(), 50);
    assert!(!texts(&els).contains(&MISSING_LABEL.to_string()));
    // The bar is labelled with what its colours stand for, right of its values.
    let label = els
        .iter()
        .find(|e| e.name == "text" && e.text.trim() == "bw")
        .expect("the colour bar's label");
    let bar_right = bar
        .iter()
        .map(|e| e.num("x") + e.num("width"))
        .fold(0.0, f64::max);
    assert!(label.num("x") > bar_right, "{label:?} left of {bar_right}");

    // A missing value: a grey cell and a legend that says what grey means.
    let mut z = z;
    z[1][2] = f64::NAN;
    let els = parse(&heatmap("m", ("x", "y", "bw"), &xs, &ys, &z));
    assert_eq!(cells_of(&els, MISSING).len(), 1);
    assert!(texts(&els).contains(&MISSING_LABEL.to_string()));
    assert!(
        els.iter()
            .any(|e| e.is("rect", "fill", MISSING) && e.num("width") < 20.0),
        "no grey legend square"
    );
}

/// The centre of a rect.
fn centre(e: &El) -> (f64, f64) {
    (
        e.num("x") + e.num("width") / 2.0,
        e.num("y") + e.num("height") / 2.0,
    )
}

#[test]
fn samples_sit_on_the_centres_of_their_grid_cells_and_the_best_is_ringed() {
    let (xs, ys) = ([0.0, 1.0, 2.0, 3.0], [10.0, 20.0]);
    let z: Vec<Vec<f64>> = (0..4)
        .map(|i| vec![2.0 * i as f64, 2.0 * i as f64 + 1.0])
        .collect();
    // One sample on the first grid point, one on the last (the best).
    let samples = [(0.0, 10.0, 0.0), (3.0, 20.0, 7.0)];
    let els = parse(&samples_map(
        "m",
        ("x", "y", "bw"),
        (&xs, &ys, &z),
        &samples,
    ));
    let placed = dots(&els, DOT_R);
    // The two samples and the legend's sign.
    assert_eq!(placed.len(), 3, "{placed:?}");
    for (k, (i, j)) in [(0usize, 0usize), (3, 1)].into_iter().enumerate() {
        let cell = cells_of(&els, &hex3(colour(z[i][j] / 7.0)));
        assert_eq!(cell.len(), 1);
        let (cx, cy) = centre(cell[0]);
        let fill = hex3(colour(samples[k].2 / 7.0));
        // The dot of the sample's colour nearest the cell (the legend has one too).
        let distance = |d: &El| (d.num("cx") - cx).hypot(d.num("cy") - cy);
        let dot = placed
            .iter()
            .filter(|d| d.attr("fill") == Some(fill.as_str()))
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))
            .expect("a dot in the sample's colour");
        let (dx, dy) = (dot.num("cx"), dot.num("cy"));
        assert!(
            (dx - cx).abs() <= 1.0 && (dy - cy).abs() <= 1.0,
            "({dx}, {dy}) vs ({cx}, {cy})"
        );
        if k == 1 {
            let ring = els
                .iter()
                .find(|e| e.name == "circle" && e.num("r") == f64::from(RING_R))
                .expect("the best ringed");
            assert_eq!((ring.num("cx"), ring.num("cy")), (dx, dy));
            assert_eq!(ring.attr("stroke"), Some("#FF0000"));
        }
    }
}

/// The numbers of the tick labels anchored at `anchor` (y-axis labels are anchored at their
/// end, x-axis labels in their middle).
fn ticks(els: &[El], anchor: &str) -> Vec<f64> {
    els.iter()
        .filter(|e| e.is("text", "text-anchor", anchor))
        .filter_map(|e| e.text.trim().parse().ok())
        .collect()
}

#[test]
fn progress_keeps_misses_off_the_scale_as_grey_ticks() {
    let scores = [Some(1.0), None, Some(3.0), None, Some(2.0), Some(f64::NAN)];
    let els = parse(&progress_plot("p", &scores));
    let grey: Vec<&El> = lines(&els, MISSING, "2");
    assert_eq!(grey.len(), 3, "a tick per miss");
    let bottom = grey[0].points()[0].1;
    assert!(grey.iter().all(|e| e.points()[0].1 == bottom));
    assert_eq!(
        dots(&els, 3).len(),
        3 + 1,
        "a dot per score and the legend's"
    );
    // The best so far, at every trial from the first, never going down.
    let best = lines(&els, &hex(BEST_COLOUR), "2");
    let line = best
        .iter()
        .map(|e| e.points())
        .max_by_key(Vec::len)
        .unwrap();
    assert_eq!(line.len(), 6);
    assert!(line.windows(2).all(|w| w[1].1 <= w[0].1), "{line:?}");
    assert!(line[0].1 > bottom - 1000.0 && line[0].1 < bottom);
    // The score axis spans the grasps: 1 to 3 padded by a twentieth.
    let y = ticks(&els, "end");
    assert!(
        y.len() >= 3 && y.iter().all(|v| (0.9..=3.1).contains(v)),
        "{y:?}"
    );
    // Trials are counted in whole numbers.
    let x: Vec<&str> = els
        .iter()
        .filter(|e| e.is("text", "text-anchor", "middle"))
        .map(|e| e.text.trim())
        .filter(|s| s.parse::<f64>().is_ok())
        .collect();
    assert!(!x.is_empty() && x.iter().all(|s| !s.contains('.')), "{x:?}");
}

#[test]
fn trials_map_2d_has_a_dot_per_trial_grey_misses_and_the_best_ringed() {
    let trials = [
        (vec![0.1, 0.2], Some(1.0)),
        (vec![0.3, 0.4], None),
        (vec![0.5, 0.6], Some(3.0)),
        (vec![0.7, 0.8], Some(2.0)),
    ];
    let els = parse(&trials_map(
        "t",
        &["approach", "vertical"],
        &[(0.0, 1.0), (0.0, 1.0)],
        &trials,
    ));
    let t = texts(&els);
    for want in ["approach", "vertical", MISSING_LABEL, "the best"] {
        assert!(t.iter().any(|s| s == want), "no {want:?}");
    }
    // Four trials and the legend's sign.
    let placed = dots(&els, DOT_R);
    assert_eq!(placed.len(), 5);
    assert_eq!(
        placed
            .iter()
            .filter(|d| d.attr("fill") == Some(MISSING))
            .count(),
        1
    );
    let zr = hit_range([Some(1.0), None, Some(3.0), Some(2.0)].into_iter());
    let top = hex3(colour((3.0 - zr.0) / (zr.1 - zr.0)));
    let best: Vec<&&El> = placed
        .iter()
        .filter(|d| d.attr("fill") == Some(top.as_str()))
        .collect();
    assert_eq!(best.len(), 1, "the best in the top colour");
    let ring = els
        .iter()
        .find(|e| e.name == "circle" && e.num("r") == f64::from(RING_R))
        .expect("ring");
    assert_eq!(
        (ring.num("cx"), ring.num("cy")),
        (best[0].num("cx"), best[0].num("cy"))
    );
    // Higher parameters further right and up.
    let (a, b) = (
        best[0],
        placed
            .iter()
            .find(|d| d.attr("fill") == Some(MISSING))
            .unwrap(),
    );
    assert!(a.num("cx") > b.num("cx") && a.num("cy") < b.num("cy"));
}

#[test]
fn trials_map_1d_draws_scores_against_the_parameter() {
    let trials = [
        (vec![0.1], Some(1.0)),
        (vec![0.5], None),
        (vec![0.9], Some(2.0)),
    ];
    let els = parse(&trials_map("t", &["approach"], &[(0.0, 1.0)], &trials));
    // Two grasps and the legend's sign, one grey tick, the best ringed.
    assert_eq!(dots(&els, DOT_R).len(), 3);
    assert_eq!(lines(&els, MISSING, "2").len(), 1);
    assert!(
        els.iter()
            .any(|e| e.name == "circle" && e.num("r") == f64::from(RING_R))
    );
    let y = ticks(&els, "end");
    assert!(
        y.iter().all(|v| (0.9..=2.1).contains(v)),
        "misses set the scale: {y:?}"
    );
}

#[test]
fn model_plot_draws_both_panels() {
    let xs = [0.0, 0.5, 1.0];
    let p = ModelPlot {
        title: "model",
        xlabel: "approach",
        xs: &xs,
        mean: &[0.0, 1.0, 0.0],
        sd: &[0.1, 0.1, f64::NAN],
        ei: &[0.2, 0.0, 0.3],
        truth: Some(&[0.0, 1.2, 0.1]),
        samples: &[(0.0, 0.0), (1.0, 0.1)],
        next: Some(0.7),
    };
    let els = parse(&model_plot(&p));
    let t = texts(&els);
    for want in [
        "model",
        "approach",
        "score",
        "EI (engine units)",
        "next trial",
        "samples",
    ] {
        assert!(t.iter().any(|s| s == want), "no {want:?} in {t:?}");
    }
    // Two samples and the legend's sign; the mean and the legend's; the EI.
    assert_eq!(dots(&els, DOT_R).len(), 3);
    let mean = lines(&els, &hex(MODEL_COLOUR), "2");
    assert_eq!(mean.iter().map(|e| e.points().len()).max(), Some(3));
    let ei = lines(&els, &hex(BEST_COLOUR), "2");
    assert_eq!(ei.len(), 1);
    assert_eq!(ei[0].points().len(), 3);
    // The band stops where the deviation is missing.
    let band: Vec<usize> = els
        .iter()
        .filter(|e| e.is("polygon", "fill", &hex(MODEL_COLOUR)))
        .map(|e| e.points().len())
        .collect();
    assert_eq!(band, [4]);
}

#[test]
fn extreme_values_never_panic() {
    let cases: [&[f64]; 5] = [
        &[1e300, -1e300],
        &[f64::MAX, f64::MIN],
        &[1e20, 1e20],
        &[1e-300, 2e-300],
        &[5e-324, 0.0],
    ];
    for ys in cases {
        let xs: Vec<f64> = ys.to_vec();
        let els = parse(&line_plot("x", "x", "y", &xs, ys));
        assert!(els.len() > 3, "{ys:?}");
        let grid = vec![ys.to_vec(), ys.to_vec()];
        parse(&heatmap("x", ("x", "y", "bw"), ys, ys, &grid));
        parse(&progress_plot(
            "x",
            &ys.iter().map(|&v| Some(v)).collect::<Vec<_>>(),
        ));
        let trials: Vec<(Vec<f64>, Option<f64>)> =
            ys.iter().map(|&v| (vec![v, v], Some(v))).collect();
        parse(&trials_map(
            "x",
            &[],
            &[(ys[0], ys[1]), (ys[1], ys[0])],
            &trials,
        ));
    }
}

#[test]
fn a_tick_at_zero_reads_zero() {
    // Ticks from -0.15 in steps of 0.05 reach zero with a rounding error (-2.8e-17).
    let xs: Vec<f64> = (0..=18).map(|k| -0.16 + 0.01 * f64::from(k)).collect();
    let els = parse(&line_plot("z", "x", "y", &xs, &xs));
    let labels: Vec<String> = texts(&els)
        .into_iter()
        .filter(|t| t.parse::<f64>().is_ok())
        .collect();
    assert!(labels.iter().any(|t| t == "0.000"), "{labels:?}");
    assert!(labels.iter().all(|t| !t.contains('e')), "{labels:?}");
}

#[test]
fn a_scan_plot_keeps_misses_off_the_scale_as_grey_ticks() {
    let xs = [-0.2, -0.1, 0.0, 0.1, 0.2];
    let hits = vec![None, Some(0.1), Some(0.3), Some(0.2), None];
    let els = parse(&scan_plot(
        "s",
        "approach offset (m)",
        "BW",
        &xs,
        &[("", hits)],
    ));
    let grey = lines(&els, MISSING, "2");
    // A tick per miss and the legend's... square (a rect, not a line).
    assert_eq!(grey.len(), 2, "{grey:?}");
    let bottom = grey[0].points()[0].1;
    assert!(grey.iter().all(|e| e.points()[0].1 == bottom));
    assert!(texts(&els).contains(&MISS_TICK_LABEL.to_string()));
    // The score axis spans the hits: 0.1 to 0.3, never the misses' scores.
    let y = ticks(&els, "end");
    assert!(
        y.len() >= 3 && y.iter().all(|v| (0.09..=0.31).contains(v)),
        "{y:?}"
    );
    let line = lines(&els, &hex(PALETTE[0]), "2");
    assert_eq!(line.len(), 1);
    assert_eq!(line[0].points().len(), 3);
    // Series that miss at different points: a tick wherever one missed, a legend per name.
    let series = [
        (
            "mean point",
            vec![None, Some(0.1), Some(0.2), Some(0.1), Some(0.1)],
        ),
        (
            "surface",
            vec![Some(0.2), None, Some(0.3), Some(0.2), Some(0.2)],
        ),
    ];
    let els = parse(&scan_plot("s", "x", "BW", &xs, &series));
    assert_eq!(lines(&els, MISSING, "2").len(), 2);
    assert!(texts(&els).contains(&"surface".to_string()));
}

/// The texts of the x-axis tick labels (anchored in their middle) that are numbers.
fn x_tick_labels(els: &[El]) -> Vec<String> {
    els.iter()
        .filter(|e| e.is("text", "text-anchor", "middle"))
        .map(|e| e.text.trim().to_string())
        .filter(|s| s.parse::<f64>().is_ok())
        .collect()
}

#[test]
fn trial_counts_are_labelled_as_whole_numbers() {
    let xs: Vec<f64> = (1..=40).map(f64::from).collect();
    let mean: Vec<f64> = xs.iter().map(|x| x.sqrt()).collect();
    let band = (mean.clone(), mean.clone());
    let els = parse(&bands_plot(
        "b",
        "trial",
        "best so far",
        &xs,
        &[("bo", mean)],
        &[band],
        None,
    ));
    let labels = x_tick_labels(&els);
    assert!(labels.len() >= 3, "{labels:?}");
    assert!(labels.iter().all(|s| !s.contains('.')), "{labels:?}");
    // A short count axis may have ticks between whole numbers: as many decimals as needed.
    let els = parse(&line_plot("s", "trial", "y", &[1.0, 2.0], &[1.0, 2.0]));
    let labels = x_tick_labels(&els);
    assert!(
        labels
            .iter()
            .all(|s| !s.ends_with(".000") && !s.ends_with('0') || s == "0")
    );
    assert!(labels.iter().any(|s| s == "1" || s == "2"), "{labels:?}");
    // Offsets in metres keep three decimals.
    let xs = [-0.1, 0.0, 0.1];
    let labels = x_tick_labels(&parse(&line_plot("s", "x", "y", &xs, &xs)));
    assert!(
        labels
            .iter()
            .all(|s| s.split('.').nth(1).is_some_and(|d| d.len() == 3)),
        "{labels:?}"
    );
}

#[test]
fn count_labels_whole_numbers_without_decimals() {
    assert_eq!(count(&5.0), "5");
    assert_eq!(count(&10.000000000001), "10");
    assert_eq!(count(&-0.0), "0");
    assert_eq!(count(&1.5), "1.5");
    assert_eq!(count(&2.25), "2.25");
    assert_eq!(count(&1.999), "2");
    assert_eq!(count(&1e300), tick(&1e300));
}
