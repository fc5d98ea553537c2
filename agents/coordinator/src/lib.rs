//! The coordinator agent owns a run. It watches hand workers by their liveliness tokens,
//! leases each trial to one idle worker, re-issues a trial whose worker vanished or whose
//! lease expired, asks the planner for as many proposals as there are idle workers, accepts
//! each trial's result exactly once, writes everything to the trial journal (SQLite) as it
//! happens, and publishes the run's status. Restarted on the same journal, it continues the
//! run: completed trials are kept, unfinished ones are issued again.
//!
//! [`state`] is the bookkeeping (no network, no disk); [`run`] wires it to the bus and the
//! journal.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod state;
pub mod waits;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, bail};
use graspopt_bus::{Bus, now_ms};
use graspopt_journal::{
    Journal, MetricValues as JournalMetrics, ResultOutcome, RunRecord, RunStatus as JournalStatus,
    TrialIssue, TrialResultRecord, TrialState, event_kind,
};
use graspopt_protocol::{
    AgentKind, Encoding, ObjectEstimate, PlannerMethod, RunId, RunPhase, RunStatus, SuggestReply,
    SuggestRequest, TrialCommand, TrialResult, WaitReason,
};
use graspopt_sim::{ParamKind, ParamSpec, TrialSpace, reference_pose};
use serde::{Deserialize, Serialize};
use tokio::sync::watch;

use crate::state::{Disposition, RunState, TrialPhase};
use crate::waits::Waits;

/// What a run is: recorded in the journal when the run is created, and taken from there when
/// it resumes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// The object the run is about (perception must agree).
    pub object: String,
    pub hand: String,
    pub params: Vec<ParamKind>,
    /// `[lower, upper]` per parameter; `None`: the simulator's defaults for the object.
    pub bounds: Option<Vec<[f64; 2]>>,
    /// Number of trials.
    pub trials: u64,
    pub seed: u64,
    pub method: PlannerMethod,
    /// Size of the initial design (space-filling, not model-based) (`None`: the engine's default).
    pub initial: Option<u32>,
    /// How the tool that created the run set up the other agents (the object's mesh, the
    /// scoring, perception's noise), kept so that resuming the run restores them. Opaque to
    /// the coordinator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<serde_json::Value>,
}

/// The run's recorded spec in the journal at `path`, if the file and the run exist.
pub fn recorded_spec(path: &std::path::Path, run: &RunId) -> anyhow::Result<Option<RunSpec>> {
    if !path.exists() {
        return Ok(None);
    }
    let journal = Journal::open(path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    let Some(record) = journal.run(run.as_str())? else {
        return Ok(None);
    };
    let spec = serde_json::from_str::<RunSpec>(&record.config_json)
        .with_context(|| format!("run {run:?}: journal holds an unreadable run spec"))?;
    Ok(Some(spec))
}

/// The run ids the journal at `path` holds, oldest first (none if there is no such file).
pub fn recorded_runs(path: &std::path::Path) -> anyhow::Result<Vec<String>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let journal = Journal::open(path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
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
pub fn sole_run(path: &std::path::Path) -> anyhow::Result<Option<RunId>> {
    let runs = recorded_runs(path)?;
    match runs.as_slice() {
        [] => Ok(None),
        [one] => Ok(Some(RunId::new(one)?)),
        _ => bail!(
            "the journal {} holds {} runs ({}): say which to resume with --run",
            path.display(),
            runs.len(),
            quoted_runs(&runs)
        ),
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
    pub fn into_error(self, run: &RunId) -> Option<anyhow::Error> {
        (!self.0.is_empty()).then(|| {
            anyhow::anyhow!(
                "run {run:?} was recorded with other settings: {}. Drop these flags to resume it, or start a new run (another --run id)",
                self.0.join("; ")
            )
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
) -> anyhow::Result<RunSpec> {
    if let Some(e) = resume_conflicts(recorded, given, explicit).into_error(run) {
        return Err(e);
    }
    let mut spec = recorded.clone();
    if explicit("trials") {
        spec.trials = spec.trials.max(given.trials);
    }
    Ok(spec)
}

/// Coordinator settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CoordinatorConfig {
    pub id: String,
    /// The journal file (empty: `results/<run>/journal.sqlite`, where `graspopt run` and
    /// `graspopt export` look by default).
    pub journal: PathBuf,
    /// A trial without a result after this long is issued again.
    pub lease_ms: u64,
    /// How long to wait for the planner before asking again.
    pub planner_timeout_ms: u64,
    /// Status publication period.
    pub status_period_ms: u64,
}

impl Default for CoordinatorConfig {
    fn default() -> Self {
        CoordinatorConfig {
            id: "coordinator".into(),
            journal: PathBuf::new(),
            lease_ms: 30_000,
            planner_timeout_ms: 30_000,
            status_period_ms: 500,
        }
    }
}

impl CoordinatorConfig {
    /// The journal file of `run` (see [`CoordinatorConfig::journal`]).
    pub fn journal_path(&self, run: &RunId) -> PathBuf {
        if self.journal.as_os_str().is_empty() {
            PathBuf::from("results")
                .join(run.as_str())
                .join("journal.sqlite")
        } else {
            self.journal.clone()
        }
    }
}

/// The trial space of a run on an object estimate.
pub fn trial_space(
    spec: &RunSpec,
    estimate: &ObjectEstimate,
) -> anyhow::Result<(TrialSpace, Vec<[f64; 2]>)> {
    let object = graspopt_convert::object_from_estimate(estimate)
        .context("coordinator: the object estimate")?;
    let defaults = graspopt_sim::pose::default_bounds(&object);
    let mut params = Vec::with_capacity(spec.params.len());
    for (i, kind) in spec.params.iter().enumerate() {
        let default = defaults
            .iter()
            .find(|d| d.kind == *kind)
            .copied()
            .context("coordinator: no default bounds for a parameter")?;
        let (lower, upper) = match &spec.bounds {
            Some(b) => {
                let b = b
                    .get(i)
                    .with_context(|| format!("run spec: no bounds for parameter {i}"))?;
                (b[0], b[1])
            }
            None => (default.lower, default.upper),
        };
        params.push(ParamSpec {
            kind: *kind,
            lower,
            upper,
        });
    }
    let space = TrialSpace::new(reference_pose(&object), params).context("run spec")?;
    let bounds = space.bounds().iter().map(|b| [b.0, b.1]).collect();
    Ok((space, bounds))
}

/// Parameter names, as the journal and CSV show them.
pub fn param_names(spec: &RunSpec) -> Vec<String> {
    spec.params
        .iter()
        .map(|k| {
            serde_json::to_value(k)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| format!("{k:?}"))
        })
        .collect()
}

/// Opens (or creates) the run in the journal and rebuilds the state from it. Resuming uses
/// the recorded spec, with the budget raised if `spec` asks for more trials (pass the result
/// of [`reconcile`]). Not resuming, a recorded run that issued no trial is started afresh
/// with `spec`; one that has trials is an error.
pub fn open_run(
    journal: &mut Journal,
    run: &RunId,
    spec: &RunSpec,
    resume: bool,
) -> anyhow::Result<(RunSpec, RunState)> {
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
            bail!(
                "run {run:?} already exists in {place} with {trials} trial{}: resume it (--resume; for a launched run, graspopt launch --resume FILE) or choose another run id",
                if trials == 1 { "" } else { "s" }
            );
        }
    }
    let spec = match existing {
        Some(record) => {
            let recorded = serde_json::from_str::<RunSpec>(&record.config_json)
                .with_context(|| format!("run {run:?}: journal holds an unreadable run spec"))?;
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
            if record.status != JournalStatus::Running {
                journal.set_run_status(run.as_str(), JournalStatus::Running, now_ms())?;
            }
            spec
        }
        None => {
            if resume {
                // A supervised coordinator is restarted with the same command line, so
                // `--resume` also starts a run that was never recorded; it says so.
                tracing::warn!(
                    "coordinator: run {run:?} is not in {place} yet: --resume starts it"
                );
            }
            journal.create_run(&RunRecord {
                run_id: run.as_str().to_string(),
                created_ms: now_ms(),
                config_json: serde_json::to_string(spec)?,
                param_names: param_names(spec),
                status: JournalStatus::Running,
            })?;
            spec.clone()
        }
    };
    let mut state = RunState::new(spec.trials);
    let mut rows = journal.trials(run.as_str())?;
    // Who each attempt went to, so that late results of attempts issued before a restart
    // are still accepted.
    let mut issued: BTreeMap<u64, BTreeMap<u32, String>> = BTreeMap::new();
    for e in journal.events(run.as_str())? {
        if e.kind == event_kind::ISSUED || e.kind == event_kind::REISSUED {
            issued
                .entry(e.trial_id)
                .or_default()
                .insert(e.attempt, e.worker.clone());
        }
    }
    // Observations in completion order (as the planner first saw them).
    rows.sort_by_key(|r| (r.completed_ms.unwrap_or(i64::MAX), r.trial_id));
    for row in &rows {
        let phase = match row.state {
            TrialState::Completed => TrialPhase::Completed {
                score: row.score.unwrap_or(f64::NAN),
            },
            TrialState::Failed => TrialPhase::Failed {
                error: row.error.clone().unwrap_or_default(),
            },
            TrialState::Running => TrialPhase::Queued {
                reason: Some("coordinator restarted".into()),
            },
        };
        state.trials.insert(
            row.trial_id,
            state::Trial {
                params: row.params.clone(),
                attempts: row.attempts,
                issued_to: issued.remove(&row.trial_id).unwrap_or_default(),
                phase,
            },
        );
        if let (TrialState::Completed, Some(score)) = (&row.state, row.score) {
            state.observe(
                row.trial_id,
                row.params.clone(),
                score,
                row.metrics.as_ref().map(|m| m.force_closure),
            );
        }
    }
    Ok((spec, state))
}

fn status(
    run: &RunId,
    spec: &RunSpec,
    state: &RunState,
    phase: RunPhase,
    waits: &Waits,
) -> RunStatus {
    let now = now_ms();
    RunStatus {
        run_id: run.clone(),
        phase,
        object: spec.object.clone(),
        param_names: param_names(spec),
        budget: spec.trials,
        completed: state.completed(),
        running: state.running(),
        failed: state.failed(),
        best: state.best.clone(),
        best_history: state.best_history.clone(),
        workers: state.worker_statuses(),
        errors: state.errors,
        stamp_ms: now,
        waiting: if phase == RunPhase::Finished {
            Vec::new()
        } else {
            waits.shown(now)
        },
    }
}

fn journal_result(r: &TrialResult, at_ms: i64) -> TrialResultRecord {
    TrialResultRecord {
        run_id: r.run_id.as_str().to_string(),
        trial_id: r.trial_id,
        attempt: r.attempt,
        worker: r.worker.clone(),
        at_ms,
        score: r.score,
        metrics: r.metrics.map(|m| JournalMetrics {
            rank: m.rank,
            force_closure: m.force_closure,
            epsilon: m.epsilon,
            volume: m.volume,
            distance: m.distance,
            bw: m.bw,
        }),
        contacts: r.contacts,
        fingers_in_contact: r.fingers_in_contact,
        cloud_points: r.cloud_points,
        details_json: serde_json::json!({
            "scorer": r.scorer,
            "cloud_transport": r.cloud_transport,
        })
        .to_string(),
    }
}

struct Ctx<'a> {
    bus: &'a Bus,
    run: &'a RunId,
    spec: &'a RunSpec,
    config: &'a CoordinatorConfig,
    journal: &'a mut Journal,
    state: RunState,
    space: Option<(TrialSpace, Vec<[f64; 2]>)>,
    request_id: u64,
    /// The encoding each worker asked for in its liveliness token (bincode by default).
    encodings: std::collections::HashMap<String, Encoding>,
    /// Live metric agents (`host/id`).
    scorers: std::collections::HashSet<String>,
    /// Trials running when the last metric agent vanished.
    orphaned: Vec<u64>,
    /// When the planner stopped giving proposals (`None`: it gives them).
    planner_down_since: Option<i64>,
    /// When that was last logged.
    planner_warned_ms: i64,
    /// The planner's engine after its last reply (also in the journal), sent back with every
    /// request: a planner that lost it (restarted) continues from it exactly.
    engine_state: Option<Vec<u8>>,
    /// What the run waits for (object estimate, metric agent, hand, planner).
    waits: Waits,
}

impl Ctx<'_> {
    /// Sends queued trials to idle workers.
    async fn issue_queued(&mut self) -> anyhow::Result<()> {
        let Some((space, _)) = &self.space else {
            return Ok(());
        };
        let mut idle = self.state.idle_workers().into_iter();
        for (trial_id, reason) in self.state.queued() {
            let Some(worker) = idle.next() else { break };
            let now = now_ms();
            let lease_until = now + self.config.lease_ms as i64;
            let Some(attempt) = self.state.assign(trial_id, &worker, now, lease_until) else {
                continue;
            };
            let params = self.state.trials[&trial_id].params.clone();
            let palm = space
                .palm_pose(&params)
                .with_context(|| format!("trial {trial_id}: palm pose"))?;
            self.journal.record_issue(&TrialIssue {
                run_id: self.run.as_str().to_string(),
                trial_id,
                attempt,
                params: params.clone(),
                worker: worker.clone(),
                at_ms: now,
                lease_until_ms: lease_until,
                reason,
            })?;
            let command = TrialCommand {
                run_id: self.run.clone(),
                trial_id,
                attempt,
                worker: worker.clone(),
                hand: self.spec.hand.clone(),
                params,
                palm_pose: graspopt_convert::pose(&palm),
                lease_ms: self.config.lease_ms,
                issued_ms: now,
            };
            let encoding = self
                .encodings
                .get(&worker)
                .copied()
                .unwrap_or(Encoding::Bincode);
            self.bus
                .put(&self.run.command_key(&worker), &command, encoding)
                .await?;
        }
        Ok(())
    }

    /// The request for proposals when workers are idle (`None`: nothing to ask).
    fn plan_request(&mut self) -> Option<SuggestRequest> {
        let n = self.state.proposals_needed();
        let (_, bounds) = self.space.as_ref()?;
        if n == 0 {
            return None;
        }
        self.request_id += 1;
        Some(SuggestRequest {
            run_id: self.run.clone(),
            request_id: self.request_id,
            method: self.spec.method,
            bounds: bounds.clone(),
            seed: self.spec.seed,
            initial: self.spec.initial,
            observations: self.state.observations.clone(),
            pending: self.state.pending_points(),
            count: n as u32,
            engine_state: self.engine_state.clone(),
        })
    }

    /// Queues the planner's proposals (as many as are still needed: the run may have moved
    /// on while the planner thought). Returns false when the planner gave none (the caller
    /// waits and asks again).
    fn take_proposals(&mut self, reply: Result<SuggestReply, graspopt_bus::BusError>) -> bool {
        let reply = match reply {
            Ok(r) => r,
            Err(e) => {
                self.planner_down(&match e {
                    graspopt_bus::BusError::NoResponder { .. } => {
                        format!("no planner is running ({e})")
                    }
                    e => e.to_string(),
                });
                return false;
            }
        };
        if let Some(e) = reply.error {
            self.planner_down(&format!("the planner could not propose: {e}"));
            return false;
        }
        if let Some(engine) = reply.engine_state {
            // Losing it costs a restarted planner its exactness, not the run.
            if let Err(e) = self
                .journal
                .set_planner_state(self.run.as_str(), &engine, now_ms())
            {
                tracing::warn!("coordinator: cannot keep the planner's state in the journal: {e}");
            }
            self.engine_state = Some(engine);
        }
        if let Some(since) = self.planner_down_since.take() {
            tracing::warn!(
                "coordinator: the planner answers again (after {:.1} s)",
                (now_ms() - since) as f64 / 1000.0
            );
        }
        let Some((_, bounds)) = &self.space else {
            return true;
        };
        let dim = bounds.len();
        let n = self.state.proposals_needed();
        for p in reply.points.into_iter().take(n) {
            if p.len() != dim {
                self.state.errors.bad_messages += 1;
                continue;
            }
            self.state.add_trial(p);
        }
        true
    }

    /// Logs that no proposal came: once when it starts, then at most every 10 s.
    fn planner_down(&mut self, why: &str) {
        let now = now_ms();
        match self.planner_down_since {
            None => {
                self.planner_down_since = Some(now);
                self.planner_warned_ms = now;
                tracing::warn!("coordinator: no proposals: {why}; asking again every 0.5 s");
            }
            Some(since) if now - self.planner_warned_ms >= 10_000 => {
                self.planner_warned_ms = now;
                tracing::warn!(
                    "coordinator: still no proposals after {:.0} s: {why}",
                    (now - since) as f64 / 1000.0
                );
            }
            Some(_) => {}
        }
    }

    /// Notes what the run waits for now: the object estimate (since the start), a metric
    /// agent and a hand (since the start or since the last one left), and the planner (since
    /// it stopped answering, or since a question asked at `planning_since` went unanswered
    /// for [`waits::PLANNER_SLOW_MS`]).
    fn note_waits(&mut self, started_ms: i64, planning_since: Option<i64>) {
        let now = now_ms();
        let since = |waiting: bool| waiting.then_some(now);
        self.waits.set(
            WaitReason::ObjectEstimate,
            self.space.is_none().then_some(started_ms),
        );
        self.waits
            .set(WaitReason::MetricAgent, since(self.scorers.is_empty()));
        self.waits
            .set(WaitReason::Hand, since(self.state.workers.is_empty()));
        let slow = planning_since.filter(|t| now - t >= waits::PLANNER_SLOW_MS);
        self.waits
            .set(WaitReason::Planner, self.planner_down_since.or(slow));
    }

    fn on_result(&mut self, result: &TrialResult) -> anyhow::Result<Disposition> {
        let now = now_ms();
        // A result must name an attempt issued to the worker it names: anything else (a
        // forged or corrupted message, a trial never proposed) is counted and never
        // reaches the journal.
        if !self.state.was_issued(result) || self.state.stale_failure(result) {
            return Ok(self.state.on_result(result, now));
        }
        let already = matches!(
            self.state.trials[&result.trial_id].phase,
            TrialPhase::Completed { .. } | TrialPhase::Failed { .. }
        );
        if !already {
            if let Some(error) = &result.error {
                self.journal.record_failure(
                    self.run.as_str(),
                    result.trial_id,
                    result.attempt,
                    error,
                    now,
                )?;
            } else {
                match self.journal.record_result(&journal_result(result, now))? {
                    ResultOutcome::Accepted => {}
                    other => tracing::warn!(
                        "coordinator: journal says {other:?} for trial {}",
                        result.trial_id
                    ),
                }
            }
        }
        // A duplicate is counted in the run's status and leaves the journal as it is.
        Ok(self.state.on_result(result, now))
    }
}

/// A proposal request on its way to the planner.
type PlannerCall<'a> = std::pin::Pin<
    Box<dyn std::future::Future<Output = Result<SuggestReply, graspopt_bus::BusError>> + Send + 'a>,
>;

/// Runs the coordinator until the run finishes; returns the final status. `progress`
/// receives every status published.
pub async fn run(
    bus: &Bus,
    run: &RunId,
    spec: &RunSpec,
    config: &CoordinatorConfig,
    resume: bool,
    progress: Option<watch::Sender<RunStatus>>,
) -> anyhow::Result<RunStatus> {
    run_until(
        bus,
        run,
        spec,
        config,
        resume,
        progress,
        std::future::pending(),
    )
    .await
}

/// [`run`], stopping early when `stop` resolves (Ctrl-C, say): the journal then records the
/// run as stopped (every result already in stays; `--resume` continues it) and the status
/// returned has the phase it had.
pub async fn run_until(
    bus: &Bus,
    run: &RunId,
    spec: &RunSpec,
    config: &CoordinatorConfig,
    resume: bool,
    progress: Option<watch::Sender<RunStatus>>,
    stop: impl std::future::Future<Output = ()>,
) -> anyhow::Result<RunStatus> {
    tokio::pin!(stop);
    let mut stopped = false;
    // Two coordinators on one run would issue each trial twice and fight over the journal.
    let _place = bus
        .wait_until_unique(run, AgentKind::Coordinator, None, Duration::from_secs(5))
        .await?;
    let journal_path = config.journal_path(run);
    let mut journal = Journal::open(&journal_path)
        .with_context(|| format!("cannot open the journal {}", journal_path.display()))?;
    let (spec, mut state) = open_run(&mut journal, run, spec, resume)?;
    state.grace_ms = config.lease_ms as i64;
    let engine_state = journal.planner_state(run.as_str())?;
    let results = bus.subscribe::<TrialResult>(&run.result_key()).await?;
    let objects = bus.subscribe::<ObjectEstimate>(&run.object_key()).await?;
    let hands = bus
        .watch_alive(&run.alive_kind_key(AgentKind::Hand))
        .await?;
    // Trials wait for a metric agent: clouds published before one listens would be lost.
    let metrics = bus
        .watch_alive(&run.alive_kind_key(AgentKind::Metric))
        .await?;
    // A planner (re)appearing answers at once: a question in flight when the network was
    // cut would otherwise wait for its timeout.
    let planners = bus
        .watch_alive(&run.alive_kind_key(AgentKind::Planner))
        .await?;
    let state_server = bus
        .serve::<graspopt_protocol::RunStatus>(&run.state_key())
        .await?;
    let _token = bus
        .declare_alive(run, AgentKind::Coordinator, &config.id)
        .await?;
    let mut ctx = Ctx {
        bus,
        run,
        spec: &spec,
        config,
        journal: &mut journal,
        state,
        space: None,
        request_id: 0,
        encodings: Default::default(),
        scorers: Default::default(),
        orphaned: Vec::new(),
        planner_down_since: None,
        planner_warned_ms: 0,
        engine_state,
        waits: Waits::default(),
    };
    let started_ms = now_ms();
    let mut tick = tokio::time::interval(Duration::from_millis(config.status_period_ms.max(20)));
    let mut lease_tick = tokio::time::interval(Duration::from_millis(50));
    let mut planner_retry_at = tokio::time::Instant::now();
    // The planner's answer is awaited beside everything else, so results, leases and
    // workers are still handled while it thinks or while the bus cannot reach it.
    let mut planning: Option<PlannerCall> = None;
    // When the question in `planning` was asked.
    let mut planning_since: Option<i64> = None;
    let planner_timeout = Duration::from_millis(config.planner_timeout_ms);
    let suggest_key = run.suggest_key();
    let status_key = run.status_key();
    loop {
        if ctx.state.finished() {
            break;
        }
        if ctx.space.is_some() && !ctx.scorers.is_empty() {
            ctx.issue_queued().await?;
            if planning.is_none()
                && tokio::time::Instant::now() >= planner_retry_at
                && let Some(request) = ctx.plan_request()
            {
                let key = suggest_key.clone();
                planning = Some(Box::pin(async move {
                    bus.query(&key, &request, planner_timeout).await
                }));
                planning_since = Some(now_ms());
            }
        }
        ctx.note_waits(started_ms, planning_since);
        tokio::select! {
            reply = async {
                match planning.as_mut() {
                    Some(call) => call.await,
                    None => std::future::pending().await,
                }
            }, if planning.is_some() => {
                planning = None;
                planning_since = None;
                if ctx.take_proposals(reply) {
                    ctx.issue_queued().await?;
                } else {
                    planner_retry_at = tokio::time::Instant::now() + Duration::from_millis(500);
                }
            },
            Some(r) = results.recv() => match r.message {
                Ok(result) if result.run_id == *run => {
                    match ctx.on_result(&result)? {
                        Disposition::Unknown => tracing::warn!("coordinator: result for unknown trial {}", result.trial_id),
                        Disposition::Duplicate => tracing::info!("coordinator: duplicate result for trial {}", result.trial_id),
                        Disposition::NotIssued => tracing::warn!("coordinator: result for trial {} attempt {} from {}, which was never issued that attempt", result.trial_id, result.attempt, result.worker),
                        Disposition::StaleFailure => tracing::warn!("coordinator: attempt {} of trial {} failed, a later attempt is running: ignored", result.attempt, result.trial_id),
                        _ => {}
                    }
                    let s = status(run, &spec, &ctx.state, RunPhase::Running, &ctx.waits);
                    if let Some(p) = &progress { let _ = p.send(s); }
                }
                Ok(result) => {
                    ctx.state.errors.bad_messages += 1;
                    tracing::warn!("coordinator: result of run {:?} on this run's key", result.run_id);
                }
                Err(e) => {
                    ctx.state.errors.bad_messages += 1;
                    tracing::warn!("coordinator: bad result on {} ({} bad messages): {e}", r.key, ctx.state.errors.bad_messages);
                }
            },
            Some(r) = objects.recv() => match r.message {
                Ok(estimate) if estimate.run_id == *run => {
                    if ctx.space.is_none() {
                        if estimate.object != spec.object {
                            bail!("perception sees {:?}, the run is about {:?}", estimate.object, spec.object);
                        }
                        ctx.space = Some(trial_space(&spec, &estimate)?);
                    }
                }
                Ok(_) => ctx.state.errors.bad_messages += 1,
                Err(e) => {
                    ctx.state.errors.bad_messages += 1;
                    tracing::warn!("coordinator: bad object estimate on {}: {e}", r.key);
                }
            },
            Some(ev) = hands.recv() => {
                if ev.agent.run == *run {
                    if ev.alive {
                        ctx.encodings.insert(ev.agent.id.clone(), ev.agent.encoding);
                        ctx.state.worker_up(&ev.agent.id, &ev.agent.host);
                    } else if let Some(t) = ctx.state.worker_down(&ev.agent.id) {
                        tracing::warn!("coordinator: worker {} lost with trial {t}: re-issuing", ev.agent.id);
                    }
                }
            },
            Some(ev) = planners.recv() => {
                if ev.alive && ev.agent.run == *run && planning.is_some() {
                    planning = None;
                    planning_since = None;
                    planner_retry_at = tokio::time::Instant::now();
                }
            },
            Some(ev) = metrics.recv() => {
                if ev.agent.run == *run {
                    let key = format!("{}/{}", ev.agent.host, ev.agent.id);
                    if ev.alive {
                        let was_empty = ctx.scorers.is_empty();
                        ctx.scorers.insert(key);
                        if was_empty {
                            let orphaned = std::mem::take(&mut ctx.orphaned);
                            for t in ctx.state.requeue_orphaned(&orphaned, now_ms()) {
                                tracing::warn!("coordinator: trial {t} ran while no metric agent was alive: re-issuing");
                            }
                        }
                    } else {
                        ctx.scorers.remove(&key);
                        if ctx.scorers.is_empty() {
                            ctx.orphaned = ctx.state.running_trials();
                            tracing::warn!("coordinator: no metric agent left: trials wait for one");
                        }
                    }
                }
            },
            Some(q) = state_server.recv() => {
                let s = status(run, &spec, &ctx.state, if ctx.space.is_some() { RunPhase::Running } else { RunPhase::Waiting }, &ctx.waits);
                let _ = q.reply(&s).await;
            },
            _ = lease_tick.tick() => {
                for t in ctx.state.expire_leases(now_ms(), config.lease_ms as i64) {
                    tracing::warn!("coordinator: lease of trial {t} expired: re-issuing");
                }
            },
            _ = &mut stop => {
                stopped = true;
                break;
            },
            _ = tick.tick() => {
                let phase = if ctx.space.is_some() { RunPhase::Running } else { RunPhase::Waiting };
                let s = status(run, &spec, &ctx.state, phase, &ctx.waits);
                if let Some(m) = ctx.waits.message(s.stamp_ms) {
                    tracing::warn!("coordinator: run {run:?} {m}");
                }
                let _ = bus.put_droppable(&status_key, &s, Encoding::Bincode).await;
                if let Some(p) = &progress { let _ = p.send(s); }
            },
        }
    }
    if stopped {
        ctx.journal
            .set_run_status(run.as_str(), JournalStatus::Stopped, now_ms())?;
        let phase = if ctx.space.is_some() {
            RunPhase::Running
        } else {
            RunPhase::Waiting
        };
        let s = status(run, &spec, &ctx.state, phase, &ctx.waits);
        let waiting = if s.waiting.is_empty() {
            String::new()
        } else {
            format!(
                " while waiting ({})",
                waits::describe(&s.waiting, s.stamp_ms)
            )
        };
        // A run that issued no trial is started afresh by the same command (see `create`).
        let unstarted = s.completed + s.failed + s.running == 0
            && ctx.journal.trials(run.as_str()).is_ok_and(|t| t.is_empty());
        let next = if unstarted {
            "no trial was issued: the same command starts it afresh"
        } else {
            "resume with --resume"
        };
        tracing::warn!(
            "coordinator: run {run:?} stopped with {} of {} trials completed ({} failed, {} running){waiting}; every result is in {}; {next}",
            s.completed,
            s.budget,
            s.failed,
            s.running,
            journal_path.display()
        );
        return Ok(s);
    }
    ctx.journal
        .set_run_status(run.as_str(), JournalStatus::Finished, now_ms())?;
    let s = status(run, &spec, &ctx.state, RunPhase::Finished, &ctx.waits);
    let _ = bus.put(&status_key, &s, Encoding::Bincode).await;
    if let Some(p) = &progress {
        let _ = p.send(s.clone());
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(trials: u64) -> RunSpec {
        RunSpec {
            object: "sphere".into(),
            hand: "barrett".into(),
            params: vec![ParamKind::Approach],
            bounds: None,
            trials,
            seed: 1,
            method: PlannerMethod::Random,
            initial: None,
            settings: None,
        }
    }

    #[test]
    fn resuming_keeps_the_record_names_contradicting_flags_and_may_raise_the_budget() {
        let run = RunId::new("r").unwrap();
        let recorded = spec(20);
        let given = RunSpec {
            object: "mug".into(),
            seed: 4,
            ..spec(10)
        };
        // Flags left at their defaults are not contradictions: the record wins.
        let none = |_: &str| false;
        assert_eq!(reconcile(&run, &recorded, &given, &none).unwrap(), recorded);
        // Given explicitly, they are, each named with both values.
        let all = |_: &str| true;
        let e = reconcile(&run, &recorded, &given, &all)
            .unwrap_err()
            .to_string();
        for part in [
            "--object mug (the run has sphere)",
            "--seed 4 (the run has 1)",
            "--trials 10 (the run has a budget of 20",
        ] {
            assert!(e.contains(part), "{part:?} not in {e}");
        }
        assert!(!e.contains("--hand"), "{e}");
        // A larger budget is taken; the rest stays recorded.
        let trials_only = |f: &str| f == "trials";
        let raised = reconcile(&run, &recorded, &spec(35), &trials_only).unwrap();
        assert_eq!(raised.trials, 35);
        assert_eq!(
            RunSpec {
                trials: 20,
                ..raised
            },
            recorded
        );
    }

    #[test]
    fn open_run_raises_a_finished_runs_budget() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        // Resuming a run never recorded starts it (a supervised restart's command line).
        let (started, _) = open_run(&mut journal, &run, &spec(5), true).unwrap();
        assert_eq!(started.trials, 5);
        journal
            .set_run_status("r", JournalStatus::Finished, 10)
            .unwrap();
        let (resumed, state) = open_run(&mut journal, &run, &spec(8), true).unwrap();
        assert_eq!(resumed.trials, 8);
        assert!(!state.finished());
        let record = journal.run("r").unwrap().unwrap();
        assert_eq!(record.status, JournalStatus::Running);
        let stored: RunSpec = serde_json::from_str(&record.config_json).unwrap();
        assert_eq!(stored.trials, 8);
        // The same budget again (or less) leaves the record as it is.
        let (again, _) = open_run(&mut journal, &run, &spec(3), true).unwrap();
        assert_eq!(again.trials, 8);
    }

    /// A trial issued for run `r`, attempt 1.
    fn issue(trial_id: u64) -> TrialIssue {
        TrialIssue {
            run_id: "r".into(),
            trial_id,
            attempt: 1,
            params: vec![0.01],
            worker: "a".into(),
            at_ms: 10,
            lease_until_ms: 1000,
            reason: None,
        }
    }

    /// A run stopped before its first trial (a wrong address) is started afresh by the same
    /// command, with the settings given now; once a trial is issued, it must be resumed.
    #[test]
    fn a_run_without_trials_starts_afresh_and_one_with_trials_must_be_resumed() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        open_run(&mut journal, &run, &spec(5), false).unwrap();
        journal.set_planner_state("r", &[1, 2, 3], 5).unwrap();
        journal
            .set_run_status("r", JournalStatus::Stopped, 10)
            .unwrap();
        let (again, state) = open_run(&mut journal, &run, &spec(7), false).unwrap();
        assert_eq!(again, spec(7));
        assert!(state.trials.is_empty());
        let record = journal.run("r").unwrap().unwrap();
        assert_eq!(record.status, JournalStatus::Running);
        assert_eq!(
            serde_json::from_str::<RunSpec>(&record.config_json).unwrap(),
            spec(7)
        );
        assert_eq!(journal.planner_state("r").unwrap(), None);
        journal.record_issue(&issue(1)).unwrap();
        let e = open_run(&mut journal, &run, &spec(7), false).unwrap_err();
        let e = e.to_string();
        assert!(
            e.contains("run \"r\" already exists") && e.contains("with 1 trial:"),
            "{e}"
        );
        assert!(e.contains("--resume"), "{e}");
        assert_eq!(journal.trials("r").unwrap().len(), 1);
    }

    /// A coordinator restarted with `--resume` still accepts the late result of an attempt
    /// issued before the restart (who got each attempt comes back from the journal's events).
    #[test]
    fn a_resumed_run_accepts_results_of_attempts_issued_before_the_restart() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        let spec = spec(2);
        open_run(&mut journal, &run, &spec, false).unwrap();
        for (attempt, worker) in [(1, "a"), (2, "b")] {
            journal
                .record_issue(&TrialIssue {
                    attempt,
                    worker: worker.into(),
                    at_ms: 10 * attempt as i64,
                    ..issue(1)
                })
                .unwrap();
        }
        let (_, mut state) = open_run(&mut journal, &run, &spec, true).unwrap();
        let result = |attempt: u32, worker: &str| TrialResult {
            attempt,
            ..crate::state::tests::result(1, worker, 0.5)
        };
        assert!(!state.was_issued(&result(1, "b")));
        assert!(state.was_issued(&result(2, "b")));
        assert_eq!(state.on_result(&result(1, "a"), 0), Disposition::Completed);
    }
}
