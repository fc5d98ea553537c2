//! Metrics of a grasp's wrench set (thesis sections 2.5-2.6, conventions in
//! `docs/metric-conventions.md`). Which metrics there are, and how each is named, stored,
//! printed and computed, is the [`table`]: **to add a metric, add its entry there**.
//!
//! - `rank`: affine rank of the wrenches; below 6 there is no force closure.
//! - `distance`: distance from the origin to the wrench hull (0 when inside).
//! - `force_closure`: the origin strictly inside the hull, every facet farther than
//!   [`FORCE_CLOSURE_MARGIN`].
//! - `epsilon`: the Largest Sphere (Ferrari-Canny) radius, 0 without force closure.
//! - `volume`: the Grasp Wrench Volume, the 6-volume of the hull.
//! - `bw`: the Bimodal Wrench metric, `epsilon` with force closure, else `-distance`;
//!   continuous across the boundary, where both are zero (a positive zero, never `-0.0`).
//!
//! Every metric returned is finite: a NaN or infinite value is reported as
//! [`QualityError::NotFiniteMetric`] instead. Inputs are bounded by [`crate::limits`].

pub mod table;
mod values;

pub use table::{COUNT, Kind, Metric, MetricDef, TABLE, Value, WrenchSet, objective_names};
pub use values::Metrics;

use serde::{Deserialize, Serialize};

use crate::contact::{Contact, GraspModel};
use crate::error::QualityError;
use crate::grasp_map::{GraspMap, check_wrenches};
use crate::hull::{affine, coordinate_scale, epa, min_norm, qp, quickhull};
use crate::wrench::Wrench;

/// A facet must be farther than this from the origin for force closure.
pub const FORCE_CLOSURE_MARGIN: f64 = 1e-9;
/// Below this distance (relative to the coordinate scale) the origin counts as touching
/// the hull, and the inscribed radius is computed to decide.
const INSIDE_TOLERANCE: f64 = 1e-10;

/// How the distance from the origin to the hull is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DistanceSolver {
    /// Wolfe's minimum-norm-point algorithm (exact, fast): the default.
    #[default]
    MinNorm,
    /// The second-order cone program solved by Clarabel.
    Clarabel,
}

/// Which metrics to compute and how.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct MetricsOptions {
    /// Compute the Grasp Wrench Volume (needs the full hull: slow for surface models).
    pub volume: bool,
    pub distance_solver: DistanceSolver,
}

impl Default for MetricsOptions {
    fn default() -> Self {
        Self {
            volume: true,
            distance_solver: DistanceSolver::MinNorm,
        }
    }
}

impl MetricsOptions {
    /// Everything but the volume: what an optimiser scoring by BW needs.
    pub fn without_volume() -> Self {
        Self {
            volume: false,
            ..Self::default()
        }
    }

    /// What scoring by `metric` needs: the volume only when it is the score.
    pub fn for_score(metric: Metric) -> Self {
        Self {
            volume: metric == Metric::Volume,
            ..Self::default()
        }
    }
}

/// All metrics of a grasp map.
pub fn evaluate(grasp: &GraspMap, options: &MetricsOptions) -> Result<Metrics, QualityError> {
    evaluate_wrenches(grasp.wrenches(), options)
}

/// All metrics of the grasp given by contacts under a model.
pub fn evaluate_contacts(
    contacts: &[Contact],
    model: &GraspModel,
    options: &MetricsOptions,
) -> Result<Metrics, QualityError> {
    evaluate(&GraspMap::from_contacts(contacts, model)?, options)
}

/// All metrics of a wrench set; errors on an empty set, a non-finite or out-of-range
/// wrench, too many wrenches (see [`crate::limits`]), or a metric that is not finite.
///
/// What several metrics share (the rank, the distance, the Largest Sphere and force
/// closure) is computed first, then each entry of the [`TABLE`] in order.
pub fn evaluate_wrenches(w: &[Wrench], options: &MetricsOptions) -> Result<Metrics, QualityError> {
    let set = shared(w, options)?;
    let mut values = [None; COUNT];
    for (value, def) in values.iter_mut().zip(&TABLE) {
        *value = match (def.compute)(&set)? {
            Some(Value::Real(x)) => Some(Value::Real(positive_zero(finite(def.key, x)?))),
            other => other,
        };
    }
    Ok(Metrics::from_values(values))
}

/// The quantities several metrics share: the rank, the distance (finite), the Largest
/// Sphere radius (finite, 0 without force closure) and force closure.
fn shared<'a>(w: &'a [Wrench], options: &'a MetricsOptions) -> Result<WrenchSet<'a>, QualityError> {
    check_wrenches(w)?;
    let basis = affine::affine_basis(w);
    let rank = basis.rank;
    let distance = finite("distance", distance_to_hull(w, options.distance_solver)?)?;
    let epsilon = if rank == 6 && distance <= INSIDE_TOLERANCE * coordinate_scale(w) {
        epa::try_inner_distance_with_basis(w, &basis)
            .map_err(|_| QualityError::HullTooLarge {
                metric: "Largest Sphere radius (epsilon)",
                points: w.len(),
                limit: quickhull::FACET_LIMIT,
            })?
            .map_or(0.0, |r| r.offset.max(0.0))
    } else {
        0.0
    };
    let force_closure = epsilon > FORCE_CLOSURE_MARGIN;
    let epsilon = finite("epsilon", if force_closure { epsilon } else { 0.0 })?;
    Ok(WrenchSet {
        wrenches: w,
        options,
        rank,
        distance,
        force_closure,
        epsilon,
    })
}

/// `value` if it is finite, else a [`QualityError::NotFiniteMetric`] naming `metric`.
fn finite(metric: &'static str, value: f64) -> Result<f64, QualityError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(QualityError::NotFiniteMetric { metric, value })
    }
}

/// `x` with a negative zero turned into a positive one (`-0.0 + 0.0 == +0.0`).
fn positive_zero(x: f64) -> f64 {
    x + 0.0
}

/// The distance from the origin to the hull of `w`.
pub fn distance_to_hull(w: &[Wrench], solver: DistanceSolver) -> Result<f64, QualityError> {
    match solver {
        DistanceSolver::MinNorm => Ok(min_norm::min_norm_point(w).distance),
        DistanceSolver::Clarabel => qp::distance_to_hull(w),
    }
}

/// The Grasp Wrench Volume: the 6-volume of the hull of `w` (0 below rank 6); an error
/// when the hull cannot be built or would need more than
/// [`FACET_LIMIT`](quickhull::FACET_LIMIT) facets.
pub fn grasp_wrench_volume(w: &[Wrench]) -> Result<f64, QualityError> {
    match quickhull::Hull::new(w) {
        Ok(h) => Ok(h.volume()),
        Err(quickhull::HullError::LowerDimensional { .. }) => Ok(0.0),
        Err(quickhull::HullError::Degenerate) => Err(QualityError::HullFailed { points: w.len() }),
        Err(quickhull::HullError::TooManyFacets) => Err(QualityError::HullTooLarge {
            metric: "volume",
            points: w.len(),
            limit: quickhull::FACET_LIMIT,
        }),
    }
}

/// The Largest Sphere radius (0 without force closure).
pub fn largest_sphere(w: &[Wrench]) -> Result<f64, QualityError> {
    Ok(evaluate_wrenches(w, &MetricsOptions::without_volume())?.epsilon())
}

/// The Bimodal Wrench metric.
pub fn bimodal_wrench(w: &[Wrench]) -> Result<f64, QualityError> {
    Ok(evaluate_wrenches(w, &MetricsOptions::without_volume())?.bw())
}
