//! Recorded contact data, and a hand that answers trials from it.
//!
//! A recording is a JSON-lines file, one executed grasp per line: the trial parameters, the
//! palm pose reached, and the raw contact clouds (the fields of a `ContactClouds` message,
//! `docs/protocol.md`), plus optionally the score it got when recorded. `graspopt record`
//! writes one from the simulator; a lab writes one from its robot's logs. The replay hand
//! answers each trial command with the recorded grasp nearest to the command's parameters,
//! so an optimization can be rerun on logged data.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use graspopt_protocol::{FingerCloud, Pose, TrialCommand};
use serde::{Deserialize, Serialize};

use crate::driver::{HandDriver, HandError, HandReading};

/// One recorded grasp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedTrial {
    /// The trial parameters (the run's parameter names, in order).
    pub params: Vec<f64>,
    pub hand: String,
    pub palm_pose: Pose,
    pub fingers: Vec<FingerCloud>,
    #[serde(default)]
    pub min_gap: Option<f64>,
    /// The score when recorded (for reference; the metric agent scores the clouds again).
    #[serde(default)]
    pub score: Option<f64>,
}

/// Why a recording cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    #[error("cannot read the recording {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("recording {path}, line {line}: {detail}")]
    Line {
        path: PathBuf,
        line: usize,
        detail: String,
    },
    #[error("recording {path} holds no grasps")]
    Empty { path: PathBuf },
}

/// A loaded recording.
#[derive(Debug, Clone)]
pub struct Recording {
    pub path: PathBuf,
    pub trials: Vec<RecordedTrial>,
}

impl Recording {
    /// Reads and checks a recording: every line a grasp, every number finite, every normal a
    /// unit vector, one parameter count throughout.
    pub fn load(path: &Path) -> Result<Recording, RecordingError> {
        let io = |source| RecordingError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        let mut trials = Vec::new();
        for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
            let line = line.map_err(io)?;
            if line.trim().is_empty() {
                continue;
            }
            let bad = |detail: String| RecordingError::Line {
                path: path.to_path_buf(),
                line: i + 1,
                detail,
            };
            let t: RecordedTrial = serde_json::from_str(&line).map_err(|e| bad(e.to_string()))?;
            if let Some(first) = trials.first().map(|f: &RecordedTrial| f.params.len())
                && first != t.params.len()
            {
                return Err(bad(format!(
                    "{} parameters, earlier lines have {first}",
                    t.params.len()
                )));
            }
            // The same checks as a ContactClouds message on the bus.
            let message = crate::serve::tag(&probe_command(&t), "check", None, Ok(t.reading()));
            graspopt_protocol::Message::validate(&message).map_err(bad)?;
            if t.params.iter().any(|v| !v.is_finite()) {
                return Err(bad("a parameter is not finite".into()));
            }
            trials.push(t);
        }
        if trials.is_empty() {
            return Err(RecordingError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(Recording {
            path: path.to_path_buf(),
            trials,
        })
    }

    /// The recorded grasp nearest to `params` (Euclidean); `None` when the parameter count
    /// differs from the recording's.
    pub fn nearest(&self, params: &[f64]) -> Option<&RecordedTrial> {
        self.trials
            .iter()
            .filter(|t| t.params.len() == params.len())
            .min_by(|a, b| dist2(&a.params, params).total_cmp(&dist2(&b.params, params)))
    }

    /// The answer to a command: the nearest recorded grasp, or why none fits.
    pub fn answer(&self, command: &TrialCommand) -> Result<HandReading, HandError> {
        match self.nearest(&command.params) {
            Some(t) if t.hand == command.hand => Ok(t.reading()),
            Some(t) => Err(HandError(format!(
                "the recording {} was made with a {} hand, the trial asks for {}",
                self.path.display(),
                t.hand,
                command.hand
            ))),
            None => Err(HandError(format!(
                "the recording {} has {} parameters per grasp, the trial has {}",
                self.path.display(),
                self.trials[0].params.len(),
                command.params.len()
            ))),
        }
    }
}

/// A hand that answers each trial with the nearest recorded grasp.
#[derive(Debug, Clone)]
pub struct ReplayHand {
    pub recording: Recording,
}

impl HandDriver for ReplayHand {
    /// Any: each recorded grasp says its hand.
    fn hand(&self) -> Option<&str> {
        None
    }

    fn execute(&mut self, command: &TrialCommand) -> Result<HandReading, HandError> {
        self.recording.answer(command)
    }
}

impl RecordedTrial {
    /// This grasp as a hand's reading.
    pub fn reading(&self) -> HandReading {
        HandReading {
            palm_pose: self.palm_pose,
            fingers: self.fingers.clone(),
            min_gap: self.min_gap,
            fingertips: Vec::new(),
        }
    }

    /// Writes this grasp as one line of a recording.
    pub fn write_line(&self, out: &mut impl Write) -> std::io::Result<()> {
        serde_json::to_writer(&mut *out, self)?;
        out.write_all(b"\n")
    }
}

fn probe_command(t: &RecordedTrial) -> TrialCommand {
    TrialCommand {
        run_id: graspopt_protocol::RunId::new("check").unwrap_or_else(|_| unreachable!()),
        trial_id: 0,
        attempt: 1,
        worker: "check".into(),
        hand: t.hand.clone(),
        params: t.params.clone(),
        palm_pose: t.palm_pose,
        lease_ms: 0,
        issued_ms: 0,
    }
}

fn dist2(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_protocol::{CloudPoint, RunId};

    fn grasp(params: Vec<f64>, score: f64) -> RecordedTrial {
        RecordedTrial {
            params,
            hand: "barrett".into(),
            palm_pose: Pose::IDENTITY,
            fingers: vec![FingerCloud {
                finger: Some(0),
                links: vec!["f0".into()],
                points: vec![CloudPoint {
                    p: [0.0, 0.0, 0.05],
                    n: [0.0, 0.0, -1.0],
                    w: 1.0,
                }],
            }],
            min_gap: None,
            score: Some(score),
        }
    }

    fn write(dir: &Path, name: &str, lines: &[String]) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, lines.join("\n")).unwrap();
        p
    }

    fn command(params: Vec<f64>) -> TrialCommand {
        TrialCommand {
            run_id: RunId::new("r").unwrap(),
            trial_id: 5,
            attempt: 2,
            worker: "replay".into(),
            hand: "barrett".into(),
            params,
            palm_pose: Pose::IDENTITY,
            lease_ms: 1000,
            issued_ms: 0,
        }
    }

    #[test]
    fn the_nearest_recorded_grasp_answers() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path().to_path_buf();
        let lines: Vec<String> = [(0.0, 0.1), (1.0, 0.2), (2.0, 0.3)]
            .iter()
            .map(|(x, s)| serde_json::to_string(&grasp(vec![*x, 0.0], *s)).unwrap())
            .collect();
        let rec = Recording::load(&write(&dir, "ok.jsonl", &lines)).unwrap();
        assert_eq!(rec.trials.len(), 3);
        assert_eq!(rec.nearest(&[1.4, 0.3]).unwrap().score, Some(0.2));
        let c = rec.answer(&command(vec![1.9, 0.0])).unwrap();
        assert_eq!(c.fingers, grasp(vec![], 0.0).fingers);
        // Wrong parameter count: a refusal, not a panic.
        let e = rec.answer(&command(vec![1.0])).unwrap_err();
        assert!(e.0.contains("2 parameters per grasp"), "{e}");

        // Bad recordings name the line and the problem.
        let mut nan = grasp(vec![0.0, 0.0], 0.0);
        nan.fingers[0].points[0].n = [0.0, 0.0, 2.0];
        let bad = vec![lines[0].clone(), serde_json::to_string(&nan).unwrap()];
        let e = Recording::load(&write(&dir, "bad.jsonl", &bad))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("unit normal"), "{e}");
        let short = vec![
            lines[0].clone(),
            serde_json::to_string(&grasp(vec![1.0], 0.0)).unwrap(),
        ];
        let e = Recording::load(&write(&dir, "short.jsonl", &short))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("1 parameters"), "{e}");
        let e = Recording::load(&write(&dir, "empty.jsonl", &[]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("no grasps"), "{e}");
        assert!(Recording::load(&dir.join("missing.jsonl")).is_err());
    }
}
