//! A launch file and its supervision (`graspopt launch FILE`): the agents a launch file
//! places on this machine, each as its own process, started and supervised.
//!
//! A launch file (TOML) names the run, the router endpoint every agent connects to, an
//! optional router, and the agents. An entry with a `host` runs only on the machine launched
//! with that `--host` (default: this machine's host name), so one file describes a whole
//! installation and each machine runs its part; an entry without `host` runs wherever the
//! file is launched. `deploy/local.toml` and `deploy/two-machines.toml` are examples.
//!
//! The router starts first (launch waits until it accepts connections), then the agents in
//! file order. Each process's stderr goes to `<logs>/<name>.log`; stdout is passed through
//! (the coordinator prints the final status there). When the coordinator exits, the others
//! are stopped (SIGTERM, then SIGKILL) and launch exits with the coordinator's status; if
//! another process exits first, launch stops everything and names it. Ctrl-C stops all.
//!
//! Each process runs in its own process group, so a terminal's Ctrl-C (or hang-up), sent to
//! the foreground group, reaches launch alone, which stops the processes in order: the
//! coordinator first (it records the run as stopped, every result in), then the agents,
//! the router last. Signalled all at once, the coordinator would see its workers leave and
//! re-issue their trials on its way out.
//!
//! Processes are signalled with `nix::sys::signal::kill` (SIGTERM, then SIGKILL after 5 s).

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use graspopt_protocol::AgentKind;
use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;
use serde::Deserialize;

use crate::error::RunnerError;

type Result<T> = std::result::Result<T, RunnerError>;

/// A launch file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaunchFile {
    /// The run every agent joins.
    pub run: String,
    /// The router endpoint every agent connects to, e.g. `tcp/192.168.1.10:7447`.
    pub endpoint: String,
    /// Disable UDP multicast scouting in every process (default true: only `endpoint`).
    #[serde(default = "yes")]
    pub no_multicast_scouting: bool,
    pub router: Option<RouterEntry>,
    #[serde(default, rename = "agent")]
    pub agents: Vec<AgentEntry>,
}

fn yes() -> bool {
    true
}

/// The router.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouterEntry {
    pub host: Option<String>,
    /// Where the router listens (default: the endpoint).
    pub listen: Option<String>,
    /// A Zenoh configuration file for the router (json5), relative to the launch file.
    pub zenoh_config: Option<PathBuf>,
}

/// One agent, or `count` copies of it.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentEntry {
    /// perception, hand, metric, planner or coordinator.
    pub kind: String,
    pub host: Option<String>,
    /// Agent id (default: the kind); with `count` > 1, `<id>-1` ... `<id>-<count>`.
    pub id: Option<String>,
    /// Number of copies (hand workers, say).
    #[serde(default = "one")]
    pub count: u32,
    /// The agent's settings file (TOML), relative to the launch file.
    pub config: Option<PathBuf>,
    /// A Zenoh configuration file (json5), relative to the launch file.
    pub zenoh_config: Option<PathBuf>,
    /// More flags for `graspopt agent <kind>`.
    #[serde(default)]
    pub args: Vec<String>,
}

fn one() -> u32 {
    1
}

impl AgentEntry {
    /// Why this entry cannot be launched: an unknown kind, or a count out of range.
    fn check(&self) -> std::result::Result<(), String> {
        if AgentKind::parse(&self.kind).is_none() {
            let kinds: Vec<&str> = AgentKind::ALL.iter().map(|k| k.as_str()).collect();
            return Err(format!(
                "unknown agent kind {:?} (one of {})",
                self.kind,
                kinds.join(", ")
            ));
        }
        if self.count == 0 {
            return Err(format!("agent {:?} has count 0", self.kind));
        }
        // As many hands as one process may run (`graspopt run --workers`): the host's
        // shared-memory service admits no more.
        if self.count as usize > graspopt_shm::DEFAULT_MAX_PUBLISHERS {
            return Err(format!(
                "agent {:?} has count {}, more than the {} processes of one kind a machine runs",
                self.kind,
                self.count,
                graspopt_shm::DEFAULT_MAX_PUBLISHERS
            ));
        }
        Ok(())
    }

    /// The ids of this entry's processes: the id (default: the kind), or `<id>-1` ...
    /// `<id>-<count>` for several.
    fn names(&self) -> Vec<String> {
        let id = self.id.clone().unwrap_or_else(|| self.kind.clone());
        if self.count > 1 {
            (1..=self.count).map(|i| format!("{id}-{i}")).collect()
        } else {
            vec![id]
        }
    }
}

/// One process to start.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    /// Unique name: the agent id, or `router`.
    pub name: String,
    pub coordinator: bool,
    /// Arguments of `graspopt`.
    pub args: Vec<String>,
    /// For the router: the `host:port` to wait for (loopback for a wildcard listener).
    pub wait_addr: Option<String>,
}

impl LaunchFile {
    pub fn parse(text: &str, origin: &Path) -> Result<LaunchFile> {
        let file = origin.to_path_buf();
        let invalid = |source: crate::error::Boxed| RunnerError::LaunchFileInvalid {
            file: file.clone(),
            source,
        };
        let refused = |why: String| RunnerError::LaunchFile {
            file: file.clone(),
            why,
        };
        let launch: LaunchFile = toml::from_str(text).map_err(|e| invalid(e.into()))?;
        graspopt_protocol::RunId::new(&launch.run).map_err(|source| RunnerError::LaunchRun {
            file: file.clone(),
            source,
        })?;
        let connect = graspopt_bus::config::EndpointUse::Connect;
        graspopt_bus::config::check_endpoint(&launch.endpoint, connect)
            .map_err(|e| invalid(e.into()))?;
        for a in &launch.agents {
            a.check().map_err(refused)?;
        }
        let mut names = std::collections::HashSet::new();
        for a in &launch.agents {
            for name in a.names() {
                // The id names the agent on the bus and its log file.
                graspopt_protocol::keys::check_agent_id(&name).map_err(|e| invalid(e.into()))?;
                if !names.insert(name.clone()) {
                    return Err(refused(format!(
                        "two agents named {name:?} (ids are unique in a run, across hosts)"
                    )));
                }
            }
        }
        let coordinator = AgentKind::Coordinator.as_str();
        if launch
            .agents
            .iter()
            .filter(|a| a.kind == coordinator)
            .count()
            > 1
        {
            return Err(refused("a run has one coordinator".into()));
        }
        Ok(launch)
    }

    /// The processes `host` runs, in start order. Paths are resolved against `base` (the
    /// launch file's folder).
    pub fn plan(&self, host: &str, base: &Path) -> Result<Vec<Planned>> {
        let here = |h: &Option<String>| h.as_deref().is_none_or(|h| h == host);
        let resolve = |p: &Path| base.join(p).display().to_string();
        let mut out = Vec::new();
        if let Some(r) = &self.router
            && here(&r.host)
        {
            let listen = r.listen.clone().unwrap_or_else(|| self.endpoint.clone());
            let mut args = vec!["router".to_string(), "--listen".into(), listen.clone()];
            if let Some(z) = &r.zenoh_config {
                args.extend(["--zenoh-config".into(), resolve(z)]);
            }
            if self.no_multicast_scouting {
                args.push("--no-multicast-scouting".into());
            }
            out.push(Planned {
                name: "router".into(),
                coordinator: false,
                args,
                wait_addr: reachable_addr(&listen),
            });
        }
        for a in self.agents.iter().filter(|a| here(&a.host)) {
            for name in a.names() {
                let mut args = vec![
                    "agent".to_string(),
                    a.kind.clone(),
                    "--run".into(),
                    self.run.clone(),
                    "--id".into(),
                    name.clone(),
                    "--connect".into(),
                    self.endpoint.clone(),
                ];
                if self.no_multicast_scouting {
                    args.push("--no-multicast-scouting".into());
                }
                if let Some(c) = &a.config {
                    args.extend(["--config".into(), resolve(c)]);
                }
                if let Some(z) = &a.zenoh_config {
                    args.extend(["--zenoh-config".into(), resolve(z)]);
                }
                args.extend(a.args.iter().cloned());
                out.push(Planned {
                    name,
                    coordinator: a.kind == AgentKind::Coordinator.as_str(),
                    args,
                    wait_addr: None,
                });
            }
        }
        Ok(out)
    }
}

/// The launch file at `path` and the processes this machine, `host`, runs of it, in start
/// order; `endpoint` replaces the file's router endpoint (a router in the file then listens
/// on it); with `resume`, the coordinator resumes its run. An error if nothing runs here.
pub fn prepare(
    path: &Path,
    host: &str,
    endpoint: Option<&str>,
    resume: bool,
) -> Result<(LaunchFile, Vec<Planned>)> {
    let text = std::fs::read_to_string(path).map_err(|source| RunnerError::LaunchRead {
        file: path.to_path_buf(),
        source,
    })?;
    let mut file = LaunchFile::parse(&text, path)?;
    if let Some(e) = endpoint {
        file.endpoint = e.to_string();
        if let Some(r) = &mut file.router {
            r.listen = None;
        }
    }
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut plan = file.plan(host, &base)?;
    if plan.is_empty() {
        return Err(RunnerError::LaunchFile {
            file: path.to_path_buf(),
            why: format!("nothing runs on host {host:?} (use --host to pick an entry's host)"),
        });
    }
    if resume {
        resume_coordinator(&mut plan, host)?;
    }
    Ok((file, plan))
}

/// Makes the coordinator of `plan` resume its run (`--resume`, once). An error if `plan`
/// has no coordinator: only the machine that runs it can resume the run.
pub fn resume_coordinator(plan: &mut [Planned], host: &str) -> Result<()> {
    let Some(c) = plan.iter_mut().find(|p| p.coordinator) else {
        return Err(RunnerError::NoCoordinatorHere {
            host: host.to_string(),
        });
    };
    if !c.args.iter().any(|a| a == "--resume") {
        c.args.push("--resume".into());
    }
    Ok(())
}

/// Where this machine reaches a router listening on `tcp/<address>:<port>`: that address,
/// or loopback for a wildcard one. `None` for other protocols.
fn reachable_addr(endpoint: &str) -> Option<String> {
    let rest = endpoint.strip_prefix("tcp/")?;
    let (host, port) = rest.rsplit_once(':')?;
    let port: u16 = port.parse().ok()?;
    let host = match host {
        "0.0.0.0" | "[::]" | "" => "127.0.0.1",
        h => h,
    };
    Some(format!("{host}:{port}"))
}

/// A started process.
struct Running {
    name: String,
    coordinator: bool,
    router: bool,
    child: Child,
    log: PathBuf,
}

/// The processes of a launch: stopped when dropped, so an early return leaves none behind.
pub struct Children(Vec<Running>);

impl Drop for Children {
    fn drop(&mut self) {
        self.terminate();
    }
}

/// How a supervised launch ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The coordinator exited (every process did, if none was a coordinator): its exit code
    /// (`None`: killed by a signal) and its log.
    Coordinator(Option<i32>, Option<PathBuf>),
    /// Another process stopped first: its name, exit status and log.
    Died(String, String, PathBuf),
    /// A shutdown signal came.
    Interrupted,
}

impl Outcome {
    /// How a launch of `file` that ended so ends: its exit status and what to say (the
    /// coordinator's end, or a Ctrl-C), or the error of a process that stopped first.
    pub fn ending(self, file: &Path) -> Result<(u8, Option<String>)> {
        match self {
            Outcome::Coordinator(Some(0), _) => Ok((0, None)),
            Outcome::Coordinator(code, log) => {
                let log = log.unwrap_or_default();
                let no_trial = i32::from(crate::ending::NO_TRIAL_COMPLETED);
                let what = if code == Some(no_trial) {
                    "no trial of the run completed"
                } else {
                    "the coordinator failed"
                };
                let said = format!(
                    "graspopt launch: {what}; the coordinator's log ({}):\n{}",
                    log.display(),
                    tail(&log, 20)
                );
                // Its exit status is launch's (1 if it was killed by a signal).
                let code = code.and_then(|c| u8::try_from(c).ok()).unwrap_or(1);
                Ok((code, Some(said)))
            }
            Outcome::Died(name, status, log) => Err(RunnerError::Died {
                name,
                status,
                tail: tail(&log, 20),
                log,
            }),
            Outcome::Interrupted => Ok((
                130,
                Some(format!(
                    "graspopt launch: interrupted, every process stopped; continue the run with graspopt launch --resume {}",
                    file.display()
                )),
            )),
        }
    }
}

impl Children {
    /// Starts `plan` in order: `exe` with each process's arguments, stderr to
    /// `<logs>/<name>.log`, stdout passed through; after the router, waits (at most 20 s)
    /// until it accepts connections. `started(name, log)` is told of each.
    pub fn start(
        plan: &[Planned],
        exe: &Path,
        logs: &Path,
        mut started: impl FnMut(&str, &Path),
    ) -> Result<Children> {
        std::fs::create_dir_all(logs).map_err(|source| RunnerError::LogFolder {
            path: logs.to_path_buf(),
            source,
        })?;
        let mut children = Children(Vec::new());
        for p in plan {
            let log = logs.join(format!("{}.log", p.name));
            let err = std::fs::File::create(&log).map_err(|source| RunnerError::Create {
                path: log.clone(),
                source,
            })?;
            let child = Command::new(exe)
                .args(&p.args)
                .stdin(Stdio::null())
                .stderr(err)
                .process_group(0)
                .spawn()
                .map_err(|source| RunnerError::Start {
                    name: p.name.clone(),
                    source,
                })?;
            started(&p.name, &log);
            children.0.push(Running {
                name: p.name.clone(),
                coordinator: p.coordinator,
                router: p.wait_addr.is_some(),
                child,
                log,
            });
            if let Some(addr) = &p.wait_addr {
                let start = Instant::now();
                while std::net::TcpStream::connect(addr.as_str()).is_err() {
                    if start.elapsed() > Duration::from_secs(20) {
                        let addr = addr.clone();
                        return Err(RunnerError::RouterSilent { addr });
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
            }
        }
        Ok(children)
    }

    /// Waits until the coordinator exits, another process stops, or `stop` completes
    /// (a shutdown signal, say), checking every 100 ms; then stops every process.
    pub async fn supervise(&mut self, stop: impl std::future::Future<Output = ()>) -> Outcome {
        let mut poll = tokio::time::interval(Duration::from_millis(100));
        tokio::pin!(stop);
        let outcome = loop {
            tokio::select! {
                biased;
                _ = &mut stop => break Outcome::Interrupted,
                _ = poll.tick() => {}
            }
            if let Some(outcome) = self.check() {
                break outcome;
            }
        };
        self.terminate();
        outcome
    }

    /// The outcome, once one process has stopped.
    fn check(&mut self) -> Option<Outcome> {
        let mut all_done = true;
        for c in self.0.iter_mut() {
            match c.child.try_wait() {
                Ok(Some(status)) if c.coordinator => {
                    return Some(Outcome::Coordinator(status.code(), Some(c.log.clone())));
                }
                Ok(Some(status)) => {
                    return Some(Outcome::Died(
                        c.name.clone(),
                        status.to_string(),
                        c.log.clone(),
                    ));
                }
                Ok(None) => all_done = false,
                Err(e) => return Some(Outcome::Died(c.name.clone(), e.to_string(), c.log.clone())),
            }
        }
        all_done.then_some(Outcome::Coordinator(Some(0), None))
    }

    /// Stops every process still running, in three waves: the coordinator, then the other
    /// agents, then the router (see the module documentation). Each wave gets SIGTERM
    /// (agents close their sessions and release shared memory), then SIGKILL for what still
    /// runs 5 s later.
    pub fn terminate(&mut self) {
        for wave in [Wave::Coordinator, Wave::Agents, Wave::Router] {
            let members: Vec<&mut Running> =
                self.0.iter_mut().filter(|c| c.wave() == wave).collect();
            stop(members);
        }
    }
}

/// When a process is stopped (see [`Children::terminate`]).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Wave {
    Coordinator,
    Agents,
    Router,
}

impl Running {
    fn wave(&self) -> Wave {
        if self.coordinator {
            Wave::Coordinator
        } else if self.router {
            Wave::Router
        } else {
            Wave::Agents
        }
    }
}

/// SIGTERM to every one of `members` still running, SIGKILL to those running 5 s later.
fn stop(mut members: Vec<&mut Running>) {
    for c in members.iter_mut() {
        if matches!(c.child.try_wait(), Ok(None))
            && let Ok(pid) = i32::try_from(c.child.id())
        {
            let _ = kill(Pid::from_raw(pid), Signal::SIGTERM);
        }
    }
    let deadline = Instant::now() + Duration::from_secs(5);
    for c in members {
        while matches!(c.child.try_wait(), Ok(None)) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        if matches!(c.child.try_wait(), Ok(None)) {
            let _ = c.child.kill();
            let _ = c.child.wait();
        }
    }
}

/// The last `lines` lines of a log file (empty if it cannot be read).
pub fn tail(path: &Path, lines: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deploy(name: &str) -> (LaunchFile, PathBuf) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../deploy")
            .join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        (LaunchFile::parse(&text, &path).unwrap(), path)
    }

    #[test]
    fn local_file_runs_everything_here_with_three_hands() {
        let (file, path) = deploy("local.toml");
        let plan = file.plan("any-host", path.parent().unwrap()).unwrap();
        let names: Vec<&str> = plan.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "router",
                "perception",
                "planner",
                "metric",
                "hand-1",
                "hand-2",
                "hand-3",
                "coordinator"
            ]
        );
        assert_eq!(plan[0].wait_addr.as_deref(), Some("127.0.0.1:7447"));
        assert_eq!(plan.iter().filter(|p| p.coordinator).count(), 1);
        for p in &plan[1..] {
            assert!(
                p.args
                    .windows(2)
                    .any(|w| w[0] == "--connect" && w[1] == file.endpoint)
            );
        }
    }

    #[test]
    fn two_machine_file_splits_the_agents_by_host() {
        let (file, path) = deploy("two-machines.toml");
        let base = path.parent().unwrap();
        let lab: Vec<String> = file
            .plan("lab-pc", base)
            .unwrap()
            .into_iter()
            .map(|p| p.name)
            .collect();
        let robot: Vec<String> = file
            .plan("robot-pc", base)
            .unwrap()
            .into_iter()
            .map(|p| p.name)
            .collect();
        assert!(lab.contains(&"router".to_string()) && lab.contains(&"coordinator".to_string()));
        assert!(
            robot
                .iter()
                .all(|n| n.starts_with("robot-hand") || n == "metric-robot")
        );
        assert!(!robot.is_empty());
        assert!(file.plan("elsewhere", base).unwrap().is_empty());
        // Every Zenoh configuration the file names exists and is read by the bus.
        for p in file
            .plan("lab-pc", base)
            .unwrap()
            .iter()
            .chain(&file.plan("robot-pc", base).unwrap())
        {
            if let Some(w) = p.args.windows(2).find(|w| w[0] == "--zenoh-config") {
                let bus = graspopt_bus::BusConfig {
                    zenoh_config: Some(PathBuf::from(&w[1])),
                    ..Default::default()
                };
                bus.zenoh_config()
                    .unwrap_or_else(|e| panic!("{}: {e}", w[1]));
            }
        }
    }

    #[test]
    fn resume_adds_one_resume_flag_to_the_coordinator_only() {
        let (file, path) = deploy("local.toml");
        let mut plan = file.plan("any-host", path.parent().unwrap()).unwrap();
        resume_coordinator(&mut plan, "any-host").unwrap();
        resume_coordinator(&mut plan, "any-host").unwrap();
        for p in &plan {
            let n = p.args.iter().filter(|a| *a == "--resume").count();
            assert_eq!(n, usize::from(p.coordinator), "{}", p.name);
        }
        let (file, path) = deploy("two-machines.toml");
        let mut robot = file.plan("robot-pc", path.parent().unwrap()).unwrap();
        let e = resume_coordinator(&mut robot, "robot-pc").unwrap_err();
        assert!(
            e.to_string()
                .contains("no coordinator runs on host \"robot-pc\""),
            "{e}"
        );
    }

    #[test]
    fn bad_launch_files_name_the_problem() {
        let origin = Path::new("x.toml");
        let err = |t: &str| crate::error::chain(&LaunchFile::parse(t, origin).unwrap_err());
        assert!(err("run = \"a b\"\nendpoint = \"tcp/h:1\"").contains("run"));
        assert!(err("run = \"r\"\nendpoint = \"h:1\"").contains("no protocol"));
        let e = err("run = \"r\"\nendpoint = \"tcp/h:1\"\n[[agent]]\nkind = \"gripper\"");
        assert!(e.contains("gripper"), "{e}");
        let e = err("run = \"r\"\nendpoint = \"tcp/h:1\"\n[[agent]]\nkind = \"hand\"\ncolour = 1");
        assert!(e.contains("colour"), "{e}");
        let two = "run = \"r\"\nendpoint = \"tcp/h:1\"\n[[agent]]\nkind = \"hand\"\nhost = \"a\"\n[[agent]]\nkind = \"hand\"\nhost = \"b\"";
        assert!(
            err(two).contains("two agents named \"hand\""),
            "{}",
            err(two)
        );
        let e =
            err("run = \"r\"\nendpoint = \"tcp/h:1\"\n[[agent]]\nkind = \"hand\"\ncount = 100000");
        assert!(
            e.contains("agent \"hand\" has count 100000, more than the 1024"),
            "{e}"
        );
        let e =
            err("run = \"r\"\nendpoint = \"tcp/h:1\"\n[[agent]]\nkind = \"hand\"\nid = \"a/b\"");
        assert!(
            e.contains("x.toml") && e.contains("invalid agent id \"a/b\""),
            "{e}"
        );
    }

    fn planned(name: &str, coordinator: bool) -> Planned {
        Planned {
            name: name.into(),
            coordinator,
            args: Vec::new(),
            wait_addr: None,
        }
    }

    /// `sh -c SCRIPT` for each entry: `exe` is the shell, the plan's arguments its script.
    fn shell_plan(entries: &[(&str, bool, &str)]) -> Vec<Planned> {
        entries
            .iter()
            .map(|(name, coordinator, script)| Planned {
                args: vec!["-c".into(), (*script).into()],
                ..planned(name, *coordinator)
            })
            .collect()
    }

    #[tokio::test]
    async fn the_coordinator_exit_ends_the_launch_and_stops_the_others() {
        let logs = tempfile::tempdir().unwrap();
        let plan = shell_plan(&[
            ("worker", false, "echo up >&2; exec sleep 30"),
            ("coordinator", true, "sleep 0.3; echo done >&2; exit 3"),
        ]);
        let mut names = Vec::new();
        let mut children = Children::start(&plan, Path::new("/bin/sh"), logs.path(), |n, _| {
            names.push(n.to_string())
        })
        .unwrap();
        assert_eq!(names, ["worker", "coordinator"]);
        let t = Instant::now();
        let outcome = children.supervise(std::future::pending()).await;
        let log = logs.path().join("coordinator.log");
        assert_eq!(outcome, Outcome::Coordinator(Some(3), Some(log.clone())));
        assert_eq!(tail(&log, 5), "done");
        // The worker was stopped by SIGTERM, not left to its 30 s.
        assert!(t.elapsed() < Duration::from_secs(10), "{:?}", t.elapsed());
        assert!(
            children
                .0
                .iter_mut()
                .all(|c| c.child.try_wait().unwrap().is_some())
        );
        assert_eq!(tail(&logs.path().join("worker.log"), 5), "up");
    }

    /// Each process is the leader of its own group (a terminal's Ctrl-C reaches launch
    /// only), and a stop goes coordinator first, then the agents, the router last: each
    /// one here notes its SIGTERM in a shared file as it gets it.
    #[test]
    fn processes_have_their_own_groups_and_stop_coordinator_first_router_last() {
        let logs = tempfile::tempdir().unwrap();
        let order = logs.path().join("order");
        let script = |name: &str| {
            format!(
                "trap 'echo {name} >> {}; exit 0' TERM; while :; do sleep 0.02; done",
                order.display()
            )
        };
        let plan = shell_plan(&[
            ("router", false, &script("router")),
            ("hand-1", false, &script("hand-1")),
            ("coordinator", true, &script("coordinator")),
        ]);
        let mut children =
            Children::start(&plan, Path::new("/bin/sh"), logs.path(), |_, _| {}).unwrap();
        // The router, without a port to wait for.
        children.0[0].router = true;
        for c in &children.0 {
            let pid = Pid::from_raw(i32::try_from(c.child.id()).unwrap());
            assert_eq!(nix::unistd::getpgid(Some(pid)).unwrap(), pid, "{}", c.name);
        }
        std::thread::sleep(Duration::from_millis(200));
        children.terminate();
        let stopped = std::fs::read_to_string(&order).unwrap();
        assert_eq!(
            stopped.lines().collect::<Vec<_>>(),
            ["coordinator", "hand-1", "router"]
        );
    }

    #[tokio::test]
    async fn another_process_stopping_first_is_named_and_a_stop_interrupts() {
        let logs = tempfile::tempdir().unwrap();
        let plan = shell_plan(&[
            ("hand-1", false, "echo broken >&2; exit 1"),
            ("coordinator", true, "exec sleep 30"),
        ]);
        let mut children =
            Children::start(&plan, Path::new("/bin/sh"), logs.path(), |_, _| {}).unwrap();
        match children.supervise(std::future::pending()).await {
            Outcome::Died(name, status, log) => {
                assert_eq!(name, "hand-1");
                assert!(status.contains('1'), "{status}");
                assert_eq!(tail(&log, 1), "broken");
            }
            other => panic!("{other:?}"),
        }
        let plan = shell_plan(&[("coordinator", true, "exec sleep 30")]);
        let mut children =
            Children::start(&plan, Path::new("/bin/sh"), logs.path(), |_, _| {}).unwrap();
        let stop = tokio::time::sleep(Duration::from_millis(200));
        assert_eq!(children.supervise(stop).await, Outcome::Interrupted);
        assert!(children.0[0].child.try_wait().unwrap().is_some());
    }
}
