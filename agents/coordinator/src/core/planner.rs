//! The core's link to the planner: when to ask for proposals, what to ask, and what its
//! reply (or its silence) does to the run.

use graspopt_bus::BusError;
use graspopt_protocol::keys::AliveKey;
use graspopt_protocol::{SuggestReply, SuggestRequest};

use super::{Action, Coordinator, Write};
use crate::error::CoordinatorError;

/// After a question the planner did not answer, how long until it is asked again.
pub const PLANNER_RETRY_MS: i64 = 500;

/// The link to the planner.
#[derive(Debug, Default)]
pub(super) struct PlannerLink {
    /// When the question in flight was asked (`None`: none is).
    pub(super) asking_since: Option<i64>,
    /// No question before this time.
    retry_at_ms: i64,
    /// When the planner stopped giving proposals (`None`: it gives them).
    pub(super) down_since: Option<i64>,
    /// When that was last logged.
    warned_ms: i64,
    /// The planner's engine after its last reply (also in the journal), sent back with
    /// every request: a planner that lost it (restarted) continues from it exactly.
    pub(super) engine_state: Option<Vec<u8>>,
    request_id: u64,
}

impl PlannerLink {
    /// A link with the engine state recorded in the journal, free to ask from `now`.
    pub(super) fn new(engine_state: Option<Vec<u8>>, now: i64) -> PlannerLink {
        PlannerLink {
            engine_state,
            retry_at_ms: now,
            ..PlannerLink::default()
        }
    }
}

impl Coordinator {
    /// The question to the planner, when none is in flight, its retry time has come and
    /// workers are idle.
    pub(super) fn ask(&mut self, now: i64) -> Option<Action> {
        if self.planner.asking_since.is_some() || now < self.planner.retry_at_ms {
            return None;
        }
        let request = self.plan_request()?;
        self.planner.asking_since = Some(now);
        Some(Action::Ask(request))
    }

    /// The planner's reply (or why none came) to the question in flight.
    pub(super) fn on_reply(
        &mut self,
        reply: Result<SuggestReply, BusError>,
        now: i64,
    ) -> Result<Vec<Action>, CoordinatorError> {
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
    pub(super) fn on_planner_alive(
        &mut self,
        agent: &AliveKey,
        alive: bool,
        now: i64,
    ) -> Vec<Action> {
        if !(alive && agent.run == self.run && self.planner.asking_since.is_some()) {
            return Vec::new();
        }
        self.planner.asking_since = None;
        self.planner.retry_at_ms = now;
        vec![Action::CancelAsk]
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
            out.push(Action::Write(Write::PlannerState {
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
        self.queue_points(reply.points, now)
    }

    /// Queues the points inside the trial space, as many as are still needed. A point of
    /// another dimension, not finite or outside the trial space is not a trial (it would
    /// fail its palm pose): counted, said, and not queued. Returns false when every point
    /// was refused (the planner cannot propose: asked again later).
    fn queue_points(&mut self, points: Vec<Vec<f64>>, now: i64) -> bool {
        let Some((_, bounds)) = &self.space else {
            return true;
        };
        let inside = |p: &[f64]| {
            p.len() == bounds.len()
                && p.iter()
                    .zip(bounds)
                    .all(|(x, [lo, hi])| x.is_finite() && lo <= x && x <= hi)
        };
        let n = self.state.proposals_needed();
        let (mut taken, mut refused) = (0, None);
        for p in points.into_iter().take(n) {
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
}
