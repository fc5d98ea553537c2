//! Queries over real sessions on loopback: the first reply comes back as soon as it is sent,
//! even while another responder holds the query open (a planner cut off by a network fault,
//! say), and a query nothing answers says so at once instead of after its timeout.

use std::time::{Duration, Instant};

use graspopt_bus::{Bus, BusError};
use graspopt_protocol::{PlannerMethod, RunId, SuggestReply, SuggestRequest};

const KEY: &str = "graspopt/querytest/planner/suggest";

fn request(run: &RunId) -> SuggestRequest {
    SuggestRequest {
        run_id: run.clone(),
        request_id: 7,
        method: PlannerMethod::Random,
        bounds: vec![[0.0, 1.0]],
        seed: 0,
        initial: None,
        observations: Vec::new(),
        pending: Vec::new(),
        count: 1,
        engine_state: None,
    }
}

async fn sessions() -> (Bus, Bus, Bus) {
    let s = Bus::loopback(2).await.unwrap();
    let mut peers = s.peers.into_iter();
    let (a, b) = (peers.next().unwrap(), peers.next().unwrap());
    (s.hub, a, b)
}

#[test]
fn the_first_reply_is_not_held_back_by_a_responder_that_never_finishes() {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let run = RunId::new("querytest").unwrap();
        let (hub, fast, silent) = sessions().await;
        // One responder answers at once; the other takes the query and never answers.
        let fast_server = fast.serve::<SuggestRequest>(KEY).await.unwrap();
        let silent_server = silent.serve::<SuggestRequest>(KEY).await.unwrap();
        let r = run.clone();
        tokio::spawn(async move {
            while let Some(q) = fast_server.recv().await {
                let reply = SuggestReply {
                    run_id: r.clone(),
                    request_id: q.request.as_ref().map_or(0, |req| req.request_id),
                    points: vec![vec![0.25]],
                    error: None,
                    engine_state: None,
                };
                q.reply(&reply).await.unwrap();
            }
        });
        let held = tokio::spawn(async move {
            let mut kept = Vec::new();
            while let Some(q) = silent_server.recv().await {
                kept.push(q);
            }
            kept.len()
        });
        tokio::time::sleep(Duration::from_millis(500)).await;
        let timeout = Duration::from_secs(10);
        let started = Instant::now();
        let reply: SuggestReply = hub.query(KEY, &request(&run), timeout).await.unwrap();
        let took = started.elapsed();
        assert_eq!(reply.points, vec![vec![0.25]]);
        assert_eq!(reply.request_id, 7);
        // Held back, the reply would come at the timeout (10 s).
        assert!(took < Duration::from_secs(2), "the reply took {took:?}");
        held.abort();
    });
}

#[test]
fn a_query_that_nothing_answers_says_so_at_once() {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let run = RunId::new("querytest").unwrap();
        let (hub, _a, _b) = sessions().await;
        let timeout = Duration::from_secs(10);
        let started = Instant::now();
        let e = hub
            .query::<_, SuggestReply>(KEY, &request(&run), timeout)
            .await
            .unwrap_err();
        assert!(started.elapsed() < Duration::from_secs(2));
        assert!(
            matches!(e, BusError::NoResponder { ref key } if key == KEY),
            "{e}"
        );
        assert_eq!(e.to_string(), format!("nothing answers on {KEY}"));
    });
}
