//! Rate and bandwidth over a sliding window of messages.

use std::collections::VecDeque;

use crate::error::WatchError;

/// Intervals a window needs before it reports a rate.
pub const MIN_INTERVALS: usize = 2;
/// The smallest window (messages): [`MIN_INTERVALS`] intervals.
pub const MIN_WINDOW: usize = MIN_INTERVALS + 1;

/// Checks the window of `topic hz` and `topic bw` (`--window`).
pub fn check_window(window: usize) -> Result<(), WatchError> {
    if window < MIN_WINDOW {
        return Err(WatchError::Window(window));
    }
    Ok(())
}

/// Arrival times and sizes of the last `capacity` messages.
#[derive(Debug, Clone)]
pub struct Window {
    capacity: usize,
    samples: VecDeque<(f64, usize)>,
}

/// What a window says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowStats {
    pub messages: usize,
    /// Messages per second: the messages after the first over the window's wall time.
    pub rate: f64,
    pub min_interval: f64,
    pub max_interval: f64,
    pub std_interval: f64,
    /// Bytes per second (the bytes after the first message over the window's wall time).
    pub bandwidth: f64,
    pub mean_size: f64,
    pub min_size: usize,
    pub max_size: usize,
}

impl Window {
    /// A window of the last `capacity` messages (at least [`MIN_WINDOW`]).
    pub fn new(capacity: usize) -> Window {
        Window {
            capacity: capacity.max(MIN_WINDOW),
            samples: VecDeque::new(),
        }
    }

    /// A message of `size` bytes arrived at `t` seconds.
    pub fn push(&mut self, t: f64, size: usize) {
        if self.samples.len() == self.capacity {
            self.samples.pop_front();
        }
        self.samples.push_back((t, size));
    }

    /// Messages in the window.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether no message arrived yet.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// What the window says at `now` (seconds, on the clock of [`Window::push`]); `None`
    /// until it holds [`MIN_INTERVALS`] intervals (so two messages that arrived together are
    /// never a rate) and some time passed since its first message.
    ///
    /// The rate and the bandwidth are taken over the window's wall time, from its first
    /// message to `now`: the messages (bytes) after the first over that time. Unlike
    /// `1 / mean interval`, a burst (several messages at once) does not make it explode, and
    /// it falls when the topic goes quiet.
    pub fn stats(&self, now: f64) -> Option<WindowStats> {
        let n = self.samples.len();
        if n < MIN_INTERVALS + 1 {
            return None;
        }
        let first = self.samples.front()?.0;
        let last = self.samples.back()?.0;
        let wall = now.max(last) - first;
        if !wall.is_finite() || wall <= 0.0 {
            return None;
        }
        let intervals: Vec<f64> = self
            .samples
            .iter()
            .zip(self.samples.iter().skip(1))
            .map(|(a, b)| b.0 - a.0)
            .collect();
        let mean = intervals.iter().sum::<f64>() / intervals.len() as f64;
        let var =
            intervals.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / intervals.len() as f64;
        let sizes = self.samples.iter().map(|s| s.1);
        let bytes_after_first: usize = self.samples.iter().skip(1).map(|s| s.1).sum();
        Some(WindowStats {
            messages: n,
            rate: intervals.len() as f64 / wall,
            min_interval: intervals.iter().copied().fold(f64::INFINITY, f64::min),
            max_interval: intervals.iter().copied().fold(0.0, f64::max),
            std_interval: var.sqrt(),
            bandwidth: bytes_after_first as f64 / wall,
            mean_size: self.samples.iter().map(|s| s.1 as f64).sum::<f64>() / n as f64,
            min_size: sizes.clone().min().unwrap_or(0),
            max_size: sizes.max().unwrap_or(0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_rate_and_spread_of_a_known_stream() {
        let mut w = Window::new(5);
        assert!(w.stats(0.0).is_none());
        // 10 Hz with alternating 0.09 / 0.11 s intervals; the window keeps the last 5.
        let mut t = 0.0;
        let mut last = 0.0;
        for i in 0..20 {
            w.push(t, 100 + i);
            last = t;
            t += if i % 2 == 0 { 0.09 } else { 0.11 };
        }
        // Asked right at the last arrival: 4 intervals over their 0.4 s.
        let s = w.stats(last).unwrap();
        assert_eq!(s.messages, 5);
        assert!((s.rate - 4.0 / 0.4).abs() < 1e-9, "{s:?}");
        assert!((s.min_interval - 0.09).abs() < 1e-12 && (s.max_interval - 0.11).abs() < 1e-12);
        assert!((s.std_interval - 0.01).abs() < 1e-12);
        // Sizes 115..119: the window's; bandwidth counts the 4 after the first.
        assert_eq!((s.min_size, s.max_size), (115, 119));
        assert!((s.mean_size - 117.0).abs() < 1e-12);
        assert!((s.bandwidth - (116 + 117 + 118 + 119) as f64 / 0.4).abs() < 1e-9);
    }

    #[test]
    fn two_messages_arriving_together_are_not_a_rate() {
        // A 2 Hz topic whose first two messages arrive 5 us apart (a burst on subscribing).
        let mut w = Window::new(100);
        w.push(0.300_000, 10);
        w.push(0.300_005, 10);
        // The old 1 / mean interval said 200000 Hz here; two messages are no rate at all.
        assert!(w.stats(1.0).is_none());
        // The stream then goes on at 2 Hz; reports come once a second.
        let mut t = 0.8;
        let mut reports = Vec::new();
        for second in 2..=10 {
            while t <= f64::from(second) {
                w.push(t, 10);
                t += 0.5;
            }
            reports.push(w.stats(f64::from(second)).unwrap().rate);
        }
        for r in &reports {
            assert!((1.5..=3.0).contains(r), "{reports:?}");
        }
        // Over nearly ten seconds the burst hardly shows.
        let last = reports[reports.len() - 1];
        assert!((last - 2.0).abs() < 0.15, "{reports:?}");
    }

    #[test]
    fn a_burst_of_messages_at_one_instant_is_not_a_rate() {
        let mut w = Window::new(10);
        for _ in 0..5 {
            w.push(2.0, 1);
        }
        assert!(w.stats(2.0).is_none());
        // A second later: 4 messages after the first over 1 s.
        let s = w.stats(3.0).unwrap();
        assert!((s.rate - 4.0).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn the_rate_falls_when_the_topic_goes_quiet() {
        let mut w = Window::new(10);
        for i in 0..5 {
            w.push(f64::from(i), 1);
        }
        let busy = w.stats(4.0).unwrap().rate;
        let quiet = w.stats(12.0).unwrap().rate;
        assert!((busy - 1.0).abs() < 1e-12 && (quiet - 4.0 / 12.0).abs() < 1e-12);
    }

    #[test]
    fn windows_below_three_messages_are_refused() {
        for bad in [0, 1, 2] {
            let e = check_window(bad).unwrap_err().to_string();
            assert!(
                e.contains("--window") && e.contains(&bad.to_string()),
                "{e}"
            );
        }
        check_window(MIN_WINDOW).unwrap();
    }
}
