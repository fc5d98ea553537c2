//! Liveliness: every agent declares a token `graspopt/<run>/alive/<kind>/<host>/<id>`; the
//! coordinator and tools watch them. A token vanishes when its process dies or loses the
//! network, which is how a killed hand worker is noticed.

use graspopt_protocol::keys::{
    AliveKey, Claim as ClaimKey, ClaimPhase, alive_key, alive_token, claim_slot_key, claim_token,
    parse_alive_key, parse_claim_key,
};
use graspopt_protocol::{AgentKind, RunId, Topic};
use tokio::sync::watch;
use zenoh::handlers::FifoChannelHandler;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::sample::{Sample, SampleKind};

use crate::task::OwnedTask;
use crate::{Bus, BusError};

/// An agent appeared or vanished.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AliveEvent {
    pub alive: bool,
    pub agent: AliveKey,
}

/// A stream of [`AliveEvent`]s, starting with the agents already alive.
pub struct AliveWatch {
    sub: Subscriber<FifoChannelHandler<Sample>>,
}

impl AliveWatch {
    /// The next event; `None` when the session closed. Keys that are not agent tokens are
    /// skipped.
    pub async fn recv(&self) -> Option<AliveEvent> {
        loop {
            let sample = self.sub.recv_async().await.ok()?;
            if let Some(agent) = parse_alive_key(sample.key_expr().as_str()) {
                return Some(AliveEvent {
                    alive: sample.kind() == SampleKind::Put,
                    agent,
                });
            }
        }
    }
}

/// Empty answers in a row after which [`Bus::wait_until_unique`] takes a place as free.
pub const UNIQUE_CHECKS: u32 = 6;

/// Looks at the other claims of a place, 150 ms apart, before [`Bus::wait_until_unique`]
/// holds it, and once more after. Agents that claim together settle it in these looks when
/// liveliness reaches them within about 150 ms; later than that, both may hold the place
/// until their [`Claim`]s see each other (see [`Claim::lost`]).
pub const CLAIM_CHECKS: u32 = 2;

/// Pause between two looks at the claims of a place.
const CLAIM_LOOK: std::time::Duration = std::time::Duration::from_millis(150);

/// How long an agent holds its place before it settles in it ([`ClaimPhase::Settled`]). A
/// holder that has not settled yet gives way to a smaller nonce held (an agent that took
/// the place at the same moment) and to anyone settled; a settled one gives way only to a
/// smaller nonce settled. So a newcomer whose view of the claims came late (it found the
/// place free and held it) gives way to the agent that held the place before it, whatever
/// their nonces, unless its view stayed blind for longer than this after it held.
pub const SETTLE_AFTER: std::time::Duration = std::time::Duration::from_secs(2);

/// A place in a run held by this agent (see [`Bus::wait_until_unique`]): keep it as long as
/// the agent runs; it is released when dropped or when the process dies.
///
/// While held, it watches the other held claims of the place: an agent that took the place
/// at the same moment (its claim reached this one late) and comes first by the rule of
/// [`SETTLE_AFTER`] takes it from this agent, which must then give way: see
/// [`Claim::lost`]. After [`SETTLE_AFTER`] it declares itself settled.
#[must_use = "the place is released when the claim is dropped"]
pub struct Claim {
    _held: Option<LivelinessToken>,
    /// The liveliness subscriber on the place's claims; its callback sets `lost`.
    _watch: Option<Subscriber<()>>,
    /// Declares the settled claim after [`SETTLE_AFTER`] and keeps it.
    _settle: Option<OwnedTask>,
    /// Why this agent lost the place, once it has.
    lost: watch::Receiver<Option<String>>,
}

impl Claim {
    /// A claim that nobody can take (a session that only listens).
    fn unchallenged() -> Claim {
        Claim {
            _held: None,
            _watch: None,
            _settle: None,
            lost: watch::channel(None).1,
        }
    }

    /// Resolves once another agent comes first for this place (both took it at the same
    /// moment, and liveliness reached them too late to settle it while claiming; see
    /// [`SETTLE_AFTER`] for who comes first), with the error the agent gives way with:
    /// [`BusError::Taken`], naming the place. It never resolves while the place stays this
    /// agent's. An agent's loop selects on it beside its work and, when it resolves, stops
    /// taking work and exits with the error. Resolves at once when the place is already
    /// lost; cancel-safe.
    pub async fn lost(&self) -> BusError {
        let mut lost = self.lost.clone();
        // The reason is copied out at once: the value's guard is not kept across an await.
        let why = lost
            .wait_for(Option::is_some)
            .await
            .map(|why| why.clone().unwrap_or_default());
        match why {
            Ok(why) => BusError::Taken(why),
            // The watch is gone (an unchallenged claim, or the session closed): nobody can
            // take the place any more.
            Err(_) => std::future::pending().await,
        }
    }
}

/// The place a claimant of [`Bus::wait_until_unique`] takes, and its claim's nonce.
struct Place<'a> {
    run: &'a RunId,
    kind: AgentKind,
    /// The agent's id (`None`: the run's one agent of `kind`).
    id: Option<&'a str>,
    /// The id, or `any`, in the claim keys.
    slot: &'a str,
    nonce: u64,
    /// The key of the place's claims.
    claims_key: String,
}

/// Where a holder stands, shared by its claims' watch and the task that settles it.
#[derive(Default)]
struct Standing {
    settled: bool,
    lost: bool,
}

/// Whether a holder with nonce `mine` (`settled` or not) gives way to `other`, a claim of
/// its place: see [`SETTLE_AFTER`].
fn gives_way_to(mine: u64, settled: bool, other: ClaimKey) -> bool {
    other.nonce != mine
        && match other.phase {
            ClaimPhase::Starting => false,
            ClaimPhase::Held => !settled && other.nonce < mine,
            ClaimPhase::Settled => !settled || other.nonce < mine,
        }
}

/// The error of an agent that gives way to another, `what` (e.g. "took its place at the
/// same moment and keeps it"), in `run`'s place of `kind` with `id` (`None`: the run's one
/// agent of `kind`).
fn gives_way(run: &RunId, kind: AgentKind, id: Option<&str>, what: &str) -> String {
    let who = match id {
        Some(id) => format!("a {} with the id {id}", kind.as_str()),
        None => format!("a {}", kind.as_str()),
    };
    format!(
        "run {run:?}: another agent, {who}, {what}: this one gives way{}",
        if id.is_some() {
            " (give it another --id)"
        } else {
            ""
        }
    )
}

/// The error of an agent whose place in `run` is held by `holder` (of `kind`, with `id`;
/// `None` when only its claim was seen).
fn already_has(
    run: &RunId,
    kind: AgentKind,
    id: Option<&str>,
    holder: Option<&AliveKey>,
) -> String {
    let what = match (id, holder) {
        (Some(id), _) => format!("a {} with the id {id}", kind.as_str()),
        (None, Some(holder)) => format!("a {} ({})", kind.as_str(), holder.id),
        (None, None) => format!("a {}", kind.as_str()),
    };
    let host = holder.map_or(String::new(), |h| format!(", alive on host {}", h.host));
    format!(
        "run {run:?} already has {what}{host}: stop it first{}",
        if id.is_some() {
            ", or give this one another --id"
        } else {
            ""
        }
    )
}

/// A random nonce for a claim.
fn claim_nonce() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u32(std::process::id());
    if let Ok(t) = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH) {
        h.write_u128(t.as_nanos());
    }
    h.finish()
}

/// Who keeps a claimant with nonce `mine` from its place, among `claims`: another agent
/// holding it (a settled one first), else a smaller starting nonce.
fn blocker(claims: &[ClaimKey], mine: u64) -> Option<ClaimKey> {
    let others = claims.iter().filter(|c| c.nonce != mine);
    others
        .clone()
        .filter(|c| c.phase.holds())
        .max_by_key(|c| (c.phase, std::cmp::Reverse(c.nonce)))
        .or_else(|| others.filter(|c| c.nonce < mine).min_by_key(|c| c.nonce))
        .copied()
}

impl Bus {
    /// Declares this agent alive until the token is dropped.
    pub async fn declare_alive(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: &str,
    ) -> Result<LivelinessToken, BusError> {
        self.declare_alive_publishing(run, kind, id, None).await
    }

    /// [`Bus::declare_alive`], the token saying which topic of its kind the agent publishes
    /// (a hand: clouds or wrenches), so that tools list it only there.
    pub async fn declare_alive_publishing(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: &str,
        publishes: Option<Topic>,
    ) -> Result<LivelinessToken, BusError> {
        graspopt_protocol::keys::check_agent_id(id).map_err(|e| BusError::Config(e.to_string()))?;
        let key = alive_token(run, kind, self.host(), id, publishes);
        self.session()
            .liveliness()
            .declare_token(key.clone())
            .await
            .map_err(|e| BusError::zenoh(format!("declaring liveliness {key}"), e))
    }

    /// Watches the tokens under `key` (e.g. [`alive_key`]), starting with those
    /// already declared.
    pub async fn watch_alive(&self, key: &str) -> Result<AliveWatch, BusError> {
        let sub = self
            .session()
            .liveliness()
            .declare_subscriber(key)
            .history(true)
            .await
            .map_err(|e| BusError::zenoh(format!("watching liveliness {key}"), e))?;
        Ok(AliveWatch { sub })
    }

    /// Takes the place this agent is about to fill in `run`, waiting (up to `wait`) until no
    /// other agent of `kind` holds it: one with the same `id` or, when `id` is `None`, any
    /// agent of that kind. A predecessor that was just killed has its token removed within
    /// moments; one still alive after `wait` is an error naming it, so that two hands never
    /// run each other's trials and two coordinators never share a run. A session that has
    /// just opened may not know every token yet, so the place counts as free only after
    /// [`UNIQUE_CHECKS`] empty answers in a row, 200 ms apart (one second).
    ///
    /// Agents that start at the same moment all find the place free; so each then declares
    /// a claim token with a random number and looks at the others' claims ([`CLAIM_CHECKS`]
    /// looks 150 ms apart): an agent that holds the place, or a smaller number, comes first.
    /// Seeing none, it holds the place and looks once more: of two that held it at the same
    /// moment, the smaller number keeps it. An agent that comes second waits, as for a
    /// predecessor, until the deadline: if the first is gone by then (killed while it took
    /// the place), it takes the place; else it gives up with an error. The winner's claim is
    /// returned; it holds the place until dropped. These looks settle it when liveliness
    /// reaches the claimants within about 150 ms; when it comes later (a loaded machine),
    /// several may hold the place at once, so a holder goes on watching the claims of its
    /// place, and one that sees another come first loses the place: its [`Claim::lost`]
    /// resolves, and the agent gives way. Who comes first: the agent that has held the
    /// place for [`SETTLE_AFTER`] (a newcomer whose view of the claims came late gives way
    /// to it), else the smaller number. Once liveliness arrives, one
    /// holder is left, whatever the delay. A session that only listens ([`Bus::reaches_out`]
    /// false: the embedded run's, on a fresh loopback port) cannot meet another agent and
    /// skips all this.
    pub async fn wait_until_unique(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: Option<&str>,
        wait: std::time::Duration,
    ) -> Result<Claim, BusError> {
        if !self.reaches_out() {
            return Ok(Claim::unchallenged());
        }
        let deadline = tokio::time::Instant::now() + wait;
        self.wait_for_holders(run, kind, id, deadline).await?;
        let slot = id.unwrap_or("any");
        let place = Place {
            run,
            kind,
            id,
            slot,
            nonce: claim_nonce(),
            claims_key: claim_slot_key(run, kind, slot),
        };
        let _starting = self.declare_claim(&place, ClaimPhase::Starting).await?;
        loop {
            // Looks until another claimant is seen; none: hold the place, and look once
            // more in case another claimant held it at the same moment.
            let mut seen = self.look_for_blocker(&place).await?;
            if seen.is_none() {
                let held = self.declare_claim(&place, ClaimPhase::Held).await?;
                tokio::time::sleep(CLAIM_LOOK).await;
                seen = self
                    .claims(&place.claims_key)
                    .await?
                    .into_iter()
                    .find(|c| gives_way_to(place.nonce, false, *c));
                if seen.is_none() {
                    return self.hold(&place, held).await;
                }
            }
            // Another agent is taking or holds the place: wait for it to go, as for a
            // predecessor, until the deadline.
            if tokio::time::Instant::now() >= deadline {
                return Err(self.kept_from(&place, seen).await);
            }
        }
    }

    /// Declares this claimant's claim of `place` in `phase` (the future owns what it
    /// needs: it may run in a task of its own).
    fn declare_claim(
        &self,
        place: &Place<'_>,
        phase: ClaimPhase,
    ) -> impl std::future::Future<Output = Result<LivelinessToken, BusError>> + Send + 'static {
        let claim = ClaimKey {
            nonce: place.nonce,
            phase,
        };
        let key = claim_token(place.run, place.kind, place.slot, claim);
        let session = self.session().clone();
        async move {
            session
                .liveliness()
                .declare_token(key.clone())
                .await
                .map_err(|e| BusError::zenoh(format!("declaring liveliness {key}"), e))
        }
    }

    /// Looks at the other claims of `place` up to [`CLAIM_CHECKS`] times, [`CLAIM_LOOK`]
    /// apart, until one keeps this claimant from it (see [`blocker`]).
    async fn look_for_blocker(&self, place: &Place<'_>) -> Result<Option<ClaimKey>, BusError> {
        let mut seen = None;
        for _ in 0..CLAIM_CHECKS {
            tokio::time::sleep(CLAIM_LOOK).await;
            seen = blocker(&self.claims(&place.claims_key).await?, place.nonce);
            if seen.is_some() {
                break;
            }
        }
        Ok(seen)
    }

    /// Holds `place` with the `held` claim: watches the other claims (see
    /// [`Claim::lost`]) and settles after [`SETTLE_AFTER`].
    async fn hold(&self, place: &Place<'_>, held: LivelinessToken) -> Result<Claim, BusError> {
        let standing = std::sync::Arc::new(std::sync::Mutex::new(Standing::default()));
        let why = gives_way(
            place.run,
            place.kind,
            place.id,
            "took its place at the same moment and keeps it",
        );
        let (watch, lost) = self
            .watch_claims(&place.claims_key, place.nonce, standing.clone(), why)
            .await?;
        let settle = self.declare_claim(place, ClaimPhase::Settled);
        let settle = OwnedTask::spawn(async move {
            tokio::time::sleep(SETTLE_AFTER).await;
            {
                let mut standing = lock(&standing);
                if standing.lost {
                    return;
                }
                // Settled before the token is out: a claim seen from now on is judged as
                // the others will judge this one's.
                standing.settled = true;
            }
            match settle.await {
                // The token lives as long as the task: until the claim drops.
                Ok(_token) => std::future::pending::<()>().await,
                Err(_) => lock(&standing).settled = false,
            }
        });
        Ok(Claim {
            _held: Some(held),
            _watch: Some(watch),
            _settle: Some(settle),
            lost,
        })
    }

    /// The error of a claimant kept from `place` until its deadline by `seen`: a holder
    /// (named when alive) or another claimant.
    async fn kept_from(&self, place: &Place<'_>, seen: Option<ClaimKey>) -> BusError {
        let (run, kind, id) = (place.run, place.kind, place.id);
        let e = match seen {
            Some(c) if c.phase.holds() => {
                let holders = self.holders(run, kind, id).await.unwrap_or_default();
                already_has(run, kind, id, holders.first())
            }
            _ => gives_way(run, kind, id, "is taking its place at the same moment"),
        };
        BusError::Taken(e)
    }

    /// Watches the claims under `key` (one place's) for the holder with nonce `mine`: the
    /// receiver turns to `why` once a claim it gives way to is seen (those already declared
    /// included; see [`gives_way_to`]), and `standing` records it. The watch lasts as long as
    /// the subscriber returned.
    async fn watch_claims(
        &self,
        key: &str,
        mine: u64,
        standing: std::sync::Arc<std::sync::Mutex<Standing>>,
        why: String,
    ) -> Result<(Subscriber<()>, watch::Receiver<Option<String>>), BusError> {
        let (lost, on_lost) = watch::channel(None);
        let sub = self
            .session()
            .liveliness()
            .declare_subscriber(key)
            .history(true)
            .callback(move |sample| {
                let Some(other) = parse_claim_key(sample.key_expr().as_str()) else {
                    return;
                };
                if sample.kind() != SampleKind::Put {
                    return;
                }
                let mut standing = lock(&standing);
                if !standing.lost && gives_way_to(mine, standing.settled, other) {
                    standing.lost = true;
                    lost.send_replace(Some(why.clone()));
                }
            })
            .await
            .map_err(|e| BusError::zenoh(format!("watching liveliness {key}"), e))?;
        Ok((sub, on_lost))
    }

    /// The claims alive under `key`.
    async fn claims(&self, key: &str) -> Result<Vec<ClaimKey>, BusError> {
        self.tokens(key, parse_claim_key).await
    }

    /// The liveliness tokens alive now under `key`, as `parse` reads them (others skipped).
    async fn tokens<T>(
        &self,
        key: &str,
        parse: impl Fn(&str) -> Option<T>,
    ) -> Result<Vec<T>, BusError> {
        let replies = self
            .session()
            .liveliness()
            .get(key)
            .await
            .map_err(|e| BusError::zenoh(format!("liveliness query {key}"), e))?;
        let mut out = Vec::new();
        while let Ok(reply) = replies.recv_async().await {
            if let Ok(sample) = reply.result()
                && let Some(token) = parse(sample.key_expr().as_str())
            {
                out.push(token);
            }
        }
        Ok(out)
    }

    /// The first step of [`Self::wait_until_unique`]: waits until no live agent holds the
    /// place.
    async fn wait_for_holders(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: Option<&str>,
        deadline: tokio::time::Instant,
    ) -> Result<(), BusError> {
        let mut free = 0;
        loop {
            let holders = self.holders(run, kind, id).await?;
            match holders.first() {
                None => {
                    free += 1;
                    if free >= UNIQUE_CHECKS {
                        return Ok(());
                    }
                }
                Some(holder) => {
                    free = 0;
                    if tokio::time::Instant::now() >= deadline {
                        return Err(BusError::Taken(already_has(run, kind, id, Some(holder))));
                    }
                }
            }
            tokio::time::sleep(std::time::Duration::from_millis(200)).await;
        }
    }

    /// The live agents of `kind` in `run` that hold the place of `id` (any of them when
    /// `id` is `None`).
    async fn holders(
        &self,
        run: &RunId,
        kind: AgentKind,
        id: Option<&str>,
    ) -> Result<Vec<AliveKey>, BusError> {
        Ok(self
            .alive_now(&alive_key(run.into(), Some(kind)))
            .await?
            .into_iter()
            .filter(|a| a.run == *run && id.is_none_or(|id| a.id == id))
            .collect())
    }

    /// The agents alive now under `key`.
    pub async fn alive_now(&self, key: &str) -> Result<Vec<AliveKey>, BusError> {
        self.tokens(key, parse_alive_key).await
    }
}

/// Locks a holder's standing (a poisoned lock still holds a consistent pair of flags).
fn lock(standing: &std::sync::Mutex<Standing>) -> std::sync::MutexGuard<'_, Standing> {
    standing
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}
