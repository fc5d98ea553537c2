//! The topic loops: list the live agents' topics, echo a topic, measure its rate.

use std::future::Future;
use std::io::Write;
use std::time::{Duration, Instant};

use crate::error::WatchError;
use graspopt_bus::Bus;
use graspopt_protocol::keys::alive_key;
use graspopt_protocol::{RunId, Runs};

use super::Format;
use super::rows::{Row, topic_rows};
use super::text::{echo_sample, human_bytes};
use super::window::{MIN_WINDOW, Window};

/// How long a new session waits for the liveliness tokens already on the bus.
const SETTLE: Duration = Duration::from_millis(300);

/// What [`echo`] prints.
#[derive(Debug, Clone)]
pub struct EchoSettings {
    /// A key expression (see [`super::resolve_key`]).
    pub key: String,
    pub format: Format,
    /// Stop after this many messages.
    pub count: Option<u64>,
    /// Stop after this long.
    pub duration: Option<Duration>,
}

/// What [`rate`] measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// Messages per second and the spread of their intervals (`topic hz`).
    Rate,
    /// Bytes per second and the message sizes (`topic bw`).
    Bandwidth,
}

/// What [`rate`] watches.
#[derive(Debug, Clone)]
pub struct RateSettings {
    /// A key expression (see [`super::resolve_key`]).
    pub key: String,
    pub measure: Measure,
    /// Messages in the sliding window (see [`super::check_window`]).
    pub window: usize,
    /// Stop after this long.
    pub duration: Option<Duration>,
}

/// Checks a `--duration` in seconds.
pub fn check_duration(seconds: Option<f64>) -> Result<Option<Duration>, WatchError> {
    match seconds {
        Some(s) if !(s.is_finite() && s > 0.0) => Err(WatchError::Duration(s)),
        Some(s) => Duration::try_from_secs_f64(s)
            .map(Some)
            .map_err(|_| WatchError::DurationTooLong(s)),
        None => Ok(None),
    }
}

/// Waits `duration` (forever if `None`), then `stop` too.
async fn until(duration: Option<Duration>, stop: impl Future<Output = ()>) {
    let timer = async {
        match duration {
            Some(d) => tokio::time::sleep(d).await,
            None => std::future::pending().await,
        }
    };
    tokio::select! {
        _ = timer => {},
        _ = stop => {},
    }
}

/// The topics of the live agents of `run` (every run if `None`).
pub async fn list(bus: &Bus, run: Option<&RunId>) -> Result<Vec<Row>, WatchError> {
    let runs = run.map_or(Runs::All, Runs::One);
    tokio::time::sleep(SETTLE).await;
    let agents = bus.alive_now(&alive_key(runs, None)).await?;
    Ok(topic_rows(&agents))
}

/// Writes every message on the key to `out` until the count, the duration or `stop`; a
/// reader that goes away (an error on `out`) stops it too.
pub async fn echo(
    bus: &Bus,
    settings: &EchoSettings,
    out: &mut impl Write,
    stop: impl Future<Output = ()>,
) -> Result<(), WatchError> {
    let sub = bus.subscribe_raw(&settings.key, 64).await?;
    let end = until(settings.duration, stop);
    tokio::pin!(end);
    let mut seen = 0u64;
    while settings.count.is_none_or(|c| seen < c) {
        let sample = tokio::select! {
            s = sub.recv() => match s { Some(s) => s, None => break },
            _ = &mut end => break,
        };
        seen += 1;
        if write!(out, "{}", echo_sample(&sample, settings.format))
            .and_then(|()| out.flush())
            .is_err()
        {
            break; // the reader went away (a pipe closed)
        }
    }
    Ok(())
}

/// The line a window says at `now` seconds.
fn rate_line(w: &Window, now: f64, key: &str, measure: Measure) -> String {
    match w.stats(now) {
        None if w.is_empty() && key.ends_with("/clouds") => format!(
            "no messages yet on {key} (a hand sends its clouds to a metric agent on its own \
             machine through shared memory, which topic tools do not see; only clouds to \
             other machines come here)"
        ),
        None if w.is_empty() => format!("no messages yet on {key}"),
        None => format!(
            "{} message(s) on {key} so far; a rate needs {MIN_WINDOW}",
            w.len()
        ),
        Some(s) if measure == Measure::Bandwidth => format!(
            "bandwidth {}/s  mean {}  min {}  max {}  window {}",
            human_bytes(s.bandwidth),
            human_bytes(s.mean_size),
            human_bytes(s.min_size as f64),
            human_bytes(s.max_size as f64),
            s.messages
        ),
        Some(s) => format!(
            "average rate {:.3} Hz  min {:.4} s  max {:.4} s  std dev {:.4} s  window {}",
            s.rate, s.min_interval, s.max_interval, s.std_interval, s.messages
        ),
    }
}

/// Writes the rate (or bandwidth) of the key to `out` once a second, and once more at the
/// end (the duration or `stop`).
pub async fn rate(
    bus: &Bus,
    settings: &RateSettings,
    out: &mut impl Write,
    stop: impl Future<Output = ()>,
) -> Result<(), WatchError> {
    let sub = bus.subscribe_raw(&settings.key, 1024).await?;
    let start = Instant::now();
    let mut w = Window::new(settings.window);
    let mut report = tokio::time::interval(Duration::from_secs(1));
    report.tick().await;
    let end = until(settings.duration, stop);
    tokio::pin!(end);
    let line = |w: &Window| {
        rate_line(
            w,
            start.elapsed().as_secs_f64(),
            &settings.key,
            settings.measure,
        )
    };
    loop {
        tokio::select! {
            s = sub.recv() => match s {
                Some(s) => w.push(start.elapsed().as_secs_f64(), s.bytes.len()),
                None => break,
            },
            _ = report.tick() => if writeln!(out, "{}", line(&w)).and_then(|()| out.flush()).is_err() {
                return Ok(());
            },
            _ = &mut end => break,
        }
    }
    let _ = writeln!(out, "{}", line(&w)).and_then(|()| out.flush());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_must_be_positive_and_finite() {
        assert_eq!(check_duration(None).unwrap(), None);
        assert_eq!(
            check_duration(Some(1.5)).unwrap(),
            Some(Duration::from_millis(1500))
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = check_duration(Some(bad)).unwrap_err().to_string();
            assert!(e.contains("--duration"), "{e}");
        }
        assert!(
            check_duration(Some(1e30))
                .unwrap_err()
                .to_string()
                .contains("too long")
        );
    }

    #[test]
    fn rate_lines_say_what_the_window_holds() {
        let mut w = Window::new(10);
        let key = "graspopt/r/status";
        assert_eq!(
            rate_line(&w, 0.0, key, Measure::Rate),
            "no messages yet on graspopt/r/status"
        );
        assert!(
            rate_line(&w, 0.0, "graspopt/r/clouds", Measure::Bandwidth)
                .contains("through shared memory, which topic tools do not see")
        );
        w.push(0.0, 1500);
        assert!(rate_line(&w, 1.0, key, Measure::Rate).starts_with("1 message(s) on"));
        w.push(0.5, 2500);
        w.push(1.0, 2000);
        assert_eq!(
            rate_line(&w, 1.0, key, Measure::Rate),
            "average rate 2.000 Hz  min 0.5000 s  max 0.5000 s  std dev 0.0000 s  window 3"
        );
        assert_eq!(
            rate_line(&w, 1.0, key, Measure::Bandwidth),
            "bandwidth 4.5 KB/s  mean 2.0 KB  min 1.5 KB  max 2.5 KB  window 3"
        );
    }
}
