//! DIRECT (DIviding RECTangles, Jones, Perttunen & Stuckman 1993; thesis section 3.3):
//! derivative-free global maximisation of a function on a box under an evaluation budget.
//!
//! The box is normalised to the unit cube. Each iteration selects the potentially optimal
//! rectangles (for each size the best one, then the lower-right convex hull of (size, value)
//! with the epsilon test of eq. 3.20), and trisects each along its longest sides, the side whose
//! two new centres have the best value being split first (eq. 3.18). [`polish`] optionally
//! refines the result with a short bounded gradient search.

use std::cmp::{Ordering, Reverse};
use std::collections::{BTreeMap, BinaryHeap};

use crate::error::{BoError, Result};
use crate::lbfgs;

/// Settings of a DIRECT run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectSettings {
    /// Maximum number of function evaluations (the run stops before a division would exceed it).
    pub max_evals: usize,
    /// Jones's epsilon in the potential-optimality test (default 1e-4).
    pub epsilon: f64,
    /// Deepest trisection level per side (3^-level side length), default 25.
    pub max_level: u32,
}

impl Default for DirectSettings {
    fn default() -> Self {
        DirectSettings {
            max_evals: 1000,
            epsilon: 1e-4,
            max_level: 25,
        }
    }
}

/// Outcome of a DIRECT run (maximisation).
#[derive(Debug, Clone, PartialEq)]
pub struct DirectResult {
    /// Best point (original coordinates).
    pub x: Vec<f64>,
    /// Best value.
    pub value: f64,
    /// Function evaluations used.
    pub evals: usize,
    /// Up to `k` best rectangle centres (original coordinates) with their values, best first
    /// (starting points for a local polish).
    pub top: Vec<(Vec<f64>, f64)>,
}

/// Heap entry: (value, index), ordered by value then index.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry(f64, usize);

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

/// Rectangles grouped by size, each group a min-heap on the value (stale entries, whose
/// rectangle has since been divided, are dropped lazily).
#[derive(Default)]
struct Groups {
    map: BTreeMap<u64, BinaryHeap<Reverse<Entry>>>,
}

impl Groups {
    fn insert(&mut self, size: f64, f: f64, idx: usize) {
        self.map
            .entry(size.to_bits())
            .or_default()
            .push(Reverse(Entry(f, idx)));
    }

    /// Best rectangle of each size, sizes ascending.
    fn representatives(&mut self, rects: &[Rect]) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.map.len());
        self.map.retain(|key, heap| {
            while let Some(Reverse(Entry(_, i))) = heap.peek() {
                if rects[*i].size.to_bits() == *key {
                    out.push(*i);
                    return true;
                }
                heap.pop();
            }
            false
        });
        out
    }
}

struct Rect {
    center: Vec<f64>,
    levels: Vec<u32>,
    /// Minimisation value (negated objective).
    f: f64,
    size: f64,
}

fn rect_size(levels: &[u32]) -> f64 {
    let mut ls: Vec<u32> = levels.to_vec();
    ls.sort_unstable();
    let s: f64 = ls.iter().map(|&l| 9f64.powi(-(l as i32))).sum();
    0.5 * s.sqrt()
}

/// The two new centres along one side: (side, c+, f(c+), c-, f(c-)).
type Trial = (usize, Vec<f64>, f64, Vec<f64>, f64);

/// Whether two points of the box `[lower, upper]` are the same up to rounding (1e-9 of each
/// side), as a point that went through a journal and back is.
pub(crate) fn same_point(a: &[f64], b: &[f64], lower: &[f64], upper: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .zip(lower.iter().zip(upper))
        .all(|((x, y), (lo, hi))| (x - y).abs() <= 1e-9 * (hi - lo))
}

/// Check bounds of a box.
pub fn check_bounds(lower: &[f64], upper: &[f64]) -> Result<()> {
    if lower.is_empty() {
        return Err(BoError::EmptyBounds);
    }
    if lower.len() != upper.len() {
        return Err(BoError::DimensionMismatch {
            expected: lower.len(),
            got: upper.len(),
        });
    }
    for (i, (l, u)) in lower.iter().zip(upper).enumerate() {
        if !(l.is_finite() && u.is_finite() && l < u) {
            return Err(BoError::InvalidBound {
                dim: i,
                lower: *l,
                upper: *u,
            });
        }
    }
    Ok(())
}

/// Maximise `f` over the box `[lower, upper]` with DIRECT. Non-finite values of `f` are
/// treated as very bad. Returns the best point, its value and the `top_k` best centres.
pub fn maximize<F>(
    mut f: F,
    lower: &[f64],
    upper: &[f64],
    settings: &DirectSettings,
    top_k: usize,
) -> Result<DirectResult>
where
    F: FnMut(&[f64]) -> f64,
{
    check_bounds(lower, upper)?;
    if settings.max_evals == 0 || settings.epsilon.is_nan() || settings.epsilon < 0.0 {
        return Err(BoError::InvalidSetting(
            "DIRECT needs max_evals >= 1 and epsilon >= 0".into(),
        ));
    }
    let d = lower.len();
    let to_x = |c: &[f64]| -> Vec<f64> {
        c.iter()
            .zip(lower.iter().zip(upper))
            .map(|(ci, (l, u))| l + ci * (u - l))
            .collect()
    };
    let mut x = vec![0.0; d];
    let mut eval = |c: &[f64], evals: &mut usize| -> f64 {
        *evals += 1;
        for ((xi, ci), (l, u)) in x.iter_mut().zip(c).zip(lower.iter().zip(upper)) {
            *xi = l + ci * (u - l);
        }
        let v = f(&x);
        if v.is_finite() { -v } else { 1e300 }
    };
    let mut search = Search::start(d, &mut eval);
    loop {
        let selected = search.potentially_optimal(settings);
        if selected.is_empty() {
            break;
        }
        let mut stop = false;
        for j in selected {
            if !search.divide(j, settings.max_evals, &mut eval) {
                stop = true;
                break;
            }
        }
        if stop || search.evals >= settings.max_evals {
            break;
        }
    }
    Ok(search.result(to_x, top_k))
}

/// The state of a DIRECT run: the rectangles (unit cube, minimisation values), grouped by
/// size, the best one and the evaluations used.
struct Search {
    rects: Vec<Rect>,
    groups: Groups,
    best: usize,
    evals: usize,
}

impl Search {
    /// The whole cube, evaluated at its centre.
    fn start(d: usize, eval: &mut impl FnMut(&[f64], &mut usize) -> f64) -> Search {
        let mut evals = 0usize;
        let c0 = vec![0.5; d];
        let f0 = eval(&c0, &mut evals);
        let levels0 = vec![0u32; d];
        let rects = vec![Rect {
            size: rect_size(&levels0),
            center: c0,
            levels: levels0,
            f: f0,
        }];
        let mut groups = Groups::default();
        groups.insert(rects[0].size, rects[0].f, 0);
        Search {
            rects,
            groups,
            best: 0,
            evals,
        }
    }

    /// The potentially optimal rectangles that may still be divided: the best of each size,
    /// on the lower convex hull of (size, value), passing the epsilon test.
    fn potentially_optimal(&mut self, settings: &DirectSettings) -> Vec<usize> {
        let rects = &self.rects;
        // Best rectangle per size (ties: the earliest); sizes ascending (positive f64 bit
        // patterns order like the values).
        let fmin = rects[self.best].f;
        let reps = self.groups.representatives(rects);
        // Start at the group whose best value is the global minimum (largest such size).
        let mut start = 0;
        for (k, &i) in reps.iter().enumerate() {
            if rects[i].f <= fmin {
                start = k;
            }
        }
        let hull = lower_hull(rects, &reps[start..]);
        // Epsilon test with the largest admissible Lipschitz constant (slope to the next).
        let thresh = fmin - settings.epsilon * fmin.abs();
        let mut selected = Vec::new();
        for (k, &j) in hull.iter().enumerate() {
            let rj = &rects[j];
            let ok = if k + 1 < hull.len() {
                let rn = &rects[hull[k + 1]];
                let slope = (rn.f - rj.f) / (rn.size - rj.size);
                rj.f - slope * rj.size <= thresh
            } else {
                true
            };
            if ok && rj.levels.iter().min().copied().unwrap_or(0) < settings.max_level {
                selected.push(j);
            }
        }
        selected
    }

    /// Trisects rectangle `j` along its longest sides, the side with the best new centre
    /// first (eq. 3.18); `false` (and nothing divided) when that would exceed `max_evals`.
    fn divide(
        &mut self,
        j: usize,
        max_evals: usize,
        eval: &mut impl FnMut(&[f64], &mut usize) -> f64,
    ) -> bool {
        let rects = &mut self.rects;
        let d = rects[j].levels.len();
        let minl = rects[j].levels.iter().min().copied().unwrap_or(0);
        let dims: Vec<usize> = (0..d).filter(|&i| rects[j].levels[i] == minl).collect();
        if self.evals + 2 * dims.len() > max_evals {
            return false;
        }
        let delta = 3f64.powi(-(minl as i32 + 1));
        let mut trial: Vec<Trial> = Vec::new();
        for &i in &dims {
            let mut cp = rects[j].center.clone();
            cp[i] += delta;
            let fp = eval(&cp, &mut self.evals);
            let mut cm = rects[j].center.clone();
            cm[i] -= delta;
            let fm = eval(&cm, &mut self.evals);
            trial.push((i, cp, fp, cm, fm));
        }
        trial.sort_by(|a, b| a.2.min(a.4).total_cmp(&b.2.min(b.4)));
        let mut levels = rects[j].levels.clone();
        for (i, cp, fp, cm, fm) in trial {
            levels[i] += 1;
            let size = rect_size(&levels);
            for (c, fv) in [(cp, fp), (cm, fm)] {
                rects.push(Rect {
                    center: c,
                    levels: levels.clone(),
                    f: fv,
                    size,
                });
                self.groups.insert(size, fv, rects.len() - 1);
                if fv < rects[self.best].f {
                    self.best = rects.len() - 1;
                }
            }
        }
        rects[j].size = rect_size(&levels);
        rects[j].levels = levels;
        self.groups.insert(rects[j].size, rects[j].f, j);
        true
    }

    /// The best point, its value and the `top_k` best centres (original coordinates).
    fn result(&self, to_x: impl Fn(&[f64]) -> Vec<f64>, top_k: usize) -> DirectResult {
        let rects = &self.rects;
        let mut order: Vec<usize> = (0..rects.len()).collect();
        order.sort_by(|&a, &b| rects[a].f.total_cmp(&rects[b].f));
        let top = order
            .iter()
            .take(top_k)
            .map(|&i| (to_x(&rects[i].center), -rects[i].f))
            .collect();
        DirectResult {
            x: to_x(&rects[self.best].center),
            value: -rects[self.best].f,
            evals: self.evals,
            top,
        }
    }
}

/// Lower convex hull of the rectangles `pts` in the (size, value) plane, sizes increasing.
fn lower_hull(rects: &[Rect], pts: &[usize]) -> Vec<usize> {
    let mut hull: Vec<usize> = Vec::new();
    for &p in pts {
        while hull.len() >= 2 {
            let o = &rects[hull[hull.len() - 2]];
            let a = &rects[hull[hull.len() - 1]];
            let b = &rects[p];
            let cross = (a.size - o.size) * (b.f - o.f) - (a.f - o.f) * (b.size - o.size);
            if cross <= 0.0 {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(p);
    }
    hull
}

/// Local polish: maximise `f` (value and gradient) from `x0` within `[lower, upper]` by a short
/// projected L-BFGS ascent. Returns the point and value (never worse than `x0`).
pub fn polish<F>(
    mut f: F,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    max_iter: usize,
) -> (Vec<f64>, f64)
where
    F: FnMut(&[f64], &mut [f64]) -> f64,
{
    let m = lbfgs::minimize_box(
        |x, g| {
            let v = f(x, g);
            g.iter_mut().for_each(|gi| *gi = -*gi);
            if v.is_finite() { -v } else { f64::INFINITY }
        },
        x0,
        lower,
        upper,
        max_iter,
        1e-9,
    );
    (m.x, -m.f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testfunctions::TestFunction;

    #[test]
    fn branin_optimum_to_1e4() {
        let tf = TestFunction::Branin;
        let (lo, hi) = tf.bounds();
        let s = DirectSettings {
            max_evals: 2000,
            ..Default::default()
        };
        let r = maximize(|x| -tf.eval(x), &lo, &hi, &s, 3).unwrap();
        assert!((-r.value - tf.f_min()).abs() < 1e-4, "{r:?}");
        assert!(r.evals <= 2000);
    }

    #[test]
    fn quadratic_6d_optimum_to_1e4() {
        let c = [0.21, 0.37, 0.55, 0.73, 0.12, 0.91];
        let q = |x: &[f64]| -> f64 {
            x.iter()
                .zip(&c)
                .enumerate()
                .map(|(i, (a, b))| (1.0 + i as f64 * 0.3) * (a - b) * (a - b))
                .sum()
        };
        let lo = vec![0.0; 6];
        let hi = vec![1.0; 6];
        let s = DirectSettings {
            max_evals: 6000,
            ..Default::default()
        };
        let r = maximize(|x| -q(x), &lo, &hi, &s, 1).unwrap();
        assert!(r.value > -1e-4, "DIRECT alone: {r:?}");
        // Polish brings the location to 1e-4 as well.
        let (x, v) = polish(
            |x, g| {
                for i in 0..6 {
                    g[i] = -2.0 * (1.0 + i as f64 * 0.3) * (x[i] - c[i]);
                }
                -q(x)
            },
            &r.x,
            &lo,
            &hi,
            50,
        );
        assert!(v >= r.value);
        for i in 0..6 {
            assert!((x[i] - c[i]).abs() < 1e-4, "{x:?}");
        }
    }

    #[test]
    fn budget_respected_and_bad_bounds_rejected() {
        let s = DirectSettings {
            max_evals: 37,
            ..Default::default()
        };
        let mut n = 0;
        let r = maximize(
            |x| {
                n += 1;
                -(x[0] - 0.3).powi(2)
            },
            &[0.0],
            &[1.0],
            &s,
            1,
        )
        .unwrap();
        assert_eq!(n, r.evals);
        assert!(r.evals <= 37);
        assert!(maximize(|_| 0.0, &[], &[], &s, 1).is_err());
        assert!(maximize(|_| 0.0, &[1.0], &[1.0], &s, 1).is_err());
        assert!(maximize(|_| 0.0, &[0.0, 0.0], &[1.0], &s, 1).is_err());
        assert!(maximize(|_| 0.0, &[f64::NAN], &[1.0], &s, 1).is_err());
        // NaN objective values do not break the run
        let r = maximize(
            |x| if x[0] > 0.6 { f64::NAN } else { x[0] },
            &[0.0],
            &[1.0],
            &s,
            1,
        )
        .unwrap();
        assert!(r.value.is_finite());
    }
}
