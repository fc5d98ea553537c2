//! `graspopt record --object mug --axes x,y --steps 9,9 --out mug.jsonl`: executes a grid of
//! simulated grasps and writes their raw contact clouds (or, with `--sensing ft` and
//! `--hand barrett_ft`, their fingertip force/torque readings) as a recording, which
//! `graspopt agent hand --set replay=FILE` and the Python hands answer trials from. The
//! format and the recording: [`graspopt_runner::record`]; this module reads the flags.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use graspopt_hand::Sensing;
use graspopt_runner::record;

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
    let (force, torque) = (args.force_resolution, args.torque_resolution);
    let tips = record::fingertip_settings(sensing, &args.sim.hand, force, torque)?;
    record::refuse_database(&args.out).context("--out")?;
    let graspopt_trial::scan::Grid { ev, axes, .. } = grid(&args.sim, &args.axes, &args.steps)?;
    let total = record::write_recording(&args.out, &ev, &axes, sensing, &tips)?;
    let what = match sensing {
        Sensing::Clouds => "grasps",
        Sensing::Wrenches => "grasps' fingertip readings",
    };
    outln!(
        "{total} {what} of the {} written to {}",
        ev.object.name(),
        args.out.display()
    )?;
    Ok(ExitCode::SUCCESS)
}
