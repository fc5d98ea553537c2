//! The coordinator's async loop: it owns the bus, the timers and the journal, turns what
//! arrives into [`Event`]s for the [`Coordinator`] core and carries out the actions it
//! returns, all in one place (`drive`).

use std::time::Duration;

use graspopt_bus::{AliveWatch, Bus, BusError, Inbox, Received, Server, Subscription, now_ms};
use graspopt_journal::{Journal, ResultOutcome, StoredRunPhase, Written};
use graspopt_protocol::keys::{COMMAND, OBJECT, RESULT, STATE, STATUS, SUGGEST, alive_key};
use graspopt_protocol::{
    AgentKind, Encoding, ObjectEstimate, RunId, RunPhase, RunStatus, SuggestReply, TrialResult,
};
use tokio::sync::watch;

use crate::CoordinatorConfig;
use crate::core::{Action, Coordinator, Event, Write};
use crate::error::CoordinatorError;
use crate::spec::{RunSpec, open_journal, open_run};

/// A proposal request on its way to the planner.
type PlannerCall<'a> = std::pin::Pin<
    Box<dyn std::future::Future<Output = Result<SuggestReply, BusError>> + Send + 'a>,
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
) -> Result<RunStatus, CoordinatorError> {
    let forever = std::future::pending();
    run_until(bus, run, spec, config, resume, progress, forever).await
}

/// [`run`], stopping early when `stop` resolves (Ctrl-C, say): the journal then records the
/// run as stopped (every result already in stays; `--resume` continues it) and the status
/// returned has the phase it had. Another live coordinator of the run is an error: found at
/// the start, or later, when both took the run at the same moment and this one gives way
/// (every result already in the journal stays).
pub async fn run_until(
    bus: &Bus,
    run: &RunId,
    spec: &RunSpec,
    config: &CoordinatorConfig,
    resume: bool,
    progress: Option<watch::Sender<RunStatus>>,
    stop: impl std::future::Future<Output = ()>,
) -> Result<RunStatus, CoordinatorError> {
    config
        .validate()
        .map_err(|e| CoordinatorError::Settings(Box::new(e)))?;
    // Two coordinators on one run would issue each trial twice and fight over the journal.
    let place = bus
        .wait_until_unique(run, AgentKind::Coordinator, None, Duration::from_secs(5))
        .await?;
    let journal_path = config.journal_path(run);
    let mut journal = open_journal(&journal_path)?;
    let (spec, state) = open_run(&mut journal, run, spec, resume)?;
    let engine_state = journal.planner_state(run.as_str())?;
    let inputs = Inputs::open(bus, run).await?;
    let _token = bus
        .declare_alive(run, AgentKind::Coordinator, &config.id)
        .await?;
    let mut core = Coordinator::new(run, spec, state, engine_state, config.lease_ms, now_ms());
    let mut io = Io {
        bus,
        run,
        journal: &mut journal,
        progress,
        planner_timeout: Duration::from_millis(config.planner_timeout_ms),
    };
    let period = Duration::from_millis(config.status_period_ms.max(20));
    if drive(&mut core, &inputs, &mut io, period, stop, place.lost()).await? {
        io.stopped(&core, &journal_path).await
    } else {
        io.finished(&core).await
    }
}

/// What the coordinator listens to.
struct Inputs {
    results: Subscription<TrialResult>,
    objects: Subscription<ObjectEstimate>,
    hands: AliveWatch,
    metrics: AliveWatch,
    planners: AliveWatch,
    state_server: Server<()>,
}

impl Inputs {
    async fn open(bus: &Bus, run: &RunId) -> Result<Inputs, BusError> {
        let alive = |kind| alive_key(run.into(), Some(kind));
        Ok(Inputs {
            results: bus.subscribe(&RESULT.key(run.into())).await?,
            objects: bus.subscribe(&OBJECT.key(run.into())).await?,
            hands: bus.watch_alive(&alive(AgentKind::Hand)).await?,
            // Trials wait for a metric agent: clouds published before one listens would be
            // lost.
            metrics: bus.watch_alive(&alive(AgentKind::Metric)).await?,
            // A planner (re)appearing answers at once: a question in flight when the
            // network was cut would otherwise wait for its timeout.
            planners: bus.watch_alive(&alive(AgentKind::Planner)).await?,
            state_server: bus.serve(&STATE.key(run)).await?,
        })
    }
}

/// Feeds events to `core` until the run finishes (false) or `stop` resolves (true): each
/// turn, what arrived becomes [`Event`]s, handled one after the other, and their actions
/// are carried out together. The planner's answer is awaited beside everything else, so
/// results, leases and workers are still handled while it thinks or while the bus cannot
/// reach it. Should `lost` resolve (another coordinator holds the run too, see
/// [`graspopt_bus::Claim::lost`]), it stops with that error: what is in the journal stays,
/// and the run's status there is the other coordinator's to write.
async fn drive<'a>(
    core: &mut Coordinator,
    inputs: &Inputs,
    io: &mut Io<'a>,
    status_period: Duration,
    stop: impl std::future::Future<Output = ()>,
    lost: impl std::future::Future<Output = BusError>,
) -> Result<bool, CoordinatorError> {
    tokio::pin!(stop);
    tokio::pin!(lost);
    let mut tick = tokio::time::interval(status_period);
    let mut lease_tick = tokio::time::interval(Duration::from_millis(50));
    let mut planning: Option<PlannerCall<'a>> = None;
    let mut inbox = Inbox::new("coordinator", core.run());
    loop {
        if core.finished() {
            return Ok(false);
        }
        let actions = core.handle(Event::Poll, now_ms())?;
        io.apply(actions, &mut planning).await?;
        let events = tokio::select! {
            reply = async {
                match planning.as_mut() {
                    Some(call) => call.await,
                    None => std::future::pending().await,
                }
            }, if planning.is_some() => {
                planning = None;
                vec![Event::Reply(reply)]
            },
            Some(r) = inputs.results.recv() => results(inputs, &mut inbox, r),
            Some(r) = inputs.objects.recv() => {
                let estimate = inbox.accept(r, "object estimate");
                vec![estimate.map_or(Event::BadMessage, |e| Event::Estimate(Box::new(e)))]
            },
            Some(e) = inputs.hands.recv() => vec![Event::Hand(e)],
            Some(e) = inputs.planners.recv() => vec![Event::Planner(e)],
            Some(e) = inputs.metrics.recv() => vec![Event::Metric(e)],
            Some(q) = inputs.state_server.recv() => {
                let _ = q.reply(&core.status(now_ms())).await;
                Vec::new()
            },
            _ = lease_tick.tick() => vec![Event::LeaseTick],
            _ = &mut stop => return Ok(true),
            e = &mut lost => return Err(e.into()),
            _ = tick.tick() => vec![Event::StatusTick],
        };
        let mut actions = Vec::new();
        for event in events {
            actions.extend(core.handle(event, now_ms())?);
        }
        io.apply(actions, &mut planning).await?;
    }
}

/// At most this many results already arrived are handled as one event (a flood of them
/// does not hold back timers and workers).
const RESULTS_AT_ONCE: usize = 256;

/// The results that arrived together, `first` and up to [`RESULTS_AT_ONCE`] in all, and a
/// turn of the loop after them: their writes and the issues of the trials their workers
/// take next make one commit.
fn results(inputs: &Inputs, inbox: &mut Inbox, first: Received<TrialResult>) -> Vec<Event> {
    let mut events = vec![result(inbox, first)];
    for _ in 1..RESULTS_AT_ONCE {
        let Some(r) = inputs.results.try_recv() else {
            break;
        };
        events.push(result(inbox, r));
    }
    events.push(Event::Poll);
    events
}

/// A result from the bus, as the core is told it.
fn result(inbox: &mut Inbox, r: Received<TrialResult>) -> Event {
    match inbox.accept(r, "result") {
        Some(result) => Event::Result(Box::new(result)),
        None => Event::BadMessage,
    }
}

/// What carries out the core's actions.
struct Io<'a> {
    bus: &'a Bus,
    run: &'a RunId,
    journal: &'a mut Journal,
    progress: Option<watch::Sender<RunStatus>>,
    planner_timeout: Duration,
}

impl<'a> Io<'a> {
    async fn apply(
        &mut self,
        actions: Vec<Action>,
        planning: &mut Option<PlannerCall<'a>>,
    ) -> Result<(), CoordinatorError> {
        // The journal first, in one transaction: each write comes at most earlier than
        // the core listed it, so no command goes out before its issue is committed.
        let (writes, rest) = split_writes(actions);
        write_journal(self.journal, self.run, &writes)?;
        for action in rest {
            match action {
                // Committed above.
                Action::Write(_) => {}
                Action::Send {
                    worker,
                    encoding,
                    command,
                } => {
                    let key = COMMAND.worker_key(self.run.into(), &worker);
                    self.bus.put(&key, &command, encoding).await?;
                }
                Action::Ask(request) => {
                    let (bus, key) = (self.bus, SUGGEST.key(self.run));
                    let timeout = self.planner_timeout;
                    *planning = Some(Box::pin(
                        async move { bus.query(&key, &request, timeout).await },
                    ));
                }
                Action::CancelAsk => *planning = None,
                Action::Publish(s) => {
                    let key = STATUS.key(self.run.into());
                    let _ = self.bus.put_droppable(&key, &s, Encoding::Bincode).await;
                }
                Action::Progress(s) => {
                    if let Some(p) = &self.progress {
                        let _ = p.send(s);
                    }
                }
            }
        }
        Ok(())
    }

    /// The run finished: recorded, its final status published.
    async fn finished(mut self, core: &Coordinator) -> Result<RunStatus, CoordinatorError> {
        let run = self.run.as_str();
        self.journal
            .set_run_phase(run, StoredRunPhase::Finished, now_ms())?;
        let s = core.status_at(RunPhase::Finished, now_ms());
        self.last_status(&s).await;
        Ok(s)
    }

    /// Publishes the run's last status, and gives it to the progress watcher.
    async fn last_status(&mut self, s: &RunStatus) {
        let _ = self
            .bus
            .put(&STATUS.key(self.run.into()), s, Encoding::Bincode)
            .await;
        if let Some(p) = &self.progress {
            let _ = p.send(s.clone());
        }
    }

    /// The run was stopped: recorded (its status, published, says so), and said how to go
    /// on.
    async fn stopped(
        mut self,
        core: &Coordinator,
        path: &std::path::Path,
    ) -> Result<RunStatus, CoordinatorError> {
        let run = self.run;
        self.journal
            .set_run_phase(run.as_str(), StoredRunPhase::Stopped, now_ms())?;
        let s = core.status_at(RunPhase::Stopped, now_ms());
        self.last_status(&s).await;
        let waiting = if s.waiting.is_empty() {
            String::new()
        } else {
            let waits = graspopt_protocol::describe_waits(&s.waiting, s.stamp_ms);
            format!(" while waiting ({waits})")
        };
        // A run that issued no trial is started afresh by the same command (see `open_run`).
        let unstarted = s.completed + s.failed + s.running == 0
            && self
                .journal
                .trials(run.as_str())
                .is_ok_and(|t| t.is_empty());
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
            path.display()
        );
        Ok(s)
    }
}

/// The journal writes among `actions`, in order, and the other actions, in order (what
/// the loop commits at once, then carries out).
pub fn split_writes(actions: Vec<Action>) -> (Vec<Write>, Vec<Action>) {
    let mut writes = Vec::new();
    let mut rest = Vec::with_capacity(actions.len());
    for action in actions {
        match action {
            Action::Write(write) => writes.push(write),
            other => rest.push(other),
        }
    }
    (writes, rest)
}

/// Carries out journal writes of the core in one transaction (the loop's, and `graspopt
/// bench coordinator`'s): what one event decided, the issues of a planner reply or the
/// results that arrived together, costs one commit. A result the journal does not accept
/// (a duplicate, say) is logged; a planner state that cannot be kept is only logged (see
/// [`Write::PlannerState`]); any other refusal, or a transaction that cannot commit, is an
/// error, returned before any command of these writes is sent.
pub fn write_journal(
    journal: &mut Journal,
    run: &RunId,
    writes: &[Write],
) -> Result<(), CoordinatorError> {
    if writes.is_empty() {
        return Ok(());
    }
    let outcomes = journal
        .write(run.as_str(), writes)
        .map_err(CoordinatorError::Commit)?;
    for (write, outcome) in writes.iter().zip(outcomes) {
        match (write, outcome) {
            (_, Ok(Written::Result(ResultOutcome::Accepted))) => {}
            (Write::Result(r), Ok(Written::Result(other))) => tracing::warn!(
                "coordinator: journal says {other:?} for trial {}",
                r.trial_id
            ),
            (_, Ok(_)) => {}
            (Write::PlannerState { .. }, Err(e)) => {
                tracing::warn!("coordinator: cannot keep the planner's state in the journal: {e}")
            }
            (_, Err(e)) => return Err(e.into()),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use graspopt_protocol::PlannerMethod;
    use graspopt_protocol::keys::{Claim, ClaimPhase, claim_token};
    use graspopt_sim::ParamKind;

    use super::*;

    /// A coordinator whose run turns out to be held by another with a smaller nonce (both
    /// took it at the same moment; the other's claim, declared here by hand, reached it
    /// late) stops with the error naming the place, and leaves the journal's record of the
    /// run as it was: still running, not marked stopped (that is the other's to write).
    #[test]
    fn a_coordinator_gives_way_to_one_that_holds_its_run_with_a_smaller_nonce() {
        let rt = tokio::runtime::Runtime::new().unwrap();
        rt.block_on(async {
            // The coordinator on the session that connects: one that only listens meets
            // nobody and holds its run unchallenged.
            let sessions = Bus::loopback(1).await.unwrap();
            let (hub, bus) = (sessions.hub, sessions.peers.into_iter().next().unwrap());
            assert!(bus.reaches_out());
            let dir = tempfile::tempdir().unwrap();
            let config = CoordinatorConfig {
                journal: dir.path().join("journal.sqlite"),
                ..CoordinatorConfig::default()
            };
            let run_id = RunId::new("givewayrun").unwrap();
            let spec = RunSpec {
                object: "sphere".into(),
                hand: "barrett".into(),
                params: vec![ParamKind::Approach],
                bounds: None,
                trials: 5,
                seed: 1,
                method: PlannerMethod::Random,
                initial: None,
                settings: None,
            };
            let coordinators = hub
                .watch_alive(&alive_key((&run_id).into(), Some(AgentKind::Coordinator)))
                .await
                .unwrap();
            let (outcome, _other) = tokio::join!(
                tokio::time::timeout(
                    Duration::from_secs(10),
                    run(&bus, &run_id, &spec, &config, false, None)
                ),
                async {
                    let alive = coordinators.recv().await.unwrap();
                    assert!(alive.alive, "{alive:?}");
                    let claim = Claim {
                        nonce: 0,
                        phase: ClaimPhase::Settled,
                    };
                    let key = claim_token(&run_id, AgentKind::Coordinator, "any", claim);
                    hub.session().liveliness().declare_token(key).await.unwrap()
                },
            );
            let e = outcome
                .expect("the coordinator gives way within 10 s")
                .expect_err("an error");
            assert_eq!(
                e.to_string(),
                "run \"givewayrun\": another agent, a coordinator, took its place at the same \
                 moment and keeps it: this one gives way"
            );
            let journal = Journal::open(&config.journal).unwrap();
            let record = journal.run(run_id.as_str()).unwrap().expect("the run");
            assert_eq!(record.status, StoredRunPhase::Running);
            drop(journal);
            let _ = bus.close().await;
            let _ = hub.close().await;
        });
    }
}
