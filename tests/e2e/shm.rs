//! Shared memory with many hands on one host.

use crate::support::{check_journal, cloud_transport, graspopt, tempdir};

/// 64 hands in one embedded run: every trial's clouds reach the metric agent through shared
/// memory, and no hand falls back to Zenoh. (The clouds service used to admit 16 publishers:
/// from the 17th hand on, `shared memory unavailable, clouds go over Zenoh:
/// ExceedsMaxSupportedPublishers`.)
#[test]
fn sixty_four_hands_on_one_host_all_send_clouds_through_shared_memory() {
    const TRIALS: usize = 192;
    let dir = tempdir("shm64");
    let out = dir.join("run");
    let shm = format!("gpe2e_shm64_{}_", std::process::id());
    let o = graspopt(&[
        "run",
        "--object",
        "cylinder",
        "--workers",
        "64",
        "--trials",
        &TRIALS.to_string(),
        "--method",
        "random",
        "--seed",
        "3",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--shm-prefix",
        &shm,
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    for fallback in ["shared memory unavailable", "using Zenoh", "ExceedsMax"] {
        assert!(
            !stderr.contains(fallback),
            "{fallback:?} in the log:\n{stderr}"
        );
    }
    let trials = check_journal(&out.join("journal.sqlite"), "run", TRIALS);
    for t in &trials {
        assert_eq!(
            cloud_transport(t),
            "shm",
            "trial {} by {}",
            t.trial_id,
            t.worker
        );
    }
    // The test covers hands past the old limit of 16.
    let mut workers: Vec<&str> = trials.iter().map(|t| t.worker.as_str()).collect();
    workers.sort();
    workers.dedup();
    assert!(
        workers.len() > 32,
        "only {} hands took trials",
        workers.len()
    );
}
