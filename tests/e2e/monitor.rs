//! `graspopt monitor` in a real (pseudo-)terminal, started after the run began: the screen,
//! as a terminal emulator renders it, shows the run, its workers and its best grasp.

use std::io::{Read, Write};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::support::{free_port, graspopt, graspopt_bin, long_run, tempdir};
use graspopt_journal::Journal;

const ROWS: u16 = 32;
const COLS: u16 = 110;

fn size(n: u16) -> std::num::NonZeroU16 {
    std::num::NonZeroU16::new(n).unwrap()
}

/// Completed trials of run `tp` so far.
fn completed(journal: &std::path::Path) -> usize {
    Journal::open(journal)
        .ok()
        .and_then(|j| j.trials("tp").ok())
        .map(|t| t.iter().filter(|t| t.score.is_some()).count())
        .unwrap_or(0)
}

#[test]
fn monitor_attaches_to_a_running_run_and_shows_it() {
    let dir = tempdir("monitor");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let out = dir.join("results");
    let _run = long_run(&dir, "tp", "cuboid", &endpoint);
    // The run is well under way before the monitor starts.
    let journal = out.join("journal.sqlite");
    let start = Instant::now();
    while completed(&journal) < 10 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the run does not progress"
        );
        std::thread::sleep(Duration::from_millis(50));
    }

    // --once: the state as text.
    let o = graspopt(&[
        "monitor",
        "--once",
        "--connect",
        &endpoint,
        "--no-multicast-scouting",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        text.contains("run \"tp\"  object cuboid  phase running"),
        "{text}"
    );
    assert!(text.contains("workers alive: 2"), "{text}");
    assert!(text.contains("best: trial "), "{text}");

    // The dashboard, in a pseudo-terminal made by script(1), read back through a terminal
    // emulator.
    let cmd = format!(
        "stty cols {COLS} rows {ROWS}; exec {} monitor --connect {endpoint} --no-multicast-scouting",
        graspopt_bin().display()
    );
    let mut child = Command::new("script")
        .args(["-qfec", &cmd, "/dev/null"])
        .env("TERM", "xterm-256color")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("script(1) from util-linux");
    let bytes = Arc::new(Mutex::new(Vec::new()));
    let reader = {
        let bytes = bytes.clone();
        let mut stdout = child.stdout.take().unwrap();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = stdout.read(&mut buf) {
                if n == 0 {
                    break;
                }
                bytes.lock().unwrap().extend_from_slice(&buf[..n]);
            }
        })
    };
    let screen = |bytes: &[u8]| {
        let mut p = vt100::Parser::new(size(ROWS), size(COLS), 0);
        p.process(bytes);
        p.screen().contents()
    };
    let start = Instant::now();
    let shown = loop {
        std::thread::sleep(Duration::from_millis(200));
        let s = screen(&bytes.lock().unwrap());
        if (s.contains("hand-2@") && s.contains("best: trial"))
            || start.elapsed() > Duration::from_secs(20)
        {
            break s;
        }
    };
    eprintln!("{shown}");
    for want in [
        "graspopt monitor",
        "tp (running)",
        "completed",
        "hand-1@",
        "hand-2@",
        "best: trial ",
        "best score so far",
        "0 bad messages",
    ] {
        assert!(shown.contains(want), "{want:?} not on screen:\n{shown}");
    }
    // The count on screen is a live one: at least what the journal had when it started.
    let n: usize = shown
        .split(" completed,")
        .next()
        .and_then(|s| s.split_whitespace().last())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no completed count on screen:\n{shown}"));
    assert!(n >= 10, "{n} completed on screen");
    // q quits, leaving the terminal restored.
    child.stdin.as_mut().unwrap().write_all(b"q").unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(10) {
            let _ = child.kill();
            panic!("monitor did not quit on q");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success());
    let _ = reader.join();
}
