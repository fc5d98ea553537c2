//! `graspopt trial --object mug --hand barrett --at x=-0.08,y=0.01`: run one simulated
//! trial and print its contacts and metrics (`--format json` for everything).

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use graspopt_report::trial::{self as trial_report, has_extension};
use graspopt_trial::Evaluation;
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
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TrialFormat {
    Text,
    Json,
}

/// `--format json`: the parameters, the score with what it was computed from (contacts,
/// fingers in contact, metrics) at the top level, and the simulated outcome.
#[derive(Serialize)]
struct TrialJson<'a> {
    params: &'a [f64],
    #[serde(flatten)]
    score: &'a graspopt_trial::TrialScore,
    outcome: &'a graspopt_sim::TrialOutcome,
}

impl<'a> TrialJson<'a> {
    fn of(e: &'a Evaluation) -> Self {
        TrialJson {
            params: &e.params,
            score: &e.score,
            outcome: &e.outcome,
        }
    }
}

/// Extensions `--scene` writes (glTF 2.0 JSON, Wavefront OBJ).
const SCENE_EXTENSIONS: [&str; 2] = ["gltf", "obj"];

/// A value for a message: as given when that is short, else `1.0000e300`.
fn compact(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 12 {
        plain
    } else {
        format!("{v:.4e}")
    }
}

/// A bound for a message: at most 4 decimals (`-0.7854`), or `1.0000e-6` when tiny or huge.
fn compact_bound(v: f64) -> String {
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.into() }
    } else {
        format!("{v:.4e}")
    }
}

/// A parameter as the user named it, with its full name when that differs: `x (approach)`.
fn described(name: &str, kind: graspopt_sim::ParamKind) -> String {
    let full = kind.name();
    if name == full {
        name.to_string()
    } else {
        format!("{name} ({full})")
    }
}

/// Checks the extensions of `--scene` and `--preview` before any work.
fn check_outputs(args: &TrialArgs) -> Result<()> {
    if let Some(path) = &args.scene
        && !SCENE_EXTENSIONS.iter().any(|e| has_extension(path, e))
    {
        let note = if has_extension(path, "glb") {
            " (binary glTF is not supported)"
        } else {
            ""
        };
        bail!(
            "--scene {}: unsupported file type{note}; the supported extensions are .gltf (glTF 2.0) \
             and .obj (Wavefront OBJ with an MTL)",
            path.display()
        );
    }
    if let Some(path) = &args.preview
        && !has_extension(path, "png")
    {
        bail!(
            "--preview {}: unsupported file type; previews are PNG pictures, the supported \
             extension is .png",
            path.display()
        );
    }
    Ok(())
}

pub fn run(args: &TrialArgs) -> Result<std::process::ExitCode> {
    check_outputs(args)?;
    let mut names = Vec::new();
    let mut kinds = Vec::new();
    let mut values = Vec::new();
    for part in args.at.split(',').filter(|p| !p.trim().is_empty()) {
        let (name, value) = part
            .split_once('=')
            .with_context(|| format!("--at: expected NAME=VALUE, got {part:?}"))?;
        let kind = graspopt_sim::ParamKind::parse(name)?;
        if kinds.contains(&kind) {
            bail!("--at: {} given twice", kind.name());
        }
        let value: f64 = value
            .trim()
            .parse()
            .with_context(|| format!("--at: {name} is not a number: {value:?}"))?;
        if !value.is_finite() {
            bail!(
                "--at: {} = {value} is not a finite number",
                described(name.trim(), kind)
            );
        }
        names.push(name.trim());
        kinds.push(kind);
        values.push(value);
    }
    let ev = args.sim.evaluator(&kinds)?;
    for (((name, kind), value), (lo, hi)) in
        names.iter().zip(&kinds).zip(&values).zip(ev.space.bounds())
    {
        // The simulator's own slack, so exact bounds pass.
        if *value < lo - 1e-9 || *value > hi + 1e-9 {
            let unit = match kind {
                graspopt_sim::ParamKind::RotX
                | graspopt_sim::ParamKind::RotY
                | graspopt_sim::ParamKind::RotZ => "rad",
                _ => "m",
            };
            bail!(
                "--at: {} = {} is outside [{}, {}] {unit} for the {}",
                described(name, *kind),
                compact(*value),
                compact_bound(lo),
                compact_bound(hi),
                ev.object.name()
            );
        }
    }
    let e = ev.evaluate(&values)?;
    let at: Vec<String> = kinds
        .iter()
        .zip(&values)
        .map(|(k, v)| format!("{}={v}", k.name()))
        .collect();
    let title = format!(
        "{}, {} hand, {}: {}",
        ev.object.name(),
        ev.hand.name(),
        if at.is_empty() {
            "reference pose".to_string()
        } else {
            at.join(",")
        },
        trial_report::score_words(&e.score)
    );
    let written = trial_report::write_pictures(
        args.scene.as_deref(),
        args.preview.as_deref(),
        &ev,
        &e,
        &title,
    )?;
    match args.format {
        TrialFormat::Json => outln!("{}", serde_json::to_string_pretty(&TrialJson::of(&e))?)?,
        TrialFormat::Text => {
            outln!(
                "object {}  hand {}  contacts {}  metric {}",
                ev.object.name(),
                ev.hand.name(),
                ev.score.contacts,
                args.sim.metric
            )?;
            for (k, v) in kinds.iter().zip(&values) {
                outln!("  {} = {v}", k.name())?;
            }
            let t = e.outcome.grasp.palm_pose.translation.vector;
            outln!(
                "palm at ({:.4}, {:.4}, {:.4}) m, retreated {:.4} m",
                t.x,
                t.y,
                t.z,
                e.outcome.grasp.retreat
            )?;
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
                    Some(m) => outln!(
                        "  {name}: {} cloud points, {} modelled contacts, mean at ({:.4}, {:.4}, {:.4}) normal ({:.3}, {:.3}, {:.3})",
                        f.cloud.points.len(),
                        modelled.len(),
                        m.position.x,
                        m.position.y,
                        m.position.z,
                        m.normal.x,
                        m.normal.y,
                        m.normal.z
                    )?,
                    None => outln!("  {name}: no contact")?,
                }
            }
            match e.score.metrics {
                Some(m) => outln!(
                    "rank {}  force closure {}  epsilon {:.6}  distance {:.6}  bw {:.6}{}",
                    m.rank,
                    m.force_closure,
                    m.epsilon,
                    m.distance,
                    m.bw,
                    m.volume
                        .map_or(String::new(), |v| format!("  volume {v:.6e}"))
                )?,
                None => outln!("no contact: nothing to score")?,
            }
            outln!("score {:.6}", e.score.score)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(compact(1e300), "1.0000e300");
        assert_eq!(compact(-0.08), "-0.08");
        assert_eq!(compact(0.020_000_1), "0.0200001");
        assert_eq!(compact_bound(-std::f64::consts::FRAC_PI_4), "-0.7854");
        assert_eq!(compact_bound(0.02), "0.02");
        assert_eq!(compact_bound(0.0), "0");
        assert_eq!(compact_bound(1e-7), "1.0000e-7");
    }
}
