//! What the monitor knows of the runs, and each run as text.

use std::collections::BTreeMap;
use std::time::Instant;

use graspopt_protocol::{RunPhase, RunStatus, describe_waits};

use graspopt_protocol::named_params;

/// What the monitor knows of one run.
#[derive(Debug, Clone, Default)]
pub struct RunView {
    pub status: Option<RunStatus>,
    pub updated: Option<Instant>,
    /// The run's coordinator holds a liveliness token.
    pub coordinator_alive: bool,
}

/// Everything on screen.
#[derive(Debug, Default)]
pub struct Monitor {
    pub runs: BTreeMap<String, RunView>,
    pub focus: usize,
}

impl Monitor {
    pub fn focused(&self) -> Option<(&String, &RunView)> {
        self.runs.iter().nth(self.focus_index())
    }

    /// The index of the focused run in [`Monitor::runs`].
    pub fn focus_index(&self) -> usize {
        self.focus.min(self.runs.len().saturating_sub(1))
    }

    pub fn next_run(&mut self) {
        if !self.runs.is_empty() {
            self.focus = (self.focus + 1) % self.runs.len();
        }
    }

    pub fn on_status(&mut self, status: RunStatus, at: Instant) {
        let view = self
            .runs
            .entry(status.run_id.as_str().to_string())
            .or_default();
        // Statuses may arrive out of order (a query's reply and the topic): keep the newest.
        if view
            .status
            .as_ref()
            .is_none_or(|s| s.stamp_ms <= status.stamp_ms)
        {
            view.status = Some(status);
            view.updated = Some(at);
        }
    }

    pub fn set_alive(&mut self, runs: &[String]) {
        for (name, view) in self.runs.iter_mut() {
            view.coordinator_alive = runs.contains(name);
        }
        for r in runs {
            self.runs.entry(r.clone()).or_default().coordinator_alive = true;
        }
    }

    /// The runs with a live coordinator and no status yet (to ask for their state).
    pub fn missing_states(&self) -> Vec<String> {
        self.runs
            .iter()
            .filter(|(_, v)| v.status.is_none() && v.coordinator_alive)
            .map(|(k, _)| k.clone())
            .collect()
    }
}

pub(crate) fn phase_name(p: RunPhase) -> &'static str {
    match p {
        RunPhase::Waiting => "waiting",
        RunPhase::Running => "running",
        RunPhase::Finished => "finished",
        RunPhase::Stopped => "stopped",
    }
}

/// The best-so-far history scaled to 0..=100 for the sparkline.
pub fn spark_data(history: &[f64]) -> Vec<u64> {
    let finite: Vec<f64> = history.iter().copied().filter(|v| v.is_finite()).collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    history
        .iter()
        .map(|v| {
            if !v.is_finite() || hi <= lo {
                if v.is_finite() { 100 } else { 0 }
            } else {
                (1.0 + 99.0 * (v - lo) / (hi - lo)).round() as u64
            }
        })
        .collect()
}

/// The text lines of one run (the text of [`crate::monitor::once`] and the dashboard's
/// panels).
pub fn run_lines(name: &str, view: &RunView, now: Instant) -> Vec<String> {
    let mut out = Vec::new();
    let age = view
        .updated
        .map(|t| format!("{:.1} s ago", now.duration_since(t).as_secs_f64()))
        .unwrap_or_else(|| "never".into());
    let coord = if view.coordinator_alive {
        "coordinator alive"
    } else {
        "coordinator gone"
    };
    let Some(s) = &view.status else {
        out.push(format!("run {name:?}: no status yet ({coord})"));
        return out;
    };
    out.push(format!(
        "run {name:?}  object {}  phase {}  updated {age}  ({coord})",
        s.object,
        phase_name(s.phase)
    ));
    out.push(format!(
        "trials: {} completed, {} running, {} failed, budget {}",
        s.completed, s.running, s.failed, s.budget
    ));
    if !s.waiting.is_empty() {
        out.push(format!(
            "waiting: {}",
            describe_waits(&s.waiting, s.stamp_ms)
        ));
    }
    match &s.best {
        Some(b) => {
            let params = named_params(&s.param_names, &b.params, ", ");
            let fc = match b.force_closure {
                Some(true) => ", force closure",
                Some(false) => ", no force closure",
                None => "",
            };
            out.push(format!(
                "best: trial {} score {} at {}{fc}",
                b.trial_id,
                graspopt_protocol::text::rounded(b.score),
                params
            ));
            if let Some(f) = &s.best_forces {
                out.push(format!("best's forces: {}", f.describe()));
            }
        }
        None => out.push("best: none yet".into()),
    }
    out.push(format!("workers alive: {}", s.workers.len()));
    for w in &s.workers {
        let t = w
            .trial
            .map(|t| format!("trial {t}"))
            .unwrap_or_else(|| "idle".into());
        out.push(format!("  {}@{}  {t}", w.id, w.host));
    }
    let e = &s.errors;
    out.push(format!(
        "errors: {} bad messages, {} unknown trials, {} not issued, {} duplicates, {} re-issued, {} failed",
        e.bad_messages, e.unknown_trial, e.not_issued, e.duplicates, e.reissued, e.failed
    ));
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use graspopt_protocol::{BestTrial, ErrorCounts, ForceAnalysis, RunId, WorkerStatus};

    /// A run "demo" on a mug, 60 trials, `completed` done, two workers, a best trial.
    pub(crate) fn status(completed: u64) -> RunStatus {
        RunStatus {
            run_id: RunId::new("demo").unwrap(),
            phase: RunPhase::Running,
            object: "mug".into(),
            param_names: vec!["approach".into(), "vertical".into()],
            budget: 60,
            completed,
            running: 1,
            failed: 0,
            best: Some(BestTrial {
                trial_id: 12,
                score: 0.2123,
                params: vec![-0.031, 0.0104],
                force_closure: Some(true),
            }),
            best_history: vec![-0.5, 0.1, 0.2123],
            workers: vec![
                WorkerStatus {
                    id: "hand-1".into(),
                    host: "lab".into(),
                    trial: Some(14),
                },
                WorkerStatus {
                    id: "hand-2".into(),
                    host: "lab".into(),
                    trial: None,
                },
            ],
            errors: ErrorCounts {
                duplicates: 2,
                ..Default::default()
            },
            stamp_ms: completed as i64,
            waiting: Vec::new(),
            best_forces: Some(ForceAnalysis {
                external: [0.0, 0.0, -4.905, 0.0, 0.0, 0.0],
                resisting_norm: Some(6.25),
                resisting_max: Some(3.5),
                net_wrench: None,
                slip_margins: Vec::new(),
                unavailable: None,
            }),
        }
    }

    #[test]
    fn sparkline_scales_the_history() {
        assert_eq!(spark_data(&[-1.0, 0.0, 1.0]), [1, 51, 100]);
        assert_eq!(spark_data(&[0.5, 0.5]), [100, 100]);
        assert!(spark_data(&[]).is_empty());
    }

    #[test]
    fn tab_cycles_through_runs() {
        let mut m = Monitor::default();
        m.set_alive(&["a".into(), "b".into()]);
        assert_eq!(m.focused().unwrap().0, "a");
        m.next_run();
        assert_eq!(m.focused().unwrap().0, "b");
        m.next_run();
        assert_eq!(m.focused().unwrap().0, "a");
        m.set_alive(&["b".into()]);
        assert!(!m.runs["a"].coordinator_alive && m.runs["b"].coordinator_alive);
        // Only a live run without a status is asked for its state.
        assert_eq!(m.missing_states(), ["b"]);
        m.on_status(status(1), Instant::now());
        m.set_alive(&["b".into(), "demo".into()]);
        assert_eq!(m.missing_states(), ["b"]);
    }
}
