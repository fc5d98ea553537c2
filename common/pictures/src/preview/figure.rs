//! Raster figures of scans (PNG): the map of a 2D scan ([`heatmap_figure`]) and the line of
//! a 1D scan ([`line_figure`]), each with a title, axes with values and names, notes that say
//! what the values are relative to, and a legend; text in the bitmap font of [`draw_text`].

use super::{
    BACKGROUND, BAR_GAP, BAR_WIDTH, Image, MISSING_COLOUR, TEXT_COLOUR, draw_line, draw_text,
    draw_text_centred, heatmap_png, text_width,
};
use crate::chart::{range, snap, tick};

/// Space around and between the parts of a figure (pixels).
const MARGIN: i64 = 8;
/// Height of a line of notes or legend.
const LINE: i64 = 14;
/// Height of a glyph of the font at scale 1.
const GLYPH: i64 = 8;
/// Length of a tick mark.
const TICK: i64 = 4;
/// The plot of a line figure (pixels).
const LINE_PLOT: (u32, u32) = (560, 280);
/// The line of a 1D scan: the first colour of the SVG charts.
pub const LINE_COLOUR: [u8; 3] = [31, 119, 180];

/// An axis of a figure: what it shows, with its units, and the values along it.
#[derive(Clone, Copy, Debug)]
pub struct Axis<'a> {
    /// Its name and units, as `approach offset (m)`.
    pub label: &'a str,
    /// The values along it (a scan's grid).
    pub values: &'a [f64],
}

/// The map of a 2D scan: `z[i][j]` at `x.values[i]` (left to right), `y.values[j]` (bottom to
/// top), one `cell` x `cell` square each, coloured as [`heatmap_png`] does (grey where not
/// finite), its colour bar labelled with its values and `z_label`.
#[derive(Clone, Copy, Debug)]
pub struct HeatmapFigure<'a> {
    pub title: &'a str,
    /// Lines under the map: what the axes and the values are relative to.
    pub notes: &'a [&'a str],
    pub x: Axis<'a>,
    pub y: Axis<'a>,
    pub z: &'a [Vec<f64>],
    /// What the colours stand for (the metric), above the colour bar.
    pub z_label: &'a str,
    /// What grey means (in the legend, when a cell is grey).
    pub missing: &'a str,
    /// Pixels per cell each way.
    pub cell: u32,
}

/// The line of a 1D scan: `ys[k]` at `x.values[k]`, `None` where the hand touched nothing,
/// drawn as a grey tick on the bottom edge; the score axis spans the other values.
#[derive(Clone, Copy, Debug)]
pub struct LineFigure<'a> {
    pub title: &'a str,
    /// Lines under the plot: what the axes and the values are relative to.
    pub notes: &'a [&'a str],
    pub x: Axis<'a>,
    /// The name of the values (the metric).
    pub y_label: &'a str,
    pub ys: &'a [Option<f64>],
    /// What a grey tick means (in the legend, when there is one).
    pub missing: &'a str,
}

/// Tick values for an axis spanning `r`, about `n` of them at a round step (1, 2, 2.5 or 5
/// times a power of ten), each with its label; the two ends when no round step fits.
fn ticks(r: (f64, f64), n: usize) -> Vec<(f64, String)> {
    let label = |v: f64| (v, tick(&snap(v, r)));
    let ends = || {
        let mut out = vec![label(r.0)];
        if r.1 > r.0 {
            out.push(label(r.1));
        }
        out
    };
    let raw = (r.1 - r.0) / n.max(1) as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return ends();
    }
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| *s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * power);
    let (first, last) = ((r.0 / step).ceil(), (r.1 / step).floor());
    if !(step.is_finite() && step > 0.0 && first.is_finite() && last - first <= 20.0) {
        return ends();
    }
    let count = (last - first).max(-1.0) as i64 + 1;
    (0..count)
        .map(|k| label((first + k as f64) * step))
        .collect()
}

/// The plot of a figure: its pixel rectangle and the values at its edges.
#[derive(Clone, Copy, Debug)]
struct Plot {
    left: i64,
    top: i64,
    width: i64,
    height: i64,
    x: (f64, f64),
    y: (f64, f64),
}

impl Plot {
    /// The pixel column of `v` on the x axis (the axis's ends on the plot's first and last
    /// columns).
    fn px(&self, v: f64) -> f64 {
        let t = (v - self.x.0) / (self.x.1 - self.x.0);
        self.left as f64 + t * (self.width - 1) as f64
    }
    /// The pixel row of `v` on the y axis (the axis's ends on the plot's last and first rows).
    fn py(&self, v: f64) -> f64 {
        let t = (v - self.y.0) / (self.y.1 - self.y.0);
        (self.top + self.height - 1) as f64 - t * (self.height - 1) as f64
    }
}

/// What surrounds the plot of a figure.
struct Frame<'a> {
    title: &'a str,
    notes: &'a [&'a str],
    /// The legend's grey square and what it means, if something is grey.
    missing: Option<&'a str>,
    /// The axes' names and the values at the plot's edges.
    x: (&'a str, (f64, f64)),
    y: (&'a str, (f64, f64)),
    /// The plot's size in pixels.
    size: (u32, u32),
    /// Room right of the plot (a colour bar and its values) and its width with the text
    /// above it (the bar's label), and room above the plot.
    right: (i64, i64),
    above: i64,
}

/// `text` drawn upwards (read with the head turned left) with its start at `(x, bottom)`.
fn draw_text_up(img: &mut Image, (x, bottom): (i64, i64), text: &str) {
    let mut line = Image::new(text_width(text, 1).max(1), GLYPH as u32, BACKGROUND);
    draw_text(&mut line, (0, 0), text, 1, TEXT_COLOUR);
    for row in 0..line.height {
        for col in 0..line.width {
            let c = line.pixels[(row * line.width + col) as usize];
            if c != BACKGROUND {
                img.set(x + i64::from(row), bottom - i64::from(col), c);
            }
        }
    }
}

/// A picture with `f`'s title, axes (a box, ticks with values, names), notes and legend
/// around an empty plot; returns it and where the plot is.
fn frame(f: &Frame) -> (Image, Plot) {
    let (pw, ph) = (i64::from(f.size.0.max(1)), i64::from(f.size.1.max(1)));
    let x_ticks = ticks(f.x.1, (pw / 90).clamp(2, 8) as usize);
    let y_ticks = ticks(f.y.1, (ph / 40).clamp(2, 8) as usize);
    let width_of = |t: &str| i64::from(text_width(t, 1));
    let y_tick_w = y_ticks.iter().map(|t| width_of(&t.1)).max().unwrap_or(0);
    let left = MARGIN + GLYPH + 6 + y_tick_w + 2 + TICK;
    let legend = f.notes.len() as i64 + i64::from(f.missing.is_some());
    let text_w = f
        .notes
        .iter()
        .map(|n| width_of(n))
        .chain(f.missing.map(|m| 12 + width_of(m)))
        .max()
        .unwrap_or(0)
        .max(left + width_of(f.x.0) - pw / 2);
    let inner = (left - MARGIN + pw + f.right.1).max(text_w);
    // A title in large letters widens a narrow figure up to 800 pixels.
    let title_scale = if i64::from(text_width(f.title, 2)) <= inner.max(800 - 2 * MARGIN) {
        2
    } else {
        1
    };
    let width = inner.max(i64::from(text_width(f.title, title_scale))) + 2 * MARGIN;
    let top = MARGIN + GLYPH * i64::from(title_scale) + MARGIN + f.above;
    let x_label_y = top + ph + TICK + 2 + GLYPH + 6;
    let legend_y = x_label_y + GLYPH + MARGIN;
    let height = legend_y + legend * LINE + MARGIN;
    let mut img = Image::new(width as u32, height as u32, BACKGROUND);
    let plot = Plot {
        left,
        top,
        width: pw,
        height: ph,
        x: f.x.1,
        y: f.y.1,
    };
    draw_text_centred(&mut img, width / 2, MARGIN, f.title, title_scale);
    draw_axes(&mut img, &plot, &x_ticks, &y_ticks);
    draw_text_centred(&mut img, left + pw / 2, x_label_y, f.x.0, 1);
    let y_label_bottom = top + ph / 2 + width_of(f.y.0) / 2;
    draw_text_up(&mut img, (MARGIN, y_label_bottom), f.y.0);
    draw_legend(&mut img, legend_y, f.notes, f.missing);
    (img, plot)
}

/// The box one pixel outside `plot`, and its ticks with their values.
fn draw_axes(img: &mut Image, plot: &Plot, x_ticks: &[(f64, String)], y_ticks: &[(f64, String)]) {
    let Plot {
        left,
        top,
        width,
        height,
        ..
    } = *plot;
    for x in left - 1..=left + width {
        img.set(x, top - 1, TEXT_COLOUR);
        img.set(x, top + height, TEXT_COLOUR);
    }
    for y in top - 1..=top + height {
        img.set(left - 1, y, TEXT_COLOUR);
        img.set(left + width, y, TEXT_COLOUR);
    }
    let width_of = |t: &str| i64::from(text_width(t, 1));
    for (v, text) in x_ticks {
        let x = plot.px(*v).round() as i64;
        for y in top + height..top + height + TICK {
            img.set(x, y, TEXT_COLOUR);
        }
        let at = (x - width_of(text) / 2, top + height + TICK + 2);
        draw_text(img, at, text, 1, TEXT_COLOUR);
    }
    for (v, text) in y_ticks {
        let y = plot.py(*v).round() as i64;
        for x in left - 1 - TICK..left - 1 {
            img.set(x, y, TEXT_COLOUR);
        }
        let at = (left - 1 - TICK - 2 - width_of(text), y - GLYPH / 2);
        draw_text(img, at, text, 1, TEXT_COLOUR);
    }
}

/// The notes, one a line from row `y`, then the grey square and what it means.
fn draw_legend(img: &mut Image, y: i64, notes: &[&str], missing: Option<&str>) {
    for (k, note) in notes.iter().enumerate() {
        draw_text(img, (MARGIN, y + k as i64 * LINE), note, 1, TEXT_COLOUR);
    }
    if let Some(missing) = missing {
        let y = y + notes.len() as i64 * LINE;
        for dy in 0..8 {
            for dx in 0..8 {
                img.set(MARGIN + dx, y + dy, MISSING_COLOUR);
            }
        }
        draw_text(img, (MARGIN + 12, y), missing, 1, TEXT_COLOUR);
    }
}

/// The cell edges of `n` cells centred on values spanning `values`' range (evenly spaced).
fn cell_edges(values: &[f64], n: usize) -> (f64, f64) {
    let r = range(values.iter().copied());
    if n > 1 {
        let step = (r.1 - r.0) / (n - 1) as f64;
        (r.0 - step / 2.0, r.1 + step / 2.0)
    } else {
        r
    }
}

/// Draws a [`HeatmapFigure`].
pub fn heatmap_figure(f: &HeatmapFigure) -> Image {
    let map = heatmap_png(f.z, f.cell);
    let cell = f.cell.max(1);
    let (nx, ny) = (
        f.z.len().max(1),
        f.z.iter().map(Vec::len).max().unwrap_or(0).max(1),
    );
    let finite = || f.z.iter().flatten().copied().filter(|v| v.is_finite());
    let (lo, hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let bar_h = ny as i64 * i64::from(cell);
    let z_ticks = if lo < hi {
        ticks((lo, hi), (bar_h / 40).clamp(2, 6) as usize)
    } else if lo == hi {
        vec![(lo, tick(&lo))]
    } else {
        Vec::new()
    };
    let z_tick_w = z_ticks
        .iter()
        .map(|t| i64::from(text_width(&t.1, 1)))
        .max()
        .unwrap_or(0);
    let bar_x = i64::from(BAR_GAP);
    let bar_end = bar_x + i64::from(BAR_WIDTH);
    let right = bar_end + TICK + 2 + z_tick_w;
    let label_w = bar_x + i64::from(text_width(f.z_label, 1));
    let any_missing = f.z.iter().flatten().any(|v| !v.is_finite());
    let (mut img, plot) = frame(&Frame {
        title: f.title,
        notes: f.notes,
        missing: any_missing.then_some(f.missing),
        x: (f.x.label, cell_edges(f.x.values, nx)),
        y: (f.y.label, cell_edges(f.y.values, ny)),
        size: (nx as u32 * cell, ny as u32 * cell),
        right: (right, right.max(label_w)),
        above: LINE,
    });
    img.blit(&map, (plot.left, plot.top));
    let bar_left = plot.left + plot.width + bar_x;
    let z_label = (bar_left, plot.top - LINE + 2);
    draw_text(&mut img, z_label, f.z_label, 1, TEXT_COLOUR);
    for (v, text) in &z_ticks {
        let t = if hi > lo { (v - lo) / (hi - lo) } else { 0.5 };
        let y = plot.top + ((1.0 - t) * (bar_h - 1) as f64).round() as i64;
        let x = plot.left + plot.width + bar_end;
        for dx in 0..TICK {
            img.set(x + dx, y, TEXT_COLOUR);
        }
        draw_text(
            &mut img,
            (x + TICK + 2, y - GLYPH / 2),
            text,
            1,
            TEXT_COLOUR,
        );
    }
    img
}

/// Draws a [`LineFigure`].
pub fn line_figure(f: &LineFigure) -> Image {
    let xs = f.x.values;
    let hits = || f.ys.iter().filter_map(|y| y.filter(|v| v.is_finite()));
    let (lo, hi) = range(hits());
    let pad = 0.05 * (hi - lo);
    let any_miss = f.ys.iter().any(Option::is_none);
    let (mut img, plot) = frame(&Frame {
        title: f.title,
        notes: f.notes,
        missing: any_miss.then_some(f.missing),
        x: (f.x.label, range(xs.iter().copied())),
        y: (f.y_label, (lo - pad, hi + pad)),
        size: LINE_PLOT,
        right: (MARGIN, MARGIN),
        above: 0,
    });
    let cols = (plot.left, plot.left + plot.width);
    let bottom = plot.top + plot.height - 1;
    let mut last: Option<(f64, f64)> = None;
    for (&x, y) in xs.iter().zip(f.ys) {
        let at = match y {
            Some(v) if v.is_finite() && x.is_finite() => Some((plot.px(x), plot.py(*v))),
            _ => None,
        };
        match (last, at) {
            (Some(a), Some(b)) => draw_line(&mut img, a, b, LINE_COLOUR, cols),
            (None, Some(b)) => draw_line(&mut img, b, b, LINE_COLOUR, cols),
            _ => {}
        }
        if y.is_none() && x.is_finite() {
            // Two columns wide, inside the plot at its edges.
            let px = (plot.px(x).round() as i64).clamp(cols.0, cols.1 - 2);
            for dy in 0..8 {
                for dx in 0..2 {
                    img.set(px + dx, bottom - dy, MISSING_COLOUR);
                }
            }
        }
        last = at;
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The columns of `img` in row `y` that have colour `c`.
    fn columns(img: &Image, y: u32, c: [u8; 3]) -> Vec<u32> {
        (0..img.width)
            .filter(|&x| img.get(x, y) == Some(c))
            .collect()
    }

    #[test]
    fn ticks_fall_on_round_values_inside_the_range() {
        let values: Vec<f64> = ticks((-0.16, 0.02), 5).into_iter().map(|t| t.0).collect();
        assert_eq!(values.len(), 4, "{values:?}");
        for (v, want) in values.iter().zip([-0.15, -0.1, -0.05, 0.0]) {
            assert!((v - want).abs() < 1e-12, "{values:?}");
        }
        let labels: Vec<String> = ticks((-0.16, 0.02), 5).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["-0.150", "-0.100", "-0.050", "0.000"]);
        // Degenerate and extreme ranges give their ends, never a panic.
        assert_eq!(ticks((1.0, 1.0), 4).len(), 1);
        assert_eq!(ticks((0.0, 5e-324), 4).len(), 2);
        assert!(ticks((-1e300, 1e300), 4).len() <= 21);
        assert!(ticks((f64::NAN, 1.0), 4).len() <= 2);
    }

    #[test]
    fn a_line_figure_draws_hits_on_their_scale_and_misses_as_grey_ticks() {
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
        // The miss's defined score (about -2) is not given: the scale spans 0.1 to 0.3.
        let ys = [None, Some(0.1), Some(0.3), Some(0.2), None];
        let img = line_figure(&LineFigure {
            title: "BW on the sphere",
            notes: &["offsets from the reference pose"],
            x: Axis {
                label: "approach offset (m)",
                values: &xs,
            },
            y_label: "BW",
            ys: &ys,
            missing: "grey tick: no contact",
        });
        assert_eq!(img.get(0, 0), Some(BACKGROUND));
        let line: Vec<(u32, u32)> = (0..img.height)
            .flat_map(|y| {
                columns(&img, y, LINE_COLOUR)
                    .into_iter()
                    .map(move |x| (x, y))
            })
            .collect();
        assert!(!line.is_empty());
        // The line spans x = 1 to 3 of the 0..4 axis: the middle half of the plot.
        let (x_lo, x_hi) = (
            line.iter().map(|p| p.0).min().unwrap(),
            line.iter().map(|p| p.0).max().unwrap(),
        );
        let (plot_w, _) = LINE_PLOT;
        assert!((i64::from(x_hi - x_lo) - i64::from(plot_w / 2)).abs() <= 3);
        // Its highest point (0.3) and lowest (0.1) are within the plot, 5% of its height
        // from the edges (the scale is the hits', padded by a twentieth).
        let (y_top, y_bottom) = (
            line.iter().map(|p| p.1).min().unwrap(),
            line.iter().map(|p| p.1).max().unwrap(),
        );
        let span = f64::from(y_bottom - y_top);
        let expected = f64::from(LINE_PLOT.1) * 0.2 / 0.22;
        assert!((span - expected).abs() <= 3.0, "{span} px, not {expected}");
        // Two grey ticks, at the ends of the axis, on the bottom edge.
        let grey_rows: Vec<u32> = (0..img.height)
            .filter(|&y| {
                let c = columns(&img, y, MISSING_COLOUR);
                c.len() == 4
            })
            .collect();
        assert_eq!(grey_rows.len(), 8, "{grey_rows:?}");
        assert!(grey_rows[0] > y_bottom, "ticks below the line");
        // The legend's square: 8 x 8 grey pixels besides the ticks' 2 x 8 x 2.
        let grey = img.pixels.iter().filter(|c| **c == MISSING_COLOUR).count();
        assert_eq!(grey, 64 + 32);
    }

    #[test]
    fn a_heatmap_figure_has_its_map_axes_and_a_labelled_colour_bar() {
        let xs = [-0.1, 0.0, 0.1];
        let ys = [0.0, 0.5];
        let z = vec![vec![-1.0, 0.0], vec![0.5, f64::NAN], vec![1.0, 3.0]];
        let f = HeatmapFigure {
            title: "BW on the mug",
            notes: &["offsets from the reference pose"],
            x: Axis {
                label: "approach offset (m)",
                values: &xs,
            },
            y: Axis {
                label: "vertical offset (m)",
                values: &ys,
            },
            z: &z,
            z_label: "BW",
            missing: "grey: no contact",
            cell: 20,
        };
        let img = heatmap_figure(&f);
        let map = heatmap_png(&z, 20);
        // The map is in the picture as heatmap_png draws it: find its top left corner by the
        // first cell's colour (the bottom left cell is the minimum, the top left 0.0).
        let (mw, mh) = (map.width, map.height);
        let found = (0..img.height.saturating_sub(mh)).find_map(|y| {
            (0..img.width.saturating_sub(mw))
                .find(|&x| {
                    (0..mh).all(|dy| (0..mw).all(|dx| img.get(x + dx, y + dy) == map.get(dx, dy)))
                })
                .map(|x| (x, y))
        });
        let (x0, y0) = found.expect("the map in the figure");
        // A box around it, and text left of it (the y values and name) and below it.
        assert_eq!(img.get(x0 - 1, y0 + 5), Some(TEXT_COLOUR));
        assert_eq!(img.get(x0 + 5, y0 + mh), Some(TEXT_COLOUR));
        let text_left =
            (0..x0 - 6).any(|x| (y0..y0 + mh).any(|y| img.get(x, y) == Some(TEXT_COLOUR)));
        assert!(text_left);
        // The colour bar's label above it and its values right of it.
        let bar_right = x0 + mw;
        let beside = (bar_right + 1..img.width)
            .any(|x| (y0..y0 + mh).any(|y| img.get(x, y) == Some(TEXT_COLOUR)));
        assert!(beside, "no values beside the colour bar");
        let above = (x0 + 3 * 20..img.width)
            .any(|x| (y0 - LINE as u32..y0).any(|y| img.get(x, y) == Some(TEXT_COLOUR)));
        assert!(above, "no label above the colour bar");
        // Grey: the missing cell (20 x 20) and the legend's square.
        let grey = img.pixels.iter().filter(|c| **c == MISSING_COLOUR).count();
        assert_eq!(grey, 400 + 64);
    }
}
