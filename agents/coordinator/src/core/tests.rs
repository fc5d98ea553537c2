use graspopt_bus::{AliveEvent, BusError};
use graspopt_protocol::keys::AliveKey;
use graspopt_protocol::{
    AgentKind, Encoding, ObjectEstimate, Pose, RunId, SuggestReply, SuggestRequest, TrialResult,
    WaitReason,
};

use super::*;
use crate::core::planner::PLANNER_RETRY_MS;

const LEASE: i64 = 1_000;

/// A coordinator of run `r` (`trials` trials, one parameter), its object estimate in, a
/// metric agent alive, and hands `workers`.
fn coordinator(trials: u64, workers: &[&str]) -> Coordinator {
    let spec = crate::spec::tests::spec(trials);
    let run = RunId::new("r").unwrap();
    let mut c = Coordinator::new(&run, spec, RunState::new(trials), None, LEASE as u64, 0);
    c.handle(
        Event::Estimate(Box::new(ObjectEstimate {
            run_id: run.clone(),
            object: "sphere".into(),
            mesh: None,
            pose: Pose::IDENTITY,
            seq: 1,
            stamp_ms: 0,
            source: "test".into(),
        })),
        0,
    )
    .unwrap();
    c.handle(Event::Metric(alive(AgentKind::Metric, "m")), 0)
        .unwrap();
    for w in workers {
        c.handle(Event::Hand(alive(AgentKind::Hand, w)), 0).unwrap();
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

/// The token of `kind` agent `id` of run `r` appearing.
fn alive(kind: AgentKind, id: &str) -> AliveEvent {
    AliveEvent {
        alive: true,
        agent: agent(kind, id),
    }
}

fn poll(c: &mut Coordinator, now: i64) -> Vec<Action> {
    c.handle(Event::Poll, now).unwrap()
}

fn on_reply(c: &mut Coordinator, reply: Result<SuggestReply, BusError>, now: i64) -> Vec<Action> {
    c.handle(Event::Reply(reply), now).unwrap()
}

fn on_result(c: &mut Coordinator, result: TrialResult, now: i64) -> Vec<Action> {
    c.handle(Event::Result(Box::new(result)), now).unwrap()
}

fn lease_tick(c: &mut Coordinator, now: i64) {
    assert!(c.handle(Event::LeaseTick, now).unwrap().is_empty());
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
        if let Action::Write(Write::Issue(issue)) = a {
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
            Action::Write(w) => Some(w),
            _ => None,
        })
        .collect()
}

#[test]
fn an_expired_lease_re_issues_the_trial_once_the_silent_worker_is_freed() {
    let mut c = coordinator(1, &["a"]);
    let request = asked(&poll(&mut c, 0));
    assert_eq!((request.count, request.request_id), (1, 1));
    let actions = on_reply(&mut c, Ok(reply(&request, vec![vec![0.01]])), 10);
    assert_eq!(
        actions[0],
        Action::Write(Write::PlannerState {
            engine: vec![7],
            at_ms: 10
        })
    );
    assert_eq!(issued(&actions), [(1, 1, "a".into(), None)]);
    // The lease runs out: the trial is queued again, its worker busy for the grace.
    lease_tick(&mut c, 10 + LEASE);
    assert!(poll(&mut c, 10 + LEASE).is_empty());
    lease_tick(&mut c, 11 + LEASE);
    assert!(issued(&poll(&mut c, 11 + LEASE)).is_empty());
    assert_eq!(c.status(11 + LEASE).errors.reissued, 1);
    // After the grace the lone worker is free and gets the trial again: attempt 2.
    lease_tick(&mut c, 12 + 2 * LEASE);
    let again = poll(&mut c, 12 + 2 * LEASE);
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
    let request = asked(&poll(&mut c, 0));
    let points = vec![vec![-0.1], vec![-0.05], vec![0.0]];
    let actions = on_reply(&mut c, Ok(reply(&request, points)), 5);
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
    assert!(!rest.iter().any(|a| matches!(a, Action::Write(_))));
}

/// A planner's point outside the trial space (or not finite) is counted and left out;
/// it failed the whole coordinator before (its palm pose is refused when issued). A
/// reply of such points only is a planner that cannot propose: asked again later.
#[test]
fn proposals_outside_the_trial_space_are_left_out() {
    let mut c = coordinator(3, &["a", "b", "c"]);
    let request = asked(&poll(&mut c, 0));
    let points = vec![vec![0.5], vec![-0.1], vec![f64::NAN]];
    let actions = on_reply(&mut c, Ok(reply(&request, points)), 5);
    assert_eq!(issued(&actions), [(1, 1, "a".into(), None)]);
    assert_eq!(c.status(5).errors.bad_messages, 2);
    // Another question for the two still needed, at once.
    let request = asked(&poll(&mut c, 6));
    assert_eq!(request.count, 2);
    let actions = on_reply(&mut c, Ok(reply(&request, vec![vec![-0.2], vec![0.03]])), 7);
    assert!(issued(&actions).is_empty());
    assert_eq!(c.status(7).errors.bad_messages, 4);
    // Only bad points: asked again after the retry delay, not at once.
    assert!(poll(&mut c, 8).is_empty());
    let request = asked(&poll(&mut c, 7 + PLANNER_RETRY_MS));
    let actions = on_reply(
        &mut c,
        Ok(reply(&request, vec![vec![-0.16], vec![0.02]])),
        600,
    );
    assert_eq!(
        issued(&actions).len(),
        2,
        "the bounds themselves are inside"
    );
}

#[test]
fn a_duplicate_result_is_recorded_once_and_counted() {
    let mut c = coordinator(1, &["a"]);
    let request = asked(&poll(&mut c, 0));
    on_reply(&mut c, Ok(reply(&request, vec![vec![0.01]])), 0);
    let first = on_result(&mut c, result(1, 1, "a", 0.5), 100);
    let [Write::Result(r)] = records(&first)[..] else {
        panic!("{first:?}")
    };
    assert_eq!((r.trial_id, r.attempt, r.score, r.at_ms), (1, 1, 0.5, 100));
    assert!(c.finished());
    let again = on_result(&mut c, result(1, 1, "a", 0.9), 200);
    assert!(records(&again).is_empty(), "{again:?}");
    let [Action::Progress(s)] = &again[..] else {
        panic!("{again:?}")
    };
    assert_eq!((s.completed, s.errors.duplicates), (1, 1));
    assert_eq!(s.best.as_ref().unwrap().score, 0.5);
    // A result never issued is counted and not recorded either.
    let stray = on_result(&mut c, result(1, 1, "b", 0.7), 300);
    assert!(records(&stray).is_empty());
    assert_eq!(c.status(300).errors.not_issued, 1);
}

#[test]
fn a_planner_down_is_asked_again_and_waited_for_until_it_is_back() {
    let mut c = coordinator(2, &["a", "b"]);
    let first = asked(&poll(&mut c, 0));
    let key = "graspopt/r/planner/suggest".to_string();
    let none = on_reply(&mut c, Err(BusError::NoResponder { key }), 10);
    assert!(none.is_empty());
    // Not asked again before the retry time; then asked again with a new id.
    assert!(poll(&mut c, 10 + PLANNER_RETRY_MS - 1).is_empty());
    let second = asked(&poll(&mut c, 10 + PLANNER_RETRY_MS));
    assert_eq!((first.request_id, second.request_id), (1, 2));
    // The run shows it waits for the planner (since it went down) once that lasts.
    let s = c.status(2_000);
    assert_eq!(s.waiting.len(), 1);
    assert_eq!(
        (s.waiting[0].reason, s.waiting[0].since_ms),
        (WaitReason::Planner, 10)
    );
    // A planner appears: the question in flight is dropped and asked again at once.
    let planner = alive(AgentKind::Planner, "p");
    let back = || Event::Planner(planner.clone());
    assert_eq!(c.handle(back(), 2_000).unwrap(), [Action::CancelAsk]);
    assert!(c.handle(back(), 2_001).unwrap().is_empty());
    let third = asked(&poll(&mut c, 2_001));
    assert_eq!((third.request_id, third.count), (3, 2));
    let actions = on_reply(
        &mut c,
        Ok(reply(&third, vec![vec![0.01], vec![0.02]])),
        2_100,
    );
    assert_eq!(issued(&actions).len(), 2);
    poll(&mut c, 2_100);
    assert!(c.status(4_000).waiting.is_empty());
    // Later requests carry the engine state the planner sent.
    assert_eq!(c.planner.engine_state, Some(vec![7]));
}

#[test]
fn bad_proposals_and_messages_are_counted_and_a_wrong_object_stops_the_run() {
    let mut c = coordinator(2, &["a", "b"]);
    let request = asked(&poll(&mut c, 0));
    let actions = on_reply(
        &mut c,
        Ok(reply(&request, vec![vec![0.01, 0.0], vec![0.02]])),
        0,
    );
    assert_eq!(issued(&actions), [(1, 1, "a".into(), None)]);
    c.handle(Event::BadMessage, 0).unwrap();
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
    let e = other
        .handle(Event::Estimate(Box::new(mug)), 0)
        .unwrap_err()
        .to_string();
    assert_eq!(e, "perception sees \"mug\", the run is about \"sphere\"");
}
