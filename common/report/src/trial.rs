//! The pictures of one trial: the preview (two views of the grasp in a PNG) and the scene
//! (object, hand links, contact points and normals as glTF 2.0 or OBJ + MTL).

use std::path::{Path, PathBuf};

use crate::error::{ReportError, Result};
use graspopt_pictures::preview;
use graspopt_quality::metrics::{Metrics, Value};
use graspopt_trial::{Evaluation, Evaluator, Metric};

/// Size of preview pictures (two views side by side).
pub const PREVIEW_WIDTH: u32 = 1200;
pub const PREVIEW_HEIGHT: u32 = 560;
/// Colours of the object and of the hand's links (alternating) in previews.
const OBJECT_COLOUR: [u8; 3] = [90, 140, 220];
const LINK_COLOURS: [[u8; 3]; 2] = [[230, 150, 60], [200, 120, 40]];

/// The title of a trial's pictures: `mug, barrett hand, x=-0.05: score -0.6463` (or
/// `reference pose` when no parameter is given).
pub fn title(ev: &Evaluator, e: &Evaluation, at: &[(&str, f64)]) -> String {
    let at: Vec<String> = at.iter().map(|(k, v)| format!("{k}={v}")).collect();
    format!(
        "{}, {} hand, {}: {}",
        ev.object.name(),
        ev.hand.name(),
        if at.is_empty() {
            "reference pose".to_string()
        } else {
            at.join(",")
        },
        score_words(&e.score)
    )
}

/// `graspopt trial`'s text, up to the score line (without a final line end): the trial,
/// where the palm went, each finger's contacts, the metrics and the score.
pub fn text(ev: &Evaluator, e: &Evaluation, at: &[(&str, f64)], metric: Metric) -> String {
    let mut lines = vec![format!(
        "object {}  hand {}  contacts {}  metric {metric}",
        ev.object.name(),
        ev.hand.name(),
        ev.score.contacts,
    )];
    lines.extend(at.iter().map(|(k, v)| format!("  {k} = {v}")));
    let t = e.outcome.grasp.palm_pose.translation.vector;
    lines.push(format!(
        "palm at ({:.4}, {:.4}, {:.4}) m, retreated {:.4} m",
        t.x, t.y, t.z, e.outcome.grasp.retreat
    ));
    let outcome = &e.outcome;
    for f in outcome.fingers.iter().chain(std::iter::once(&outcome.palm)) {
        let name = f
            .finger
            .map_or("palm".to_string(), |i| format!("finger {}", i + 1));
        lines.push(match f.mean_point() {
            Some(m) => format!(
                "  {name}: {} cloud points, {} modelled contacts, mean at ({:.4}, {:.4}, {:.4}) normal ({:.3}, {:.3}, {:.3})",
                f.cloud.points.len(),
                f.contacts(ev.score.contacts).len(),
                m.position.x,
                m.position.y,
                m.position.z,
                m.normal.x,
                m.normal.y,
                m.normal.z
            ),
            None => format!("  {name}: no contact"),
        });
    }
    lines.push(match &e.score.metrics {
        Some(m) => metrics_words(m),
        None => "no contact: nothing to score".to_string(),
    });
    lines.push(format!("score {:.6}", e.score.score));
    lines.join("\n")
}

/// The metrics in words, in the metric table's order, an optional metric (computed only
/// when asked: the volume) last and only when computed:
/// `rank 6  force closure false  epsilon 0.000000  distance 0.646259  bw -0.646259`.
pub fn metrics_words(m: &Metrics) -> String {
    let (always, optional): (Vec<_>, Vec<_>) = m.iter().partition(|(def, _)| !def.optional);
    let words: Vec<String> = always
        .into_iter()
        .chain(optional)
        .filter_map(|(def, value)| {
            let value = match value? {
                Value::Real(x) if def.scientific => format!("{x:.6e}"),
                Value::Real(x) => format!("{x:.6}"),
                v => v.to_string(),
            };
            Some(format!("{} {value}", def.label))
        })
        .collect();
    words.join("  ")
}

/// A trial's score in words for a picture's title: `score 0.2412, force closure`, or
/// `no contact`.
pub fn score_words(s: &graspopt_trial::TrialScore) -> String {
    match s.metrics {
        None => "no contact".to_string(),
        Some(m) if m.force_closure() => format!("score {:.4}, force closure", s.score),
        Some(_) => format!("score {:.4}", s.score),
    }
}

/// The preview picture of the evaluated trial `e` under `title`: the object (blue) and the
/// hand's links (orange), two views (see [`preview::render`]).
pub fn preview_image(ev: &Evaluator, e: &Evaluation, title: &str) -> Result<preview::Image> {
    let meshes = graspopt_sim::scene::scene_meshes(&ev.object, ev.hand.as_ref(), &e.outcome.grasp)?;
    let contacts = e.outcome.contacts(ev.score.contacts, true);
    let posts = graspopt_sim::scene::knuckle_posts(ev.hand.as_ref(), &e.outcome.grasp);
    let mut coloured: Vec<_> = meshes
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
    // The posts in the palm's colour.
    coloured.extend(posts.iter().map(|m| (m, LINK_COLOURS[1])));
    Ok(preview::render(
        &coloured,
        &contacts,
        (PREVIEW_WIDTH, PREVIEW_HEIGHT),
        title,
    ))
}

/// Whether `path` ends in `.ext` (any case).
pub fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case(ext))
}

/// Extensions a scene is written in (glTF 2.0 JSON, Wavefront OBJ).
pub const SCENE_EXTENSIONS: [&str; 2] = ["gltf", "obj"];

/// Refuses, before any work, a `scene` file whose extension is not one of
/// [`SCENE_EXTENSIONS`] and a `preview` that is not a `.png`.
pub fn check_outputs(scene: Option<&Path>, preview: Option<&Path>) -> Result<()> {
    if let Some(path) = scene
        && !SCENE_EXTENSIONS.iter().any(|e| has_extension(path, e))
    {
        let note = if has_extension(path, "glb") {
            " (binary glTF is not supported)"
        } else {
            ""
        };
        return Err(ReportError::Output(format!(
            "--scene {}: unsupported file type{note}; the supported extensions are .gltf (glTF 2.0) \
             and .obj (Wavefront OBJ with an MTL)",
            path.display()
        )));
    }
    if let Some(path) = preview
        && !has_extension(path, "png")
    {
        return Err(ReportError::Output(format!(
            "--preview {}: unsupported file type; previews are PNG pictures, the supported \
             extension is .png",
            path.display()
        )));
    }
    Ok(())
}

/// Writes the scene of the trial `e` to `scene` (glTF 2.0 if it ends in `.gltf`, else OBJ with
/// its MTL beside it) and its preview under `title` to `preview` (PNG), each if given; returns
/// the paths written.
pub fn write_pictures(
    scene: Option<&Path>,
    preview: Option<&Path>,
    ev: &Evaluator,
    e: &Evaluation,
    title: &str,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    if let Some(path) = scene {
        let meshes =
            graspopt_sim::scene::scene_meshes(&ev.object, ev.hand.as_ref(), &e.outcome.grasp)?;
        let contacts = e.outcome.contacts(ev.score.contacts, true);
        let (lo, hi) = ev.object.aabb();
        let normal_length = ((hi - lo).norm() * 0.15).clamp(1e-3, 0.05);
        if has_extension(path, "gltf") {
            graspopt_scene::write_gltf(path, &meshes, &contacts, normal_length)
                .map_err(ReportError::picture)?;
            written.push(path.to_path_buf());
        } else {
            graspopt_scene::write_obj(path, &meshes, &contacts, normal_length)
                .map_err(ReportError::picture)?;
            written.push(path.to_path_buf());
            written.push(graspopt_scene::mtl_path(path));
        }
    }
    if let Some(path) = preview {
        preview_image(ev, e, title)?
            .save_png(path)
            .map_err(ReportError::picture)?;
        written.push(path.to_path_buf());
    }
    Ok(written)
}
