//! `graspopt monitor`: a live dashboard of the runs on the bus.
//!
//! Runs are found from the coordinators' liveliness tokens; each run's current state is
//! asked from its coordinator (so the monitor works when started after the run began), then
//! followed through the status topic. For the focused run it shows the trials by state, the
//! workers alive with their current trial, the best grasp so far, a sparkline of the best
//! score so far and the error counters. `q` or Esc quits, Tab switches runs. `--once` prints
//! the same as text and exits (for scripts).

use std::collections::BTreeMap;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Result;
use clap::Args;
use graspopt_bus::{Bus, BusArgs};
use graspopt_protocol::keys::ROOT;
use graspopt_protocol::{RunId, RunPhase, RunStatus};
use ratatui::Frame;
use ratatui::layout::{Constraint, Layout};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Gauge, Paragraph, Sparkline};
use tokio::sync::mpsc;

use crate::out::outln;

#[derive(Args, Debug)]
pub struct MonitorArgs {
    /// Only this run (default: every run with a live coordinator).
    #[arg(long)]
    pub run: Option<String>,
    /// Print the runs' state as text once and exit.
    #[arg(long)]
    pub once: bool,
    #[command(flatten)]
    pub bus: BusArgs,
}

/// What the monitor knows of one run.
#[derive(Debug, Clone, Default)]
pub struct RunView {
    pub status: Option<RunStatus>,
    pub updated: Option<Instant>,
    /// The run's coordinator holds a liveliness token.
    pub coordinator_alive: bool,
}

/// Everything on screen.
#[derive(Debug, Default)]
pub struct Monitor {
    pub runs: BTreeMap<String, RunView>,
    pub focus: usize,
}

impl Monitor {
    pub fn focused(&self) -> Option<(&String, &RunView)> {
        self.runs
            .iter()
            .nth(self.focus.min(self.runs.len().saturating_sub(1)))
    }

    pub fn next_run(&mut self) {
        if !self.runs.is_empty() {
            self.focus = (self.focus + 1) % self.runs.len();
        }
    }

    pub fn on_status(&mut self, status: RunStatus, at: Instant) {
        let view = self
            .runs
            .entry(status.run_id.as_str().to_string())
            .or_default();
        // Statuses may arrive out of order (a query's reply and the topic): keep the newest.
        if view
            .status
            .as_ref()
            .is_none_or(|s| s.stamp_ms <= status.stamp_ms)
        {
            view.status = Some(status);
            view.updated = Some(at);
        }
    }

    pub fn set_alive(&mut self, runs: &[String]) {
        for (name, view) in self.runs.iter_mut() {
            view.coordinator_alive = runs.contains(name);
        }
        for r in runs {
            self.runs.entry(r.clone()).or_default().coordinator_alive = true;
        }
    }
}

fn phase_name(p: RunPhase) -> &'static str {
    match p {
        RunPhase::Waiting => "waiting",
        RunPhase::Running => "running",
        RunPhase::Finished => "finished",
    }
}

/// The best-so-far history scaled to 0..=100 for the sparkline.
pub fn spark_data(history: &[f64]) -> Vec<u64> {
    let finite: Vec<f64> = history.iter().copied().filter(|v| v.is_finite()).collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    history
        .iter()
        .map(|v| {
            if !v.is_finite() || hi <= lo {
                if v.is_finite() { 100 } else { 0 }
            } else {
                (1.0 + 99.0 * (v - lo) / (hi - lo)).round() as u64
            }
        })
        .collect()
}

/// The text lines of one run (used by `--once` and by the dashboard's panels).
pub fn run_lines(name: &str, view: &RunView, now: Instant) -> Vec<String> {
    let mut out = Vec::new();
    let age = view
        .updated
        .map(|t| format!("{:.1} s ago", now.duration_since(t).as_secs_f64()))
        .unwrap_or_else(|| "never".into());
    let coord = if view.coordinator_alive {
        "coordinator alive"
    } else {
        "coordinator gone"
    };
    let Some(s) = &view.status else {
        out.push(format!("run {name:?}: no status yet ({coord})"));
        return out;
    };
    out.push(format!(
        "run {name:?}  object {}  phase {}  updated {age}  ({coord})",
        s.object,
        phase_name(s.phase)
    ));
    out.push(format!(
        "trials: {} completed, {} running, {} failed, budget {}",
        s.completed, s.running, s.failed, s.budget
    ));
    if !s.waiting.is_empty() {
        out.push(format!(
            "waiting: {}",
            graspopt_coordinator::waits::describe(&s.waiting, s.stamp_ms)
        ));
    }
    match &s.best {
        Some(b) => {
            let params = super::run::named_params(&s.param_names, &b.params, ", ");
            let fc = match b.force_closure {
                Some(true) => ", force closure",
                Some(false) => ", no force closure",
                None => "",
            };
            out.push(format!(
                "best: trial {} score {:.5} at {}{fc}",
                b.trial_id, b.score, params
            ));
        }
        None => out.push("best: none yet".into()),
    }
    out.push(format!("workers alive: {}", s.workers.len()));
    for w in &s.workers {
        let t = w
            .trial
            .map(|t| format!("trial {t}"))
            .unwrap_or_else(|| "idle".into());
        out.push(format!("  {}@{}  {t}", w.id, w.host));
    }
    let e = &s.errors;
    out.push(format!(
        "errors: {} bad messages, {} unknown trials, {} not issued, {} duplicates, {} re-issued, {} failed",
        e.bad_messages, e.unknown_trial, e.not_issued, e.duplicates, e.reissued, e.failed
    ));
    out
}

/// Draws the dashboard.
pub fn draw(frame: &mut Frame, m: &Monitor, now: Instant) {
    let area = frame.area();
    let [top, gauge, middle, workers, spark, bottom] = Layout::vertical([
        Constraint::Length(3),
        Constraint::Length(3),
        Constraint::Length(5),
        Constraint::Min(4),
        Constraint::Length(6),
        Constraint::Length(3),
    ])
    .areas(area);
    let titles: Vec<Span> = m
        .runs
        .iter()
        .enumerate()
        .flat_map(|(i, (name, v))| {
            let phase = v
                .status
                .as_ref()
                .map(|s| phase_name(s.phase))
                .unwrap_or("?");
            let style = if i == m.focus.min(m.runs.len().saturating_sub(1)) {
                Style::default().add_modifier(Modifier::BOLD | Modifier::REVERSED)
            } else {
                Style::default()
            };
            [
                Span::styled(format!(" {name} ({phase}) "), style),
                Span::raw(" "),
            ]
        })
        .collect();
    let runs_line = if titles.is_empty() {
        Line::from("no runs: waiting for a coordinator (check --connect)")
    } else {
        Line::from(titles)
    };
    frame.render_widget(
        Paragraph::new(runs_line).block(
            Block::default()
                .borders(Borders::ALL)
                .title(" graspopt monitor: runs (Tab: next, q: quit) "),
        ),
        top,
    );
    let Some((name, view)) = m.focused() else {
        return;
    };
    let lines = run_lines(name, view, now);
    let (ratio, label) = match &view.status {
        Some(s) if s.budget > 0 => (
            (s.completed + s.failed) as f64 / s.budget as f64,
            format!("{}/{} trials", s.completed + s.failed, s.budget),
        ),
        _ => (0.0, "no status".into()),
    };
    frame.render_widget(
        Gauge::default()
            .block(
                Block::default()
                    .borders(Borders::ALL)
                    .title(format!(" {} ", lines.first().cloned().unwrap_or_default())),
            )
            .gauge_style(Style::default().fg(Color::Green))
            .ratio(ratio.clamp(0.0, 1.0))
            .label(label),
        gauge,
    );
    // Trials, what the run waits for (if anything) and the best trial.
    let summary: Vec<Line> = lines
        .iter()
        .skip(1)
        .take_while(|l| !l.starts_with("workers alive:"))
        .map(|l| Line::from(l.clone()))
        .collect();
    frame.render_widget(
        Paragraph::new(summary).block(Block::default().borders(Borders::ALL).title(" trials ")),
        middle,
    );
    let worker_lines: Vec<Line> = lines
        .iter()
        .skip_while(|l| !l.starts_with("workers alive:"))
        .take_while(|l| !l.starts_with("errors:"))
        .map(|l| Line::from(l.clone()))
        .collect();
    frame.render_widget(
        Paragraph::new(worker_lines)
            .block(Block::default().borders(Borders::ALL).title(" workers ")),
        workers,
    );
    let history = view
        .status
        .as_ref()
        .map(|s| s.best_history.clone())
        .unwrap_or_default();
    let data = spark_data(&history);
    let width = spark.width.saturating_sub(2) as usize;
    let shown = &data[data.len().saturating_sub(width)..];
    let title = match history.last() {
        Some(last) => format!(
            " best score so far: {last:.5} after {} trials ",
            history.len()
        ),
        None => " best score so far ".into(),
    };
    frame.render_widget(
        Sparkline::default()
            .block(Block::default().borders(Borders::ALL).title(title))
            .data(shown)
            .max(100)
            .style(Style::default().fg(Color::Yellow)),
        spark,
    );
    let errors = lines
        .iter()
        .find(|l| l.starts_with("errors:"))
        .cloned()
        .unwrap_or_default();
    frame.render_widget(
        Paragraph::new(errors).block(Block::default().borders(Borders::ALL)),
        bottom,
    );
}

/// The runs whose coordinator is alive.
async fn live_runs(bus: &Bus, only: Option<&RunId>) -> Vec<String> {
    let run = only.map(RunId::as_str).unwrap_or("*");
    let key = format!("{ROOT}/{run}/alive/coordinator/**");
    let mut runs: Vec<String> = bus
        .alive_now(&key)
        .await
        .unwrap_or_default()
        .into_iter()
        .map(|a| a.run.as_str().to_string())
        .collect();
    runs.sort();
    runs.dedup();
    runs
}

/// Asks each run's coordinator for its current state.
async fn ask_states(bus: &Bus, m: &mut Monitor) {
    let missing: Vec<String> = m
        .runs
        .iter()
        .filter(|(_, v)| v.status.is_none() && v.coordinator_alive)
        .map(|(k, _)| k.clone())
        .collect();
    for r in missing {
        let Ok(id) = RunId::new(&r) else { continue };
        match bus
            .get::<RunStatus>(&id.state_key(), Duration::from_secs(2))
            .await
        {
            Ok(s) => m.on_status(s, Instant::now()),
            Err(e) => tracing::warn!("monitor: state of run {r:?}: {e}"),
        }
    }
}

pub fn run(args: &MonitorArgs) -> Result<ExitCode> {
    let only = args.run.as_deref().map(RunId::new).transpose()?;
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(async {
        let mut bus_args = args.bus.clone();
        bus_args.no_shm = true;
        let bus = Bus::open(&bus_args).await?;
        let r = if args.once {
            once(&bus, only.as_ref()).await
        } else {
            dashboard(&bus, only.as_ref()).await
        };
        let _ = bus.close().await;
        r
    })?;
    Ok(ExitCode::SUCCESS)
}

async fn once(bus: &Bus, only: Option<&RunId>) -> Result<()> {
    // Liveliness tokens reach a new session shortly after it connects.
    tokio::time::sleep(Duration::from_millis(300)).await;
    let mut m = Monitor::default();
    m.set_alive(&live_runs(bus, only).await);
    ask_states(bus, &mut m).await;
    if m.runs.is_empty() {
        outln!("no runs: no live coordinator (check --connect)")?;
    }
    let now = Instant::now();
    for (name, view) in &m.runs {
        for l in run_lines(name, view, now) {
            outln!("{l}")?;
        }
        outln!()?;
    }
    Ok(())
}

enum Key {
    Quit,
    Next,
}

async fn dashboard(bus: &Bus, only: Option<&RunId>) -> Result<()> {
    let status_key = format!("{ROOT}/{}/status", only.map(RunId::as_str).unwrap_or("*"));
    let statuses = bus.subscribe_ring::<RunStatus>(&status_key, 64).await?;
    let alive = bus
        .watch_alive(&format!(
            "{ROOT}/{}/alive/coordinator/**",
            only.map(RunId::as_str).unwrap_or("*")
        ))
        .await?;
    // Keys are read on their own thread (crossterm's read blocks).
    let (keys_tx, mut keys) = mpsc::unbounded_channel();
    std::thread::spawn(move || {
        use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};
        while let Ok(ev) = event::read() {
            if let Event::Key(k) = ev
                && k.kind == KeyEventKind::Press
            {
                let key = match k.code {
                    KeyCode::Char('q') | KeyCode::Esc => Key::Quit,
                    // Raw mode delivers Ctrl-C as a key, not a signal.
                    KeyCode::Char('c') if k.modifiers.contains(KeyModifiers::CONTROL) => Key::Quit,
                    KeyCode::Tab | KeyCode::Right | KeyCode::Down => Key::Next,
                    _ => continue,
                };
                let quit = matches!(key, Key::Quit);
                if keys_tx.send(key).is_err() || quit {
                    break;
                }
            }
        }
    });
    let mut terminal = match ratatui::try_init() {
        Ok(t) => t,
        Err(e) => {
            // Raw mode may be on already: give the shell its terminal back.
            ratatui::restore();
            return Err(anyhow::anyhow!(
                "cannot use this terminal for the dashboard: {e} (try --once)"
            ));
        }
    };
    let mut m = Monitor::default();
    let mut alive_runs: Vec<String> = Vec::new();
    let mut redraw = tokio::time::interval(Duration::from_millis(250));
    let mut ask = tokio::time::interval(Duration::from_secs(2));
    let signal = graspopt_runner::signal::shutdown_signal();
    tokio::pin!(signal);
    let result = loop {
        tokio::select! {
            _ = redraw.tick() => {
                let now = Instant::now();
                if let Err(e) = terminal.draw(|f| draw(f, &m, now)) {
                    break Err(e.into());
                }
            }
            _ = ask.tick() => ask_states(bus, &mut m).await,
            Some(s) = statuses.recv() => if let Ok(s) = s.message {
                m.on_status(s, Instant::now());
            },
            Some(ev) = alive.recv() => {
                let run = ev.agent.run.as_str().to_string();
                if ev.alive {
                    if !alive_runs.contains(&run) { alive_runs.push(run); }
                } else {
                    alive_runs.retain(|r| *r != run);
                }
                m.set_alive(&alive_runs);
                ask_states(bus, &mut m).await;
            }
            Some(k) = keys.recv() => match k {
                Key::Quit => break Ok(()),
                Key::Next => m.next_run(),
            },
            _ = &mut signal => break Ok(()),
        }
    };
    ratatui::restore();
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_protocol::{BestTrial, ErrorCounts, WorkerStatus};
    use ratatui::Terminal;
    use ratatui::backend::TestBackend;

    /// The dashboard drawn on a 100 x 30 terminal, one line per row.
    fn screen(m: &Monitor) -> String {
        let mut term = Terminal::new(TestBackend::new(100, 30)).unwrap();
        term.draw(|f| draw(f, m, Instant::now())).unwrap();
        term.backend()
            .buffer()
            .content()
            .iter()
            .map(|c| c.symbol())
            .collect::<Vec<_>>()
            .chunks(100)
            .map(|row| row.concat() + "\n")
            .collect()
    }

    fn status(completed: u64) -> RunStatus {
        RunStatus {
            run_id: RunId::new("demo").unwrap(),
            phase: RunPhase::Running,
            object: "mug".into(),
            param_names: vec!["approach".into(), "vertical".into()],
            budget: 60,
            completed,
            running: 1,
            failed: 0,
            best: Some(BestTrial {
                trial_id: 12,
                score: 0.2123,
                params: vec![-0.031, 0.0104],
                force_closure: Some(true),
            }),
            best_history: vec![-0.5, 0.1, 0.2123],
            workers: vec![
                WorkerStatus {
                    id: "hand-1".into(),
                    host: "lab".into(),
                    trial: Some(14),
                },
                WorkerStatus {
                    id: "hand-2".into(),
                    host: "lab".into(),
                    trial: None,
                },
            ],
            errors: ErrorCounts {
                duplicates: 2,
                ..Default::default()
            },
            stamp_ms: completed as i64,
            waiting: Vec::new(),
        }
    }

    #[test]
    fn the_dashboard_shows_trials_workers_best_and_errors() {
        let mut m = Monitor::default();
        m.set_alive(&["demo".into()]);
        m.on_status(status(30), Instant::now());
        // An older status arriving late does not go back in time.
        m.on_status(status(20), Instant::now());
        let screen = screen(&m);
        for want in [
            "demo (running)",
            "30/60 trials",
            "30 completed, 1 running, 0 failed",
            "best: trial 12 score 0.21230 at approach=-0.03100, vertical=0.01040, force closure",
            "hand-1@lab  trial 14",
            "hand-2@lab  idle",
            "2 duplicates",
            "best score so far: 0.21230 after 3 trials",
        ] {
            assert!(screen.contains(want), "{want:?} not on screen:\n{screen}");
        }
    }

    #[test]
    fn the_dashboard_and_once_say_what_the_run_waits_for() {
        let mut s = status(0);
        s.best = None;
        s.stamp_ms = 20_000;
        s.waiting = vec![
            graspopt_protocol::Waiting {
                reason: graspopt_protocol::WaitReason::MetricAgent,
                since_ms: 8_000,
            },
            graspopt_protocol::Waiting {
                reason: graspopt_protocol::WaitReason::Planner,
                since_ms: 17_000,
            },
        ];
        let mut m = Monitor::default();
        m.set_alive(&["demo".into()]);
        m.on_status(s, Instant::now());
        let want = "waiting: no metric agent (12 s), no planner answer (3 s)";
        let lines = run_lines("demo", &m.runs["demo"], Instant::now());
        assert!(lines.iter().any(|l| l == want), "{lines:?}");
        let screen = screen(&m);
        for want in [want, "best: none yet", "hand-1@lab  trial 14"] {
            assert!(screen.contains(want), "{want:?} not on screen:\n{screen}");
        }
    }

    #[test]
    fn sparkline_scales_the_history() {
        assert_eq!(spark_data(&[-1.0, 0.0, 1.0]), [1, 51, 100]);
        assert_eq!(spark_data(&[0.5, 0.5]), [100, 100]);
        assert!(spark_data(&[]).is_empty());
    }

    #[test]
    fn tab_cycles_through_runs() {
        let mut m = Monitor::default();
        m.set_alive(&["a".into(), "b".into()]);
        assert_eq!(m.focused().unwrap().0, "a");
        m.next_run();
        assert_eq!(m.focused().unwrap().0, "b");
        m.next_run();
        assert_eq!(m.focused().unwrap().0, "a");
        m.set_alive(&["b".into()]);
        assert!(!m.runs["a"].coordinator_alive && m.runs["b"].coordinator_alive);
    }
}
