//! A run's life as a user drives it, with real processes: resumed with its recorded settings
//! (flags that contradict them refused, a larger budget accepted), stopped by Ctrl-C and
//! finished by `--resume`, and never shared by two hands with one id or two coordinators.

use std::time::Duration;

use crate::support::{
    Cluster, Proc, check_journal, completed_now, graspopt, signal, tempdir, wait_until,
};
use graspopt_journal::{Journal, StoredRunPhase, StoredTrialPhase};

fn text(o: &std::process::Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn a_resumed_run_keeps_its_recorded_settings_and_refuses_contradicting_flags() {
    let dir = tempdir("lifecycle-resume");
    let out = dir.join("results");
    let out_s = out.to_str().unwrap();
    let shm = format!("gpe2e_lcres_{}_", std::process::id());
    let base = ["--quiet", "--workers", "2", "--shm-prefix", &shm];
    let mut first = vec!["run", "--object", "sphere", "--metric", "epsilon"];
    first.extend_from_slice(&["--trials", "12", "--seed", "3", "--out", out_s]);
    first.extend_from_slice(&base);
    let o = graspopt(&first);
    assert!(o.status.success(), "{}", text(&o));
    let journal = out.join("journal.sqlite");
    check_journal(&journal, "run", 12);

    // Flags that contradict the record are refused, all named, and nothing changes.
    let mut wrong = vec!["run", "--resume", "--out", out_s, "--object", "mug"];
    wrong.extend_from_slice(&["--metric", "bw", "--trials", "6"]);
    wrong.extend_from_slice(&base);
    let o = graspopt(&wrong);
    assert!(!o.status.success());
    let msg = text(&o);
    for part in [
        "--object mug (the run has sphere)",
        "--metric bw (the run has epsilon)",
        "--trials 6 (the run has a budget of 12",
    ] {
        assert!(msg.contains(part), "{part:?} not in: {msg}");
    }
    let j = Journal::open(&journal).unwrap();
    assert_eq!(j.trials("run").unwrap().len(), 12);
    assert_eq!(
        j.run("run").unwrap().unwrap().status,
        StoredRunPhase::Finished
    );
    drop(j);

    // Resumed with only a larger budget: the sphere, scored by epsilon, six more trials.
    let mut more = vec!["run", "--resume", "--out", out_s, "--trials", "18"];
    more.extend_from_slice(&base);
    let o = graspopt(&more);
    assert!(o.status.success(), "{}", text(&o));
    let trials = check_journal(&journal, "run", 18);
    for t in &trials {
        let score = t.score.unwrap();
        assert!(
            score >= 0.0,
            "trial {}: score {score} is not an epsilon",
            t.trial_id
        );
        if let Some(m) = &t.metrics {
            assert_eq!(Some(score), m.real("epsilon"), "trial {}", t.trial_id);
        }
    }
    let j = Journal::open(&journal).unwrap();
    let record = j.run("run").unwrap().unwrap();
    assert_eq!(record.status, StoredRunPhase::Finished);
    let spec: serde_json::Value = serde_json::from_str(&record.config_json).unwrap();
    assert_eq!(spec["object"], "sphere");
    assert_eq!(spec["trials"], 18);
    drop(j);

    // Nothing to resume, and a folder that holds another run.
    let other_out = dir.join("elsewhere");
    let mut none = vec!["run", "--resume", "--out", other_out.to_str().unwrap()];
    none.extend_from_slice(&base);
    let o = graspopt(&none);
    assert!(!o.status.success());
    assert!(text(&o).contains("nothing to resume"), "{}", text(&o));
    let mut taken = vec!["run", "--run", "other", "--out", out_s];
    taken.extend_from_slice(&base);
    let o = graspopt(&taken);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("holds run \"run\" already"),
        "{}",
        text(&o)
    );
    let runs = Journal::open(&journal).unwrap().runs().unwrap();
    assert_eq!(runs.len(), 1);
}

/// The planner's engine is kept in the journal: a run stopped and resumed (a new process,
/// so a new planner) proposes exactly the trials the same run makes without a stop. One
/// worker, so that the trials complete in the same order in both runs; the stop comes after
/// the 5-point initial design and 3 model-based trials, so the resumed planner continues a
/// fitted model (rebuilt from the history alone, it would propose other points).
#[test]
fn a_stopped_and_resumed_run_proposes_what_the_uninterrupted_run_does() {
    let dir = tempdir("lifecycle-exact");
    let shm = format!("gpe2e_lcexa_{}_", std::process::id());
    let base = ["--quiet", "--workers", "1", "--shm-prefix", &shm];
    let run = |out: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["run", "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.extend_from_slice(&base);
        let o = graspopt(&args);
        assert!(o.status.success(), "{}", text(&o));
    };
    let whole = dir.join("whole");
    run(
        &whole,
        &["--object", "mug", "--seed", "11", "--trials", "14"],
    );
    let cut = dir.join("cut");
    run(&cut, &["--object", "mug", "--seed", "11", "--trials", "8"]);
    let j = Journal::open(&cut.join("journal.sqlite")).unwrap();
    assert!(j.planner_state("run").unwrap().is_some());
    drop(j);
    run(&cut, &["--resume", "--trials", "14"]);

    let params = |out: &std::path::Path| -> Vec<Vec<u64>> {
        check_journal(&out.join("journal.sqlite"), "run", 14)
            .iter()
            .map(|t| t.params.iter().map(|p| p.to_bits()).collect())
            .collect()
    };
    let (a, b) = (params(&whole), params(&cut));
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert_eq!(
            x,
            y,
            "trial {}: the resumed run proposed another point",
            i + 1
        );
    }
}

#[test]
fn ctrl_c_stops_a_run_that_resume_then_finishes() {
    let dir = tempdir("lifecycle-stop");
    let out = dir.join("results");
    let out_s = out.to_str().unwrap();
    let shm = format!("gpe2e_lcstop_{}_", std::process::id());
    let args = |extra: &[&'static str]| {
        let mut v: Vec<String> = [
            "run",
            "--object",
            "cylinder",
            "--trials",
            "60",
            "--workers",
            "1",
            "--trial-cost-ms",
            "40",
            "--quiet",
            "--out",
            out_s,
            "--shm-prefix",
            &shm,
        ]
        .map(String::from)
        .to_vec();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let first_args = args(&[]);
    let first_refs: Vec<&str> = first_args.iter().map(String::as_str).collect();
    let run = Proc::start("first", &first_refs, &dir);
    let journal = out.join("journal.sqlite");
    wait_until("five trials", Duration::from_secs(60), || {
        completed_now(&journal, "run") >= 5
    });
    signal(&run, "INT");
    let (status, stdout) = run.wait_output(Duration::from_secs(20));
    assert_eq!(status.code(), Some(130), "{stdout}");
    assert!(
        stdout.contains("stopped; continue with --resume"),
        "{stdout}"
    );
    let j = Journal::open(&journal).unwrap();
    assert_eq!(
        j.run("run").unwrap().unwrap().status,
        StoredRunPhase::Stopped
    );
    let done = j
        .trials("run")
        .unwrap()
        .iter()
        .filter(|t| t.state == StoredTrialPhase::Completed)
        .count();
    assert!((5..60).contains(&done), "{done} trials completed");
    drop(j);

    let resume_args = args(&["--resume"]);
    let resume_refs: Vec<&str> = resume_args.iter().map(String::as_str).collect();
    let o = graspopt(&resume_refs);
    assert!(o.status.success(), "{}", text(&o));
    check_journal(&journal, "run", 60);
    let j = Journal::open(&journal).unwrap();
    assert_eq!(
        j.run("run").unwrap().unwrap().status,
        StoredRunPhase::Finished
    );
}

#[test]
fn a_second_hand_with_an_id_in_use_and_a_second_coordinator_are_refused() {
    let c = Cluster::start("lifecycle-unique", "uq");
    let _support = c.support("mug");
    // Long enough (30 trials of 500 ms) for the refusals, which wait 5 s for the holder
    // to vanish, to happen while the run goes on.
    let _hands = c.hands(1, &["--set", "trial_cost_ms=500"]);
    let coordinator = c.coordinator("mug", "30", "1", &[]);
    let journal = c.journal();
    wait_until("a first trial", Duration::from_secs(60), || {
        completed_now(&journal, "uq") >= 1
    });
    let twin = c.agent("twin", &["hand", "--id", "hand-1"]);
    let second = c.coordinator_as("second", "mug", "30", "1", &["--resume"]);
    let (status, _) = twin.wait_output(Duration::from_secs(30));
    assert!(!status.success());
    let log = c.log("twin");
    assert!(
        log.contains("run \"uq\" already has a hand with the id hand-1"),
        "{log}"
    );
    let (status, _) = second.wait_output(Duration::from_secs(30));
    assert!(!status.success());
    let log = c.log("second");
    assert!(
        log.contains("run \"uq\" already has a coordinator"),
        "{log}"
    );
    assert!(
        completed_now(&journal, "uq") < 30,
        "the run ended before the checks"
    );
    let status = c.final_status(coordinator, Duration::from_secs(120));
    assert_eq!(status["completed"], 30);
    assert_eq!(status["errors"]["duplicates"], 0, "{status}");
    check_journal(&journal, "uq", 30);
}
