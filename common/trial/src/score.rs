//! Scoring a trial outcome.
//!
//! The contacts of the chosen contact model (per finger, optionally the palm) become
//! wrenches about a reference point, torques divided by a torque scale (by default the
//! object's centre of mass and its bounding radius), and one metric of their hull is the
//! score.
//!
//! **A trial that touches nothing** (no modelled contact) has no wrench space. It scores
//! `-(B + 1) - min(d / rho, 1)`, where `B` bounds the norm of any contact wrench on this
//! object (so `-B` is below the BW of every touching grasp), `d` is the closed hand's
//! smallest distance to the object and `rho` the torque scale: finite, always below any
//! touching grasp, and better the nearer the hand came, so an optimiser still learns from
//! it. Scored by another metric (epsilon, volume: 0 without force closure), it scores 0.

use graspopt_quality::metrics::{Metrics, MetricsOptions, evaluate_contacts};
use graspopt_quality::{Contact, FrictionModel, GraspModel};
use graspopt_sim::{ContactModel, Object, TrialOutcome};
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

use crate::error::TrialError;

/// The metric that becomes the score: an objective of the quality crate's metric table
/// (`bw` by default, `epsilon`, `volume`; [`Metric::parse`] also takes `ls` and `gwv`).
pub use graspopt_quality::metrics::Metric;

/// The point about which torques are taken.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceFrame {
    /// The object's centre of mass (the thesis's usual choice): the default.
    #[default]
    Object,
    /// The world origin.
    World,
    /// The palm origin at its final pose.
    Palm,
    /// A given point (world).
    Point([f64; 3]),
}

impl ReferenceFrame {
    /// The frames users choose by name (`--frame`), in the order `--help` lists them.
    pub const NAMED: [ReferenceFrame; 3] = [
        ReferenceFrame::Object,
        ReferenceFrame::World,
        ReferenceFrame::Palm,
    ];

    /// `object`, `world`, `palm`, or `point` (a given point).
    pub fn name(&self) -> &'static str {
        match self {
            ReferenceFrame::Object => "object",
            ReferenceFrame::World => "world",
            ReferenceFrame::Palm => "palm",
            ReferenceFrame::Point(_) => "point",
        }
    }

    /// One of the named frames: `object`, `world` or `palm`.
    pub fn parse(name: &str) -> Result<Self, TrialError> {
        Self::NAMED
            .into_iter()
            .find(|f| f.name() == name.trim())
            .ok_or_else(|| {
                TrialError::Settings(format!(
                    "unknown reference frame {name:?}: expected object, world or palm"
                ))
            })
    }
}

/// How a trial outcome is scored.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScoreSettings {
    /// Which of the simulator's contact models supplies the contacts.
    pub contacts: ContactModel,
    /// The contact model of each contact point (soft finger by default, as in the thesis).
    pub model: FrictionModel,
    pub frame: ReferenceFrame,
    /// Torque scale in metres; `None`: the object's bounding radius.
    pub torque_scale: Option<f64>,
    pub metric: Metric,
    /// Count the palm's contacts too.
    pub include_palm: bool,
}

impl Default for ScoreSettings {
    fn default() -> Self {
        Self {
            contacts: ContactModel::Surface,
            model: FrictionModel::SoftFinger {
                mu: 0.5,
                edges: 8,
                gamma: 0.005,
            },
            frame: ReferenceFrame::Object,
            torque_scale: None,
            metric: Metric::Bw,
            include_palm: true,
        }
    }
}

/// The score of one trial and what it was computed from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrialScore {
    pub score: f64,
    /// Modelled contact points scored.
    pub contacts: usize,
    pub fingers_in_contact: usize,
    /// The metrics, when there were contacts.
    pub metrics: Option<Metrics>,
}

/// Scores an outcome on `object`.
pub fn score_outcome(
    outcome: &TrialOutcome,
    object: &Object,
    settings: &ScoreSettings,
) -> Result<TrialScore, TrialError> {
    let contacts: Vec<Contact> = outcome
        .contacts(settings.contacts, settings.include_palm)
        .iter()
        .map(|c| Contact::normalized(c.position.coords, c.normal))
        .collect::<Result<_, _>>()?;
    let grasp_model = grasp_model(outcome, object, settings)?;
    let fingers_in_contact = outcome.fingers_in_contact();
    if contacts.is_empty() {
        return Ok(TrialScore {
            score: no_contact_score(outcome, object, &grasp_model, settings.metric),
            contacts: 0,
            fingers_in_contact,
            metrics: None,
        });
    }
    let options = MetricsOptions::for_score(settings.metric);
    let metrics = evaluate_contacts(&contacts, &grasp_model, &options)?;
    let score = metrics.real(settings.metric).unwrap_or(0.0);
    Ok(TrialScore {
        score,
        contacts: contacts.len(),
        fingers_in_contact,
        metrics: Some(metrics),
    })
}

/// The grasp model of the settings for this outcome (reference point and torque scale
/// resolved).
pub fn grasp_model(
    outcome: &TrialOutcome,
    object: &Object,
    settings: &ScoreSettings,
) -> Result<GraspModel, TrialError> {
    let reference = reference_point(outcome, object, settings.frame);
    let rho = settings
        .torque_scale
        .unwrap_or_else(|| object.bounding_sphere().1);
    let model = GraspModel::new(settings.model)
        .with_reference_point(reference.coords)
        .with_torque_scale(rho);
    model.validate()?;
    Ok(model)
}

fn reference_point(outcome: &TrialOutcome, object: &Object, frame: ReferenceFrame) -> Point3<f64> {
    match frame {
        ReferenceFrame::Object => object.centre_of_mass(),
        ReferenceFrame::World => Point3::origin(),
        ReferenceFrame::Palm => Point3::from(outcome.grasp.palm_pose.translation.vector),
        ReferenceFrame::Point(p) => Point3::new(p[0], p[1], p[2]),
    }
}

/// The score of a trial without contacts (see the module documentation).
pub fn no_contact_score(
    outcome: &TrialOutcome,
    object: &Object,
    model: &GraspModel,
    metric: Metric,
) -> f64 {
    if metric != Metric::Bw {
        return 0.0;
    }
    let rho = model.torque_scale;
    let bound = wrench_norm_bound(object, model);
    let gap = closest_gap(outcome).map_or(1.0, |g| (g / rho).min(1.0));
    -(bound + 1.0) - gap
}

/// The closed hand's smallest finite link-object distance, if any.
pub fn closest_gap(outcome: &TrialOutcome) -> Option<f64> {
    let gap = outcome
        .grasp
        .link_distances
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(f64::INFINITY, f64::min);
    gap.is_finite().then_some(gap)
}

/// An upper bound on the norm of any contact wrench on `object` under `model`: force at
/// most `sqrt(1 + mu^2)`, lever arm at most the distance `R` from the reference point to
/// the farthest point of the object, torsion at most `gamma`.
pub fn wrench_norm_bound(object: &Object, model: &GraspModel) -> f64 {
    let (centre, radius) = object.bounding_sphere();
    let reach = (centre.coords - model.reference_point).norm() + radius;
    let rho = model.torque_scale;
    let (mu, gamma) = match model.contact {
        FrictionModel::Frictionless => (0.0, 0.0),
        FrictionModel::PointFriction { mu, .. } => (mu, 0.0),
        FrictionModel::SoftFinger { mu, gamma, .. } => (mu, gamma),
    };
    let force = (1.0 + mu * mu).sqrt();
    force * (1.0 + (reach / rho).powi(2)).sqrt() + gamma / rho
}
