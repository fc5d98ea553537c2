//! SVG charts of scans, runs and experiments, drawn with `plotters` and its SVG backend: a
//! line plot, several lines with bands, scans along one axis (misses as grey ticks off the
//! scale), the model of a 1D run, heatmaps with samples and a labelled colour bar, a run's
//! progress and its trials on the parameter space, and the colour map they share with the
//! PNG pictures of [`crate::preview`]. An axis of trial counts reads in whole numbers.
//!
//! plotters is built without default features, with `svg_backend` only: plotters,
//! plotters-backend and plotters-svg, pure Rust, no font library. Text is laid out with
//! plotters' estimate of glyph widths and rendered by the SVG viewer, so no font is needed.
//!
//! Compile cost on the 2-core build machine (`cargo clean -p graspopt-pictures -p plotters
//! -p plotters-backend -p plotters-svg`, then `cargo build -p graspopt-pictures --timings`,
//! dev profile, this crate at opt-level 3 as set in the root `Cargo.toml`): plotters 3.7 s,
//! plotters-svg 1.2 s, plotters-backend 0.7 s, and this crate 16.4 s instead of 5.5 s with
//! the hand-written SVG it replaces (plotters' generic drawing code is compiled here, at
//! opt-level 3): 19.8 s wall instead of 5.5 s. With this crate at opt-level 1 it takes
//! 13.6 s, at 0 4.1 s, but the PNG rasteriser ([`crate::preview`]) wants 3.
//!
//! Kept by hand: the colour map ([`colour`], also used by the PNG pictures), the legend (one
//! or two lines above the plot, so it never hides data; plotters' legend is a box inside the
//! plot), the colour bar (a second plotters chart of 50 rectangles beside the map: plotters
//! has none) and the one-line SVG written if plotters reports an error.
//!
//! Every chart returns a complete SVG document. Input with no finite value gives an
//! empty-state chart (axes and the note [`NO_DATA`]), never a panic; non-finite points
//! break a line instead of being joined across.

use std::error::Error;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::{ComposedElement, DashedPathElement};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Chart size in pixels (the model plot is taller, [`MODEL_H`]).
const W: u32 = 640;
const H: u32 = 420;
const MODEL_H: u32 = 560;
/// Width of the colour bar beside a map, its values and its label included.
const BAR_W: u32 = 110;
const FONT: &str = "sans-serif";
/// The note written in a chart with nothing to draw.
pub const NO_DATA: &str = "no finite values to draw";

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
type Drawn = Result<(), Box<dyn Error>>;

/// The series colours, in order.
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];
/// The best-so-far line and the trial dots of run charts, and the model plot's EI.
const BEST_COLOUR: RGBColor = PALETTE[0];
/// The model plot's mean, band and samples.
const MODEL_COLOUR: RGBColor = PALETTE[1];
/// The next trial in the model plot.
const NEXT_COLOUR: RGBColor = PALETTE[2];
const GREY: RGBColor = RGBColor(128, 128, 128);
/// The colour of grasps that touched nothing, in every chart and map (as in the PNG maps),
/// as plotters writes it in SVG.
pub const MISSING: &str = "#808080";
/// What grey means, in legends.
pub const MISSING_LABEL: &str = "grey: no contact";
/// Radius in pixels of a sample or trial dot, and of the ring around the best one.
const DOT_R: i32 = 4;
const RING_R: i32 = 9;

/// Values beyond this magnitude are drawn at it: the axes stay computable.
const LIMIT: f64 = 1e100;

/// `(lo, hi)` of the finite values (held within [`LIMIT`]), widened by half a unit, or a
/// hundredth of their magnitude if more, on each side when they are all equal (or too close
/// for the axis to be divided); `(0, 1)` when there are none.
pub(crate) fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .map(|v| v.clamp(-LIMIT, LIMIT))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let scale = lo.abs().max(hi.abs());
    if hi - lo < 1e-12 || hi - lo <= 1e-9 * scale {
        let pad = (0.01 * scale).max(0.5);
        (lo - pad, hi + pad)
    } else {
        (lo, hi)
    }
}

/// An axis tick label: three decimals, or three significant digits for very small or large
/// numbers.
pub(crate) fn tick(v: &f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-2..1e5).contains(&a) {
        format!("{v:.2e}")
    } else {
        format!("{v:.3}")
    }
}

/// `v` on an axis spanning `r`, with the rounding error of a tick at zero (say -2.8e-17,
/// from `-0.15 + 3 * 0.05`) set to zero.
pub(crate) fn snap(v: f64, r: (f64, f64)) -> f64 {
    if v.abs() < 1e-9 * (r.1 - r.0) { 0.0 } else { v }
}

/// An axis tick label for counts (trials): a whole number as one (`5`, not `5.000`); a tick
/// between two (on a short axis) with the decimals it needs, up to two; a huge one as [`tick`].
fn count(v: &f64) -> String {
    let r = v.round();
    if r.abs() >= 1e15 || !v.is_finite() {
        tick(v)
    } else if (v - r).abs() <= 1e-9 * r.abs().max(1.0) {
        // `+ 0.0` turns -0 into 0.
        format!("{:.0}", r + 0.0)
    } else {
        let decimals = format!("{v:.2}");
        decimals
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    }
}

/// Whether `xs` are counts: at least two finite values, every one a whole number of at most
/// a million (trial numbers), so the axis is labelled by [`count`].
fn is_count_axis(xs: &[f64]) -> bool {
    let finite: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    finite.len() >= 2 && finite.iter().all(|x| x.fract() == 0.0 && x.abs() <= 1e6)
}

/// The axes' ranges of a chart, to hold what is drawn near them: a point far outside would
/// overflow plotters' pixel arithmetic (a panic in debug builds).
#[derive(Clone, Copy)]
struct Fit {
    x: (f64, f64),
    y: (f64, f64),
}

impl Fit {
    /// `(x, y)` held within ten times the axes' spans of the plot.
    fn at(self, (x, y): (f64, f64)) -> (f64, f64) {
        let hold = |v: f64, r: (f64, f64)| {
            let span = r.1 - r.0;
            v.clamp(r.0 - 10.0 * span, r.1 + 10.0 * span)
        };
        (hold(x, self.x), hold(y, self.y))
    }
}

/// Splits points into runs of consecutive finite points: a line is broken where a value is
/// missing instead of being drawn across the gap.
/// Points are held near the axes by `fit`.
fn runs(points: impl Iterator<Item = (f64, f64)>, fit: Fit) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (x, y) in points {
        if x.is_finite() && y.is_finite() {
            if let Some(r) = out.last_mut() {
                r.push(fit.at((x, y)));
            }
        } else if out.last().is_some_and(|r| !r.is_empty()) {
            out.push(Vec::new());
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// Draws a chart of `size` pixels titled `title` with `draw` and returns the SVG. An error
/// from plotters (none is expected when writing to a string) gives an SVG that says so.
fn render(size: (u32, u32), title: &str, draw: impl FnOnce(&Area) -> Drawn) -> String {
    let mut out = String::new();
    let result: Drawn = (|| {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE)?;
        let area = root.titled(title, (FONT, 19))?;
        draw(&area)?;
        root.present()?;
        Ok(())
    })();
    match result {
        Ok(()) => out,
        Err(e) => error_svg(size, &format!("cannot draw the chart {title:?}: {e}")),
    }
}

/// A small SVG holding one line of text: the message of a chart that could not be drawn.
fn error_svg(size: (u32, u32), message: &str) -> String {
    let text = message
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    format!(
        "<svg width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" xmlns=\"http://www.w3.org/2000/svg\">\n\
         <text x=\"10\" y=\"30\" font-family=\"{FONT}\" font-size=\"12\">{text}</text>\n</svg>\n",
        size.0, size.1
    )
}

/// A chart on `area` with axes `xr`, `yr` (ticks labelled by `fmt` on x, [`tick`] on y;
/// light grid lines) and the axis descriptions `(x, y)` (an empty x: none).
fn axes<'a, 'b>(
    area: &'a Area<'b>,
    xr: (f64, f64),
    yr: (f64, f64),
    (xlabel, ylabel): (&str, &str),
    fmt: fn(&f64) -> String,
) -> Result<Chart<'a, 'b>, Box<dyn Error>> {
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .margin_right(20)
        .x_label_area_size(if xlabel.is_empty() { 24 } else { 42 })
        .y_label_area_size(66)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
    let fx = |v: &f64| fmt(&snap(*v, xr));
    let fy = |v: &f64| tick(&snap(*v, yr));
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .max_light_lines(0)
        .bold_line_style(BLACK.mix(0.08))
        .axis_desc_style((FONT, 15))
        .label_style((FONT, 14))
        .draw()?;
    Ok(chart)
}

/// Writes [`NO_DATA`] in the middle of the chart's plotting area.
fn no_data(chart: &Chart) -> Drawn {
    let area = chart.plotting_area().strip_coord_spec();
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 16).into_font())
        .color(&GREY)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw(&Text::new(NO_DATA, (w as i32 / 2, h as i32 / 2), style))?;
    Ok(())
}

/// A legend entry's sign.
#[derive(Clone, Copy)]
enum Mark {
    /// A line of this colour and width.
    Line(RGBColor, u32),
    /// A dashed line of this colour.
    Dashed(RGBColor),
    /// A dot of this colour ringed in black (as [`dot`]).
    Dot(RGBColor),
    /// A small faint dot of this colour (as in [`progress_plot`]).
    Faint(RGBColor),
    /// A ring of this colour.
    Ring(RGBColor),
    /// A filled square of this colour.
    Square(RGBColor),
}

/// Left edge of the legend's first entry: about the plotting area's left edge.
const LEGEND_LEFT: i32 = 76;
/// Height of one line of the legend.
const LEGEND_ROW: i32 = 20;

/// Draws a legend of `entries` (sign, text) on as many lines as it needs at the top of
/// `area`, above the plot so it never hides data; returns the area below it.
fn legend<'b>(area: &Area<'b>, entries: &[(Mark, &str)]) -> Result<Area<'b>, Box<dyn Error>> {
    if entries.is_empty() {
        return Ok(area.clone());
    }
    let (w, _) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let mut rows: Vec<Vec<(i32, Mark, &str)>> = vec![Vec::new()];
    let mut x = LEGEND_LEFT;
    for &(mark, text) in entries {
        let width = 24 + area.estimate_text_size(text, &style)?.0 as i32 + 18;
        if x + width > w as i32 && rows.last().is_some_and(|r| !r.is_empty()) {
            rows.push(Vec::new());
            x = LEGEND_LEFT;
        }
        if let Some(r) = rows.last_mut() {
            r.push((x, mark, text));
        }
        x += width;
    }
    let (strip, rest) = area.split_vertically(LEGEND_ROW * rows.len() as i32 + 4);
    for (k, row) in rows.iter().enumerate() {
        let y = LEGEND_ROW * k as i32 + LEGEND_ROW / 2;
        for &(x, mark, text) in row {
            let line = vec![(x, y), (x + 18, y)];
            match mark {
                Mark::Line(c, width) => strip.draw(&PathElement::new(line, c.stroke_width(width))),
                Mark::Dashed(c) => {
                    strip.draw(&DashedPathElement::new(line, 4, 3, c.stroke_width(1)))
                }
                Mark::Dot(c) => strip.draw(&dot((x + 9, y), c)),
                Mark::Faint(c) => strip.draw(&Circle::new((x + 9, y), 3, c.mix(0.45).filled())),
                Mark::Ring(c) => strip.draw(&Circle::new((x + 9, y), 6, c.stroke_width(2))),
                Mark::Square(c) => strip.draw(&Rectangle::new(
                    [(x + 3, y - 6), (x + 15, y + 6)],
                    c.filled(),
                )),
            }?;
            strip.draw(&Text::new(text, (x + 24, y), style.clone()))?;
        }
    }
    Ok(rest)
}

/// A line plot of `ys` against `xs`, with a dashed zero line when 0 is in range.
pub fn line_plot(title: &str, xlabel: &str, ylabel: &str, xs: &[f64], ys: &[f64]) -> String {
    lines_plot(title, xlabel, ylabel, xs, &[("", ys.to_vec())])
}

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

/// The legend's words for the grey ticks of grasps that touched nothing.
pub const MISS_TICK_LABEL: &str = "grey tick: no contact (below the scale)";

/// Scans along one axis: named series of scores against the same `xs`, `None` where the hand
/// touched nothing. A miss's score is far below every grasp's, so misses are grey ticks on the
/// bottom edge (one per point where a series missed) and never set the scale, which spans the
/// grasps' scores; the line of a series is broken at its misses.
pub fn scan_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    series: &[(&str, Vec<Option<f64>>)],
) -> String {
    let lines: Vec<(&str, Vec<f64>)> = series
        .iter()
        .map(|(name, ys)| (*name, ys.iter().map(|y| y.unwrap_or(f64::NAN)).collect()))
        .collect();
    let misses: Vec<f64> = xs
        .iter()
        .enumerate()
        .filter(|&(k, _)| series.iter().any(|(_, ys)| ys.get(k) == Some(&None)))
        .map(|(_, &x)| x)
        .collect();
    let chart = Lines {
        series: &lines,
        bands: &[],
        reference: None,
        misses: &misses,
    };
    lines_chart(title, (xlabel, ylabel), xs, &chart)
}

/// The polygons of a band between `low` and `high` over `xs`: one per run of points where
/// all three are finite, held near the axes by `fit`.
fn band_polygons(xs: &[f64], low: &[f64], high: &[f64], fit: Fit) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut run: Vec<(f64, f64, f64)> = Vec::new();
    let points = xs.iter().zip(low).zip(high).map(|((&x, &l), &h)| (x, l, h));
    for p in points.chain([(f64::NAN, 0.0, 0.0)]) {
        if p.0.is_finite() && p.1.is_finite() && p.2.is_finite() {
            run.push(p);
        } else if !run.is_empty() {
            let upper = run.iter().map(|&(x, _, h)| fit.at((x, h)));
            let lower = run.iter().rev().map(|&(x, l, _)| fit.at((x, l)));
            out.push(upper.chain(lower).collect());
            run.clear();
        }
    }
    out
}

/// A dashed line through `points`, `dash` pixels on and off.
fn dashed(
    points: Vec<(f64, f64)>,
    dash: i32,
    style: ShapeStyle,
) -> DashedPathElement<std::vec::IntoIter<(f64, f64)>, i32> {
    DashedPathElement::new(points, dash, dash, style)
}

/// [`lines_plot`] with a shaded band `(low, high)` behind series `k` for each `bands[k]`
/// (empty bands are skipped) and an optional dashed horizontal reference line with a label.
/// When every `x` is a whole number (trial counts) the x axis is labelled in whole numbers.
pub fn bands_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    xs: &[f64],
    series: &[(&str, Vec<f64>)],
    bands: &[(Vec<f64>, Vec<f64>)],
    reference: Option<(f64, &str)>,
) -> String {
    let chart = Lines {
        series,
        bands,
        reference,
        misses: &[],
    };
    lines_chart(title, (xlabel, ylabel), xs, &chart)
}

/// What a chart of lines against the same `xs` draws.
struct Lines<'a> {
    /// Named series (a NaN breaks the line).
    series: &'a [(&'a str, Vec<f64>)],
    /// A band behind series `k` for each `bands[k]`.
    bands: &'a [(Vec<f64>, Vec<f64>)],
    /// A dashed horizontal line and its label.
    reference: Option<(f64, &'a str)>,
    /// Where a grasp touched nothing: grey ticks on the bottom edge.
    misses: &'a [f64],
}

/// Draws [`Lines`] against `xs`.
fn lines_chart(title: &str, (xlabel, ylabel): (&str, &str), xs: &[f64], c: &Lines) -> String {
    let Lines {
        series,
        bands,
        reference,
        misses,
    } = *c;
    render((W, H), title, |area| {
        let reference = reference.filter(|r| r.0.is_finite());
        let mut entries: Vec<(Mark, &str)> = reference
            .iter()
            .map(|&(_, label)| (Mark::Dashed(BLACK), label))
            .collect();
        for (k, (name, _)) in series.iter().enumerate() {
            if !name.is_empty() {
                entries.push((Mark::Line(PALETTE[k % PALETTE.len()], 2), name));
            }
        }
        if !misses.is_empty() {
            entries.push((Mark::Square(GREY), MISS_TICK_LABEL));
        }
        let area = legend(area, &entries)?;
        let xr = range(xs.iter().copied());
        let yr = range(
            series
                .iter()
                .flat_map(|(_, ys)| ys.iter().copied())
                .chain(bands.iter().flat_map(|(l, h)| l.iter().chain(h).copied()))
                .chain(reference.map(|r| r.0)),
        );
        let fmt = if is_count_axis(xs) { count } else { tick };
        let mut chart = axes(&area, xr, yr, (xlabel, ylabel), fmt)?;
        let fit = Fit { x: xr, y: yr };
        for (k, (low, high)) in bands.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            chart.draw_series(
                band_polygons(xs, low, high, fit)
                    .into_iter()
                    .map(|p| Polygon::new(p, colour.mix(0.18).filled())),
            )?;
        }
        if let Some((value, _)) = reference {
            let level = vec![(xr.0, value), (xr.1, value)];
            chart.draw_series([dashed(level, 6, BLACK.stroke_width(1))])?;
        }
        if yr.0 < 0.0 && yr.1 > 0.0 {
            let zero = vec![(xr.0, 0.0), (xr.1, 0.0)];
            chart.draw_series([dashed(zero, 4, GREY.stroke_width(1))])?;
        }
        let mut drawn = 0;
        for (k, (_, ys)) in series.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let parts = runs(xs.iter().copied().zip(ys.iter().copied()), fit);
            drawn += parts.len();
            chart.draw_series(
                parts
                    .into_iter()
                    .map(|r| PathElement::new(r, colour.stroke_width(2))),
            )?;
        }
        let ticks: Vec<_> = misses.iter().map(|&x| miss_tick(&chart, x)).collect();
        chart.draw_series(ticks)?;
        if drawn == 0 {
            no_data(&chart)?;
        }
        Ok(())
    })
}

/// A dot ringed in black, drawn at a point of type `C`.
type Dot<C, DB> = ComposedElement<C, DB, Circle<(i32, i32), i32>, Circle<(i32, i32), i32>>;

/// A dot of `colour` ringed in black at `at`, as drawn for samples and trials.
fn dot<C, DB: DrawingBackend>(at: C, colour: RGBColor) -> Dot<C, DB> {
    EmptyElement::at(at)
        + Circle::new((0, 0), DOT_R, colour.filled())
        + Circle::new((0, 0), DOT_R, BLACK.stroke_width(1))
}

/// The red ring that marks the best sample or trial.
fn best_ring(at: (f64, f64)) -> Circle<(f64, f64), i32> {
    Circle::new(at, RING_R, RED.stroke_width(2))
}

/// A short vertical grey tick up from the chart's bottom edge at `x`: a grasp that touched
/// nothing.
fn miss_tick(chart: &Chart, x: f64) -> PathElement<(f64, f64)> {
    let yr = chart.y_range();
    let (_, h) = chart.plotting_area().dim_in_pixel();
    let up = 8.0 * (yr.end - yr.start) / f64::from(h.max(1));
    let xr = chart.x_range();
    let x = Fit {
        x: (xr.start, xr.end),
        y: (yr.start, yr.end),
    }
    .at((x, yr.start))
    .0;
    PathElement::new(
        vec![(x, yr.start), (x, yr.start + up)],
        GREY.stroke_width(2),
    )
}

/// The scale of the scores of grasps that touched something (misses never set it), padded
/// by a twentieth.
fn hit_range(scores: impl Iterator<Item = Option<f64>>) -> (f64, f64) {
    let (lo, hi) = range(scores.flatten());
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

mod map;
mod model;
mod run;

pub use map::{colour, heatmap, samples_map};
use map::{colour_of, with_colour_bar};
pub use model::{ModelPlot, model_plot};
pub use run::{progress_plot, trials_map};

#[cfg(test)]
mod tests;
