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
//!
//! The recording itself is `graspopt_runner::record`; this module reads the flags.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Args;
use graspopt_hand::Sensing;
use graspopt_trial::fingertips::{FingertipSettings, fingertips};

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
            .context("--force-resolution / --torque-resolution")?;
        let hand = graspopt_sim::hand_by_name(&args.sim.hand)?;
        fingertips(hand.as_ref()).context("--sensing ft")?;
    } else if args.force_resolution.is_some() || args.torque_resolution.is_some() {
        bail!("--force-resolution and --torque-resolution need --sensing ft");
    }
    graspopt_runner::record::refuse_database(&args.out).context("--out")?;
    let graspopt_trial::scan::Grid { ev, axes, .. } = grid(&args.sim, &args.axes, &args.steps)?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let file = std::fs::File::create(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut out = std::io::BufWriter::new(file);
    let total = graspopt_runner::record::record_grid(&ev, &axes, sensing, &tips, &mut out)?;
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
