//! The same run three ways gives the same trials: embedded (every agent in one process,
//! clouds through shared memory), embedded with clouds over Zenoh, and every agent its own
//! process around a router. With one worker and a fixed seed nothing depends on timing.

use std::path::Path;
use std::time::Duration;

use crate::support::{Cluster, check_journal, cloud_transport, graspopt, tempdir};
use graspopt_journal::TrialRow;

const TRIALS: usize = 8;
const SEED: &str = "5";

fn embedded(dir: &Path, name: &str, extra: &[&str]) -> Vec<TrialRow> {
    let out = dir.join(name);
    let shm = format!("gpe2e_eq{name}_{}_", std::process::id());
    let mut args = vec![
        "run",
        "--object",
        "mug",
        "--workers",
        "1",
        "--trials",
        "8",
        "--seed",
        SEED,
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--shm-prefix",
        &shm,
    ];
    args.extend_from_slice(extra);
    let o = graspopt(&args);
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    check_journal(&out.join("journal.sqlite"), "run", TRIALS)
}

/// Same parameters, scores and metrics, trial by trial (bit for bit: same code, same inputs).
fn assert_same_trials(a: &[TrialRow], b: &[TrialRow], what: &str) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(
            x.params, y.params,
            "{what}: parameters of trial {}",
            x.trial_id
        );
        assert_eq!(x.score, y.score, "{what}: score of trial {}", x.trial_id);
        assert_eq!(
            x.metrics, y.metrics,
            "{what}: metrics of trial {}",
            x.trial_id
        );
        assert_eq!(
            x.contacts, y.contacts,
            "{what}: contacts of trial {}",
            x.trial_id
        );
        assert_eq!(
            x.cloud_points, y.cloud_points,
            "{what}: cloud points of trial {}",
            x.trial_id
        );
    }
}

#[test]
fn one_worker_gives_the_same_trials_embedded_multi_process_and_over_either_cloud_path() {
    let dir = tempdir("equivalence");
    let shm = embedded(&dir, "shm", &[]);
    let zenoh = embedded(&dir, "zenoh", &["--no-shm"]);
    for t in &shm {
        assert_eq!(cloud_transport(t), "shm", "trial {}", t.trial_id);
    }
    for t in &zenoh {
        assert_eq!(cloud_transport(t), "zenoh", "trial {}", t.trial_id);
    }
    assert_same_trials(&shm, &zenoh, "shared memory vs Zenoh");
    // Something was touched, so the metrics compared are not all empty.
    assert!(shm.iter().any(|t| t.metrics.is_some()));

    let c = Cluster::start("equivalence-mp", "run");
    let journal = c.journal();
    let _perception = c.agent(
        "perception",
        &[
            "perception",
            "--set",
            "object=mug",
            "--set",
            &format!("seed={SEED}"),
        ],
    );
    let _planner = c.agent("planner", &["planner"]);
    let _metric = c.agent("metric", &["metric"]);
    let _hand = c.agent("hand-1", &["hand", "--id", "hand-1"]);
    let coordinator = c.coordinator("mug", "8", SEED, &[]);
    c.final_status(coordinator, Duration::from_secs(120));
    let multi = check_journal(&journal, "run", TRIALS);
    assert_same_trials(&shm, &multi, "embedded vs multi-process");
}
