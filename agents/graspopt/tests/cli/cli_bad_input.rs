//! Bad input to `graspopt` gets a clear error naming the flag and its value (exit 1; 2 for a
//! value its flag's parser refuses, naming the range it accepts), never a panic (101) or an
//! abort (134), and loses nothing already recorded.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::support::{graspopt, graspopt_ok, tempdir};

/// Runs `graspopt`, killing it after `limit` (a command that should have refused its input
/// at once must not hang the tests); `None` if it had to be killed.
fn graspopt_within(args: &[&str], limit: Duration) -> Option<Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_graspopt"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run graspopt");
    let started = Instant::now();
    loop {
        if child.try_wait().expect("wait for graspopt").is_some() {
            return Some(child.wait_with_output().expect("graspopt output"));
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Asserts `out` is a refusal (exit 1, no panic) whose message holds every one of `expected`.
fn assert_refused(out: &Output, args: &[&str], expected: &[&str]) {
    assert_exit(out, args, 1, expected);
}

/// Asserts `out` exited with `code` (no panic) and its message holds every one of `expected`.
fn assert_exit(out: &Output, args: &[&str], code: i32, expected: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    for e in expected {
        assert!(stderr.contains(e), "{args:?}: expected {e:?} in: {stderr}");
    }
}

fn refused(args: &[&str], expected: &[&str]) -> Output {
    let out = graspopt(args);
    assert_refused(&out, args, expected);
    out
}

/// As [`refused`], for a value its flag's parser refuses, naming the range it accepts: a
/// usage error (exit 2).
fn usage_refused(args: &[&str], expected: &[&str]) -> Output {
    let out = graspopt(args);
    assert_exit(&out, args, 2, expected);
    out
}

// --- export ---

/// A finished run of three trials in `dir`; returns its journal.
fn small_run(dir: &Path) -> PathBuf {
    graspopt_ok(&[
        "run",
        "--run",
        "r1",
        "--object",
        "sphere",
        "--trials",
        "3",
        "--workers",
        "1",
        "--method",
        "random",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ]);
    let journal = dir.join("journal.sqlite");
    assert!(std::fs::metadata(&journal).unwrap().len() > 0);
    journal
}

#[test]
fn export_refuses_to_overwrite_its_journal() {
    let dir = tempdir("export-self");
    let journal = small_run(&dir);
    let before = std::fs::read(&journal).unwrap();
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let link = dir.join("link.sqlite");
    std::os::unix::fs::symlink(&journal, &link).unwrap();
    let j = journal.to_str().unwrap();
    let same = [
        journal.clone(),
        dir.join(".").join("journal.sqlite"),
        dir.join("sub").join("..").join("journal.sqlite"),
        link.clone(),
    ];
    for out_path in &same {
        for format in ["csv", "json"] {
            let o = out_path.to_str().unwrap();
            let args = ["export", "r1", "--journal", j, "--format", format, "-o", o];
            refused(&args, &["--output", o, "journal"]);
            assert_eq!(
                std::fs::read(&journal).unwrap(),
                before,
                "{args:?} changed the journal"
            );
        }
    }
    // Through the symlink as the journal, too.
    let args = ["export", "r1", "--journal", link.to_str().unwrap(), "-o", j];
    refused(&args, &["--output"]);
    assert_eq!(std::fs::read(&journal).unwrap(), before);
    // The journal still exports.
    let ok = graspopt(&["export", "r1", "--journal", j]);
    assert!(ok.status.success());
    assert_eq!(String::from_utf8_lossy(&ok.stdout).lines().count(), 1 + 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn failed_export_leaves_an_existing_output_alone() {
    let dir = tempdir("export-keep");
    let journal = small_run(&dir);
    let j = journal.to_str().unwrap();
    let out = dir.join("trials-old.csv");
    std::fs::write(&out, "previous export\n").unwrap();
    let o = out.to_str().unwrap();
    // An unknown run fails after the journal was opened: the old output stays.
    let bad = graspopt(&["export", "nope", "--journal", j, "-o", o]);
    assert_eq!(bad.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "previous export\n");
    // A successful export replaces it, leaving no temporary file behind.
    graspopt_ok(&["export", "r1", "--journal", j, "-o", o]);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("trial,state"), "{text}");
    assert_eq!(text.lines().count(), 1 + 3);
    let stray: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

// --- scan ---

#[test]
fn scan_refuses_grids_too_large_to_hold() {
    let dir = tempdir("scan-big");
    let d = dir.to_str().unwrap();
    // 10^20 points: more than a usize counts.
    refused(
        &[
            "scan",
            "--axes",
            "x,y,rz,rx",
            "--steps",
            "100000",
            "--out",
            d,
        ],
        &["--steps", "100000"],
    );
    // 10^9 points on one axis: above the limit.
    refused(
        &["scan", "--steps", "1000000000", "--out", d],
        &["--steps 1000000000", "10000000"],
    );
    refused(
        &["scan", "--axes", "x,y", "--steps", "4000,4000", "--out", d],
        &["--steps 4000,4000", "16000000"],
    );
    // Nothing was written.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scan_of_three_axes_says_it_writes_the_csv_only() {
    let dir = tempdir("scan-3d");
    let out = graspopt(&[
        "scan",
        "--object",
        "sphere",
        "--axes",
        "x,y,rz",
        "--steps",
        "2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("note:") && stderr.contains("1 or 2 axes"),
        "{stderr}"
    );
    let files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(files, ["sphere-bw-approach-vertical-rz.csv"]);
    let help = graspopt(&["scan", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("3 or more axes") && help.contains("CSV only"),
        "{help}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

// --- optimize-function ---

#[test]
fn optimize_function_validates_initial_budget_and_seeds() {
    refused(
        &[
            "optimize-function",
            "branin",
            "--init",
            "18446744073709551615",
        ],
        &["--initial 18446744073709551615", "--budget 50"],
    );
    refused(
        &[
            "optimize-function",
            "branin",
            "--budget",
            "3",
            "--init",
            "1000000000",
        ],
        &["--initial 1000000000", "--budget 3"],
    );
    usage_refused(
        &[
            "optimize-function",
            "branin",
            "--budget",
            "18446744073709551615",
        ],
        &[
            "'18446744073709551615' for '--budget <BUDGET>': must be a whole number from 1 to 100,000",
        ],
    );
    usage_refused(
        &["optimize-function", "branin", "--seeds", "0"],
        &["'0' for '--seeds <SEEDS>': must be a whole number from 1 to 1,000"],
    );
    // `--initial` is the flag (as in `graspopt run`), `--init` its alias.
    for flag in ["--initial", "--init"] {
        let out = graspopt(&[
            "optimize-function",
            "branin",
            "--method",
            "random",
            "--seeds",
            "1",
            "--budget",
            "3",
            flag,
            "3",
        ]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{flag}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("budget 3, initial 3"), "{flag}: {stdout}");
    }
}

// --- bench ---

#[test]
fn bench_validates_every_argument_before_running() {
    let out = usage_refused(
        &["bench", "clouds", "--points", "100", "--messages", "0"],
        &["'0' for '--messages <MESSAGES>': must be a whole number from 1 to 100,000"],
    );
    assert!(out.stdout.is_empty());
    usage_refused(
        &["bench", "clouds", "--points", "18446744073709551615"],
        &["--points <POINTS>': must be a whole number from 0 to 1,000,000"],
    );
    // The 1-worker case must not run before the 0 is refused.
    for workers in ["1,0", "0", "1,100000"] {
        let args = [
            "bench",
            "pipeline",
            "--workers",
            workers,
            "--trial-cost-ms",
            "0",
            "--trials-per-worker",
            "1",
        ];
        let out = graspopt_within(&args, Duration::from_secs(60)).expect("bench pipeline hung");
        assert_exit(
            &out,
            &args,
            2,
            &["--workers <WORKERS>': must be a whole number from 1 to 256"],
        );
        assert!(
            out.stdout.is_empty(),
            "{args:?} ran before refusing: {}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
    usage_refused(
        &["bench", "pipeline", "--overhead-trials", "1"],
        &[
            "'1' for '--overhead-trials <OVERHEAD_TRIALS>': must be a whole number from 2 to 100,000",
        ],
    );
}

#[test]
fn bench_planner_validates_its_arguments_and_prints_one_row_per_dimension() {
    refused(&["bench", "planner", "--dims", "3"], &["--dims"]);
    usage_refused(
        &["bench", "planner", "--pending", "0"],
        &["'0' for '--pending <PENDING>': must be a whole number from 1 to 100,000"],
    );
    usage_refused(
        &["bench", "planner", "--rounds", "0"],
        &["'0' for '--rounds <ROUNDS>': must be a whole number from 1 to 1,000"],
    );
    // Past the engine's model cap (150), small enough to be quick.
    let out = graspopt(&[
        "bench",
        "planner",
        "--observations",
        "200",
        "--pending",
        "4",
        "--rounds",
        "2",
        "--dims",
        "2",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<&str> = stdout.lines().filter(|l| l.starts_with("| 2 |")).collect();
    assert_eq!(rows.len(), 1, "{stdout}");
    assert!(rows[0].starts_with("| 2 | branin | 200-204 |"), "{stdout}");
}

#[test]
fn bench_coordinator_validates_its_arguments_and_prints_one_row_per_run() {
    usage_refused(
        &["bench", "coordinator", "--trials", "0"],
        &["'0' for '--trials <TRIALS>': must be a whole number from 1 to 100,000"],
    );
    usage_refused(
        &[
            "bench",
            "coordinator",
            "--workers",
            "1,300",
            "--trials",
            "5",
        ],
        &["'300' for '--workers <WORKERS>': must be a whole number from 1 to 256"],
    );
    // Clap refuses an unknown path itself (exit code 2).
    let out = graspopt(&["bench", "coordinator", "--paths", "disk"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("'disk'") && stderr.contains("--paths"),
        "{stderr}"
    );
    let args = [
        "bench",
        "coordinator",
        "--workers",
        "1,3",
        "--trials",
        "6",
        "--paths",
        "core",
    ];
    let out = graspopt_within(&args, Duration::from_secs(120)).expect("bench coordinator hung");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("| core |"))
        .collect();
    assert_eq!(rows.len(), 2, "{stdout}");
    assert!(rows[0].starts_with("| core | 1 | 6 |"), "{stdout}");
    assert!(rows[1].starts_with("| core | 3 | 6 |"), "{stdout}");
}

// --- experiment metrics ---

#[test]
fn experiment_metrics_refuses_fewer_than_two_steps() {
    let dir = tempdir("metrics-steps");
    let out_dir = dir.join("out");
    let o = out_dir.to_str().unwrap();
    let steps = "'--steps <STEPS>': must be a whole number from 2 to 100,000";
    let steps_2d = "'--steps-2d <STEPS_2D>': must be a whole number from 2 to 3,000";
    usage_refused(
        &[
            "experiment",
            "metrics",
            "--steps",
            "0",
            "--steps-2d",
            "0",
            "--out",
            o,
        ],
        &[steps],
    );
    usage_refused(
        &["experiment", "metrics", "--steps", "1", "--out", o],
        &[steps],
    );
    usage_refused(
        &["experiment", "metrics", "--steps-2d", "1", "--out", o],
        &[steps_2d],
    );
    usage_refused(
        &["experiment", "metrics", "--steps-2d", "100000", "--out", o],
        &[steps_2d],
    );
    assert!(!out_dir.exists(), "a refused experiment wrote {o}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `experiment sensing` runs `--trials` per object twice over seven objects and averages
/// `--samples` per reading: both bounded, refused as usage errors (exit 2) before anything
/// runs.
#[test]
fn experiment_sensing_bounds_its_trials_and_samples() {
    for (flag, value, range) in [
        ("--trials", "0", "1..=100000"),
        ("--trials", "100001", "1..=100000"),
        ("--samples", "0", "1..=10000"),
        ("--samples", "10001", "1..=10000"),
    ] {
        let out = graspopt(&["experiment", "sensing", flag, value]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {stderr}");
        for part in [flag, value, range] {
            assert!(
                stderr.contains(part),
                "{flag} {value}: {part:?} not in {stderr}"
            );
        }
        assert!(out.stdout.is_empty(), "{flag} {value}");
    }
}

#[test]
fn experiment_metrics_report_tables_each_have_a_header() {
    let dir = tempdir("metrics-report");
    graspopt_ok(&[
        "experiment",
        "metrics",
        "--steps",
        "3",
        "--steps-2d",
        "2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let lines: Vec<&str> = report.lines().collect();
    // Every block of table lines starts with a header and its |---| separator.
    let mut tables = 0;
    for (i, l) in lines.iter().enumerate() {
        let starts_block = l.starts_with('|') && (i == 0 || !lines[i - 1].starts_with('|'));
        if starts_block {
            tables += 1;
            assert!(
                l.starts_with("| object") || l.starts_with("| frame"),
                "a table without a header at line {}: {l}\n{report}",
                i + 1
            );
            assert!(
                lines.get(i + 1).is_some_and(|n| n.starts_with("|---")),
                "line {}: {l}\n{report}",
                i + 1
            );
        }
    }
    // 4.3-4.5, two for 4.6 (cuboid, sphere), 4.7, 4.8, 4.9-4.15.
    assert_eq!(tables, 6, "{report}");
    let sphere_rows = lines
        .iter()
        .filter(|l| l.starts_with("| sphere | "))
        .count();
    assert!(sphere_rows >= 3, "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}

// --- topic, router ---

#[test]
fn topic_rate_windows_below_three_messages_are_refused() {
    for what in ["hz", "bw"] {
        let args = [
            "topic",
            what,
            "status",
            "--window",
            "0",
            "--duration",
            "2",
            "--no-multicast-scouting",
        ];
        let out = graspopt_within(&args, Duration::from_secs(30)).expect("topic hung");
        assert_exit(
            &out,
            &args,
            2,
            &["'--window <WINDOW>': must be a whole number of 3 or more"],
        );
    }
}

#[test]
fn router_has_no_agent_flags() {
    // A router is always a router and never uses shared memory: those agent flags are
    // unknown to it (clap's usage error, status 2), and it does not start.
    for flags in [
        vec!["--mode", "client"],
        vec!["--mode", "router"],
        vec!["--shm-prefix", "p"],
        vec!["--no-shm"],
    ] {
        let mut args = vec!["router", "--listen", "tcp/127.0.0.1:0"];
        args.extend(&flags);
        let out = graspopt_within(&args, Duration::from_secs(20))
            .unwrap_or_else(|| panic!("`graspopt {}` kept running", args.join(" ")));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(flags[0]), "{args:?}: {stderr}");
        assert!(!stderr.contains("listening"), "{args:?}: {stderr}");
    }
    // An address it cannot listen on is named (Zenoh's own error does not name it).
    let args = ["router", "--listen", "tcp/nosuchhost.invalid:7447"];
    let out = graspopt_within(&args, Duration::from_secs(30)).expect("the router kept running");
    assert_refused(
        &out,
        &args,
        &["cannot listen on tcp/nosuchhost.invalid:7447"],
    );
}

// --- trial ---

#[test]
fn trial_names_the_bad_parameter_compactly() {
    refused(
        &["trial", "--object", "sphere", "--at", "x=NaN"],
        &["--at", "x (approach) = NaN"],
    );
    refused(
        &["trial", "--object", "sphere", "--at", "y=0,rz=inf"],
        &["--at", "rz", "inf"],
    );
    let out = refused(
        &["trial", "--object", "sphere", "--at", "x=1e300"],
        &["--at", "x (approach)", "1.0000e300", "outside"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.len() < 200, "{stderr}");
    assert!(!stderr.contains("000000000000"), "{stderr}");
}

#[test]
fn trial_refuses_picture_files_it_cannot_write() {
    let dir = tempdir("trial-ext");
    let jpg = dir.join("p.jpg");
    let stl = dir.join("s.stl");
    let bare = dir.join("scene");
    let base = ["trial", "--object", "sphere", "--at", "x=-0.1"];
    let with = |flag: &str, p: &Path| -> Vec<String> {
        base.iter()
            .map(|s| s.to_string())
            .chain([flag.to_string(), p.to_str().unwrap().to_string()])
            .collect()
    };
    for (flag, path, expected) in [
        ("--preview", &jpg, vec![".png"]),
        ("--scene", &stl, vec![".gltf", ".obj"]),
        ("--scene", &bare, vec![".gltf", ".obj"]),
    ] {
        let args = with(flag, path);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let mut want = vec![flag, path.to_str().unwrap()];
        want.extend(expected);
        refused(&args, &want);
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "files written");
    std::fs::remove_dir_all(&dir).unwrap();
}

// --- the open-file limit ---

/// `graspopt args` under `ulimit` set to `limit` (e.g. `-n 300`: soft and hard; `-Sn 200`:
/// soft only), through `sh`, since setting a child's limit from Rust needs `unsafe`.
fn graspopt_under_ulimit(limit: &str, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit {limit} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_graspopt"))
        .args(args)
        .output()
        .expect("run sh")
}

/// A run whose hand workers need more open files than the hard limit allows is refused before
/// anything is written, with both numbers and what to do.
#[test]
fn run_refuses_more_workers_than_the_open_file_limit_allows() {
    let dir = tempdir("nofile-refused");
    let out = dir.join("r");
    let args = [
        "run",
        "--workers",
        "64",
        "--trials",
        "2",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = graspopt_under_ulimit("-n 300", &args);
    assert_refused(
        &o,
        &args,
        &[
            "--workers 64 needs about 1920 open files",
            "at most 300",
            "use at most 6 workers",
            "graspopt launch",
        ],
    );
    // A run refused at start does not first announce where to attach.
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("attach with"), "{stderr}");
    assert!(!out.exists(), "a refused run wrote {}", out.display());
    // More hands than one process runs, whatever the limit.
    let args = ["run", "--workers", "100000", "--out", out.to_str().unwrap()];
    refused(
        &args,
        &["--workers 100000 is more than the 1024 hand workers one process runs"],
    );
    assert!(!out.exists(), "a refused run wrote {}", out.display());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A soft limit below what the workers need is raised to the hard one: every trial completes
/// and every hand sends its clouds through shared memory (under the soft limit of 200, eight
/// hands ran out of descriptors: lease expiries and fallbacks to Zenoh).
#[test]
fn run_raises_a_soft_open_file_limit_its_workers_exceed() {
    let dir = tempdir("nofile-raised");
    let out = dir.join("r");
    let args = [
        "run",
        "--object",
        "sphere",
        "--method",
        "random",
        "--workers",
        "8",
        "--trials",
        "16",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = graspopt_under_ulimit("-Sn 200", &args);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("16 trials completed, 0 failed"),
        "{stdout}\n{stderr}"
    );
    for warning in [
        "shared memory unavailable",
        "expired",
        "Too many open files",
    ] {
        assert!(!stderr.contains(warning), "{warning}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `topic list` at an address where nothing answers says so and fails, rather than listing no
/// agents as an idle bus would.
#[test]
fn topic_list_names_an_address_where_nothing_answers() {
    refused(
        &["topic", "list", "--connect", "tcp/127.0.0.1:1"],
        &["nothing answers at tcp/127.0.0.1:1"],
    );
}

/// A launch file whose agent has a flag its command does not know is refused before
/// anything starts (with --dry-run too), naming the file, the agent and the flag.
#[test]
fn launch_checks_every_agent_s_flags_before_starting_any() {
    let dir = tempdir("launch-args");
    let file = dir.join("typo.toml");
    std::fs::write(
        &file,
        "run = \"r\"\nendpoint = \"tcp/127.0.0.1:7449\"\n[router]\n[[agent]]\nkind = \"planner\"\n\
         [[agent]]\nkind = \"hand\"\nargs = [\"--trial-cost\", \"5\"]\n",
    )
    .unwrap();
    let path = file.to_str().unwrap();
    let logs = dir.join("logs");
    for extra in [&["--dry-run"][..], &[]] {
        let mut args = vec!["launch", path, "--logs", logs.to_str().unwrap()];
        args.extend_from_slice(extra);
        let out = refused(&args, &["typo.toml: hand:", "'--trial-cost'"]);
        // Nothing started: no log folder.
        assert!(!logs.exists());
        assert!(out.stdout.is_empty());
    }
    // A setting the agent does not have, or cannot take, likewise.
    for (set, why) in [
        ("trial_cost=5", "unknown key `trial_cost` at the top level"),
        (
            "trial_cost_ms=soon",
            "invalid type: string \"soon\", expected u64",
        ),
    ] {
        let text = format!(
            "run = \"r\"\nendpoint = \"tcp/127.0.0.1:7449\"\n[[agent]]\nkind = \"hand\"\n\
             args = [\"--set\", \"{set}\"]\n"
        );
        std::fs::write(&file, text).unwrap();
        let args = [
            "launch",
            path,
            "--dry-run",
            "--logs",
            logs.to_str().unwrap(),
        ];
        refused(&args, &["typo.toml: hand:", &format!("--set {set}: {why}")]);
        assert!(!logs.exists());
    }
}
