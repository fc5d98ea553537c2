//! Scene meshes for export and previews: the object's surface and the hand's links at a grasp,
//! as plain triangle meshes in the world frame (another module writes OBJ/glTF or draws them).

use nalgebra::{Isometry3, Point3, Translation3, Vector3};

use crate::error::{Result, SimError};
use crate::hand::{Grasp, Hand, LinkShape};
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

/// Posts between the palm and each finger's first joint where the hand's model leaves a gap
/// (the Barrett's knuckle housings are not simulated), so that pictures show one hand: for
/// each finger, a cylinder as wide as its first link, from that link's joint end (the
/// middle of its lowest face, in its own frame) straight down to the palm's top face. In the
/// world frame, at the grasp's final pose; none for a hand without a palm link.
pub fn knuckle_posts(hand: &dyn Hand, grasp: &Grasp) -> Vec<TriangleMesh> {
    let links = hand.links();
    let Some(palm) = links.iter().position(|l| l.finger.is_none()) else {
        return Vec::new();
    };
    let Some(palm_pose) = grasp.link_poses.get(palm) else {
        return Vec::new();
    };
    let top = links[palm]
        .shape
        .mesh()
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let up = palm_pose.rotation * Vector3::z();
    let top_centre = palm_pose * Point3::new(0.0, 0.0, top);
    let mut posts = Vec::new();
    let mut seen = Vec::new();
    for (link, pose) in links.iter().zip(&grasp.link_poses) {
        let Some(finger) = link.finger else { continue };
        if seen.contains(&finger) {
            continue;
        }
        seen.push(finger);
        let mesh = link.shape.mesh();
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for v in &mesh.vertices {
            lo = lo.inf(&v.coords);
            hi = hi.sup(&v.coords);
        }
        let joint = pose * Point3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, lo.z);
        let gap = (joint - top_centre).dot(&up);
        let radius = (hi.x - lo.x).min(hi.y - lo.y) / 2.0;
        if !(gap > 1e-4 && radius.is_finite() && radius > 0.0) {
            continue;
        }
        let centre = joint - up * (gap / 2.0);
        let post = LinkShape::Cylinder {
            radius,
            half_height: gap / 2.0,
        };
        let at = Isometry3::from_parts(Translation3::from(centre.coords), palm_pose.rotation);
        posts.push(post.mesh().transformed(&at));
    }
    posts
}
