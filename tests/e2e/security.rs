//! The authenticated deployment of `deploy/zenoh/secure/` (issue 7): agents log in to the
//! router with a user name and password, and the router's access-control list lets each
//! role publish only what it publishes. A run goes through; a client without credentials or
//! with a wrong password cannot connect; an observer (allowed to watch) and a hand (allowed
//! to publish clouds) cannot get a forged result to the coordinator, let alone the journal.

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::support::{Cluster, check_journal, cloud_transport, repo_root, report};
use graspopt_bus::Bus;
use graspopt_protocol::keys::{RESULT, Runs, TABLE, alive_key, alive_token};
use graspopt_protocol::{AgentKind, Encoding, RunId, TrialResult};
use serde_json::json;

const TRIALS: u64 = 8;

pub(crate) fn secure(file: &str) -> PathBuf {
    repo_root().join("deploy/zenoh/secure").join(file)
}

/// The router's configuration with the dictionary's path made absolute (the file names it
/// relative to the repository root), written to `dir`.
pub(crate) fn router_config(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(secure("router.json5")).unwrap();
    let relative = "deploy/zenoh/secure/credentials.txt";
    assert!(text.contains(relative));
    let absolute = secure("credentials.txt");
    let path = dir.join("router.json5");
    std::fs::write(&path, text.replace(relative, absolute.to_str().unwrap())).unwrap();
    vec!["--zenoh-config".into(), path.to_str().unwrap().into()]
}

/// A result that the coordinator would take for trial `id` from `hand-1`, the only worker,
/// if it reached it: attempt 1, an impossible score.
fn forged(id: u64) -> TrialResult {
    TrialResult {
        run_id: RunId::new("sec").unwrap(),
        trial_id: id,
        attempt: 1,
        worker: "hand-1".into(),
        scorer: "metric".into(),
        score: 1.0e6,
        metrics: None,
        contacts: 3,
        fingers_in_contact: 3,
        cloud_points: 3,
        cloud_transport: "zenoh".into(),
        error: None,
        forces: None,
    }
}

#[test]
fn only_authenticated_agents_in_their_roles_reach_the_journal() {
    let c = Cluster::start_with("secure", "sec", router_config);
    let role = |r: &str| secure(&format!("{r}.json5"));
    // Clouds over Zenoh too (no shared memory), as between two hosts: the ACL sees them.
    let agent = |name: &str, r: &str, args: &[&str]| {
        let config = role(r);
        let mut v = args.to_vec();
        v.extend_from_slice(&["--zenoh-config", config.to_str().unwrap(), "--no-shm"]);
        c.agent(name, &v)
    };
    let _perception = agent(
        "perception",
        "perception",
        &["perception", "--set", "object=cuboid"],
    );
    let _planner = agent("planner", "planner", &["planner"]);
    let _metric = agent("metric", "metric", &["metric"]);
    let _hand = agent(
        "hand-1",
        "hand",
        &["hand", "--id", "hand-1", "--set", "trial_cost_ms=300"],
    );
    let config = role("coordinator");
    let coordinator = c.coordinator(
        "cuboid",
        &TRIALS.to_string(),
        "4",
        &["--zenoh-config", config.to_str().unwrap(), "--no-shm"],
    );
    let run = RunId::new("sec").unwrap();
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let (refused, forged_sent, observed, posing) = runtime.block_on(async {
        // No credentials, and a wrong password: refused when connecting.
        let anonymous = Bus::open(&c.client_args(None)).await;
        let wrong = c.dir.join("wrong.json5");
        let text = std::fs::read_to_string(role("hand")).unwrap();
        std::fs::write(&wrong, text.replace("change-me-hand", "guess")).unwrap();
        let guessed = Bus::open(&c.client_args(Some(wrong))).await;
        let refused = [anonymous.is_err(), guessed.is_err()];

        // An observer may watch the results, and a hand may publish clouds; neither may
        // publish a result. Both try, for every trial, all through the run.
        // (The watcher is a session of its own: a session delivers its own puts to its own
        // subscribers without the router.)
        let watcher = Bus::open(&c.client_args(Some(role("observer"))))
            .await
            .unwrap();
        let observer = Bus::open(&c.client_args(Some(role("observer"))))
            .await
            .unwrap();
        let hand = Bus::open(&c.client_args(Some(role("hand")))).await.unwrap();
        let results = watcher
            .subscribe::<TrialResult>(&RESULT.key(Runs::One(&run)).to_string())
            .await
            .unwrap();
        // A hand posing as a metric agent (the coordinator would issue trials to nobody).
        let _posing = hand
            .declare_alive(&run, AgentKind::Metric, "posing-metric")
            .await
            .unwrap();
        let mut sent = 0u64;
        let mut observed = 0u64;
        while observed < TRIALS {
            for id in 1..=TRIALS {
                for bus in [&observer, &hand] {
                    bus.put(
                        &RESULT.key(Runs::One(&run)).to_string(),
                        &forged(id),
                        Encoding::Bincode,
                    )
                    .await
                    .unwrap();
                    sent += 1;
                }
            }
            // The observer sees the real results (never a forged one).
            if let Ok(Some(r)) =
                tokio::time::timeout(Duration::from_millis(50), results.recv()).await
            {
                let r = r.message.unwrap();
                assert!(r.score < 1.0e6, "a forged result went through: {r:?}");
                observed += 1;
            }
            assert!(sent < 200_000, "the run does not progress");
        }
        let metrics: Vec<String> = watcher
            .alive_now(&alive_key(Runs::One(&run), Some(AgentKind::Metric)))
            .await
            .unwrap()
            .into_iter()
            .map(|a| a.id)
            .collect();
        assert_eq!(
            metrics,
            ["metric"],
            "metric agents the router lets others see"
        );
        let posing = metrics.iter().filter(|m| *m != "metric").count();
        (refused, sent, observed, posing)
    });
    assert_eq!(
        refused,
        [true, true],
        "clients without valid credentials connected"
    );
    let status = c.final_status(coordinator, Duration::from_secs(120));
    assert_eq!(status["completed"], TRIALS, "{status}");
    // Had any forged result reached the coordinator it would have completed a trial (score
    // 1e6) or been counted: as a duplicate, or as not issued.
    let reached: u64 = ["bad_messages", "unknown_trial", "not_issued", "duplicates"]
        .iter()
        .map(|k| status["errors"][k].as_u64().unwrap())
        .sum();
    assert_eq!(
        reached, 0,
        "forged results reached the coordinator: {status}"
    );
    let trials = check_journal(&c.journal(), "sec", TRIALS as usize);
    assert!(trials.iter().all(|t| t.score.unwrap() < 1.0e6));
    assert!(trials.iter().all(|t| cloud_transport(t) == "zenoh"));
    report(json!({
        "test": "security: user/password authentication and access control",
        "refused_connections": refused.iter().filter(|r| **r).count(),
        "forged_results_sent": forged_sent, "posing_liveliness_tokens_seen": posing,
        "forged_results_reaching_the_coordinator": reached, "real_results_seen_by_observer": observed,
        "trials": TRIALS,
    }));
}

/// The router's access list as Zenoh reads it: per role, the rules it may use, as
/// `(messages, key expressions)` of the rules that allow ingress.
fn ingress_rules(role: &str) -> Vec<(Vec<String>, Vec<String>)> {
    let config = zenoh::Config::from_file(secure("router.json5")).unwrap();
    let acl: serde_json::Value =
        serde_json::from_str(&config.get_json("access_control").unwrap()).unwrap();
    let subjects: Vec<&str> = acl["subjects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["usernames"].as_array().unwrap().iter().any(|u| u == role))
        .map(|s| s["id"].as_str().unwrap())
        .collect();
    let granted: Vec<&str> = acl["policies"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| {
            p["subjects"]
                .as_array()
                .unwrap()
                .iter()
                .any(|s| subjects.contains(&s.as_str().unwrap()))
        })
        .flat_map(|p| p["rules"].as_array().unwrap().iter())
        .map(|r| r.as_str().unwrap())
        .collect();
    let strings = |v: &serde_json::Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_string())
            .collect()
    };
    acl["rules"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| granted.contains(&r["id"].as_str().unwrap()))
        .filter(|r| {
            r["permission"] == "allow" && strings(&r["flows"]).iter().any(|f| f == "ingress")
        })
        .map(|r| (strings(&r["messages"]), strings(&r["key_exprs"])))
        .collect()
}

/// Whether `role` may send `message` on every key of `key` (a key expression).
fn allowed(rules: &[(Vec<String>, Vec<String>)], message: &str, key: &str) -> bool {
    let key = zenoh::key_expr::KeyExpr::try_from(key.to_string()).unwrap();
    rules.iter().any(|(messages, exprs)| {
        messages.iter().any(|m| m == message)
            && exprs.iter().any(|e| {
                zenoh::key_expr::KeyExpr::try_from(e.clone())
                    .unwrap()
                    .includes(&key)
            })
    })
}

/// The access list of `router.json5` against the key table: every topic may be put by the
/// role that publishes it and by no other, every query served by its role, and every agent
/// kind may declare its liveliness token. (A topic added to the table without its rule
/// here: its hand, say, would be silently dropped by the router.)
#[test]
fn the_routers_access_list_lets_each_role_publish_what_the_key_table_says() {
    use graspopt_protocol::AgentKind;
    let roles: Vec<&str> = AgentKind::ALL.iter().map(|k| k.as_str()).collect();
    let mut missing = Vec::new();
    let mut extra = Vec::new();
    for entry in TABLE {
        let key = entry.key_expr(Runs::All);
        for role in roles.iter().copied().chain(["observer"]) {
            let rules = ingress_rules(role);
            let publishes = role == entry.by.as_str();
            let needs: &[&str] = if entry.is_query() {
                &["declare_queryable", "reply"]
            } else {
                &["put"]
            };
            for message in needs {
                match (publishes, allowed(&rules, message, &key)) {
                    (true, false) => missing.push(format!("{role} may not {message} on {key}")),
                    (false, true) => extra.push(format!("{role} may {message} on {key}")),
                    _ => {}
                }
            }
        }
    }
    let run = RunId::new("r").unwrap();
    let mut tokens: Vec<(AgentKind, String)> = AgentKind::ALL
        .into_iter()
        .map(|kind| (kind, alive_token(&run, kind, "host", "agent-1", None)))
        .collect();
    // A hand's token may name the topic it publishes.
    for topic in graspopt_protocol::keys::Topic::ALL {
        if topic.entry().by == AgentKind::Hand {
            let token = alive_token(&run, AgentKind::Hand, "host", "h-1", Some(topic));
            tokens.push((AgentKind::Hand, token));
        }
    }
    for (kind, token) in tokens {
        if !allowed(&ingress_rules(kind.as_str()), "liveliness_token", &token) {
            missing.push(format!("{} may not declare {token}", kind.as_str()));
        }
    }
    assert!(missing.is_empty(), "router.json5 lacks rules: {missing:#?}");
    assert!(extra.is_empty(), "router.json5 allows too much: {extra:#?}");
}

/// A failed login to the secure router is said as one: no credentials (a peer or a client
/// without `transport.auth.usrpwd`) or a wrong password, for an agent and for a watcher,
/// naming the endpoint and what to check, without Zenoh's source-file paths. An address
/// where nothing listens is still "nothing answers".
#[test]
fn a_failed_login_says_that_authentication_failed() {
    let c = Cluster::start_with("secure-login", "sec-login", router_config);
    let wrong = c.dir.join("wrong-hand.json5");
    let text = std::fs::read_to_string(secure("hand.json5")).unwrap();
    std::fs::write(&wrong, text.replace("change-me-hand", "guess")).unwrap();
    let wrong = wrong.to_str().unwrap().to_string();
    let ep = c.endpoint.as_str();
    for (args, user) in [
        // A wrong password, in client mode: an agent and a watcher.
        (
            vec![
                "agent",
                "hand",
                "--run",
                "r",
                "--zenoh-config",
                &wrong,
                "--connect",
                ep,
            ],
            "user \"hand\"",
        ),
        (
            vec!["topic", "list", "--zenoh-config", &wrong, "--connect", ep],
            "user \"hand\"",
        ),
        // No credentials at all: a watcher as a peer, and an agent as a client.
        (
            vec!["topic", "list", "--connect", ep],
            "gives no user name and password",
        ),
        (
            vec![
                "agent",
                "planner",
                "--run",
                "r",
                "--mode",
                "client",
                "--connect",
                ep,
            ],
            "gives no user name and password",
        ),
    ] {
        let out = crate::support::graspopt(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        for part in [
            &format!("authentication failed at {ep}"),
            user,
            "transport.auth.usrpwd",
            "credentials dictionary",
        ] {
            assert!(stderr.contains(part), "{args:?}: {part:?} not in {stderr}");
        }
        for not in [".rs:", "Unable to connect", "nothing answers"] {
            assert!(!stderr.contains(not), "{args:?}: {not:?} in {stderr}");
        }
    }
}
