//! The one boundary between nalgebra (the public API) and parry's glam-based math types.

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};

/// nalgebra point to parry vector.
pub(crate) fn p2g(p: &Point3<f64>) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

/// nalgebra vector to parry vector.
pub(crate) fn v2g(v: &Vector3<f64>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// parry vector to nalgebra point.
pub(crate) fn g2p(v: Vector) -> Point3<f64> {
    Point3::new(v.x, v.y, v.z)
}

/// parry vector to nalgebra vector.
pub(crate) fn g2v(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// nalgebra isometry to parry pose.
pub(crate) fn iso2pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// parry pose to nalgebra isometry.
#[cfg(test)]
pub(crate) fn pose2iso(pose: &Pose) -> Isometry3<f64> {
    use nalgebra::{Quaternion, Translation3, UnitQuaternion};
    let r = pose.rotation;
    let t = pose.translation;
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::from_quaternion(Quaternion::new(r.w, r.x, r.y, r.z)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_isometry_and_points() {
        let iso = Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.4, 0.5, -0.6));
        let back = pose2iso(&iso2pose(&iso));
        assert!((back.to_homogeneous() - iso.to_homogeneous()).norm() < 1e-12);
        let p = Point3::new(0.01, 0.02, 0.03);
        let a = iso * p;
        let b = g2p(iso2pose(&iso).transform_point(p2g(&p)));
        assert!((a - b).norm() < 1e-12);
        assert_eq!(g2v(v2g(&Vector3::x())), Vector3::x());
    }
}
