//! A run killed (SIGKILL) in the middle and resumed from its journal: every trial completed
//! before the kill is kept as it was, the run finishes its budget, and `graspopt export`
//! reads the result.

use std::time::{Duration, Instant};

use graspopt_e2e::{Proc, check_journal, graspopt, tempdir};
use graspopt_journal::{Journal, TrialState};

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
                .filter(|t| t.state == TrialState::Completed)
                .count();
            if done >= 6 && trials.iter().any(|t| t.state == TrialState::Running) {
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
        .filter(|t| t.state == TrialState::Completed)
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
        .filter(|t| t.state == TrialState::Running)
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
