//! Ways to fill a loaned shared-memory sample with 10,000 contact points (7 `f64` each, as
//! little-endian bytes) without `unsafe`, timed from the loan to the send (no subscriber):
//!
//! - `zeroed bytes`: `loan_slice` (zero-filled `[u8]`), then each value written into
//!   `payload_mut()` at its offset;
//! - `bytes from fn`: `loan_slice_uninit` + `write_from_fn`, one byte per call;
//! - `u64 from fn`: a `[u64]` service, `loan_slice_uninit` + `write_from_fn`, one value per call;
//! - `copy from Vec`: the bytes built in a `Vec` first, then `write_from_slice` (the copy the
//!   direct paths avoid; building the `Vec` included).
//!
//! ```text
//! cargo run --release -p graspopt-shm --features tools --example fill -- [points] [rounds]
//! ```

use std::time::{Duration, Instant};

use iceoryx2::prelude::*;

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e6
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>());
    let points = args.next().transpose()?.unwrap_or(10_000);
    let rounds = args.next().transpose()?.unwrap_or(300);
    let values: Vec<[f64; 7]> = (0..points)
        .map(|i| {
            let a = i as f64 * 1e-3;
            [
                a.cos() * 0.04,
                a.sin() * 0.04,
                0.01,
                -a.cos(),
                -a.sin(),
                0.0,
                1.0,
            ]
        })
        .collect();
    let bytes = points * 56;
    let mut config = Config::default();
    config.global.prefix = FileName::new(format!("fill{}_", std::process::id()).as_bytes())?;
    let node = NodeBuilder::new()
        .config(&config)
        .create::<ipc_threadsafe::Service>()?;
    let bytes_service = node
        .service_builder(&"graspopt/bench/fill/bytes".try_into()?)
        .publish_subscribe::<[u8]>()
        .open_or_create()?;
    let words_service = node
        .service_builder(&"graspopt/bench/fill/words".try_into()?)
        .publish_subscribe::<[u64]>()
        .open_or_create()?;
    let bytes_pub = bytes_service
        .publisher_builder()
        .initial_max_slice_len(bytes)
        .create()?;
    let words_pub = words_service
        .publisher_builder()
        .initial_max_slice_len(bytes / 8)
        .create()?;

    let (mut zeroed, mut from_fn, mut words, mut copy) = (vec![], vec![], vec![], vec![]);
    for _ in 0..rounds {
        let t = Instant::now();
        let mut sample = bytes_pub.loan_slice(bytes)?;
        for (chunk, v) in sample.payload_mut().chunks_exact_mut(56).zip(&values) {
            for (out, x) in chunk.chunks_exact_mut(8).zip(v) {
                out.copy_from_slice(&x.to_le_bytes());
            }
        }
        sample.send()?;
        zeroed.push(t.elapsed());

        let t = Instant::now();
        let mut it = values.iter().flatten().flat_map(|x| x.to_le_bytes());
        let sample = bytes_pub
            .loan_slice_uninit(bytes)?
            .write_from_fn(|_| it.next().unwrap_or(0));
        sample.send()?;
        from_fn.push(t.elapsed());

        let t = Instant::now();
        let mut it = values.iter().flatten().map(|x| x.to_bits().to_le());
        let sample = words_pub
            .loan_slice_uninit(bytes / 8)?
            .write_from_fn(|_| it.next().unwrap_or(0));
        sample.send()?;
        words.push(t.elapsed());

        let t = Instant::now();
        let mut buf = Vec::with_capacity(bytes);
        for x in values.iter().flatten() {
            buf.extend_from_slice(&x.to_le_bytes());
        }
        let sample = bytes_pub.loan_slice_uninit(bytes)?.write_from_slice(&buf);
        sample.send()?;
        copy.push(t.elapsed());
    }
    println!("{points} points ({bytes} bytes), {rounds} rounds, median loan + fill + send:");
    println!("| way | median (µs) |");
    println!("|---|---|");
    println!("| zeroed bytes | {:.1} |", median(zeroed));
    println!("| bytes from fn | {:.1} |", median(from_fn));
    println!("| u64 from fn | {:.1} |", median(words));
    println!("| copy from Vec | {:.1} |", median(copy));
    Ok(())
}
