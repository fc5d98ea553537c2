//! Benchmark of the force analysis named in issue 20 (single thread, medians): the
//! least-norm contact forces of a 3-finger grasp resisting gravity (at most 1 ms).
//!
//! Run: `cargo bench -p graspopt-quality --bench forces`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_quality::{Contact, FrictionModel, Resisting, gravity_wrench, resisting_forces};
use nalgebra::Vector3;

const SOFT: FrictionModel = FrictionModel::SoftFinger {
    mu: 0.5,
    edges: 8,
    gamma: 0.005,
};

/// Three contacts on the equator of a sphere of radius 4 cm at the given longitudes
/// (degrees), normals pointing to the centre.
fn equator(longitudes: [f64; 3]) -> Vec<Contact> {
    longitudes
        .iter()
        .map(|a| {
            let (s, c) = a.to_radians().sin_cos();
            let n = Vector3::new(c, s, 0.0);
            Contact::new(n * 0.04, -n)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let origin = Vector3::zeros();
    let g = Vector3::new(0.0, 0.0, -9.81);
    // 0.5 kg with its centre of mass 1 cm off the centre.
    let gravity = gravity_wrench(0.5, &g, &Vector3::new(0.01, 0.0, 0.0), &origin).expect("wrench");
    let cases = [
        ("resists", [0.0, 120.0, 240.0]),
        // All three on one side, the object pulled away from them.
        ("cannot resist", [0.0, 30.0, 60.0]),
    ];
    for (name, longitudes) in cases {
        let contacts = equator(longitudes);
        let external = if name == "resists" {
            gravity
        } else {
            gravity + nalgebra::Vector6::new(-2.0, -2.0, 0.0, 0.0, 0.0, 0.0)
        };
        let outcome = resisting_forces(&contacts, &SOFT, &external, &origin).expect("solve");
        assert_eq!(
            matches!(outcome, Resisting::Forces { .. }),
            name == "resists",
            "{name}: {outcome:?}"
        );
        c.bench_function(
            &format!("resisting_forces, 3 soft fingers, 0.5 kg, {name}"),
            |b| {
                b.iter(|| {
                    resisting_forces(black_box(&contacts), &SOFT, black_box(&external), &origin)
                })
            },
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
