//! Small SVG charts for scans: a line plot (1D) and a heatmap with a colour bar (2D).
//! SVG needs no fonts on this machine: the viewer renders the text.

use std::fmt::Write;

const W: f64 = 640.0;
const H: f64 = 420.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 90.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 55.0;

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        (0.0, 1.0)
    } else if hi - lo < 1e-12 {
        (lo - 0.5, hi + 0.5)
    } else {
        (lo, hi)
    }
}

fn header(out: &mut String, title: &str) {
    header_sized(out, title, H);
}

/// The SVG opening, a white background and the title, for a chart `height` pixels high.
fn header_sized(out: &mut String, title: &str, height: f64) {
    let _ = write!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{height}" viewBox="0 0 {W} {height}" font-family="sans-serif" font-size="12">
<rect width="{W}" height="{height}" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>
"#,
        W / 2.0,
        escape(title)
    );
}

fn axes(out: &mut String, x: (f64, f64), y: (f64, f64), xlabel: &str, ylabel: &str, width: f64) {
    let (x0, y0, x1, y1) = (LEFT, H - BOTTOM, LEFT + width, TOP);
    let _ = writeln!(
        out,
        r#"<rect x="{x0}" y="{y1}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        x1 - x0,
        y0 - y1
    );
    for i in 0..=4 {
        let t = i as f64 / 4.0;
        let px = x0 + t * (x1 - x0);
        let py = y0 - t * (y0 - y1);
        let _ = writeln!(
            out,
            r#"<line x1="{px}" y1="{y0}" x2="{px}" y2="{}" stroke="black"/><text x="{px}" y="{}" text-anchor="middle">{:.3}</text>"#,
            y0 + 5.0,
            y0 + 18.0,
            x.0 + t * (x.1 - x.0)
        );
        let _ = writeln!(
            out,
            r#"<line x1="{}" y1="{py}" x2="{x0}" y2="{py}" stroke="black"/><text x="{}" y="{}" text-anchor="end">{:.3}</text>"#,
            x0 - 5.0,
            x0 - 8.0,
            py + 4.0,
            y.0 + t * (y.1 - y.0)
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text><text transform="translate(16 {}) rotate(-90)" text-anchor="middle">{}</text>"#,
        (x0 + x1) / 2.0,
        H - 12.0,
        escape(xlabel),
        (y0 + y1) / 2.0,
        escape(ylabel)
    );
}

/// A line plot of `ys` against `xs`, with a dashed zero line when 0 is in range.
pub fn line_plot(title: &str, xlabel: &str, ylabel: &str, xs: &[f64], ys: &[f64]) -> String {
    lines_plot(title, xlabel, ylabel, xs, &[("", ys.to_vec())])
}

const COLOURS: [&str; 6] = [
    "rgb(31,119,180)",
    "rgb(214,39,40)",
    "rgb(44,160,44)",
    "rgb(148,103,189)",
    "rgb(255,127,14)",
    "rgb(23,190,207)",
];

/// Several named series against the same `xs`, with a legend when names are given.
pub fn lines_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    series: &[(&str, Vec<f64>)],
) -> String {
    bands_plot(title, xlabel, ylabel, xs, series, &[], None)
}

/// A shaded band between `low` and `high` over `xs`, mapped to pixels by `to_px`.
fn band(
    out: &mut String,
    xs: &[f64],
    low: &[f64],
    high: &[f64],
    to_px: (&dyn Fn(f64) -> f64, &dyn Fn(f64) -> f64),
    colour: &str,
    opacity: f64,
) {
    let upper = xs.iter().zip(high).map(|(&x, &y)| (x, y));
    let lower = xs.iter().zip(low).rev().map(|(&x, &y)| (x, y));
    let points: Vec<String> = upper
        .chain(lower)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| format!("{:.2},{:.2}", to_px.0(x), to_px.1(y)))
        .collect();
    if !points.is_empty() {
        let _ = writeln!(
            out,
            r#"<polygon points="{}" fill="{colour}" fill-opacity="{opacity}" stroke="none"/>"#,
            points.join(" ")
        );
    }
}

/// [`lines_plot`] with a shaded band `(low, high)` behind series `k` for each `bands[k]`
/// (empty bands are skipped) and an optional dashed horizontal reference line with a label.
pub fn bands_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    series: &[(&str, Vec<f64>)],
    bands: &[(Vec<f64>, Vec<f64>)],
    reference: Option<(f64, &str)>,
) -> String {
    let mut out = String::new();
    header(&mut out, title);
    let width = W - LEFT - 30.0;
    let xr = range(xs.iter().copied());
    let yr = range(
        series
            .iter()
            .flat_map(|(_, ys)| ys.iter().copied())
            .chain(bands.iter().flat_map(|(l, h)| l.iter().chain(h).copied()))
            .chain(reference.map(|r| r.0)),
    );
    axes(&mut out, xr, yr, xlabel, ylabel, width);
    let px = |x: f64| LEFT + (x - xr.0) / (xr.1 - xr.0) * width;
    let py = |y: f64| (H - BOTTOM) - (y - yr.0) / (yr.1 - yr.0) * (H - BOTTOM - TOP);
    for (k, (low, high)) in bands.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        band(&mut out, xs, low, high, (&px, &py), colour, 0.18);
    }
    if let Some((value, label)) = reference {
        let _ = writeln!(
            out,
            r#"<line x1="{LEFT}" y1="{0:.2}" x2="{1}" y2="{0:.2}" stroke="black" stroke-dasharray="6 4"/><text x="{2}" y="{3:.2}" text-anchor="end">{4}</text>"#,
            py(value),
            LEFT + width,
            LEFT + width - 4.0,
            py(value) - 4.0,
            escape(label)
        );
    }
    if yr.0 < 0.0 && yr.1 > 0.0 {
        let _ = writeln!(
            out,
            r#"<line x1="{LEFT}" y1="{0}" x2="{1}" y2="{0}" stroke="gray" stroke-dasharray="4 3"/>"#,
            py(0.0),
            LEFT + width
        );
    }
    for (k, (name, ys)) in series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let points: Vec<String> = xs
            .iter()
            .zip(ys)
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|(&x, &y)| format!("{:.2},{:.2}", px(x), py(y)))
            .collect();
        let _ = writeln!(
            out,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="2"/>"#,
            points.join(" ")
        );
        if !name.is_empty() {
            let y = TOP + 16.0 + 16.0 * k as f64;
            let _ = writeln!(
                out,
                r#"<line x1="{0}" y1="{y}" x2="{1}" y2="{y}" stroke="{colour}" stroke-width="2"/><text x="{2}" y="{3}">{4}</text>"#,
                LEFT + 10.0,
                LEFT + 30.0,
                LEFT + 36.0,
                y + 4.0,
                escape(name)
            );
        }
    }
    out.push_str("</svg>\n");
    out
}

/// The model of a 1D run after some trials (thesis figures 4.16-4.17): in the upper panel
/// the posterior mean with a two-sigma band, the true scan in grey, the samples as dots and
/// the next trial as a vertical line; in the lower panel the expected improvement.
pub struct ModelPlot<'a> {
    pub title: &'a str,
    pub xlabel: &'a str,
    pub xs: &'a [f64],
    pub mean: &'a [f64],
    pub sd: &'a [f64],
    pub ei: &'a [f64],
    /// The score along the same `xs` from a grid scan, if known.
    pub truth: Option<&'a [f64]>,
    pub samples: &'a [(f64, f64)],
    pub next: Option<f64>,
}

/// Draws a [`ModelPlot`].
pub fn model_plot(p: &ModelPlot) -> String {
    const HEIGHT: f64 = 560.0;
    let width = W - LEFT - 30.0;
    let mut out = String::new();
    header_sized(&mut out, p.title, HEIGHT);
    let xr = range(p.xs.iter().copied());
    let upper: Vec<f64> = p.mean.iter().zip(p.sd).map(|(m, s)| m + 2.0 * s).collect();
    let lower: Vec<f64> = p.mean.iter().zip(p.sd).map(|(m, s)| m - 2.0 * s).collect();
    // The score axis spans the scan where given (its finite values: grasps, not misses), else
    // the samples and the mean, padded by a tenth; everything else is clipped to it (misses
    // sit on the bottom edge), since the band can be far wider where the model saw misses.
    let yr = {
        let (lo, hi) = match p.truth {
            Some(truth) if truth.iter().any(|v| v.is_finite()) => range(truth.iter().copied()),
            _ => range(p.mean.iter().copied().chain(p.samples.iter().map(|s| s.1))),
        };
        let pad = 0.1 * (hi - lo);
        (lo - pad, hi + pad)
    };
    let er = range(p.ei.iter().copied().chain([0.0]));
    let px = |x: f64| LEFT + (x - xr.0) / (xr.1 - xr.0) * width;
    // (top, bottom) of each panel in pixels.
    let panels = [(TOP, 370.0), (400.0, HEIGHT - BOTTOM)];
    let py = |panel: usize, r: (f64, f64), y: f64| {
        let (t, b) = panels[panel];
        b - (y.clamp(r.0, r.1) - r.0) / (r.1 - r.0) * (b - t)
    };
    let line = |out: &mut String, panel: usize, r: (f64, f64), ys: &[f64], style: &str| {
        let pts: Vec<String> =
            p.xs.iter()
                .zip(ys)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(&x, &y)| format!("{:.2},{:.2}", px(x), py(panel, r, y)))
                .collect();
        let _ = writeln!(
            out,
            r#"<polyline points="{}" fill="none" {style}/>"#,
            pts.join(" ")
        );
    };
    for (k, (t, b)) in panels.iter().enumerate() {
        let r = if k == 0 { yr } else { er };
        let _ = writeln!(
            out,
            r#"<rect x="{LEFT}" y="{t}" width="{width}" height="{}" fill="none" stroke="black"/>"#,
            b - t
        );
        for i in 0..=2 {
            let v = r.0 + (r.1 - r.0) * i as f64 / 2.0;
            let y = py(k, r, v);
            let _ = writeln!(
                out,
                r#"<text x="{}" y="{:.2}" text-anchor="end">{v:.3}</text>"#,
                LEFT - 6.0,
                y + 4.0
            );
        }
        let label = if k == 0 { "score" } else { "EI (engine units)" };
        let _ = writeln!(
            out,
            r#"<text transform="translate(16 {}) rotate(-90)" text-anchor="middle">{label}</text>"#,
            (t + b) / 2.0
        );
    }
    for i in 0..=4 {
        let x = xr.0 + (xr.1 - xr.0) * i as f64 / 4.0;
        let _ = writeln!(
            out,
            r#"<text x="{:.2}" y="{}" text-anchor="middle">{x:.3}</text>"#,
            px(x),
            HEIGHT - BOTTOM + 18.0
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        LEFT + width / 2.0,
        HEIGHT - 12.0,
        escape(p.xlabel)
    );
    let to_py = |y: f64| py(0, yr, y);
    band(
        &mut out,
        p.xs,
        &lower,
        &upper,
        (&px, &to_py),
        "rgb(214,39,40)",
        0.15,
    );
    if let Some(truth) = p.truth {
        line(
            &mut out,
            0,
            yr,
            truth,
            r#"stroke="gray" stroke-width="1.5""#,
        );
    }
    line(
        &mut out,
        0,
        yr,
        &upper,
        r#"stroke="rgb(214,39,40)" stroke-dasharray="5 3""#,
    );
    line(
        &mut out,
        0,
        yr,
        &lower,
        r#"stroke="rgb(214,39,40)" stroke-dasharray="5 3""#,
    );
    line(
        &mut out,
        0,
        yr,
        p.mean,
        r#"stroke="rgb(214,39,40)" stroke-width="2""#,
    );
    line(
        &mut out,
        1,
        er,
        p.ei,
        r#"stroke="rgb(31,119,180)" stroke-width="2""#,
    );
    for &(x, y) in p.samples {
        let _ = writeln!(
            out,
            r#"<circle cx="{:.2}" cy="{:.2}" r="4" fill="rgb(214,39,40)" stroke="black"/>"#,
            px(x),
            py(0, yr, y)
        );
    }
    if let Some(x) = p.next {
        let _ = writeln!(
            out,
            r#"<line x1="{0:.2}" y1="{TOP}" x2="{0:.2}" y2="{1}" stroke="rgb(44,160,44)" stroke-width="1.5" stroke-dasharray="2 2"/>"#,
            px(x),
            HEIGHT - BOTTOM
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}">mean, 2 sd (red), scan (grey), samples (dots), next trial (green)</text>"#,
        LEFT + 6.0,
        TOP + 14.0
    );
    out.push_str("</svg>\n");
    out
}

/// A heatmap ([`heatmap`]) with samples drawn on it as dots coloured by their own value on
/// the map's scale, the best one as a larger ring.
pub fn samples_map(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    grid: (&[f64], &[f64], &[Vec<f64>]),
    samples: &[(f64, f64, f64)],
) -> String {
    let (xs, ys, z) = grid;
    let mut out = heatmap(title, xlabel, ylabel, xs, ys, z);
    out.truncate(out.trim_end().len() - "</svg>".len());
    let width = W - LEFT - RIGHT;
    let xr = range(xs.iter().copied());
    let yr = range(ys.iter().copied());
    let zr = range(z.iter().flatten().copied());
    // Grid value k is drawn as cell k, so a sample at it goes to the cell's centre.
    let (nx, ny) = (xs.len().max(2) as f64, ys.len().max(2) as f64);
    let px = |x: f64| LEFT + ((x - xr.0) / (xr.1 - xr.0) * (nx - 1.0) + 0.5) * width / nx;
    let py = |y: f64| {
        let h = H - BOTTOM - TOP;
        (H - BOTTOM) - ((y - yr.0) / (yr.1 - yr.0) * (ny - 1.0) + 0.5) * h / ny
    };
    // A veil over the map so the samples stand out.
    let _ = writeln!(
        out,
        r#"<rect x="{LEFT}" y="{TOP}" width="{width}" height="{}" fill="white" fill-opacity="0.45"/>"#,
        H - BOTTOM - TOP
    );
    for &(x, y, v) in samples {
        let (r, g, b) = colour((v - zr.0) / (zr.1 - zr.0));
        let _ = writeln!(
            out,
            r#"<circle cx="{:.2}" cy="{:.2}" r="4.5" fill="rgb({r},{g},{b})" stroke="black" stroke-width="0.8"/>"#,
            px(x),
            py(y)
        );
    }
    if let Some(&(x, y, _)) = samples.iter().max_by(|a, b| a.2.total_cmp(&b.2)) {
        best_ring(&mut out, px(x), py(y));
    }
    out.push_str("</svg>\n");
    out
}

/// The red ring that marks the best sample or trial at pixel `(x, y)`.
fn best_ring(out: &mut String, x: f64, y: f64) {
    let _ = writeln!(
        out,
        r#"<circle cx="{x:.2}" cy="{y:.2}" r="9" fill="none" stroke="red" stroke-width="2"/>"#
    );
}

/// A colour for `t` in [0, 1]: dark blue, through white-ish green, to yellow.
pub fn colour(t: f64) -> (u8, u8, u8) {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let stops = [
        (0.0, (48.0, 18.0, 59.0)),
        (0.25, (40.0, 110.0, 200.0)),
        (0.5, (30.0, 190.0, 160.0)),
        (0.75, (170.0, 220.0, 60.0)),
        (1.0, (250.0, 230.0, 40.0)),
    ];
    for w in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (w[0], w[1]);
        if t <= t1 {
            let f = (t - t0) / (t1 - t0);
            let mix = |a: f64, b: f64| (a + f * (b - a)).round() as u8;
            return (mix(c0.0, c1.0), mix(c0.1, c1.1), mix(c0.2, c1.2));
        }
    }
    (250, 230, 40)
}

/// A heatmap of `z[i][j]` over `xs[i]` (horizontal) and `ys[j]` (vertical).
pub fn heatmap(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    ys: &[f64],
    z: &[Vec<f64>],
) -> String {
    let mut out = String::new();
    header(&mut out, title);
    let width = W - LEFT - RIGHT;
    let xr = range(xs.iter().copied());
    let yr = range(ys.iter().copied());
    let zr = range(z.iter().flatten().copied());
    let (nx, ny) = (xs.len().max(1) as f64, ys.len().max(1) as f64);
    let cw = width / nx;
    let ch = (H - BOTTOM - TOP) / ny;
    for (i, column) in z.iter().enumerate() {
        for (j, &v) in column.iter().enumerate() {
            let fill = fill_of(v, zr);
            let _ = writeln!(
                out,
                r#"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="{fill}"/>"#,
                LEFT + i as f64 * cw,
                H - BOTTOM - (j as f64 + 1.0) * ch,
                cw + 0.3,
                ch + 0.3
            );
        }
    }
    axes(&mut out, xr, yr, xlabel, ylabel, width);
    colour_bar(&mut out, LEFT + width + 20.0, zr);
    if z.iter().flatten().any(|v| !v.is_finite()) {
        legend(&mut out, &[(Mark::Square(MISSING), MISSING_LABEL)]);
    }
    out.push_str("</svg>\n");
    out
}

/// The SVG colour of a value on the scale `zr`, grey ([`MISSING`]) when it is not finite.
fn fill_of(v: f64, zr: (f64, f64)) -> String {
    if v.is_finite() {
        let (r, g, b) = colour((v - zr.0) / (zr.1 - zr.0));
        format!("rgb({r},{g},{b})")
    } else {
        MISSING.to_string()
    }
}

/// A vertical colour bar at column `bx` beside the plot area, `zr.0` at the bottom and
/// `zr.1` at the top, with both values written.
fn colour_bar(out: &mut String, bx: f64, zr: (f64, f64)) {
    for k in 0..50 {
        let t = k as f64 / 49.0;
        let (r, g, b) = colour(t);
        let y = H - BOTTOM - (k as f64 + 1.0) * (H - BOTTOM - TOP) / 50.0;
        let _ = writeln!(
            out,
            r#"<rect x="{bx}" y="{y:.2}" width="14" height="{:.2}" fill="rgb({r},{g},{b})"/>"#,
            (H - BOTTOM - TOP) / 50.0 + 0.3
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}">{:.3}</text><text x="{}" y="{}">{:.3}</text>"#,
        bx,
        TOP - 6.0,
        zr.1,
        bx,
        H - BOTTOM + 16.0,
        zr.0
    );
}

/// The colour of grasps that touched nothing, in every chart and map (as in the PNG maps).
pub const MISSING: &str = "rgb(128,128,128)";
/// What grey means, in legends.
pub const MISSING_LABEL: &str = "grey: no contact";

/// A legend entry's sign.
#[derive(Clone, Copy)]
enum Mark<'a> {
    /// A filled square of this colour.
    Square(&'a str),
    /// A line of this colour.
    Line(&'a str),
    /// A dot of this colour.
    Dot(&'a str),
    /// A ring of this colour.
    Ring(&'a str),
}

/// A legend on one line between the title and the plot area.
fn legend(out: &mut String, entries: &[(Mark, &str)]) {
    let y = TOP - 6.0;
    let mut x = LEFT;
    for (mark, text) in entries {
        let _ = match mark {
            Mark::Square(c) => writeln!(
                out,
                r#"<rect x="{x}" y="{}" width="11" height="11" fill="{c}" stroke="black" stroke-width="0.5"/>"#,
                y - 10.0
            ),
            Mark::Line(c) => writeln!(
                out,
                r#"<line x1="{x}" y1="{0}" x2="{1}" y2="{0}" stroke="{c}" stroke-width="2"/>"#,
                y - 4.0,
                x + 11.0
            ),
            Mark::Dot(c) => writeln!(
                out,
                r#"<circle cx="{}" cy="{}" r="4" fill="{c}" stroke="black" stroke-width="0.8"/>"#,
                x + 5.5,
                y - 4.5
            ),
            Mark::Ring(c) => writeln!(
                out,
                r#"<circle cx="{}" cy="{}" r="5" fill="none" stroke="{c}" stroke-width="2"/>"#,
                x + 5.5,
                y - 4.5
            ),
        };
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{y}" font-size="11">{}</text>"#,
            x + 15.0,
            escape(text)
        );
        // About 6 pixels per character at font size 11.
        x += 15.0 + 6.0 * text.chars().count() as f64 + 14.0;
    }
}

/// The colour of the best-so-far line and of trial dots in run charts.
const BEST_COLOUR: &str = "rgb(31,119,180)";

/// The scale of the scores of grasps that touched something (misses never set it), padded
/// by a twentieth.
fn hit_range(scores: impl Iterator<Item = Option<f64>>) -> (f64, f64) {
    let (lo, hi) = range(scores.flatten());
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// A run's progress: each trial's score (dots) and the best score so far (a line), against
/// the trials in the order they completed. `scores[k]` is `None` for a trial that touched
/// nothing: its score is far below every grasp's, so it is drawn as a grey tick on the
/// bottom edge and never sets the scale, which spans the scores of the grasps.
pub fn progress_plot(title: &str, scores: &[Option<f64>]) -> String {
    let mut out = String::new();
    header(&mut out, title);
    let width = W - LEFT - 30.0;
    let n = scores.len().max(1) as f64;
    let xr = (1.0, n.max(2.0));
    let yr = hit_range(scores.iter().copied());
    axes(
        &mut out,
        xr,
        yr,
        "trial (in the order completed)",
        "score",
        width,
    );
    let px = |x: f64| LEFT + (x - xr.0) / (xr.1 - xr.0) * width;
    let py = |y: f64| (H - BOTTOM) - (y - yr.0) / (yr.1 - yr.0) * (H - BOTTOM - TOP);
    let mut best: Option<f64> = None;
    let mut line = Vec::new();
    for (k, s) in scores.iter().enumerate() {
        let x = px(k as f64 + 1.0);
        match s {
            Some(v) => {
                best = Some(best.map_or(*v, |b| b.max(*v)));
                let _ = writeln!(
                    out,
                    r#"<circle cx="{x:.2}" cy="{:.2}" r="2.5" fill="{BEST_COLOUR}" fill-opacity="0.45"/>"#,
                    py(*v)
                );
            }
            None => {
                let _ = writeln!(
                    out,
                    r#"<line x1="{x:.2}" y1="{0}" x2="{x:.2}" y2="{1}" stroke="{MISSING}" stroke-width="2"/>"#,
                    H - BOTTOM,
                    H - BOTTOM - 8.0
                );
            }
        }
        if let Some(b) = best {
            line.push(format!("{x:.2},{:.2}", py(b)));
        }
    }
    let _ = writeln!(
        out,
        r#"<polyline points="{}" fill="none" stroke="{BEST_COLOUR}" stroke-width="2"/>"#,
        line.join(" ")
    );
    legend(
        &mut out,
        &[
            (Mark::Line(BEST_COLOUR), "best so far"),
            (Mark::Dot(BEST_COLOUR), "a trial's score"),
            (
                Mark::Square(MISSING),
                "grey tick: no contact (below the scale)",
            ),
        ],
    );
    out.push_str("</svg>\n");
    out
}

/// The trials of a run on its parameter space: one dot per trial at its first two
/// parameters (`bounds` the axes' ranges), coloured by score on the scale of the grasps
/// that touched something, grey where it touched nothing (`None`), the best ringed in red;
/// with one parameter, the score against it instead (misses as grey ticks on the bottom edge).
pub fn trials_map(
    title: &str,
    labels: &[&str],
    bounds: &[(f64, f64)],
    trials: &[(Vec<f64>, Option<f64>)],
) -> String {
    let mut out = String::new();
    header(&mut out, title);
    let zr = hit_range(trials.iter().map(|t| t.1));
    let best = trials
        .iter()
        .filter_map(|(p, s)| s.map(|s| (p, s)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if bounds.len() < 2 {
        let width = W - LEFT - 30.0;
        let xr = bounds.first().copied().unwrap_or((0.0, 1.0));
        let label = labels.first().copied().unwrap_or("parameter");
        axes(&mut out, xr, zr, label, "score", width);
        let px = |x: f64| LEFT + (x - xr.0) / (xr.1 - xr.0) * width;
        let py = |y: f64| (H - BOTTOM) - (y - zr.0) / (zr.1 - zr.0) * (H - BOTTOM - TOP);
        for (p, s) in trials {
            let Some(&x) = p.first() else { continue };
            let _ = match s {
                Some(v) => writeln!(
                    out,
                    r#"<circle cx="{:.2}" cy="{:.2}" r="4" fill="{BEST_COLOUR}" stroke="black" stroke-width="0.8"/>"#,
                    px(x),
                    py(*v)
                ),
                None => writeln!(
                    out,
                    r#"<line x1="{0:.2}" y1="{1}" x2="{0:.2}" y2="{2}" stroke="{MISSING}" stroke-width="2"/>"#,
                    px(x),
                    H - BOTTOM,
                    H - BOTTOM - 8.0
                ),
            };
        }
        if let Some((p, s)) = best {
            best_ring(&mut out, px(p[0]), py(s));
        }
        legend(
            &mut out,
            &[
                (Mark::Dot(BEST_COLOUR), "a trial"),
                (Mark::Ring("red"), "the best"),
                (
                    Mark::Square(MISSING),
                    "grey tick: no contact (below the scale)",
                ),
            ],
        );
    } else {
        let width = W - LEFT - RIGHT;
        let (xr, yr) = (bounds[0], bounds[1]);
        let xlabel = labels.first().copied().unwrap_or("parameter 1");
        let ylabel = labels.get(1).copied().unwrap_or("parameter 2");
        axes(&mut out, xr, yr, xlabel, ylabel, width);
        colour_bar(&mut out, LEFT + width + 20.0, zr);
        let px = |x: f64| LEFT + (x - xr.0) / (xr.1 - xr.0) * width;
        let py = |y: f64| (H - BOTTOM) - (y - yr.0) / (yr.1 - yr.0) * (H - BOTTOM - TOP);
        // Misses first, then the grasps from the lowest score up, so the best show on top.
        let mut order: Vec<&(Vec<f64>, Option<f64>)> = trials.iter().collect();
        order.sort_by(|a, b| {
            let key = |t: &(Vec<f64>, Option<f64>)| t.1.unwrap_or(f64::NEG_INFINITY);
            key(a).total_cmp(&key(b))
        });
        for (p, s) in order {
            let (Some(&x), Some(&y)) = (p.first(), p.get(1)) else {
                continue;
            };
            let fill = fill_of(s.unwrap_or(f64::NAN), zr);
            let _ = writeln!(
                out,
                r#"<circle cx="{:.2}" cy="{:.2}" r="4.5" fill="{fill}" stroke="black" stroke-width="0.8"/>"#,
                px(x),
                py(y)
            );
        }
        if let Some((p, _)) = best {
            best_ring(&mut out, px(p[0]), py(p[1]));
        }
        legend(
            &mut out,
            &[
                (Mark::Dot("rgb(170,220,60)"), "a trial, by score"),
                (Mark::Ring("red"), "the best"),
                (Mark::Square(MISSING), MISSING_LABEL),
            ],
        );
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests;
