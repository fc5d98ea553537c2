//! The planner agent: answers the coordinator's proposal requests with the Bayesian
//! optimization engine (`graspopt-bayesopt`, with `Settings::for_grasps`: the thesis's
//! settings with the misses' scores compressed) or random search.
//!
//! A request carries the whole history of the run (observations in completion order and the
//! trials pending), so the planner holds no state that matters: it keeps the engine of the
//! last request warm and, when the new history extends the old one, only tells it the new
//! observations; otherwise (a restart, another run) it rebuilds the engine from the history.
//! The same history and seed give the same proposals.
//!
//! [`Planner::propose`] is the logic (no network); [`run`] wires it to the bus.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

use std::sync::{Arc, Mutex};

use anyhow::Context;
use graspopt_bayesopt::baseline::{AskTell, RandomSearch};
use graspopt_bayesopt::optimizer::{Optimizer, Settings};
use graspopt_bus::Bus;
use graspopt_protocol::{
    AgentKind, Observation, PlannerMethod, RunId, SuggestReply, SuggestRequest,
};
use serde::{Deserialize, Serialize};

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

enum Engine {
    Bo(Box<Optimizer>),
    Random(RandomSearch),
}

struct Warm {
    run_id: RunId,
    method: PlannerMethod,
    bounds: Vec<[f64; 2]>,
    seed: u64,
    initial: Option<u32>,
    told: Vec<Observation>,
    engine: Engine,
}

/// Proposes trials; see the module documentation.
#[derive(Default)]
pub struct Planner {
    warm: Option<Warm>,
    /// Engines rebuilt from a history (restarts, other runs).
    pub rebuilds: u64,
}

impl Planner {
    fn engine_for(&mut self, req: &SuggestRequest) -> Result<&mut Warm, String> {
        let reusable = self.warm.as_ref().is_some_and(|w| {
            w.run_id == req.run_id
                && w.method == req.method
                && w.bounds == req.bounds
                && w.seed == req.seed
                && w.initial == req.initial
                && req.observations.len() >= w.told.len()
                && req.observations[..w.told.len()] == w.told[..]
        });
        if !reusable {
            let bounds: Vec<(f64, f64)> = req.bounds.iter().map(|b| (b[0], b[1])).collect();
            let engine = match req.method {
                PlannerMethod::Bo => {
                    let settings = Settings {
                        n_init: req.initial.map(|n| n as usize),
                        ..Settings::for_grasps()
                    };
                    Engine::Bo(Box::new(
                        Optimizer::new(&bounds, settings, req.seed).map_err(|e| e.to_string())?,
                    ))
                }
                PlannerMethod::Random => Engine::Random(
                    RandomSearch::new(&bounds, false, req.seed).map_err(|e| e.to_string())?,
                ),
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
        }
        self.warm
            .as_mut()
            .ok_or_else(|| "planner state missing".to_string())
    }

    /// Proposes `req.count` points given the request's history.
    pub fn propose(&mut self, req: &SuggestRequest) -> Result<Vec<Vec<f64>>, String> {
        let warm = self.engine_for(req)?;
        for o in &req.observations[warm.told.len()..] {
            let told = match &mut warm.engine {
                Engine::Bo(opt) => opt.observe(&o.x, o.y),
                Engine::Random(r) => r.observe(&o.x, o.y),
            };
            told.map_err(|e| format!("observation rejected: {e}"))?;
            warm.told.push(o.clone());
        }
        let count = req.count as usize;
        match &mut warm.engine {
            Engine::Bo(opt) => {
                opt.set_pending(req.pending.clone())
                    .map_err(|e| format!("pending point rejected: {e}"))?;
                opt.suggest(count).map_err(|e| e.to_string())
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
                r.suggest(count).map_err(|e| e.to_string())
            }
        }
    }
}

/// Answers proposal requests until the task is cancelled.
pub async fn run(bus: &Bus, run: &RunId, config: &PlannerConfig) -> anyhow::Result<()> {
    let server = bus.serve::<SuggestRequest>(&run.suggest_key()).await?;
    let _token = bus
        .declare_alive(run, AgentKind::Planner, &config.id)
        .await?;
    let planner = Arc::new(Mutex::new(Planner::default()));
    let mut bad = 0u64;
    while let Some(incoming) = server.recv().await {
        let req = match &incoming.request {
            Ok(r) if r.run_id == *run => r.clone(),
            Ok(r) => {
                bad += 1;
                tracing::warn!(
                    "planner {}: request of run {} refused ({bad} bad messages)",
                    config.id,
                    r.run_id
                );
                let _ = incoming
                    .reply_error(&format!("this planner serves run {run}, not {}", r.run_id))
                    .await;
                continue;
            }
            Err(e) => {
                bad += 1;
                tracing::warn!(
                    "planner {}: bad request ({bad} bad messages): {e}",
                    config.id
                );
                let _ = incoming.reply_error(&e.to_string()).await;
                continue;
            }
        };
        let p = planner.clone();
        let r2 = req.clone();
        let outcome = tokio::task::spawn_blocking(move || match p.lock() {
            Ok(mut planner) => planner.propose(&r2),
            Err(_) => Err("planner state poisoned".to_string()),
        })
        .await
        .context("planner: proposal thread panicked")?;
        let reply = match outcome {
            Ok(points) => SuggestReply {
                run_id: req.run_id.clone(),
                request_id: req.request_id,
                points,
                error: None,
            },
            Err(e) => {
                tracing::warn!("planner {}: cannot propose: {e}", config.id);
                SuggestReply {
                    run_id: req.run_id.clone(),
                    request_id: req.request_id,
                    points: Vec::new(),
                    error: Some(e),
                }
            }
        };
        if let Err(e) = incoming.reply(&reply).await {
            tracing::warn!("planner {}: cannot reply: {e}", config.id);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(e.contains("pending"), "{e}");
    }
}
