//! `graspopt record --object mug --axes x,y --steps 9,9 --out mug.jsonl`: executes a grid of
//! simulated grasps and writes their raw contact clouds as a recording (JSON lines), the
//! format `graspopt agent hand --replay` and `examples/python/hand_agent.py` answer trials
//! from, standing in for a robot's logged fingertip data.
//!
//! `--sensing ft` (with `--hand barrett_ft`) records what force/torque sensors under the
//! fingertips read instead: each line holds the grasp's fingertip readings (as in a
//! `FingertipWrenches` message, with the sensor noise of `--force-resolution` and
//! `--torque-resolution`, drawn from a generator seeded with the grid point's index), the score
//! the metric agent gives those readings (`score`) and the score of the true, noise-free
//! fingertip contacts they were simulated from (`true_score`).
//! `examples/python/ft_hand_agent.py` and `agent hand --replay` answer trials from it.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Args;
use graspopt_convert::{TrialTag, clouds_from_outcome, fingertip_wrench, isometry};
use graspopt_hand::Sensing;
use graspopt_hand::replay::RecordedTrial;
use graspopt_protocol::{FingertipWrenches, RunId};
use graspopt_sim::{TrialOutcome, run_trial};
use graspopt_trial::Evaluator;
use graspopt_trial::fingertips::{
    FingertipSettings, fingertip_score, fingertips, simulate_readings,
};
use graspopt_trial::forces::ForceSettings;
use graspopt_trial::measured::{MeasuredTrial, score_measured};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

use super::scan::grid;
use super::setup::{SimArgs, sensing};
use crate::out::outln;

#[derive(Args, Debug)]
pub struct RecordArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Parameters of the grid, comma separated: x (approach), y (vertical), lateral, rx, ry, rz.
    #[arg(long, visible_alias = "params", default_value = "x,y")]
    pub axes: String,
    /// Grid points per axis, comma separated (one value applies to every axis).
    #[arg(long, default_value = "9")]
    pub steps: String,
    /// The recording to write.
    #[arg(long)]
    pub out: PathBuf,
    /// What to record: clouds (contact points and normals, the default), or ft (the readings
    /// of force/torque sensors under spherical fingertips: use --hand barrett_ft).
    #[arg(long, value_parser = sensing())]
    pub sensing: Option<Sensing>,
    /// Fingertip sensors' force resolution (N; the noise's standard deviation and quantum;
    /// default 1/320, an ATI Nano17's; 0: exact).
    #[arg(long, requires = "sensing")]
    pub force_resolution: Option<f64>,
    /// Fingertip sensors' torque resolution (N m; default 1.5625e-5, 1/64 N mm; 0: exact).
    #[arg(long, requires = "sensing")]
    pub torque_resolution: Option<f64>,
}

pub fn run(args: &RecordArgs) -> Result<ExitCode> {
    let sensing = args.sensing.unwrap_or_default();
    let mut tips = FingertipSettings::default();
    if sensing == Sensing::Ft {
        tips.noise.force_resolution = args.force_resolution.unwrap_or(tips.noise.force_resolution);
        tips.noise.torque_resolution = args
            .torque_resolution
            .unwrap_or(tips.noise.torque_resolution);
        tips.noise
            .validate()
            .context("graspopt record: fingertip sensor noise")?;
        let hand = graspopt_sim::hand_by_name(&args.sim.hand).context("graspopt record")?;
        fingertips(hand.as_ref()).context("graspopt record --sensing ft")?;
    } else if args.force_resolution.is_some() || args.torque_resolution.is_some() {
        bail!("--force-resolution and --torque-resolution need --sensing ft");
    }
    let graspopt_trial::scan::Grid { ev, axes, .. } = grid(&args.sim, &args.axes, &args.steps)?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let file = std::fs::File::create(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut out = std::io::BufWriter::new(file);
    let tag = TrialTag {
        run_id: RunId::new("record")?,
        trial_id: 0,
        attempt: 1,
        worker: "record".into(),
    };
    // Every grid point, the first axis varying slowest.
    let total: usize = axes.iter().map(Vec::len).product();
    for flat in 0..total {
        let params = graspopt_trial::scan::grid_point(&axes, flat);
        let at = || format!("grasp at {params:?}");
        let trial = match sensing {
            Sensing::Clouds => {
                let e = ev.evaluate(&params).with_context(at)?;
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
            Sensing::Ft => {
                let pose = ev.space.palm_pose(&params).with_context(at)?;
                let outcome = run_trial(&ev.object, ev.hand.as_ref(), &pose, &ev.contacts)
                    .with_context(at)?;
                let mut rng = ChaCha8Rng::seed_from_u64(flat as u64);
                fingertip_trial(&ev, &tag, params.clone(), &outcome, &tips, &mut rng)
                    .with_context(at)?
            }
        };
        trial.write_line(&mut out)?;
    }
    out.flush()?;
    let what = match sensing {
        Sensing::Clouds => "grasps",
        Sensing::Ft => "grasps' fingertip readings",
    };
    outln!(
        "{total} {what} of the {} written to {}",
        ev.object.name(),
        args.out.display()
    )?;
    Ok(ExitCode::SUCCESS)
}

/// One recorded grasp of a force-sensing hand: the readings of its touching fingertips, the
/// score the metric agent gives them (the evaluator's contact and score settings) and the
/// score of the true contacts, each scored as one-point clouds.
fn fingertip_trial(
    ev: &Evaluator,
    tag: &TrialTag,
    params: Vec<f64>,
    outcome: &TrialOutcome,
    tips: &FingertipSettings,
    rng: &mut ChaCha8Rng,
) -> Result<RecordedTrial> {
    let simulated = simulate_readings(
        outcome,
        ev.hand.as_ref(),
        &ev.object,
        &ev.score,
        &ForceSettings::default(),
        tips,
        rng,
    )?;
    // What the simulated hand sends: its palm pose and gap as in its clouds.
    let clouds = clouds_from_outcome(tag, outcome, 0);
    let readings = FingertipWrenches {
        run_id: tag.run_id.clone(),
        trial_id: tag.trial_id,
        attempt: tag.attempt,
        worker: tag.worker.clone(),
        hand: clouds.hand.clone(),
        palm_pose: clouds.palm_pose,
        fingertips: simulated
            .iter()
            .map(|t| fingertip_wrench(&t.sensor, 0))
            .collect(),
        min_gap: clouds.min_gap,
        error: None,
        executed_ms: 0,
    };
    let config = graspopt_metric::MetricConfig {
        contacts: ev.contacts,
        score: ev.score,
        ..Default::default()
    };
    let (scored, _) = graspopt_metric::score_wrenches(&readings, &ev.object, &config);
    if let Some(e) = scored.error {
        bail!("the metric agent cannot score its fingertip readings: {e}");
    }
    let truth: Vec<_> = simulated
        .iter()
        .map(|t| (t.sensor.finger, t.sensor.link.clone(), t.truth))
        .collect();
    let measured = MeasuredTrial::from_fingertips(
        &clouds.hand,
        isometry(&clouds.palm_pose),
        &truth,
        clouds.min_gap,
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
