//! The coordinator's error type. The messages are the ones users see (tests and
//! docs/troubleshooting.md quote them). Where a message wraps a cause, the cause is the
//! error's `source()` and not part of the message, so a chain printed with `{:#}` says each
//! once; the errors of other crates the coordinator only passes on are transparent.

use std::path::PathBuf;

use graspopt_bus::BusError;
use graspopt_journal::JournalError;
use graspopt_protocol::RunId;
use graspopt_protocol::keys::KeyError;
use graspopt_sim::SimError;

use crate::MAX_WAIT_MS;
use crate::spec::MAX_TRIALS;

/// Everything that stops a coordinator or refuses a run.
#[derive(Debug, thiserror::Error)]
pub enum CoordinatorError {
    /// A lease or planner timeout the coordinator cannot keep (see
    /// [`crate::CoordinatorConfig::validate`]).
    #[error("{name} is {value}: it must be between 1 and {MAX_WAIT_MS} (a week)")]
    Wait { name: &'static str, value: u64 },
    /// The coordinator's settings were refused (the wrapped error says which and why).
    #[error("coordinator settings: {0}")]
    Settings(Box<CoordinatorError>),
    /// A trial budget of 0 or over [`MAX_TRIALS`].
    #[error("--trials is {0}: it must be between 1 and {MAX_TRIALS}")]
    Trials(u64),
    #[error("cannot open the journal {}", path.display())]
    OpenJournal {
        path: PathBuf,
        #[source]
        source: JournalError,
    },
    /// A batch of journal writes could not be committed.
    #[error("the journal could not commit")]
    Commit(#[source] JournalError),
    #[error(transparent)]
    Journal(#[from] JournalError),
    /// The run spec recorded in the journal does not parse.
    #[error("run {run:?}: journal holds an unreadable run spec")]
    UnreadableSpec {
        run: RunId,
        #[source]
        source: serde_json::Error,
    },
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A new run whose id the journal already has, with trials.
    #[error(
        "run {run:?} already exists in {place} with {trials} trial{}: resume it (--resume; for a launched run, graspopt launch --resume FILE) or choose another run id",
        if *trials == 1 { "" } else { "s" }
    )]
    RunExists {
        run: RunId,
        place: String,
        trials: usize,
    },
    /// `--resume` without `--run` on a journal of several runs.
    #[error(
        "the journal {} holds {} runs ({}): say which to resume with --run",
        path.display(),
        runs.len(),
        crate::spec::quoted_runs(runs)
    )]
    WhichRun { path: PathBuf, runs: Vec<String> },
    /// Flags of a resumed run that contradict its record, each described as
    /// `--flag given (the run has recorded)`.
    #[error(
        "run {run:?} was recorded with other settings: {}. Drop these flags to resume it, or start a new run (another --run id)",
        conflicts.join("; ")
    )]
    Conflicts { run: RunId, conflicts: Vec<String> },
    #[error("cannot create the folder {}", path.display())]
    CreateFolder {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Perception sees another object than the run is about.
    #[error("perception sees {seen:?}, the run is about {expected:?}")]
    WrongObject { seen: String, expected: String },
    /// The object estimate is not an object the simulator can build.
    #[error("coordinator: the object estimate")]
    Estimate(#[source] SimError),
    /// The run spec does not make a trial space on the object.
    #[error("run spec")]
    Spec(#[source] SimError),
    #[error("run spec: no bounds for parameter {0}")]
    NoBounds(usize),
    /// A queued trial's parameters give no palm pose.
    #[error("trial {trial}: palm pose")]
    PalmPose {
        trial: u64,
        #[source]
        source: SimError,
    },
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Key(#[from] KeyError),
    #[error(transparent)]
    Bus(#[from] BusError),
}
