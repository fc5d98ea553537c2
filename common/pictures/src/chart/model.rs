//! The model plot of a 1D run: the posterior mean and its band over the scan, the samples
//! and the next trial, and the expected improvement below.

use super::*;

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
    render((W, MODEL_H), p.title, |area| {
        let next = p.next.filter(|x| x.is_finite());
        let area = legend(area, &model_legend(p, next.is_some()))?;
        let xr = range(p.xs.iter().copied());
        let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 * 64 / 100);
        let next = model_panel(&top, p, xr, next)?;
        ei_panel(&bottom, p, xr, next)
    })
}

/// The legend of a [`ModelPlot`] (the scan and the next trial when it has them).
fn model_legend<'a>(p: &ModelPlot, next: bool) -> Vec<(Mark, &'a str)> {
    let mut entries = vec![
        (Mark::Line(MODEL_COLOUR, 2), "mean"),
        (Mark::Dashed(MODEL_COLOUR), "mean +- 2 sd"),
    ];
    if p.truth.is_some() {
        entries.push((Mark::Line(GREY, 2), "scan"));
    }
    entries.push((Mark::Dot(MODEL_COLOUR), "samples"));
    if next {
        entries.push((Mark::Dashed(NEXT_COLOUR), "next trial"));
    }
    entries
}

/// The score axis of a [`ModelPlot`]: it spans the scan where given (its finite values:
/// grasps, not misses), else the samples and the mean, padded by a tenth; everything else
/// is clipped to it (misses sit on the bottom edge), since the band can be far wider where
/// the model saw misses.
fn score_range(p: &ModelPlot) -> (f64, f64) {
    let (lo, hi) = match p.truth {
        Some(truth) if truth.iter().any(|v| v.is_finite()) => range(truth.iter().copied()),
        _ => range(p.mean.iter().copied().chain(p.samples.iter().map(|s| s.1))),
    };
    let pad = 0.1 * (hi - lo);
    (lo - pad, hi + pad)
}

/// The upper panel of a [`ModelPlot`] on `top` (x axis `xr`): the band, the scan, the
/// mean, the samples and the `next` trial. Returns where the next trial's line is drawn.
fn model_panel(
    top: &Area,
    p: &ModelPlot,
    xr: (f64, f64),
    next: Option<f64>,
) -> Result<Option<f64>, Box<dyn Error>> {
    let yr = score_range(p);
    let clip = |y: f64| y.clamp(yr.0, yr.1);
    let clipped = |ys: &[f64]| -> Vec<f64> { ys.iter().map(|&y| clip(y)).collect() };
    let upper: Vec<f64> = p
        .mean
        .iter()
        .zip(p.sd)
        .map(|(m, s)| clip(m + 2.0 * s))
        .collect();
    let lower: Vec<f64> = p
        .mean
        .iter()
        .zip(p.sd)
        .map(|(m, s)| clip(m - 2.0 * s))
        .collect();
    let fit = Fit { x: xr, y: yr };
    let line = |ys: &[f64]| runs(p.xs.iter().copied().zip(ys.iter().copied()), fit);
    let mut chart = axes(top, xr, yr, ("", "score"), tick)?;
    chart.draw_series(
        band_polygons(p.xs, &lower, &upper, fit)
            .into_iter()
            .map(|b| Polygon::new(b, MODEL_COLOUR.mix(0.15).filled())),
    )?;
    if let Some(truth) = p.truth {
        chart.draw_series(
            line(&clipped(truth))
                .into_iter()
                .map(|r| PathElement::new(r, GREY.stroke_width(2))),
        )?;
    }
    for edge in [&upper, &lower] {
        chart.draw_series(
            line(edge)
                .into_iter()
                .map(|r| dashed(r, 4, MODEL_COLOUR.stroke_width(1))),
        )?;
    }
    let parts = line(&clipped(p.mean));
    let drawn = parts.len();
    chart.draw_series(
        parts
            .into_iter()
            .map(|r| PathElement::new(r, MODEL_COLOUR.stroke_width(2))),
    )?;
    chart.draw_series(
        p.samples
            .iter()
            .filter(|s| s.0.is_finite() && s.1.is_finite())
            .map(|&(x, y)| dot(fit.at((x, y)), MODEL_COLOUR)),
    )?;
    let next = next.map(|x| fit.at((x, 0.0)).0);
    if let Some(x) = next {
        let at = vec![(x, yr.0), (x, yr.1)];
        chart.draw_series([dashed(at, 3, NEXT_COLOUR.stroke_width(2))])?;
    }
    if drawn == 0 {
        no_data(&chart)?;
    }
    Ok(next)
}

/// The lower panel of a [`ModelPlot`] on `bottom`: the expected improvement, and the line
/// of the `next` trial.
fn ei_panel(bottom: &Area, p: &ModelPlot, xr: (f64, f64), next: Option<f64>) -> Drawn {
    let er = range(p.ei.iter().copied().chain([0.0]));
    let mut chart = axes(bottom, xr, er, (p.xlabel, "EI (engine units)"), tick)?;
    let fit = Fit { x: xr, y: er };
    chart.draw_series(
        runs(p.xs.iter().copied().zip(p.ei.iter().copied()), fit)
            .into_iter()
            .map(|r| PathElement::new(r, BEST_COLOUR.stroke_width(2))),
    )?;
    if let Some(x) = next {
        let at = vec![(x, er.0), (x, er.1)];
        chart.draw_series([dashed(at, 3, NEXT_COLOUR.stroke_width(2))])?;
    }
    Ok(())
}
