//! The run a coordinator started on its own serves (`graspopt agent coordinator`), and the
//! trial budget a run may have.

use graspopt_protocol::RunId;
use graspopt_sim::{Object, ParamSpec, TrialSpace};

use super::resume::{journaled_spec, range_conflicts, reconcile, resume_conflicts, sole_run};
use super::{RunSpec, bounds_of};
use crate::error::CoordinatorError;

/// The run a coordinator started on its own serves (`graspopt agent coordinator`): `run`,
/// or with `resume` and no run id given explicitly (`explicit("run")`), the only run of the
/// journal; its spec is `given`, or with `resume` the recorded one reconciled with `given`
/// (contrary explicit settings refused, `ranges` among them when `explicit("range")`). A run
/// not recorded yet is started, so that a supervised coordinator can be restarted with one
/// command line; it records the bounds of `object`'s space with `ranges` in place unless
/// `given` has bounds. The journal's folder is created.
///
/// The budget `trials` must be 1 to [`MAX_TRIALS`].
pub fn standalone_run(
    run: &str,
    config: &crate::CoordinatorConfig,
    given: RunSpec,
    object: &Object,
    ranges: &[ParamSpec],
    resume: bool,
    explicit: &dyn Fn(&str) -> bool,
) -> Result<(RunId, RunSpec), CoordinatorError> {
    check_trials(given.trials)?;
    let mut run_id = RunId::new(run)?;
    if resume
        && !explicit("run")
        && let Some(only) = sole_run(&config.journal_path(&run_id))?
    {
        run_id = only;
    }
    let journal = config.journal_path(&run_id);
    let recorded = if resume {
        journaled_spec(&journal, &run_id)?
    } else {
        None
    };
    let spec = match recorded {
        Some(recorded) => {
            let mut c = resume_conflicts(&recorded, &given, explicit);
            if explicit("range") {
                c.0.extend(range_conflicts(&recorded, ranges));
            }
            if let Some(e) = c.into_error(&run_id) {
                return Err(e);
            }
            reconcile(&run_id, &recorded, &given, explicit)?
        }
        None => RunSpec {
            bounds: match given.bounds {
                Some(b) => Some(b),
                None => Some(bounds_of(&TrialSpace::with_ranges(
                    object,
                    &given.params,
                    ranges,
                )?)),
            },
            ..given
        },
    };
    if let Some(dir) = journal.parent()
        && !dir.as_os_str().is_empty()
    {
        std::fs::create_dir_all(dir).map_err(|source| CoordinatorError::CreateFolder {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    Ok((run_id, spec))
}

/// The largest trial budget of a run: a billion trials, days of the fastest pipeline
/// measured (`graspopt bench coordinator`); larger numbers are typos, and trial ids are
/// SQLite integers.
pub const MAX_TRIALS: u64 = 1_000_000_000;

/// Refuses a trial budget of 0 or over [`MAX_TRIALS`], naming `--trials`.
pub fn check_trials(trials: u64) -> Result<(), CoordinatorError> {
    if !(1..=MAX_TRIALS).contains(&trials) {
        return Err(CoordinatorError::Trials(trials));
    }
    Ok(())
}
