//! Grasps shared by the integration tests.

use graspopt_quality::Contact;
use nalgebra::Vector3;

/// Contacts on the unit sphere at the given equator angles (degrees), normals inward.
pub fn equator(angles: &[f64]) -> Vec<Contact> {
    angles
        .iter()
        .map(|a| {
            let (s, c) = a.to_radians().sin_cos();
            let p = Vector3::new(c, s, 0.0);
            Contact::new(p, -p)
        })
        .collect()
}
