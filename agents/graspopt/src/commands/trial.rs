//! `graspopt trial --object mug --hand barrett --at x=-0.08,y=0.01`: run one simulated
//! trial and print its contacts and metrics (`--format json` for everything).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use graspopt_trial::{Evaluation, Evaluator};

use super::setup::{SimArgs, param_kind, param_name};
use crate::{export, render};

/// Size of `--preview` pictures (two views side by side).
pub const PREVIEW_WIDTH: u32 = 1200;
pub const PREVIEW_HEIGHT: u32 = 560;
/// Colours of the object and of the hand's links (alternating) in previews.
const OBJECT_COLOUR: [u8; 3] = [90, 140, 220];
const LINK_COLOURS: [[u8; 3]; 2] = [[230, 150, 60], [200, 120, 40]];

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
    /// Write the scene (object, hand links, contact points and normals) for any 3D viewer:
    /// glTF 2.0 if FILE ends in `.gltf`, else a Wavefront OBJ with its colours in an MTL next
    /// to it.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Draw the grasp from two viewpoints (along the approach axis, from the side) into a PNG.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
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
    let written = write_pictures(args, &ev, &e)?;
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
    for path in written {
        // JSON goes to stdout alone, so it stays parseable.
        match args.format {
            TrialFormat::Text => println!("wrote {}", path.display()),
            TrialFormat::Json => eprintln!("wrote {}", path.display()),
        }
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// Writes `--scene` and `--preview` (if asked for); returns the paths written.
fn write_pictures(args: &TrialArgs, ev: &Evaluator, e: &Evaluation) -> Result<Vec<PathBuf>> {
    if args.scene.is_none() && args.preview.is_none() {
        return Ok(Vec::new());
    }
    let meshes = graspopt_sim::scene::scene_meshes(&ev.object, ev.hand.as_ref(), &e.outcome.grasp)?;
    let contacts = e.outcome.contacts(ev.score.contacts, true);
    let mut written = Vec::new();
    if let Some(path) = &args.scene {
        let (lo, hi) = ev.object.aabb();
        let normal_length = ((hi - lo).norm() * 0.15).clamp(1e-3, 0.05);
        if has_extension(path, "glb") {
            bail!(
                "--scene {}: binary glTF (.glb) is not supported; write .gltf or .obj",
                path.display()
            );
        }
        if has_extension(path, "gltf") {
            export::write_gltf(path, &meshes, &contacts, normal_length)?;
            written.push(path.clone());
        } else {
            export::write_obj(path, &meshes, &contacts, normal_length)?;
            written.push(path.clone());
            written.push(export::mtl_path(path));
        }
    }
    if let Some(path) = &args.preview {
        let coloured: Vec<_> = meshes
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let c = if k == 0 {
                    OBJECT_COLOUR
                } else {
                    LINK_COLOURS[k % 2]
                };
                (&m.mesh, c)
            })
            .collect();
        render::render_grasp(&coloured, &contacts, PREVIEW_WIDTH, PREVIEW_HEIGHT).save_png(path)?;
        written.push(path.clone());
    }
    Ok(written)
}

fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case(ext))
}
