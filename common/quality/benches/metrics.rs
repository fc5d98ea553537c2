//! Benchmarks of the figures named in the quality issue (single thread, medians):
//! - three soft-finger contacts, k = 8 (48 wrenches), all metrics but volume;
//! - a surface model, 3 fingers x 21 points x 8 edges x 2 (1,008 wrenches), BW only.
//!
//! Run: `cargo bench -p graspopt-quality --bench metrics`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_quality::metrics::{MetricsOptions, evaluate};
use graspopt_quality::{Contact, FrictionModel, GraspMap, GraspModel};
use nalgebra::Vector3;

const SOFT: FrictionModel = FrictionModel::SoftFinger {
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

/// 100 seeded random grasps of three soft-finger contacts on the unit sphere (k = 8,
/// 48 wrenches each), split by force closure; each timed separately, so the report
/// gives the typical cost rather than one hand-picked grasp.
fn random_grasps(c: &mut Criterion) {
    let model = GraspModel::new(SOFT);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut closed = Vec::new();
    let mut open = Vec::new();
    for _ in 0..100 {
        let contacts: Vec<Contact> = (0..3)
            .map(|_| {
                let z: f64 = 2.0 * uniform() - 1.0;
                let lon = std::f64::consts::TAU * uniform();
                on_sphere(lon, z.asin())
            })
            .collect();
        let g = GraspMap::from_contacts(&contacts, &model).expect("grasp");
        let fc = evaluate(&g, &MetricsOptions::without_volume())
            .expect("metrics")
            .force_closure();
        if fc { closed.push(g) } else { open.push(g) }
    }
    for (name, set) in [("force closure", &closed), ("no force closure", &open)] {
        c.bench_function(
            &format!(
                "random 3 soft contacts, {name} ({} grasps), all but volume, per grasp",
                set.len()
            ),
            |b| {
                b.iter_custom(|iters| {
                    let start = std::time::Instant::now();
                    for _ in 0..iters {
                        for g in set.iter() {
                            let _ = black_box(evaluate(
                                black_box(g),
                                &MetricsOptions::without_volume(),
                            ));
                        }
                    }
                    start.elapsed() / set.len().max(1) as u32
                })
            },
        );
    }
}

criterion_group!(benches, bench, random_grasps);
criterion_main!(benches);
