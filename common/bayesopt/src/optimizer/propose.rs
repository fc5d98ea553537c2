//! How the optimizer proposes its next points: the initial design, the model round, the
//! acquisition maximisers (EI, qEI) and the batch rules.

use super::*;

impl Optimizer {
    /// Propose `q` new points (distinct from each other, from the observations and from the
    /// pending points), taking into account the points still pending. The points are added
    /// to the pending list until observed.
    pub fn suggest(&mut self, q: usize) -> Result<Vec<Vec<f64>>> {
        if q == 0 {
            return Err(BoError::InvalidSetting("q must be >= 1".into()));
        }
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(q);
        let mut info = RoundInfo::default();
        self.restart_if_stagnant();
        self.initial_points(q, &mut out, &mut info);
        if out.len() < q {
            self.model_points(q, &mut out, &mut info)?;
        }
        self.pending.extend(out.iter().cloned());
        self.last_round = info;
        Ok(out)
    }

    /// A new epoch when the restart rule says this one stagnates: its best point becomes a
    /// tabu centre.
    pub(super) fn restart_if_stagnant(&mut self) {
        if let Some(rule) = self.settings.restart
            && self.epoch_stagnates(&rule)
        {
            let sign = if self.settings.minimize { -1.0 } else { 1.0 };
            let from = self.epoch_start;
            if let Some(i) = (from..self.ys.len())
                .max_by(|a, b| (sign * self.ys[*a]).total_cmp(&(sign * self.ys[*b])))
            {
                self.tabu.push(self.to_unit(&self.xs[i]));
            }
            self.epoch_start = self.ys.len();
        }
    }

    /// Adds to `out` (up to `q` points) the epoch's initial design (and random points while
    /// fewer than 2 observations exist).
    pub(super) fn initial_points(
        &mut self,
        q: usize,
        out: &mut Vec<Vec<f64>>,
        info: &mut RoundInfo,
    ) {
        let epoch_init = match self.settings.restart {
            Some(rule) if self.epoch_start > 0 => rule.init.max(2),
            _ => self.n_init(),
        };
        let epoch_len = self.xs.len() - self.epoch_start.min(self.xs.len());
        while out.len() < q
            && (epoch_len + self.pending.len() + out.len() < epoch_init || epoch_len < 2)
        {
            let u = if self.epoch_start == 0 {
                self.next_design_point(epoch_init, out)
            } else {
                self.rng.unit_point(self.dim())
            };
            out.push(self.unit_to_box(&u));
            info.random_points += 1;
        }
    }

    /// The next point (unit cube) of the first epoch's design. The design is drawn whole when
    /// first needed and handed out in order, skipping its points already observed, pending or
    /// in `out`: an engine rebuilt from a run's history continues the same design, and a
    /// design point whose trial failed (dropped from both) is not followed by a point still
    /// pending. Past its end: a random point.
    pub(super) fn next_design_point(&mut self, epoch_init: usize, out: &[Vec<f64>]) -> Vec<f64> {
        let d = self.dim();
        if self.design.is_empty() {
            let n = epoch_init.max(2);
            self.design = match self.settings.initial_design {
                InitialDesign::Random => (0..n).map(|_| self.rng.unit_point(d)).collect(),
                InitialDesign::MaximinLatinHypercube { candidates } => {
                    maximin_latin_hypercube(&mut self.rng, n, d, candidates)
                }
            };
        }
        let next = (self.design_next..self.design.len()).find(|&i| {
            let x = self.unit_to_box(&self.design[i]);
            !self
                .xs
                .iter()
                .chain(&self.pending)
                .chain(out)
                .any(|p| same_point(p, &x, &self.lower, &self.upper))
        });
        match next {
            Some(i) => {
                self.design_next = i + 1;
                self.design[i].clone()
            }
            None => self.rng.unit_point(d),
        }
    }

    /// Fills `out` up to `q` points from the model: EI maximisers (or qEI points), each
    /// conditioning the next through a lie or the joint posterior.
    pub(super) fn model_points(
        &mut self,
        q: usize,
        out: &mut Vec<Vec<f64>>,
        info: &mut RoundInfo,
    ) -> Result<()> {
        let data = self.standardised();
        let full = self.rounds.is_multiple_of(self.settings.full_refit_every);
        let gp = self.fit_model(&data, full)?;
        let xi = self.settings.xi.xi(gp.kernel().signal_variance);
        info.xi = Some(xi);
        let mut round = self.open_round(gp, &data, xi, out)?;
        while out.len() < q {
            let qei_point = round.qei.is_some() && !round.chosen.is_empty();
            let (u, ei) = self.propose_one(&mut round, qei_point, q, out.is_empty())?;
            let u = self.settle_point(&round, u, ei, qei_point, info);
            if info.best_ei.is_none() {
                info.best_ei = Some(ei);
                info.relative_ei = Some(if round.y_range > 0.0 {
                    ei / round.y_range
                } else {
                    f64::INFINITY
                });
            }
            if round.qei.is_some() {
                round.chosen.push(u.clone());
            } else {
                let lie = self.lie(&round.gp, &u, round.incumbent, round.y_mean, round.y_min);
                if out.len() + 1 < q {
                    round.incumbent = round.incumbent.max(lie);
                    round.gp.push(u.clone(), lie)?;
                }
            }
            round.taken.push(u.clone());
            out.push(self.unit_to_box(&u));
        }
        if let Some(rel) = info.relative_ei {
            if rel < self.settings.stop.relative_ei_threshold {
                self.low_ei_streak = self.low_ei_streak.saturating_add(1);
            } else {
                self.low_ei_streak = 0;
            }
        }
        self.rounds = self.rounds.saturating_add(1);
        Ok(())
    }

    /// A model-based round on `gp` fitted to `data`, with the pending points and those
    /// already in `out` entered: by lies into the GP, or (qEI) as chosen points that enter
    /// jointly through the GP's posterior (no fantasy values).
    pub(super) fn open_round(
        &self,
        gp: Gp,
        data: &Standardised,
        xi: f64,
        out: &[Vec<f64>],
    ) -> Result<Round> {
        let y_max = data.y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let y_min = data.y.iter().copied().fold(f64::INFINITY, f64::min);
        let fantasies: Vec<Vec<f64>> = self
            .pending
            .iter()
            .chain(out.iter())
            .map(|p| self.to_unit(p))
            .collect();
        let mut round = Round {
            gp,
            xi,
            incumbent: y_max,
            y_mean: data.y.iter().sum::<f64>() / data.y.len().max(1) as f64,
            y_min,
            // The range of the modelled outputs (standardised, after the output transform,
            // this epoch): without a transform, EI over the observed range of y; with one, a
            // few compressed misses do not inflate the range.
            y_range: y_max - y_min,
            taken: data.x.clone(),
            chosen: Vec::new(),
            capped: self.settings.model_cap.filter(|c| data.y.len() > c.size),
            qei: match self.settings.batch {
                BatchStrategy::Qei { samples } => Some(samples.max(1)),
                _ => None,
            },
            // qEI's base samples come from a generator of this round (the main stream is
            // left as it is).
            qei_rng: Rng::new(
                self.seed
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .wrapping_add(self.rounds as u64),
            ),
        };
        for u in fantasies {
            if round.qei.is_some() {
                round.chosen.push(u.clone());
                round.taken.push(u);
                continue;
            }
            let lie = self.lie(&round.gp, &u, round.incumbent, round.y_mean, y_min);
            round.incumbent = round.incumbent.max(lie);
            round.gp.push(u.clone(), lie)?;
            round.taken.push(u);
        }
        Ok(round)
    }

    /// The next maximiser of the round and its EI (or qEI gain, for a `qei_point`); `first`:
    /// the round's first point.
    pub(super) fn propose_one(
        &self,
        round: &mut Round,
        qei_point: bool,
        q: usize,
        first: bool,
    ) -> Result<(Vec<f64>, f64)> {
        match round.qei {
            Some(samples) if qei_point => {
                let target = round.incumbent + round.xi;
                let ctx = QeiContext::new(
                    &round.gp,
                    &round.chosen,
                    target,
                    samples,
                    &mut round.qei_rng,
                )?;
                self.maximize_qei(ctx)
            }
            _ => {
                // A qEI batch spreads its points itself: only a round of one point with
                // nothing pending is diversified.
                let alone = round.qei.is_none() || (q == 1 && self.pending.is_empty());
                let (gp, incumbent, xi) = (&round.gp, round.incumbent, round.xi);
                // The large-n mode's batch path: a point conditioned on others (pending, or
                // earlier in the round) gets the cap's smaller effort.
                let effort = match round.capped {
                    Some(cap) if !first || !self.pending.is_empty() => Effort {
                        evals_per_dim: cap.batch_evals_per_dim,
                        polish_starts: self.settings.polish_starts.min(1),
                    },
                    _ => Effort {
                        evals_per_dim: self.settings.direct_evals_per_dim,
                        polish_starts: self.settings.polish_starts,
                    },
                };
                self.ei_point(gp, incumbent, xi, round.y_min, alone && first, effort)
            }
        }
    }

    /// The point to propose for the maximiser `u` of EI `ei`: an exploration step when EI is
    /// below [`Settings::explore_below_ei`] (EI points only: a qEI gain is not an EI), a
    /// random point when `u` was already taken, else `u`.
    pub(super) fn settle_point(
        &mut self,
        round: &Round,
        u: Vec<f64>,
        ei: f64,
        qei_point: bool,
        info: &mut RoundInfo,
    ) -> Vec<f64> {
        let duplicate = round.taken.iter().any(|t| {
            t.iter()
                .zip(&u)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                < 1e-16
        });
        let explore = !qei_point && matches!(self.settings.explore_below_ei, Some(th) if ei < th);
        if explore {
            info.exploration_points += 1;
            self.exploration_point(&round.gp)
        } else if duplicate {
            self.rng.unit_point(self.dim())
        } else {
            u
        }
    }

    /// The EI (or UCB) maximiser on `gp` and its value. When `first` and this is a
    /// diversification round ([`Settings::diversify_every`]), the EI maximiser is assumed to be
    /// as bad as the worst observation (`y_min`, constant liar) and the next maximiser is
    /// returned instead, `diversify_depth` times.
    pub(super) fn ei_point(
        &self,
        gp: &Gp,
        incumbent: f64,
        xi: f64,
        y_min: f64,
        first: bool,
        effort: Effort,
    ) -> Result<(Vec<f64>, f64)> {
        let k = self.settings.diversify_every;
        let diversify = k > 0 && first && self.rounds % k == k - 1;
        let depth = self.settings.diversify_depth.max(1);
        let share = if diversify {
            1.0 / (1 + depth) as f64
        } else {
            1.0
        };
        // In a diversification round each maximisation keeps its kernel rows for the next
        // one, whose GP only has fantasy points appended (see `RowMemo`).
        let mut memo = diversify.then(RowMemo::default);
        let (mut u, mut ei) =
            self.maximize_acquisition(gp, incumbent, xi, (share, effort), None, memo.as_mut())?;
        if diversify {
            let mut g2 = gp.clone();
            for step in 0..depth {
                g2.push(u.clone(), y_min)?;
                let previous = memo.take();
                memo = (step + 1 < depth).then(RowMemo::default);
                let (u2, ei2) = self.maximize_acquisition(
                    &g2,
                    incumbent,
                    xi,
                    (share, effort),
                    previous.as_ref(),
                    memo.as_mut(),
                )?;
                u = u2;
                ei = ei.max(ei2);
            }
        }
        Ok((u, ei))
    }

    /// Space-filling exploration step: the random candidate (100 d uniform draws) with the
    /// largest posterior variance.
    pub(super) fn exploration_point(&mut self, gp: &Gp) -> Vec<f64> {
        let d = self.dim();
        let mut best = self.rng.unit_point(d);
        let mut best_var = gp.predict(&best).1;
        for _ in 1..100 * d {
            let c = self.rng.unit_point(d);
            let v = gp.predict(&c).1;
            if v > best_var {
                best_var = v;
                best = c;
            }
        }
        best
    }

    pub(super) fn lie(&self, gp: &Gp, u: &[f64], incumbent: f64, mean: f64, min: f64) -> f64 {
        match self.settings.batch {
            // Qei never lies (its points enter the joint posterior); the arm is for completeness.
            BatchStrategy::KrigingBeliever | BatchStrategy::Qei { .. } => gp.predict(u).0,
            BatchStrategy::ConstantLiarMin => min,
            BatchStrategy::ConstantLiarMean => mean,
            BatchStrategy::ConstantLiarMax => incumbent,
        }
    }

    /// Penalty (and its gradient, added to `g`) inside the balls around earlier epochs'
    /// incumbents: linear in the squared distance, steep enough to dominate the acquisition.
    pub(super) fn tabu_penalty(&self, u: &[f64], mut g: Option<&mut [f64]>) -> f64 {
        let d = self.dim();
        let radius = self
            .settings
            .restart
            .map_or(0.0, |r| r.tabu_radius * (d as f64).sqrt());
        let r2 = radius * radius;
        let mut p = 0.0;
        if r2 <= 0.0 {
            return p;
        }
        let k = 1e3 / r2;
        for c in &self.tabu {
            let d2: f64 = u.iter().zip(c).map(|(a, b)| (a - b) * (a - b)).sum();
            if d2 < r2 {
                p -= k * (r2 - d2);
                if let Some(g) = g.as_deref_mut() {
                    for ((gi, a), b) in g.iter_mut().zip(u).zip(c) {
                        *gi += 2.0 * k * (a - b);
                    }
                }
            }
        }
        p
    }

    /// Maximise the log qEI gain of `ctx` (plus the restart penalty) on the unit cube: DIRECT
    /// with the acquisition's budget, then (unless [`Settings::polish_starts`] is 0) an L-BFGS
    /// polish of DIRECT's best point with central finite-difference gradients and
    /// [`QEI_POLISH_ITERS`] iterations. Returns the point and its qEI gain (0 on the floor).
    pub(super) fn maximize_qei(&self, mut ctx: QeiContext<'_>) -> Result<(Vec<f64>, f64)> {
        let d = self.dim();
        let lo = vec![0.0; d];
        let hi = vec![1.0; d];
        let ds = DirectSettings {
            max_evals: (self.settings.direct_evals_per_dim * d).max(2 * d + 1),
            ..DirectSettings::default()
        };
        let res = direct::maximize(
            |u| ctx.log_gain(u) + self.tabu_penalty(u, None),
            &lo,
            &hi,
            &ds,
            1,
        )?;
        let (mut best_u, mut best_v) = (res.x, res.value);
        if self.settings.polish_starts > 0 {
            const H: f64 = 1e-6;
            let mut x = vec![0.0; d];
            let (u, v) = direct::polish(
                |u, g| {
                    x.copy_from_slice(u);
                    for i in 0..d {
                        let (a, b) = ((u[i] - H).max(0.0), (u[i] + H).min(1.0));
                        x[i] = b;
                        let fb = ctx.log_gain(&x);
                        x[i] = a;
                        let fa = ctx.log_gain(&x);
                        x[i] = u[i];
                        g[i] = if b > a && fa > LOG_EI_FLOOR && fb > LOG_EI_FLOOR {
                            (fb - fa) / (b - a)
                        } else {
                            0.0
                        };
                    }
                    ctx.log_gain(u) + self.tabu_penalty(u, Some(g))
                },
                &best_u,
                &lo,
                &hi,
                QEI_POLISH_ITERS,
            );
            if v > best_v && v.is_finite() {
                best_u = u;
                best_v = v;
            }
        }
        let gain = if best_v <= LOG_EI_FLOOR {
            0.0
        } else {
            ctx.log_gain(&best_u).exp()
        };
        Ok((best_u, gain))
    }

    /// Maximise the acquisition on the unit cube: DIRECT then L-BFGS polish from the best
    /// centres. Returns the point and its EI (standardised units; the UCB value for UCB).
    /// `reuse`: kernel rows kept by the previous maximisation on a GP that `gp` extends (see
    /// [`RowMemo`]); `record`: where to keep this one's.
    pub(super) fn maximize_acquisition(
        &self,
        gp: &Gp,
        incumbent: f64,
        xi: f64,
        (budget_share, effort): (f64, Effort),
        reuse: Option<&RowMemo>,
        mut record: Option<&mut RowMemo>,
    ) -> Result<(Vec<f64>, f64)> {
        let d = self.dim();
        let lo = vec![0.0; d];
        let hi = vec![1.0; d];
        let acq = self.settings.acquisition;
        let mut buffer = Vec::new();
        let (mut k_row, mut v_row) = (Vec::new(), Vec::new());
        if let Some(rec) = record.as_deref_mut() {
            rec.len = gp.len();
            rec.rows.clear();
        }
        let value = |u: &[f64]| -> f64 {
            let (m, v) = if reuse.is_none() && record.is_none() {
                gp.predict_with_buffer(u, &mut buffer)
            } else {
                let rows = (&mut k_row, &mut v_row);
                predict_with_memo(gp, u, reuse, record.as_deref_mut(), rows)
            };
            let a = match acq {
                AcquisitionKind::ExpectedImprovement => {
                    log_expected_improvement(m, v, incumbent, xi)
                }
                AcquisitionKind::Ucb { beta } => acquisition::ucb(m, v, beta),
            };
            a + self.tabu_penalty(u, None)
        };
        let ds = DirectSettings {
            max_evals: ((effort.evals_per_dim * d) as f64 * budget_share).max(2.0 * d as f64 + 1.0)
                as usize,
            ..DirectSettings::default()
        };
        let res = direct::maximize(value, &lo, &hi, &ds, effort.polish_starts.max(1))?;
        let (best_u, best_v) = self.polish_acquisition(
            gp,
            &res.top[..res.top.len().min(effort.polish_starts)],
            incumbent,
            xi,
            (res.x, res.value),
        );
        let (m, var) = gp.predict(&best_u);
        let ei = match acq {
            AcquisitionKind::ExpectedImprovement => {
                if best_v <= LOG_EI_FLOOR {
                    0.0
                } else {
                    expected_improvement(m, var, incumbent, xi)
                }
            }
            AcquisitionKind::Ucb { .. } => best_v,
        };
        Ok((best_u, ei))
    }

    /// `best` (DIRECT's maximum of the acquisition on `gp`), improved by an L-BFGS polish
    /// from each of the first [`Settings::polish_starts`] of DIRECT's `top` points.
    pub(super) fn polish_acquisition(
        &self,
        gp: &Gp,
        top: &[(Vec<f64>, f64)],
        incumbent: f64,
        xi: f64,
        best: (Vec<f64>, f64),
    ) -> (Vec<f64>, f64) {
        let (mut best_u, mut best_v) = best;
        if self.settings.polish_starts == 0 {
            return (best_u, best_v);
        }
        let d = self.dim();
        let (lo, hi) = (vec![0.0; d], vec![1.0; d]);
        let acq = self.settings.acquisition;
        let mut dm = vec![0.0; d];
        let mut dv = vec![0.0; d];
        for (start, _) in top.iter().take(self.settings.polish_starts) {
            let (u, v) = direct::polish(
                |u, g| {
                    let (m, var) = gp.predict_with_grad(u, &mut dm, &mut dv);
                    let a = match acq {
                        AcquisitionKind::ExpectedImprovement => {
                            acquisition::log_ei_with_grad(m, var, &dm, &dv, incumbent, xi, g)
                        }
                        AcquisitionKind::Ucb { beta } => {
                            acquisition::ucb_with_grad(m, var, &dm, &dv, beta, g)
                        }
                    };
                    a + self.tabu_penalty(u, Some(g))
                },
                start,
                &lo,
                &hi,
                self.settings.polish_iters,
            );
            if v > best_v && v.is_finite() {
                best_u = u;
                best_v = v;
            }
        }
        (best_u, best_v)
    }
}

/// The posterior at `u` on `gp` through the kernel rows `rows` (`k`, `L^{-1} k`): those of
/// the first conditioning points come from `reuse` when it kept them for `u`, and the full
/// rows are kept in `record`.
pub(super) fn predict_with_memo(
    gp: &Gp,
    u: &[f64],
    reuse: Option<&RowMemo>,
    record: Option<&mut RowMemo>,
    (k_row, v_row): (&mut Vec<f64>, &mut Vec<f64>),
) -> (f64, f64) {
    let key: Vec<u64> = u.iter().map(|c| c.to_bits()).collect();
    let mut from = 0;
    if let Some((len, row)) = reuse.and_then(|r| r.rows.get(&key).map(|w| (r.len, w))) {
        k_row.clear();
        k_row.extend_from_slice(&row[..len]);
        v_row.clear();
        v_row.extend_from_slice(&row[len..]);
        from = len;
    }
    let mv = gp.predict_extending(u, from, k_row, v_row);
    if let Some(rec) = record {
        let mut row = Vec::with_capacity(2 * k_row.len());
        row.extend_from_slice(k_row);
        row.extend_from_slice(v_row);
        rec.rows.insert(key, row);
    }
    mv
}

/// The work spent maximising one point's acquisition: DIRECT evaluations per dimension and
/// polish starts.
#[derive(Debug, Clone, Copy)]
pub(super) struct Effort {
    evals_per_dim: usize,
    polish_starts: usize,
}

/// One model-based round of [`Optimizer::suggest`] (standardised outputs, unit cube).
pub(super) struct Round {
    /// The model, with the lies of the points entered so far (not with qEI).
    gp: Gp,
    xi: f64,
    incumbent: f64,
    y_mean: f64,
    y_min: f64,
    /// The range of the modelled outputs, for the relative EI.
    y_range: f64,
    /// Observed, pending and proposed points: a maximiser among them is replaced.
    taken: Vec<Vec<f64>>,
    /// With qEI: the points pending or proposed, which enter the joint posterior.
    chosen: Vec<Vec<f64>>,
    /// With qEI: its number of base samples.
    qei: Option<usize>,
    /// The model cap, when this round's model is capped (the large-n mode).
    capped: Option<ModelCap>,
    qei_rng: Rng,
}

/// Kernel rows `k(u, x_i)` and `L^{-1} k` of the first `len` conditioning points at every
/// point `u` (keyed by its bits) where one DIRECT run evaluated the acquisition. The runs of a
/// diversification round maximise on the same GP with fantasy points appended, and DIRECT
/// revisits many of the same points (a third to a half of them): there only the rows of the
/// appended points are computed ([`Gp::predict_extending`], bit-identical to a full
/// prediction).
#[derive(Default)]
pub(super) struct RowMemo {
    len: usize,
    rows: HashMap<Vec<u64>, Vec<f64>>,
}
