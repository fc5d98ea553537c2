//! Scene meshes for export and previews: the object's surface and the hand's links at a grasp,
//! as plain triangle meshes in the world frame (another module writes OBJ/glTF or draws them).

use crate::error::{Result, SimError};
use crate::hand::{Grasp, Hand};
use crate::mesh::TriangleMesh;
use crate::object::Object;

/// A named mesh in the world frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NamedMesh {
    /// What it is (`object`, a link name).
    pub name: String,
    /// The triangles (world frame).
    pub mesh: TriangleMesh,
}

/// The object's surface in the world frame.
pub fn object_mesh(object: &Object) -> NamedMesh {
    NamedMesh {
        name: object.name().to_string(),
        mesh: object.surface_mesh(),
    }
}

/// Each link of `hand` at the grasp's final pose, in the world frame.
pub fn hand_meshes(hand: &dyn Hand, grasp: &Grasp) -> Result<Vec<NamedMesh>> {
    if grasp.link_poses.len() != hand.links().len() {
        return Err(SimError::InvalidInput(format!(
            "grasp has {} link poses, hand `{}` has {} links",
            grasp.link_poses.len(),
            hand.name(),
            hand.links().len()
        )));
    }
    Ok(hand
        .links()
        .iter()
        .zip(&grasp.link_poses)
        .map(|(l, pose)| NamedMesh {
            name: l.name.clone(),
            mesh: l.shape.mesh().transformed(pose),
        })
        .collect())
}

/// The object and the hand's links together.
pub fn scene_meshes(object: &Object, hand: &dyn Hand, grasp: &Grasp) -> Result<Vec<NamedMesh>> {
    let mut v = vec![object_mesh(object)];
    v.extend(hand_meshes(hand, grasp)?);
    Ok(v)
}
