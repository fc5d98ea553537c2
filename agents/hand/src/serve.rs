//! The bus loop of every hand, written once around a [`HandDriver`].

use std::time::{Duration, Instant};

use graspopt_bus::{Bus, CloudSender, Inbox, Subscription, now_ms};
use graspopt_protocol::keys::{COMMAND, OBJECT, WRENCHES};
use graspopt_protocol::{
    AgentKind, ContactClouds, Encoding, FingertipWrenches, ObjectEstimate, RunId, TrialCommand,
};

use crate::driver::{HandDriver, HandError, HandReading, Sensing};
use crate::error::HandAgentError;

/// How long a starting hand waits for a predecessor with its id to vanish (a worker killed
/// and restarted at once) before refusing to start.
pub const UNIQUE_WAIT: Duration = Duration::from_secs(5);

/// Serves the trial commands sent to worker `id` of `run` with `driver` until the session
/// closes or the task is cancelled: claims the id (refuses to start while another hand with
/// it is alive, see [`UNIQUE_WAIT`]), subscribes, declares itself alive, then for each
/// command of this run and worker executes it on a thread of its own, pads the trial to at
/// least `cost` (a robot's cycle time), and sends the clouds, tagged with the trial, to the
/// metric agents (or, for a driver that senses [`Sensing::Wrenches`], the fingertip readings on
/// the wrenches topic). A failed execution is sent as clouds (readings) with the reason in
/// `error`. Messages of other runs or workers, and ones that do not decode, are counted and
/// logged. Should another hand with the id turn out to hold the place too (both claimed
/// it at the same moment and liveliness came late, see [`graspopt_bus::Claim::lost`]), the
/// one that gives way takes no more commands and returns the error naming it (a trial
/// already running is finished and sent first).
pub async fn serve(
    bus: &Bus,
    run: &RunId,
    id: &str,
    cost: Duration,
    mut driver: impl HandDriver,
) -> Result<(), HandAgentError> {
    // Two hands with one id would both execute every trial sent to that id.
    let place = bus
        .wait_until_unique(run, AgentKind::Hand, Some(id), UNIQUE_WAIT)
        .await?;
    let commands = bus.subscribe(&COMMAND.worker_key(run.into(), id)).await?;
    let objects = bus.subscribe(&OBJECT.key(run.into())).await?;
    let sender = CloudSender::open(bus, run).await;
    // Declared last: the coordinator sends commands once it sees the token, which says
    // what this hand publishes.
    let publishes = Some(driver.sensing().topic());
    let _token = bus
        .declare_alive_publishing(run, AgentKind::Hand, id, publishes)
        .await?;
    let mut inbox = Inbox::new(format!("hand {id}"), run);
    loop {
        // A subscription that ends (`None`): the session closed.
        let command = tokio::select! {
            // The place first: a hand that gives way takes no further command.
            biased;
            e = place.lost() => return Err(e.into()),
            r = objects.recv() => {
                let Some(r) = r else { return Ok(()) };
                if let Some(e) = inbox.accept(r, "object estimate") {
                    driver.set_object(&e);
                }
                continue;
            },
            r = commands.recv() => match r.map(|r| inbox.accept(r, "command")) {
                None => return Ok(()),
                Some(Some(c)) if c.worker == id => c,
                Some(Some(c)) => {
                    inbox.refuse(format_args!("command for {}/{} ignored", c.run_id, c.worker));
                    continue;
                }
                Some(None) => continue,
            },
        };
        // Wait for the world's object if perception has not spoken yet.
        tokio::select! {
            biased;
            e = place.lost() => return Err(e.into()),
            object = wait_for_object(&mut driver, &objects, &mut inbox) => if !object {
                return Ok(());
            },
        }
        let started = Instant::now();
        let (back, outcome) = execute(driver, &command, id).await?;
        driver = back;
        if let Some(rest) = cost.checked_sub(started.elapsed()) {
            tokio::time::sleep(rest).await;
        }
        let sent = match driver.sensing() {
            Sensing::Clouds => sender
                .send(&tag(&command, id, driver.hand(), outcome))
                .await
                .map(|_| ()),
            Sensing::Wrenches => {
                let readings = tag_wrenches(&command, id, driver.hand(), outcome);
                bus.put(&WRENCHES.key(run.into()), &readings, Encoding::Bincode)
                    .await
            }
        };
        if let Err(e) = sent {
            tracing::warn!(
                "hand {id}: cannot send what it measured in trial {}: {e}",
                command.trial_id
            );
        }
    }
}

/// Feeds object estimates to `driver` while it needs one; false when the session closed.
async fn wait_for_object(
    driver: &mut impl HandDriver,
    objects: &Subscription<ObjectEstimate>,
    inbox: &mut Inbox,
) -> bool {
    while driver.needs_object() {
        let Some(r) = objects.recv().await else {
            return false;
        };
        if let Some(e) = inbox.accept(r, "object estimate") {
            driver.set_object(&e);
        }
    }
    true
}

/// Executes `command` with `driver` on a blocking thread (a command for another hand is
/// refused without it); gives the driver back with the outcome.
async fn execute<D: HandDriver>(
    mut driver: D,
    command: &TrialCommand,
    id: &str,
) -> Result<(D, Result<HandReading, HandError>), HandAgentError> {
    if let Some(hand) = driver.hand()
        && !graspopt_sim::same_hand(hand, &command.hand)
    {
        let why = HandError::OtherHand {
            worker: id.to_string(),
            has: hand.to_string(),
            asked: command.hand.clone(),
        };
        return Ok((driver, Err(why)));
    }
    let command = command.clone();
    tokio::task::spawn_blocking(move || {
        let outcome = driver.execute(&command);
        (driver, outcome)
    })
    .await
    .map_err(HandAgentError::Panicked)
}

/// The clouds message answering `command`, sent by worker `id` now: the reading, or no
/// clouds and the reason in `error`. `hand`: the driver's hand (`None`: the one asked for).
pub fn tag(
    command: &TrialCommand,
    id: &str,
    hand: Option<&str>,
    outcome: Result<HandReading, HandError>,
) -> ContactClouds {
    let (palm_pose, fingers, min_gap, error) = match outcome {
        Ok(r) => (r.palm_pose, r.fingers, r.min_gap, None),
        Err(e) => (command.palm_pose, Vec::new(), None, Some(e.to_string())),
    };
    ContactClouds {
        run_id: command.run_id.clone(),
        trial_id: command.trial_id,
        attempt: command.attempt,
        worker: id.to_string(),
        hand: hand.unwrap_or(&command.hand).to_string(),
        palm_pose,
        fingers,
        min_gap,
        error,
        executed_ms: now_ms(),
    }
}

/// The fingertip readings answering `command`, sent by worker `id` now: the reading, or no
/// readings and the reason in `error`. `hand`: the driver's hand (`None`: the one asked for).
pub fn tag_wrenches(
    command: &TrialCommand,
    id: &str,
    hand: Option<&str>,
    outcome: Result<HandReading, HandError>,
) -> FingertipWrenches {
    let (palm_pose, fingertips, min_gap, error) = match outcome {
        Ok(r) => (r.palm_pose, r.fingertips, r.min_gap, None),
        Err(e) => (command.palm_pose, Vec::new(), None, Some(e.to_string())),
    };
    FingertipWrenches {
        run_id: command.run_id.clone(),
        trial_id: command.trial_id,
        attempt: command.attempt,
        worker: id.to_string(),
        hand: hand.unwrap_or(&command.hand).to_string(),
        palm_pose,
        fingertips,
        min_gap,
        error,
        executed_ms: now_ms(),
    }
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use graspopt_bus::{CloudReceiver, CongestionControl};
    use graspopt_protocol::keys::{Claim, ClaimPhase, alive_key, claim_token};
    use graspopt_protocol::{CloudPoint, Encoding, FingerCloud, Pose};

    use super::*;

    /// A barrett hand that needs the object first, fails every even trial, and notes what it
    /// was given.
    struct Flaky {
        seen: Arc<Mutex<Vec<String>>>,
        object: bool,
    }

    impl HandDriver for Flaky {
        fn hand(&self) -> Option<&str> {
            Some("barrett")
        }
        fn needs_object(&self) -> bool {
            !self.object
        }
        fn set_object(&mut self, estimate: &ObjectEstimate) {
            self.object = true;
            self.seen.lock().unwrap().push(estimate.object.clone());
        }
        fn execute(&mut self, command: &TrialCommand) -> Result<HandReading, HandError> {
            self.seen
                .lock()
                .unwrap()
                .push(format!("trial {}", command.trial_id));
            if command.trial_id.is_multiple_of(2) {
                return Err(HandError::Fault(format!(
                    "fault on trial {}",
                    command.trial_id
                )));
            }
            Ok(HandReading {
                palm_pose: Pose::IDENTITY,
                fingers: vec![FingerCloud {
                    finger: Some(0),
                    links: vec!["f0".into()],
                    points: vec![CloudPoint {
                        p: [0.0, 0.0, command.trial_id as f64],
                        n: [0.0, 0.0, -1.0],
                        w: 1.0,
                    }],
                }],
                min_gap: Some(0.5),
                fingertips: Vec::new(),
            })
        }
    }

    fn command(run: &RunId, trial_id: u64, worker: &str, hand: &str) -> TrialCommand {
        TrialCommand {
            run_id: run.clone(),
            trial_id,
            attempt: 2,
            worker: worker.into(),
            hand: hand.into(),
            params: vec![0.1],
            palm_pose: Pose {
                translation: [0.0, 0.0, 0.3],
                ..Pose::IDENTITY
            },
            lease_ms: 10_000,
            issued_ms: 0,
        }
    }

    fn estimate(run: &RunId, object: &str) -> ObjectEstimate {
        ObjectEstimate {
            run_id: run.clone(),
            object: object.into(),
            mesh: None,
            pose: Pose::IDENTITY,
            seq: 1,
            stamp_ms: 0,
            source: "test".into(),
        }
    }

    /// A session listening on loopback (the hand's) and one connected to it.
    async fn sessions() -> (Bus, Bus) {
        let s = Bus::loopback(1).await.unwrap();
        (s.hub, s.peers.into_iter().next().unwrap())
    }

    /// Trial, attempt, worker, hand, number of clouds and error of a clouds message.
    fn summary(c: &ContactClouds) -> (u64, u32, &str, &str, usize, Option<&str>) {
        (
            c.trial_id,
            c.attempt,
            c.worker.as_str(),
            c.hand.as_str(),
            c.fingers.len(),
            c.error.as_deref(),
        )
    }

    /// The coordinator's and metric agent's side of one hand served on loopback: a command
    /// waits for the object estimate, each command of the run and worker gets its clouds
    /// (tagged, padded to the cost, a failure as an error), a command for another hand is
    /// refused without executing, stray messages are not acted on, and serving ends when the
    /// session closes.
    #[test]
    fn serve_answers_each_command_of_its_run_and_worker_once() {
        let rt = tokio::runtime::Runtime::new().unwrap();
        rt.block_on(async {
            let run = RunId::new("servetest").unwrap();
            let other = RunId::new("elsewhere").unwrap();
            let (hand_bus, bus) = sessions().await;
            let mut clouds = CloudReceiver::open(&bus, &run).await.unwrap();
            let hands = bus
                .watch_alive(&alive_key((&run).into(), Some(AgentKind::Hand)))
                .await
                .unwrap();
            let seen = Arc::new(Mutex::new(Vec::new()));
            let driver = Flaky {
                seen: seen.clone(),
                object: false,
            };
            let (b, r) = (hand_bus.clone(), run.clone());
            let cost = Duration::from_millis(60);
            let served = tokio::spawn(async move { serve(&b, &r, "w1", cost, driver).await });
            let alive = hands.recv().await.unwrap();
            assert!(alive.alive && alive.agent.id == "w1");

            let key = COMMAND.worker_key((&run).into(), "w1");
            let put = |c: TrialCommand| {
                let (bus, key) = (bus.clone(), key.clone());
                async move { bus.put(&key, &c, Encoding::Bincode).await.unwrap() }
            };
            let sent_ms = now_ms();
            // Before any estimate: the command waits for one; another run's is ignored.
            put(command(&run, 1, "w1", "barrett")).await;
            let object_key = OBJECT.key((&run).into());
            bus.put(&object_key, &estimate(&other, "mug"), Encoding::Json)
                .await
                .unwrap();
            bus.put(&object_key, &estimate(&run, "sphere"), Encoding::Json)
                .await
                .unwrap();
            // Stray messages: another worker's, another run's, undecodable bytes.
            put(command(&run, 7, "w2", "barrett")).await;
            put(command(&other, 8, "w1", "barrett")).await;
            bus.put_bytes(
                key.as_str(),
                vec![1, 2, 3],
                Encoding::Bincode,
                CongestionControl::Block,
            )
            .await
            .unwrap();
            put(command(&run, 2, "w1", "barrett")).await;
            put(command(&run, 3, "w1", "parallel_jaw")).await;
            put(command(&run, 5, "w1", "barrett")).await;

            let mut got = Vec::new();
            for _ in 0..4 {
                let c = tokio::time::timeout(Duration::from_secs(20), clouds.recv())
                    .await
                    .expect("clouds within 20 s")
                    .unwrap()
                    .message
                    .unwrap();
                got.push(c);
            }
            assert_eq!(
                got.iter().map(summary).collect::<Vec<_>>(),
                [
                    (1, 2, "w1", "barrett", 1, None),
                    (2, 2, "w1", "barrett", 0, Some("fault on trial 2")),
                    (
                        3,
                        2,
                        "w1",
                        "barrett",
                        0,
                        Some("worker w1 has a barrett hand, the trial asks for parallel_jaw")
                    ),
                    (5, 2, "w1", "barrett", 1, None),
                ]
            );
            assert!(got.iter().all(|c| c.run_id == run));
            // The reading's pose for an executed trial, the command's for a refused one.
            assert_eq!(got[0].palm_pose, Pose::IDENTITY);
            assert_eq!(got[0].min_gap, Some(0.5));
            assert_eq!(got[0].fingers[0].points[0].p, [0.0, 0.0, 1.0]);
            assert_eq!(got[2].palm_pose.translation, [0.0, 0.0, 0.3]);
            // One trial at a time, each padded to the cost.
            for (i, c) in got.iter().enumerate() {
                assert!(c.executed_ms >= sent_ms + 60 * (i as i64 + 1), "{i}");
            }
            assert_eq!(
                *seen.lock().unwrap(),
                ["sphere", "trial 1", "trial 2", "trial 5"]
            );
            // The hand's session closing ends it.
            hand_bus.close().await.unwrap();
            tokio::time::timeout(Duration::from_secs(5), served)
                .await
                .expect("serve ends once its session closed")
                .unwrap()
                .unwrap();
            let _ = bus.close().await;
        });
    }

    /// A hand whose place turns out to be held by another with a smaller nonce (both took
    /// it at the same moment; the other's claim, declared here by hand, reached it late)
    /// stops serving with the error naming its id, and its token vanishes.
    #[test]
    fn serve_gives_way_to_a_hand_that_holds_its_id_with_a_smaller_nonce() {
        let rt = tokio::runtime::Runtime::new().unwrap();
        rt.block_on(async {
            let run = RunId::new("givewaytest").unwrap();
            // The hand on the session that connects: one that only listens meets nobody and
            // holds its place unchallenged.
            let (bus, hand_bus) = sessions().await;
            assert!(hand_bus.reaches_out());
            let hands = bus
                .watch_alive(&alive_key((&run).into(), Some(AgentKind::Hand)))
                .await
                .unwrap();
            let driver = Flaky {
                seen: Arc::new(Mutex::new(Vec::new())),
                object: true,
            };
            let (b, r) = (hand_bus.clone(), run.clone());
            let served =
                tokio::spawn(async move { serve(&b, &r, "w1", Duration::ZERO, driver).await });
            let alive = hands.recv().await.unwrap();
            assert!(alive.alive && alive.agent.id == "w1");
            assert!(!served.is_finished());
            let claim = Claim {
                nonce: 0,
                phase: ClaimPhase::Settled,
            };
            let _other = bus
                .session()
                .liveliness()
                .declare_token(claim_token(&run, AgentKind::Hand, "w1", claim))
                .await
                .unwrap();
            let e = tokio::time::timeout(Duration::from_secs(2), served)
                .await
                .expect("the hand gives way within 2 s")
                .unwrap()
                .expect_err("an error");
            assert!(
                e.to_string().contains(
                    "another agent, a hand with the id w1, took its place at the same moment \
                     and keeps it: this one gives way (give it another --id)"
                ),
                "{e}"
            );
            let gone = tokio::time::timeout(Duration::from_secs(2), hands.recv())
                .await
                .expect("the token vanishes")
                .unwrap();
            assert!(!gone.alive && gone.agent.id == "w1", "{gone:?}");
            let _ = bus.close().await;
            let _ = hand_bus.close().await;
        });
    }
}
