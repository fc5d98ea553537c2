//! Drawing the dashboard (ratatui).

use std::time::Instant;

use ratatui::Frame;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Gauge, Paragraph, Sparkline};

use super::app::{Monitor, RunView, phase_name, run_lines, spark_data};

/// Draws the dashboard: the runs, then the focused run's progress, trials, workers, best
/// score so far and errors.
pub fn draw(frame: &mut Frame, m: &Monitor, now: Instant) {
    let [top, gauge, middle, workers, spark, bottom] = Layout::vertical([
        Constraint::Length(3),
        Constraint::Length(3),
        Constraint::Length(5),
        Constraint::Min(4),
        Constraint::Length(6),
        Constraint::Length(3),
    ])
    .areas(frame.area());
    draw_runs(frame, m, top);
    let Some((name, view)) = m.focused() else {
        return;
    };
    let lines = run_lines(name, view, now);
    draw_gauge(
        frame,
        view,
        lines.first().cloned().unwrap_or_default(),
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
    draw_spark(frame, view, spark);
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

/// The runs' names and phases, the focused one highlighted.
fn draw_runs(frame: &mut Frame, m: &Monitor, area: Rect) {
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
            let style = if i == m.focus_index() {
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
        area,
    );
}

/// The trials done out of the budget, under the run's headline.
fn draw_gauge(frame: &mut Frame, view: &RunView, headline: String, area: Rect) {
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
                    .title(format!(" {headline} ")),
            )
            .gauge_style(Style::default().fg(Color::Green))
            .ratio(ratio.clamp(0.0, 1.0))
            .label(label),
        area,
    );
}

/// The best score so far, as many trials as fit.
fn draw_spark(frame: &mut Frame, view: &RunView, area: Rect) {
    let history = view
        .status
        .as_ref()
        .map(|s| s.best_history.clone())
        .unwrap_or_default();
    let data = spark_data(&history);
    let width = area.width.saturating_sub(2) as usize;
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
        area,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::app::tests::status;
    use graspopt_protocol::{WaitReason, Waiting};
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
            "best's forces: holds the load (4.905 N): least contact forces 6.250 N in all",
            "hand-1@lab  trial 14",
            "hand-2@lab  idle",
            "2 duplicates",
            "best score so far: 0.21230 after 3 trials",
        ] {
            assert!(screen.contains(want), "{want:?} not on screen:\n{screen}");
        }
        // The whole line where there is room (`--once`, a wide terminal).
        let forces = "best's forces: holds the load (4.905 N): least contact forces 6.250 N in all (2-norm over the contacts), 3.500 N at the most loaded contact";
        let lines = run_lines("demo", &m.runs["demo"], Instant::now());
        assert!(lines.iter().any(|l| l == forces), "{lines:?}");
    }

    #[test]
    fn the_dashboard_and_once_say_what_the_run_waits_for() {
        let mut s = status(0);
        s.best = None;
        s.stamp_ms = 20_000;
        s.waiting = vec![
            Waiting {
                reason: WaitReason::MetricAgent,
                since_ms: 8_000,
            },
            Waiting {
                reason: WaitReason::Planner,
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
}
