//! The coordinator's core: the rules of a run as a state machine without I/O. Each event (a
//! result, an estimate, a worker coming or going, a planner reply, a timer) is one method
//! taking the time (`now`, milliseconds since the epoch) and returning the [`Action`]s to
//! carry out, in order: journal writes, commands to send, questions to the planner, status
//! to publish. The async loop in [`crate::run`] only moves messages and timers.

use std::collections::{HashMap, HashSet};

use anyhow::{Context, bail};
use graspopt_bus::BusError;
use graspopt_journal::{TrialIssue, TrialResultRecord};
use graspopt_protocol::keys::AliveKey;
use graspopt_protocol::{
    Encoding, ObjectEstimate, RunId, RunPhase, RunStatus, SuggestReply, SuggestRequest,
    TrialCommand, TrialResult, WaitReason,
};
use graspopt_sim::TrialSpace;

use crate::spec::{RunSpec, param_names, trial_space};
use crate::state::{Disposition, RunState, TrialPhase};
use crate::waits::{self, Waits};

/// After a question the planner did not answer, how long until it is asked again.
pub const PLANNER_RETRY_MS: i64 = 500;

/// A write to the run's journal (what a batch of them keeps: `graspopt_journal::batch`).
pub use graspopt_journal::Write;

/// What the loop does for the core, in the order given, except that the journal writes of
/// one call are committed together before the rest (see [`crate::run::record`]): a write
/// only ever comes earlier, never a command before its issue.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    Record(Write),
    /// Sends a trial command to a worker, in the encoding it asked for.
    Send {
        worker: String,
        encoding: Encoding,
        command: TrialCommand,
    },
    /// Asks the planner (answered with [`Coordinator::on_reply`]).
    Ask(SuggestRequest),
    /// Drops the question in flight (the planner came back: ask again at once).
    CancelAsk,
    /// Publishes the run's status on the bus.
    Publish(RunStatus),
    /// Hands the run's status to whoever follows the run in-process.
    Progress(RunStatus),
}

/// The link to the planner.
#[derive(Debug, Default)]
struct PlannerLink {
    /// When the question in flight was asked (`None`: none is).
    asking_since: Option<i64>,
    /// No question before this time.
    retry_at_ms: i64,
    /// When the planner stopped giving proposals (`None`: it gives them).
    down_since: Option<i64>,
    /// When that was last logged.
    warned_ms: i64,
    /// The planner's engine after its last reply (also in the journal), sent back with
    /// every request: a planner that lost it (restarted) continues from it exactly.
    engine_state: Option<Vec<u8>>,
    request_id: u64,
}

/// One run's coordinator, without I/O.
pub struct Coordinator {
    run: RunId,
    spec: RunSpec,
    lease_ms: u64,
    state: RunState,
    /// The trial space and its bounds, once the object estimate came.
    space: Option<(TrialSpace, Vec<[f64; 2]>)>,
    /// The encoding each worker asked for in its liveliness token (bincode by default).
    encodings: HashMap<String, Encoding>,
    /// Live metric agents (`host/id`).
    scorers: HashSet<String>,
    /// Trials running when the last metric agent vanished.
    orphaned: Vec<u64>,
    planner: PlannerLink,
    /// What the run waits for (object estimate, metric agent, hand, planner).
    waits: Waits,
    started_ms: i64,
}

impl Coordinator {
    /// The coordinator of `run` with the spec and state opened from the journal
    /// ([`crate::spec::open_run`]) and the planner's engine state recorded there, starting
    /// at `now`. Trials are leased for `lease_ms`.
    pub fn new(
        run: &RunId,
        spec: RunSpec,
        mut state: RunState,
        engine_state: Option<Vec<u8>>,
        lease_ms: u64,
        now: i64,
    ) -> Coordinator {
        state.set_grace_ms(lease_ms as i64);
        Coordinator {
            run: run.clone(),
            spec,
            lease_ms,
            state,
            space: None,
            encodings: HashMap::new(),
            scorers: HashSet::new(),
            orphaned: Vec::new(),
            planner: PlannerLink {
                engine_state,
                retry_at_ms: now,
                ..PlannerLink::default()
            },
            waits: Waits::default(),
            started_ms: now,
        }
    }

    pub fn run(&self) -> &RunId {
        &self.run
    }

    pub fn spec(&self) -> &RunSpec {
        &self.spec
    }

    /// Every trial of the budget issued and finished.
    pub fn finished(&self) -> bool {
        self.state.finished()
    }

    /// What to do between events: lease queued trials to idle workers and ask the planner
    /// for more (once the trial space is known and a metric agent listens), and note what
    /// the run waits for.
    pub fn poll(&mut self, now: i64) -> anyhow::Result<Vec<Action>> {
        let mut out = Vec::new();
        if self.space.is_some() && !self.scorers.is_empty() {
            out = self.issue_queued(now)?;
            if self.planner.asking_since.is_none()
                && now >= self.planner.retry_at_ms
                && let Some(request) = self.plan_request()
            {
                self.planner.asking_since = Some(now);
                out.push(Action::Ask(request));
            }
        }
        self.note_waits(now);
        Ok(out)
    }

    /// The planner's reply (or why none came) to the question in flight.
    pub fn on_reply(
        &mut self,
        reply: Result<SuggestReply, BusError>,
        now: i64,
    ) -> anyhow::Result<Vec<Action>> {
        self.planner.asking_since = None;
        let mut out = Vec::new();
        if self.take_proposals(reply, now, &mut out) {
            out.extend(self.issue_queued(now)?);
        } else {
            self.planner.retry_at_ms = now + PLANNER_RETRY_MS;
        }
        Ok(out)
    }

    /// A planner's token came or went: one (re)appearing answers at once, so a question in
    /// flight when the network was cut is dropped and asked again.
    pub fn on_planner_alive(&mut self, agent: &AliveKey, alive: bool, now: i64) -> Vec<Action> {
        if !(alive && agent.run == self.run && self.planner.asking_since.is_some()) {
            return Vec::new();
        }
        self.planner.asking_since = None;
        self.planner.retry_at_ms = now;
        vec![Action::CancelAsk]
    }

    /// A result of this run: journaled if it is the first of an attempt issued to the
    /// worker it names; counted otherwise.
    pub fn on_result(&mut self, result: &TrialResult, now: i64) -> Vec<Action> {
        let mut out = Vec::new();
        // A result must name an attempt issued to the worker it names: anything else (a
        // forged or corrupted message, a trial never proposed) is counted and never
        // reaches the journal. A duplicate leaves the journal as it is.
        let first = self.state.was_issued(result)
            && !self.state.stale_failure(result)
            && self.state.trial(result.trial_id).is_some_and(|t| {
                !matches!(
                    t.phase,
                    TrialPhase::Completed { .. } | TrialPhase::Failed { .. }
                )
            });
        if first {
            out.push(Action::Record(match &result.error {
                Some(error) => Write::Failure {
                    trial_id: result.trial_id,
                    attempt: result.attempt,
                    error: error.clone(),
                    at_ms: now,
                },
                None => Write::Result(Box::new(journal_result(result, now))),
            }));
        }
        log_disposition(result, self.state.on_result(result, now));
        out.push(Action::Progress(self.status_at(RunPhase::Running, now)));
        out
    }

    /// A message that was not acted on (it did not decode, or named another run).
    pub fn on_bad_message(&mut self) {
        self.state.count_bad_message();
    }

    /// An object estimate of this run: the first one sets the trial space.
    pub fn on_estimate(&mut self, estimate: &ObjectEstimate) -> anyhow::Result<()> {
        if self.space.is_none() {
            if estimate.object != self.spec.object {
                bail!(
                    "perception sees {:?}, the run is about {:?}",
                    estimate.object,
                    self.spec.object
                );
            }
            self.space = Some(trial_space(&self.spec, estimate)?);
        }
        Ok(())
    }

    /// A hand worker's token came or went: a worker lost with a trial has it re-issued.
    pub fn on_hand(&mut self, agent: &AliveKey, alive: bool) {
        if agent.run != self.run {
            return;
        }
        if alive {
            self.encodings.insert(agent.id.clone(), agent.encoding);
            self.state.worker_up(&agent.id, &agent.host);
        } else if let Some(t) = self.state.worker_down(&agent.id) {
            tracing::warn!(
                "coordinator: worker {} lost with trial {t}: re-issuing",
                agent.id
            );
        }
    }

    /// A metric agent's token came or went. Trials wait while none is alive (clouds sent to
    /// nobody are lost); the ones running when the last left are re-issued once one is back.
    pub fn on_metric(&mut self, agent: &AliveKey, alive: bool, now: i64) {
        if agent.run != self.run {
            return;
        }
        let key = format!("{}/{}", agent.host, agent.id);
        if alive {
            let was_empty = self.scorers.is_empty();
            self.scorers.insert(key);
            if was_empty {
                let orphaned = std::mem::take(&mut self.orphaned);
                for t in self.state.requeue_orphaned(&orphaned, now) {
                    tracing::warn!(
                        "coordinator: trial {t} ran while no metric agent was alive: re-issuing"
                    );
                }
            }
        } else {
            self.scorers.remove(&key);
            if self.scorers.is_empty() {
                self.orphaned = self.state.running_trials();
                tracing::warn!("coordinator: no metric agent left: trials wait for one");
            }
        }
    }

    /// Trials whose lease expired are queued again.
    pub fn on_lease_tick(&mut self, now: i64) {
        for t in self.state.expire_leases(now, self.lease_ms as i64) {
            tracing::warn!("coordinator: lease of trial {t} expired: re-issuing");
        }
    }

    /// Time to publish the status (and to log what the run waits for, when that changed).
    pub fn on_status_tick(&mut self, now: i64) -> Vec<Action> {
        let s = self.status(now);
        if let Some(m) = self.waits.message(s.stamp_ms) {
            tracing::warn!("coordinator: run {:?} {m}", self.run);
        }
        vec![Action::Publish(s.clone()), Action::Progress(s)]
    }

    /// The run's status now: running once the trial space is known, waiting before.
    pub fn status(&self, now: i64) -> RunStatus {
        let phase = if self.space.is_some() {
            RunPhase::Running
        } else {
            RunPhase::Waiting
        };
        self.status_at(phase, now)
    }

    /// The run's status in `phase` (a finished run waits for nothing).
    pub fn status_at(&self, phase: RunPhase, now: i64) -> RunStatus {
        RunStatus {
            run_id: self.run.clone(),
            phase,
            object: self.spec.object.clone(),
            param_names: param_names(&self.spec),
            budget: self.spec.trials,
            completed: self.state.completed(),
            running: self.state.running(),
            failed: self.state.failed(),
            best: self.state.best().cloned(),
            best_history: self.state.best_history().to_vec(),
            workers: self.state.worker_statuses(),
            errors: self.state.errors(),
            stamp_ms: now,
            waiting: if phase == RunPhase::Finished {
                Vec::new()
            } else {
                self.waits.shown(now)
            },
            best_forces: self.state.best_forces().cloned(),
        }
    }

    /// Leases queued trials to idle workers: a journal write and a command each.
    fn issue_queued(&mut self, now: i64) -> anyhow::Result<Vec<Action>> {
        let Some((space, _)) = &self.space else {
            return Ok(Vec::new());
        };
        let mut out = Vec::new();
        let mut idle = self.state.idle_workers().into_iter();
        for (trial_id, reason) in self.state.queued() {
            let Some(worker) = idle.next() else { break };
            let lease_until = now + self.lease_ms as i64;
            let Some(attempt) = self.state.assign(trial_id, &worker, now, lease_until) else {
                continue;
            };
            let params = self
                .state
                .trial(trial_id)
                .map(|t| t.params.clone())
                .unwrap_or_default();
            let palm = space
                .palm_pose(&params)
                .with_context(|| format!("trial {trial_id}: palm pose"))?;
            out.push(Action::Record(Write::Issue(TrialIssue {
                run_id: self.run.as_str().to_string(),
                trial_id,
                attempt,
                params: params.clone(),
                worker: worker.clone(),
                at_ms: now,
                lease_until_ms: lease_until,
                reason,
            })));
            let command = TrialCommand {
                run_id: self.run.clone(),
                trial_id,
                attempt,
                worker: worker.clone(),
                hand: self.spec.hand.clone(),
                params,
                palm_pose: graspopt_convert::pose(&palm),
                lease_ms: self.lease_ms,
                issued_ms: now,
            };
            let encoding = self.encodings.get(&worker).copied();
            out.push(Action::Send {
                worker,
                encoding: encoding.unwrap_or(Encoding::Bincode),
                command,
            });
        }
        Ok(out)
    }

    /// The request for proposals when workers are idle (`None`: nothing to ask).
    fn plan_request(&mut self) -> Option<SuggestRequest> {
        let n = self.state.proposals_needed();
        let (_, bounds) = self.space.as_ref()?;
        if n == 0 {
            return None;
        }
        self.planner.request_id += 1;
        Some(SuggestRequest {
            run_id: self.run.clone(),
            request_id: self.planner.request_id,
            method: self.spec.method,
            bounds: bounds.clone(),
            seed: self.spec.seed,
            initial: self.spec.initial,
            observations: self.state.observations().to_vec(),
            pending: self.state.pending_points(),
            count: n as u32,
            engine_state: self.planner.engine_state.clone(),
        })
    }

    /// Queues the planner's proposals (as many as are still needed: the run may have moved
    /// on while the planner thought); the engine state it sent goes to `out`. Returns false
    /// when the planner gave none (it is asked again after [`PLANNER_RETRY_MS`]).
    fn take_proposals(
        &mut self,
        reply: Result<SuggestReply, BusError>,
        now: i64,
        out: &mut Vec<Action>,
    ) -> bool {
        let reply = match reply {
            Ok(r) => r,
            Err(e @ BusError::NoResponder { .. }) => {
                self.planner_down(&format!("no planner is running ({e})"), now);
                return false;
            }
            Err(e) => {
                self.planner_down(&e.to_string(), now);
                return false;
            }
        };
        if let Some(e) = reply.error {
            self.planner_down(&format!("the planner could not propose: {e}"), now);
            return false;
        }
        if let Some(engine) = reply.engine_state {
            out.push(Action::Record(Write::PlannerState {
                engine: engine.clone(),
                at_ms: now,
            }));
            self.planner.engine_state = Some(engine);
        }
        if let Some(since) = self.planner.down_since.take() {
            tracing::warn!(
                "coordinator: the planner answers again (after {:.1} s)",
                (now - since) as f64 / 1000.0
            );
        }
        let Some((_, bounds)) = &self.space else {
            return true;
        };
        // A point of another dimension, not finite or outside the trial space is not a
        // trial (it would fail its palm pose): counted, said, and not issued.
        let inside = |p: &[f64]| {
            p.len() == bounds.len()
                && p.iter()
                    .zip(bounds)
                    .all(|(x, [lo, hi])| x.is_finite() && lo <= x && x <= hi)
        };
        let n = self.state.proposals_needed();
        let (mut taken, mut refused) = (0, None);
        for p in reply.points.into_iter().take(n) {
            if inside(&p) {
                self.state.add_trial(p);
                taken += 1;
            } else {
                self.state.count_bad_message();
                refused.get_or_insert(p);
            }
        }
        match refused {
            Some(p) if taken == 0 => {
                let why = format!(
                    "the planner proposed only points outside the trial space, e.g. {p:?} (bounds {bounds:?})"
                );
                self.planner_down(&why, now);
                false
            }
            Some(p) => {
                tracing::warn!(
                    "coordinator: a proposal outside the trial space was left out: {p:?} (bounds {bounds:?})"
                );
                true
            }
            None => true,
        }
    }

    /// Logs that no proposal came: once when it starts, then at most every 10 s.
    fn planner_down(&mut self, why: &str, now: i64) {
        let link = &mut self.planner;
        match link.down_since {
            None => {
                link.down_since = Some(now);
                link.warned_ms = now;
                tracing::warn!("coordinator: no proposals: {why}; asking again every 0.5 s");
            }
            Some(since) if now - link.warned_ms >= 10_000 => {
                link.warned_ms = now;
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
    /// it stopped answering, or since a question went unanswered for
    /// [`waits::PLANNER_SLOW_MS`]).
    fn note_waits(&mut self, now: i64) {
        let since = |waiting: bool| waiting.then_some(now);
        self.waits.set(
            WaitReason::ObjectEstimate,
            self.space.is_none().then_some(self.started_ms),
        );
        self.waits
            .set(WaitReason::MetricAgent, since(self.scorers.is_empty()));
        self.waits
            .set(WaitReason::Hand, since(!self.state.has_workers()));
        let slow = self
            .planner
            .asking_since
            .filter(|t| now - t >= waits::PLANNER_SLOW_MS);
        self.waits
            .set(WaitReason::Planner, self.planner.down_since.or(slow));
    }
}

/// Logs what a result that completed nothing did.
fn log_disposition(result: &TrialResult, disposition: Disposition) {
    let (trial, attempt) = (result.trial_id, result.attempt);
    match disposition {
        Disposition::Unknown => {
            tracing::warn!("coordinator: result for unknown trial {trial}")
        }
        Disposition::Duplicate => {
            tracing::info!("coordinator: duplicate result for trial {trial}")
        }
        Disposition::NotIssued => tracing::warn!(
            "coordinator: result for trial {trial} attempt {attempt} from {}, which was never issued that attempt",
            result.worker
        ),
        Disposition::StaleFailure => tracing::warn!(
            "coordinator: attempt {attempt} of trial {trial} failed, a later attempt is running: ignored"
        ),
        Disposition::Completed | Disposition::Failed => {}
    }
}

/// A result as the journal records it.
pub(crate) fn journal_result(r: &TrialResult, at_ms: i64) -> TrialResultRecord {
    TrialResultRecord {
        run_id: r.run_id.as_str().to_string(),
        trial_id: r.trial_id,
        attempt: r.attempt,
        worker: r.worker.clone(),
        at_ms,
        score: r.score,
        metrics: r.metrics.clone(),
        contacts: r.contacts,
        fingers_in_contact: r.fingers_in_contact,
        cloud_points: r.cloud_points,
        details_json: serde_json::json!({
            "scorer": r.scorer,
            "cloud_transport": r.cloud_transport,
        })
        .to_string(),
        forces: r.forces.clone(),
    }
}

#[cfg(test)]
mod tests {
    use graspopt_protocol::{AgentKind, PlannerMethod, Pose};
    use graspopt_sim::ParamKind;

    use super::*;

    const LEASE: i64 = 1_000;

    /// A coordinator of run `r` (`trials` trials, one parameter), its object estimate in, a
    /// metric agent alive, and hands `workers`.
    fn coordinator(trials: u64, workers: &[&str]) -> Coordinator {
        let spec = RunSpec {
            object: "sphere".into(),
            hand: "barrett".into(),
            params: vec![ParamKind::Approach],
            bounds: None,
            trials,
            seed: 1,
            method: PlannerMethod::Random,
            initial: None,
            settings: None,
        };
        let run = RunId::new("r").unwrap();
        let mut c = Coordinator::new(&run, spec, RunState::new(trials), None, LEASE as u64, 0);
        c.on_estimate(&ObjectEstimate {
            run_id: run.clone(),
            object: "sphere".into(),
            mesh: None,
            pose: Pose::IDENTITY,
            seq: 1,
            stamp_ms: 0,
            source: "test".into(),
        })
        .unwrap();
        c.on_metric(&agent(AgentKind::Metric, "m"), true, 0);
        for w in workers {
            c.on_hand(&agent(AgentKind::Hand, w), true);
        }
        c
    }

    fn agent(kind: AgentKind, id: &str) -> AliveKey {
        AliveKey {
            run: RunId::new("r").unwrap(),
            kind,
            host: "h".into(),
            id: id.into(),
            encoding: Encoding::Bincode,
            publishes: None,
        }
    }

    fn reply(request: &SuggestRequest, points: Vec<Vec<f64>>) -> SuggestReply {
        SuggestReply {
            run_id: request.run_id.clone(),
            request_id: request.request_id,
            points,
            error: None,
            engine_state: Some(vec![7]),
        }
    }

    /// The request among `actions`.
    fn asked(actions: &[Action]) -> SuggestRequest {
        match actions {
            [.., Action::Ask(r)] => r.clone(),
            other => panic!("no question in {other:?}"),
        }
    }

    /// (trial, attempt, worker, reason) of each issue among `actions`, checking that each
    /// is followed by its command.
    fn issued(actions: &[Action]) -> Vec<(u64, u32, String, Option<String>)> {
        let mut out = Vec::new();
        for (i, a) in actions.iter().enumerate() {
            if let Action::Record(Write::Issue(issue)) = a {
                let Some(Action::Send {
                    worker, command, ..
                }) = actions.get(i + 1)
                else {
                    panic!("issue without its command: {actions:?}")
                };
                assert_eq!(
                    (worker, command.trial_id, command.attempt),
                    (&issue.worker, issue.trial_id, issue.attempt)
                );
                let reason = issue.reason.clone();
                out.push((issue.trial_id, issue.attempt, issue.worker.clone(), reason));
            }
        }
        out
    }

    fn result(trial_id: u64, attempt: u32, worker: &str, score: f64) -> TrialResult {
        TrialResult {
            attempt,
            ..crate::state::tests::result(trial_id, worker, score)
        }
    }

    fn records(actions: &[Action]) -> Vec<&Write> {
        actions
            .iter()
            .filter_map(|a| match a {
                Action::Record(w) => Some(w),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn an_expired_lease_re_issues_the_trial_once_the_silent_worker_is_freed() {
        let mut c = coordinator(1, &["a"]);
        let request = asked(&c.poll(0).unwrap());
        assert_eq!((request.count, request.request_id), (1, 1));
        let actions = c
            .on_reply(Ok(reply(&request, vec![vec![0.01]])), 10)
            .unwrap();
        assert_eq!(
            actions[0],
            Action::Record(Write::PlannerState {
                engine: vec![7],
                at_ms: 10
            })
        );
        assert_eq!(issued(&actions), [(1, 1, "a".into(), None)]);
        // The lease runs out: the trial is queued again, its worker busy for the grace.
        c.on_lease_tick(10 + LEASE);
        assert!(c.poll(10 + LEASE).unwrap().is_empty());
        c.on_lease_tick(11 + LEASE);
        assert!(issued(&c.poll(11 + LEASE).unwrap()).is_empty());
        assert_eq!(c.status(11 + LEASE).errors.reissued, 1);
        // After the grace the lone worker is free and gets the trial again: attempt 2.
        c.on_lease_tick(12 + 2 * LEASE);
        let again = c.poll(12 + 2 * LEASE).unwrap();
        let why = Some("lease of worker a expired".to_string());
        assert_eq!(issued(&again), [(1, 2, "a".into(), why)]);
        let Some(Action::Send { command, .. }) = again.get(1) else {
            panic!("{again:?}")
        };
        assert_eq!(command.lease_ms, LEASE as u64);
        assert_eq!(command.issued_ms, 12 + 2 * LEASE);
    }

    /// The loop commits one event's writes together, then carries out the rest: the
    /// issues of one planner reply are one batch, their commands keep their order.
    #[test]
    fn a_reply_s_issues_are_one_batch_before_its_commands() {
        let mut c = coordinator(3, &["a", "b", "c"]);
        let request = asked(&c.poll(0).unwrap());
        let points = vec![vec![-0.1], vec![-0.05], vec![0.0]];
        let actions = c.on_reply(Ok(reply(&request, points)), 5).unwrap();
        let (writes, rest) = crate::run::split_writes(actions);
        let issues: Vec<(u64, &str)> = writes
            .iter()
            .filter_map(|w| match w {
                Write::Issue(i) => Some((i.trial_id, i.worker.as_str())),
                _ => None,
            })
            .collect();
        assert!(matches!(writes[0], Write::PlannerState { .. }));
        assert_eq!(issues, [(1, "a"), (2, "b"), (3, "c")]);
        let sent: Vec<(u64, &str)> = rest
            .iter()
            .filter_map(|a| match a {
                Action::Send {
                    worker, command, ..
                } => Some((command.trial_id, worker.as_str())),
                _ => None,
            })
            .collect();
        assert_eq!(sent, issues);
        assert!(!rest.iter().any(|a| matches!(a, Action::Record(_))));
    }

    /// A planner's point outside the trial space (or not finite) is counted and left out;
    /// it failed the whole coordinator before (its palm pose is refused when issued). A
    /// reply of such points only is a planner that cannot propose: asked again later.
    #[test]
    fn proposals_outside_the_trial_space_are_left_out() {
        let mut c = coordinator(3, &["a", "b", "c"]);
        let request = asked(&c.poll(0).unwrap());
        let points = vec![vec![0.5], vec![-0.1], vec![f64::NAN]];
        let actions = c.on_reply(Ok(reply(&request, points)), 5).unwrap();
        assert_eq!(issued(&actions), [(1, 1, "a".into(), None)]);
        assert_eq!(c.status(5).errors.bad_messages, 2);
        // Another question for the two still needed, at once.
        let request = asked(&c.poll(6).unwrap());
        assert_eq!(request.count, 2);
        let actions = c
            .on_reply(Ok(reply(&request, vec![vec![-0.2], vec![0.03]])), 7)
            .unwrap();
        assert!(issued(&actions).is_empty());
        assert_eq!(c.status(7).errors.bad_messages, 4);
        // Only bad points: asked again after the retry delay, not at once.
        assert!(c.poll(8).unwrap().is_empty());
        let request = asked(&c.poll(7 + PLANNER_RETRY_MS).unwrap());
        let actions = c
            .on_reply(Ok(reply(&request, vec![vec![-0.16], vec![0.02]])), 600)
            .unwrap();
        assert_eq!(
            issued(&actions).len(),
            2,
            "the bounds themselves are inside"
        );
    }

    #[test]
    fn a_duplicate_result_is_recorded_once_and_counted() {
        let mut c = coordinator(1, &["a"]);
        let request = asked(&c.poll(0).unwrap());
        c.on_reply(Ok(reply(&request, vec![vec![0.01]])), 0)
            .unwrap();
        let first = c.on_result(&result(1, 1, "a", 0.5), 100);
        let [Write::Result(r)] = records(&first)[..] else {
            panic!("{first:?}")
        };
        assert_eq!((r.trial_id, r.attempt, r.score, r.at_ms), (1, 1, 0.5, 100));
        assert!(c.finished());
        let again = c.on_result(&result(1, 1, "a", 0.9), 200);
        assert!(records(&again).is_empty(), "{again:?}");
        let [Action::Progress(s)] = &again[..] else {
            panic!("{again:?}")
        };
        assert_eq!((s.completed, s.errors.duplicates), (1, 1));
        assert_eq!(s.best.as_ref().unwrap().score, 0.5);
        // A result never issued is counted and not recorded either.
        let stray = c.on_result(&result(1, 1, "b", 0.7), 300);
        assert!(records(&stray).is_empty());
        assert_eq!(c.status(300).errors.not_issued, 1);
    }

    #[test]
    fn a_planner_down_is_asked_again_and_waited_for_until_it_is_back() {
        let mut c = coordinator(2, &["a", "b"]);
        let first = asked(&c.poll(0).unwrap());
        let key = "graspopt/r/planner/suggest".to_string();
        let none = c.on_reply(Err(BusError::NoResponder { key }), 10).unwrap();
        assert!(none.is_empty());
        // Not asked again before the retry time; then asked again with a new id.
        assert!(c.poll(10 + PLANNER_RETRY_MS - 1).unwrap().is_empty());
        let second = asked(&c.poll(10 + PLANNER_RETRY_MS).unwrap());
        assert_eq!((first.request_id, second.request_id), (1, 2));
        // The run shows it waits for the planner (since it went down) once that lasts.
        let s = c.status(2_000);
        assert_eq!(s.waiting.len(), 1);
        assert_eq!(
            (s.waiting[0].reason, s.waiting[0].since_ms),
            (WaitReason::Planner, 10)
        );
        // A planner appears: the question in flight is dropped and asked again at once.
        let planner = agent(AgentKind::Planner, "p");
        assert_eq!(
            c.on_planner_alive(&planner, true, 2_000),
            [Action::CancelAsk]
        );
        assert!(c.on_planner_alive(&planner, true, 2_001).is_empty());
        let third = asked(&c.poll(2_001).unwrap());
        assert_eq!((third.request_id, third.count), (3, 2));
        let actions = c
            .on_reply(Ok(reply(&third, vec![vec![0.01], vec![0.02]])), 2_100)
            .unwrap();
        assert_eq!(issued(&actions).len(), 2);
        c.poll(2_100).unwrap();
        assert!(c.status(4_000).waiting.is_empty());
        // Later requests carry the engine state the planner sent.
        assert_eq!(c.planner.engine_state, Some(vec![7]));
    }

    #[test]
    fn bad_proposals_and_messages_are_counted_and_a_wrong_object_stops_the_run() {
        let mut c = coordinator(2, &["a", "b"]);
        let request = asked(&c.poll(0).unwrap());
        let actions = c
            .on_reply(Ok(reply(&request, vec![vec![0.01, 0.0], vec![0.02]])), 0)
            .unwrap();
        assert_eq!(issued(&actions), [(1, 1, "a".into(), None)]);
        c.on_bad_message();
        assert_eq!(c.status(0).errors.bad_messages, 2);
        let mut other = Coordinator::new(
            &RunId::new("r").unwrap(),
            c.spec().clone(),
            RunState::new(1),
            None,
            1,
            0,
        );
        let mug = ObjectEstimate {
            run_id: RunId::new("r").unwrap(),
            object: "mug".into(),
            mesh: None,
            pose: Pose::IDENTITY,
            seq: 1,
            stamp_ms: 0,
            source: "p".into(),
        };
        let e = other.on_estimate(&mug).unwrap_err().to_string();
        assert_eq!(e, "perception sees \"mug\", the run is about \"sphere\"");
    }
}
