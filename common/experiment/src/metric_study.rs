//! The metric study of thesis figures 4.3-4.15 as data: which scans, with which settings, and
//! what is read off them. `graspopt experiment metrics` lays them out (graspopt-report).
//!
//! - 4.3-4.5 ([`approach_metrics`]): Largest Sphere, Grasp Wrench Volume and BW along the
//!   approach axis with mean-point contacts (the volume needs the full hull, too slow for
//!   surface models);
//! - 4.6 ([`MetricStudy::contact_models`]): BW with the mean-point, circular-patch and surface models;
//! - 4.7 ([`sphere_map`]): 2D BW maps of the sphere, mean point and surface model;
//! - 4.8 ([`frames`]): BW in the object, world and hand frames (torque scale fixed);
//! - 4.9-4.15 ([`object_map`]): 2D BW maps of all seven objects.

use graspopt_sim::contact::oldest_first;
use graspopt_sim::{ContactModel, ParamKind};
use graspopt_trial::scan::ScanPoint;
use graspopt_trial::{Metric, ReferenceFrame};

use crate::error::ExperimentError;
use crate::scans::{Scan, evaluator, scan, span};

/// The most points of a 1D scan.
pub const MAX_STEPS: usize = 100_000;
/// The most points per axis of a 2D scan (9 million points in all).
pub const MAX_STEPS_2D: usize = 3000;

/// Figures 4.3-4.5: the figure and its object.
pub const APPROACH_FIGURES: [(&str, &str); 3] = [
    ("4.3", "sphere"),
    ("4.4", "rotated_cuboid"),
    ("4.5", "star_prism"),
];
/// Figure 4.6's objects.
pub const CONTACT_MODEL_OBJECTS: [&str; 2] = ["cuboid", "sphere"];
/// Figure 4.7's contact models and their names.
pub const SPHERE_MAP_MODELS: [(&str, ContactModel); 2] = [
    ("mean-point", ContactModel::MeanPoint),
    ("surface", ContactModel::Surface),
];
/// Figure 4.8's fixed torque scale (m).
pub const FRAMES_TORQUE_SCALE: f64 = 0.05;

/// The study's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct MetricStudy {
    /// Hand: a built-in name or a URDF file.
    pub hand: String,
    /// Points of each 1D scan.
    pub steps: usize,
    /// Points per axis of each 2D scan.
    pub steps_2d: usize,
    /// Worker threads (0: all cores).
    pub threads: usize,
}

/// Figures 4.3-4.5 on one object: the scan and the three metrics along it.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproachMetrics {
    pub scan: Scan,
    /// Largest Sphere (epsilon), 0 where nothing is touched.
    pub ls: Vec<f64>,
    /// Grasp Wrench Volume, 0 where nothing is touched.
    pub gwv: Vec<f64>,
    /// BW, NaN where nothing is touched.
    pub bw: Vec<f64>,
    /// Width of the force-closure range (LS > 0), m.
    pub force_closure_range: f64,
    /// Width of the range where the hand touches (BW defined), m.
    pub touched_range: f64,
    /// Approach offset of the BW maximum (NaN if BW is nowhere defined).
    pub bw_max_at: f64,
}

/// One variant of a 1D comparison (4.6, 4.8): its name and its scan along the approach axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    pub name: &'static str,
    pub scan: Scan,
}

impl Variant {
    /// Width of the force-closure range, m.
    pub fn force_closure_range(&self) -> f64 {
        span(&self.scan.axes[0], &self.scan.points, |p| {
            p.score.metrics.is_some_and(|m| m.force_closure())
        })
    }
}

/// A 2D BW map (approach x vertical) of one object.
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    pub object: String,
    pub scan: Scan,
}

impl Map {
    /// The best point of the map.
    pub fn best(&self) -> Result<&ScanPoint, ExperimentError> {
        self.scan
            .argmax()
            .ok_or_else(|| ExperimentError::Settings("empty scan".into()))
    }
}

impl MetricStudy {
    /// Checks the scan sizes: a range needs at least two points per axis.
    pub fn check(&self) -> Result<(), ExperimentError> {
        if !(2..=MAX_STEPS).contains(&self.steps) {
            return Err(ExperimentError::Settings(format!(
                "--steps must be between 2 and {MAX_STEPS}, got {}",
                self.steps
            )));
        }
        if !(2..=MAX_STEPS_2D).contains(&self.steps_2d) {
            return Err(ExperimentError::Settings(format!(
                "--steps-2d must be between 2 and {MAX_STEPS_2D}, got {}",
                self.steps_2d
            )));
        }
        Ok(())
    }

    /// Figures 4.3-4.5: LS, GWV and BW along the approach axis of `object`, mean-point
    /// contacts.
    pub fn approach_metrics(&self, object: &str) -> Result<ApproachMetrics, ExperimentError> {
        let mut ev = evaluator(&self.hand, object, &[ParamKind::Approach])?;
        ev.score.contacts = ContactModel::MeanPoint;
        ev.score.metric = Metric::Volume;
        let scan = scan(&ev, &[self.steps], self.threads)?;
        let points = &scan.points;
        let get = |f: &dyn Fn(&ScanPoint) -> f64| points.iter().map(f).collect::<Vec<f64>>();
        let ls = get(&|p| p.score.metrics.map_or(0.0, |m| m.epsilon()));
        let gwv = get(&|p| p.score.metrics.and_then(|m| m.volume()).unwrap_or(0.0));
        let bw = get(&|p| p.score.metrics.map_or(f64::NAN, |m| m.bw()));
        let xs = &scan.axes[0];
        let force_closure_range = span(xs, points, |p| {
            p.score.metrics.is_some_and(|m| m.epsilon() > 0.0)
        });
        let touched_range = span(xs, points, |p| p.score.metrics.is_some());
        let bw_max_at = points
            .iter()
            .zip(&bw)
            .filter(|(_, b)| b.is_finite())
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or(f64::NAN, |(p, _)| p.params[0]);
        Ok(ApproachMetrics {
            ls,
            gwv,
            bw,
            force_closure_range,
            touched_range,
            bw_max_at,
            scan,
        })
    }

    /// Figure 4.6: BW along the approach axis of `object` with each registered contact model
    /// ([`graspopt_sim::contact::MODELS`]), oldest first as the thesis orders them, each named
    /// by its label.
    pub fn contact_models(&self, object: &str) -> Result<Vec<Variant>, ExperimentError> {
        oldest_first()
            .into_iter()
            .map(|(_, e)| e.model)
            .map(|model| {
                let mut ev = evaluator(&self.hand, object, &[ParamKind::Approach])?;
                ev.score.contacts = model;
                Ok(Variant {
                    name: model.label(),
                    scan: scan(&ev, &[self.steps], self.threads)?,
                })
            })
            .collect()
    }

    /// Figure 4.7: the 2D BW map of the sphere with `model`.
    pub fn sphere_map(&self, model: ContactModel) -> Result<Map, ExperimentError> {
        self.map("sphere", Some(model))
    }

    /// Figure 4.8: BW on the sphere along the approach axis in the object frame, the world
    /// frame and the hand's (the palm at the reference pose), torque scale fixed.
    pub fn frames(&self) -> Result<Vec<Variant>, ExperimentError> {
        let reference = evaluator(&self.hand, "sphere", &[ParamKind::Approach])?
            .space
            .reference
            .translation
            .vector;
        [
            ("object", ReferenceFrame::Object),
            ("world", ReferenceFrame::World),
            (
                "hand (reference palm)",
                ReferenceFrame::Point([reference.x, reference.y, reference.z]),
            ),
        ]
        .into_iter()
        .map(|(name, frame)| {
            let mut ev = evaluator(&self.hand, "sphere", &[ParamKind::Approach])?;
            ev.score.frame = frame;
            ev.score.torque_scale = Some(FRAMES_TORQUE_SCALE);
            Ok(Variant {
                name,
                scan: scan(&ev, &[self.steps], self.threads)?,
            })
        })
        .collect()
    }

    /// Figures 4.9-4.15: the 2D BW map of `object` (surface model).
    pub fn object_map(&self, object: &str) -> Result<Map, ExperimentError> {
        self.map(object, None)
    }

    fn map(&self, object: &str, model: Option<ContactModel>) -> Result<Map, ExperimentError> {
        let mut ev = evaluator(
            &self.hand,
            object,
            &[ParamKind::Approach, ParamKind::Vertical],
        )?;
        if let Some(model) = model {
            ev.score.contacts = model;
        }
        Ok(Map {
            object: ev.object.name().to_string(),
            scan: scan(&ev, &[self.steps_2d, self.steps_2d], self.threads)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn study() -> MetricStudy {
        MetricStudy {
            hand: "barrett".into(),
            steps: 11,
            steps_2d: 7,
            threads: 0,
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    // The values below are those `graspopt experiment metrics --steps 11 --steps-2d 7` wrote
    // before the study moved here (fig4.3-sphere.csv, fig4.7-sphere-surface.csv).

    #[test]
    fn the_sphere_along_the_approach_axis_peaks_at_the_nearest_pose() {
        let m = study().approach_metrics("sphere").unwrap();
        assert_eq!(m.scan.points.len(), 11);
        let last = m.scan.points.last().unwrap();
        assert!(close(m.bw_max_at, 0.01999999999999999), "{}", m.bw_max_at);
        assert_eq!(last.params[0], m.bw_max_at);
        assert!(close(m.ls[10], 0.22131990598449022), "{}", m.ls[10]);
        assert!(close(m.gwv[10], 0.07820935851604366), "{}", m.gwv[10]);
        assert!(close(m.bw[10], 0.22131990598449022), "{}", m.bw[10]);
        assert!(m.bw[0].is_nan() && m.ls[0] == 0.0 && m.gwv[0] == 0.0);
        // One point (18 mm of grid) in force closure, nine touching.
        assert!(
            close(m.force_closure_range, 0.018),
            "{}",
            m.force_closure_range
        );
        assert!(close(m.touched_range, 0.162), "{}", m.touched_range);
    }

    #[test]
    fn the_sphere_map_has_its_known_argmax() {
        let map = study().sphere_map(ContactModel::Surface).unwrap();
        assert_eq!(map.object, "sphere");
        assert_eq!(map.scan.points.len(), 49);
        let best = map.best().unwrap();
        assert!(
            close(best.params[0], 0.020000000000000018),
            "{:?}",
            best.params
        );
        assert_eq!(best.params[1], 0.0);
        assert!(
            close(best.score.score, 0.24807419843458234),
            "{}",
            best.score.score
        );
        assert_eq!(map.scan.force_closure(), 7);
    }

    #[test]
    fn each_comparison_has_its_variants_in_order() {
        let s = MetricStudy {
            steps: 3,
            ..study()
        };
        let models = s.contact_models("cuboid").unwrap();
        let names: Vec<&str> = models.iter().map(|v| v.name).collect();
        assert_eq!(names, ["mean point", "circular patch", "surface"]);
        let frames = s.frames().unwrap();
        let names: Vec<&str> = frames.iter().map(|v| v.name).collect();
        assert_eq!(names, ["object", "world", "hand (reference palm)"]);
        assert!(frames.iter().all(|v| v.scan.points.len() == 3));
        let e = MetricStudy {
            steps_2d: 3001,
            ..study()
        }
        .check()
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--steps-2d must be between 2 and 3000, got 3001"
        );
        let hand = MetricStudy {
            hand: "teapot".into(),
            ..study()
        }
        .approach_metrics("sphere")
        .unwrap_err();
        assert!(matches!(hand, ExperimentError::Hand { .. }), "{hand}");
    }
}
