//! A run killed (SIGKILL) in the middle and resumed from its journal: every trial completed
//! before the kill is kept as it was, the run finishes its budget, and `graspopt export`
//! reads the result.

use std::time::{Duration, Instant};

use crate::support::{
    Cluster, Proc, check_journal, completed_now, graspopt, signal, tempdir, wait_until,
};
use graspopt_journal::{Journal, StoredRunPhase, StoredTrialPhase};

const TRIALS: usize = 20;

fn run_args<'a>(out: &'a str, shm: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec![
        "run",
        "--object",
        "wine_glass",
        "--workers",
        "2",
        "--trials",
        "20",
        "--seed",
        "9",
        "--trial-cost-ms",
        "150",
        "--quiet",
        "--out",
        out,
        "--shm-prefix",
        shm,
    ];
    v.extend_from_slice(extra);
    v
}

#[test]
fn a_killed_run_resumes_from_its_journal_and_loses_nothing() {
    let dir = tempdir("resume");
    let out = dir.join("results");
    let out_s = out.to_str().unwrap().to_string();
    let shm = format!("gpe2e_resume_{}_", std::process::id());
    let journal = out.join("journal.sqlite");
    let mut first = Proc::start("first", &run_args(&out_s, &shm, &[]), &dir);
    // Kill it once some trials are done and others are running.
    let start = Instant::now();
    let before = loop {
        if let Ok(j) = Journal::open(&journal)
            && let Ok(trials) = j.trials("run")
        {
            let done = trials
                .iter()
                .filter(|t| t.state == StoredTrialPhase::Completed)
                .count();
            if done >= 6 && trials.iter().any(|t| t.state == StoredTrialPhase::Running) {
                first.kill();
                break Journal::open(&journal).unwrap().trials("run").unwrap();
            }
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the run does not progress"
        );
        std::thread::sleep(Duration::from_millis(10));
    };
    assert!(Journal::open(&journal).unwrap().integrity_check().unwrap());
    let completed_before: Vec<_> = before
        .iter()
        .filter(|t| t.state == StoredTrialPhase::Completed)
        .cloned()
        .collect();
    assert!(completed_before.len() < TRIALS);

    // Resume: the same command with --resume.
    let o = graspopt(&run_args(&out_s, &shm, &["--resume"]));
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let after = check_journal(&journal, "run", TRIALS);
    for t in &completed_before {
        let a = &after[t.trial_id as usize - 1];
        assert_eq!(
            (&a.params, a.score, &a.metrics, a.attempts),
            (&t.params, t.score, &t.metrics, t.attempts),
            "trial {} changed on resume",
            t.trial_id
        );
    }
    // A trial running at the kill was issued again and completed once.
    let running_before: Vec<u64> = before
        .iter()
        .filter(|t| t.state == StoredTrialPhase::Running)
        .map(|t| t.trial_id)
        .collect();
    assert!(!running_before.is_empty());
    for id in running_before {
        assert!(after[id as usize - 1].attempts >= 2, "trial {id} re-issued");
    }

    // export reads the finished run.
    let o = graspopt(&[
        "export",
        "run",
        "--journal",
        journal.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let trials = v
        .as_array()
        .or_else(|| v["trials"].as_array())
        .unwrap_or_else(|| panic!("no trials in {v}"));
    assert_eq!(trials.len(), TRIALS);
}

/// The documented resume: a run with its own id, stopped by Ctrl-C, continues with the very
/// command it prints (`--resume --out DIR`, no `--run`). A journal of several runs makes
/// `--resume` without `--run` an error that lists them, as is a `--run` the journal lacks.
#[test]
fn a_stopped_run_resumes_with_the_command_it_prints() {
    let dir = tempdir("resume-printed");
    let out = dir.join("results");
    let out_s = out.to_str().unwrap();
    let shm = format!("gpe2e_rsprn_{}_", std::process::id());
    let journal = out.join("journal.sqlite");
    let first = Proc::start(
        "first",
        &[
            "run",
            "--run",
            "stopme",
            "--object",
            "cylinder",
            "--workers",
            "1",
            "--trials",
            "12",
            "--method",
            "random",
            "--trial-cost-ms",
            "100",
            "--quiet",
            "--out",
            out_s,
            "--shm-prefix",
            &shm,
        ],
        &dir,
    );
    wait_until("two trials", Duration::from_secs(60), || {
        completed_now(&journal, "stopme") >= 2
    });
    signal(&first, "INT");
    let (status, stdout) = first.wait_output(Duration::from_secs(20));
    assert_eq!(status.code(), Some(130), "{stdout}");
    // "... (stopped; continue with --resume --out DIR)": run exactly that.
    let hint = stdout
        .split("continue with ")
        .nth(1)
        .and_then(|rest| rest.split(')').next())
        .unwrap_or_else(|| panic!("no resume hint in {stdout}"));
    assert_eq!(hint, format!("--resume --out {out_s}"));
    let mut args = vec!["run"];
    args.extend(hint.split(' '));
    args.extend_from_slice(&["--quiet", "--shm-prefix", &shm]);
    let o = graspopt(&args);
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{text}");
    check_journal(&journal, "stopme", 12);
    // The id reads as a name in messages.
    assert!(stdout.contains("run \"stopme\": "), "{stdout}");
    assert!(
        text.contains("run \"stopme\": 12 of 12 trials completed"),
        "{text}"
    );

    // A second run in the same journal: which one to resume must be said.
    let mut j = Journal::open(&journal).unwrap();
    let record = j.run("stopme").unwrap().unwrap();
    j.create_run(&graspopt_journal::RunRow {
        run_id: "other".into(),
        ..record
    })
    .unwrap();
    drop(j);
    let o = graspopt(&["run", "--resume", "--out", out_s, "--quiet"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("holds 2 runs (\"stopme\", \"other\"): say which to resume with --run"),
        "{err}"
    );
    let o = graspopt(&[
        "run", "--resume", "--run", "nosuch", "--out", out_s, "--quiet",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("run \"nosuch\" is not in") && err.contains("\"stopme\", \"other\""),
        "{err}"
    );
}

/// A coordinator stopped before its first trial (here: no other agent ever came; a wrong
/// address does the same) leaves its run recorded with no trial. The same command starts
/// it afresh, saying so, and the run completes.
#[test]
fn a_run_stopped_before_its_first_trial_starts_afresh_with_the_same_command() {
    let c = Cluster::start("resume-fresh", "q");
    let journal = c.journal();
    let first = c.coordinator("mug", "4", "2", &[]);
    wait_until("the run recorded", Duration::from_secs(30), || {
        journal.exists() && Journal::open(&journal).unwrap().run("q").unwrap().is_some()
    });
    signal(&first, "INT");
    let (status, _) = first.wait_output(Duration::from_secs(20));
    assert_eq!(status.code(), Some(130), "{}", c.log("coordinator"));
    // The stop says what will work, not --resume.
    assert!(
        c.log("coordinator")
            .contains("no trial was issued: the same command starts it afresh"),
        "{}",
        c.log("coordinator")
    );
    let j = Journal::open(&journal).unwrap();
    assert_eq!(j.run("q").unwrap().unwrap().status, StoredRunPhase::Stopped);
    assert!(j.trials("q").unwrap().is_empty());
    drop(j);

    let _support = c.support("mug");
    let _hands = c.hands(1, &[]);
    let again = c.coordinator_as("again", "mug", "4", "2", &[]);
    let status = c.final_status(again, Duration::from_secs(120));
    assert_eq!(status["completed"], 4);
    assert!(
        c.log("again").contains("run \"q\" is in ")
            && c.log("again").contains("starting it afresh"),
        "{}",
        c.log("again")
    );
    check_journal(&journal, "q", 4);

    // With trials issued, the same command is refused: the run must be resumed.
    let third = c.coordinator_as("third", "mug", "4", "2", &[]);
    let (status, _) = third.wait_output(Duration::from_secs(30));
    assert!(!status.success());
    let log = c.log("third");
    assert!(
        log.contains("run \"q\" already exists in") && log.contains("with 4 trials: resume it"),
        "{log}"
    );
}

/// A one-worker run stopped by Ctrl-C three times, each time with a trial running, and
/// resumed each time with the command it prints (`--resume --out DIR`, which keeps its one
/// worker and its trial cost), makes the same trials, bit for bit, as the run made in one
/// go: the trial that was running is run again with its parameters, and the planner
/// continues from its state of that moment. The stops come after the 5-point initial
/// design, so the planner continues a fitted model.
#[test]
fn a_run_stopped_mid_trial_and_resumed_proposes_what_the_uninterrupted_run_does() {
    let dir = tempdir("resume-midtrial");
    let shm = format!("gpe2e_rsmid_{}_", std::process::id());
    let args = |out: &std::path::Path, extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = ["run", "--quiet", "--shm-prefix", &shm, "--out"]
            .map(String::from)
            .to_vec();
        v.push(out.to_str().unwrap().to_string());
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let first_flags = [
        "--object",
        "mug",
        "--seed",
        "11",
        "--trials",
        "16",
        "--workers",
        "1",
        "--trial-cost-ms",
        "150",
    ];
    let whole = dir.join("whole");
    let whole_args = args(&whole, &first_flags);
    let o = graspopt(&whole_args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let cut = dir.join("cut");
    let journal = cut.join("journal.sqlite");
    let running = || -> Vec<u64> {
        Journal::open(&journal)
            .unwrap()
            .trials("run")
            .unwrap()
            .iter()
            .filter(|t| t.state == StoredTrialPhase::Running)
            .map(|t| t.trial_id)
            .collect()
    };
    let mut stopped_mid_trial = Vec::new();
    for (i, done) in [6, 9, 12].into_iter().enumerate() {
        let a = if i == 0 {
            args(&cut, &first_flags)
        } else {
            args(&cut, &["--resume"])
        };
        let mut p = Proc::start(
            &format!("cut-{i}"),
            &a.iter().map(String::as_str).collect::<Vec<_>>(),
            &dir,
        );
        // Stop while a trial runs, once `done` trials are complete and this process has
        // completed one (so that it handles Ctrl-C).
        let done = done.max(completed_now(&journal, "run") + 1);
        let start = Instant::now();
        while completed_now(&journal, "run") < done || running().is_empty() {
            if let Some(s) = p.child.try_wait().unwrap() {
                panic!("cut-{i} ended ({s}) before its stop: it did not keep one slow worker");
            }
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "cut-{i}: no progress"
            );
            std::thread::sleep(Duration::from_millis(10));
        }
        signal(&p, "INT");
        let (status, stdout) = p.wait_output(Duration::from_secs(30));
        assert_eq!(status.code(), Some(130), "{stdout}");
        stopped_mid_trial.extend(running());
    }
    assert!(!stopped_mid_trial.is_empty(), "no stop came mid-trial");
    let last = args(&cut, &["--resume"]);
    let o = graspopt(&last.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let a = check_journal(&whole.join("journal.sqlite"), "run", 16);
    let b = check_journal(&journal, "run", 16);
    for id in &stopped_mid_trial {
        assert!(
            b[*id as usize - 1].attempts >= 2,
            "trial {id} was run again"
        );
    }
    let workers: std::collections::BTreeSet<&str> = b.iter().map(|t| t.worker.as_str()).collect();
    assert_eq!(workers.into_iter().collect::<Vec<_>>(), ["hand-1"]);
    for (x, y) in a.iter().zip(&b) {
        let bits = |t: &graspopt_journal::TrialRow| -> Vec<u64> {
            t.params.iter().map(|p| p.to_bits()).collect()
        };
        assert_eq!(
            (bits(x), x.score.map(f64::to_bits)),
            (bits(y), y.score.map(f64::to_bits)),
            "trial {} (stopped with trials {stopped_mid_trial:?} running): the resumed run differs",
            x.trial_id
        );
    }
}

/// A run of a hand from a URDF file, given relative to the folder it started in, resumes
/// from another folder with a larger budget: the journal keeps the hand's name, the run's
/// settings its file. Its force-sensing flag is kept too, and contradicting it is refused.
#[test]
fn a_run_of_a_hand_from_a_file_resumes_from_another_folder() {
    let dir = tempdir("resumefile");
    let hand = crate::journeys::copy_test_hand(&dir);
    assert!(hand.starts_with(&*dir));
    let out = dir.join("results");
    let shm = format!("gpe2e_rsf_{}_", std::process::id());
    let run = |cwd: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "run",
            "--object",
            "cylinder",
            "--workers",
            "1",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--shm-prefix",
            &shm,
        ];
        args.extend_from_slice(extra);
        std::process::Command::new(crate::support::graspopt_bin())
            .current_dir(cwd)
            .args(&args)
            .output()
            .unwrap()
    };
    let first = run(&dir, &["--hand", "hands/claw/claw.urdf", "--trials", "3"]);
    assert!(first.status.success(), "{first:?}");
    let journal = Journal::open(&out.join("journal.sqlite")).unwrap();
    let spec: serde_json::Value =
        serde_json::from_str(&journal.run("run").unwrap().unwrap().config_json).unwrap();
    assert_eq!(spec["hand"], "claw", "the run knows the hand by its name");
    drop(journal);
    let elsewhere = tempdir("resumefile-elsewhere");
    let resumed = run(&elsewhere, &["--resume", "--trials", "5"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let said = String::from_utf8_lossy(&resumed.stdout);
    assert!(said.contains("5 trials completed, 0 failed"), "{said}");
    check_journal(&out.join("journal.sqlite"), "run", 5);
    let refused = run(
        &elsewhere,
        &["--resume", "--trials", "6", "--sensing", "ft"],
    );
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--sensing ft (the run has clouds)"), "{err}");
    // The hand's file moved: said, and given again where it is now, the run goes on.
    let moved = dir.join("moved");
    std::fs::rename(dir.join("hands"), &moved).unwrap();
    let gone = run(&elsewhere, &["--resume", "--trials", "6"]);
    let err = String::from_utf8_lossy(&gone.stderr);
    assert!(!gone.status.success());
    assert!(
        err.contains("claw.urdf is gone: give --hand FILE where it is now"),
        "{err}"
    );
    let file = moved.join("claw/claw.urdf");
    let again = run(
        &elsewhere,
        &[
            "--resume",
            "--trials",
            "6",
            "--hand",
            file.to_str().unwrap(),
        ],
    );
    assert!(again.status.success(), "{again:?}");
    check_journal(&out.join("journal.sqlite"), "run", 6);
}

/// `graspopt run --workers 0` waits for a hand to attach; stopped by Ctrl-C before any came,
/// it says that the same command starts it afresh (not to resume it: there is nothing to
/// resume), and exits as stopped.
#[test]
fn a_run_stopped_before_its_first_trial_says_the_same_command_starts_it_afresh() {
    let dir = tempdir("workers0");
    let out = dir.join("results");
    let shm = format!("gpe2e_w0_{}_", std::process::id());
    let run = Proc::start(
        "run",
        &[
            "run",
            "--workers",
            "0",
            "--trials",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--shm-prefix",
            &shm,
        ],
        &dir,
    );
    wait_until(
        "the run announces its endpoint",
        Duration::from_secs(60),
        || crate::support::log(&dir, "run").contains("(attach with --connect)"),
    );
    signal(&run, "INT");
    let (status, stdout) = run.wait_output(Duration::from_secs(60));
    assert_eq!(status.code(), Some(130), "{stdout}");
    assert!(
        stdout.contains("(stopped before its first trial: the same command starts it afresh)"),
        "{stdout}"
    );
}
