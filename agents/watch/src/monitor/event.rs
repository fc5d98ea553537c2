//! The monitor's loops: the bus (liveliness, states, statuses) and the keyboard.

use std::future::Future;
use std::time::{Duration, Instant};

use crate::error::WatchError;
use graspopt_bus::{Bus, BusError};
use graspopt_protocol::keys::{STATE, STATUS, alive_key};
use graspopt_protocol::{AgentKind, RunId, Runs};
use tokio::sync::mpsc;

use super::app::{Monitor, run_lines};
use super::ui::draw;

/// How long a new session waits for the liveliness tokens already on the bus.
const SETTLE: Duration = Duration::from_millis(300);
/// How long [`once`] keeps looking for a live coordinator before it says there is none.
const ONCE_PATIENCE: Duration = Duration::from_secs(3);

/// `only` this run, or every run.
fn runs(only: Option<&RunId>) -> Runs<'_> {
    only.map_or(Runs::All, Runs::One)
}

/// The liveliness key of the coordinators of `only` (or of every run).
fn coordinators(only: Option<&RunId>) -> String {
    alive_key(runs(only), Some(AgentKind::Coordinator))
}

/// The runs whose coordinator is alive (`only`: this run, if it is).
pub async fn live_runs(bus: &Bus, only: Option<&RunId>) -> Vec<String> {
    let mut runs: Vec<String> = bus
        .alive_now(&coordinators(only))
        .await
        .unwrap_or_default()
        .into_iter()
        .map(|a| a.run.as_str().to_string())
        .collect();
    runs.sort();
    runs.dedup();
    runs
}

/// Asks each live run without a status for its coordinator's current state.
pub async fn ask_states(bus: &Bus, m: &mut Monitor) {
    for r in m.missing_states() {
        let Ok(id) = RunId::new(&r) else { continue };
        match bus.get(&STATE.key(&id), Duration::from_secs(2)).await {
            Ok(s) => m.on_status(s, Instant::now()),
            Err(e) => tracing::warn!("monitor: state of run {r:?}: {e}"),
        }
    }
}

/// The runs' state as text, once: each run's [`run_lines`] and an empty line; an error
/// when there is none and the endpoints the bus connects to were not reached
/// ([`Bus::check_linked`]).
pub async fn once(bus: &Bus, only: Option<&RunId>) -> Result<Vec<String>, BusError> {
    tokio::time::sleep(SETTLE).await;
    let mut m = Monitor::default();
    // Through a router, a coordinator's token can reach a session that just connected a
    // moment later than the settling time (seen on a loaded 2-core machine): look again for
    // a while before saying there is none.
    let deadline = Instant::now() + ONCE_PATIENCE;
    let mut alive = live_runs(bus, only).await;
    while alive.is_empty() && Instant::now() < deadline {
        tokio::time::sleep(SETTLE).await;
        alive = live_runs(bus, only).await;
    }
    m.set_alive(&alive);
    ask_states(bus, &mut m).await;
    if m.runs.is_empty() {
        // No run, and no link to the endpoints given: that is the endpoints' fault.
        bus.check_linked().await?;
        return Ok(vec![
            "no runs: no live coordinator (check --connect)".into(),
        ]);
    }
    let now = Instant::now();
    let mut out = Vec::new();
    for (name, view) in &m.runs {
        out.extend(run_lines(name, view, now));
        out.push(String::new());
    }
    Ok(out)
}

enum Key {
    Quit,
    Next,
}

/// Reads the keyboard on its own thread (crossterm's read blocks).
fn read_keys() -> mpsc::UnboundedReceiver<Key> {
    let (keys_tx, keys) = mpsc::unbounded_channel();
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
    keys
}

/// The dashboard on this terminal, until `q`, Esc or `stop`.
pub async fn dashboard(
    bus: &Bus,
    only: Option<&RunId>,
    stop: impl Future<Output = ()>,
) -> Result<(), WatchError> {
    let statuses = bus.subscribe_ring(&STATUS.key(runs(only)), 64).await?;
    let alive = bus.watch_alive(&coordinators(only)).await?;
    let mut keys = read_keys();
    let mut terminal = match ratatui::try_init() {
        Ok(t) => t,
        Err(e) => {
            // Raw mode may be on already: give the shell its terminal back.
            ratatui::restore();
            return Err(WatchError::Terminal(e));
        }
    };
    let mut m = Monitor::default();
    let mut alive_runs: Vec<String> = Vec::new();
    let mut redraw = tokio::time::interval(Duration::from_millis(250));
    let mut ask = tokio::time::interval(Duration::from_secs(2));
    tokio::pin!(stop);
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
            _ = &mut stop => break Ok(()),
        }
    };
    ratatui::restore();
    result
}
