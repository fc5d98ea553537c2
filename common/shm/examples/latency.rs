//! Send-to-callback latency of one shared-memory channel.
//!
//! A publisher (main thread) and a subscriber (its own thread, as always) in
//! one process; the clock is read just before `send()` and on entry to the
//! subscriber's callback. Between messages the sender waits for the callback
//! and then pauses, so the subscriber thread is asleep when each message is
//! sent: the numbers include its wake-up, as for sparse traffic.
//!
//! ```text
//! cargo run --release -p graspopt-shm --features tools --example latency -- [messages] [bytes] [gap_us]
//! ```
//! Defaults: 1000 messages of 480000 bytes (10,000 points x 48 bytes), 1000 µs gap.

use std::sync::mpsc::channel;
use std::time::{Duration, Instant};

use graspopt_shm::{ShmConfig, ShmPublisher, ShmSubscriber};

fn arg(index: usize, default: usize) -> usize {
    std::env::args()
        .nth(index)
        .map(|a| {
            a.parse()
                .unwrap_or_else(|_| panic!("argument {index}: {a:?} is not a number"))
        })
        .unwrap_or(default)
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let rank = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[rank]
}

fn report(what: &str, mut samples: Vec<Duration>) {
    samples.sort();
    let us = |d: Duration| d.as_secs_f64() * 1e6;
    println!(
        "{what:<22} median {:>8.1} µs   p90 {:>8.1} µs   p99 {:>8.1} µs   max {:>8.1} µs",
        us(percentile(&samples, 0.5)),
        us(percentile(&samples, 0.9)),
        us(percentile(&samples, 0.99)),
        us(samples[samples.len() - 1]),
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let messages = arg(1, 1000);
    let bytes = arg(2, 480_000).max(8);
    let gap = Duration::from_micros(arg(3, 1000) as u64);
    let warm_up = 50;

    let config = ShmConfig::for_run(&format!("latency-{}", std::process::id()));
    let service = "graspopt/bench/latency";

    let (tx, rx) = channel::<(u64, Instant)>();
    let _subscriber = ShmSubscriber::open(&config, service, move |payload: &[u8]| {
        let arrived = Instant::now();
        let mut seq = [0u8; 8];
        seq.copy_from_slice(&payload[..8]);
        let _ = tx.send((u64::from_le_bytes(seq), arrived));
    })?;
    let publisher = ShmPublisher::open(&config, service)?;

    let mut message: Vec<u8> = (0..bytes).map(|i| (i % 251) as u8).collect();
    let mut latency = Vec::with_capacity(messages);
    let mut send_time = Vec::with_capacity(messages);
    for seq in 0..(warm_up + messages) as u64 {
        message[..8].copy_from_slice(&seq.to_le_bytes());
        let start = Instant::now();
        publisher.send(&message)?;
        let sent = Instant::now();
        let (got, arrived) = rx.recv_timeout(Duration::from_secs(10))?;
        assert_eq!(got, seq, "messages out of order");
        if seq >= warm_up as u64 {
            latency.push(arrived - start);
            send_time.push(sent - start);
        }
        std::thread::sleep(gap);
    }

    println!(
        "{messages} messages of {bytes} bytes, {} µs apart (after {warm_up} warm-up messages)",
        gap.as_micros()
    );
    report("send() to callback", latency);
    report("send() call", send_time);
    Ok(())
}
