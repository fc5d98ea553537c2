//! Figures of the distributed pipeline (`graspopt bench`), measured in one run so ratios are
//! fair on a noisy machine. Each returns its measurements; `Display` writes them as the
//! markdown tables of docs/benchmarks.md.
//!
//! - [`pipeline`]: trial throughput of the embedded run for several worker counts at a
//!   simulated trial cost, and the coordinator + bus overhead per trial at zero trial cost
//!   (median cycle time of a one-worker run minus the median time of the same trial executed
//!   and scored directly).
//! - [`clouds`]: latency of one contact-clouds message from a hand's sender to a metric's
//!   receiver in another session on this host, over iceoryx2 shared memory (the fixed layout
//!   written into the sample) and over Zenoh (bincode), in the same run.
//! - [`coordinator`]: the ceiling of one coordinator and its journal, with synthetic agents.

use std::fmt;
use std::path::Path;
use std::time::{Duration, Instant};

use graspopt_bayesopt::benchmark::median;
use graspopt_bus::{Bus, BusConfig, CloudPath, CloudReceiver, CloudSender, free_loopback_port};
use graspopt_protocol::{
    CloudPoint, ContactClouds, Encoding, FingerCloud, PlannerMethod, Pose, RunId, RunStatus,
};
use graspopt_sim::ParamKind;
use graspopt_trial::TrialSettings;
use tokio::sync::watch;

use crate::error::{Boxed, RunnerError};
use crate::{Embedded, RunSettings, placeholder, run_embedded};

type Result<T> = std::result::Result<T, BenchError>;

impl From<RunnerError> for BenchError {
    fn from(e: RunnerError) -> Self {
        BenchError::Runner(Box::new(e))
    }
}

/// Why a benchmark could not measure.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("bench follower")]
    Follower(#[source] tokio::task::JoinError),
    #[error("no cloud within 5 s")]
    NoCloud(#[source] tokio::time::error::Elapsed),
    #[error("receiver closed")]
    ReceiverClosed,
    #[error("the clouds took the {0} path, not the one measured")]
    OtherPath(&'static str),
    /// What it measured is not what it sent: which check failed.
    #[error("{0}")]
    Changed(&'static str),
    #[error(transparent)]
    Runner(Box<RunnerError>),
    #[error(transparent)]
    Bus(#[from] graspopt_bus::BusError),
    #[error(transparent)]
    Journal(#[from] graspopt_journal::JournalError),
    #[error(transparent)]
    Trial(#[from] graspopt_trial::TrialError),
    #[error(transparent)]
    Key(#[from] graspopt_protocol::keys::KeyError),
    #[error(transparent)]
    Decode(#[from] graspopt_protocol::DecodeError),
    #[error(transparent)]
    Encode(#[from] graspopt_protocol::codec::EncodeError),
    /// The shared-memory layout's error.
    #[error(transparent)]
    Layout(Boxed),
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error(transparent)]
    Coordinator(#[from] graspopt_coordinator::CoordinatorError),
    /// A check of what a benchmark run did failed: what was found.
    #[error("{0}")]
    Check(String),
    #[error("a synthetic agent panicked: {0}")]
    Panicked(#[source] tokio::task::JoinError),
}

pub mod coordinator;
pub mod functions;

/// What [`pipeline`] measures.
#[derive(Debug, Clone)]
pub struct PipelineSettings {
    /// Simulated trial cost of the throughput runs (milliseconds).
    pub trial_cost_ms: u64,
    /// Trials per worker in the throughput runs.
    pub trials_per_worker: u64,
    /// One throughput run per worker count.
    pub workers: Vec<usize>,
    /// Trials of the overhead run (a cycle is the time between two).
    pub overhead_trials: u64,
    /// How the throughput runs propose trials.
    pub method: PlannerMethod,
}

/// One throughput run.
#[derive(Debug, Clone, PartialEq)]
pub struct Throughput {
    pub workers: usize,
    pub trials: usize,
    /// From the first trial's issue to the last trial's result, by the journal's clock.
    pub seconds: f64,
}

impl Throughput {
    pub fn rate(&self) -> f64 {
        self.trials as f64 / self.seconds
    }
}

/// [`pipeline`]'s figures.
#[derive(Debug, Clone)]
pub struct PipelineReport {
    pub settings: PipelineSettings,
    pub throughput: Vec<Throughput>,
    /// Median time between two results of the one-worker, zero-cost run (milliseconds).
    pub cycle_ms: f64,
    /// Median time of the same trials executed and scored directly (milliseconds).
    pub direct_ms: f64,
}

/// The benchmark's object, hand and scoring: the cylinder, the Barrett hand, the defaults.
fn bench_trial() -> TrialSettings {
    TrialSettings {
        object: "cylinder".into(),
        ..TrialSettings::default()
    }
}

fn bench_run(
    dir: &Path,
    tag: &str,
    workers: usize,
    trials: u64,
    cost: u64,
    method: PlannerMethod,
) -> Result<Embedded> {
    let settings = RunSettings {
        run: format!("bench-{tag}"),
        trial: bench_trial(),
        workers,
        trials,
        params: vec![ParamKind::Approach, ParamKind::Vertical],
        method,
        seed: 1,
        out: Some(dir.join(tag)),
        trial_cost_ms: cost,
        lease_ms: 60_000,
        ..RunSettings::default()
    };
    Ok(settings.embedded()?)
}

/// Runs an embedded run and returns the instants at which each trial completed.
async fn timed_run(e: &Embedded) -> Result<(RunStatus, Vec<Instant>)> {
    let (tx, mut rx) = watch::channel(placeholder(e));
    let follow = tokio::spawn(async move {
        let mut seen = 0u64;
        let mut times = Vec::new();
        while rx.changed().await.is_ok() {
            let done = rx.borrow().completed;
            while seen < done {
                times.push(Instant::now());
                seen += 1;
            }
        }
        times
    });
    let status = run_embedded(e, Some(tx)).await?;
    let times = follow.await.map_err(BenchError::Follower)?;
    Ok((status, times))
}

/// Throughput per worker count and overhead per trial; the runs' folders go to a
/// temporary folder, deleted at the end.
pub async fn pipeline(settings: &PipelineSettings) -> Result<PipelineReport> {
    let dir = tempfile::Builder::new()
        .prefix("graspopt-bench-")
        .tempdir()?;
    let mut throughput = Vec::new();
    for &w in &settings.workers {
        let trials = settings.trials_per_worker * w as u64;
        let cost = settings.trial_cost_ms;
        let e = bench_run(
            dir.path(),
            &format!("tp{w}"),
            w,
            trials,
            cost,
            settings.method,
        )?;
        timed_run(&e).await?;
        // Every trial counts, start-up (agents joining) does not.
        let journal = graspopt_journal::Journal::open(&e.coordinator.journal)?;
        let rows = journal.trials(e.run.as_str())?;
        let first = rows.iter().map(|r| r.issued_ms).min().unwrap_or(0);
        let last = rows
            .iter()
            .filter_map(|r| r.completed_ms)
            .max()
            .unwrap_or(0);
        throughput.push(Throughput {
            workers: w,
            trials: rows.len(),
            seconds: (last - first).max(1) as f64 / 1e3,
        });
    }
    let e = bench_run(
        dir.path(),
        "overhead",
        1,
        settings.overhead_trials,
        0,
        PlannerMethod::Random,
    )?;
    let (_, times) = timed_run(&e).await?;
    let cycles: Vec<f64> = times
        .windows(2)
        .map(|w| w[1].duration_since(w[0]).as_secs_f64() * 1e3)
        .collect();
    // The same trials executed and scored directly, in this process.
    let journal = graspopt_journal::Journal::open(&e.coordinator.journal)?;
    let mut direct = Vec::new();
    for r in journal.trials(e.run.as_str())? {
        let t = Instant::now();
        e.evaluator.evaluate(&r.params)?;
        direct.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(PipelineReport {
        settings: settings.clone(),
        throughput,
        cycle_ms: median(&cycles).unwrap_or(f64::NAN),
        direct_ms: median(&direct).unwrap_or(f64::NAN),
    })
}

impl fmt::Display for PipelineReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.settings;
        writeln!(
            f,
            "## Throughput: simulated trial cost {} ms, cylinder, 2D, {} proposals",
            s.trial_cost_ms,
            s.method.name()
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "| workers | trials | seconds | trials/s | speed-up | speed-up / workers |"
        )?;
        writeln!(f, "|---|---|---|---|---|---|")?;
        let base = self.throughput.first().map_or(f64::NAN, Throughput::rate);
        for t in &self.throughput {
            let up = t.rate() / base;
            writeln!(
                f,
                "| {} | {} | {:.2} | {:.2} | {up:.2} | {:.2} |",
                t.workers,
                t.trials,
                t.seconds,
                t.rate(),
                up / t.workers as f64
            )?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "## Overhead per trial: one worker, zero trial cost, {} trials",
            s.overhead_trials
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "| median cycle (ms) | median direct trial (ms) | overhead (ms) |"
        )?;
        writeln!(f, "|---|---|---|")?;
        writeln!(
            f,
            "| {:.3} | {:.3} | {:.3} |",
            self.cycle_ms,
            self.direct_ms,
            self.cycle_ms - self.direct_ms
        )
    }
}

/// A contact-clouds message of `points` points over three fingers.
pub fn cloud_message(run: &RunId, trial: u64, points: usize) -> ContactClouds {
    let per = points / 3;
    let fingers = (0..3)
        .map(|f| FingerCloud {
            finger: Some(f),
            links: vec![format!("f{f}")],
            points: (0..per + usize::from((f as usize) < points % 3))
                .map(|i| {
                    let a = i as f64 * 1e-3;
                    CloudPoint {
                        p: [a.cos() * 0.04, a.sin() * 0.04, f as f64 * 0.01],
                        n: [-a.cos(), -a.sin(), 0.0],
                        w: 1.0,
                    }
                })
                .collect(),
        })
        .collect();
    ContactClouds {
        run_id: run.clone(),
        trial_id: trial,
        attempt: 1,
        worker: "bench".into(),
        hand: "barrett".into(),
        palm_pose: Pose::IDENTITY,
        fingers,
        min_gap: None,
        error: None,
        executed_ms: 0,
    }
}

/// The latency of each message (microseconds, after 10 unmeasured ones) and the path taken.
async fn cloud_latency(shm: bool, points: usize, messages: usize) -> Result<(CloudPath, Vec<f64>)> {
    let port = free_loopback_port()?;
    let prefix = format!("graspopt_bench_{}_{}_", std::process::id(), u8::from(shm));
    let mut a = BusConfig::loopback(vec![format!("tcp/127.0.0.1:{port}")], vec![]);
    a.shm_prefix = Some(prefix.clone());
    a.no_shm = !shm;
    let mut b = BusConfig::loopback(vec![], vec![format!("tcp/127.0.0.1:{port}")]);
    b.shm_prefix = Some(prefix);
    b.no_shm = !shm;
    let hand_bus = Bus::open(&a).await?;
    let metric_bus = Bus::open(&b).await?;
    let run = RunId::new("bench-clouds")?;
    let mut receiver = CloudReceiver::open(&metric_bus, &run).await?;
    let sender = CloudSender::open(&hand_bus, &run).await;
    tokio::time::sleep(Duration::from_millis(500)).await;
    let mut lat = Vec::with_capacity(messages);
    let mut path = CloudPath::Zenoh;
    for i in 0..messages + 10 {
        let msg = cloud_message(&run, i as u64, points);
        let t = Instant::now();
        path = sender.send(&msg).await?;
        let got = tokio::time::timeout(Duration::from_secs(5), receiver.recv())
            .await
            .map_err(BenchError::NoCloud)?
            .ok_or(BenchError::ReceiverClosed)?;
        let m = got.message?;
        if m.trial_id != i as u64 || m.point_count() != points {
            return Err(BenchError::Changed("wrong message"));
        }
        if i >= 10 {
            lat.push(t.elapsed().as_secs_f64() * 1e6);
        }
    }
    drop(receiver);
    let _ = hand_bus.close().await;
    let _ = metric_bus.close().await;
    Ok((path, lat))
}

/// One path's latencies (microseconds).
#[derive(Debug, Clone)]
pub struct PathLatency {
    pub path: CloudPath,
    pub median_us: f64,
    pub p90_us: f64,
}

/// [`clouds`]' figures.
#[derive(Debug, Clone)]
pub struct CloudsReport {
    pub points: usize,
    pub messages: usize,
    /// Bytes of one message encoded with bincode (the Zenoh path's payload).
    pub encoded_bytes: usize,
    /// Bytes of one message in the shared-memory layout.
    pub layout_bytes: usize,
    /// Median bincode encoding and decoding with validation times (microseconds).
    pub encode_us: f64,
    pub decode_us: f64,
    /// Median times to write the layout into a buffer and read it back with validation
    /// (microseconds).
    pub write_us: f64,
    pub read_us: f64,
    /// Shared memory first, then Zenoh.
    pub paths: Vec<PathLatency>,
}

fn time_us(f: impl FnOnce() -> Result<()>) -> Result<f64> {
    let t = Instant::now();
    f()?;
    Ok(t.elapsed().as_secs_f64() * 1e6)
}

/// Cloud latency hand -> metric over shared memory and over Zenoh, in the same run, and the
/// codecs' share: bincode on the Zenoh path, the fixed layout on the shared-memory path.
pub async fn clouds(points: usize, messages: usize) -> Result<CloudsReport> {
    use graspopt_protocol::layout;
    let msg = cloud_message(&RunId::new("bench-clouds")?, 0, points);
    // The paths first, in the state an agent's process is in: a message encoded with
    // bincode (one 560 KB buffer for 10,000 points) leaves the allocator warm, and glibc's,
    // its trim threshold raised, then hid 200-400 µs of page faults per cloud.
    let mut paths = Vec::new();
    for shm in [true, false] {
        let (path, mut lat) = cloud_latency(shm, points, messages).await?;
        if (path == CloudPath::SharedMemory) != shm {
            return Err(BenchError::OtherPath(path.as_str()));
        }
        lat.sort_by(f64::total_cmp);
        let p90 = lat
            .get((lat.len() * 9 / 10).min(lat.len().saturating_sub(1)))
            .copied()
            .unwrap_or(f64::NAN);
        paths.push(PathLatency {
            path,
            median_us: median(&lat).unwrap_or(f64::NAN),
            p90_us: p90,
        });
    }
    let encoded_bytes = graspopt_protocol::encode(&msg, Encoding::Bincode)?.len();
    let layout_bytes = layout::clouds_len(&msg).map_err(|e| BenchError::Layout(e.into()))?;
    let (mut enc, mut dec, mut write, mut read) = (vec![], vec![], vec![], vec![]);
    let mut bytes = Vec::new();
    let mut buf = vec![0u8; layout_bytes];
    for _ in 0..messages {
        enc.push(time_us(|| {
            bytes = graspopt_protocol::encode(&msg, Encoding::Bincode)?;
            Ok(())
        })?);
        dec.push(time_us(|| {
            let back: ContactClouds = graspopt_protocol::decode(&bytes, Encoding::Bincode)?;
            if back.point_count() != points {
                return Err(BenchError::Changed("decode lost points"));
            }
            Ok(())
        })?);
        write.push(time_us(|| {
            let written = layout::write_clouds(&msg, &mut buf);
            written.map_err(|e| BenchError::Layout(e.into()))
        })?);
        let mut back = None;
        read.push(time_us(|| {
            back = Some(layout::read_clouds(&buf).map_err(|e| BenchError::Layout(e.into()))?);
            Ok(())
        })?);
        if back.as_ref() != Some(&msg) {
            return Err(BenchError::Changed("the layout changed the clouds"));
        }
    }
    let m = |v: &[f64]| median(v).unwrap_or(f64::NAN);
    Ok(CloudsReport {
        points,
        messages,
        encoded_bytes,
        layout_bytes,
        encode_us: m(&enc),
        decode_us: m(&dec),
        write_us: m(&write),
        read_us: m(&read),
        paths,
    })
}

impl fmt::Display for CloudsReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "## Contact clouds, hand -> metric on one host: {} points, {} messages per path",
            self.points, self.messages
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "Zenoh carries bincode ({} bytes; encoding median {:.0} µs, decoding with validation {:.0} µs); \
             shared memory the fixed layout ({} bytes; writing median {:.0} µs, reading with validation {:.0} µs, \
             both here into and from a heap buffer).",
            self.encoded_bytes,
            self.encode_us,
            self.decode_us,
            self.layout_bytes,
            self.write_us,
            self.read_us
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "| path | median (µs) | p90 (µs) | median minus the path's codec (µs) |"
        )?;
        writeln!(f, "|---|---|---|---|")?;
        for p in &self.paths {
            let codec = match p.path {
                CloudPath::SharedMemory => self.write_us + self.read_us,
                CloudPath::Zenoh => self.encode_us + self.decode_us,
            };
            writeln!(
                f,
                "| {} | {:.0} | {:.0} | {:.0} |",
                p.path.as_str(),
                p.median_us,
                p.p90_us,
                p.median_us - codec
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clouds bench runs end to end: both paths deliver every message (each checked
    /// against what was sent), shared memory first, and the layout round-trips the message.
    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn the_clouds_bench_runs_both_paths() {
        let report = clouds(3_001, 12).await.unwrap();
        let paths: Vec<CloudPath> = report.paths.iter().map(|p| p.path).collect();
        assert_eq!(paths, [CloudPath::SharedMemory, CloudPath::Zenoh]);
        let msg = cloud_message(&RunId::new("bench-clouds").unwrap(), 0, 3_001);
        assert_eq!(msg.point_count(), 3_001);
        assert_eq!(
            report.layout_bytes,
            graspopt_protocol::layout::clouds_len(&msg).unwrap()
        );
        assert_eq!(report.layout_bytes % 8, 0);
        assert!(report.layout_bytes >= 3_001 * graspopt_protocol::layout::POINT_BYTES);
        for p in &report.paths {
            assert!(p.median_us.is_finite() && p.median_us > 0.0, "{p:?}");
        }
    }
}
