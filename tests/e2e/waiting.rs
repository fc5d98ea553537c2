//! A coordinator that cannot issue trials says what it waits for: in its log (after a second,
//! then every few seconds), in the run's status and in `graspopt monitor`.

use std::time::Duration;

use crate::support::{Cluster, graspopt, wait_until};

#[test]
fn the_coordinator_says_what_it_waits_for_in_its_log_status_and_monitor() {
    let c = Cluster::start("waiting", "wait");
    let coordinator = c.coordinator("sphere", "3", "1", &["--method", "random"]);
    // Nothing else runs: before, the coordinator printed nothing at all.
    wait_until(
        "the coordinator says it waits for perception, a metric agent and a hand",
        Duration::from_secs(20),
        || {
            c.log("coordinator")
                .contains("run \"wait\" is waiting: no object estimate yet (")
                && c.log("coordinator").contains("no metric agent (")
                && c.log("coordinator").contains("no hand (")
        },
    );
    let connect = ["--connect", c.endpoint.as_str(), "--no-shm"];
    let mut args = vec!["monitor", "--once", "--run", "wait"];
    args.extend(connect);
    let o = graspopt(&args);
    let text = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        text.contains("waiting: no object estimate yet (")
            && text.contains("s), no metric agent (")
            && text.contains("s), no hand ("),
        "{text}\n{stderr}"
    );
    // The status on the bus carries the same.
    let mut args = vec![
        "topic", "echo", "status", "--run", "wait", "--count", "1", "--format", "json",
    ];
    args.extend(connect);
    let o = graspopt(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let status: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&o.stdout).lines().next().unwrap()).unwrap();
    let reasons: Vec<&str> = status["message"]["waiting"]
        .as_array()
        .unwrap_or_else(|| panic!("no waiting in {status}"))
        .iter()
        .map(|w| w["reason"].as_str().unwrap())
        .collect();
    assert_eq!(
        reasons,
        ["object_estimate", "metric_agent", "hand"],
        "{status}"
    );

    // Everything but the planner: the wait changes to the planner's answer.
    let _perception = c.agent("perception", &["perception", "--set", "object=sphere"]);
    let _metric = c.agent("metric", &["metric"]);
    let _hands = c.hands(1, &[]);
    wait_until(
        "the coordinator says it waits for the planner",
        Duration::from_secs(30),
        || {
            c.log("coordinator")
                .contains("run \"wait\" is waiting: no planner answer (")
        },
    );
    let _planner = c.agent("planner", &["planner"]);
    let status = c.final_status(coordinator, Duration::from_secs(60));
    assert_eq!(status["completed"], 3, "{status}");
    assert_eq!(status["waiting"], serde_json::json!([]), "{status}");
    let log = c.log("coordinator");
    assert!(log.contains("run \"wait\" is no longer waiting"), "{log}");
}
