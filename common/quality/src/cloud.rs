//! Preprocessing of a raw contact cloud (thesis eq. 2.12): the mean contact
//! `c_m = (p_m, R_m)`, the mean position with a frame whose z axis is the mean normal.
//!
//! A finger touching an object yields many contact points; the surface model of
//! section 2.3 starts from their mean. Projecting a patch onto the object belongs to the
//! simulator (it needs the object's geometry); this module only needs the points.

use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

use crate::contact::{Contact, tangent_basis};
use crate::error::QualityError;

/// The mean contact of a cloud: position `p_m` and frame `R_m` (columns: `t1`, `t2`,
/// and the mean normal as z).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanContact {
    pub position: Vector3<f64>,
    pub frame: Rotation3<f64>,
}

impl MeanContact {
    /// The mean normal (the z axis of `R_m`).
    pub fn normal(&self) -> Vector3<f64> {
        self.frame.matrix().column(2).into_owned()
    }

    /// The mean contact as a single point contact.
    pub fn contact(&self) -> Contact {
        Contact::new(self.position, self.normal())
    }
}

/// The mean contact of a raw cloud: mean position, normalised mean normal, and the
/// frame whose z axis is that normal (x and y by the tangent-basis convention).
pub fn mean_contact(cloud: &[Contact]) -> Result<MeanContact, QualityError> {
    if cloud.is_empty() {
        return Err(QualityError::Empty("contact points"));
    }
    let mut p = Vector3::zeros();
    let mut n = Vector3::zeros();
    for (i, c) in cloud.iter().enumerate() {
        c.validate(i)?;
        p += c.position;
        n += c.normal;
    }
    p /= cloud.len() as f64;
    let norm = n.norm();
    // Normals that cancel (to rounding) have no mean direction.
    if norm <= 1e-9 * cloud.len() as f64 {
        return Err(QualityError::NoMeanNormal);
    }
    let n = n / norm;
    let (t1, t2) = tangent_basis(&n);
    let frame = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[t1, t2, n]));
    Ok(MeanContact { position: p, frame })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_of_a_symmetric_cloud() {
        let cloud: Vec<Contact> = [-1.0, 1.0]
            .iter()
            .map(|&s| {
                Contact::normalized(Vector3::new(s, 0.0, 2.0), Vector3::new(0.1 * s, 0.0, 1.0))
                    .unwrap()
            })
            .collect();
        let m = mean_contact(&cloud).unwrap();
        assert!((m.position - Vector3::new(0.0, 0.0, 2.0)).norm() < 1e-15);
        assert!((m.normal() - Vector3::z()).norm() < 1e-15);
        let r = m.frame.matrix();
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14);
        assert!((r.determinant() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn degenerate_clouds_are_errors() {
        assert_eq!(
            mean_contact(&[]),
            Err(QualityError::Empty("contact points"))
        );
        let opposed = [
            Contact::new(Vector3::zeros(), Vector3::z()),
            Contact::new(Vector3::zeros(), -Vector3::z()),
        ];
        assert_eq!(mean_contact(&opposed), Err(QualityError::NoMeanNormal));
    }
}
