//! The scene's error type. The messages name the file (tests quote them).

use std::path::PathBuf;

/// What keeps a scene from being built or written.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A mesh whose triangles name a vertex it does not have.
    #[error("mesh {name} has a vertex index {index} out of range")]
    VertexIndex { name: String, index: u32 },
    /// The scene file could not be built or written; the source says why.
    #[error("cannot write the scene {}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The scene's MTL file could not be written.
    #[error("cannot write the scene's materials {}", path.display())]
    WriteMaterials {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}
