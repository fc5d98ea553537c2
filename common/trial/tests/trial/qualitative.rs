//! The qualitative results of thesis chapter 4 (figures 4.3-4.8), asserted on the simulator.
//!
//! Common set-up unless a test says otherwise: the Barrett hand at spread 0 (F1 and F2 side
//! by side facing F3, the hand's default), the built-in sphere (radius 35 mm), the default
//! trial space around [`reference_pose`] (approach offsets `[-0.16, 0.02]` m: from beyond
//! the fingertips' reach to the palm pressing the object; vertical offsets `+-45` mm), the
//! default scoring (surface contact model, soft fingers mu 0.5 with 8 cone edges and
//! gamma 5 mm, palm contacts included, torques about the object's centre of mass divided by
//! its bounding radius).
//!
//! The Barrett hand is the corrected BH8 (distal links bent 50 degrees at rest, as in
//! OpenRAVE's model); with it and the exact contact regions the width of the informative BW
//! range (claim 1) and BW's continuity at the sphere's force-closure boundaries (claim 2) hold.
//! One part is not reproduced; its test asserts it as stated and is `#[ignore]`d with the
//! reason (run it with `cargo test -p graspopt-trial --test trial -- --ignored qualitative::`): the
//! world-frame argmax (claim 3). The tests next to it assert the parts that hold.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, ParamKind, ParamSpec, TrialSpace, reference_pose};
use graspopt_trial::scan::{linspace, scan_grid, worker_count};
use graspopt_trial::{Evaluation, Evaluator, ReferenceFrame};

/// Step of the 1D approach scans (61 samples over the default range).
const APPROACH_STEP: f64 = 0.003;
/// Step of the 1D vertical scans (37 samples over the sphere's default range).
const VERTICAL_STEP: f64 = 0.0025;

/// An evaluator scanning one parameter of `object` between `lower` and `upper`, around the
/// default reference pose, with the Barrett hand and the default scoring.
fn evaluator(object: &str, kind: ParamKind, lower: f64, upper: f64) -> Evaluator {
    let object = Object::by_name(object).unwrap();
    let space = TrialSpace::new(
        reference_pose(&object),
        vec![ParamSpec { kind, lower, upper }],
    )
    .unwrap();
    Evaluator::new(object, hand_by_name("barrett").unwrap(), space)
}

/// The default bounds of `kind` for `object`.
fn default_range(object: &str, kind: ParamKind) -> (f64, f64) {
    let object = Object::by_name(object).unwrap();
    let spec = graspopt_sim::pose::default_bounds(&object)
        .into_iter()
        .find(|p| p.kind == kind)
        .unwrap();
    (spec.lower, spec.upper)
}

/// `lower..=upper` in steps of (about) `step`.
fn grid(lower: f64, upper: f64, step: f64) -> Vec<f64> {
    linspace(lower, upper, ((upper - lower) / step).round() as usize + 1)
}

/// Every trial of a 1D scan over `xs`, in parallel on all cores, in order (the full
/// evaluation: [`scan_grid`] keeps only the scores, these tests also look at the contacts).
fn evaluate_all(ev: &Evaluator, xs: &[f64]) -> Vec<Evaluation> {
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Evaluation>>> = Mutex::new(vec![None; xs.len()]);
    std::thread::scope(|scope| {
        for _ in 0..worker_count(0, xs.len()) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= xs.len() {
                        break;
                    }
                    let e = ev.evaluate(&[xs[i]]).unwrap();
                    results.lock().unwrap()[i] = Some(e);
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap()
        .into_iter()
        .flatten()
        .collect()
}

/// What the claims look at in one trial of a 1D scan.
#[derive(Debug, Clone)]
struct Sample {
    x: f64,
    /// The score: BW when the hand touches, the no-contact score otherwise.
    bw: f64,
    /// Largest Sphere (epsilon), 0 without force closure or contact.
    ls: f64,
    fc: bool,
    /// Some modelled contact (the BW of the contacts is defined).
    touched: bool,
    /// The palm touches the object.
    palm: bool,
    /// Which links touch (palm first).
    links: Vec<bool>,
    /// Offset along the approach axis from the object's centre to the centroid of the
    /// fingers' mean contact points (`None` without finger contact).
    contact_offset: Option<f64>,
}

fn sample(ev: &Evaluator, e: &Evaluation) -> Sample {
    let approach = ev.space.reference.rotation * nalgebra::Vector3::z();
    let centre = ev.object.centre_of_mass();
    let points: Vec<_> = e
        .outcome
        .fingers
        .iter()
        .filter_map(|f| f.mean_point())
        .collect();
    let contact_offset = (!points.is_empty()).then(|| {
        let sum = points
            .iter()
            .fold(nalgebra::Vector3::zeros(), |s, p| s + (p.position - centre));
        (sum / points.len() as f64).dot(&approach)
    });
    let m = e.score.metrics;
    Sample {
        x: e.params[0],
        bw: e.score.score,
        ls: m.map_or(0.0, |m| m.epsilon()),
        fc: m.is_some_and(|m| m.force_closure()),
        touched: m.is_some(),
        palm: e.outcome.palm.touches(),
        links: e.outcome.grasp.link_touching.clone(),
        contact_offset,
    }
}

fn scan_1d(ev: &Evaluator, xs: &[f64]) -> Vec<Sample> {
    evaluate_all(ev, xs).iter().map(|e| sample(ev, e)).collect()
}

/// The sphere scanned along the approach axis (thesis figure 4.3), up to the last offset
/// before the palm reaches the sphere: the thesis's curve is negative on both sides of its
/// force-closure window, so its hand never pressed the palm on the sphere; with the palm
/// pressing, the grasp is force-closure whatever the fingers do.
fn sphere_approach_scan() -> (Evaluator, Vec<Sample>) {
    let (lo, hi) = default_range("sphere", ParamKind::Approach);
    let ev = evaluator("sphere", ParamKind::Approach, lo, hi);
    let mut samples = scan_1d(&ev, &grid(lo, hi, APPROACH_STEP));
    let palm = samples.iter().position(|s| s.palm).unwrap_or(samples.len());
    samples.truncate(palm);
    (ev, samples)
}

/// Widths (metres, samples times step) of the claim-1 ranges of a scan.
#[derive(Debug)]
struct Widths {
    /// Where LS > 0.
    ls: f64,
    /// Where the hand touches (BW finite).
    touched: f64,
    /// Where BW is informative (see [`informative`]).
    informative: f64,
}

/// Which samples carry information in BW: the force-closure ones, and the non-force-closure
/// touching ones from which BW rises strictly, sample after sample, all the way into a
/// force-closure region: each step towards it gains more than 1% of the BW span of the
/// touching samples. A plateau (one finger on the sphere: the same BW wherever it touches,
/// its normal passing through the centre) is not informative, nor is anything beyond it.
fn informative(samples: &[Sample]) -> Vec<bool> {
    let touched: Vec<f64> = samples.iter().filter(|s| s.touched).map(|s| s.bw).collect();
    let span = touched.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - touched.iter().copied().fold(f64::INFINITY, f64::min);
    let gain = 0.01 * span;
    let mut info: Vec<bool> = samples.iter().map(|s| s.fc).collect();
    let n = samples.len();
    for i in (0..n).filter(|&i| samples[i].fc) {
        // Outwards on each side while BW keeps falling by more than `gain` per step.
        for dir in [-1_isize, 1] {
            let mut inner = i;
            loop {
                let j = inner as isize + dir;
                if j < 0 || j >= n as isize {
                    break;
                }
                let j = j as usize;
                let s = &samples[j];
                if s.fc || !s.touched || s.bw >= samples[inner].bw - gain {
                    break;
                }
                info[j] = true;
                inner = j;
            }
        }
    }
    info
}

fn widths(samples: &[Sample], step: f64) -> Widths {
    let count = |f: &dyn Fn(usize) -> bool| (0..samples.len()).filter(|&i| f(i)).count() as f64;
    let info = informative(samples);
    Widths {
        ls: count(&|i| samples[i].ls > 0.0) * step,
        touched: count(&|i| samples[i].touched) * step,
        informative: count(&|i| info[i]) * step,
    }
}

/// The touching sample of highest BW.
fn best(samples: &[Sample]) -> &Sample {
    samples
        .iter()
        .filter(|s| s.touched)
        .max_by(|a, b| a.bw.total_cmp(&b.bw))
        .unwrap()
}

fn table(samples: &[Sample]) -> String {
    samples
        .iter()
        .map(|s| {
            format!(
                "{:+.4} bw {:+.4} ls {:.4} fc {} palm {} offset {:?}\n",
                s.x, s.bw, s.ls, s.fc, s.palm, s.contact_offset
            )
        })
        .collect()
}

/// Claim 1, the parts that hold (thesis 4.2, figure 4.3: "both LS and BW exhibit a smooth
/// behavior with a clear maximum at about the center of the object ... It is visible a
/// smooth transition from positive (force-closure) to negative (non-force-closure)
/// values").
///
/// Set-up: [`sphere_approach_scan`] (sphere, approach axis from -0.16 m to the palm's
/// first contact, 3 mm steps, surface model, object frame, torque scale = bounding radius).
/// Asserts: BW is finite at every touching sample and positive exactly where LS is; the
/// scan has at least two touching non-force-closure samples before its force-closure
/// window over which BW rises strictly (by more than 1% of its span per step) into that
/// window (two, so that BW rises within the negative part, not only across the sign); the
/// best BW is "at the centre of the object": the centroid of the best grasp's finger
/// contacts lies within a quarter radius of the sphere's centre along the approach axis
/// (the contacts straddle the equator).
#[test]
fn sphere_approach_bw_is_finite_rises_into_force_closure_and_peaks_at_the_centre() {
    let (ev, samples) = sphere_approach_scan();
    let t = table(&samples);
    for s in samples.iter().filter(|s| s.touched) {
        assert!(s.bw.is_finite(), "{t}");
        assert_eq!(s.bw > 0.0, s.ls > 0.0, "at {}: {t}", s.x);
    }
    let first_fc = samples.iter().position(|s| s.fc).expect("no force closure");
    let info = informative(&samples);
    let lead_in = (0..first_fc)
        .filter(|&i| samples[i].touched && info[i])
        .count();
    assert!(
        lead_in >= 2,
        "BW does not rise into force closure before it: {t}"
    );
    let top = best(&samples);
    let radius = ev.object.bounding_sphere().1;
    let offset = top.contact_offset.unwrap();
    assert!(
        offset.abs() <= radius / 4.0,
        "best BW {} at {} with contacts {offset} m from the centre: {t}",
        top.bw,
        top.x
    );
}

/// Claim 1 as stated (thesis 4.2: "whereas the classical metrics only provide results in
/// the force closure range (about 30mm), our metric provides sensible results in a range of
/// more than 80mm"): on the sphere's approach scan, BW is informative (see [`informative`]:
/// force closure, or strictly rising into it, not a plateau) over at least twice the width
/// where LS > 0. Set-up: as in the test above.
///
/// Holds with the corrected BH8 (distal links bent 50 degrees at rest, OpenRAVE's model),
/// narrowly: on this scan (3 mm steps up to the palm's first contact at +0.008 m) LS > 0 over
/// 3 mm (one sample, +0.005) and BW is informative over 12 mm (rising from -0.075 at -0.001
/// into force closure; BW is finite over 147 mm). Over the 93 mm from -0.139 to -0.046 m the
/// open hand would intersect the sphere (its fingertips come within 5 mm of the approach
/// axis) and is retreated until F3's fingertip touches it: the same one-finger grasp at every
/// offset, a plateau (-0.93), not informative. Over the full range (palm pressing included)
/// LS > 0 over 16 mm and the hand touches over 160 mm (1 mm steps); with straight distal
/// links it was 157 mm and 168 mm, and this claim failed (the contacts did not sweep over
/// the sphere, so force closure spanned the whole finger-contact range). The thesis reports
/// LS over about 30 mm and BW over more than 80 mm.
#[test]
fn sphere_approach_bw_is_informative_over_twice_the_force_closure_range() {
    let (_, samples) = sphere_approach_scan();
    let w = widths(&samples, APPROACH_STEP);
    assert!(
        samples
            .iter()
            .filter(|s| s.touched)
            .all(|s| s.bw.is_finite()),
        "{}",
        table(&samples)
    );
    assert!(
        w.informative >= 2.0 * w.ls,
        "LS > 0 over {} m, BW finite over {} m, informative over {} m\n{}",
        w.ls,
        w.touched,
        w.informative,
        table(&samples)
    );
}

/// Claim 2 (thesis 4.2, figures 4.3-4.5: BW "changes sign where force closure begins", with
/// "a smooth transition from positive (force-closure) to negative (non-force-closure)
/// values, which provide continuity").
///
/// Scans: the sphere along the approach axis (3 mm steps, palm contacts included) and along
/// the vertical axis at the reference approach (2.5 mm steps), the rotated cuboid and the
/// star prism along the approach axis (3 mm); default scoring. Asserts, at every sample,
/// BW > 0 exactly when the grasp is force-closure (so at every pair of consecutive samples
/// where force closure switches, BW switches sign), with at least one switch on each
/// sphere scan. The sign follows from BW's definition; what can fail is the continuity the
/// thesis shows on figure 4.3: on the sphere's approach scan, at each switch where the same
/// links touch on both sides, the boundary is bisected to below 1 um and BW on both sides
/// of it must be within 1% of the scan's BW span of zero (no jump at the boundary).
///
/// Not asserted on the other scans: the cuboid's and the star's edges make BW jump (thesis
/// 4.2).
///
/// History: with contact clouds sampled on a 2.5 mm grid of the links, BW jumped at the
/// sphere's boundaries (-0.0064 to +0.0011 on the vertical scan, -0.066 to +0.033 on the
/// approach scan with the bent distal links), each time where a cloud sample crossed the 1 mm
/// contact distance and moved a finger's mean contact by up to 5 mm. The exact contact
/// regions (issue 16) made both continuous.
#[test]
fn bw_changes_sign_and_stays_continuous_where_force_closure_switches() {
    sign_and_continuity(true);
}

/// The checks of claim 2; the continuity one only when `check_continuity`.
fn sign_and_continuity(check_continuity: bool) {
    let scans = [
        (
            "sphere",
            ParamKind::Approach,
            APPROACH_STEP,
            check_continuity,
        ),
        (
            "sphere",
            ParamKind::Vertical,
            VERTICAL_STEP,
            check_continuity,
        ),
        ("rotated_cuboid", ParamKind::Approach, APPROACH_STEP, false),
        ("star_prism", ParamKind::Approach, APPROACH_STEP, false),
    ];
    for (object, kind, step, continuity) in scans {
        let (lo, hi) = default_range(object, kind);
        let ev = evaluator(object, kind, lo, hi);
        let samples = scan_1d(&ev, &grid(lo, hi, step));
        let t = table(&samples);
        for s in &samples {
            assert_eq!(s.bw > 0.0, s.fc, "{object} {kind:?} at {}: {t}", s.x);
        }
        let switches: Vec<usize> = (1..samples.len())
            .filter(|&i| samples[i].fc != samples[i - 1].fc)
            .collect();
        if object == "sphere" {
            assert!(!switches.is_empty(), "{object} {kind:?}: no switch: {t}");
        }
        if !continuity {
            continue;
        }
        let span = samples
            .iter()
            .filter(|s| s.touched)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
                (a.min(s.bw), b.max(s.bw))
            });
        let tolerance = 0.01 * (span.1 - span.0);
        let mut checked = 0;
        for i in switches {
            let (a, b) = (&samples[i - 1], &samples[i]);
            if a.links != b.links {
                continue;
            }
            let (mut lo, mut hi) = (a.x, b.x);
            let (mut bw_lo, mut bw_hi) = (a.bw, b.bw);
            while hi - lo > 1e-6 {
                let mid = 0.5 * (lo + hi);
                let m = sample(&ev, &ev.evaluate(&[mid]).unwrap());
                assert_eq!(m.bw > 0.0, m.fc);
                if m.fc == a.fc {
                    (lo, bw_lo) = (mid, m.bw);
                } else {
                    (hi, bw_hi) = (mid, m.bw);
                }
            }
            assert!(
                bw_lo.abs() <= tolerance && bw_hi.abs() <= tolerance,
                "{object} {kind:?}: BW jumps from {bw_lo} to {bw_hi} at the force-closure \
                 boundary {lo}..{hi} (tolerance {tolerance})"
            );
            checked += 1;
        }
        assert!(checked > 0, "{object} {kind:?}: no continuity check: {t}");
    }
}

/// The cells of a 2D scan of the sphere (approach x vertical, default bounds, 15 x 15)
/// holding its maximum score (exact ties: the same maximum), with the given frame and the
/// torque scale fixed at 0.05 m (as `graspopt experiment metrics` for figure 4.8).
fn argmax_cells(frame: ReferenceFrame) -> (Vec<Vec<f64>>, f64) {
    let object = Object::by_name("sphere").unwrap();
    let space = TrialSpace::approach_vertical_2d(&object);
    let axes: Vec<Vec<f64>> = space
        .bounds()
        .iter()
        .map(|&(lo, hi)| linspace(lo, hi, 15))
        .collect();
    let mut ev = Evaluator::new(object, hand_by_name("barrett").unwrap(), space);
    ev.score.frame = frame;
    ev.score.torque_scale = Some(0.05);
    let points = scan_grid(&ev, &axes, 0, &|_| {}).unwrap();
    let top = points
        .iter()
        .map(|p| p.score.score)
        .fold(f64::NEG_INFINITY, f64::max);
    let cells = points
        .iter()
        .filter(|p| p.score.score == top)
        .map(|p| p.params.clone())
        .collect();
    (cells, top)
}

/// The hand's frame at the reference pose: fixed for the whole scan, as the thesis requires
/// ("as long as the reference frame chosen at the beginning of the experiment remains
/// unchanged throughout the experiment's duration, any frame can be chosen").
fn hand_reference_frame() -> ReferenceFrame {
    let origin = reference_pose(&Object::by_name("sphere").unwrap())
        .translation
        .vector;
    ReferenceFrame::Point([origin.x, origin.y, origin.z])
}

/// Claim 3 (thesis 4.4, figure 4.8: "the position of the maximum value will generate the
/// same grasp hierarchy independently of the changes to the reference frames"), for the
/// object frame and the hand's frame.
///
/// Set-up: the sphere, approach x vertical over the default bounds, 15 x 15 grid, surface
/// model, torque scale fixed at 0.05 m. The hand frame is the palm frame at the reference
/// pose (fixed across the scan; its origin 85 mm before the centre along the approach axis).
/// Asserts the set of maximal cells is the same in both frames.
#[test]
fn argmax_of_the_2d_sphere_scan_is_the_same_in_the_object_and_hand_frames() {
    let (object, top) = argmax_cells(ReferenceFrame::Object);
    let (hand, hand_top) = argmax_cells(hand_reference_frame());
    assert_eq!(
        object, hand,
        "object frame: BW {top} at {object:?}; hand frame: {hand_top} at {hand:?}"
    );
}

/// Claim 3 for the world frame (figure 4.8, left): the set of maximal cells of the 2D scan
/// is the same in the world and object frames. Set-up as above.
///
/// Not reproduced: the world frame moves the maximum two cells down (object frame: BW 0.2996
/// at approach 0.02, vertical 0; world frame: 0.2491 at approach 0.02, vertical -12.9 mm). On
/// the seven objects (`cargo run --release -p graspopt-trial --features tools --example frames`, table in
/// docs/benchmarks.md) the world frame moves the 2D argmax by 0 to 7 cells, the palm frame by
/// 0 or 1 on six objects (8 on the mug). The best grasps form a flat ridge along the vertical
/// axis (palm pressing, fingers closed); moving the torque reference shears the wrench space,
/// the largest inscribed ball is not invariant under a shear, and the ridge's top moves along
/// it. The thesis's invariance is empirical and holds here only up to the width of a flat
/// maximum.
#[test]
#[ignore = "not reproduced: the world frame moves the argmax two cells (12.9 mm) down the ridge of best grasps (see the doc comment)"]
fn argmax_of_the_2d_sphere_scan_is_the_same_in_the_world_and_object_frames() {
    let (object, top) = argmax_cells(ReferenceFrame::Object);
    let (world, world_top) = argmax_cells(ReferenceFrame::World);
    assert_eq!(
        object, world,
        "object frame: BW {top} at {object:?}; world frame: {world_top} at {world:?}"
    );
}
