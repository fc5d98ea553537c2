//! `graspopt bench`: figures of the distributed pipeline, measured in one run so ratios are
//! fair on a noisy machine.
//!
//! - `pipeline`: trial throughput of the embedded run with 1, 2 and 4 hand workers at a
//!   simulated trial cost, and the coordinator + bus overhead per trial at zero trial cost
//!   (median cycle time of a one-worker run minus the median time of the same trial executed
//!   and scored directly).
//! - `clouds`: latency of one contact-clouds message from a hand's sender to a metric's
//!   receiver in another session on this host, over iceoryx2 shared memory and over Zenoh.

use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use graspopt_bus::{Bus, BusArgs, CloudPath, CloudReceiver, CloudSender, free_loopback_port};
use graspopt_protocol::{CloudPoint, ContactClouds, FingerCloud, Pose, RunId, RunStatus};
use tokio::sync::watch;

use super::run::{Method, RunArgs};
use super::setup::SimArgs;
use crate::out::outln;
use graspopt_runner::{Embedded, placeholder, run_embedded};

/// The most hand workers of one throughput run.
pub const MAX_WORKERS: usize = 256;
/// The most points of one contact-cloud message.
pub const MAX_POINTS: usize = 1_000_000;
/// The most messages per path, or trials per run.
pub const MAX_MESSAGES: usize = 100_000;

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Subcommand, Debug)]
pub enum What {
    /// Throughput versus workers, and overhead per trial.
    Pipeline {
        /// Simulated trial cost for the throughput runs (milliseconds, at most 60000).
        #[arg(long, default_value_t = 200)]
        trial_cost_ms: u64,
        /// Trials per worker in the throughput runs (at least 1).
        #[arg(long, default_value_t = 10)]
        trials_per_worker: u64,
        /// Worker counts, each 1 to 256.
        #[arg(long, default_value = "1,2,4", value_delimiter = ',')]
        workers: Vec<usize>,
        /// Trials of the overhead run (at least 2: a cycle is the time between two).
        #[arg(long, default_value_t = 100)]
        overhead_trials: u64,
        /// How the throughput runs propose trials.
        #[arg(long, value_enum, default_value_t = Method::Random)]
        method: Method,
    },
    /// Contact-cloud latency, shared memory versus Zenoh.
    Clouds {
        /// Points per message (at most 1000000).
        #[arg(long, default_value_t = 10_000)]
        points: usize,
        /// Messages per path (1 to 100000).
        #[arg(long, default_value_t = 300)]
        messages: usize,
    },
}

/// Checks every argument before anything runs.
fn validate(what: &What) -> Result<()> {
    match what {
        What::Pipeline {
            trial_cost_ms,
            trials_per_worker,
            workers,
            overhead_trials,
            ..
        } => {
            if workers.is_empty() {
                bail!("--workers: give at least one worker count");
            }
            if let Some(w) = workers.iter().find(|w| !(1..=MAX_WORKERS).contains(*w)) {
                bail!("--workers: each count must be between 1 and {MAX_WORKERS}, got {w}");
            }
            if *trials_per_worker < 1 {
                bail!("--trials-per-worker must be at least 1, got {trials_per_worker}");
            }
            let max_workers = workers.iter().copied().max().unwrap_or(1) as u64;
            if trials_per_worker.saturating_mul(max_workers) > MAX_MESSAGES as u64 {
                bail!(
                    "--trials-per-worker {trials_per_worker} with {max_workers} workers is more than \
                     {MAX_MESSAGES} trials in one run"
                );
            }
            if !(2..=MAX_MESSAGES as u64).contains(overhead_trials) {
                bail!(
                    "--overhead-trials must be between 2 and {MAX_MESSAGES}, got {overhead_trials}"
                );
            }
            if *trial_cost_ms > 60_000 {
                bail!("--trial-cost-ms must be at most 60000 (one minute), got {trial_cost_ms}");
            }
        }
        What::Clouds { points, messages } => {
            if *points > MAX_POINTS {
                bail!("--points must be at most {MAX_POINTS}, got {points}");
            }
            if !(1..=MAX_MESSAGES).contains(messages) {
                bail!("--messages must be between 1 and {MAX_MESSAGES}, got {messages}");
            }
        }
    }
    Ok(())
}

pub fn run(args: &BenchArgs) -> Result<ExitCode> {
    validate(&args.what)?;
    let runtime = tokio::runtime::Runtime::new()?;
    match &args.what {
        What::Pipeline {
            trial_cost_ms,
            trials_per_worker,
            workers,
            overhead_trials,
            method,
        } => runtime.block_on(pipeline(
            *trial_cost_ms,
            *trials_per_worker,
            workers,
            *overhead_trials,
            *method,
        ))?,
        What::Clouds { points, messages } => runtime.block_on(clouds(*points, *messages))?,
    }
    Ok(ExitCode::SUCCESS)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

/// The benchmark's object, hand and scoring: the cylinder, the Barrett hand, the defaults.
fn bench_sim() -> SimArgs {
    SimArgs {
        object: "cylinder".into(),
        mesh: None,
        mesh_scale: 1.0,
        hand: "barrett".into(),
        contacts: super::setup::Contacts::Surface,
        metric: "bw".into(),
        frame: super::setup::Frame::Object,
        torque_scale: None,
    }
}

fn embedded(tag: &str, workers: usize, trials: u64, cost: u64, method: Method) -> Result<Embedded> {
    let dir = std::env::temp_dir().join(format!("graspopt-bench-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let args = RunArgs {
        sim: bench_sim(),
        run: format!("bench-{tag}"),
        workers,
        trials,
        params: vec!["x".into(), "y".into()],
        method,
        initial: None,
        seed: 1,
        out: Some(dir),
        resume: false,
        trial_cost_ms: cost,
        lease_ms: 60_000,
        position_noise: 0.0,
        rotation_noise: 0.0,
        quiet: true,
        bus: BusArgs::default(),
    };
    super::run::embedded(&args)
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
    let times = follow.await.context("bench follower")?;
    Ok((status, times))
}

async fn pipeline(
    cost: u64,
    per_worker: u64,
    workers: &[usize],
    overhead_trials: u64,
    method: Method,
) -> Result<()> {
    outln!("## Throughput: simulated trial cost {cost} ms, cylinder, 2D, {method:?} proposals")?;
    outln!()?;
    outln!("| workers | trials | seconds | trials/s | speed-up | speed-up / workers |")?;
    outln!("|---|---|---|---|---|---|")?;
    let mut base: Option<f64> = None;
    for &w in workers {
        let trials = per_worker * w as u64;
        let e = embedded(&format!("tp{w}"), w, trials, cost, method)?;
        timed_run(&e).await?;
        // From the first trial's issue to the last trial's result, by the journal's clock:
        // every trial counts, start-up (agents joining) does not.
        let journal = graspopt_journal::Journal::open(&e.coordinator.journal)?;
        let rows = journal.trials(e.run.as_str())?;
        let first = rows.iter().map(|r| r.issued_ms).min().unwrap_or(0);
        let last = rows
            .iter()
            .filter_map(|r| r.completed_ms)
            .max()
            .unwrap_or(0);
        let span = (last - first).max(1) as f64 / 1e3;
        let rate = rows.len() as f64 / span;
        let b = *base.get_or_insert(rate);
        outln!(
            "| {w} | {trials} | {span:.2} | {rate:.2} | {:.2} | {:.2} |",
            rate / b,
            rate / b / w as f64
        )?;
    }
    outln!()?;
    outln!("## Overhead per trial: one worker, zero trial cost, {overhead_trials} trials")?;
    let e = embedded("overhead", 1, overhead_trials, 0, Method::Random)?;
    let (_, times) = timed_run(&e).await?;
    let mut cycles: Vec<f64> = times
        .windows(2)
        .map(|w| w[1].duration_since(w[0]).as_secs_f64() * 1e3)
        .collect();
    let cycle = median(&mut cycles);
    // The same trials executed and scored directly, in this process.
    let journal = graspopt_journal::Journal::open(&e.coordinator.journal)?;
    let rows = journal.trials(e.run.as_str())?;
    let ev = bench_sim().evaluator(&e.spec.params)?;
    let mut direct = Vec::with_capacity(rows.len());
    for r in &rows {
        let t = Instant::now();
        ev.evaluate(&r.params)?;
        direct.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let direct = median(&mut direct);
    outln!()?;
    outln!("| median cycle (ms) | median direct trial (ms) | overhead (ms) |")?;
    outln!("|---|---|---|")?;
    outln!("| {cycle:.3} | {direct:.3} | {:.3} |", cycle - direct)?;
    Ok(())
}

fn cloud_message(run: &RunId, trial: u64, points: usize) -> ContactClouds {
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

async fn cloud_latency(shm: bool, points: usize, messages: usize) -> Result<(CloudPath, Vec<f64>)> {
    let port = free_loopback_port()?;
    let prefix = format!("graspopt_bench_{}_{}_", std::process::id(), u8::from(shm));
    let mut a = BusArgs::loopback(vec![format!("tcp/127.0.0.1:{port}")], vec![]);
    a.shm_prefix = Some(prefix.clone());
    a.no_shm = !shm;
    let mut b = BusArgs::loopback(vec![], vec![format!("tcp/127.0.0.1:{port}")]);
    b.shm_prefix = Some(prefix);
    b.no_shm = !shm;
    let hand_bus = Bus::open(&a).await?;
    let metric_bus = Bus::open(&b).await?;
    let run = RunId::new("bench-clouds")?;
    let mut receiver = CloudReceiver::open(&metric_bus, &run).await?;
    let sender = CloudSender::open(&hand_bus, &run);
    tokio::time::sleep(Duration::from_millis(500)).await;
    let mut lat = Vec::with_capacity(messages);
    let mut path = CloudPath::Zenoh;
    for i in 0..messages + 10 {
        let msg = cloud_message(&run, i as u64, points);
        let t = Instant::now();
        path = sender.send(&msg).await?;
        let got = tokio::time::timeout(Duration::from_secs(5), receiver.recv())
            .await
            .context("no cloud within 5 s")?
            .context("receiver closed")?;
        let m = got.message?;
        anyhow::ensure!(
            m.trial_id == i as u64 && m.point_count() == points,
            "wrong message"
        );
        if i >= 10 {
            lat.push(t.elapsed().as_secs_f64() * 1e6);
        }
    }
    drop(receiver);
    let _ = hand_bus.close().await;
    let _ = metric_bus.close().await;
    Ok((path, lat))
}

async fn clouds(points: usize, messages: usize) -> Result<()> {
    outln!(
        "## Contact clouds, hand -> metric on one host: {points} points ({} bytes encoded), {messages} messages",
        graspopt_protocol::encode(
            &cloud_message(&RunId::new("x")?, 0, points),
            graspopt_protocol::Encoding::Bincode
        )?
        .len()
    )?;
    // What both paths share: encoding on the hand's side, decoding (with validation) on the
    // metric's.
    let msg = cloud_message(&RunId::new("bench-clouds")?, 0, points);
    let (mut enc, mut dec) = (Vec::new(), Vec::new());
    for _ in 0..messages {
        let t = Instant::now();
        let bytes = graspopt_protocol::encode(&msg, graspopt_protocol::Encoding::Bincode)?;
        enc.push(t.elapsed().as_secs_f64() * 1e6);
        let t = Instant::now();
        let back: ContactClouds =
            graspopt_protocol::decode(&bytes, graspopt_protocol::Encoding::Bincode)?;
        dec.push(t.elapsed().as_secs_f64() * 1e6);
        anyhow::ensure!(back.point_count() == points, "decode lost points");
    }
    let (enc, dec) = (median(&mut enc), median(&mut dec));
    let codec = enc + dec;
    outln!()?;
    outln!("Encoding (bincode) median {enc:.0} µs, decoding with validation median {dec:.0} µs.")?;
    outln!()?;
    outln!("| path | median (µs) | p90 (µs) | median minus encode + decode ({codec:.0} µs) |")?;
    outln!("|---|---|---|---|")?;
    for shm in [true, false] {
        let (path, mut lat) = cloud_latency(shm, points, messages).await?;
        let med = median(&mut lat);
        let p90 = lat
            .get((lat.len() * 9 / 10).min(lat.len().saturating_sub(1)))
            .copied()
            .unwrap_or(f64::NAN);
        outln!(
            "| {} | {med:.0} | {p90:.0} | {:.0} |",
            path.as_str(),
            med - codec
        )?;
    }
    Ok(())
}
