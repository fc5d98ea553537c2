//! What the publisher capacity of a service costs: for each `max_publishers`, the time to
//! create the service (the first subscriber's `open`), to open publishers, the shared memory
//! the service's files take (`/dev/shm` and iceoryx2's directory, apparent and allocated
//! bytes), and the send latency with every publisher present.
//!
//! ```text
//! cargo run --release -p graspopt-shm --features tools --example capacity -- [publishers] [capacities...]
//! ```
//! Defaults: 64 publishers opened; capacities 16 256 1024.

use std::os::unix::fs::MetadataExt;
use std::sync::mpsc::channel;
use std::time::{Duration, Instant};

use graspopt_shm::{ShmConfig, ShmPublisher, ShmSubscriber};

/// Apparent and allocated bytes of the files whose name contains `prefix`, under `dir`.
fn usage(dir: &str, prefix: &str) -> (u64, u64) {
    let mut total = (0, 0);
    let Ok(entries) = std::fs::read_dir(dir) else {
        return total;
    };
    for e in entries.flatten() {
        let Ok(meta) = e.metadata() else { continue };
        if meta.is_dir() {
            let (a, b) = usage(&e.path().to_string_lossy(), prefix);
            total = (total.0 + a, total.1 + b);
        } else if e.file_name().to_string_lossy().contains(prefix) {
            total = (total.0 + meta.len(), total.1 + meta.blocks() * 512);
        }
    }
    total
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>());
    let publishers = args.next().transpose()?.unwrap_or(64);
    let mut capacities: Vec<usize> = args.collect::<Result<_, _>>()?;
    if capacities.is_empty() {
        capacities = vec![16, 256, 1024];
    }
    println!(
        "| max_publishers | create service + subscriber (ms) | open {publishers} publishers (ms, total) | /dev/shm apparent (MB) | /dev/shm allocated (MB) | send 480 KB median (µs) |"
    );
    println!("|---|---|---|---|---|---|");
    for cap in capacities {
        let config = ShmConfig {
            max_publishers: cap,
            ..ShmConfig::for_run(&format!("cap{cap}-{}", std::process::id()))
        };
        let service = "graspopt/bench/capacity";
        let (tx, rx) = channel::<Instant>();
        let t = Instant::now();
        let subscriber = ShmSubscriber::open(&config, service, move |_: &[u8]| {
            let _ = tx.send(Instant::now());
        })?;
        let create = t.elapsed();
        let t = Instant::now();
        let pubs = (0..publishers.min(cap))
            .map(|_| ShmPublisher::open(&config, service))
            .collect::<Result<Vec<_>, _>>()?;
        let open = t.elapsed();
        let message = vec![7u8; 480_000];
        let mut lat = Vec::new();
        for i in 0..200 {
            let p = &pubs[i % pubs.len()];
            let t = Instant::now();
            p.send(&message)?;
            let got = rx.recv_timeout(Duration::from_secs(5))?;
            lat.push(got - t);
            std::thread::sleep(Duration::from_micros(500));
        }
        lat.sort();
        let (a1, b1) = usage("/dev/shm", &config.prefix);
        let (a2, b2) = usage("/tmp/iceoryx2", &config.prefix);
        println!(
            "| {cap} | {:.1} | {:.1} | {:.1} | {:.1} | {:.0} |",
            create.as_secs_f64() * 1e3,
            open.as_secs_f64() * 1e3,
            (a1 + a2) as f64 / 1e6,
            (b1 + b2) as f64 / 1e6,
            lat[lat.len() / 2].as_secs_f64() * 1e6,
        );
        drop(pubs);
        drop(subscriber);
    }
    Ok(())
}
