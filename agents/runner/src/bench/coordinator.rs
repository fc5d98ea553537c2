//! `graspopt bench coordinator`: the ceiling of the run-tracking part (one coordinator and
//! its SQLite journal) apart from the simulation's CPU cost. Synthetic hands, metric agent
//! and planner answer at once; the journal is a real file in a temporary folder, opened as
//! a run opens it (WAL, `synchronous=NORMAL`).
//!
//! Each worker count is measured on two paths:
//!
//! - [`BenchPath::Core`]: the coordinator's I/O-free core ([`Coordinator`]) driven directly,
//!   its journal writes carried out by [`graspopt_coordinator::write_journal`] as the loop does.
//!   One thread: every command is answered by its result at once, the results arriving
//!   together as they do from workers that answer at once (the loop takes them as one
//!   event), and a question to the planner is answered at once. Each event's journal
//!   writes are one transaction, as in the loop ([`graspopt_coordinator::split_writes`]). The
//!   lease and status timers run as in the loop. This is the ceiling of the core and the
//!   journal; the time inside journal calls is measured.
//! - [`BenchPath::Bus`]: the real coordinator loop ([`graspopt_coordinator::run`]) on an
//!   in-process Zenoh bus (one session on a loopback port, as an embedded run has), with
//!   synthetic hands (one task each, with its liveliness token, answering each command
//!   with a result at once: hand and metric agent in one), a metric agent's token, a
//!   planner answering each question at once, and the object estimate. The difference to
//!   the core path is what the bus and the async loop cost. Times come from the journal
//!   (milliseconds); the journal's share is not measured on this path.
//!
//! Every run checks its journal: every trial issued once (one attempt), completed once.

use std::collections::{HashMap, VecDeque};
use std::fmt;
use std::path::Path;
use std::time::{Duration, Instant};

use super::BenchError;

type Result<T> = std::result::Result<T, BenchError>;

/// Fails with [`BenchError::Check`] unless `cond` holds.
macro_rules! ensure {
    ($cond:expr, $($fmt:tt)+) => {
        if !$cond {
            return Err(BenchError::Check(format!($($fmt)+)));
        }
    };
}
use graspopt_bus::{AliveEvent, Bus, BusConfig, now_ms};
use graspopt_coordinator::{
    Action, Coordinator, CoordinatorConfig, Event, RunSpec, Write, open_run,
};
use graspopt_journal::{Journal, StoredTrialPhase, event_kind};
use graspopt_protocol::keys::{AliveKey, COMMAND, OBJECT, RESULT, SUGGEST};
use graspopt_protocol::{
    AgentKind, Encoding, ObjectEstimate, PlannerMethod, Pose, RunId, SuggestReply, SuggestRequest,
    TrialCommand, TrialResult,
};
use graspopt_sim::ParamKind;

use crate::embedded::own_bus;

/// Which coordinator is measured (see the module's doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BenchPath {
    Core,
    Bus,
}

impl BenchPath {
    pub fn as_str(self) -> &'static str {
        match self {
            BenchPath::Core => "core",
            BenchPath::Bus => "bus",
        }
    }
}

/// What [`coordinator`] measures.
#[derive(Debug, Clone)]
pub struct CoordinatorSettings {
    /// One run per worker count and path.
    pub workers: Vec<usize>,
    /// Trials of each run.
    pub trials: u64,
    pub paths: Vec<BenchPath>,
}

/// One run's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct CoordinatorRow {
    pub path: BenchPath,
    pub workers: usize,
    /// Trials completed (each issued once and recorded once: checked in the journal).
    pub trials: u64,
    /// From the first issue to the last result recorded.
    pub seconds: f64,
    /// Time of a trial from its issue to its result recorded (milliseconds).
    pub median_ms: f64,
    pub p99_ms: f64,
    /// Share of the run's time spent in journal writes (`None`: not measured).
    pub journal_share: Option<f64>,
    /// Journal transactions per trial (`None`: not measured). One per write would be two.
    pub commits_per_trial: Option<f64>,
}

impl CoordinatorRow {
    pub fn rate(&self) -> f64 {
        self.trials as f64 / self.seconds
    }
}

/// [`coordinator`]'s figures.
#[derive(Debug, Clone)]
pub struct CoordinatorReport {
    pub settings: CoordinatorSettings,
    pub rows: Vec<CoordinatorRow>,
}

/// Every path for every worker count; the journals go to a temporary folder, deleted at
/// the end.
pub async fn coordinator(settings: &CoordinatorSettings) -> Result<CoordinatorReport> {
    let dir = tempfile::Builder::new()
        .prefix("graspopt-bench-coordinator-")
        .tempdir()?;
    let mut rows = Vec::new();
    for &path in &settings.paths {
        for &w in &settings.workers {
            rows.push(match path {
                BenchPath::Core => core_run(dir.path(), w, settings.trials)?,
                BenchPath::Bus => bus_run(dir.path(), w, settings.trials).await?,
            });
        }
    }
    Ok(CoordinatorReport {
        settings: settings.clone(),
        rows,
    })
}

/// The run of the benchmark: the cylinder, the Barrett hand, two parameters.
fn bench_spec(trials: u64) -> RunSpec {
    RunSpec {
        object: "cylinder".into(),
        hand: "barrett".into(),
        params: vec![ParamKind::Approach, ParamKind::Vertical],
        bounds: None,
        trials,
        seed: 1,
        method: PlannerMethod::Random,
        initial: None,
        settings: None,
    }
}

fn estimate(run: &RunId) -> ObjectEstimate {
    ObjectEstimate {
        run_id: run.clone(),
        object: "cylinder".into(),
        mesh: None,
        pose: Pose::IDENTITY,
        seq: 1,
        stamp_ms: now_ms(),
        source: "bench".into(),
    }
}

/// The token of a synthetic agent appearing.
fn agent(run: &RunId, kind: AgentKind, id: String) -> AliveEvent {
    AliveEvent {
        alive: true,
        agent: AliveKey {
            run: run.clone(),
            kind,
            host: "bench".into(),
            id,
            encoding: Encoding::Bincode,
            publishes: None,
        },
    }
}

/// The synthetic planner's answer: `count` points spread over the bounds (a Kronecker
/// sequence, numbered by the observations and pending points so far).
fn proposals(request: &SuggestRequest) -> SuggestReply {
    let start = request.observations.len() + request.pending.len();
    let points = (0..request.count as usize)
        .map(|i| {
            let n = (start + i + 1) as f64;
            request
                .bounds
                .iter()
                .enumerate()
                .map(|(d, [lo, hi])| {
                    let alpha = [0.618_033_988_749_895, 0.414_213_562_373_095][d % 2];
                    lo + (n * alpha).fract() * (hi - lo)
                })
                .collect()
        })
        .collect();
    SuggestReply {
        run_id: request.run_id.clone(),
        request_id: request.request_id,
        points,
        error: None,
        engine_state: None,
    }
}

/// The synthetic hand and metric agent's answer to a command.
fn answer(command: &TrialCommand) -> TrialResult {
    TrialResult {
        run_id: command.run_id.clone(),
        trial_id: command.trial_id,
        attempt: command.attempt,
        worker: command.worker.clone(),
        scorer: "bench-metric".into(),
        score: command.params.iter().map(|p| p.sin()).sum::<f64>().abs(),
        metrics: None,
        contacts: 3,
        fingers_in_contact: 3,
        cloud_points: 0,
        cloud_transport: String::new(),
        error: None,
        forces: None,
    }
}

/// The median and 99th percentile of `values` (NaN when empty).
fn median_p99(mut values: Vec<f64>) -> (f64, f64) {
    values.sort_by(f64::total_cmp);
    let at = |q: f64| {
        let i = ((values.len() as f64 * q) as usize).min(values.len().saturating_sub(1));
        values.get(i).copied().unwrap_or(f64::NAN)
    };
    (at(0.5), at(0.99))
}

/// Checks that every trial of the run was issued once and completed once; returns the
/// number of trials.
fn check_journal(journal: &Journal, run: &RunId, trials: u64) -> Result<u64> {
    let rows = journal.trials(run.as_str())?;
    ensure!(
        rows.len() as u64 == trials,
        "{} trials in the journal, {trials} expected",
        rows.len()
    );
    for r in &rows {
        ensure!(
            r.state == StoredTrialPhase::Completed && r.attempts == 1,
            "trial {} is {:?} after {} attempts",
            r.trial_id,
            r.state,
            r.attempts
        );
    }
    let events = journal.events(run.as_str())?;
    let count = |kind: &str| events.iter().filter(|e| e.kind == kind).count() as u64;
    let (issued, results) = (count(event_kind::ISSUED), count(event_kind::RESULT));
    ensure!(
        issued == trials && results == trials && events.len() as u64 == 2 * trials,
        "journal events: {issued} issued, {results} results, {} in all, for {trials} trials",
        events.len()
    );
    Ok(trials)
}

/// How the core path spends its time.
#[derive(Default)]
struct CoreClock {
    journal: Duration,
    commits: u64,
    first_issue: Option<Instant>,
    last_result: Option<Instant>,
    issued: HashMap<(u64, u32), Instant>,
    latency_ms: Vec<f64>,
}

/// The core and its journal, driven directly (see the module's doc).
pub fn core_run(dir: &Path, workers: usize, trials: u64) -> Result<CoordinatorRow> {
    let run = RunId::new(&format!("bench-core-{workers}"))?;
    let path = dir.join(format!("core-{workers}.sqlite"));
    let mut journal = Journal::open(&path).map_err(|e| {
        BenchError::Check(format!("cannot open the journal {}: {e}", path.display()))
    })?;
    let (spec, state) = open_run(&mut journal, &run, &bench_spec(trials), false)?;
    let config = CoordinatorConfig::default();
    let mut core = Coordinator::new(&run, spec, state, None, config.lease_ms, now_ms());
    core.handle(Event::Estimate(Box::new(estimate(&run))), 0)?;
    let metric = agent(&run, AgentKind::Metric, "metric".into());
    core.handle(Event::Metric(metric), 0)?;
    for i in 1..=workers {
        let hand = agent(&run, AgentKind::Hand, format!("hand-{i}"));
        core.handle(Event::Hand(hand), 0)?;
    }
    let mut clock = CoreClock::default();
    let mut line: VecDeque<TrialCommand> = VecDeque::new();
    let status_period = Duration::from_millis(config.status_period_ms);
    let lease_period = Duration::from_millis(50);
    let (mut status_at, mut lease_at) = (Instant::now(), Instant::now());
    while !core.finished() {
        let mut actions = core.handle(Event::Poll, now_ms())?;
        if line.is_empty() && actions.is_empty() {
            return Err(BenchError::Check(
                "the coordinator stalled: nothing running, nothing to issue".into(),
            ));
        }
        // Every worker answers at once: the results arrive together, as the loop takes
        // them (one event, then the issues of the freed workers' next trials).
        if !line.is_empty() {
            for command in line.drain(..) {
                let result = Event::Result(Box::new(answer(&command)));
                actions.extend(core.handle(result, now_ms())?);
            }
            actions.extend(core.handle(Event::Poll, now_ms())?);
        }
        if status_at.elapsed() >= status_period {
            status_at = Instant::now();
            actions.extend(core.handle(Event::StatusTick, now_ms())?);
        }
        if lease_at.elapsed() >= lease_period {
            lease_at = Instant::now();
            actions.extend(core.handle(Event::LeaseTick, now_ms())?);
        }
        carry_out(
            &mut core,
            &mut journal,
            &run,
            actions,
            &mut line,
            &mut clock,
        )?;
    }
    let trials = check_journal(&journal, &run, trials)?;
    let (Some(first), Some(last)) = (clock.first_issue, clock.last_result) else {
        return Err(BenchError::Check("no trial ran".into()));
    };
    let seconds = last.duration_since(first).as_secs_f64();
    let (median_ms, p99_ms) = median_p99(clock.latency_ms);
    Ok(CoordinatorRow {
        path: BenchPath::Core,
        workers,
        trials,
        seconds,
        median_ms,
        p99_ms,
        journal_share: Some(clock.journal.as_secs_f64() / seconds),
        commits_per_trial: Some(clock.commits as f64 / trials as f64),
    })
}

/// Carries out the core's actions as the loop does: journal writes (timed), commands into
/// the line of workers, questions answered at once (their actions carried out next).
fn carry_out(
    core: &mut Coordinator,
    journal: &mut Journal,
    run: &RunId,
    actions: Vec<Action>,
    line: &mut VecDeque<TrialCommand>,
    clock: &mut CoreClock,
) -> Result<()> {
    let mut todo = actions;
    while !todo.is_empty() {
        // As the loop: the writes of one event in one transaction, then the rest.
        let (writes, rest) = graspopt_coordinator::split_writes(std::mem::take(&mut todo));
        let start = Instant::now();
        graspopt_coordinator::write_journal(journal, run, &writes)?;
        let end = Instant::now();
        clock.journal += end - start;
        clock.commits += u64::from(!writes.is_empty());
        for write in &writes {
            match write {
                Write::Issue(i) => {
                    clock.first_issue.get_or_insert(start);
                    clock.issued.insert((i.trial_id, i.attempt), start);
                }
                Write::Result(r) => {
                    clock.last_result = Some(end);
                    if let Some(t) = clock.issued.remove(&(r.trial_id, r.attempt)) {
                        clock.latency_ms.push((end - t).as_secs_f64() * 1e3);
                    }
                }
                _ => {}
            }
        }
        for action in rest {
            match action {
                Action::Write(_) => {}
                Action::Send { command, .. } => line.push_back(command),
                // Answered at once; what the reply leads to is the next event.
                Action::Ask(request) => {
                    let reply = Event::Reply(Ok(proposals(&request)));
                    todo.extend(core.handle(reply, now_ms())?);
                }
                Action::CancelAsk | Action::Publish(_) | Action::Progress(_) => {}
            }
        }
    }
    Ok(())
}

/// The coordinator's loop on an in-process bus (see the module's doc).
pub async fn bus_run(dir: &Path, workers: usize, trials: u64) -> Result<CoordinatorRow> {
    let run = RunId::new(&format!("bench-bus-{workers}"))?;
    let mut args = own_bus(BusConfig::default(), &run)?;
    args.no_shm = true;
    let bus = Bus::open(&args).await?;
    let mut synthetic = Synthetic::start(&bus, &run, workers).await?;
    let config = CoordinatorConfig {
        id: "bench-coordinator".into(),
        journal: dir.join(format!("bus-{workers}.sqlite")),
        lease_ms: 60_000,
        ..CoordinatorConfig::default()
    };
    let spec = bench_spec(trials);
    let status = tokio::select! {
        s = graspopt_coordinator::run(&bus, &run, &spec, &config, false, None) => Ok(s?),
        Some(t) = synthetic.tasks.join_next() => match t {
            Ok(Ok(())) => Err(BenchError::Check("a synthetic agent stopped before the run finished".into())),
            Ok(Err(e)) => Err(e),
            Err(join) => Err(BenchError::Panicked(join)),
        },
    };
    synthetic.stop().await;
    let _ = bus.close().await;
    let status = status?;
    ensure!(
        status.completed == trials,
        "{} of {trials} trials completed",
        status.completed
    );
    let journal = Journal::open(&config.journal)?;
    let mut row = journal_row(&journal, &run, trials)?;
    row.workers = workers;
    Ok(row)
}

/// The synthetic agents of the bus path, one task each; a task holds its agent's
/// liveliness token.
struct Synthetic {
    tasks: tokio::task::JoinSet<Result<()>>,
}

impl Synthetic {
    /// A metric agent's token, a planner answering each question at once, `workers` hands
    /// answering each command with a result at once, and perception saying what it sees
    /// until the coordinator listens.
    async fn start(bus: &Bus, run: &RunId, workers: usize) -> Result<Synthetic> {
        let mut s = Synthetic {
            tasks: tokio::task::JoinSet::new(),
        };
        let metric = bus
            .declare_alive(run, AgentKind::Metric, "bench-metric")
            .await?;
        let planner = bus
            .declare_alive(run, AgentKind::Planner, "bench-planner")
            .await?;
        let server = bus.serve::<SuggestRequest>(&SUGGEST.key(run)).await?;
        s.tasks.spawn(async move {
            let _tokens = (metric, planner);
            while let Some(q) = server.recv().await {
                match &q.request {
                    Ok(request) => q.reply(&proposals(request)).await?,
                    Err(e) => q.reply_error(&e.to_string()).await?,
                }
            }
            Ok::<(), BenchError>(())
        });
        for i in 1..=workers {
            s.hand(bus, run, format!("hand-{i}")).await?;
        }
        let (b, r) = (bus.clone(), run.clone());
        s.tasks.spawn(async move {
            loop {
                b.put(&OBJECT.key((&r).into()), &estimate(&r), Encoding::Bincode)
                    .await?;
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
        });
        Ok(s)
    }

    /// A hand (and metric agent in one) answering each command with a result at once.
    async fn hand(&mut self, bus: &Bus, run: &RunId, id: String) -> Result<()> {
        let commands = bus
            .subscribe::<TrialCommand>(&COMMAND.worker_key(run.into(), &id))
            .await?;
        let token = bus.declare_alive(run, AgentKind::Hand, &id).await?;
        let (b, r) = (bus.clone(), run.clone());
        self.tasks.spawn(async move {
            let _token = token;
            while let Some(c) = commands.recv().await {
                if let Ok(command) = c.message {
                    b.put(
                        &RESULT.key((&r).into()),
                        &answer(&command),
                        Encoding::Bincode,
                    )
                    .await?;
                }
            }
            Ok::<(), BenchError>(())
        });
        Ok(())
    }

    /// Stops every task (their tokens with them).
    async fn stop(mut self) {
        self.tasks.abort_all();
        while self.tasks.join_next().await.is_some() {}
    }
}

/// The bus path's figures, from its journal (checked first): times in milliseconds, the
/// journal's share not measured. `workers` is left at 0 for the caller.
fn journal_row(journal: &Journal, run: &RunId, trials: u64) -> Result<CoordinatorRow> {
    let trials = check_journal(journal, run, trials)?;
    let rows = journal.trials(run.as_str())?;
    let first = rows.iter().map(|r| r.issued_ms).min().unwrap_or(0);
    let last = rows
        .iter()
        .filter_map(|r| r.completed_ms)
        .max()
        .unwrap_or(0);
    let latency = rows
        .iter()
        .filter_map(|r| Some((r.completed_ms? - r.issued_ms) as f64))
        .collect();
    let (median_ms, p99_ms) = median_p99(latency);
    Ok(CoordinatorRow {
        path: BenchPath::Bus,
        workers: 0,
        trials,
        seconds: (last - first).max(1) as f64 / 1e3,
        median_ms,
        p99_ms,
        journal_share: None,
        commits_per_trial: None,
    })
}

impl fmt::Display for CoordinatorReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "## Coordinator and journal: {} trials per run, synthetic agents answering at once",
            self.settings.trials
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "| path | workers | trials | seconds | trials/s | median trial (ms) | p99 trial (ms) | journal share | commits per trial |"
        )?;
        writeln!(f, "|---|---|---|---|---|---|---|---|---|")?;
        for r in &self.rows {
            let share = r
                .journal_share
                .map_or("-".to_string(), |s| format!("{:.0}%", s * 100.0));
            let commits = r
                .commits_per_trial
                .map_or("-".to_string(), |c| format!("{c:.3}"));
            writeln!(
                f,
                "| {} | {} | {} | {:.2} | {:.0} | {:.3} | {:.3} | {share} | {commits} |",
                r.path.as_str(),
                r.workers,
                r.trials,
                r.seconds,
                r.rate(),
                r.median_ms,
                r.p99_ms
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_core_path_issues_and_records_every_trial_once() {
        let dir = tempfile::tempdir().unwrap();
        for workers in [1, 3] {
            let row = core_run(dir.path(), workers, 7).unwrap();
            assert_eq!(
                (row.path, row.workers, row.trials),
                (BenchPath::Core, workers, 7)
            );
            assert!(row.median_ms <= row.p99_ms);
            let share = row.journal_share.unwrap();
            assert!(share > 0.0 && share <= 1.0, "{share}");
        }
    }

    /// With many workers the results arrive together and the issues of one planner reply
    /// go together: far fewer commits than the two writes per trial (each trial's issue
    /// and result), with every trial still issued and recorded once (checked in the run).
    #[test]
    fn the_core_path_commits_what_arrives_together_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let one = core_run(dir.path(), 1, 64)
            .unwrap()
            .commits_per_trial
            .unwrap();
        let many = core_run(dir.path(), 32, 640)
            .unwrap()
            .commits_per_trial
            .unwrap();
        // One worker: its result and the next issue (after the planner's answer) are two
        // events; 32 workers: about two commits per 32 trials.
        assert!((1.0..=2.0).contains(&one), "{one}");
        assert!(many < 0.1, "{many} commits per trial with 32 workers");
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn the_bus_path_issues_and_records_every_trial_once() {
        let dir = tempfile::tempdir().unwrap();
        let row = bus_run(dir.path(), 3, 9).await.unwrap();
        assert_eq!((row.path, row.workers, row.trials), (BenchPath::Bus, 3, 9));
        assert_eq!(row.journal_share, None);
    }

    #[test]
    fn the_journal_check_refuses_a_trial_not_completed() {
        let dir = tempfile::tempdir().unwrap();
        core_run(dir.path(), 2, 4).unwrap();
        let journal = Journal::open(&dir.path().join("core-2.sqlite")).unwrap();
        let run = RunId::new("bench-core-2").unwrap();
        assert_eq!(check_journal(&journal, &run, 4).unwrap(), 4);
        let e = check_journal(&journal, &run, 5).unwrap_err().to_string();
        assert_eq!(e, "4 trials in the journal, 5 expected");
    }

    #[test]
    fn the_report_is_a_table_row_per_run() {
        let row = |path, journal_share| CoordinatorRow {
            path,
            workers: 32,
            trials: 1000,
            seconds: 0.5,
            median_ms: 1.25,
            p99_ms: 3.5,
            journal_share,
            commits_per_trial: journal_share.map(|_| 0.05),
        };
        let report = CoordinatorReport {
            settings: CoordinatorSettings {
                workers: vec![32],
                trials: 1000,
                paths: vec![BenchPath::Core, BenchPath::Bus],
            },
            rows: vec![row(BenchPath::Core, Some(0.4)), row(BenchPath::Bus, None)],
        };
        let text = report.to_string();
        assert!(text.contains("| core | 32 | 1000 | 0.50 | 2000 | 1.250 | 3.500 | 40% | 0.050 |"));
        assert!(text.contains("| bus | 32 | 1000 | 0.50 | 2000 | 1.250 | 3.500 | - | - |"));
    }
}
