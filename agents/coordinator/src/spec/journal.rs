//! Opening a run in the journal: creating it, or continuing it with its state rebuilt from
//! the journal's trials and events.

use std::collections::BTreeMap;

use graspopt_bus::now_ms;
use graspopt_journal::{Journal, RunRow, StoredRunPhase, StoredTrialPhase, event_kind};
use graspopt_protocol::RunId;

use super::resume::read_spec;
use super::{RunSpec, param_names};
use crate::error::CoordinatorError;
use crate::state::{RunState, Trial, TrialPhase};

/// Opens (or creates) the run in the journal and rebuilds the state from it. Resuming uses
/// the recorded spec, with the budget raised if `spec` asks for more trials (pass the result
/// of [`super::reconcile`]). Not resuming, a recorded run that issued no trial is started afresh
/// with `spec`; one that has trials is an error.
pub fn open_run(
    journal: &mut Journal,
    run: &RunId,
    spec: &RunSpec,
    resume: bool,
) -> Result<(RunSpec, RunState), CoordinatorError> {
    let place = journal
        .path()
        .map_or_else(|| "the journal".to_string(), |p| p.display().to_string());
    let mut existing = journal.run(run.as_str())?;
    if existing.is_some() && !resume {
        // A start that stopped before its first trial (a wrong address, say) leaves its run
        // recorded with nothing in it: the same command starts it afresh.
        if journal.remove_unstarted_run(run.as_str())? {
            tracing::warn!(
                "coordinator: run {run:?} is in {place} without any trial (an earlier start issued none): starting it afresh"
            );
            existing = None;
        } else {
            let trials = journal.trials(run.as_str())?.len();
            return Err(CoordinatorError::RunExists {
                run: run.clone(),
                place,
                trials,
            });
        }
    }
    let spec = match existing {
        Some(record) => continue_run(journal, run, spec, &record)?,
        None => {
            if resume {
                // A supervised coordinator is restarted with the same command line, so
                // `--resume` also starts a run that was never recorded; it says so.
                tracing::warn!(
                    "coordinator: run {run:?} is not in {place} yet: --resume starts it"
                );
            }
            journal.create_run(&RunRow {
                run_id: run.as_str().to_string(),
                created_ms: now_ms(),
                config_json: serde_json::to_string(spec)?,
                param_names: param_names(spec),
                status: StoredRunPhase::Running,
            })?;
            spec.clone()
        }
    };
    let state = rebuild_state(journal, run, spec.trials)?;
    Ok((spec, state))
}

/// The spec of a recorded run being resumed: its record, with the budget raised (and
/// recorded) when `spec` asks for more trials; the run is marked running again.
fn continue_run(
    journal: &mut Journal,
    run: &RunId,
    spec: &RunSpec,
    record: &RunRow,
) -> Result<RunSpec, CoordinatorError> {
    let recorded = read_spec(run, record)?;
    // A resumed run keeps its record; only its budget may grow (see `reconcile`).
    let spec = if spec.trials > recorded.trials {
        let before = recorded.trials;
        let raised = RunSpec {
            trials: spec.trials,
            ..recorded
        };
        journal.set_run_config(run.as_str(), &serde_json::to_string(&raised)?)?;
        tracing::warn!(
            "coordinator: run {run:?}: budget raised from {before} to {} trials",
            raised.trials
        );
        raised
    } else {
        recorded
    };
    if record.status != StoredRunPhase::Running {
        journal.set_run_phase(run.as_str(), StoredRunPhase::Running, now_ms())?;
    }
    Ok(spec)
}

/// The state of the run as the journal records it, with a budget of `budget` trials.
fn rebuild_state(
    journal: &Journal,
    run: &RunId,
    budget: u64,
) -> Result<RunState, CoordinatorError> {
    let mut state = RunState::new(budget);
    let mut rows = journal.trials(run.as_str())?;
    // Who each attempt went to, so that late results of attempts issued before a restart
    // are still accepted.
    let mut issued: BTreeMap<u64, BTreeMap<u32, String>> = BTreeMap::new();
    // Where each completed trial's result stands in the journal's events.
    let mut completed_at: BTreeMap<u64, i64> = BTreeMap::new();
    for e in journal.events(run.as_str())? {
        if e.kind == event_kind::ISSUED || e.kind == event_kind::REISSUED {
            issued
                .entry(e.trial_id)
                .or_default()
                .insert(e.attempt, e.worker.clone());
        } else if e.kind == event_kind::RESULT {
            completed_at.entry(e.trial_id).or_insert(e.seq);
        }
    }
    // Observations in completion order, as the planner first saw them: the order the results
    // were recorded in. Their millisecond times tie when workers answer together, and a tie
    // broken otherwise (by trial id) gave the planner a history its saved engine was not
    // told, which it then rebuilt.
    rows.sort_by_key(|r| {
        (
            completed_at.get(&r.trial_id).copied().unwrap_or(i64::MAX),
            r.trial_id,
        )
    });
    for row in &rows {
        let phase = match row.state {
            StoredTrialPhase::Completed => TrialPhase::Completed {
                score: row.score.unwrap_or(f64::NAN),
            },
            StoredTrialPhase::Failed => TrialPhase::Failed {
                error: row.error.clone().unwrap_or_default(),
            },
            StoredTrialPhase::Running => TrialPhase::Queued {
                reason: Some("coordinator restarted".into()),
            },
        };
        let trial = Trial {
            params: row.params.clone(),
            attempts: row.attempts,
            issued_to: issued.remove(&row.trial_id).unwrap_or_default(),
            phase,
        };
        state.restore_trial(row.trial_id, trial);
        if let (StoredTrialPhase::Completed, Some(score)) = (&row.state, row.score) {
            state.observe(
                row.trial_id,
                row.params.clone(),
                score,
                row.metrics.as_ref().and_then(|m| m.flag("force_closure")),
                row.forces.as_ref(),
            );
        }
    }
    Ok(state)
}
