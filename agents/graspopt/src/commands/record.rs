//! `graspopt record --object mug --axes x,y --steps 9,9 --out mug.jsonl`: executes a grid of
//! simulated grasps and writes their raw contact clouds as a recording (JSON lines), the
//! format `graspopt agent hand --replay` and `examples/python/hand_agent.py` answer trials
//! from, standing in for a robot's logged fingertip data.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use graspopt_convert::{TrialTag, clouds_from_outcome};
use graspopt_hand::replay::RecordedTrial;
use graspopt_protocol::RunId;

use super::scan::grid;
use super::setup::SimArgs;
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
}

pub fn run(args: &RecordArgs) -> Result<ExitCode> {
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
        let e = ev
            .evaluate(&params)
            .with_context(|| format!("grasp at {params:?}"))?;
        let clouds = clouds_from_outcome(&tag, &e.outcome, 0);
        RecordedTrial {
            params,
            hand: clouds.hand,
            palm_pose: clouds.palm_pose,
            fingers: clouds.fingers,
            min_gap: clouds.min_gap,
            score: Some(e.score.score),
        }
        .write_line(&mut out)?;
    }
    out.flush()?;
    outln!(
        "{total} grasps of the {} written to {}",
        ev.object.name(),
        args.out.display()
    )?;
    Ok(ExitCode::SUCCESS)
}
