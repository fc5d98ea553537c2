//! `graspopt topic list|echo|hz|bw`: watch the bus from a terminal.
//!
//! - `list`: the topics of the live agents (from their liveliness tokens), with each topic's
//!   message type and publishers.
//! - `echo KEY`: every message on a topic, decoded (`--format json` for one JSON object per
//!   line; `--count N`, `--duration S` to stop).
//! - `hz KEY`: the message rate over a sliding window, with the min/max/std of the intervals.
//! - `bw KEY`: the bandwidth over a sliding window, with the mean/min/max message size.
//!
//! `KEY` is a key expression (`graspopt/mug/result`, `graspopt/*/status`) or a topic name
//! (`object`, `command`, `clouds`, `result`, `status`) completed with `--run` (default: every
//! run). Subscriptions go through ring buffers: a slow terminal loses the oldest messages and
//! never slows the agents. Clouds that travel through shared memory (hand and metric agent on
//! one host) are not on Zenoh and so are not seen here.

use std::collections::{BTreeMap, VecDeque};
use std::io::Write;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use clap::{Args, Subcommand, ValueEnum};
use graspopt_bus::{Bus, BusArgs};
use graspopt_protocol::keys::{AliveKey, ROOT};
use graspopt_protocol::{AgentKind, RunId, Topic, decode_topic};
use serde_json::{Value, json};

use crate::out::outln;

#[derive(Args, Debug)]
pub struct TopicArgs {
    #[command(subcommand)]
    pub what: TopicCommand,
    #[command(flatten)]
    pub bus: BusArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// For people.
    Text,
    /// One JSON document per line (per message for echo).
    Json,
}

/// Which messages to watch.
#[derive(Args, Debug, Clone)]
pub struct Watch {
    /// A key expression, or a topic name: object, command, clouds, result, status.
    pub key: String,
    /// The run (with a topic name; default: every run).
    #[arg(long)]
    pub run: Option<String>,
    /// Stop after this many seconds.
    #[arg(long)]
    pub duration: Option<f64>,
}

#[derive(Subcommand, Debug)]
pub enum TopicCommand {
    /// The topics of the live agents, with message type and publishers.
    List {
        /// Only this run.
        #[arg(long)]
        run: Option<String>,
        /// text (a table) or json.
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
    },
    /// Print the messages on a topic, decoded.
    Echo {
        #[command(flatten)]
        watch: Watch,
        /// text (decoded, indented) or json (one object per line).
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Stop after this many messages.
        #[arg(long)]
        count: Option<u64>,
    },
    /// Message rate of a topic.
    Hz {
        #[command(flatten)]
        watch: Watch,
        /// Messages in the sliding window (at least 3: a rate needs two intervals).
        #[arg(long, default_value_t = 100)]
        window: usize,
    },
    /// Bandwidth of a topic.
    Bw {
        #[command(flatten)]
        watch: Watch,
        /// Messages in the sliding window (at least 3: a rate needs two intervals).
        #[arg(long, default_value_t = 100)]
        window: usize,
    },
}

const TOPIC_NAMES: [(&str, &str); 5] = [
    ("object", "object"),
    ("command", "hand/*/command"),
    ("clouds", "clouds"),
    ("result", "result"),
    ("status", "status"),
];

/// The key expression a `KEY` argument means.
pub fn resolve_key(key: &str, run: Option<&str>) -> Result<String> {
    if key.contains('/') {
        if run.is_some() {
            bail!("--run goes with a topic name, not with a key expression ({key})");
        }
        return Ok(key.to_string());
    }
    let run = match run {
        Some(r) => RunId::new(r)?.as_str().to_string(),
        None => "*".to_string(),
    };
    match TOPIC_NAMES.iter().find(|(name, _)| *name == key) {
        Some((_, rest)) => Ok(format!("{ROOT}/{run}/{rest}")),
        None => bail!(
            "unknown topic {key:?}: give a key expression (graspopt/<run>/result) or one of {}",
            TOPIC_NAMES.map(|(n, _)| n).join(", ")
        ),
    }
}

/// Intervals a window needs before it reports a rate.
pub const MIN_INTERVALS: usize = 2;
/// The smallest `--window` (messages): [`MIN_INTERVALS`] intervals.
pub const MIN_WINDOW: usize = MIN_INTERVALS + 1;

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

/// Bytes for people: `812 B`, `12.4 KB`, `3.10 MB`.
pub fn human_bytes(b: f64) -> String {
    if b < 1e3 {
        format!("{b:.0} B")
    } else if b < 1e6 {
        format!("{:.1} KB", b / 1e3)
    } else {
        format!("{:.2} MB", b / 1e6)
    }
}

/// Arrays longer than this print their first items and a count.
const LONG_ARRAY: usize = 8;

/// A decoded message as indented `field: value` lines; long arrays are shortened.
pub fn render_text(value: &Value, indent: usize, out: &mut String) {
    let pad = "  ".repeat(indent);
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                match v {
                    Value::Object(m) if !m.is_empty() => {
                        out.push_str(&format!("{pad}{k}:\n"));
                        render_text(v, indent + 1, out);
                    }
                    Value::Array(a) if a.iter().any(|x| x.is_object()) => {
                        out.push_str(&format!("{pad}{k}: ({} items)\n", a.len()));
                        for (i, x) in a.iter().enumerate().take(LONG_ARRAY) {
                            out.push_str(&format!("{pad}  - [{i}]\n"));
                            render_text(x, indent + 2, out);
                        }
                        if a.len() > LONG_ARRAY {
                            out.push_str(&format!("{pad}  ... {} more\n", a.len() - LONG_ARRAY));
                        }
                    }
                    _ => out.push_str(&format!("{pad}{k}: {}\n", scalar(v))),
                }
            }
        }
        other => out.push_str(&format!("{pad}{}\n", scalar(other))),
    }
}

fn scalar(v: &Value) -> String {
    match v {
        Value::Array(a) if a.len() > LONG_ARRAY => {
            let head: Vec<String> = a.iter().take(3).map(scalar).collect();
            format!("[{}, ... ({} items)]", head.join(", "), a.len())
        }
        Value::Array(a) => {
            let items: Vec<String> = a.iter().map(scalar).collect();
            format!("[{}]", items.join(", "))
        }
        Value::String(s) => s.clone(),
        Value::Null => "-".into(),
        Value::Object(_) => v.to_string(),
        other => other.to_string(),
    }
}

/// One row of `topic list`.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub run: String,
    pub key: String,
    pub message: &'static str,
    /// `id@host` of each publisher.
    pub publishers: Vec<String>,
}

/// The topics the live agents publish (and the queries they answer), by run then key.
pub fn topic_rows(agents: &[AliveKey]) -> Vec<Row> {
    let mut by_run: BTreeMap<String, Vec<&AliveKey>> = BTreeMap::new();
    for a in agents {
        by_run
            .entry(a.run.as_str().to_string())
            .or_default()
            .push(a);
    }
    let mut rows = Vec::new();
    for (run, agents) in by_run {
        let Ok(id) = RunId::new(&run) else { continue };
        let of = |kind: AgentKind| -> Vec<String> {
            let mut v: Vec<String> = agents
                .iter()
                .filter(|a| a.kind == kind)
                .map(|a| format!("{}@{}", a.id, a.host))
                .collect();
            v.sort();
            v
        };
        let mut push = |key: String, message: &'static str, publishers: Vec<String>| {
            if !publishers.is_empty() {
                rows.push(Row {
                    run: run.clone(),
                    key,
                    message,
                    publishers,
                });
            }
        };
        for topic in Topic::ALL {
            let publishers = of(topic.publisher());
            match topic {
                Topic::Command => {
                    let mut hands: Vec<&str> = agents
                        .iter()
                        .filter(|a| a.kind == AgentKind::Hand)
                        .map(|a| a.id.as_str())
                        .collect();
                    hands.sort();
                    for h in hands {
                        push(id.command_key(h), topic.message_type(), publishers.clone());
                    }
                }
                Topic::Object => push(id.object_key(), topic.message_type(), publishers),
                Topic::Clouds => push(id.clouds_key(), topic.message_type(), publishers),
                Topic::Result => push(id.result_key(), topic.message_type(), publishers),
                Topic::Status => push(id.status_key(), topic.message_type(), publishers),
            }
        }
        push(
            id.suggest_key(),
            "query SuggestRequest -> SuggestReply",
            of(AgentKind::Planner),
        );
        push(
            id.state_key(),
            "query -> RunStatus",
            of(AgentKind::Coordinator),
        );
    }
    rows.sort_by(|a, b| (&a.run, &a.key).cmp(&(&b.run, &b.key)));
    rows
}

pub fn run(args: &TopicArgs) -> Result<ExitCode> {
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(run_async(args))
}

async fn run_async(args: &TopicArgs) -> Result<ExitCode> {
    // Bad arguments are refused before connecting to anything.
    match &args.what {
        TopicCommand::Hz { watch, window } | TopicCommand::Bw { watch, window } => {
            check_window(*window)?;
            resolve_key(&watch.key, watch.run.as_deref())?;
            deadline(watch)?;
        }
        TopicCommand::Echo { watch, .. } => {
            resolve_key(&watch.key, watch.run.as_deref())?;
            deadline(watch)?;
        }
        TopicCommand::List { .. } => {}
    }
    let mut bus_args = args.bus.clone();
    // A watcher never takes part in the shared-memory cloud path.
    bus_args.no_shm = true;
    let bus = Bus::open(&bus_args).await?;
    let result = match &args.what {
        TopicCommand::List { run, format } => list(&bus, run.as_deref(), *format).await,
        TopicCommand::Echo {
            watch,
            format,
            count,
        } => echo(&bus, watch, *format, *count).await,
        TopicCommand::Hz { watch, window } => rate(&bus, watch, *window, false).await,
        TopicCommand::Bw { watch, window } => rate(&bus, watch, *window, true).await,
    };
    let _ = bus.close().await;
    result.map(|()| ExitCode::SUCCESS)
}

async fn list(bus: &Bus, run: Option<&str>, format: Format) -> Result<()> {
    let run = match run {
        Some(r) => RunId::new(r)?.as_str().to_string(),
        None => "*".into(),
    };
    // Liveliness tokens reach a new session shortly after it connects.
    tokio::time::sleep(Duration::from_millis(300)).await;
    let agents = bus.alive_now(&format!("{ROOT}/{run}/alive/**")).await?;
    let rows = topic_rows(&agents);
    match format {
        Format::Json => {
            let v: Vec<Value> = rows
                .iter()
                .map(|r| {
                    json!({"run": r.run, "key": r.key, "type": r.message, "publishers": r.publishers})
                })
                .collect();
            outln!("{}", Value::Array(v))?;
        }
        Format::Text => {
            if rows.is_empty() {
                eprintln!("no live agents (check --connect, or the run id)");
                return Ok(());
            }
            let w = rows.iter().map(|r| r.key.len()).max().unwrap_or(0);
            let t = rows.iter().map(|r| r.message.len()).max().unwrap_or(0);
            outln!("{:w$}  {:t$}  PUBLISHERS", "TOPIC", "TYPE")?;
            for r in &rows {
                outln!(
                    "{:w$}  {:t$}  {}",
                    r.key,
                    r.message,
                    r.publishers.join(", ")
                )?;
            }
        }
    }
    Ok(())
}

fn deadline(watch: &Watch) -> Result<Option<tokio::time::Instant>> {
    match watch.duration {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            bail!("--duration must be a positive number of seconds, got {s}")
        }
        Some(s) => {
            let d = Duration::try_from_secs_f64(s)
                .map_err(|_| anyhow::anyhow!("--duration {s} is too long"))?;
            Ok(Some(tokio::time::Instant::now() + d))
        }
        None => Ok(None),
    }
}

async fn until(deadline: Option<tokio::time::Instant>) {
    match deadline {
        Some(d) => tokio::time::sleep_until(d).await,
        None => std::future::pending().await,
    }
}

async fn echo(bus: &Bus, watch: &Watch, format: Format, count: Option<u64>) -> Result<()> {
    let key = resolve_key(&watch.key, watch.run.as_deref())?;
    let end = deadline(watch)?;
    let sub = bus.subscribe_raw(&key, 64).await?;
    let mut seen = 0u64;
    let stop = until(end);
    tokio::pin!(stop);
    let signal = graspopt_runner::signal::shutdown_signal();
    tokio::pin!(signal);
    while count.is_none_or(|c| seen < c) {
        let sample = tokio::select! {
            s = sub.recv() => match s { Some(s) => s, None => break },
            _ = &mut stop => break,
            _ = &mut signal => break,
        };
        seen += 1;
        let topic = Topic::classify(&sample.key).map(|(_, t)| t);
        let decoded = match topic {
            Some(t) => decode_topic(t, &sample.bytes, sample.encoding).map_err(|e| e.to_string()),
            None => Err("not a graspopt topic".to_string()),
        };
        let type_name = topic.map_or("?", Topic::message_type);
        match format {
            Format::Json => {
                let v = match decoded {
                    Ok(m) => {
                        json!({"key": sample.key, "type": type_name, "bytes": sample.bytes.len(), "message": m})
                    }
                    Err(e) => {
                        json!({"key": sample.key, "type": type_name, "bytes": sample.bytes.len(), "error": e})
                    }
                };
                if writeln!(std::io::stdout(), "{v}").is_err() {
                    break; // the reader went away (a pipe closed)
                }
            }
            Format::Text => {
                let mut out = format!(
                    "--- {}  {type_name}  {} {}\n",
                    sample.key,
                    sample.encoding.mime(),
                    human_bytes(sample.bytes.len() as f64)
                );
                match decoded {
                    Ok(m) => render_text(&m, 1, &mut out),
                    Err(e) => out.push_str(&format!("  cannot decode: {e}\n")),
                }
                if write!(std::io::stdout(), "{out}").is_err() {
                    break;
                }
            }
        }
    }
    Ok(())
}

/// Checks `--window` of `topic hz` and `topic bw`.
pub fn check_window(window: usize) -> Result<()> {
    if window < MIN_WINDOW {
        bail!(
            "--window must be at least {MIN_WINDOW} messages (a rate needs {MIN_INTERVALS} intervals), got {window}"
        );
    }
    Ok(())
}

async fn rate(bus: &Bus, watch: &Watch, window: usize, bandwidth: bool) -> Result<()> {
    let key = resolve_key(&watch.key, watch.run.as_deref())?;
    let end = deadline(watch)?;
    let sub = bus.subscribe_raw(&key, 1024).await?;
    let start = Instant::now();
    let mut w = Window::new(window);
    let mut report = tokio::time::interval(Duration::from_secs(1));
    report.tick().await;
    let stop = until(end);
    tokio::pin!(stop);
    let signal = graspopt_runner::signal::shutdown_signal();
    tokio::pin!(signal);
    let line = |w: &Window| -> String {
        match w.stats(start.elapsed().as_secs_f64()) {
            None if w.is_empty() => format!("no messages yet on {key}"),
            None => format!(
                "{} message(s) on {key} so far; a rate needs {MIN_WINDOW}",
                w.len()
            ),
            Some(s) if bandwidth => format!(
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
    };
    loop {
        tokio::select! {
            s = sub.recv() => match s {
                Some(s) => w.push(start.elapsed().as_secs_f64(), s.bytes.len()),
                None => break,
            },
            _ = report.tick() => if writeln!(std::io::stdout(), "{}", line(&w)).is_err() {
                return Ok(());
            },
            _ = &mut stop => break,
            _ = &mut signal => break,
        }
    }
    let _ = writeln!(std::io::stdout(), "{}", line(&w));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_become_key_expressions() {
        assert_eq!(
            resolve_key("result", Some("mug")).unwrap(),
            "graspopt/mug/result"
        );
        assert_eq!(
            resolve_key("command", None).unwrap(),
            "graspopt/*/hand/*/command"
        );
        assert_eq!(resolve_key("graspopt/x/**", None).unwrap(), "graspopt/x/**");
        let e = resolve_key("results", None).unwrap_err().to_string();
        assert!(e.contains("results") && e.contains("status"), "{e}");
        assert!(resolve_key("result", Some("a/b")).is_err());
        assert!(resolve_key("graspopt/x/result", Some("x")).is_err());
    }

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

    #[test]
    fn long_arrays_are_shortened_and_nesting_indented() {
        let v = json!({"trial_id": 3, "params": [0.1, 0.2],
            "fingers": [{"finger": 0, "points": (0..100).collect::<Vec<_>>()}], "error": null});
        let mut out = String::new();
        render_text(&v, 0, &mut out);
        assert!(out.contains("trial_id: 3\n"), "{out}");
        assert!(out.contains("params: [0.1, 0.2]\n"), "{out}");
        assert!(out.contains("fingers: (1 items)\n"), "{out}");
        assert!(
            out.contains("    points: [0, 1, 2, ... (100 items)]\n"),
            "{out}"
        );
        assert!(out.contains("error: -\n"), "{out}");
    }

    #[test]
    fn list_rows_follow_the_live_agents() {
        let run = RunId::new("r").unwrap();
        let a = |kind, id: &str| AliveKey {
            run: run.clone(),
            kind,
            host: "h".into(),
            id: id.into(),
            encoding: graspopt_protocol::Encoding::Bincode,
        };
        let rows = topic_rows(&[
            a(AgentKind::Metric, "metric"),
            a(AgentKind::Hand, "hand-2"),
            a(AgentKind::Hand, "hand-1"),
            a(AgentKind::Coordinator, "coordinator"),
        ]);
        let keys: Vec<&str> = rows.iter().map(|r| r.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "graspopt/r/clouds",
                "graspopt/r/coordinator/state",
                "graspopt/r/hand/hand-1/command",
                "graspopt/r/hand/hand-2/command",
                "graspopt/r/result",
                "graspopt/r/status"
            ]
        );
        let clouds = &rows[0];
        assert_eq!(clouds.message, "ContactClouds");
        assert_eq!(clouds.publishers, ["hand-1@h", "hand-2@h"]);
    }
}
