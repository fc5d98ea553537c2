//! The rigid pose every message that places something uses.

use serde::{Deserialize, Serialize};

use super::finite;
use crate::error::{Problem, ValidationError};

/// A rigid pose: translation (metres) and a unit quaternion `[w, x, y, z]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub translation: [f64; 3],
    pub rotation: [f64; 4],
}

impl Pose {
    pub const IDENTITY: Pose = Pose {
        translation: [0.0; 3],
        rotation: [1.0, 0.0, 0.0, 0.0],
    };

    /// Finite, with a quaternion of norm 1 within 1e-6; the error names `field` of a `Pose`.
    pub fn validate(&self, field: &str) -> Result<(), ValidationError> {
        self.validate_in("Pose", field)
    }

    /// [`Pose::validate`] for the pose at `field` of a message of type `message_type`.
    pub(crate) fn validate_in(
        &self,
        message_type: &'static str,
        field: &str,
    ) -> Result<(), ValidationError> {
        finite(
            message_type,
            &format!("{field}.translation"),
            &self.translation,
        )?;
        finite(message_type, &format!("{field}.rotation"), &self.rotation)?;
        let n = self.rotation.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-6 {
            return Err(ValidationError::new(
                message_type,
                format!("{field}.rotation"),
                Problem::NotUnitQuaternion(n),
            ));
        }
        Ok(())
    }
}
