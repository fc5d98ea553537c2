//! The colour map and the maps drawn with it: a heatmap of a 2D scan, and the same with a
//! model's samples on it (figures 4.16-4.27), each beside its colour bar.

use super::*;

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

/// The colour of a value on the scale `zr`, grey when it is not finite.
pub(super) fn colour_of(v: f64, zr: (f64, f64)) -> RGBColor {
    if v.is_finite() {
        let (r, g, b) = colour((v - zr.0) / (zr.1 - zr.0));
        RGBColor(r, g, b)
    } else {
        GREY
    }
}

/// Splits `area` into a plotting part and, on the right, a colour bar for the scale `zr`
/// (`zr.0` at the bottom, `zr.1` at the top) with its values and, beside them, `label` (what
/// the colours stand for); returns the plotting part.
/// The bar's top and bottom line up with a plotting area built by [`axes`] with an x label.
pub(super) fn with_colour_bar<'b>(
    area: &Area<'b>,
    zr: (f64, f64),
    label: &str,
) -> Result<Area<'b>, Box<dyn Error>> {
    let (w, _) = area.dim_in_pixel();
    let (main, bar) = area.split_horizontally(w.saturating_sub(BAR_W));
    let mut chart = ChartBuilder::on(&bar)
        .margin(10)
        .margin_left(0)
        .x_label_area_size(42)
        .right_y_label_area_size(BAR_W as i32 - 30)
        .build_cartesian_2d(0.0..1.0, zr.0..zr.1)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .set_tick_mark_size(LabelAreaPosition::Right, 5)
        .y_labels(6)
        .y_label_formatter(&|v: &f64| tick(&snap(*v, zr)))
        .y_desc(label)
        .axis_desc_style((FONT, 15))
        .label_style((FONT, 13))
        .draw()?;
    const STEPS: usize = 50;
    let dz = (zr.1 - zr.0) / STEPS as f64;
    chart.draw_series((0..STEPS).map(|k| {
        let (r, g, b) = colour((k as f64 + 0.5) / STEPS as f64);
        let z0 = zr.0 + k as f64 * dz;
        Rectangle::new([(0.0, z0), (1.0, z0 + dz)], RGBColor(r, g, b).filled())
    }))?;
    Ok(main)
}

/// The cells of a map along one axis: `n` cells for values spanning `r`, evenly spaced, value
/// `k` drawn as the cell around `r.0 + k * step`. Returns the axis range (the outer cell
/// edges) and the step.
fn cells(n: usize, r: (f64, f64)) -> ((f64, f64), f64) {
    if n > 1 {
        let step = (r.1 - r.0) / (n - 1) as f64;
        ((r.0 - step / 2.0, r.1 + step / 2.0), step)
    } else {
        (r, r.1 - r.0)
    }
}

/// A map of `z[i][j]` over `xs[i]` (horizontal) and `ys[j]` (vertical), with samples drawn
/// on it when given.
fn map(
    title: &str,
    (xlabel, ylabel, zlabel): (&str, &str, &str),
    (xs, ys, z): (&[f64], &[f64], &[Vec<f64>]),
    samples: &[(f64, f64, f64)],
) -> String {
    render((W, H), title, |area| {
        let zr = range(z.iter().flatten().copied());
        let samples: Vec<(f64, f64, f64)> = samples
            .iter()
            .copied()
            .filter(|s| s.0.is_finite() && s.1.is_finite())
            .collect();
        let best = samples.iter().max_by(|a, b| a.2.total_cmp(&b.2));
        let mut entries = Vec::new();
        if !samples.is_empty() {
            entries.push((Mark::Dot(colour_of(zr.1, zr)), "a sample, by value"));
            entries.push((Mark::Ring(RED), "the best"));
        }
        if z.iter().flatten().any(|v| !v.is_finite()) {
            entries.push((Mark::Square(GREY), MISSING_LABEL));
        }
        let area = legend(area, &entries)?;
        let main = with_colour_bar(&area, zr, zlabel)?;
        let nx = xs.len().max(z.len());
        let ny = ys.len().max(z.iter().map(Vec::len).max().unwrap_or(0));
        let ((xa, sx), (ya, sy)) = (
            cells(nx, range(xs.iter().copied())),
            cells(ny, range(ys.iter().copied())),
        );
        let mut chart = axes(&main, xa, ya, (xlabel, ylabel), tick)?;
        let fit = Fit { x: xa, y: ya };
        let centre = |a: (f64, f64), s: f64, k: usize| a.0 + (k as f64 + 0.5) * s;
        chart.draw_series(z.iter().enumerate().flat_map(|(i, column)| {
            column.iter().enumerate().map(move |(j, &v)| {
                let (cx, cy) = (centre(xa, sx, i), centre(ya, sy, j));
                Rectangle::new(
                    [
                        (cx - sx / 2.0, cy - sy / 2.0),
                        (cx + sx / 2.0, cy + sy / 2.0),
                    ],
                    colour_of(v, zr).filled(),
                )
            })
        }))?;
        if !samples.is_empty() {
            // A veil over the map so the samples stand out.
            let veil = Rectangle::new([(xa.0, ya.0), (xa.1, ya.1)], WHITE.mix(0.45).filled());
            chart.draw_series([veil])?;
            let dots = samples
                .iter()
                .map(|&(x, y, v)| dot(fit.at((x, y)), colour_of(v, zr)));
            chart.draw_series(dots)?;
        }
        if let Some(&(x, y, _)) = best {
            chart.draw_series([best_ring(fit.at((x, y)))])?;
        }
        if !z.iter().flatten().any(|v| v.is_finite()) {
            no_data(&chart)?;
        }
        Ok(())
    })
}

/// A heatmap ([`heatmap`]) with samples drawn on it as dots coloured by their own value on
/// the map's scale, the best one as a larger ring; `zlabel` names the values (beside the
/// colour bar).
pub fn samples_map(
    title: &str,
    (xlabel, ylabel, zlabel): (&str, &str, &str),
    grid: (&[f64], &[f64], &[Vec<f64>]),
    samples: &[(f64, f64, f64)],
) -> String {
    map(title, (xlabel, ylabel, zlabel), grid, samples)
}

/// A heatmap of `z[i][j]` over `xs[i]` (horizontal) and `ys[j]` (vertical), the values
/// evenly spaced (as a grid scan's); cells that are not finite are grey ([`MISSING`]).
/// `labels` name the axes and the values (`zlabel`, beside the colour bar).
pub fn heatmap(
    title: &str,
    labels: (&str, &str, &str),
    xs: &[f64],
    ys: &[f64],
    z: &[Vec<f64>],
) -> String {
    map(title, labels, (xs, ys, z), &[])
}
