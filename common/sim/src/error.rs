//! Typed errors of the simulator. Every fallible public function returns [`SimError`]; no input
//! (pose, mesh, name) can make this crate panic.

use thiserror::Error;

/// Everything that can go wrong while building objects, hands or running a trial.
#[derive(Debug, Error)]
pub enum SimError {
    /// An object name that is not one of the built-in objects.
    #[error("unknown object `{name}`; valid names are: {valid}")]
    UnknownObject {
        /// The name that was asked for.
        name: String,
        /// The valid names, comma separated.
        valid: String,
    },
    /// A hand name that is not one of the built-in hands.
    #[error("unknown hand `{name}`; valid names are: {valid}")]
    UnknownHand {
        /// The name that was asked for.
        name: String,
        /// The valid names, comma separated.
        valid: String,
    },
    /// A hand description (URDF and its settings) that cannot be used; names the file and the
    /// joint, link or mesh at fault.
    #[error("hand `{file}`: {reason}")]
    BadHand {
        /// The URDF (or settings) file, or the built-in hand's source.
        file: String,
        /// What is wrong, naming the joint, link or file.
        reason: String,
    },
    /// A pose, parameter or setting with a NaN or infinite component.
    #[error("non-finite value in {what}")]
    NonFinite {
        /// Which input was not finite.
        what: String,
    },
    /// A mesh with no vertices or no triangles.
    #[error("mesh `{name}` is empty ({vertices} vertices, {triangles} triangles)")]
    EmptyMesh {
        /// Mesh name (file name or object name).
        name: String,
        /// Vertex count.
        vertices: usize,
        /// Triangle count.
        triangles: usize,
    },
    /// A mesh that does not enclose a volume.
    #[error(
        "mesh `{name}` is not watertight: {reason}; repair it (e.g. MeshLab: Filters > Cleaning and Repairing > Merge Close Vertices, then Close Holes; or Blender's 3D-Print Toolbox: Make Manifold) and load it again"
    )]
    NotWatertight {
        /// Mesh name.
        name: String,
        /// The first defect found (e.g. an edge used by one triangle only).
        reason: String,
    },
    /// A user mesh whose size cannot be an object a hand grasps (a mesh in millimetres read as
    /// metres, say).
    #[error(
        "mesh `{name}` has a bounding radius of {radius:.4e} m{scaled}: a hand grasps objects of {min} m to {max} m in radius; {advice}"
    )]
    ImplausibleSize {
        /// Mesh name (the path).
        name: String,
        /// Half the diagonal of its bounding box, after scaling (metres).
        radius: f64,
        /// ` after scaling by S`, or empty.
        scaled: String,
        /// The smallest plausible radius.
        min: f64,
        /// The largest plausible radius.
        max: f64,
        /// Which scale factor would make it plausible (`--mesh-scale S` in graspopt's commands).
        advice: String,
    },
    /// A malformed mesh file or buffer.
    #[error("cannot parse mesh `{name}`: {reason}")]
    MeshParse {
        /// Mesh name (usually the path).
        name: String,
        /// What was wrong, with a line number when there is one.
        reason: String,
    },
    /// A mesh file whose extension is not `.obj` or `.stl`.
    #[error("unsupported mesh format `{path}`: expected .obj or .stl")]
    UnsupportedFormat {
        /// The path.
        path: String,
    },
    /// An I/O error while reading a mesh file.
    #[error("cannot read mesh file `{path}`")]
    Io {
        /// The path.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A parameter vector of the wrong length or outside its bounds, or an invalid setting.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A trial parameter name that is none of those [`crate::ParamKind::parse`] accepts.
    #[error(
        "unknown trial parameter {name:?}: expected x (approach), y (vertical), lateral, rx, ry or rz"
    )]
    UnknownParam { name: String },
    /// A parameter range (`NAME=LOWER:UPPER`) that cannot be used, and why.
    #[error("range {text:?}: {reason}")]
    Range {
        /// The range as written.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A collision query that parry does not support for the shapes involved.
    #[error("unsupported collision query between {0}")]
    UnsupportedQuery(String),
    /// The hand could not be placed clear of the object by retreating along its approach axis.
    #[error("hand still intersects the object after retreating {0:.3} m along the approach axis")]
    CannotClear(f64),
}

/// Result alias of this crate.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// Errors unless every value is finite.
pub(crate) fn ensure_finite(values: &[f64], what: &str) -> Result<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SimError::NonFinite {
            what: what.to_string(),
        })
    }
}

/// Why a set of points has no convex hull ([`crate::mesh::convex_hull`]).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum HullError {
    /// Fewer than four points.
    #[error("{0} points are fewer than the four a volume needs")]
    TooFewPoints(usize),
    /// A point with a NaN or infinite coordinate (the point, as debug text).
    #[error("a point is not finite ({0})")]
    NotFinite(String),
    /// Points parry cannot build a hull from (its reason, as debug text).
    #[error("its points are degenerate, no hull can be built ({0})")]
    Degenerate(String),
    /// Points that span no volume.
    #[error("its points are flat: they enclose no volume")]
    Flat,
}
