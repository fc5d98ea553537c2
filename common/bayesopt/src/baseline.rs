//! The common ask/tell trait and the two baselines behind it: uniform random search and the
//! exhaustive grid (points visited in a seeded random order, so a budget smaller than the grid
//! is an unbiased subsample).

use serde::{Deserialize, Serialize};

use crate::direct::{check_bounds, same_point};
use crate::error::{BoError, Result};
use crate::rng::Rng;

/// Ask/tell interface shared by the engine and the baselines.
pub trait AskTell {
    /// Propose `q` points to evaluate.
    fn suggest(&mut self, q: usize) -> Result<Vec<Vec<f64>>>;
    /// Tell the value observed at `x`.
    fn observe(&mut self, x: &[f64], y: f64) -> Result<()>;
    /// Best observation so far (by the method's own direction).
    fn best(&self) -> Option<(Vec<f64>, f64)>;
}

/// Observations with a direction; shared bookkeeping of the baselines.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Record {
    lower: Vec<f64>,
    upper: Vec<f64>,
    minimize: bool,
    best: Option<(Vec<f64>, f64)>,
    count: usize,
}

impl Record {
    fn new(bounds: &[(f64, f64)], minimize: bool) -> Result<Self> {
        let lower: Vec<f64> = bounds.iter().map(|b| b.0).collect();
        let upper: Vec<f64> = bounds.iter().map(|b| b.1).collect();
        check_bounds(&lower, &upper)?;
        Ok(Record {
            lower,
            upper,
            minimize,
            best: None,
            count: 0,
        })
    }

    fn observe(&mut self, x: &[f64], y: f64) -> Result<()> {
        if x.len() != self.lower.len() {
            return Err(BoError::DimensionMismatch {
                expected: self.lower.len(),
                got: x.len(),
            });
        }
        if !y.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return Err(BoError::NonFinite {
                what: "observation",
            });
        }
        let better = match &self.best {
            None => true,
            Some((_, b)) => {
                if self.minimize {
                    y < *b
                } else {
                    y > *b
                }
            }
        };
        if better {
            self.best = Some((x.to_vec(), y));
        }
        self.count = self.count.saturating_add(1);
        Ok(())
    }
}

/// Uniform random search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RandomSearch {
    record: Record,
    rng: Rng,
    /// Points drawn from the stream so far.
    #[serde(default)]
    drawn: usize,
}

impl RandomSearch {
    /// Random search on `bounds`, minimising if `minimize`.
    pub fn new(bounds: &[(f64, f64)], minimize: bool, seed: u64) -> Result<Self> {
        Ok(RandomSearch {
            record: Record::new(bounds, minimize)?,
            rng: Rng::new(seed),
            drawn: 0,
        })
    }

    /// Continues the stream after the points a run already issued (`known`: its
    /// observations and pending points), so a search rebuilt from the run's history proposes
    /// what the original would have, not the run's first points again. Only a fresh search
    /// moves: it skips to just after the last of its first `4 n + 64` stream points that is in
    /// `known` (points that failed and left the history are skipped with the others); with no
    /// such point it stays where it is.
    pub fn resume_after(&mut self, known: &[&[f64]]) {
        if self.drawn > 0 || known.is_empty() {
            return;
        }
        let (lower, upper) = (&self.record.lower, &self.record.upper);
        let mut probe = self.clone();
        let mut last = None;
        for i in 0..4 * known.len() + 64 {
            let p = probe.draw();
            if known.iter().any(|k| same_point(k, &p, lower, upper)) {
                last = Some(i);
            }
        }
        if let Some(i) = last {
            for _ in 0..=i {
                self.draw();
            }
        }
    }

    /// Observations told so far.
    pub fn observation_count(&self) -> usize {
        self.record.count
    }

    /// The box: one `(lower, upper)` per dimension.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        let r = &self.record;
        r.lower
            .iter()
            .copied()
            .zip(r.upper.iter().copied())
            .collect()
    }

    /// Checks a deserialised search (see [`crate::optimizer::Optimizer::check_state`]):
    /// valid bounds, and a finite best point of their dimension.
    pub fn check_state(&self) -> Result<()> {
        let r = &self.record;
        check_bounds(&r.lower, &r.upper)?;
        if let Some((x, y)) = &r.best {
            if x.len() != r.lower.len() {
                return Err(BoError::DimensionMismatch {
                    expected: r.lower.len(),
                    got: x.len(),
                });
            }
            if !y.is_finite() || x.iter().any(|v| !v.is_finite()) {
                return Err(BoError::NonFinite { what: "best point" });
            }
        }
        Ok(())
    }

    fn draw(&mut self) -> Vec<f64> {
        self.drawn = self.drawn.saturating_add(1);
        let r = &self.record;
        r.lower
            .iter()
            .zip(&r.upper)
            .map(|(l, u)| self.rng.uniform_range(*l, *u))
            .collect()
    }
}

impl AskTell for RandomSearch {
    fn suggest(&mut self, q: usize) -> Result<Vec<Vec<f64>>> {
        Ok((0..q).map(|_| self.draw()).collect())
    }
    fn observe(&mut self, x: &[f64], y: f64) -> Result<()> {
        self.record.observe(x, y)
    }
    fn best(&self) -> Option<(Vec<f64>, f64)> {
        self.record.best.clone()
    }
}

/// Exhaustive grid with `points_per_dim` points per dimension (bounds included), visited in a
/// seeded random order (or in lexicographic order with `shuffle = false`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridSearch {
    record: Record,
    points_per_dim: usize,
    order: Vec<usize>,
    next: usize,
}

impl GridSearch {
    /// Grid search; errors if the grid has more than 10^7 points or fewer than 2 per dimension.
    pub fn new(
        bounds: &[(f64, f64)],
        points_per_dim: usize,
        minimize: bool,
        shuffle: bool,
        seed: u64,
    ) -> Result<Self> {
        let record = Record::new(bounds, minimize)?;
        if points_per_dim < 2 {
            return Err(BoError::InvalidSetting(
                "grid needs >= 2 points per dim".into(),
            ));
        }
        let total = (0..bounds.len()).try_fold(1usize, |acc, _| {
            acc.checked_mul(points_per_dim).filter(|t| *t <= 10_000_000)
        });
        let Some(total) = total else {
            return Err(BoError::InvalidSetting(
                "grid larger than 10^7 points".into(),
            ));
        };
        let mut order: Vec<usize> = (0..total).collect();
        if shuffle {
            let mut rng = Rng::new(seed);
            for i in (1..total).rev() {
                let j = rng.below(i + 1);
                order.swap(i, j);
            }
        }
        Ok(GridSearch {
            record,
            points_per_dim,
            order,
            next: 0,
        })
    }

    /// Number of grid points.
    pub fn size(&self) -> usize {
        self.order.len()
    }

    /// Grid point of linear index `idx`.
    pub fn point(&self, idx: usize) -> Vec<f64> {
        let r = &self.record;
        let mut rest = idx;
        let m = self.points_per_dim;
        r.lower
            .iter()
            .zip(&r.upper)
            .map(|(l, u)| {
                let k = rest % m;
                rest /= m;
                l + (u - l) * k as f64 / (m - 1) as f64
            })
            .collect()
    }
}

impl AskTell for GridSearch {
    /// Errors when the grid is exhausted.
    fn suggest(&mut self, q: usize) -> Result<Vec<Vec<f64>>> {
        if self.next + q > self.order.len() {
            return Err(BoError::NotEnoughData("grid exhausted".into()));
        }
        let pts = (0..q)
            .map(|k| self.point(self.order[self.next + k]))
            .collect();
        self.next += q;
        Ok(pts)
    }
    fn observe(&mut self, x: &[f64], y: f64) -> Result<()> {
        self.record.observe(x, y)
    }
    fn best(&self) -> Option<(Vec<f64>, f64)> {
        self.record.best.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_covers_all_points_once() {
        let mut g = GridSearch::new(&[(0.0, 1.0), (-1.0, 1.0)], 3, true, true, 5).unwrap();
        assert_eq!(g.size(), 9);
        let mut pts = g.suggest(9).unwrap();
        pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
        pts.dedup();
        assert_eq!(pts.len(), 9);
        assert!(pts.contains(&vec![0.5, 0.0]) && pts.contains(&vec![1.0, 1.0]));
        assert!(g.suggest(1).is_err());
        for p in &pts {
            g.observe(p, p[0] + p[1]).unwrap();
        }
        assert_eq!(g.best().unwrap().1, -1.0);
    }

    #[test]
    fn random_search_in_bounds_and_errors() {
        let mut r = RandomSearch::new(&[(2.0, 3.0)], false, 1).unwrap();
        for p in r.suggest(100).unwrap() {
            assert!(p[0] >= 2.0 && p[0] < 3.0);
        }
        assert!(r.observe(&[2.5], f64::NAN).is_err());
        assert!(r.observe(&[2.5, 1.0], 1.0).is_err());
        assert!(RandomSearch::new(&[], false, 1).is_err());
        assert!(RandomSearch::new(&[(1.0, 0.0)], false, 1).is_err());
        assert!(GridSearch::new(&[(0.0, 1.0); 8], 10, false, false, 0).is_err());
    }
}
