//! Any reading at all: every contact `locate` returns explains the reading, lies on the
//! surface, above the base, and pushes.

use graspopt_sensing::{
    ContactKind, FingertipSurface, FingertipWrench, NoContact, SensingSettings, locate, wrench_of,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::support::{capsule, ellipsoid, sphere, unit};

/// Distance-like measure of how far `p` is off `surface` (0 on it): the surface point
/// near `p` along its normal is found by the forward model's own normal, so compare
/// with each shape's equation instead.
fn off_surface(surface: &FingertipSurface, p: &nalgebra::Point3<f64>) -> f64 {
    let c = surface.center();
    match *surface {
        FingertipSurface::Sphere { radius, .. } => ((p - c).norm() - radius).abs(),
        FingertipSurface::Ellipsoid { semi_axes, .. } => {
            let d = (p - c).component_div(&nalgebra::Vector3::from(semi_axes));
            (d.norm() - 1.0).abs() * semi_axes.iter().cloned().fold(0.0, f64::max)
        }
        FingertipSurface::Capsule {
            half_length,
            radius,
            ..
        } => {
            let z = (p.z - c.z).clamp(-half_length, half_length);
            ((p - nalgebra::Point3::new(c.x, c.y, c.z + z)).norm() - radius).abs()
        }
    }
}

#[test]
fn every_contact_returned_explains_its_reading() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for surface in [sphere(), ellipsoid(), capsule()] {
        for kind in [ContactKind::Point, ContactKind::SoftFinger] {
            let settings = SensingSettings {
                kind,
                ..SensingSettings::default()
            };
            let mut accepted = 0;
            for i in 0..50_000 {
                // Forces from 0.01 to 100 N, torques up to 0.05 N m times the force, and
                // for the point model mostly nearly perpendicular to the force (else
                // nearly all are refused for torsion).
                let f = unit(&mut rng) * 10f64.powf(-2.0 + 4.0 * rng.random::<f64>());
                let mut t = unit(&mut rng) * 0.05 * rng.random::<f64>() * f.norm();
                if kind == ContactKind::Point && rng.random::<f64>() < 0.9 {
                    t -= f * (t.dot(&f) / f.norm_squared()) * (1.0 - 1e-3 * rng.random::<f64>());
                }
                let r = FingertipWrench {
                    force: f,
                    torque: t,
                };
                let c = match locate(&surface, &r, &settings) {
                    Ok(c) => c,
                    Err(NoContact::Ambiguous { separation }) => {
                        panic!("case {i}: ambiguous ({separation} m apart) for {r:?}")
                    }
                    Err(NoContact::Invalid(e)) => panic!("case {i}: {e}"),
                    Err(_) => continue,
                };
                accepted += 1;
                assert!(c.point.coords.iter().all(|x| x.is_finite()), "case {i}");
                assert_eq!(c.force, -f, "case {i}");
                assert!(off_surface(&surface, &c.point) < 1e-12, "case {i}: {c:?}");
                if let Some(base) = surface.base_z() {
                    assert!(c.point.z >= base - settings.surface_tolerance, "case {i}");
                }
                let fn_ = c.force.dot(&c.normal);
                // Pushes; a grazing point contact is tangent (to the golden-section
                // search's precision on the ellipsoid, about 1e-8 rad).
                assert!(fn_ >= -1e-6 * f.norm(), "case {i}: normal force {fn_}");
                // The contact's own reading equals the measured one but for what the
                // tolerances allow: a torque part along F up to the pitch tolerance, a
                // grazing miss up to the surface tolerance.
                let back = wrench_of(&surface, &c.point, &c.force, c.torsion);
                let allowed = (settings.pitch_tolerance + settings.surface_tolerance) * f.norm()
                    + 1e-12 * (1.0 + t.norm());
                assert!(
                    (back.torque - t).norm() <= allowed,
                    "case {i}: torque {:?} back {:?}",
                    t,
                    back.torque
                );
            }
            println!("{surface:?} {kind:?}: {accepted} of 50000 accepted");
            assert!(accepted > 500, "{kind:?}: only {accepted} accepted");
        }
    }
}
