//! Shared helpers: angles, random surface points and forces.

use graspopt_sensing::FingertipSurface;
use nalgebra::{Point3, Unit, Vector3};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The angle (rad) between two unit vectors, accurate for small angles.
pub fn angle(a: &Unit<Vector3<f64>>, b: &Unit<Vector3<f64>>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// A unit vector uniform on the sphere.
pub fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.sample::<f64, _>(StandardNormal),
            rng.sample::<f64, _>(StandardNormal),
            rng.sample::<f64, _>(StandardNormal),
        );
        let n = v.norm();
        if n > 1e-6 {
            return v / n;
        }
    }
}

/// A random point of `surface` (not uniform by area), above its base if it has one.
pub fn surface_point(surface: &FingertipSurface, rng: &mut ChaCha8Rng) -> Point3<f64> {
    loop {
        let p = match *surface {
            FingertipSurface::Sphere { center, radius, .. } => {
                Point3::from(center) + unit(rng) * radius
            }
            FingertipSurface::Ellipsoid {
                center, semi_axes, ..
            } => Point3::from(center) + unit(rng).component_mul(&Vector3::from(semi_axes)),
            FingertipSurface::Capsule {
                center,
                half_length,
                radius,
                ..
            } => {
                let c = Point3::from(center);
                let u = unit(rng);
                if rng.random::<f64>() < 0.5 {
                    // On the cylinder.
                    let n = Vector3::new(u.x, u.y, 0.0).normalize();
                    let z = (2.0 * rng.random::<f64>() - 1.0) * half_length;
                    c + n * radius + Vector3::z() * z
                } else {
                    // On the cap on the side u points to.
                    let end = Vector3::z() * half_length * u.z.signum();
                    c + end + u * radius
                }
            }
        };
        if surface.base_z().is_none_or(|b| p.z > b) {
            return p;
        }
    }
}

/// A force the fingertip applies at a contact with outward normal `n`: normal component
/// in [lo, hi] N, tangential part inside the friction cone of coefficient `mu`.
pub fn cone_force(
    n: &Unit<Vector3<f64>>,
    mu: f64,
    lo: f64,
    hi: f64,
    rng: &mut ChaCha8Rng,
) -> Vector3<f64> {
    let normal = lo + (hi - lo) * rng.random::<f64>();
    let t = unit(rng);
    let tangent = (t - n.into_inner() * t.dot(n)).normalize();
    let ratio = mu * rng.random::<f64>().sqrt();
    (n.into_inner() + tangent * ratio) * normal
}

/// The fingertips the tests use, all in a sensor frame whose z axis points out of the
/// finger.
pub fn sphere() -> FingertipSurface {
    FingertipSurface::Sphere {
        center: [0.001, -0.002, 0.012],
        radius: 0.008,
        base_z: None,
    }
}

pub fn ellipsoid() -> FingertipSurface {
    FingertipSurface::Ellipsoid {
        center: [0.0, 0.001, 0.02],
        semi_axes: [0.009, 0.006, 0.015],
        base_z: None,
    }
}

pub fn capsule() -> FingertipSurface {
    FingertipSurface::Capsule {
        center: [0.0, 0.0, 0.02],
        half_length: 0.01,
        radius: 0.006,
        base_z: Some(0.012),
    }
}
