//! A wrong `--connect`: an endpoint that does not parse is refused at once, one that does not
//! answer is named within a few seconds and tried again until it answers, and Zenoh's own
//! warnings (with their source paths) stay out of a user's terminal unless `RUST_LOG` asks.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::support::{Proc, free_port, graspopt_bin, log, tempdir, wait_for_port, wait_until};

/// Starts `graspopt args...` as a user would: no `RUST_LOG`, stderr to `<logs>/<name>.log`.
fn start_plain(name: &str, args: &[&str], logs: &Path) -> Proc {
    let stderr = std::fs::File::create(logs.join(format!("{name}.log"))).unwrap();
    let child = Command::new(graspopt_bin())
        .args(args)
        .env_remove("RUST_LOG")
        .stdout(Stdio::piped())
        .stderr(stderr)
        .spawn()
        .unwrap();
    Proc {
        name: name.to_string(),
        child,
    }
}

#[test]
fn endpoints_that_do_not_parse_are_refused_at_once_naming_them() {
    let dir = tempdir("bad-endpoints");
    let cases = [
        (
            "tcp/127.0.0.1:99999",
            "port 99999 is out of range (1 to 65535)",
        ),
        (
            "127.0.0.1:7447",
            "no protocol: write e.g. tcp/127.0.0.1:7447",
        ),
        (
            "udp/127.0.0.1:7447",
            "unknown protocol \"udp\": graspopt speaks tcp and unixsock-stream",
        ),
    ];
    for (i, (endpoint, why)) in cases.iter().enumerate() {
        for (kind, args) in [
            ("hand", vec!["agent", "hand", "--run", "bad"]),
            ("monitor", vec!["monitor", "--once"]),
        ] {
            let name = format!("{kind}-{i}");
            let mut args = args.clone();
            args.extend(["--connect", endpoint, "--no-shm"]);
            // Before: the agent waited forever on a port Zenoh could never use.
            let (status, _) = start_plain(&name, &args, &dir).wait_output(Duration::from_secs(15));
            let text = log(&dir, &name);
            assert_eq!(status.code(), Some(1), "{name}: {text}");
            assert!(
                text.contains(&format!("endpoint {endpoint:?}")) && text.contains(why),
                "{name}: {text}"
            );
            assert!(!text.contains(".rs:"), "{name}: {text}");
        }
    }
}

#[test]
fn an_endpoint_that_does_not_answer_is_named_then_reported_reached() {
    let dir = tempdir("unreachable");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let _hand = start_plain(
        "hand",
        &[
            "agent",
            "hand",
            "--run",
            "far",
            "--connect",
            &endpoint,
            "--no-shm",
        ],
        &dir,
    );
    wait_until(
        "the hand names the endpoint it cannot reach",
        Duration::from_secs(15),
        || log(&dir, "hand").contains(&format!("cannot reach {endpoint}: nothing answers there")),
    );
    let _router = Proc::start(
        "router",
        &["router", "--listen", &endpoint, "--no-multicast-scouting"],
        &dir,
    );
    wait_for_port(port, Duration::from_secs(20));
    wait_until(
        "the hand says it reached the router",
        Duration::from_secs(20),
        || log(&dir, "hand").contains(&format!("reached {endpoint} after")),
    );
    let text = log(&dir, "hand");
    // Zenoh's own warnings ("Unable to connect to ...! at /root/.cargo/registry/...rs:NN",
    // "Scouting delay elapsed ...") are not shown without RUST_LOG.
    assert!(!text.contains(".rs:"), "{text}");
    assert!(!text.contains(" zenoh"), "{text}");
    assert!(!text.contains("Scouting delay"), "{text}");
}

#[test]
fn a_host_name_that_does_not_resolve_is_named() {
    let dir = tempdir("nosuchhost");
    let _hand = start_plain(
        "hand",
        &[
            "agent",
            "hand",
            "--run",
            "far",
            "--connect",
            "tcp/nosuchhost.invalid:7447",
            "--no-shm",
        ],
        &dir,
    );
    wait_until(
        "the hand says the host name does not resolve",
        Duration::from_secs(40),
        || {
            log(&dir, "hand").contains(
                "cannot reach tcp/nosuchhost.invalid:7447: the host name nosuchhost.invalid does not resolve",
            )
        },
    );
}

#[test]
fn a_hand_given_a_wrong_address_does_not_join_through_multicast_scouting() {
    let dir = tempdir("scouting");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let out = dir.join("results");
    let shm = format!("gpe2e_scout_{}_", std::process::id());
    // A run that listens and scouts, as a user's `graspopt run --listen` does.
    let run = Proc::start(
        "run",
        &[
            "run",
            "--run",
            "scout",
            "--object",
            "sphere",
            "--workers",
            "1",
            "--trials",
            "60",
            "--method",
            "random",
            "--trial-cost-ms",
            "100",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--listen",
            &endpoint,
            "--shm-prefix",
            &shm,
        ],
        &dir,
    );
    wait_for_port(port, Duration::from_secs(30));
    // A hand on the same machine whose address has a typo: before, it found the run by
    // multicast scouting and took trials, so the typo went unnoticed.
    let wrong = format!("tcp/127.0.0.1:{}", free_port());
    let _hand = start_plain(
        "hand-x",
        &[
            "agent",
            "hand",
            "--run",
            "scout",
            "--id",
            "hand-x",
            "--connect",
            &wrong,
            "--no-shm",
        ],
        &dir,
    );
    let (status, _) = run.wait_output(Duration::from_secs(120));
    assert!(status.success(), "{}", log(&dir, "run"));
    let journal = graspopt_journal::Journal::open(&out.join("journal.sqlite")).unwrap();
    let workers: std::collections::BTreeSet<String> = journal
        .events("scout")
        .unwrap()
        .into_iter()
        .map(|e| e.worker)
        .filter(|w| !w.is_empty())
        .collect();
    assert_eq!(
        workers.into_iter().collect::<Vec<_>>(),
        ["hand-1"],
        "only the run's own hand worked"
    );
    let text = log(&dir, "hand-x");
    assert!(text.contains(&format!("cannot reach {wrong}")), "{text}");
}
