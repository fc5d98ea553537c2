//! What can go wrong when running agents: a run's settings refused, its folder, a settings
//! file, a launch file, the processes of a launch, a recording. The messages name the flag
//! or key to change (tests and docs/troubleshooting.md quote them).

use std::path::PathBuf;

use graspopt_protocol::RunId;

/// An error of another crate, kept with its message and causes (an agent's, the
/// coordinator's).
pub type Boxed = Box<dyn std::error::Error + Send + Sync>;

/// Why a run, an agent or a launch cannot go on.
#[derive(Debug, thiserror::Error)]
pub enum RunnerError {
    #[error(
        "--workers {workers} is more than the {max} hand workers one process runs (the capacity of a \
         host's shared-memory clouds service): run more hands as separate processes or on \
         other hosts (graspopt launch, graspopt agent hand)"
    )]
    TooManyWorkers { workers: usize, max: usize },
    #[error(
        "--workers {workers} needs about {need} open files, and this process may open at \
         most {hard} (ulimit -Hn; soft limit {soft}): use at most {most} workers, raise \
         the limit (ulimit -n {need}, or LimitNOFILE= in a systemd unit), or run the \
         hands as separate processes (graspopt launch, graspopt agent hand)"
    )]
    OpenFiles {
        workers: usize,
        need: u64,
        hard: u64,
        soft: u64,
        most: u64,
    },
    #[error("--lease-ms is {lease_ms}: it must be between 1 and {max} (a week)")]
    Lease { lease_ms: u64, max: u64 },
    #[error(
        "--trial-cost-ms {trial_cost_ms} is not shorter than the lease of a trial (--lease-ms {lease_ms}): every \
         trial would expire before it ends and be issued again forever; raise --lease-ms"
    )]
    TrialCost { trial_cost_ms: u64, lease_ms: u64 },
    #[error(
        "--hand {hand}: the coordinator knows a hand by its name; where its file is not on this host, give the name `graspopt hands FILE` prints"
    )]
    HandName {
        hand: String,
        #[source]
        source: graspopt_sim::SimError,
    },
    #[error("--position-noise / --rotation-noise")]
    Noise(#[source] graspopt_perception::PerceptionError),
    #[error("run {run:?}: its hand's file {} is gone: give --hand FILE where it is now", file.display())]
    HandFileGone { run: RunId, file: PathBuf },
    /// A setting recorded with a run that this version does not know.
    #[error("run {run:?}: recorded {what}")]
    Recorded {
        run: RunId,
        what: String,
        #[source]
        source: Option<Boxed>,
    },
    #[error(
        "no journal at {}: there is nothing to resume (start the run without --resume)",
        journal.display()
    )]
    NoJournal { journal: PathBuf },
    #[error(
        "run {run:?} is not in {}: there is nothing to resume (start it without --resume)",
        journal.display()
    )]
    NotRecorded { run: RunId, journal: PathBuf },
    #[error(
        "run {run:?} is not in {}, which holds run {runs}: resume one of those (--run ID, or no --run if there is one), or start {run:?} without --resume",
        journal.display()
    )]
    OtherRuns {
        run: RunId,
        journal: PathBuf,
        runs: String,
    },
    #[error(
        "the results folder {} holds run {runs} already (its trials.csv, trials.json and best.svg would be overwritten): choose another --out, or resume {it} with --resume --out {}{run_flag}",
        out.display(),
        out.display()
    )]
    FolderTaken {
        out: PathBuf,
        runs: String,
        it: &'static str,
        run_flag: &'static str,
    },
    #[error("cannot create the results folder {}", path.display())]
    CreateFolder {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("an agent stopped before the run finished")]
    AgentStopped,
    #[error("an agent panicked: {0}")]
    AgentPanicked(tokio::task::JoinError),
    /// An agent's or the coordinator's error.
    #[error(transparent)]
    Agent(Boxed),
    #[error("cannot read the settings file {}", path.display())]
    ReadSettings {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A settings file that does not parse or has a key the settings do not have.
    #[error("settings file {}", path.display())]
    SettingsFile {
        path: PathBuf,
        #[source]
        source: Boxed,
    },
    /// A key the settings do not have: the keys of its table.
    #[error("unknown key `{key}` {place}; the keys there are {keys}")]
    UnknownKey {
        key: String,
        place: String,
        keys: String,
    },
    /// A `--set` without `=`.
    #[error("--set {0:?}: write it as KEY=VALUE (docs/agent-config.md)")]
    SetWithoutValue(String),
    /// A `--set key=value` that does not fit the settings.
    #[error("--set {key}={value}: {why}")]
    Set {
        key: String,
        value: String,
        why: String,
    },
    #[error("cannot read why trials failed from the journal {}", journal.display())]
    Failures {
        journal: PathBuf,
        #[source]
        source: graspopt_journal::JournalError,
    },
    #[error("cannot read the launch file {}", file.display())]
    LaunchRead {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A launch file that cannot be used: the file and why.
    #[error("launch file {}: {why}", file.display())]
    LaunchFile { file: PathBuf, why: String },
    /// A launch file's part that does not parse or check.
    #[error("launch file {}", file.display())]
    LaunchFileInvalid {
        file: PathBuf,
        #[source]
        source: Boxed,
    },
    #[error("launch file {}: run", file.display())]
    LaunchRun {
        file: PathBuf,
        #[source]
        source: graspopt_protocol::keys::KeyError,
    },
    #[error(
        "--resume: no coordinator runs on host {host:?}; resume the run on the machine that runs the coordinator"
    )]
    NoCoordinatorHere { host: String },
    #[error("cannot create the log folder {}", path.display())]
    LogFolder {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot create {}", path.display())]
    Create {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot start {name}")]
    Start {
        name: String,
        #[source]
        source: std::io::Error,
    },
    /// A process of a launch stopped before the run finished.
    #[error(
        "{name} stopped ({status}) before the run finished; everything was stopped. Its log ({}):\n{tail}",
        log.display()
    )]
    Died {
        name: String,
        status: String,
        log: PathBuf,
        tail: String,
    },
    #[error("the router does not accept connections on {addr} after 20 s")]
    RouterSilent { addr: String },
    #[error(
        "{} is an SQLite database (a run's journal?): a recording would replace it; write it elsewhere",
        path.display()
    )]
    Database { path: PathBuf },
    #[error("grasp at {params:?}")]
    Grasp {
        params: Vec<f64>,
        #[source]
        source: Box<RunnerError>,
    },
    /// Settings given with `flags` that cannot be used.
    #[error("{flags}")]
    Flags {
        flags: &'static str,
        #[source]
        source: Boxed,
    },
    #[error("--force-resolution and --torque-resolution need --sensing ft")]
    NeedsFt,
    #[error("the metric agent cannot score its fingertip readings: {0}")]
    FingertipScore(String),
    #[error(transparent)]
    Trial(#[from] graspopt_trial::TrialError),
    #[error(transparent)]
    Sim(#[from] graspopt_sim::SimError),
    #[error(transparent)]
    Key(#[from] graspopt_protocol::keys::KeyError),
    #[error(transparent)]
    Bus(#[from] graspopt_bus::BusError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error(transparent)]
    Errno(#[from] nix::errno::Errno),
}

impl RunnerError {
    /// The coordinator's (or an agent's) error, kept with its message and causes.
    pub fn agent(e: impl Into<Boxed>) -> RunnerError {
        RunnerError::Agent(e.into())
    }
}

/// `e` and its causes, as `{:#}` prints an error chain: `outer: inner: ...` (tests, and
/// messages that quote an error whole).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(inner) = source {
        text.push_str(": ");
        text.push_str(&inner.to_string());
        source = inner.source();
    }
    text
}
