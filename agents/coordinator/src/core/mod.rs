//! The coordinator's core: the rules of a run as a state machine without I/O. Every
//! [`Event`] (a turn of the loop, a result, an estimate, a worker coming or going, a planner
//! reply, a timer) goes through [`Coordinator::handle`] with the time (`now`, milliseconds
//! since the epoch), which returns the [`Action`]s to carry out, in order: journal writes,
//! commands to send, questions to the planner, status to publish. The async loop in
//! [`crate::run`](mod@crate::run) only moves messages and timers.
//!
//! - `planner`: asking the planner and taking its proposals.
//! - `trials`: leasing queued trials and accepting their results.
//! - `workers`: hand workers and metric agents coming and going.
//! - `status`: the run's status and what it waits for.
//!
//! To handle a new event: a variant of [`Event`], its arm in [`Coordinator::handle`], and a
//! method in the submodule of its concern returning the actions.

use std::collections::{HashMap, HashSet};

use graspopt_bus::{AliveEvent, BusError};
use graspopt_protocol::{Encoding, ObjectEstimate, RunId, SuggestReply, TrialResult};
use graspopt_sim::TrialSpace;

use crate::error::CoordinatorError;
use crate::spec::{RunSpec, trial_space};
use crate::state::RunState;
use crate::waits::Waits;

mod planner;
mod status;
mod trials;
mod workers;

pub use planner::PLANNER_RETRY_MS;
#[cfg(test)]
pub(crate) use trials::journal_result;

/// A write to the run's journal (what a batch of them keeps: `graspopt_journal::batch`).
pub use graspopt_journal::Write;

/// What the loop does for the core, in the order given, except that the journal writes of
/// one call are committed together before the rest (see [`crate::run::record`]): a write
/// only ever comes earlier, never a command before its issue.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    Write(Write),
    /// Sends a trial command to a worker, in the encoding it asked for.
    Send {
        worker: String,
        encoding: Encoding,
        command: graspopt_protocol::TrialCommand,
    },
    /// Asks the planner (answered with [`Event::Reply`]).
    Ask(graspopt_protocol::SuggestRequest),
    /// Drops the question in flight (the planner came back: ask again at once).
    CancelAsk,
    /// Publishes the run's status on the bus.
    Publish(graspopt_protocol::RunStatus),
    /// Hands the run's status to whoever follows the run in-process.
    Progress(graspopt_protocol::RunStatus),
}

/// What the core is told: each is handled by [`Coordinator::handle`].
#[derive(Debug)]
pub enum Event {
    /// A turn of the loop, between events: queued trials are leased to idle workers and the
    /// planner asked for more (once the trial space is known and a metric agent listens),
    /// and what the run waits for is noted.
    Poll,
    /// The planner's reply (or why none came) to the question in flight.
    Reply(Result<SuggestReply, BusError>),
    /// A result of this run: journaled if it is the first of an attempt issued to the
    /// worker it names; counted otherwise.
    Result(Box<TrialResult>),
    /// A message that was not acted on (it did not decode, or named another run): counted.
    BadMessage,
    /// An object estimate of this run: the first one sets the trial space.
    Estimate(Box<ObjectEstimate>),
    /// A hand worker's token came or went: a worker lost with a trial has it re-issued.
    Hand(AliveEvent),
    /// A metric agent's token came or went. Trials wait while none is alive (clouds sent to
    /// nobody are lost); the ones running when the last left are re-issued once one is back.
    Metric(AliveEvent),
    /// A planner's token came or went: one (re)appearing answers at once, so a question in
    /// flight when the network was cut is dropped and asked again.
    Planner(AliveEvent),
    /// The lease timer: trials whose lease expired are queued again.
    LeaseTick,
    /// Time to publish the status (and to log what the run waits for, when that changed).
    StatusTick,
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
    planner: planner::PlannerLink,
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
            planner: planner::PlannerLink::new(engine_state, now),
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

    /// Handles `event` at `now`: the actions to carry out, in order. An error stops the run
    /// (an object other than the run's, a proposal without a palm pose).
    pub fn handle(&mut self, event: Event, now: i64) -> Result<Vec<Action>, CoordinatorError> {
        let nothing = Vec::new();
        Ok(match event {
            Event::Poll => self.poll(now)?,
            Event::Reply(reply) => self.on_reply(reply, now)?,
            Event::Result(result) => self.on_result(&result, now),
            Event::BadMessage => {
                self.state.count_bad_message();
                nothing
            }
            Event::Estimate(estimate) => {
                self.on_estimate(&estimate)?;
                nothing
            }
            Event::Hand(e) => {
                self.on_hand(&e.agent, e.alive);
                nothing
            }
            Event::Metric(e) => {
                self.on_metric(&e.agent, e.alive, now);
                nothing
            }
            Event::Planner(e) => self.on_planner_alive(&e.agent, e.alive, now),
            Event::LeaseTick => {
                self.on_lease_tick(now);
                nothing
            }
            Event::StatusTick => self.on_status_tick(now),
        })
    }

    /// What to do between events: lease queued trials to idle workers and ask the planner
    /// for more (once the trial space is known and a metric agent listens), and note what
    /// the run waits for.
    fn poll(&mut self, now: i64) -> Result<Vec<Action>, CoordinatorError> {
        let mut out = Vec::new();
        if self.space.is_some() && !self.scorers.is_empty() {
            out = self.issue_queued(now)?;
            out.extend(self.ask(now));
        }
        self.note_waits(now);
        Ok(out)
    }

    /// An object estimate of this run: the first one sets the trial space.
    fn on_estimate(&mut self, estimate: &ObjectEstimate) -> Result<(), CoordinatorError> {
        if self.space.is_none() {
            if estimate.object != self.spec.object {
                return Err(CoordinatorError::WrongObject {
                    seen: estimate.object.clone(),
                    expected: self.spec.object.clone(),
                });
            }
            self.space = Some(trial_space(&self.spec, estimate)?);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
