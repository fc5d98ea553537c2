//! `graspopt trial --object mug --hand barrett --at x=-0.08,y=0.01`: run one simulated
//! trial and print its contacts and metrics (`--format json` for everything).

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};

use super::setup::{SimArgs, param_kind, param_name};

#[derive(Args, Debug)]
pub struct TrialArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Offsets from the reference pose, e.g. `x=-0.08,y=0.01` (metres; rx, ry, rz in
    /// radians). Parameters not given are 0.
    #[arg(long, default_value = "")]
    pub at: String,
    #[arg(long, value_enum, default_value_t = TrialFormat::Text)]
    pub format: TrialFormat,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TrialFormat {
    Text,
    Json,
}

pub fn run(args: &TrialArgs) -> Result<std::process::ExitCode> {
    let mut kinds = Vec::new();
    let mut values = Vec::new();
    for part in args.at.split(',').filter(|p| !p.trim().is_empty()) {
        let (name, value) = part
            .split_once('=')
            .with_context(|| format!("--at: expected NAME=VALUE, got {part:?}"))?;
        let kind = param_kind(name)?;
        if kinds.contains(&kind) {
            bail!("--at: {} given twice", param_name(kind));
        }
        let value: f64 = value
            .trim()
            .parse()
            .with_context(|| format!("--at: {name} is not a number: {value:?}"))?;
        kinds.push(kind);
        values.push(value);
    }
    let ev = args.sim.evaluator(&kinds)?;
    let e = ev.evaluate(&values)?;
    match args.format {
        TrialFormat::Json => println!("{}", serde_json::to_string_pretty(&e)?),
        TrialFormat::Text => {
            println!(
                "object {}  hand {}  contacts {:?}  metric {}",
                ev.object.name(),
                ev.hand.name(),
                ev.score.contacts,
                args.sim.metric
            );
            for (k, v) in kinds.iter().zip(&values) {
                println!("  {} = {v}", param_name(*k));
            }
            let t = e.outcome.grasp.palm_pose.translation.vector;
            println!(
                "palm at ({:.4}, {:.4}, {:.4}) m, retreated {:.4} m",
                t.x, t.y, t.z, e.outcome.grasp.retreat
            );
            for f in e
                .outcome
                .fingers
                .iter()
                .chain(std::iter::once(&e.outcome.palm))
            {
                let name = f
                    .finger
                    .map_or("palm".to_string(), |i| format!("finger {}", i + 1));
                let modelled = f.contacts(ev.score.contacts);
                match f.mean_point {
                    Some(m) => println!(
                        "  {name}: {} cloud points, {} modelled contacts, mean at ({:.4}, {:.4}, {:.4}) normal ({:.3}, {:.3}, {:.3})",
                        f.cloud.points.len(),
                        modelled.len(),
                        m.position.x,
                        m.position.y,
                        m.position.z,
                        m.normal.x,
                        m.normal.y,
                        m.normal.z
                    ),
                    None => println!("  {name}: no contact"),
                }
            }
            match e.score.metrics {
                Some(m) => println!(
                    "rank {}  force closure {}  epsilon {:.6}  distance {:.6}  bw {:.6}{}",
                    m.rank,
                    m.force_closure,
                    m.epsilon,
                    m.distance,
                    m.bw,
                    m.volume
                        .map_or(String::new(), |v| format!("  volume {v:.6e}"))
                ),
                None => println!("no contact: nothing to score"),
            }
            println!("score {:.6}", e.score.score);
        }
    }
    Ok(std::process::ExitCode::SUCCESS)
}
