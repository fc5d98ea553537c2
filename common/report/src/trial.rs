//! The pictures of one trial: the preview (two views of the grasp in a PNG) and the scene
//! (object, hand links, contact points and normals as glTF 2.0 or OBJ + MTL).

use std::path::{Path, PathBuf};

use anyhow::Result;
use graspopt_pictures::preview;
use graspopt_trial::{Evaluation, Evaluator};

/// Size of preview pictures (two views side by side).
pub const PREVIEW_WIDTH: u32 = 1200;
pub const PREVIEW_HEIGHT: u32 = 560;
/// Colours of the object and of the hand's links (alternating) in previews.
const OBJECT_COLOUR: [u8; 3] = [90, 140, 220];
const LINK_COLOURS: [[u8; 3]; 2] = [[230, 150, 60], [200, 120, 40]];

/// A trial's score in words for a picture's title: `score 0.2412, force closure`, or
/// `no contact`.
pub fn score_words(s: &graspopt_trial::TrialScore) -> String {
    match s.metrics {
        None => "no contact".to_string(),
        Some(m) if m.force_closure => format!("score {:.4}, force closure", s.score),
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
        anyhow::bail!(
            "--scene {}: unsupported file type{note}; the supported extensions are .gltf (glTF 2.0) \
             and .obj (Wavefront OBJ with an MTL)",
            path.display()
        );
    }
    if let Some(path) = preview
        && !has_extension(path, "png")
    {
        anyhow::bail!(
            "--preview {}: unsupported file type; previews are PNG pictures, the supported \
             extension is .png",
            path.display()
        );
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
            graspopt_scene::write_gltf(path, &meshes, &contacts, normal_length)?;
            written.push(path.to_path_buf());
        } else {
            graspopt_scene::write_obj(path, &meshes, &contacts, normal_length)?;
            written.push(path.to_path_buf());
            written.push(graspopt_scene::mtl_path(path));
        }
    }
    if let Some(path) = preview {
        preview_image(ev, e, title)?.save_png(path)?;
        written.push(path.to_path_buf());
    }
    Ok(written)
}
