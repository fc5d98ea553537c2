//! Recordings for the replay hand (`graspopt record`): a grid of simulated grasps written as
//! JSON lines ([`RecordedTrial`]), the format `graspopt agent hand --set replay=FILE` and the
//! Python hands answer trials from, standing in for a robot's logged data.
//!
//! With [`Sensing::Clouds`] each line holds the grasp's raw contact clouds and its score.
//! With [`Sensing::Wrenches`] it holds what force/torque sensors under the fingertips read
//! ([`fingertip_trial`]): the readings (as in a `FingertipWrenches` message, with the sensor
//! noise of the [`FingertipSettings`], drawn from a generator seeded with the grid point's
//! index), the score the metric agent gives them (`score`) and the score of the true,
//! noise-free fingertip contacts they were simulated from (`true_score`).

use std::io::Write;

use crate::error::RunnerError;

type Result<T> = std::result::Result<T, RunnerError>;
use graspopt_convert::{TrialTag, clouds_from_outcome, fingertip_wrench, isometry};
use graspopt_hand::Sensing;
use graspopt_hand::replay::RecordedTrial;
use graspopt_protocol::{FingertipWrenches, RunId};
use graspopt_sim::{TrialOutcome, run_trial};
use graspopt_trial::Evaluator;
use graspopt_trial::fingertips::{
    FingertipSettings, fingertip_score, fingertips, simulate_wrenches,
};
use graspopt_trial::forces::ForceSettings;
use graspopt_trial::measured::{MeasuredTrial, score_measured};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

/// Refuses `out` as a recording's file if it holds an SQLite database (a run's journal,
/// say): writing the recording would replace it.
pub fn refuse_database(out: &std::path::Path) -> Result<()> {
    if graspopt_journal::output::holds_database(out) {
        return Err(RunnerError::Database {
            path: out.to_path_buf(),
        });
    }
    Ok(())
}

/// The fingertip sensors of a recording of `sensing` by `hand`: the default noise, or the
/// resolutions given, which only [`Sensing::Wrenches`] takes.
pub fn fingertip_settings(
    sensing: Sensing,
    hand: &str,
    force_resolution: Option<f64>,
    torque_resolution: Option<f64>,
) -> Result<FingertipSettings> {
    let mut tips = FingertipSettings::default();
    if sensing != Sensing::Wrenches {
        if force_resolution.is_some() || torque_resolution.is_some() {
            return Err(RunnerError::NeedsFt);
        }
        return Ok(tips);
    }
    let noise = &mut tips.noise;
    noise.force_resolution = force_resolution.unwrap_or(noise.force_resolution);
    noise.torque_resolution = torque_resolution.unwrap_or(noise.torque_resolution);
    noise.validate().map_err(|e| RunnerError::Flags {
        flags: "--force-resolution / --torque-resolution",
        source: e.into(),
    })?;
    let hand = graspopt_sim::hand_by_name(hand)?;
    fingertips(hand.as_ref()).map_err(|e| RunnerError::Flags {
        flags: "--sensing ft",
        source: e.into(),
    })?;
    Ok(tips)
}

/// Records the grid `axes` (see [`record_grid`]) to the file `out`, its folder created;
/// returns how many grasps.
pub fn write_recording(
    out: &std::path::Path,
    ev: &Evaluator,
    axes: &[Vec<f64>],
    sensing: Sensing,
    tips: &FingertipSettings,
) -> Result<usize> {
    let create = |path: &std::path::Path| {
        let path = path.to_path_buf();
        move |source| RunnerError::Create { path, source }
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(create(dir))?;
    }
    let file = std::fs::File::create(out).map_err(create(out))?;
    record_grid(ev, axes, sensing, tips, &mut std::io::BufWriter::new(file))
}

/// The tag of every recorded grasp (a recording belongs to no run).
fn tag() -> Result<TrialTag> {
    Ok(TrialTag {
        run_id: RunId::new("record")?,
        trial_id: 0,
        attempt: 1,
        worker: "record".into(),
    })
}

/// Records every point of the grid `axes` (the first axis varying slowest) to `out`, one
/// line per grasp; returns how many. `tips` matters only for [`Sensing::Wrenches`].
pub fn record_grid(
    ev: &Evaluator,
    axes: &[Vec<f64>],
    sensing: Sensing,
    tips: &FingertipSettings,
    out: &mut impl Write,
) -> Result<usize> {
    let tag = tag()?;
    let total: usize = axes.iter().map(Vec::len).product();
    for flat in 0..total {
        let params = graspopt_trial::scan::grid_point(axes, flat);
        let at = |e: RunnerError| RunnerError::Grasp {
            params: params.clone(),
            source: Box::new(e),
        };
        let trial = match sensing {
            Sensing::Clouds => {
                let e = ev.evaluate(&params).map_err(|e| at(e.into()))?;
                let clouds = clouds_from_outcome(&tag, &e.outcome, 0);
                RecordedTrial {
                    params,
                    hand: clouds.hand,
                    palm_pose: clouds.palm_pose,
                    fingers: clouds.fingers,
                    fingertips: None,
                    min_gap: clouds.min_gap,
                    score: Some(e.score.score),
                    true_score: None,
                }
            }
            Sensing::Wrenches => {
                let mut rng = ChaCha8Rng::seed_from_u64(flat as u64);
                fingertip_trial(ev, params.clone(), tips, &mut rng).map_err(at)?
            }
        };
        trial.write_line(out)?;
    }
    out.flush()?;
    Ok(total)
}

/// One recorded grasp of a force-sensing hand at `params`: the readings of its touching
/// fingertips (noise drawn from `rng`), the score the metric agent gives them (the
/// evaluator's contact and score settings) and the score of the true contacts, each scored
/// as one-point clouds.
pub fn fingertip_trial(
    ev: &Evaluator,
    params: Vec<f64>,
    tips: &FingertipSettings,
    rng: &mut ChaCha8Rng,
) -> Result<RecordedTrial> {
    let pose = ev.space.palm_pose(&params)?;
    let outcome = run_trial(&ev.object, ev.hand.as_ref(), &pose, &ev.contacts)?;
    let tag = tag()?;
    let simulated = simulate_wrenches(
        &outcome,
        ev.hand.as_ref(),
        &ev.object,
        &ev.score,
        &ForceSettings::default(),
        tips,
        rng,
    )?;
    let readings = readings(&tag, &outcome, &simulated);
    let config = graspopt_metric::MetricConfig {
        contacts: ev.contacts,
        score: ev.score,
        ..Default::default()
    };
    let (scored, _) = graspopt_metric::score_wrenches(&readings, &ev.object, &config);
    if let Some(e) = scored.error {
        return Err(RunnerError::FingertipScore(e));
    }
    let truth: Vec<_> = simulated
        .iter()
        .map(|t| (t.sensor.finger, t.sensor.link.clone(), t.truth))
        .collect();
    let measured = MeasuredTrial::from_fingertips(
        &readings.hand,
        isometry(&readings.palm_pose),
        &truth,
        readings.min_gap,
    );
    // Scored as the metric agent scores readings: each contact one point.
    let (true_score, _) = score_measured(
        &measured,
        &ev.object,
        &ev.contacts,
        &fingertip_score(&ev.score),
    )?;
    Ok(RecordedTrial {
        params,
        hand: readings.hand,
        palm_pose: readings.palm_pose,
        fingers: Vec::new(),
        fingertips: Some(readings.fingertips),
        min_gap: readings.min_gap,
        score: Some(scored.score),
        true_score: Some(true_score.score),
    })
}

/// What the simulated hand sends for `outcome`: its fingertips' readings, with its palm pose
/// and gap as in its clouds.
fn readings(
    tag: &TrialTag,
    outcome: &TrialOutcome,
    simulated: &[graspopt_trial::fingertips::SimulatedFingertip],
) -> FingertipWrenches {
    let clouds = clouds_from_outcome(tag, outcome, 0);
    FingertipWrenches {
        run_id: tag.run_id.clone(),
        trial_id: tag.trial_id,
        attempt: tag.attempt,
        worker: tag.worker.clone(),
        hand: clouds.hand,
        palm_pose: clouds.palm_pose,
        fingertips: simulated
            .iter()
            .map(|t| fingertip_wrench(&t.sensor, 0))
            .collect(),
        min_gap: clouds.min_gap,
        error: None,
        executed_ms: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recording_does_not_replace_a_journal() {
        let dir = tempfile::tempdir().unwrap();
        let journal = dir.path().join("journal.sqlite");
        drop(graspopt_journal::Journal::open(&journal).unwrap());
        let e = refuse_database(&journal).unwrap_err().to_string();
        assert!(e.contains("journal.sqlite is an SQLite database"), "{e}");
        let text = dir.path().join("old.jsonl");
        std::fs::write(&text, "{}\n").unwrap();
        assert!(refuse_database(&text).is_ok());
        assert!(refuse_database(&dir.path().join("new.jsonl")).is_ok());
    }
}
