//! Benchmarks of the figures named in the quality issue (single thread, medians):
//! - three soft-finger contacts, k = 8 (48 wrenches), all metrics but volume;
//! - a surface model, 3 fingers x 21 points x 8 edges x 2 (1,008 wrenches), BW only.
//!
//! Run: `cargo bench -p graspopt-quality --bench metrics`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_quality::metrics::{MetricsOptions, evaluate};
use graspopt_quality::{Contact, ContactModel, GraspMap, GraspModel};
use nalgebra::Vector3;

const SOFT: ContactModel = ContactModel::SoftFinger {
    mu: 0.5,
    edges: 8,
    gamma: 0.05,
};

/// A contact on the unit sphere at longitude `lon`, latitude `lat` (radians), normal
/// pointing to the centre.
fn on_sphere(lon: f64, lat: f64) -> Contact {
    let p = Vector3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
    Contact::new(p, -p)
}

/// A 21-point patch (centre, 8 points at radius r/2, 12 at radius r) around a point.
fn patch(lon: f64, lat: f64, r: f64) -> Vec<Contact> {
    let mut out = vec![on_sphere(lon, lat)];
    for (ring, count) in [(0.5, 8), (1.0, 12)] {
        for k in 0..count {
            let a = std::f64::consts::TAU * k as f64 / count as f64;
            out.push(on_sphere(
                lon + ring * r * a.cos(),
                lat + ring * r * a.sin(),
            ));
        }
    }
    out
}

fn bench(c: &mut Criterion) {
    let model = GraspModel::new(SOFT);
    let third = std::f64::consts::TAU / 3.0;
    let cases = [
        (
            "3 soft contacts, force closure",
            [0.0, third, 2.0 * third],
            0.0,
        ),
        ("3 soft contacts, no force closure", [0.0, 0.6, 1.2], 0.0),
    ];
    for (name, lons, lat) in cases {
        let contacts: Vec<Contact> = lons.iter().map(|&l| on_sphere(l, lat)).collect();
        let g = GraspMap::from_contacts(&contacts, &model).expect("grasp");
        assert_eq!(g.wrenches().len(), 48);
        c.bench_function(&format!("{name} (48 wrenches), all but volume"), |b| {
            b.iter(|| evaluate(black_box(&g), &MetricsOptions::without_volume()))
        });
    }
    let surface_cases = [
        ("surface model, force closure", [0.0, third, 2.0 * third]),
        ("surface model, no force closure", [0.0, 0.7, 1.4]),
    ];
    for (name, lons) in surface_cases {
        let contacts: Vec<Contact> = lons.iter().flat_map(|&l| patch(l, 0.1, 0.15)).collect();
        let g = GraspMap::from_contacts(&contacts, &model).expect("grasp");
        assert_eq!(g.wrenches().len(), 1008);
        c.bench_function(&format!("{name} (1008 wrenches), BW"), |b| {
            b.iter(|| evaluate(black_box(&g), &MetricsOptions::without_volume()))
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
