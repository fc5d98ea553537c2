//! Several machines, each with its own router, on one host: Linux network namespaces made by
//! the test, so every "machine" has its own network stack and address and its agents reach
//! the others only through the routers. One router is killed (SIGKILL) mid-run and started
//! again; the run completes with nothing lost. This is the two-machine guide of
//! `deploy/README.md`, with a third machine: the same router configuration and flags.
//!
//! Namespaces need root (CAP_NET_ADMIN) and `ip` (iproute2). Without them the test is skipped
//! with a message on stderr, unless `GRASPOPT_REQUIRE_NETNS=1` (set by `.ci/run`) makes that a
//! failure. Run it with `cargo test -p graspopt --test e2e -- --ignored netns::`.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use crate::support::{
    Proc, assert_nothing_lost, check_journal, cloud_transport, col, completed_now, graspopt,
    graspopt_bin, read_csv, repo_root, report, tempdir, wait_until,
};
use graspopt_journal::{Journal, StoredTrialPhase, event_kind};
use serde_json::json;

/// Prefix of the namespaces this test makes: `<prefix><pid>-<nonce>-<machine>`.
const PREFIX: &str = "graspopt-e2e-";

/// The machines: namespace suffix and address on the shared link (a /24).
const MACHINES: [(&str, &str); 3] = [("a", "10.47.0.1"), ("b", "10.47.0.2"), ("c", "10.47.0.3")];

/// The port every router listens on (deploy/zenoh/router.json5): each namespace has its own.
const ROUTER_PORT: u16 = 7447;

/// Runs `ip args...`; the error names the command and what `ip` said.
fn ip(args: &[&str]) -> Result<(), String> {
    let out = Command::new("ip")
        .args(args)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run `ip` (iproute2): {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "`ip {}` failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

/// Network namespaces joined by a bridge, deleted when dropped (a failed test included): the
/// processes still in them are killed, the veth pairs and the namespaces deleted. Nothing is
/// made in the host's own namespace: the bridge lives in a namespace of its own.
struct Net {
    /// The bridge's namespace.
    switch: String,
    /// The machines' namespaces, in [`MACHINES`] order.
    machines: Vec<String>,
    /// Every namespace made so far (for the cleanup, also of a half-made net).
    made: Vec<String>,
}

impl Net {
    /// Makes the namespaces (names unique to this test process and call), links each to the
    /// bridge with a veth pair, and gives each its address; loopback is up in each.
    fn create() -> Result<Net, String> {
        sweep_leftovers();
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let base = format!("{PREFIX}{}-{nanos:x}-", std::process::id());
        let mut net = Net {
            switch: format!("{base}sw"),
            machines: MACHINES.iter().map(|(m, _)| format!("{base}{m}")).collect(),
            made: Vec::new(),
        };
        let sw = net.switch.clone();
        net.add(&sw)?;
        ip(&["-n", &sw, "link", "add", "br0", "type", "bridge"])?;
        ip(&["-n", &sw, "link", "set", "br0", "up"])?;
        for (ns, (m, addr)) in net.machines.clone().iter().zip(MACHINES) {
            net.add(ns)?;
            let port = format!("p{m}");
            // The pair is made with its ends already in place: eth0 in the machine, the
            // port on the bridge.
            ip(&[
                "link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", &port, "netns",
                &sw,
            ])?;
            ip(&["-n", &sw, "link", "set", &port, "master", "br0"])?;
            ip(&["-n", &sw, "link", "set", &port, "up"])?;
            ip(&[
                "-n",
                ns,
                "addr",
                "add",
                &format!("{addr}/24"),
                "dev",
                "eth0",
            ])?;
            ip(&["-n", ns, "link", "set", "eth0", "up"])?;
            ip(&["-n", ns, "link", "set", "lo", "up"])?;
        }
        // Processes can be started inside (`ip netns exec` needs to remount /sys).
        ip(&["netns", "exec", &net.machines[0], "true"])?;
        Ok(net)
    }

    fn add(&mut self, ns: &str) -> Result<(), String> {
        ip(&["netns", "add", ns])?;
        self.made.push(ns.to_string());
        Ok(())
    }

    /// Starts `graspopt args...` inside namespace `ns`, stderr to `<logs>/<name>.log`
    /// (`ip netns exec` execs the program: the process is graspopt itself).
    fn start(&self, ns: &str, name: &str, args: &[&str], logs: &Path) -> Proc {
        let log = std::fs::File::create(logs.join(format!("{name}.log"))).unwrap();
        let child = Command::new("ip")
            .args(["netns", "exec", ns])
            .arg(graspopt_bin())
            .args(args)
            .env("RUST_LOG", "warn")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(log)
            .spawn()
            .unwrap_or_else(|e| panic!("start {name} in {ns}: {e}"));
        Proc {
            name: name.to_string(),
            child,
        }
    }
}

impl Net {
    /// Stops every process in the namespaces as a service manager would (SIGTERM: agents
    /// close their sessions and release their shared memory), waiting up to 10 s.
    fn stop(&self) {
        for ns in &self.made {
            signal_all_in(ns, "TERM");
        }
        let start = Instant::now();
        while self.made.iter().any(|ns| !pids_in(ns).is_empty())
            && start.elapsed() < Duration::from_secs(10)
        {
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Net {
    fn drop(&mut self) {
        for ns in &self.made {
            kill_all_in(ns);
        }
        for (m, _) in MACHINES {
            let _ = ip(&["-n", &self.switch, "link", "del", &format!("p{m}")]);
        }
        for ns in self.made.iter().rev() {
            if let Err(e) = ip(&["netns", "del", ns]) {
                eprintln!("netns: cleanup: {e}");
            }
        }
    }
}

/// The processes in namespace `ns` (only this test's own start there).
fn pids_in(ns: &str) -> Vec<String> {
    Command::new("ip")
        .args(["netns", "pids", ns])
        .output()
        .map(|out| {
            String::from_utf8_lossy(&out.stdout)
                .split_whitespace()
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default()
}

/// Sends `signal` (`TERM`, `KILL`) to every process in namespace `ns`.
fn signal_all_in(ns: &str, signal: &str) {
    for pid in pids_in(ns) {
        let _ = Command::new("kill")
            .args([format!("-{signal}"), pid])
            .status();
    }
}

/// SIGKILLs every process left in namespace `ns`.
fn kill_all_in(ns: &str) {
    signal_all_in(ns, "KILL");
}

/// Deletes the namespaces of earlier runs of this test whose process is gone (a test killed
/// before its cleanup ran). Unique names already keep them from colliding; this keeps them
/// from piling up.
fn sweep_leftovers() {
    let Ok(out) = Command::new("ip").args(["netns", "list"]).output() else {
        return;
    };
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        let Some(name) = line.split_whitespace().next() else {
            continue;
        };
        let Some(pid) = name
            .strip_prefix(PREFIX)
            .and_then(|rest| rest.split('-').next())
        else {
            continue;
        };
        if !Path::new("/proc").join(pid).exists() {
            kill_all_in(name);
            let _ = ip(&["netns", "del", name]);
        }
    }
}

/// Whether `GRASPOPT_REQUIRE_NETNS=1` makes a skip a failure.
fn required() -> bool {
    std::env::var("GRASPOPT_REQUIRE_NETNS").is_ok_and(|v| v == "1")
}

/// Milliseconds since the epoch (the journal's clock: the coordinator runs on this host).
fn now_ms() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as i64)
}

/// Three machines, each a network namespace with its own address and router; the routers of
/// b and c connect to a's (as robot-pc's router connects to lab-pc's in deploy/README.md),
/// and every agent connects only to the router of its own machine:
///
/// - a (10.47.0.1): router, perception, planner, coordinator (and journal), hand a-1
/// - b (10.47.0.2): router, metric agent, hands b-1 and b-2 (clouds through shared memory)
/// - c (10.47.0.3): router, hands c-1 and c-2 (clouds over Zenoh, through c's, a's and b's
///   routers to b's metric agent)
///
/// c's router is killed (SIGKILL) while c's hands hold trials and started again a second
/// later: the coordinator sees c's hands vanish and re-issues their trials, c's hands
/// reconnect by themselves and take trials again, and the run completes its budget with
/// every trial recorded exactly once.
#[test]
#[ignore = "needs root for network namespaces: .ci/run runs it (tests/e2e/main.rs)"]
fn a_run_across_three_network_namespaces_survives_a_router_restart() {
    let net = match Net::create() {
        Ok(net) => net,
        Err(why) => {
            assert!(
                !required(),
                "GRASPOPT_REQUIRE_NETNS=1, but no network namespaces here: {why}"
            );
            eprintln!(
                "netns: SKIPPED: cannot make network namespaces here (needs root with \
                 CAP_NET_ADMIN and iproute2): {why}"
            );
            return;
        }
    };
    let started = Instant::now();
    let dir = tempdir("netns");
    let run = "netns";
    let n: u64 = 90;
    let journal = dir.join("journal.sqlite");
    let router_config = repo_root().join("deploy/zenoh/router.json5");
    let router_config = router_config.to_str().unwrap();
    let lab = format!("tcp/{}:{ROUTER_PORT}", MACHINES[0].1);
    let local = format!("tcp/127.0.0.1:{ROUTER_PORT}");
    let [a, b, c] = [0, 1, 2].map(|i| net.machines[i].as_str());

    // Each machine's router, started as deploy/README.md says: a's as `graspopt launch
    // deploy/two-machines.toml --host lab-pc` starts it, b's and c's as robot-pc's (step 6),
    // linked to a's.
    let router = |ns: &str, name: &str| {
        let args = if ns == a {
            vec![
                "router",
                "--listen",
                "tcp/0.0.0.0:7447",
                "--zenoh-config",
                router_config,
                "--no-multicast-scouting",
            ]
        } else {
            vec!["router", "--zenoh-config", router_config, "--connect", &lab]
        };
        net.start(ns, name, &args, &dir)
    };
    let _router_a = router(a, "router-a");
    let _router_b = router(b, "router-b");
    let mut router_c = router(c, "router-c");

    // An agent on machine `ns` (`m` its letter), connected to its own router only, as
    // `graspopt launch` starts it with `endpoint = "tcp/127.0.0.1:7447"`. Namespaces share
    // /dev/shm: a shared-memory prefix per machine keeps b's shared memory to b.
    let agent = |ns: &str, m: &str, id: &str, args: &[&str]| {
        let shm = format!("gpe2e_netns_{}_{m}_", std::process::id());
        let mut v = vec!["agent"];
        v.extend_from_slice(args);
        v.extend([
            "--run",
            run,
            "--id",
            id,
            "--connect",
            local.as_str(),
            "--no-multicast-scouting",
            "--shm-prefix",
            shm.as_str(),
        ]);
        net.start(ns, id, &v, &dir)
    };
    let hand =
        |ns: &str, m: &str, id: &str| agent(ns, m, id, &["hand", "--set", "trial_cost_ms=250"]);
    let _agents = [
        agent(a, "a", "perception", &["perception", "--set", "object=mug"]),
        agent(a, "a", "planner", &["planner"]),
        hand(a, "a", "a-1"),
        agent(b, "b", "metric", &["metric"]),
        hand(b, "b", "b-1"),
        hand(b, "b", "b-2"),
        hand(c, "c", "c-1"),
        hand(c, "c", "c-2"),
    ];
    let journal_arg = journal.to_str().unwrap();
    let total = n.to_string();
    // A lease far longer than the run: re-issues come from the lost liveliness tokens.
    let coordinator = agent(
        a,
        "a",
        "coordinator",
        &[
            "coordinator",
            "--object",
            "mug",
            "--trials",
            &total,
            "--seed",
            "4",
            "--method",
            "random",
            "--set",
            &format!("journal={journal_arg}"),
            "--set",
            "lease_ms=60000",
        ],
    );
    let on_c = |w: &str| w.starts_with("c-");
    let running_on_c = || -> BTreeSet<u64> {
        Journal::open(&journal)
            .and_then(|j| j.trials(run))
            .map(|ts| {
                ts.iter()
                    .filter(|t| t.state == StoredTrialPhase::Running && on_c(&t.worker))
                    .map(|t| t.trial_id)
                    .collect()
            })
            .unwrap_or_default()
    };

    // Mid-run, while both of c's hands hold a trial: kill c's router.
    wait_until(
        "10 trials done, both of c's hands holding one",
        Duration::from_secs(90),
        || completed_now(&journal, run) >= 10 && running_on_c().len() == 2,
    );
    router_c.kill();
    let killed_ms = now_ms();
    // What c's hands held at the kill: their results can no longer reach the metric agent.
    let held = running_on_c();
    let done_at_kill = completed_now(&journal, run);
    assert!(!held.is_empty(), "c's hands held no trial at the kill");
    assert!(
        done_at_kill < n as usize - 20,
        "the kill came too late: {done_at_kill} of {n} trials done"
    );
    std::thread::sleep(Duration::from_secs(1));
    let _router_c = router(c, "router-c-restarted");
    let restarted_ms = now_ms();

    let name = coordinator.name.clone();
    let (status, stdout) = coordinator.wait_output(Duration::from_secs(90));
    assert!(
        status.success(),
        "{name} failed: {stdout}\n{}",
        crate::support::log(&dir, &name)
    );
    let status: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(status["completed"], n, "{status}");

    // The journal: every trial completed, recorded exactly once.
    let trials = check_journal(&journal, run, n as usize);
    let lost = assert_nothing_lost(&journal, run, n);
    let events = Journal::open(&journal).unwrap().events(run).unwrap();
    // The trials c held were re-issued at once (on the lost liveliness tokens, not the
    // one-minute lease) and completed by their later attempt. (A result that left c just
    // before the kill may still complete its trial at attempt 1: at least one of the two
    // held is re-issued.)
    let reissued: Vec<u64> = held
        .iter()
        .copied()
        .filter(|id| trials[*id as usize - 1].attempts >= 2)
        .collect();
    assert!(
        !reissued.is_empty(),
        "no trial held by c was re-issued: {held:?}"
    );
    for id in &reissued {
        let t = &trials[*id as usize - 1];
        assert!(t.result_attempt.unwrap() >= 2, "trial {id}: {t:?}");
        assert!(
            events
                .iter()
                .any(|e| e.trial_id == *id && e.kind == event_kind::REISSUED),
            "trial {id}: no re-issue event"
        );
    }
    assert!(
        status["errors"]["reissued"].as_u64().unwrap() >= reissued.len() as u64,
        "{status}"
    );
    assert!(
        now_ms() - killed_ms < 60_000,
        "the run outlasted the lease: the re-issues may have waited for it"
    );
    // Results from hands on every machine, and from c's hands after the restart: they
    // reconnected by themselves.
    for m in ["a-", "b-", "c-"] {
        assert!(
            trials.iter().any(|t| t.worker.starts_with(m)),
            "no result from a hand {m}*"
        );
    }
    let c_after = trials
        .iter()
        .filter(|t| on_c(&t.worker) && t.completed_ms.unwrap() > restarted_ms)
        .count();
    assert!(
        c_after > 0,
        "c's hands completed nothing after their router came back"
    );
    // b's clouds stayed in b's shared memory; a's and c's crossed the routers.
    for t in &trials {
        let expected = if t.worker.starts_with("b-") {
            "shm"
        } else {
            "zenoh"
        };
        assert_eq!(
            cloud_transport(t),
            expected,
            "trial {}: {}",
            t.trial_id,
            t.worker
        );
    }

    // The exported run agrees: one CSV row and one JSON trial per trial, the same workers.
    let csv = dir.join("trials.csv");
    let json_path = dir.join("trials.json");
    for (format, path) in [("csv", &csv), ("json", &json_path)] {
        let out = graspopt(&[
            "export",
            run,
            "--journal",
            journal_arg,
            "--format",
            format,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (header, rows) = read_csv(&csv);
    assert_eq!(rows.len(), n as usize);
    let (trial_col, worker_col) = (col(&header, "trial"), col(&header, "worker"));
    for (row, t) in rows.iter().zip(&trials) {
        assert_eq!(row[trial_col], t.trial_id.to_string());
        assert_eq!(row[worker_col], t.worker);
    }
    let exported: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let exported = exported["trials"].as_array().unwrap();
    assert_eq!(exported.len(), n as usize);
    for id in &reissued {
        assert!(exported[*id as usize - 1]["attempts"].as_u64().unwrap() >= 2);
    }

    net.stop();
    report(json!({
        "test": "three network namespaces, one router killed and restarted",
        "machines": 3, "routers": 3, "faults": 1, "trials": n, "lost": lost,
        "held_by_c_at_kill": held.len(), "held_reissued": reissued.len(), "done_at_kill": done_at_kill,
        "reissued": status["errors"]["reissued"],
        "completed_on_c_after_restart": c_after,
        "router_down_ms": restarted_ms - killed_ms,
        "test_s": started.elapsed().as_secs_f64(),
    }));
}
