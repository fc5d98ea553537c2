//! The planner agent: answers the coordinator's proposal requests with the Bayesian
//! optimization engine (`graspopt-bayesopt`, with `Settings::for_grasps`: the thesis's
//! settings with the misses' scores compressed) or random search.
//!
//! A request carries the whole history of the run (observations in completion order and the
//! trials pending), so the planner holds no state that matters: it keeps the engine of the
//! last request warm and, when the new history extends the old one, only tells it the new
//! observations. Each reply also carries the engine as it left it (`engine_state`), which
//! the coordinator keeps in its journal and sends back with every request: a planner without
//! the run's engine (restarted, or started for a resumed run), or whose last reply was lost
//! (its engine has moved on without the coordinator), continues from that state and
//! proposes exactly what the first planner would have. Without a usable state (none yet,
//! another version, a history that does not extend it) it rebuilds the engine from the
//! history: the same design, the same data, but a model fitted afresh, whose proposals
//! differ slightly from a warm engine's.
//!
//! [`Planner::answer`] is the logic (no network); [`run`] wires it to the bus, and
//! [`PlannerAgent`] is it as an [`Agent`].
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod bench;
mod engine;
mod error;

use std::sync::{Arc, Mutex};

use graspopt_bayesopt::baseline::{AskTell, RandomSearch};
use graspopt_bayesopt::optimizer::Optimizer;
use graspopt_bus::{Agent, Bus};
use graspopt_protocol::keys::SUGGEST;
use graspopt_protocol::{AgentKind, PlannerMethod, RunId, SuggestReply, SuggestRequest};
use serde::{Deserialize, Serialize};

use crate::engine::{Engine, Warm, bo_settings};
pub use crate::error::PlannerError;

/// Planner settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlannerConfig {
    pub id: String,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        PlannerConfig {
            id: "planner".into(),
        }
    }
}

/// The reply to `req` saying why there are no proposals.
pub fn failed_reply(req: &SuggestRequest, error: &PlannerError) -> SuggestReply {
    SuggestReply {
        run_id: req.run_id.clone(),
        request_id: req.request_id,
        points: Vec::new(),
        error: Some(error.to_string()),
        engine_state: None,
    }
}

/// Points proposed, and the engine state to reply with.
#[derive(Debug, Clone, PartialEq)]
pub struct Proposal {
    pub points: Vec<Vec<f64>>,
    /// See the module documentation; `None` if it could not be encoded, which only costs a
    /// later restart its exactness.
    pub engine_state: Option<Vec<u8>>,
}

/// Proposes trials; see the module documentation.
#[derive(Default)]
pub struct Planner {
    warm: Option<Warm>,
    /// The engine state of the last reply.
    last_saved: Option<Vec<u8>>,
    /// Engines rebuilt from a history (no usable saved state).
    pub rebuilds: u64,
    /// Engines continued from a request's `engine_state`.
    pub restores: u64,
}

impl Planner {
    /// The reply to `req` from the planner of run `serving`: the proposal, or a reply whose
    /// `error` says why there is none. A request of another run is refused (the error).
    pub fn answer(
        &mut self,
        serving: &RunId,
        req: &SuggestRequest,
    ) -> Result<SuggestReply, PlannerError> {
        if req.run_id != *serving {
            return Err(PlannerError::OtherRun {
                serving: serving.clone(),
                asked: req.run_id.clone(),
            });
        }
        Ok(match self.propose_and_save(req) {
            Ok(proposal) => SuggestReply {
                run_id: req.run_id.clone(),
                request_id: req.request_id,
                points: proposal.points,
                error: None,
                engine_state: proposal.engine_state,
            },
            Err(e) => failed_reply(req, &e),
        })
    }

    /// Makes `self.warm` the engine for `req`: the warm one if the request continues it and
    /// carries the state of this planner's last reply (a request carrying another state
    /// follows a reply that was lost, or another planner's: the warm engine has moved on
    /// without the coordinator), else the request's state if `use_state` and it is usable,
    /// else a new engine told nothing. Returns whether the engine was restored.
    fn engine_for(&mut self, req: &SuggestRequest, use_state: bool) -> Result<bool, PlannerError> {
        let in_step = req.engine_state.is_none() || req.engine_state == self.last_saved;
        let warm_fits = self.warm.as_ref().is_some_and(|w| w.continued_by(req));
        if warm_fits && (in_step || !use_state) {
            return Ok(false);
        }
        if use_state && let Some(bytes) = &req.engine_state {
            match Warm::restore(bytes, req) {
                Ok(warm) => {
                    self.warm = Some(warm);
                    self.restores += 1;
                    return Ok(true);
                }
                Err(why) => tracing::warn!(
                    "planner: run {:?}: the saved engine state is not used ({why}): \
                     rebuilding the engine from the run's history",
                    req.run_id
                ),
            }
        }
        let bounds: Vec<(f64, f64)> = req.bounds.iter().map(|b| (b[0], b[1])).collect();
        let engine = match req.method {
            PlannerMethod::Bo => Engine::Bo(Box::new(Optimizer::new(
                &bounds,
                bo_settings(req),
                req.seed,
            )?)),
            PlannerMethod::Random => Engine::Random(RandomSearch::new(&bounds, false, req.seed)?),
        };
        self.rebuilds += 1;
        self.warm = Some(Warm {
            run_id: req.run_id.clone(),
            method: req.method,
            bounds: req.bounds.clone(),
            seed: req.seed,
            initial: req.initial,
            told: Vec::new(),
            engine,
        });
        Ok(false)
    }

    /// Proposes `req.count` points given the request's history, with the engine state to
    /// reply with.
    pub fn propose_and_save(&mut self, req: &SuggestRequest) -> Result<Proposal, PlannerError> {
        let points = self.propose(req)?;
        let engine_state = match self.warm.as_ref().map(Warm::save) {
            Some(Ok(bytes)) => Some(bytes),
            Some(Err(e)) => {
                tracing::warn!("planner: run {:?}: {e}", req.run_id);
                None
            }
            None => None,
        };
        self.last_saved.clone_from(&engine_state);
        Ok(Proposal {
            points,
            engine_state,
        })
    }

    /// Proposes `req.count` points given the request's history. An engine restored from
    /// the request's state that fails is dropped for one rebuilt from the history.
    pub fn propose(&mut self, req: &SuggestRequest) -> Result<Vec<Vec<f64>>, PlannerError> {
        let restored = self.engine_for(req, true)?;
        match self.propose_with_warm(req) {
            Err(e) if restored => {
                tracing::warn!(
                    "planner: run {:?}: the engine restored from the saved state fails ({e}): \
                     rebuilding it from the run's history",
                    req.run_id
                );
                self.warm = None;
                self.engine_for(req, false)?;
                self.propose_with_warm(req)
            }
            outcome => outcome,
        }
    }

    fn propose_with_warm(&mut self, req: &SuggestRequest) -> Result<Vec<Vec<f64>>, PlannerError> {
        let warm = self.warm.as_mut().ok_or(PlannerError::Missing)?;
        for o in &req.observations[warm.told.len()..] {
            let told = match &mut warm.engine {
                Engine::Bo(opt) => opt.observe(&o.x, o.y),
                Engine::Random(r) => r.observe(&o.x, o.y),
            };
            told.map_err(PlannerError::Observation)?;
            warm.told.push(o.clone());
        }
        let count = req.count as usize;
        match &mut warm.engine {
            Engine::Bo(opt) => {
                opt.set_pending(req.pending.clone())
                    .map_err(PlannerError::Pending)?;
                Ok(opt.suggest(count)?)
            }
            Engine::Random(r) => {
                // A rebuilt search continues the stream after the points already issued.
                let known: Vec<&[f64]> = req
                    .observations
                    .iter()
                    .map(|o| o.x.as_slice())
                    .chain(req.pending.iter().map(Vec::as_slice))
                    .collect();
                r.resume_after(&known);
                Ok(r.suggest(count)?)
            }
        }
    }
}

/// Answers proposal requests until the task is cancelled.
pub async fn run(bus: &Bus, run: &RunId, config: &PlannerConfig) -> Result<(), PlannerError> {
    let server = bus.serve(&SUGGEST.key(run)).await?;
    let _token = bus
        .declare_alive(run, AgentKind::Planner, &config.id)
        .await?;
    let planner = Arc::new(Mutex::new(Planner::default()));
    let mut bad = 0u64;
    let id = &config.id;
    while let Some(incoming) = server.recv().await {
        let req = match &incoming.request {
            Ok(r) => r.clone(),
            Err(e) => {
                bad += 1;
                tracing::warn!("planner {id}: bad request ({bad} bad messages): {e}");
                let _ = incoming.reply_error(&e.to_string()).await;
                continue;
            }
        };
        let (p, serving) = (planner.clone(), run.clone());
        let reply = tokio::task::spawn_blocking(move || match p.lock() {
            Ok(mut planner) => planner.answer(&serving, &req),
            Err(_) => Ok(failed_reply(&req, &PlannerError::Poisoned)),
        })
        .await
        .map_err(PlannerError::Panicked)?;
        let reply = match reply {
            Ok(reply) => reply,
            Err(e) => {
                bad += 1;
                tracing::warn!("planner {id}: request refused: {e} ({bad} bad messages)");
                let _ = incoming.reply_error(&e.to_string()).await;
                continue;
            }
        };
        if let Some(e) = &reply.error {
            tracing::warn!("planner {id}: cannot propose: {e}");
        }
        if let Err(e) = incoming.reply(&reply).await {
            tracing::warn!("planner {id}: cannot reply: {e}");
        }
    }
    Ok(())
}

/// The planner agent (`graspopt agent planner`).
pub struct PlannerAgent;

impl Agent for PlannerAgent {
    const KIND: AgentKind = AgentKind::Planner;
    const ABOUT: &'static str = "Proposes trials";
    type Config = PlannerConfig;
    type Output = ();
    type Error = PlannerError;

    fn id(config: &mut PlannerConfig) -> &mut String {
        &mut config.id
    }

    fn validate(_: &PlannerConfig) -> Result<(), PlannerError> {
        Ok(())
    }

    async fn run(
        &self,
        bus: &Bus,
        run_id: &RunId,
        config: &PlannerConfig,
        stop: impl Future<Output = ()> + Send,
    ) -> Result<(), PlannerError> {
        graspopt_bus::agent::until(run(bus, run_id, config), stop).await
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{FNV_OFFSET, STATE_FORMAT, fnv, state_header};
    use graspopt_bayesopt::optimizer::Settings;
    use graspopt_protocol::Observation;

    fn request(
        observations: Vec<Observation>,
        pending: Vec<Vec<f64>>,
        count: u32,
    ) -> SuggestRequest {
        SuggestRequest {
            run_id: RunId::new("r").unwrap(),
            request_id: 1,
            method: PlannerMethod::Bo,
            bounds: vec![[0.0, 1.0], [-1.0, 1.0]],
            seed: 3,
            initial: Some(3),
            observations,
            pending,
            count,
            engine_state: None,
        }
    }

    fn f(x: &[f64]) -> f64 {
        -(x[0] - 0.3).powi(2) - (x[1] - 0.2).powi(2)
    }

    #[test]
    fn a_restarted_planner_continues_the_design_and_rebuilds_deterministically() {
        let mut warm = Planner::default();
        let mut history: Vec<Observation> = Vec::new();
        for _ in 0..8 {
            let points = warm.propose(&request(history.clone(), vec![], 1)).unwrap();
            assert_eq!(points.len(), 1);
            history.push(Observation {
                x: points[0].clone(),
                y: f(&points[0]),
            });
        }
        assert_eq!(warm.rebuilds, 1);
        // A planner restarted inside the initial design (3 points) continues that design:
        // it proposes the warm planner's third point, not the first one again.
        let mut restarted = Planner::default();
        let third = restarted
            .propose(&request(history[..2].to_vec(), vec![], 1))
            .unwrap();
        assert_eq!(third, vec![history[2].x.clone()]);
        // Restarted planners given the same history propose the same points.
        let mut cold = Planner::default();
        let replay = cold.propose(&request(history.clone(), vec![], 2)).unwrap();
        assert_eq!(replay.len(), 2);
        let mut again = Planner::default();
        assert_eq!(
            again.propose(&request(history.clone(), vec![], 2)).unwrap(),
            replay
        );
        // Different history: rebuild.
        let mut other = history.clone();
        other[0].y += 1.0;
        warm.propose(&request(other, vec![], 1)).unwrap();
        assert_eq!(warm.rebuilds, 2);
    }

    /// Runs `steps` proposals of one point with a warm planner; at each step a planner that
    /// never saw the run, given the previous reply's engine state, must propose the same
    /// point and leave the same state. Returns whether a planner given only the history
    /// ever proposed something else.
    fn restarted_from_the_state_continue_exactly(method: PlannerMethod, steps: usize) -> bool {
        let mut warm = Planner::default();
        let mut history: Vec<Observation> = Vec::new();
        let mut state: Option<Vec<u8>> = None;
        let mut rebuilt_differs = false;
        for step in 0..steps {
            let req = SuggestRequest {
                method,
                engine_state: state.clone(),
                // One trial pending from time to time, as with a second worker.
                pending: if step % 3 == 2 {
                    vec![vec![0.9, -0.9]]
                } else {
                    vec![]
                },
                ..request(history.clone(), vec![], 1)
            };
            let Proposal {
                points,
                engine_state: saved,
            } = warm.propose_and_save(&req).unwrap();
            assert!(saved.is_some());
            let mut restarted = Planner::default();
            let again = restarted.propose_and_save(&req).unwrap();
            assert_eq!(again.points, points, "step {step}");
            assert_eq!(again.engine_state, saved, "step {step}");
            let from_state = u64::from(state.is_some());
            assert_eq!(
                (restarted.restores, restarted.rebuilds),
                (from_state, 1 - from_state)
            );
            let mut rebuilt = Planner::default();
            let without = SuggestRequest {
                engine_state: None,
                ..req.clone()
            };
            rebuilt_differs |= rebuilt.propose(&without).unwrap() != points;
            state = saved;
            history.push(Observation {
                y: f(&points[0]),
                x: points[0].clone(),
            });
        }
        assert_eq!((warm.rebuilds, warm.restores), (1, 0));
        rebuilt_differs
    }

    #[test]
    fn a_planner_given_the_saved_engine_state_continues_exactly() {
        // Past the 3-point design: 13 model-based proposals.
        let rebuilt_differs = restarted_from_the_state_continue_exactly(PlannerMethod::Bo, 16);
        // Why the state is kept: an engine rebuilt from the history fits its model afresh
        // (the warm one starts each fit from the last) and proposes other points.
        assert!(rebuilt_differs);
        restarted_from_the_state_continue_exactly(PlannerMethod::Random, 6);
    }

    /// Past the engine's model cap (the large-n mode), with a batch of 16 and 16 trials
    /// pending: the points are in the box and new, and a restarted planner given the state
    /// continues exactly (the capped model's subset draws nothing).
    #[test]
    fn past_the_model_cap_batches_are_valid_and_continue_exactly_from_the_state() {
        use graspopt_bayesopt::GRASP_MODEL_CAP;
        let mut rng = graspopt_bayesopt::rng::Rng::new(8);
        let mut point = || vec![rng.uniform(), 2.0 * rng.uniform() - 1.0];
        let mut history: Vec<Observation> = (0..GRASP_MODEL_CAP + 40)
            .map(|_| {
                let x = point();
                Observation { y: f(&x), x }
            })
            .collect();
        let mut pending: Vec<Vec<f64>> = (0..16).map(|_| point()).collect();
        let mut warm = Planner::default();
        let mut state = None;
        for round in 0..3 {
            let req = SuggestRequest {
                engine_state: state.clone(),
                ..request(history.clone(), pending.clone(), 16)
            };
            let proposal = warm.propose_and_save(&req).unwrap();
            assert_eq!(proposal.points.len(), 16);
            for (i, p) in proposal.points.iter().enumerate() {
                assert!((0.0..=1.0).contains(&p[0]) && (-1.0..=1.0).contains(&p[1]));
                let known = history
                    .iter()
                    .map(|o| &o.x)
                    .chain(&pending)
                    .chain(&proposal.points[..i]);
                for q in known {
                    assert!(
                        (p[0] - q[0]).abs() + (p[1] - q[1]).abs() > 1e-9,
                        "round {round}"
                    );
                }
            }
            let mut restarted = Planner::default();
            assert_eq!(restarted.propose_and_save(&req).unwrap(), proposal);
            state = proposal.engine_state;
            history.extend(pending.drain(..).map(|x| Observation { y: f(&x), x }));
            pending = proposal.points;
        }
        // The best point so far is near the optimum (0.3, 0.2).
        let best = history
            .iter()
            .map(|o| o.y)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(best > -1e-3, "{best}");
    }

    /// A warm planner after `n` proposals: its history and the state of its last reply.
    fn after(n: usize) -> (Planner, Vec<Observation>, Vec<u8>) {
        let mut warm = Planner::default();
        let mut history: Vec<Observation> = Vec::new();
        let mut state = None;
        for _ in 0..n {
            let Proposal {
                points,
                engine_state,
            } = warm
                .propose_and_save(&request(history.clone(), vec![], 1))
                .unwrap();
            state = engine_state;
            history.push(Observation {
                y: f(&points[0]),
                x: points[0].clone(),
            });
        }
        (warm, history, state.unwrap())
    }

    /// `engine` saved as the state of a run with this history.
    fn forge(engine: Engine, method: PlannerMethod, history: &[Observation]) -> Vec<u8> {
        let req = request(history.to_vec(), vec![], 1);
        Warm {
            run_id: req.run_id,
            method,
            bounds: req.bounds,
            seed: req.seed,
            initial: req.initial,
            told: history.to_vec(),
            engine,
        }
        .save()
        .unwrap()
    }

    /// A BO engine as the planner builds it, told `history` (with `y` changed by `shift`).
    fn told(history: &[Observation], settings: Settings, shift: f64) -> Engine {
        let req = request(vec![], vec![], 1);
        let bounds: Vec<(f64, f64)> = req.bounds.iter().map(|b| (b[0], b[1])).collect();
        let mut opt = Optimizer::new(&bounds, settings, req.seed).unwrap();
        for o in history {
            opt.observe(&o.x, o.y + shift).unwrap();
        }
        Engine::Bo(Box::new(opt))
    }

    /// Unusable engine states for a run with `history` whose good state is `good`: what is
    /// wrong, the state, the request's history and seed.
    fn unusable_states(
        history: &[Observation],
        good: &[u8],
    ) -> Vec<(&'static str, Vec<u8>, Vec<Observation>, u64)> {
        let (history, good) = (history.to_vec(), good.to_vec());
        let mut flipped = good.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 0x55;
        let mut other_version = good.clone();
        other_version[state_header().len() - 2] ^= 1;
        let mut changed_history = history.clone();
        changed_history[1].y += 1e-9;
        let defaults = bo_settings(&request(vec![], vec![], 1));
        let other_settings = Settings {
            direct_evals_per_dim: 1_000_000_000,
            ..defaults.clone()
        };
        let random = RandomSearch::new(&[(0.0, 1.0), (-1.0, 1.0)], false, 3).unwrap();
        let cases: Vec<(&str, Vec<u8>, Vec<Observation>, u64)> = vec![
            ("garbage", vec![7; 40], history.clone(), 3),
            ("empty", Vec::new(), history.clone(), 3),
            (
                "truncated",
                good[..good.len() / 2].to_vec(),
                history.clone(),
                3,
            ),
            (
                "trailing bytes",
                [good.clone(), vec![0]].concat(),
                history.clone(),
                3,
            ),
            ("flipped byte", flipped, history.clone(), 3),
            ("other version", other_version, history.clone(), 3),
            ("another seed", good.clone(), history.clone(), 4),
            ("another history", good.clone(), changed_history, 3),
            ("shorter history", good.clone(), history[..3].to_vec(), 3),
            (
                "other settings",
                forge(
                    told(&history, other_settings, 0.0),
                    PlannerMethod::Bo,
                    &history,
                ),
                history.clone(),
                3,
            ),
            (
                "engine told other values",
                forge(
                    told(&history, defaults.clone(), 1.0),
                    PlannerMethod::Bo,
                    &history,
                ),
                history.clone(),
                3,
            ),
            (
                "engine of another method",
                forge(Engine::Random(random), PlannerMethod::Bo, &history),
                history.clone(),
                3,
            ),
        ];
        cases
    }

    #[test]
    fn an_unusable_engine_state_is_passed_over_for_the_history() {
        let (mut warm, history, good) = after(6);
        for (what, bytes, observations, seed) in unusable_states(&history, &good) {
            let req = SuggestRequest {
                seed,
                engine_state: Some(bytes),
                ..request(observations.clone(), vec![], 1)
            };
            let mut p = Planner::default();
            let points = p.propose(&req).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!((p.restores, p.rebuilds), (0, 1), "{what}");
            let rebuilt = Planner::default()
                .propose(&SuggestRequest {
                    engine_state: None,
                    ..req.clone()
                })
                .unwrap();
            assert_eq!(points, rebuilt, "{what}");
        }
        // The intact state is used: the next point of the uninterrupted planner.
        let req = SuggestRequest {
            engine_state: Some(good),
            ..request(history.clone(), vec![], 1)
        };
        let mut p = Planner::default();
        assert_eq!(p.propose(&req).unwrap(), warm.propose(&req).unwrap());
        assert_eq!((p.restores, p.rebuilds), (1, 0));
    }

    #[test]
    fn after_a_lost_reply_the_planner_follows_the_coordinators_state() {
        // Two identical warm planners; each answers a request whose reply the coordinator
        // never gets (its query timed out): their engines move on without it.
        let (mut warm, history, state) = after(6);
        let (mut unaware, _, _) = after(6);
        for p in [&mut warm, &mut unaware] {
            p.propose_and_save(&request(history.clone(), vec![], 1))
                .unwrap();
        }
        // Meanwhile a result came in; the coordinator asks with the state it has, the one
        // before the lost reply.
        let mut longer = history.clone();
        let x = vec![0.5, 0.5];
        longer.push(Observation { y: f(&x), x });
        let req = SuggestRequest {
            engine_state: Some(state),
            ..request(longer.clone(), vec![], 1)
        };
        let followed = warm.propose_and_save(&req).unwrap();
        assert_eq!((warm.restores, warm.rebuilds), (1, 1));
        // What a planner started now (or any planner restarted later) proposes.
        let mut fresh = Planner::default();
        assert_eq!(followed, fresh.propose_and_save(&req).unwrap());
        // Kept warm regardless, the engine would propose something else.
        let without = SuggestRequest {
            engine_state: None,
            ..req.clone()
        };
        assert_ne!(
            unaware.propose_and_save(&without).unwrap().points,
            followed.points
        );
        // From there on the warm planner is in step with the coordinator again.
        let mut next_history = longer;
        next_history.push(Observation {
            y: f(&followed.points[0]),
            x: followed.points[0].clone(),
        });
        let next = SuggestRequest {
            engine_state: followed.engine_state.clone(),
            ..request(next_history, vec![], 1)
        };
        assert_eq!(
            warm.propose_and_save(&next).unwrap(),
            fresh.propose_and_save(&next).unwrap()
        );
        assert_eq!((warm.restores, fresh.restores), (1, 1));
    }

    /// The layout the format number stands for: a fresh engine of each kind, encoded. When
    /// this fails, the engines changed shape: bump `STATE_FORMAT`, then update the digests.
    #[test]
    fn the_saved_engine_layout_is_pinned() {
        let req = request(vec![], vec![], 1);
        let bounds: Vec<(f64, f64)> = req.bounds.iter().map(|b| (b[0], b[1])).collect();
        let bo = Engine::Bo(Box::new(
            Optimizer::new(&bounds, bo_settings(&req), 3).unwrap(),
        ));
        let random = Engine::Random(RandomSearch::new(&bounds, false, 3).unwrap());
        let body = |e: Engine, m| {
            let bytes = forge(e, m, &[]);
            fnv(FNV_OFFSET, &bytes[state_header().len() + 8..])
        };
        assert_eq!(
            (
                STATE_FORMAT,
                body(bo, PlannerMethod::Bo),
                body(random, PlannerMethod::Random)
            ),
            (2, 10576826521970506532, 17208041730547130713)
        );
    }

    #[test]
    fn a_restarted_random_search_continues_its_stream() {
        let random = |observations: Vec<Observation>, pending: Vec<Vec<f64>>| SuggestRequest {
            method: PlannerMethod::Random,
            ..request(observations, pending, 1)
        };
        let mut warm = Planner::default();
        let mut history: Vec<Observation> = Vec::new();
        for _ in 0..4 {
            let x = warm
                .propose(&random(history.clone(), vec![]))
                .unwrap()
                .remove(0);
            history.push(Observation { y: f(&x), x });
        }
        // Restarted after two results with the third trial still pending: the fourth point.
        let mut restarted = Planner::default();
        let next = restarted
            .propose(&random(history[..2].to_vec(), vec![history[2].x.clone()]))
            .unwrap();
        assert_eq!(next, vec![history[3].x.clone()]);
        // The second trial failed (it left the history): still the fourth point, not the
        // pending third one.
        let mut restarted = Planner::default();
        let next = restarted
            .propose(&random(history[..1].to_vec(), vec![history[2].x.clone()]))
            .unwrap();
        assert_eq!(next, vec![history[3].x.clone()]);
    }

    #[test]
    fn pending_points_are_avoided_and_bad_ones_refused() {
        let mut p = Planner::default();
        let history: Vec<Observation> = [[0.1, 0.1], [0.9, -0.5], [0.5, 0.5], [0.2, 0.9]]
            .iter()
            .map(|x| Observation {
                x: x.to_vec(),
                y: f(x),
            })
            .collect();
        let pts = p
            .propose(&request(history.clone(), vec![vec![0.3, 0.2]], 3))
            .unwrap();
        assert_eq!(pts.len(), 3);
        for q in &pts {
            assert!((q[0] - 0.3).abs() + (q[1] - 0.2).abs() > 1e-9);
        }
        let e = p
            .propose(&request(history, vec![vec![5.0, 0.0]], 1))
            .unwrap_err();
        assert!(e.to_string().contains("pending"), "{e}");
    }
}
