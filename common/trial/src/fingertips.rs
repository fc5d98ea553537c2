//! Fingertips with force/torque sensors, simulated: where each spherical fingertip of a
//! simulated hand touches the object, the force it applies there, and the reading a six-axis
//! sensor under it would give (with Nano17-like noise); and the way back, from readings to
//! contacts (intrinsic contact sensing, `graspopt-sensing`).
//!
//! A fingertip is a collision body of a sphere shape on a finger (the last such body of each
//! finger): `barrett_ft`'s 12 mm spheres, or a user URDF's. Its sensor sits
//! [`FingertipSettings::sensor_depth`] below the sphere's centre along the body's `z` (the
//! direction of the phalanx), axes parallel to the body's, so the fingertip surface in the
//! sensor frame is a sphere centred at `(0, 0, sensor_depth)`.
//!
//! The contact of a touching fingertip is the point of its sphere towards the nearest point of
//! the object (the simulator leaves a gap of at most 0.2 mm), the normal that direction (into
//! the object). The forces are the least-norm forces that hold the object's weight
//! ([`crate::forces`]) plus a grip: a hand squeezes harder than the least it needs. The grip is
//! [`FingertipSettings::grip`] newtons along each normal, projected onto the internal forces
//! (those with no net wrench, the null space of the contacts' force map), so the forces still
//! hold exactly the weight; it is halved until every force is inside its friction cone.
//! Where the fingertips alone cannot hold the weight (the palm or the phalanges carry the
//! object, only one tip touches, or the solver gives up on a degenerate grasp), each touching
//! tip presses [`FingertipSettings::squeeze`] newtons along its normal, as a closed hand
//! does.

use graspopt_quality::forces::{ContactForces, Resisting};
use graspopt_quality::{Contact, FrictionModel};
use graspopt_sensing::{
    ContactKind, FingertipSurface, FingertipWrench, NoContact, SensingSettings, SensorNoise,
    locate, wrench_of,
};
use graspopt_sim::{ContactModel, Hand, LinkShape, Object, TrialOutcome};
use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::TrialError;
use crate::forces::{ForceSettings, analyse_contacts};
use crate::score::{ScoreSettings, grasp_model};

/// How the simulated fingertips sense.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FingertipSettings {
    /// What a fingertip transmits: a soft finger (a force and a moment about the normal, the
    /// thesis's contact model and the default) or a point contact with friction.
    pub kind: ContactKind,
    /// The sensor noise of one sample (Nano17 by default; [`SensorNoise::NONE`] for exact
    /// readings).
    pub noise: SensorNoise,
    /// How many samples a reading averages: the hand holds still while its sensors sample
    /// (a Nano17 is read at 1 kHz or more; 16 samples are 16 ms of it), which divides the
    /// noise by about 4. 1: a single sample. Default 16.
    pub samples: u32,
    /// How far below the sphere's centre the sensor's origin is (m). Default 15 mm.
    pub sensor_depth: f64,
    /// The normal force each touching tip applies when the tips alone cannot hold the
    /// object (N). Default 10 N.
    pub squeeze: f64,
    /// The grip (N) each tip adds along its normal, as internal forces, to the least forces
    /// that hold the weight. Default 10 N (a BH8 fingertip presses up to about 20 N).
    pub grip: f64,
}

impl Default for FingertipSettings {
    fn default() -> Self {
        FingertipSettings {
            kind: ContactKind::SoftFinger,
            noise: SensorNoise::default(),
            samples: 16,
            sensor_depth: 0.015,
            squeeze: 10.0,
            grip: 10.0,
        }
    }
}

/// How readings are turned into contacts for a hand whose fingertips transmit soft-finger
/// contacts (the default [`FingertipSettings`], and the thesis's contact model): the sensing
/// library's defaults with the soft-finger model.
pub fn soft_finger_sensing() -> SensingSettings {
    SensingSettings {
        kind: ContactKind::SoftFinger,
        ..SensingSettings::default()
    }
}

/// A fingertip of a hand: a sphere body on a finger.
#[derive(Debug, Clone, PartialEq)]
pub struct Fingertip {
    pub finger: usize,
    /// Index of the body in [`Hand::links`] (and in a grasp's link poses).
    pub link: usize,
    /// The body's name.
    pub name: String,
    pub radius: f64,
}

/// The fingertips of `hand`: the last sphere body of each finger. A hand without any is an
/// error naming it (a force-sensing hand needs spherical fingertips).
pub fn fingertips(hand: &dyn Hand) -> Result<Vec<Fingertip>, TrialError> {
    let mut tips: Vec<Fingertip> = Vec::new();
    for (i, link) in hand.links().iter().enumerate() {
        if let (Some(finger), LinkShape::Sphere { radius }) = (link.finger, &link.shape) {
            let tip = Fingertip {
                finger,
                link: i,
                name: link.name.clone(),
                radius: *radius,
            };
            match tips.iter_mut().find(|t| t.finger == finger) {
                Some(t) => *t = tip,
                None => tips.push(tip),
            }
        }
    }
    if tips.is_empty() {
        return Err(TrialError::Settings(format!(
            "hand {} has no spherical fingertips to carry force sensors (barrett_ft has)",
            hand.name()
        )));
    }
    tips.sort_by_key(|t| t.finger);
    Ok(tips)
}

/// A contact of a fingertip, in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingertipContact {
    pub point: Point3<f64>,
    /// Unit normal into the object (the fingertip's outward normal).
    pub normal: Vector3<f64>,
    /// The force the fingertip applies to the object (N).
    pub force: Vector3<f64>,
    /// The moment about `normal` the fingertip applies to the object (N m).
    pub torsion: f64,
}

impl FingertipContact {
    /// As a quality contact (position and normal).
    pub fn contact(&self) -> Contact {
        Contact::new(self.point.coords, self.normal)
    }
}

/// One fingertip's sensor in a trial: where it is, its surface, what it read.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorReading {
    pub finger: usize,
    /// The fingertip body's name.
    pub link: String,
    /// The sensor frame in the world.
    pub sensor_pose: Isometry3<f64>,
    /// The fingertip surface in the sensor frame.
    pub surface: FingertipSurface,
    /// The wrench on the fingertip, sensor frame.
    pub reading: FingertipWrench,
}

/// A simulated fingertip: its sensor reading and the contact it was made from.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedFingertip {
    pub sensor: SensorReading,
    pub truth: FingertipContact,
}

/// The friction model the fingertips transmit: the score's friction (and torsion, for soft
/// fingers) with the kind of contact the sensors assume.
pub fn fingertip_model(kind: ContactKind, score: &FrictionModel) -> FrictionModel {
    let (mu, edges, gamma) = match *score {
        FrictionModel::Frictionless => (0.0, 8, 0.0),
        FrictionModel::PointFriction { mu, edges } => (mu, edges, 0.0),
        FrictionModel::SoftFinger { mu, edges, gamma } => (mu, edges, gamma),
    };
    match kind {
        ContactKind::Point => FrictionModel::PointFriction { mu, edges },
        ContactKind::SoftFinger => FrictionModel::SoftFinger { mu, edges, gamma },
    }
}

/// How a force-sensing hand's contacts are scored: as `score` says, but each sensed contact as
/// the one point it is (the mean-point model). A sensor gives one point and normal per
/// fingertip; the surface or patch models would make up the extent of a contact it did not
/// measure (and a surface patch grown from one point jumps with its position near an edge).
pub fn fingertip_score(score: &ScoreSettings) -> ScoreSettings {
    ScoreSettings {
        contacts: ContactModel::MeanPoint,
        ..*score
    }
}

/// `forces` (in equilibrium with the load) plus the grip: `grip` N along each contact's
/// normal projected onto the internal forces (no net wrench about `reference`), halved until
/// every force is inside its friction cone under `model` (at most 20 times, then no grip).
fn with_grip(
    contacts: &[Contact],
    forces: ContactForces,
    model: &FrictionModel,
    reference: &Vector3<f64>,
    grip: f64,
) -> ContactForces {
    let m = contacts.len();
    if m < 2 || grip == 0.0 {
        return forces;
    }
    // The force map: column block i maps contact i's force to its wrench.
    let mut g = nalgebra::DMatrix::<f64>::zeros(6, 3 * m);
    for (i, c) in contacts.iter().enumerate() {
        let r = c.position - reference;
        for k in 0..3 {
            let e = Vector3::ith(k, 1.0);
            let t = r.cross(&e);
            for row in 0..3 {
                g[(row, 3 * i + k)] = e[row];
                g[(3 + row, 3 * i + k)] = t[row];
            }
        }
    }
    let squeeze = nalgebra::DVector::from_iterator(
        3 * m,
        contacts
            .iter()
            .flat_map(|c| (c.normal * grip).iter().copied().collect::<Vec<_>>()),
    );
    let Ok(pinv) = g.clone().pseudo_inverse(1e-12) else {
        return forces;
    };
    let internal = &squeeze - &pinv * (&g * &squeeze);
    let mut scale = 1.0;
    for _ in 0..20 {
        let gripped = ContactForces::new(
            (0..m)
                .map(|i| forces.forces[i] + internal.fixed_rows::<3>(3 * i) * scale)
                .collect(),
            forces.torsions.clone(),
        );
        let inside = graspopt_quality::forces::slip_margins(contacts, model, &gripped)
            .is_ok_and(|margins| margins.iter().all(|s| s.holds(0.0)));
        if inside {
            return gripped;
        }
        scale *= 0.5;
    }
    forces
}

/// The sensor readings of the touching fingertips of a simulated trial (see the module
/// documentation), with noise from `rng`.
pub fn simulate_wrenches<R: rand::Rng + ?Sized>(
    outcome: &TrialOutcome,
    hand: &dyn Hand,
    object: &Object,
    score: &ScoreSettings,
    forces: &ForceSettings,
    settings: &FingertipSettings,
    rng: &mut R,
) -> Result<Vec<SimulatedFingertip>, TrialError> {
    check_settings(settings)?;
    let touching = touching_tips(outcome, hand, object, settings)?;
    let contacts: Vec<Contact> = touching
        .iter()
        .map(|t| Contact::new(t.point.coords, t.normal))
        .collect();
    let model = fingertip_model(settings.kind, &score.model);
    let reference = grasp_model(outcome, object, score)?.reference_point;
    forces.validate()?;
    let applied = applied_forces(&contacts, &model, &reference, object, forces, settings);
    Ok(touching
        .into_iter()
        .enumerate()
        .map(|(i, touch)| sensed(touch, &applied, i, settings, rng))
        .collect())
}

/// The noise valid, the sensor depth finite, the squeeze finite and > 0, the grip finite
/// and >= 0.
fn check_settings(settings: &FingertipSettings) -> Result<(), TrialError> {
    settings.noise.validate().map_err(sensing_settings)?;
    if !(settings.sensor_depth.is_finite()
        && settings.squeeze.is_finite()
        && settings.squeeze > 0.0
        && settings.grip.is_finite()
        && settings.grip >= 0.0)
    {
        return Err(TrialError::Settings(format!(
            "sensor_depth must be finite, squeeze finite and > 0 and grip finite and >= 0, got {}, {} and {}",
            settings.sensor_depth, settings.squeeze, settings.grip
        )));
    }
    Ok(())
}

/// A fingertip that touches the object: its sensor's pose, and the contact point and normal
/// (into the object) on the tip's sphere.
struct Touch {
    tip: Fingertip,
    sensor_pose: Isometry3<f64>,
    point: Point3<f64>,
    normal: Vector3<f64>,
}

/// The fingertips whose link touches the object, each touching it at the point of its
/// sphere nearest the object.
fn touching_tips(
    outcome: &TrialOutcome,
    hand: &dyn Hand,
    object: &Object,
    settings: &FingertipSettings,
) -> Result<Vec<Touch>, TrialError> {
    let grasp = &outcome.grasp;
    let mut touching = Vec::new();
    for tip in fingertips(hand)? {
        if !grasp.link_touching.get(tip.link).copied().unwrap_or(false) {
            continue;
        }
        let Some(body) = grasp.link_poses.get(tip.link) else {
            continue;
        };
        let centre = Point3::from(body.translation.vector);
        let nearest = object.closest_point(&centre)?;
        let to = nearest.point - centre;
        if to.norm() <= 0.0 {
            continue;
        }
        let normal = to.normalize();
        let sensor_pose = body * Translation3::new(0.0, 0.0, -settings.sensor_depth);
        let point = centre + normal * tip.radius;
        touching.push(Touch {
            tip,
            sensor_pose,
            point,
            normal,
        });
    }
    Ok(touching)
}

/// The forces the tips apply: the least forces that hold the object plus the grip, or, when
/// none hold it, a squeeze along each normal. Least forces that are unavailable (a solver
/// that stopped on a degenerate grasp) count as "cannot resist": the tips squeeze.
fn applied_forces(
    contacts: &[Contact],
    model: &FrictionModel,
    reference: &Vector3<f64>,
    object: &Object,
    forces: &ForceSettings,
    settings: &FingertipSettings,
) -> ContactForces {
    let held = match analyse_contacts(contacts, model, reference, object, forces, None) {
        Ok(g) => match g.resisting {
            Resisting::Forces { forces, .. } if !contacts.is_empty() => Some(forces),
            _ => None,
        },
        Err(_) => None,
    };
    match held {
        Some(least) => with_grip(contacts, least, model, reference, settings.grip),
        None => ContactForces::without_torsion(
            contacts
                .iter()
                .map(|c| c.normal * settings.squeeze)
                .collect(),
        ),
    }
}

/// What the sensor of `touch` (the `i`-th touching tip) reads of the force `applied` to it,
/// with noise.
fn sensed<R: rand::Rng + ?Sized>(
    touch: Touch,
    applied: &ContactForces,
    i: usize,
    settings: &FingertipSettings,
    rng: &mut R,
) -> SimulatedFingertip {
    let Touch {
        tip,
        sensor_pose,
        point,
        normal,
    } = touch;
    let truth = FingertipContact {
        point,
        normal,
        force: applied.forces[i],
        torsion: applied.torsions[i],
    };
    let surface = FingertipSurface::Sphere {
        center: [0.0, 0.0, settings.sensor_depth],
        radius: tip.radius,
        base_z: None,
    };
    let inverse = sensor_pose.inverse();
    let exact = wrench_of(
        &surface,
        &(inverse * point),
        &(inverse * truth.force),
        truth.torsion,
    );
    let reading = sample_mean(&settings.noise, &exact, settings.samples, rng);
    SimulatedFingertip {
        sensor: SensorReading {
            finger: tip.finger,
            link: tip.name,
            sensor_pose,
            surface,
            reading,
        },
        truth,
    }
}

/// The mean of `samples` noisy samples of `exact` (one sample when `samples` is 0 or 1).
fn sample_mean<R: rand::Rng + ?Sized>(
    noise: &SensorNoise,
    exact: &FingertipWrench,
    samples: u32,
    rng: &mut R,
) -> FingertipWrench {
    let n = samples.max(1);
    let mut sum = FingertipWrench {
        force: Vector3::zeros(),
        torque: Vector3::zeros(),
    };
    for _ in 0..n {
        let r = noise.apply(exact, rng);
        sum.force += r.force;
        sum.torque += r.torque;
    }
    FingertipWrench {
        force: sum.force / f64::from(n),
        torque: sum.torque / f64::from(n),
    }
}

/// The contact a sensor reading stands for, in the world frame, or why there is none.
pub fn sense(
    sensor: &SensorReading,
    settings: &SensingSettings,
) -> Result<FingertipContact, NoContact> {
    let c = locate(&sensor.surface, &sensor.reading, settings)?;
    let pose = &sensor.sensor_pose;
    Ok(FingertipContact {
        point: pose * c.point,
        normal: pose * c.normal.into_inner(),
        force: pose * c.force,
        torsion: c.torsion,
    })
}

fn sensing_settings(e: graspopt_sensing::SensingError) -> TrialError {
    TrialError::Settings(format!("sensor noise: {e}"))
}
