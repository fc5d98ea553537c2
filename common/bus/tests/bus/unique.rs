//! Taking a place in a run over real sessions on loopback: of agents that start at the same
//! moment with one id, exactly one gets the place; a later one is refused while it is held
//! and gets it once the holder is gone; a holder whose place is also held with a smaller
//! nonce (liveliness that came too late to settle it while claiming) gives way.

use std::time::Duration;

use graspopt_bus::{Bus, BusError};
use graspopt_protocol::keys::{Claim as ClaimKey, claim_token};
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
        assert!(e.to_string().contains("has just taken its place"), "{e}");
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
/// (a loaded machine): the second's held claim is declared by hand, after the first holds
/// the place, as the first would see it arrive. A held claim with a larger nonce leaves the
/// holder in place; a starting one with a smaller nonce too (it waits for the holder); a
/// held one with a smaller nonce takes the place: the holder's `lost` resolves within a
/// second, with an error naming the place, and stays resolved. Another place's holder is
/// not touched.
#[test]
fn a_holder_gives_way_to_a_smaller_nonce_held_late() {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let run = RunId::new("uniquelate").unwrap();
        let (_hub, _endpoint, peers) = hub_and_peers(3).await;
        let wait = Duration::from_millis(500);
        let holder = peers[0]
            .wait_until_unique(&run, AgentKind::Hand, Some("h1"), wait)
            .await
            .unwrap();
        let neighbour = peers[1]
            .wait_until_unique(&run, AgentKind::Hand, Some("h2"), wait)
            .await
            .unwrap();
        let late = &peers[2];
        let declare = |nonce: u64, held: bool| {
            let key = claim_token(&run, AgentKind::Hand, "h1", ClaimKey { nonce, held });
            async move {
                late.session()
                    .liveliness()
                    .declare_token(key)
                    .await
                    .unwrap()
            }
        };
        let larger = declare(u64::MAX, true).await;
        let starting = declare(0, false).await;
        // Agents await it inside spawned tasks.
        fn sendable(_: &impl Send) {}
        sendable(&holder.lost());
        let settle = Duration::from_millis(1000);
        assert!(
            tokio::time::timeout(settle, holder.lost()).await.is_err(),
            "a larger nonce or a claimant still starting takes no place"
        );
        let smaller = declare(0, true).await;
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
        assert!(
            tokio::time::timeout(Duration::from_millis(300), neighbour.lost())
                .await
                .is_err(),
            "another id is another place"
        );
    });
}

fn errors(outcomes: &[Result<graspopt_bus::Claim, BusError>]) -> Vec<String> {
    outcomes
        .iter()
        .filter_map(|o| o.as_ref().err().map(|e| e.to_string()))
        .collect()
}
