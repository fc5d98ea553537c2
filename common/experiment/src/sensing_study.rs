//! The force-sensing round trip (issue #20's figures): on simulated trials of the seven objects
//! with `barrett_ft` (the BH8 with spherical fingertips), each touching fingertip's contact is
//! turned into a force/torque sensor reading (with or without Nano17-like noise) and found
//! again from it; how far the found contacts are from the true ones, and how far BW scored on
//! the found contacts is from BW on the true ones.
//!
//! Trials are uniform random points of each object's default 2D space (approach distance and
//! height, the runs' default), from a seeded generator (the noise has a generator of its own,
//! so runs that differ in noise only see the same trials). Both scores use the metric agent's
//! path: the contacts as one-point clouds per fingertip, scored with the default settings and
//! the fingertip contact model ([`graspopt_trial::fingertips::fingertip_score`]).

use graspopt_sensing::{SensingSettings, SensorNoise};
use graspopt_sim::ContactModelSettings;
use graspopt_sim::{Object, ParamKind};
use graspopt_trial::ScoreSettings;
use graspopt_trial::fingertips::{
    FingertipContact, FingertipSettings, fingertip_score, sense, simulate_wrenches,
};
use graspopt_trial::forces::ForceSettings;
use graspopt_trial::measured::{MeasuredTrial, score_measured};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::ExperimentError;
use crate::scans::evaluator;
use crate::target::median;

/// BW on found contacts counts as agreeing when within this fraction of BW on the true ones.
pub const BW_AGREEMENT: f64 = 0.02;

/// What the study runs.
#[derive(Debug, Clone, PartialEq)]
pub struct SensingStudySettings {
    /// Built-in objects.
    pub objects: Vec<String>,
    /// Random trials per object.
    pub trials: usize,
    pub seed: u64,
    /// The sensors' noise, per sample.
    pub noise: SensorNoise,
    /// Samples averaged per reading.
    pub samples: u32,
    /// How readings become contacts.
    pub sensing: SensingSettings,
}

impl Default for SensingStudySettings {
    fn default() -> Self {
        SensingStudySettings {
            objects: Object::names().iter().map(|s| s.to_string()).collect(),
            trials: 200,
            seed: 0,
            noise: SensorNoise::default(),
            samples: FingertipSettings::default().samples,
            sensing: graspopt_trial::fingertips::soft_finger_sensing(),
        }
    }
}

/// One object's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectRoundTrip {
    pub object: String,
    pub trials: usize,
    /// Fingertip contacts simulated, and how many readings gave no contact.
    pub tips: usize,
    pub refused: usize,
    /// Distance between found and true contact points (m), per found contact.
    pub position_errors: Vec<f64>,
    /// Angle between found and true normals (rad), per found contact.
    pub normal_errors: Vec<f64>,
    /// Trials in force closure on the true contacts, and of those, how many have BW on the
    /// found contacts within [`BW_AGREEMENT`] of BW on the true ones.
    pub force_closure: usize,
    pub bw_agree: usize,
    /// Largest relative BW difference on force-closure trials.
    pub bw_worst: f64,
}

impl ObjectRoundTrip {
    /// No figures yet for `object` and its `trials`.
    fn empty(object: &str, trials: usize) -> Self {
        ObjectRoundTrip {
            object: object.to_string(),
            trials,
            tips: 0,
            refused: 0,
            position_errors: Vec::new(),
            normal_errors: Vec::new(),
            force_closure: 0,
            bw_agree: 0,
            bw_worst: 0.0,
        }
    }

    pub fn median_position(&self) -> Option<f64> {
        median(&self.position_errors)
    }
    pub fn median_normal(&self) -> Option<f64> {
        median(&self.normal_errors)
    }
    pub fn max_position(&self) -> Option<f64> {
        self.position_errors.iter().copied().reduce(f64::max)
    }
    pub fn max_normal(&self) -> Option<f64> {
        self.normal_errors.iter().copied().reduce(f64::max)
    }
}

/// The angle between two unit vectors, accurate near 0 (acos loses half the digits there).
fn angle(a: &nalgebra::Vector3<f64>, b: &nalgebra::Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Runs the study.
pub fn round_trip(
    settings: &SensingStudySettings,
) -> Result<Vec<ObjectRoundTrip>, ExperimentError> {
    let tips_settings = FingertipSettings {
        noise: settings.noise,
        samples: settings.samples,
        kind: settings.sensing.kind,
        ..FingertipSettings::default()
    };
    let score = fingertip_score(&ScoreSettings::default());
    let contacts = ContactModelSettings::default();
    let forces = ForceSettings::default();
    // Trials and noise from generators of their own: runs that differ in noise only see the
    // same trials.
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut noise_rng = ChaCha8Rng::seed_from_u64(settings.seed ^ 0x5EED_0FF0);
    let mut rows = Vec::new();
    for name in &settings.objects {
        let ev = evaluator(
            "barrett_ft",
            name,
            &[ParamKind::Approach, ParamKind::Vertical],
        )?;
        let mut row = ObjectRoundTrip::empty(name, settings.trials);
        for _ in 0..settings.trials {
            let u: Vec<f64> = (0..ev.space.dim()).map(|_| rng.random::<f64>()).collect();
            let params = ev.space.from_unit(&u)?;
            let e = ev.evaluate(&params)?;
            let tips = simulate_wrenches(
                &e.outcome,
                ev.hand.as_ref(),
                &ev.object,
                &score,
                &forces,
                &tips_settings,
                &mut noise_rng,
            )?;
            let mut truth: Vec<(usize, String, FingertipContact)> = Vec::new();
            let mut found = Vec::new();
            for tip in &tips {
                row.tips += 1;
                let key = (tip.sensor.finger, tip.sensor.link.clone());
                truth.push((key.0, key.1.clone(), tip.truth));
                match sense(&tip.sensor, &settings.sensing) {
                    Ok(c) => {
                        row.position_errors.push((c.point - tip.truth.point).norm());
                        row.normal_errors.push(angle(&c.normal, &tip.truth.normal));
                        found.push((key.0, key.1, c));
                    }
                    Err(_) => row.refused += 1,
                }
            }
            if truth.is_empty() {
                continue;
            }
            let palm = e.outcome.grasp.palm_pose;
            let hand = ev.hand.name();
            let scored = |c: &[(usize, String, FingertipContact)]| {
                let m = MeasuredTrial::from_fingertips(hand, palm, c, None);
                score_measured(&m, &ev.object, &contacts, &score).map(|(s, _)| s)
            };
            let true_score = scored(&truth)?;
            if !true_score.metrics.is_some_and(|m| m.force_closure()) {
                continue;
            }
            row.force_closure += 1;
            let found_score = scored(&found)?;
            let rel = (found_score.score - true_score.score).abs() / true_score.score.abs();
            row.bw_worst = row.bw_worst.max(rel);
            if rel <= BW_AGREEMENT {
                row.bw_agree += 1;
            }
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The study's figures as a markdown table: per object, the fingertip contacts, the readings
/// refused, the median and largest position (mm) and normal (degrees) errors, and on
/// force-closure trials the share whose BW agrees within [`BW_AGREEMENT`], with the worst
/// relative difference.
pub fn markdown_table(rows: &[ObjectRoundTrip]) -> String {
    let mut out = String::from(
        "| object | trials | tip contacts | refused | position error median / max (mm) | normal error median / max (deg) | force-closure trials | BW within 2% | worst BW difference |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.3e}", v * 1e3));
    let deg = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.3e}", v.to_degrees()));
    let mut all = ObjectRoundTrip::empty("all", 0);
    for r in rows {
        all.trials += r.trials;
        all.tips += r.tips;
        all.refused += r.refused;
        all.position_errors.extend(&r.position_errors);
        all.normal_errors.extend(&r.normal_errors);
        all.force_closure += r.force_closure;
        all.bw_agree += r.bw_agree;
        all.bw_worst = all.bw_worst.max(r.bw_worst);
    }
    for r in rows.iter().chain(std::iter::once(&all)) {
        let share = if r.force_closure == 0 {
            "-".to_string()
        } else {
            format!(
                "{} ({:.1}%)",
                r.bw_agree,
                100.0 * r.bw_agree as f64 / r.force_closure as f64
            )
        };
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} / {} | {} / {} | {} | {} | {:.2}% |\n",
            r.object,
            r.trials,
            r.tips,
            r.refused,
            mm(r.median_position()),
            mm(r.max_position()),
            deg(r.median_normal()),
            deg(r.max_normal()),
            r.force_closure,
            share,
            100.0 * r.bw_worst
        ));
    }
    out
}
