//! Wrenches (force, torque) in R^6 and their change of frame (thesis eq. 2.1-2.3).

use nalgebra::{Matrix3, Matrix6, Rotation3, Vector3, Vector6};

/// A wrench `(f, tau)`: force in the first three components, torque in the last three.
pub type Wrench = Vector6<f64>;

/// Builds a wrench from its force and torque.
pub fn wrench(force: &Vector3<f64>, torque: &Vector3<f64>) -> Wrench {
    Wrench::new(force.x, force.y, force.z, torque.x, torque.y, torque.z)
}

/// The force part of a wrench.
pub fn force(w: &Wrench) -> Vector3<f64> {
    Vector3::new(w[0], w[1], w[2])
}

/// The torque part of a wrench.
pub fn torque(w: &Wrench) -> Vector3<f64> {
    Vector3::new(w[3], w[4], w[5])
}

/// The skew-symmetric matrix `[p]x` with `[p]x v = p x v` (eq. 2.3).
pub fn skew(p: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -p.z, p.y, p.z, 0.0, -p.x, -p.y, p.x, 0.0)
}

/// A rigid change of frame for wrenches: frame B seen from frame C, i.e. the rotation
/// `R_cb` and the position `p_bc` of B's origin in C (eq. 2.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameChange {
    pub rotation: Rotation3<f64>,
    pub translation: Vector3<f64>,
}

impl FrameChange {
    /// The change of frame from B to C.
    pub fn new(rotation: Rotation3<f64>, translation: Vector3<f64>) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// The 6x6 matrix of eq. 2.2: `[[R, 0], [[p]x R, R]]`.
    pub fn matrix(&self) -> Matrix6<f64> {
        let r = *self.rotation.matrix();
        let pr = skew(&self.translation) * r;
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&pr);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
        m
    }

    /// The wrench `w_b`, applied at B's origin, as the equivalent wrench at C's origin.
    pub fn apply(&self, w: &Wrench) -> Wrench {
        let f = self.rotation * force(w);
        let t = self.translation.cross(&f) + self.rotation * torque(w);
        wrench(&f, &t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skew_matches_cross_product() {
        let p = Vector3::new(0.3, -1.2, 2.0);
        let v = Vector3::new(-0.7, 0.4, 1.1);
        assert!((skew(&p) * v - p.cross(&v)).norm() < 1e-15);
    }

    #[test]
    fn frame_change_adds_the_moment_of_the_force() {
        // A unit force along x applied at B, whose origin is at (0, 1, 0) in C: the
        // torque about C's origin is (0,1,0) x (1,0,0) = (0,0,-1).
        let change = FrameChange::new(Rotation3::identity(), Vector3::new(0.0, 1.0, 0.0));
        let w = wrench(&Vector3::x(), &Vector3::zeros());
        let wc = change.apply(&w);
        assert!((wc - Wrench::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0)).norm() < 1e-15);
        assert!((change.matrix() * w - wc).norm() < 1e-15);
    }

    #[test]
    fn frame_changes_compose() {
        let a = FrameChange::new(
            Rotation3::from_euler_angles(0.1, 0.2, 0.3),
            Vector3::new(0.5, -0.2, 0.1),
        );
        let b = FrameChange::new(
            Rotation3::from_euler_angles(-0.4, 0.7, 0.05),
            Vector3::new(-0.3, 0.9, 0.4),
        );
        let w = Wrench::new(0.3, -0.1, 0.9, 0.2, 0.05, -0.4);
        let two_steps = b.apply(&a.apply(&w));
        let product = b.matrix() * a.matrix() * w;
        assert!((two_steps - product).norm() < 1e-14);
    }
}
