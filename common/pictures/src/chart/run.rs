//! The charts of a run: its progress (each trial's score and the best so far) and its
//! trials on the parameter space.

use super::*;

/// A run's progress: each trial's score (dots) and the best score so far (a line), against
/// the trials in the order they completed. `scores[k]` is `None` for a trial that touched
/// nothing: its score is far below every grasp's, so it is drawn as a grey tick on the
/// bottom edge and never sets the scale, which spans the scores of the grasps.
pub fn progress_plot(title: &str, scores: &[Option<f64>]) -> String {
    render((W, H), title, |area| {
        let area = legend(
            area,
            &[
                (Mark::Line(BEST_COLOUR, 2), "best so far"),
                (Mark::Faint(BEST_COLOUR), "a trial's score"),
                (Mark::Square(GREY), MISS_TICK_LABEL),
            ],
        )?;
        let scores: Vec<Option<f64>> = scores.iter().map(|s| s.filter(|v| v.is_finite())).collect();
        let n = scores.len().max(1) as f64;
        let xr = (1.0, n.max(2.0));
        let yr = hit_range(scores.iter().copied());
        let names = ("trial (in the order completed)", "score");
        let mut chart = axes(&area, xr, yr, names, count)?;
        let fit = Fit { x: xr, y: yr };
        let trial = |k: usize| k as f64 + 1.0;
        let mut best: Option<f64> = None;
        let best_line: Vec<(f64, f64)> = scores
            .iter()
            .enumerate()
            .filter_map(|(k, s)| {
                if let Some(v) = *s {
                    best = Some(best.map_or(v, |b| b.max(v)));
                }
                best.map(|b| fit.at((trial(k), b)))
            })
            .collect();
        let ticks: Vec<_> = (0..scores.len())
            .filter(|&k| scores[k].is_none())
            .map(|k| miss_tick(&chart, trial(k)))
            .collect();
        chart.draw_series(ticks)?;
        chart.draw_series(
            (0..scores.len())
                .filter_map(|k| Some((trial(k), scores[k]?)))
                .map(|at| Circle::new(fit.at(at), 3, BEST_COLOUR.mix(0.45).filled())),
        )?;
        if best_line.is_empty() {
            no_data(&chart)?;
        } else {
            chart.draw_series([PathElement::new(best_line, BEST_COLOUR.stroke_width(2))])?;
        }
        Ok(())
    })
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
    let finite = |v: Option<&f64>| v.copied().filter(|v| v.is_finite());
    // (parameter 1, parameter 2 if any, score if a grasp) of the trials that can be drawn.
    let points: Vec<(f64, Option<f64>, Option<f64>)> = trials
        .iter()
        .filter_map(|(p, s)| Some((finite(p.first())?, finite(p.get(1)), finite(s.as_ref()))))
        .collect();
    let zr = hit_range(points.iter().map(|t| t.2));
    let best = points
        .iter()
        .filter_map(|&(x, y, s)| Some((x, y, s?)))
        .max_by(|a, b| a.2.total_cmp(&b.2));
    let bound = |k: usize| range(bounds.get(k).map_or([0.0, 1.0], |b| [b.0, b.1]).into_iter());
    let label = |k: usize, default: &'static str| labels.get(k).copied().unwrap_or(default);
    let drawn = Trials { points, zr, best };
    if bounds.len() < 2 {
        return drawn.score_plot(title, bound(0), label(0, "parameter"));
    }
    let names = (label(0, "parameter 1"), label(1, "parameter 2"));
    drawn.map(title, (bound(0), bound(1)), names)
}

/// The trials [`trials_map`] draws: (parameter 1, parameter 2 if any, score if a grasp)
/// of each, the range of the grasps' scores, and the best.
struct Trials {
    points: Vec<(f64, Option<f64>, Option<f64>)>,
    zr: (f64, f64),
    best: Option<(f64, Option<f64>, f64)>,
}

impl Trials {
    /// One parameter (range `xr`, named `xlabel`): the score against it, misses as grey
    /// ticks on the bottom edge.
    fn score_plot(&self, title: &str, xr: (f64, f64), xlabel: &str) -> String {
        let Trials { points, zr, best } = self;
        let zr = *zr;
        render((W, H), title, |area| {
            let area = legend(
                area,
                &[
                    (Mark::Dot(BEST_COLOUR), "a trial"),
                    (Mark::Ring(RED), "the best"),
                    (Mark::Square(GREY), MISS_TICK_LABEL),
                ],
            )?;
            let names = (xlabel, "score");
            let mut chart = axes(&area, xr, zr, names, tick)?;
            let fit = Fit { x: xr, y: zr };
            let ticks: Vec<_> = points
                .iter()
                .filter(|t| t.2.is_none())
                .map(|t| miss_tick(&chart, t.0))
                .collect();
            chart.draw_series(ticks)?;
            chart.draw_series(
                points
                    .iter()
                    .filter_map(|&(x, _, s)| Some(dot(fit.at((x, s?)), BEST_COLOUR))),
            )?;
            if let Some((x, _, s)) = *best {
                chart.draw_series([best_ring(fit.at((x, s)))])?;
            }
            if points.is_empty() {
                no_data(&chart)?;
            }
            Ok(())
        })
    }

    /// Two parameters or more (the first two's ranges `(xr, yr)`, named `names`): a dot per
    /// trial coloured by score, beside the colour bar.
    fn map(&self, title: &str, (xr, yr): ((f64, f64), (f64, f64)), names: (&str, &str)) -> String {
        let Trials { points, zr, best } = self;
        let zr = *zr;
        render((W, H), title, |area| {
            let area = legend(
                area,
                &[
                    (Mark::Dot(RGBColor(170, 220, 60)), "a trial, by score"),
                    (Mark::Ring(RED), "the best"),
                    (Mark::Square(GREY), MISSING_LABEL),
                ],
            )?;
            let main = with_colour_bar(&area, zr, "score")?;
            let mut chart = axes(&main, xr, yr, names, tick)?;
            let fit = Fit { x: xr, y: yr };
            // Misses first, then the grasps from the lowest score up, so the best show on
            // top.
            let mut order: Vec<(f64, f64, Option<f64>)> = points
                .iter()
                .filter_map(|&(x, y, s)| Some((x, y?, s)))
                .collect();
            order.sort_by(|a, b| {
                let key = |s: Option<f64>| s.unwrap_or(f64::NEG_INFINITY);
                key(a.2).total_cmp(&key(b.2))
            });
            chart.draw_series(
                order
                    .iter()
                    .map(|&(x, y, s)| dot(fit.at((x, y)), colour_of(s.unwrap_or(f64::NAN), zr))),
            )?;
            if let Some((x, Some(y), _)) = *best {
                chart.draw_series([best_ring(fit.at((x, y)))])?;
            }
            if order.is_empty() {
                no_data(&chart)?;
            }
            Ok(())
        })
    }
}
