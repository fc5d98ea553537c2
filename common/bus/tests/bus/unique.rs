//! Taking a place in a run over real sessions on loopback: of agents that start at the same
//! moment with one id, exactly one gets the place; a later one is refused while it is held
//! and gets it once the holder is gone; a holder whose place is also held by one that comes
//! first (liveliness that came too late to settle it while claiming) gives way.

use std::time::Duration;

use graspopt_bus::alive::SETTLE_AFTER;
use graspopt_bus::{Bus, BusError};
use graspopt_protocol::keys::{
    Claim as ClaimKey, ClaimPhase, claim_slot_key, claim_token, parse_claim_key,
};
use graspopt_protocol::{AgentKind, RunId};

async fn hub_and_peers(n: usize) -> (Bus, String, Vec<Bus>) {
    let s = Bus::loopback(n).await.unwrap();
    assert!(s.peers.iter().all(Bus::reaches_out));
    (s.hub, s.endpoint, s.peers)
}

async fn peer(endpoint: &str) -> Bus {
    let bus = Bus::loopback_peer(endpoint).await.unwrap();
    assert!(bus.reaches_out());
    bus
}

#[test]
fn of_agents_starting_together_one_takes_the_place() {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let run = RunId::new("uniquetest").unwrap();
        let (_hub, endpoint, peers) = hub_and_peers(3).await;
        let wait = Duration::from_millis(500);
        let (a, b, c) = tokio::join!(
            peers[0].wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait),
            peers[1].wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait),
            peers[2].wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait),
        );
        let outcomes = vec![a, b, c];
        let winners: Vec<_> = outcomes.iter().filter(|o| o.is_ok()).collect();
        assert_eq!(winners.len(), 1, "{:?}", errors(&outcomes));
        for e in errors(&outcomes) {
            assert!(e.contains("gives way"), "{e}");
        }
        // Another id is another place.
        let other = peer(&endpoint).await;
        let _h2 = other
            .wait_until_unique(&run, AgentKind::Hand, Some("h2"), wait)
            .await
            .unwrap();
        // While the place is held, a newcomer gives way; once released, it takes it.
        let late = peer(&endpoint).await;
        let e = late
            .wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait)
            .await
            .err()
            .expect("the place is held");
        assert!(matches!(e, BusError::Taken(_)), "{e}");
        assert_eq!(
            e.to_string(),
            "run \"uniquetest\" already has a hand with the id h1: stop it first, or give \
             this one another --id"
        );
        // One claimant a moment after another (the first is looking, or already holds it):
        // one place, one holder.
        for lag_ms in [100, 250, 400] {
            let run = RunId::new(&format!("uniquelag{lag_ms}")).unwrap();
            let first = peer(&endpoint).await;
            let second = peer(&endpoint).await;
            let (a, b) = tokio::join!(
                first.wait_until_unique(&run, AgentKind::Coordinator, None, wait),
                async {
                    tokio::time::sleep(Duration::from_millis(lag_ms)).await;
                    second
                        .wait_until_unique(&run, AgentKind::Coordinator, None, wait)
                        .await
                },
            );
            let outcomes = vec![a, b];
            assert_eq!(
                outcomes.iter().filter(|o| o.is_ok()).count(),
                1,
                "lag {lag_ms} ms: {:?}",
                errors(&outcomes)
            );
        }
        let mut outcomes = outcomes;
        outcomes.retain(|o| o.is_ok());
        drop(outcomes);
        tokio::time::sleep(Duration::from_millis(300)).await;
        let _h1 = late
            .wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait)
            .await
            .unwrap();
    });
}

/// Two agents that both took a place because their claims reached each other too late
/// (a loaded machine): the other's claims are declared by hand, after the holder holds the
/// place, as the holder would see them arrive.
/// - A holder that has not settled yet (it took the place less than `SETTLE_AFTER` ago)
///   stays for a held claim with a larger nonce or a starting one with a smaller nonce, and
///   gives way within a second to a held one with a smaller nonce (they took it at the same
///   moment) or a settled one with any nonce (it is the newcomer whose view came late).
/// - A settled holder stays for a held claim with a smaller nonce (a newcomer) and a
///   settled one with a larger nonce, and gives way to a settled one with a smaller nonce
///   (both settled before they saw each other).
/// - Another place's holder is not touched.
#[test]
fn a_holder_gives_way_to_who_comes_first() {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let run = RunId::new("uniquelate").unwrap();
        let (_hub, _endpoint, peers) = hub_and_peers(3).await;
        let wait = Duration::from_millis(500);
        let late = &peers[2];
        let declare = |slot: &'static str, nonce: u64, phase: ClaimPhase| {
            let key = claim_token(&run, AgentKind::Hand, slot, ClaimKey { nonce, phase });
            async move {
                late.session()
                    .liveliness()
                    .declare_token(key)
                    .await
                    .unwrap()
            }
        };
        let established = peers[1]
            .wait_until_unique(&run, AgentKind::Hand, Some("h3"), wait)
            .await
            .unwrap();
        let holder = peers[0]
            .wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait)
            .await
            .unwrap();
        let larger = declare("h1", u64::MAX, ClaimPhase::Held).await;
        let starting = declare("h1", 0, ClaimPhase::Starting).await;
        // Agents await it inside spawned tasks.
        fn sendable(_: &impl Send) {}
        sendable(&holder.lost());
        assert!(
            tokio::time::timeout(Duration::from_millis(500), holder.lost())
                .await
                .is_err(),
            "a larger nonce or a claimant still starting takes no place"
        );
        let smaller = declare("h1", 0, ClaimPhase::Held).await;
        let e = tokio::time::timeout(Duration::from_secs(1), holder.lost())
            .await
            .expect("the holder gives way within a second");
        assert!(matches!(e, BusError::Taken(_)), "{e}");
        assert_eq!(
            e.to_string(),
            "run \"uniquelate\": another agent, a hand with the id h1, took its place at the \
             same moment and keeps it: this one gives way (give it another --id)"
        );
        // Lost for good, even once the other is gone.
        drop((smaller, starting, larger));
        tokio::time::sleep(Duration::from_millis(300)).await;
        let again = tokio::time::timeout(Duration::from_millis(100), holder.lost()).await;
        assert!(again.is_ok(), "lost stays resolved");

        // The holder of h3 has settled (it has held its place for SETTLE_AFTER).
        let h3 = claim_slot_key(&run, AgentKind::Hand, "h3");
        let deadline = tokio::time::Instant::now() + SETTLE_AFTER + Duration::from_secs(3);
        loop {
            let replies = late.session().liveliness().get(&h3).await.unwrap();
            let mut phases = Vec::new();
            while let Ok(reply) = replies.recv_async().await {
                if let Ok(sample) = reply.result() {
                    phases.extend(parse_claim_key(sample.key_expr().as_str()).map(|c| c.phase));
                }
            }
            if phases.contains(&ClaimPhase::Settled) {
                break;
            }
            assert!(
                tokio::time::Instant::now() < deadline,
                "the holder of h3 never settled: {phases:?}"
            );
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
        assert!(
            tokio::time::timeout(Duration::from_millis(300), established.lost())
                .await
                .is_err(),
            "another id is another place"
        );
        let newcomer = declare("h3", 0, ClaimPhase::Held).await;
        let settled_larger = declare("h3", u64::MAX, ClaimPhase::Settled).await;
        assert!(
            tokio::time::timeout(Duration::from_secs(1), established.lost())
                .await
                .is_err(),
            "a settled holder stays for a newcomer and for a larger nonce settled"
        );
        let settled_smaller = declare("h3", 0, ClaimPhase::Settled).await;
        let e = tokio::time::timeout(Duration::from_secs(1), established.lost())
            .await
            .expect("a settled holder gives way to a smaller nonce settled within a second");
        assert!(e.to_string().contains("a hand with the id h3"), "{e}");
        drop((newcomer, settled_larger, settled_smaller));

        // A holder that has not settled gives way to one settled, whatever the nonces.
        let fresh = peers[0]
            .wait_until_unique(&run, AgentKind::Hand, Some("h4"), wait)
            .await
            .unwrap();
        let _settled = declare("h4", u64::MAX, ClaimPhase::Settled).await;
        let e = tokio::time::timeout(Duration::from_secs(1), fresh.lost())
            .await
            .expect("a newcomer gives way to a settled holder within a second");
        assert!(e.to_string().contains("a hand with the id h4"), "{e}");
    });
}

fn errors(outcomes: &[Result<graspopt_bus::Claim, BusError>]) -> Vec<String> {
    outcomes
        .iter()
        .filter_map(|o| o.as_ref().err().map(|e| e.to_string()))
        .collect()
}
