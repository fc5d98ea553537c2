//! The object the trials are planned against ([`ObjectEstimate`], the `object` topic).

use serde::{Deserialize, Serialize};

use super::{Message, Pose, finite};
use crate::error::{Problem, ValidationError};
use crate::keys::RunId;

/// A triangle mesh sent with an object (user meshes; built-in objects are sent by name).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshData {
    pub vertices: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// perception -> everyone: the object the trials are planned against, in the world frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectEstimate {
    pub run_id: RunId,
    /// A built-in object name (`mug`, `sphere`, ...) or the user mesh's name.
    pub object: String,
    /// The mesh, for objects that are not built in.
    pub mesh: Option<MeshData>,
    /// The estimated pose of the object's frame in the world.
    pub pose: Pose,
    /// Increases with every new estimate.
    pub seq: u64,
    pub stamp_ms: i64,
    /// Who estimated it (an agent id).
    pub source: String,
}

impl Message for ObjectEstimate {
    const TYPE: &'static str = "ObjectEstimate";
    fn run_id(&self) -> &RunId {
        &self.run_id
    }
    fn validate(&self) -> Result<(), ValidationError> {
        let invalid = |field: String, problem| ValidationError::new(Self::TYPE, field, problem);
        if self.object.trim().is_empty() {
            return Err(invalid("object".into(), Problem::Empty));
        }
        self.pose.validate_in(Self::TYPE, "pose")?;
        if let Some(mesh) = &self.mesh {
            for (i, v) in mesh.vertices.iter().enumerate() {
                finite(Self::TYPE, &format!("mesh.vertices[{i}]"), v)?;
            }
            let n = mesh.vertices.len();
            for (i, t) in mesh.triangles.iter().enumerate() {
                if t.iter().any(|&k| k as usize >= n) {
                    let field = format!("mesh.triangles[{i}]");
                    return Err(invalid(field, Problem::MissingVertex));
                }
            }
        }
        Ok(())
    }
}
