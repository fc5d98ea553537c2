//! Resuming a run: its recorded spec and runs, the flags given again that contradict the
//! record, and the budget a resumed run may raise.

use graspopt_journal::{Journal, RunRow};
use graspopt_protocol::RunId;
use graspopt_sim::ParamSpec;

use super::{RunSpec, param_names};
use crate::error::CoordinatorError;

/// The ranges given for a run being resumed (`--range`) that contradict its record, each
/// described as the other flags' are: a range must be the recorded bounds of one of the
/// run's parameters.
pub fn range_conflicts(recorded: &RunSpec, ranges: &[ParamSpec]) -> Vec<String> {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9;
    let names: Vec<&str> = recorded.params.iter().map(|k| k.name()).collect();
    let mut out = Vec::new();
    for r in ranges {
        let Some(i) = recorded.params.iter().position(|k| *k == r.kind) else {
            out.push(format!(
                "--range {r} (the run's parameters are {})",
                names.join(", ")
            ));
            continue;
        };
        match recorded.bounds.as_ref().and_then(|b| b.get(i)) {
            None => out.push(format!(
                "--range {r} (the run has the simulator's default range of {})",
                r.kind
            )),
            Some(b) if !(same(b[0], r.lower) && same(b[1], r.upper)) => {
                let had = ParamSpec {
                    lower: b[0],
                    upper: b[1],
                    ..*r
                };
                out.push(format!("--range {r} (the run has {had})"));
            }
            Some(_) => {}
        }
    }
    out
}

/// The run's recorded spec in the journal at `path`, if the file and the run exist.
pub fn journaled_spec(
    path: &std::path::Path,
    run: &RunId,
) -> Result<Option<RunSpec>, CoordinatorError> {
    if !path.exists() {
        return Ok(None);
    }
    let journal = open_journal(path)?;
    let Some(record) = journal.run(run.as_str())? else {
        return Ok(None);
    };
    Ok(Some(read_spec(run, &record)?))
}

/// Opens the journal at `path`, the error naming it.
pub(crate) fn open_journal(path: &std::path::Path) -> Result<Journal, CoordinatorError> {
    Journal::open(path).map_err(|source| CoordinatorError::OpenJournal {
        path: path.to_path_buf(),
        source,
    })
}

/// The spec recorded with the run of `record`.
pub(super) fn read_spec(run: &RunId, record: &RunRow) -> Result<RunSpec, CoordinatorError> {
    serde_json::from_str::<RunSpec>(&record.config_json).map_err(|source| {
        CoordinatorError::UnreadableSpec {
            run: run.clone(),
            source,
        }
    })
}

/// The run ids the journal at `path` holds, oldest first (none if there is no such file).
pub fn journaled_runs(path: &std::path::Path) -> Result<Vec<String>, CoordinatorError> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let journal = open_journal(path)?;
    Ok(journal.runs()?.into_iter().map(|r| r.run_id).collect())
}

/// `"a", "b"`: run ids quoted, for messages.
pub fn quoted_runs(ids: &[String]) -> String {
    ids.iter()
        .map(|id| format!("{id:?}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The run a `--resume` without `--run` continues: the only run of the journal at `path`
/// (`None` when there is no such file or it holds no run). A journal of several runs is an
/// error that lists them.
pub fn sole_run(path: &std::path::Path) -> Result<Option<RunId>, CoordinatorError> {
    let runs = journaled_runs(path)?;
    match runs.as_slice() {
        [] => Ok(None),
        [one] => Ok(Some(RunId::new(one)?)),
        _ => Err(CoordinatorError::WhichRun {
            path: path.to_path_buf(),
            runs,
        }),
    }
}

/// Flags given on the command line that contradict the record of a run being resumed,
/// each described as `--flag given (the run has recorded)`.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Conflicts(pub Vec<String>);

impl Conflicts {
    /// Notes `--flag` (underscores written as dashes) if it was given (`explicit(flag)`)
    /// with a value other than the recorded one.
    pub fn check<T: PartialEq + std::fmt::Display>(
        &mut self,
        explicit: &dyn Fn(&str) -> bool,
        flag: &str,
        given: T,
        recorded: T,
    ) {
        if explicit(flag) && given != recorded {
            let flag = flag.replace('_', "-");
            self.0
                .push(format!("--{flag} {given} (the run has {recorded})"));
        }
    }
}

/// The flags given on the command line (`explicit(name)`: `--name` was given; `object`,
/// `hand`, `params`, `trials`, `seed`, `method`, `initial`) whose values in `given`
/// contradict the recorded spec of a run being resumed. A larger budget is not a
/// contradiction: resuming may raise it.
pub fn resume_conflicts(
    recorded: &RunSpec,
    given: &RunSpec,
    explicit: &dyn Fn(&str) -> bool,
) -> Conflicts {
    let mut c = Conflicts::default();
    c.check(explicit, "object", &given.object, &recorded.object);
    c.check(explicit, "hand", &given.hand, &recorded.hand);
    let params = |s: &RunSpec| param_names(s).join(",");
    c.check(explicit, "params", params(given), params(recorded));
    c.check(explicit, "seed", given.seed, recorded.seed);
    let method = |s: &RunSpec| format!("{:?}", s.method).to_lowercase();
    c.check(explicit, "method", method(given), method(recorded));
    let initial = |s: &RunSpec| {
        s.initial
            .map_or("the engine's default".to_string(), |n| n.to_string())
    };
    c.check(explicit, "initial", initial(given), initial(recorded));
    if explicit("trials") && given.trials < recorded.trials {
        c.0.push(format!(
            "--trials {} (the run has a budget of {}; resuming can raise it, not lower it)",
            given.trials, recorded.trials
        ));
    }
    c
}

impl Conflicts {
    /// The error for a resumed run whose flags contradict its record (`None`: none do).
    pub fn into_error(self, run: &RunId) -> Option<CoordinatorError> {
        (!self.0.is_empty()).then(|| CoordinatorError::Conflicts {
            run: run.clone(),
            conflicts: self.0,
        })
    }
}

/// The spec a resumed run continues with: the recorded one, with the budget raised when
/// `--trials` asks for more. Contradicting flags (see [`resume_conflicts`]) are an error
/// naming them, since the run's trials were made with the recorded values.
pub fn reconcile(
    run: &RunId,
    recorded: &RunSpec,
    given: &RunSpec,
    explicit: &dyn Fn(&str) -> bool,
) -> Result<RunSpec, CoordinatorError> {
    if let Some(e) = resume_conflicts(recorded, given, explicit).into_error(run) {
        return Err(e);
    }
    let mut spec = recorded.clone();
    if explicit("trials") {
        spec.trials = spec.trials.max(given.trials);
    }
    Ok(spec)
}
