//! One full scored trial on the mug at its reference pose: close the Barrett hand,
//! extract contact clouds, build the surface model, compute BW. Then, on that trial's
//! outcome, the score alone and the force analysis alone (what a metric agent adds to every
//! result: the least forces that hold the object's weight, one Clarabel solve over the
//! surface model's contacts).
//!
//! Run: `cargo bench -p graspopt-trial --bench trial`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, TrialSpace};
use graspopt_trial::forces::{ForceSettings, analyse_outcome};
use graspopt_trial::{Evaluator, score_outcome};

fn bench(c: &mut Criterion) {
    let object = Object::by_name("mug").expect("mug");
    let space = TrialSpace::approach_vertical_2d(&object);
    let ev = Evaluator::new(
        object,
        hand_by_name("barrett").expect("hand"),
        space.clone(),
    );
    let x = [-0.09, 0.0];
    let e = ev.evaluate(&x).expect("trial");
    assert!(
        e.score.contacts > 0,
        "the benchmark grasp must touch the mug"
    );
    c.bench_function("scored trial, mug, barrett, surface model, BW", |b| {
        b.iter(|| ev.evaluate(black_box(&x)))
    });
    c.bench_function("score of that outcome alone (surface model, BW)", |b| {
        b.iter(|| score_outcome(black_box(&e.outcome), &ev.object, &ev.score))
    });
    let forces = ForceSettings::default();
    analyse_outcome(&e.outcome, &ev.object, &ev.score, &forces).expect("the force analysis");
    println!("the trial's score counts {} contacts", e.score.contacts);
    c.bench_function("force analysis of that outcome (0.5 kg, Clarabel)", |b| {
        b.iter(|| analyse_outcome(black_box(&e.outcome), &ev.object, &ev.score, &forces))
    });
    // The same trial with the hand-written BH8 (the URDF hand's test oracle): what the
    // URDF hand's general kinematics cost.
    let object = Object::by_name("mug").expect("mug");
    let oracle = Evaluator::new(
        object,
        Box::new(graspopt_sim::BarrettOracle::default()),
        space,
    );
    c.bench_function(
        "scored trial, mug, barrett oracle, surface model, BW",
        |b| b.iter(|| oracle.evaluate(black_box(&x))),
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
