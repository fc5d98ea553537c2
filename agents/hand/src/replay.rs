//! Recorded contact data, and a hand that answers trials from it.
//!
//! A recording is a JSON-lines file, one executed grasp per line: the trial parameters, the
//! palm pose reached, and what the hand measured: the raw contact clouds (`fingers`, as in a
//! `ContactClouds` message, `docs/protocol.md`), or for a hand with fingertip force/torque
//! sensors the readings (`fingertips`, as in a `FingertipWrenches` message); plus optionally
//! the score it got when recorded and, for readings, the score of the true contacts they were
//! simulated from (`true_score`). One recording holds one kind. `graspopt record` writes one
//! from the simulator (`--sensing ft` for readings); a lab writes one from its robot's logs.
//! The replay hand answers each trial command with the recorded grasp nearest to the
//! command's parameters, as clouds or readings as recorded, so an optimization can be rerun
//! on logged data.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use graspopt_protocol::{FingerCloud, FingertipWrench, Pose, TrialCommand};
use serde::{Deserialize, Serialize};

use crate::driver::{HandDriver, HandError, HandReading, Sensing};

/// One recorded grasp.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedTrial {
    /// The trial parameters (the run's parameter names, in order).
    pub params: Vec<f64>,
    pub hand: String,
    pub palm_pose: Pose,
    /// The raw contact clouds (a hand that senses clouds); empty in a recording of fingertip
    /// readings.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fingers: Vec<FingerCloud>,
    /// The fingertip force/torque readings (a hand that senses forces), as in a
    /// `FingertipWrenches` message; absent in a recording of clouds. Present, even empty,
    /// makes this a grasp of a force-sensing hand.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fingertips: Option<Vec<FingertipWrench>>,
    #[serde(default)]
    pub min_gap: Option<f64>,
    /// The score when recorded (for reference; the metric agent scores the clouds or
    /// readings again).
    #[serde(default)]
    pub score: Option<f64>,
    /// Readings simulated from known contacts: the score of those true (noise-free) contacts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_score: Option<f64>,
}

/// Why a recording cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    /// The I/O error is in the message, so it is not a `source()` (a chain printed with
    /// `{:#}` would say it twice).
    #[error("cannot read the recording {path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
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
    /// What its grasps hold: clouds or fingertip readings (the same for all).
    pub sensing: Sensing,
}

impl Recording {
    /// Reads and checks a recording: every line a grasp, every number finite, every normal a
    /// unit vector and every fingertip surface valid (the checks of the message the grasp is
    /// sent as), one parameter count and one kind of measurement throughout.
    pub fn load(path: &Path) -> Result<Recording, RecordingError> {
        let io = |error| RecordingError::Io {
            path: path.to_path_buf(),
            error,
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
            if let Some(first) = trials.first().map(RecordedTrial::sensing)
                && first != t.sensing()
            {
                return Err(bad(format!(
                    "{}, earlier lines have {}",
                    holds(t.sensing()),
                    holds(first)
                )));
            }
            if t.fingertips.is_some() && !t.fingers.is_empty() {
                return Err(bad(
                    "both contact clouds (fingers) and fingertip readings (fingertips): \
                     a grasp holds one of them"
                        .into(),
                ));
            }
            // The same checks as the message on the bus.
            let (command, reading) = (probe_command(&t), Ok(t.reading()));
            match t.sensing() {
                Sensing::Clouds => graspopt_protocol::Message::validate(&crate::serve::tag(
                    &command, "check", None, reading,
                )),
                Sensing::Wrenches => graspopt_protocol::Message::validate(
                    &crate::serve::tag_wrenches(&command, "check", None, reading),
                ),
            }
            .map_err(|e| bad(e.to_string()))?;
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
            sensing: trials[0].sensing(),
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
            Some(t) => Err(HandError::RecordedHand {
                path: self.path.clone(),
                recorded: t.hand.clone(),
                asked: command.hand.clone(),
            }),
            None => Err(HandError::RecordedParams {
                path: self.path.clone(),
                recorded: self.trials[0].params.len(),
                asked: command.params.len(),
            }),
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

    /// What the recording holds: its readings are sent as `FingertipWrenches`, its clouds as
    /// `ContactClouds`.
    fn sensing(&self) -> Sensing {
        self.recording.sensing
    }

    fn execute(&mut self, command: &TrialCommand) -> Result<HandReading, HandError> {
        self.recording.answer(command)
    }
}

impl RecordedTrial {
    /// What this grasp holds: fingertip readings when it has `fingertips`, else clouds.
    pub fn sensing(&self) -> Sensing {
        match self.fingertips {
            Some(_) => Sensing::Wrenches,
            None => Sensing::Clouds,
        }
    }

    /// This grasp as a hand's reading.
    pub fn reading(&self) -> HandReading {
        HandReading {
            palm_pose: self.palm_pose,
            fingers: self.fingers.clone(),
            min_gap: self.min_gap,
            fingertips: self.fingertips.clone().unwrap_or_default(),
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

/// What a grasp of this kind holds, for errors.
fn holds(sensing: Sensing) -> &'static str {
    match sensing {
        Sensing::Clouds => "contact clouds (fingers)",
        Sensing::Wrenches => "fingertip readings (fingertips)",
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
            fingertips: None,
            min_gap: None,
            score: Some(score),
            true_score: None,
        }
    }

    /// A grasp of a force-sensing hand: one fingertip pressed along -z.
    fn ft_grasp(params: Vec<f64>, score: f64) -> RecordedTrial {
        RecordedTrial {
            params,
            hand: "barrett_ft".into(),
            palm_pose: Pose::IDENTITY,
            fingers: Vec::new(),
            fingertips: Some(vec![FingertipWrench {
                finger: 1,
                link: "tip1".into(),
                sensor_pose: Pose::IDENTITY,
                surface: graspopt_protocol::FingertipSurface::Sphere {
                    center: [0.0, 0.0, 0.015],
                    radius: 0.012,
                    base_z: None,
                },
                force: [0.0, 0.0, -2.0],
                torque: [0.0, 0.0, 0.0],
                stamp_ms: 7,
            }]),
            min_gap: None,
            score: Some(score),
            true_score: Some(score + 0.001),
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
        assert!(e.to_string().contains("2 parameters per grasp"), "{e}");

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

    /// A recording of fingertip readings: the replay hand senses forces and answers with the
    /// recorded readings; mixing kinds, or a bad reading, is refused by line and field.
    #[test]
    fn a_recording_of_fingertip_readings_is_answered_with_readings() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path().to_path_buf();
        let lines: Vec<String> = [(0.0, 0.1), (1.0, 0.2)]
            .iter()
            .map(|(x, s)| serde_json::to_string(&ft_grasp(vec![*x], *s)).unwrap())
            .collect();
        // The wire's field names, no clouds.
        assert!(
            lines[0].contains("\"fingertips\":[{\"finger\":1,\"link\":\"tip1\"")
                && lines[0].contains("\"shape\":\"sphere\"")
                && lines[0].contains("\"true_score\":0.101")
                && !lines[0].contains("fingers"),
            "{}",
            lines[0]
        );
        let rec = Recording::load(&write(&dir, "ft.jsonl", &lines)).unwrap();
        assert_eq!(rec.sensing, Sensing::Wrenches);
        let mut hand = ReplayHand { recording: rec };
        assert_eq!(hand.sensing(), Sensing::Wrenches);
        let mut c = command(vec![0.9]);
        c.hand = "barrett_ft".into();
        let r = hand.execute(&c).unwrap();
        assert!(r.fingers.is_empty());
        assert_eq!(Some(r.fingertips), ft_grasp(vec![], 0.0).fingertips);
        // A clouds recording stays a clouds recording.
        let clouds = vec![serde_json::to_string(&grasp(vec![0.0], 0.1)).unwrap()];
        let rec = Recording::load(&write(&dir, "clouds.jsonl", &clouds)).unwrap();
        assert_eq!(ReplayHand { recording: rec }.sensing(), Sensing::Clouds);

        let load_err = |name: &str, lines: Vec<String>| {
            Recording::load(&write(&dir, name, &lines))
                .unwrap_err()
                .to_string()
        };
        let e = load_err("mixed.jsonl", vec![lines[0].clone(), clouds[0].clone()]);
        assert!(
            e.contains("mixed.jsonl, line 2") && e.contains("earlier lines have fingertip"),
            "{e}"
        );
        let mut both = ft_grasp(vec![1.0], 0.0);
        both.fingers = grasp(vec![], 0.0).fingers;
        let e = load_err(
            "both.jsonl",
            vec![lines[0].clone(), serde_json::to_string(&both).unwrap()],
        );
        assert!(
            e.contains("line 2") && e.contains("both contact clouds"),
            "{e}"
        );
        let mut flat = ft_grasp(vec![1.0], 0.0);
        flat.fingertips.as_mut().unwrap()[0].surface =
            graspopt_protocol::FingertipSurface::Sphere {
                center: [0.0, 0.0, 0.015],
                radius: 0.0,
                base_z: None,
            };
        let e = load_err(
            "flat.jsonl",
            vec![lines[0].clone(), serde_json::to_string(&flat).unwrap()],
        );
        assert!(
            e.contains("flat.jsonl, line 2") && e.contains("fingertips[0].surface: radius"),
            "{e}"
        );
    }
}
