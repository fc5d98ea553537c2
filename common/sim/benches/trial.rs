//! One full trial (close the Barrett hand, contact clouds, all three contact models including the
//! surface model) on the mug at its default reference pose.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_sim::pose::reference_pose;
use graspopt_sim::{BarrettOracle, ContactModelSettings, Object, run_trial};

fn trial(c: &mut Criterion) {
    let mug = Object::by_name("mug").expect("built-in mug");
    let hand = BarrettOracle::default();
    let pose = reference_pose(&mug);
    let settings = ContactModelSettings::default();
    let check = run_trial(&mug, &hand, &pose, &settings).expect("trial");
    assert_eq!(check.fingers_in_contact(), 3);
    c.bench_function("trial_mug_barrett_default_pose", |b| {
        b.iter(|| run_trial(black_box(&mug), &hand, black_box(&pose), &settings).expect("trial"))
    });
}

criterion_group!(benches, trial);
criterion_main!(benches);
