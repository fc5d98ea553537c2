//! Taking a place in a run over real sessions on loopback: of agents that start at the same
//! moment with one id, exactly one gets the place; a later one is refused while it is held
//! and gets it once the holder is gone.

use std::time::Duration;

use graspopt_bus::{Bus, BusArgs, BusError, free_loopback_port};
use graspopt_protocol::{AgentKind, RunId};

async fn hub_and_peers(n: usize) -> (Bus, String, Vec<Bus>) {
    let endpoint = format!("tcp/127.0.0.1:{}", free_loopback_port().unwrap());
    let mut args = BusArgs::loopback(vec![endpoint.clone()], Vec::new());
    args.no_shm = true;
    let hub = Bus::open(&args).await.unwrap();
    let mut peers = Vec::new();
    for _ in 0..n {
        peers.push(peer(&endpoint).await);
    }
    (hub, endpoint, peers)
}

async fn peer(endpoint: &str) -> Bus {
    let mut args = BusArgs::loopback(Vec::new(), vec![endpoint.to_string()]);
    args.no_shm = true;
    let bus = Bus::open(&args).await.unwrap();
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

fn errors(outcomes: &[Result<graspopt_bus::Claim, BusError>]) -> Vec<String> {
    outcomes
        .iter()
        .filter_map(|o| o.as_ref().err().map(|e| e.to_string()))
        .collect()
}
