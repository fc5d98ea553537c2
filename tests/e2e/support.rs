//! What the end-to-end tests share: the `graspopt` binary of this build, scratch folders,
//! free loopback ports, child processes that are killed when the test ends (pass or fail), a
//! router with agents around it, and checks of a finished run's journal.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The repository's root folder.
pub fn repo_root() -> PathBuf {
    // These tests belong to the package in agents/graspopt.
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .and_then(Path::parent)
        .expect("agents/graspopt is two levels inside the repository")
        .to_path_buf()
}

/// The `graspopt` binary of this very build: cargo builds it before it builds the tests of
/// its package, so a test never runs a stale binary.
pub fn graspopt_bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_graspopt"))
}

/// Runs `graspopt` to completion.
pub fn graspopt(args: &[&str]) -> Output {
    Command::new(graspopt_bin())
        .args(args)
        .output()
        .expect("run graspopt")
}

pub use crate::scratch::{Scratch, tempdir};

/// A free TCP port on 127.0.0.1.
pub fn free_port() -> u16 {
    std::net::TcpListener::bind(("127.0.0.1", 0))
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// A child process killed (SIGKILL) when dropped.
pub struct Proc {
    pub name: String,
    pub child: Child,
}

impl Proc {
    /// Starts `graspopt args...`, stdout piped (read it with [`Proc::wait_output`]), stderr to
    /// a log file in `logs`.
    pub fn start(name: &str, args: &[&str], logs: &Path) -> Proc {
        let log = std::fs::File::create(logs.join(format!("{name}.log"))).unwrap();
        let child = Command::new(graspopt_bin())
            .args(args)
            .env("RUST_LOG", "warn")
            .stdout(Stdio::piped())
            .stderr(log)
            .spawn()
            .unwrap_or_else(|e| panic!("start {name}: {e}"));
        Proc {
            name: name.to_string(),
            child,
        }
    }

    /// SIGKILL now.
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// Waits up to `timeout` for the process to exit; returns its stdout. Panics on timeout
    /// (the process is killed by drop).
    pub fn wait_output(mut self, timeout: Duration) -> (std::process::ExitStatus, String) {
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                let mut out = String::new();
                if let Some(mut s) = self.child.stdout.take() {
                    use std::io::Read;
                    s.read_to_string(&mut out).unwrap();
                }
                return (status, out);
            }
            assert!(
                start.elapsed() < timeout,
                "{} did not finish within {timeout:?}",
                self.name
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The log of a process started with [`Proc::start`].
pub fn log(logs: &Path, name: &str) -> String {
    std::fs::read_to_string(logs.join(format!("{name}.log"))).unwrap_or_default()
}

/// Parses a CSV file written by `graspopt export` into header and rows (no quoted commas in
/// the columns these tests read).
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

/// Waits until something accepts TCP connections on `127.0.0.1:port`.
pub fn wait_for_port(port: u16, timeout: Duration) {
    let start = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            start.elapsed() < timeout,
            "nothing listens on port {port} after {timeout:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A router on a free loopback port and the flags every agent of one run needs to join it.
pub struct Cluster {
    pub dir: Scratch,
    /// The router's endpoint, `tcp/127.0.0.1:<port>`.
    pub endpoint: String,
    pub run: String,
    /// This cluster's shared-memory prefix (unique per test process and cluster).
    pub shm: String,
    router: Proc,
}

impl Cluster {
    /// Starts the router and waits until it listens.
    pub fn start(name: &str, run: &str) -> Cluster {
        Cluster::start_with(name, run, |_| Vec::new())
    }

    /// As [`Cluster::start`], with more router flags, made from the scratch folder (a
    /// configuration file written there, say).
    pub fn start_with(
        name: &str,
        run: &str,
        router_flags: impl FnOnce(&Path) -> Vec<String>,
    ) -> Cluster {
        // What earlier runs of these tests left (killed agents' shared memory), once per
        // test process; live agents of concurrent tests are not touched.
        static CLEAN: std::sync::Once = std::sync::Once::new();
        CLEAN.call_once(|| {
            let _ = graspopt_shm::clean_stale_prefixes("gpe2e_");
        });
        let dir = tempdir(name);
        let port = free_port();
        let endpoint = format!("tcp/127.0.0.1:{port}");
        let mut args: Vec<String> = ["router", "--listen", &endpoint, "--no-multicast-scouting"]
            .map(String::from)
            .to_vec();
        args.extend(router_flags(&dir));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let router = Proc::start("router", &args, &dir);
        wait_for_port(port, Duration::from_secs(20));
        // Short: the prefix is at most 32 characters.
        let tag: String = name
            .chars()
            .filter(char::is_ascii_alphanumeric)
            .take(6)
            .collect();
        let shm = format!("gpe2e_{tag}_{}_", std::process::id());
        Cluster {
            dir,
            endpoint,
            run: run.to_string(),
            shm,
            router,
        }
    }

    /// Starts `graspopt agent ...` (`args` from `agent` on) with the run, router and
    /// shared-memory flags added; its stderr goes to `<dir>/<name>.log`.
    pub fn agent(&self, name: &str, args: &[&str]) -> Proc {
        let mut v: Vec<&str> = vec!["agent"];
        v.extend_from_slice(args);
        v.extend_from_slice(&[
            "--run",
            &self.run,
            "--connect",
            &self.endpoint,
            "--no-multicast-scouting",
            "--shm-prefix",
            &self.shm,
        ]);
        Proc::start(name, &v, &self.dir)
    }

    /// Perception (publishing `object` at its true pose), a planner and a metric agent: what
    /// every run needs besides its hands and coordinator.
    pub fn support(&self, object: &str) -> Vec<Proc> {
        vec![
            self.agent(
                "perception",
                &["perception", "--set", &format!("object={object}")],
            ),
            self.agent("planner", &["planner"]),
            self.agent("metric", &["metric"]),
        ]
    }

    /// Hands `hand-1` ... `hand-<n>`, each with `extra` flags.
    pub fn hands(&self, n: usize, extra: &[&str]) -> Vec<Proc> {
        (1..=n)
            .map(|i| {
                let id = format!("hand-{i}");
                let mut args = vec!["hand", "--id", &id];
                args.extend_from_slice(extra);
                self.agent(&id, &args)
            })
            .collect()
    }

    /// This cluster's journal: `<dir>/journal.sqlite`.
    pub fn journal(&self) -> PathBuf {
        self.dir.join("journal.sqlite")
    }

    /// The coordinator of a run of `trials` trials on `object` with `seed`, journal
    /// [`Cluster::journal`], and `extra` flags.
    pub fn coordinator(&self, object: &str, trials: &str, seed: &str, extra: &[&str]) -> Proc {
        self.coordinator_as("coordinator", object, trials, seed, extra)
    }

    /// As [`Cluster::coordinator`], logging to `<dir>/<name>.log` (a restarted coordinator).
    pub fn coordinator_as(
        &self,
        name: &str,
        object: &str,
        trials: &str,
        seed: &str,
        extra: &[&str],
    ) -> Proc {
        let journal = format!("journal={}", self.journal().display());
        let mut args = vec![
            "coordinator",
            "--object",
            object,
            "--trials",
            trials,
            "--seed",
            seed,
            "--set",
            &journal,
        ];
        args.extend_from_slice(extra);
        self.agent(name, &args)
    }

    /// Waits for the coordinator to finish successfully; returns the final status it printed.
    pub fn final_status(&self, coordinator: Proc, timeout: Duration) -> serde_json::Value {
        let name = coordinator.name.clone();
        let (status, stdout) = coordinator.wait_output(timeout);
        assert!(
            status.success(),
            "{name} failed: {stdout}\n{}",
            self.log(&name)
        );
        serde_json::from_str(stdout.trim()).unwrap()
    }

    /// Flags of an in-test client of this cluster's router (no shared memory, no
    /// scouting), with a Zenoh configuration file if given.
    pub fn client_args(&self, zenoh_config: Option<PathBuf>) -> graspopt_bus::BusConfig {
        graspopt_bus::BusConfig {
            connect: vec![self.endpoint.clone()],
            mode: Some(graspopt_bus::BusMode::Client),
            zenoh_config,
            no_multicast_scouting: true,
            no_shm: true,
            ..Default::default()
        }
    }

    /// The log of one of this cluster's processes.
    pub fn log(&self, name: &str) -> String {
        log(&self.dir, name)
    }

    /// The router process (to check it survived, or to kill it).
    pub fn router(&mut self) -> &mut Proc {
        &mut self.router
    }

    /// Starts the router again on the same endpoint (after [`Proc::kill`] on it).
    pub fn restart_router(&mut self) {
        let port: u16 = self
            .endpoint
            .rsplit(':')
            .next()
            .and_then(|p| p.parse().ok())
            .unwrap();
        self.router = Proc::start(
            "router-restarted",
            &[
                "router",
                "--listen",
                &self.endpoint,
                "--no-multicast-scouting",
            ],
            &self.dir,
        );
        wait_for_port(port, Duration::from_secs(20));
    }
}

/// A failed test leaves the tail of every process's log on stderr: a run that stalled in CI
/// then says which agent stopped and why.
/// Its agents are dead by then (declared after the cluster, dropped and killed before it):
/// the shared memory they left under this cluster's prefix is removed, so killed agents do
/// not pile files into /dev/shm and /tmp/iceoryx2 run after run.
impl Drop for Cluster {
    fn drop(&mut self) {
        // Best effort: a failure leaves files behind, never fails the test. What iceoryx2
        // keeps per prefix once its nodes are gone (a management segment) goes too: the
        // prefix is this cluster's alone.
        let _ = graspopt_shm::clean_stale_prefixes(&self.shm);
        for dir in ["/dev/shm", "/tmp/iceoryx2"] {
            for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
                if entry.file_name().to_string_lossy().starts_with(&self.shm) {
                    let _ = std::fs::remove_file(entry.path());
                }
            }
        }
        if !std::thread::panicking() {
            return;
        }
        let Ok(entries) = std::fs::read_dir(&*self.dir) else {
            return;
        };
        let mut logs: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "log"))
            .collect();
        logs.sort();
        for path in logs {
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            let lines: Vec<&str> = text.lines().collect();
            let tail = &lines[lines.len().saturating_sub(40)..];
            eprintln!("---- {} (last {} lines)", path.display(), tail.len());
            for line in tail {
                eprintln!("{line}");
            }
        }
    }
}

/// Column index by name.
pub fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// Checks the journal of a finished run: exactly `n` completed trials with finite scores and
/// metrics consistent with each other (BW > 0 exactly when force closure), ids 1..=n.
/// Returns the trials.
pub fn check_journal(path: &Path, run: &str, n: usize) -> Vec<graspopt_journal::TrialRow> {
    let journal = graspopt_journal::Journal::open(path).unwrap();
    assert!(journal.integrity_check().unwrap());
    let trials = journal.trials(run).unwrap();
    assert_eq!(trials.len(), n, "trials in the journal");
    for (i, t) in trials.iter().enumerate() {
        assert_eq!(t.trial_id, i as u64 + 1);
        assert_eq!(
            t.state,
            graspopt_journal::StoredTrialPhase::Completed,
            "trial {}",
            t.trial_id
        );
        assert!(t.score.unwrap().is_finite());
        if let Some(m) = &t.metrics {
            let real = |key| m.real(key).unwrap();
            assert!(real("bw").is_finite() && real("epsilon") >= 0.0 && real("distance") >= 0.0);
            let fc = m.flag("force_closure");
            assert_eq!(Some(real("bw") > 0.0), fc, "trial {}", t.trial_id);
        }
    }
    trials
}

/// The best (id, score) the journal holds for a run.
pub fn journal_best(path: &Path, run: &str) -> (u64, f64) {
    let journal = graspopt_journal::Journal::open(path).unwrap();
    let best = journal.best(run).unwrap().unwrap();
    (best.trial_id, best.score.unwrap())
}

/// The path a trial's clouds took to the metric agent (`shm` or `zenoh`), from the journal.
pub fn cloud_transport(t: &graspopt_journal::TrialRow) -> String {
    let details: serde_json::Value =
        serde_json::from_str(t.details_json.as_deref().unwrap_or("{}")).unwrap();
    details["cloud_transport"]
        .as_str()
        .unwrap_or_default()
        .to_string()
}

/// Sends a signal to a process with `kill(1)` (`STOP`, `CONT`, `KILL`).
pub fn signal(p: &Proc, name: &str) {
    let ok = Command::new("kill")
        .args([format!("-{name}"), p.child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill -{name} {}", p.name);
}

/// An embedded run of `run_id` on `object` that lasts (1000 random trials of 40 ms on two
/// workers), listening on `endpoint` for tools to attach; results in `<dir>/results`.
pub fn long_run(dir: &Path, run_id: &str, object: &str, endpoint: &str) -> Proc {
    let out = dir.join("results");
    let shm = format!("gpe2e_{run_id}_{}_", std::process::id());
    let p = Proc::start(
        "run",
        &[
            "run",
            "--run",
            run_id,
            "--object",
            object,
            "--workers",
            "2",
            "--trials",
            "1000",
            "--method",
            "random",
            "--trial-cost-ms",
            "40",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--listen",
            endpoint,
            "--no-multicast-scouting",
            "--shm-prefix",
            &shm,
        ],
        dir,
    );
    let port: u16 = endpoint.rsplit(':').next().unwrap().parse().unwrap();
    wait_for_port(port, Duration::from_secs(30));
    p
}

/// Completed trials in the journal right now (0 while it does not exist yet).
pub fn completed_now(path: &Path, run: &str) -> usize {
    if !path.exists() {
        return 0;
    }
    let journal = graspopt_journal::Journal::open(path)
        .unwrap_or_else(|e| panic!("journal {}: {e}", path.display()));
    match journal.run(run) {
        Ok(Some(_)) => journal.counts(run).map(|c| c.completed),
        Ok(None) => Ok(0),
        Err(e) => Err(e),
    }
    .unwrap_or_else(|e| panic!("journal {}: {e}", path.display()))
}

/// Waits until `pred` holds, polling every 20 ms; panics with `what` after `timeout`.
pub fn wait_until(what: &str, timeout: Duration, mut pred: impl FnMut() -> bool) {
    let start = Instant::now();
    while !pred() {
        assert!(start.elapsed() < timeout, "{what}: not after {timeout:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Records one test's figures: printed, and appended as a JSON line to
/// `target/<profile>/reliability.jsonl` (`.ci/run` prints that file; docs/reliability.md
/// quotes it).
pub fn report(figures: serde_json::Value) {
    use std::io::Write;
    println!("reliability: {figures}");
    let bin = graspopt_bin();
    let path = bin
        .parent()
        .unwrap_or(Path::new("."))
        .join("reliability.jsonl");
    if let Ok(mut f) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
    {
        let _ = writeln!(f, "{figures}");
    }
}

/// What a finished run of `n` trials lost and recorded twice, from its journal: trials of
/// `1..=n` not completed, and trials with more than one accepted result in the event log.
pub fn lost_and_recorded_twice(path: &Path, run: &str, n: u64) -> (u64, u64) {
    let journal = graspopt_journal::Journal::open(path).unwrap();
    let completed: std::collections::BTreeSet<u64> = journal
        .trials(run)
        .unwrap()
        .iter()
        .filter(|t| t.state == graspopt_journal::StoredTrialPhase::Completed)
        .map(|t| t.trial_id)
        .collect();
    let lost = (1..=n).filter(|id| !completed.contains(id)).count() as u64;
    let mut results: std::collections::BTreeMap<u64, u64> = Default::default();
    for e in journal.events(run).unwrap() {
        if e.kind == graspopt_journal::event_kind::RESULT {
            *results.entry(e.trial_id).or_default() += 1;
        }
    }
    let twice = results.values().filter(|&&c| c > 1).count() as u64;
    (lost, twice)
}

/// Asserts that a finished run of `n` trials lost none and recorded none twice; returns the
/// number lost (0) for the test's report.
pub fn assert_nothing_lost(path: &Path, run: &str, n: u64) -> u64 {
    let (lost, twice) = lost_and_recorded_twice(path, run, n);
    assert_eq!((lost, twice), (0, 0), "trials lost, trials recorded twice");
    lost
}
