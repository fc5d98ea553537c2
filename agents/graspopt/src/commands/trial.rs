//! `graspopt trial --object mug --hand barrett --at x=-0.08,y=0.01`: run one simulated
//! trial and print its contacts, metrics and force analysis (`--format json` for everything).

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use graspopt_convert::force_analysis;
use graspopt_protocol::ForceAnalysis;
use graspopt_quality::forces::Resisting;
use graspopt_report::trial as trial_report;
use graspopt_trial::forces::{ForceSettings, analyse_outcome};
use graspopt_trial::{Evaluation, NamedPoint};
use serde::Serialize;

use super::setup::SimArgs;
use crate::out::outln;

#[derive(Args, Debug)]
pub struct TrialArgs {
    #[command(flatten)]
    pub sim: SimArgs,
    /// Offsets from the reference pose, e.g. `x=-0.08,y=0.01` (metres; rx, ry, rz in
    /// radians). Parameters not given are 0.
    #[arg(long, default_value = "")]
    pub at: String,
    /// text (for reading) or json (everything, one object).
    #[arg(long, value_enum, default_value_t = TrialFormat::Text)]
    pub format: TrialFormat,
    /// Write the scene (object, hand links, contact points and normals) for any 3D viewer:
    /// glTF 2.0 if FILE ends in `.gltf`, a Wavefront OBJ (with its colours in an MTL next to
    /// it) if it ends in `.obj`; other extensions are refused.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Draw the grasp from two viewpoints (along the approach axis, from the side) into a PNG
    /// (FILE must end in `.png`).
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// The object's mass for the force analysis (kg): the grasp must hold its weight.
    #[arg(long, default_value_t = ForceSettings::default().object_mass)]
    pub object_mass: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TrialFormat {
    Text,
    Json,
}

/// `--format json`: the parameters, the score with what it was computed from (contacts,
/// fingers in contact, metrics) at the top level, the force analysis (as in results) and the
/// simulated outcome.
#[derive(Serialize)]
struct TrialJson<'a> {
    params: &'a [f64],
    #[serde(flatten)]
    score: &'a graspopt_trial::TrialScore,
    forces: &'a ForceAnalysis,
    outcome: &'a graspopt_sim::TrialOutcome,
}

impl<'a> TrialJson<'a> {
    fn of(e: &'a Evaluation, forces: &'a ForceAnalysis) -> Self {
        TrialJson {
            params: &e.params,
            score: &e.score,
            forces,
            outcome: &e.outcome,
        }
    }
}

pub fn run(args: &TrialArgs) -> Result<std::process::ExitCode> {
    trial_report::check_outputs(args.scene.as_deref(), args.preview.as_deref())?;
    let point = NamedPoint::parse(&args.at).context("--at")?;
    let ev = args.sim.evaluator(&point.kinds)?;
    point
        .check_within(&ev.space, ev.object.name())
        .context("--at")?;
    let e = ev.evaluate(&point.values)?;
    let force_settings = ForceSettings {
        object_mass: args.object_mass,
        ..ForceSettings::default()
    };
    let grasp_forces = analyse_outcome(&e.outcome, &ev.object, &ev.score, &force_settings)
        .context("force analysis")?;
    let forces = force_analysis(&grasp_forces);
    let at: Vec<(&str, f64)> = point
        .kinds
        .iter()
        .map(|k| k.name())
        .zip(point.values.iter().copied())
        .collect();
    let title = trial_report::title(&ev, &e, &at);
    let written = trial_report::write_pictures(
        args.scene.as_deref(),
        args.preview.as_deref(),
        &ev,
        &e,
        &title,
    )?;
    match args.format {
        TrialFormat::Json => outln!(
            "{}",
            serde_json::to_string_pretty(&TrialJson::of(&e, &forces))?
        )?,
        TrialFormat::Text => {
            let text = trial_report::text(&ev, &e, &at, args.sim.metric);
            let why = match &grasp_forces.resisting {
                Resisting::CannotResist { reason } => format!(": {reason}"),
                _ => String::new(), // held, or unavailable: `describe` says why
            };
            outln!("{text}")?;
            let (mass, words) = (args.object_mass, forces.describe());
            outln!("forces ({mass} kg object): {words}{why}")?;
        }
    }
    for path in written {
        // JSON goes to stdout alone, so it stays parseable.
        match args.format {
            TrialFormat::Text => outln!("wrote {}", path.display())?,
            TrialFormat::Json => eprintln!("wrote {}", path.display()),
        }
    }
    Ok(std::process::ExitCode::SUCCESS)
}
