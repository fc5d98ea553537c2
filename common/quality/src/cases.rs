//! Grasp cases as data: the serde types of the case file that `graspopt quality --input`
//! reads and that the reference cases (`tests/data/metric-cases.json`) are written in.
//!
//! A file is an object with `cases`; a case has `params` + `contacts`, or `wrenches`, or
//! both (the contacts win). Every table refuses an unknown key, naming it, so a misspelling
//! is not silently replaced by a default; a case's descriptive keys (`kind`, `name`,
//! `description`, `notes`, `comment`) are accepted and ignored, and `expected` holds the
//! reference values where a file has them. Parsing the text is the caller's (this crate
//! reads no file): `serde_json::from_str::<CaseFile>`, or one [`Case`] at a time to keep
//! the good cases of a file with bad ones.

use nalgebra::Vector3;
use serde::Deserialize;
use serde::de::IgnoredAny;

use crate::contact::{Contact, FrictionModel, GraspModel};
use crate::error::QualityError;
use crate::grasp_map::GraspMap;
use crate::metrics::Metrics;
use crate::wrench::Wrench;

/// A case file.
#[derive(Debug, Clone, Deserialize)]
pub struct CaseFile {
    pub cases: Vec<Case>,
}

/// One grasp to evaluate.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    pub params: Option<CaseParams>,
    pub contacts: Option<Vec<CaseContact>>,
    pub wrenches: Option<Vec<[f64; 6]>>,
    /// The reference values, where the file has them: any metric of the table by its key
    /// (other keys are ignored).
    pub expected: Option<Metrics>,
    /// Descriptive keys, accepted whatever their value and not kept.
    #[serde(default)]
    pub kind: IgnoredAny,
    #[serde(default)]
    pub name: IgnoredAny,
    #[serde(default)]
    pub description: IgnoredAny,
    #[serde(default)]
    pub notes: IgnoredAny,
    #[serde(default)]
    pub comment: IgnoredAny,
}

/// The contact model of a case's contacts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionModelName {
    Frictionless,
    PointFriction,
    SoftFinger,
}

/// A case's `params`. A key the model does not use (`gamma` of a point contact) is
/// accepted and ignored.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseParams {
    pub model: FrictionModelName,
    pub mu: Option<f64>,
    pub edges: Option<usize>,
    pub gamma: Option<f64>,
    /// Default: the origin.
    pub reference_point: Option<[f64; 3]>,
    /// Default: 1.
    pub torque_scale: Option<f64>,
}

/// One contact: its position and unit normal (into the object).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseContact {
    pub position: [f64; 3],
    pub normal: [f64; 3],
}

/// What is wrong with a case, naming the field.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("params.{0}: missing (the {1} model needs it)")]
    Missing(&'static str, &'static str),
    #[error("`contacts` given without `params`")]
    NoParams,
    #[error("neither `contacts` (with `params`) nor `wrenches` given")]
    Empty,
    #[error("{0}: {1}")]
    Invalid(&'static str, QualityError),
}

impl CaseParams {
    /// The grasp model these parameters describe, validated.
    pub fn model(&self) -> Result<GraspModel, CaseError> {
        let name = match self.model {
            FrictionModelName::Frictionless => "frictionless",
            FrictionModelName::PointFriction => "point_friction",
            FrictionModelName::SoftFinger => "soft_finger",
        };
        let need = |v: Option<f64>, key| v.ok_or(CaseError::Missing(key, name));
        let edges = || self.edges.ok_or(CaseError::Missing("edges", name));
        let contact = match self.model {
            FrictionModelName::Frictionless => FrictionModel::Frictionless,
            FrictionModelName::PointFriction => FrictionModel::PointFriction {
                mu: need(self.mu, "mu")?,
                edges: edges()?,
            },
            FrictionModelName::SoftFinger => FrictionModel::SoftFinger {
                mu: need(self.mu, "mu")?,
                edges: edges()?,
                gamma: need(self.gamma, "gamma")?,
            },
        };
        let model = GraspModel {
            contact,
            reference_point: Vector3::from(self.reference_point.unwrap_or_default()),
            torque_scale: self.torque_scale.unwrap_or(1.0),
        };
        model
            .validate()
            .map_err(|e| CaseError::Invalid("params", e))?;
        Ok(model)
    }
}

impl Case {
    /// The grasp map of the case: from `params` + `contacts` when contacts are present,
    /// else from `wrenches`.
    pub fn grasp_map(&self) -> Result<GraspMap, CaseError> {
        if let Some(contacts) = &self.contacts {
            let model = self.params.as_ref().ok_or(CaseError::NoParams)?.model()?;
            let contacts: Vec<Contact> = contacts
                .iter()
                .map(|c| Contact::new(Vector3::from(c.position), Vector3::from(c.normal)))
                .collect();
            return GraspMap::from_contacts(&contacts, &model)
                .map_err(|e| CaseError::Invalid("contacts", e));
        }
        if let Some(wrenches) = &self.wrenches {
            let wrenches = wrenches.iter().map(|w| Wrench::from_row_slice(w)).collect();
            return GraspMap::from_wrenches(wrenches)
                .map_err(|e| CaseError::Invalid("wrenches", e));
        }
        Err(CaseError::Empty)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(text: &str) -> Result<Case, serde_json::Error> {
        serde_json::from_str(text)
    }

    #[test]
    fn a_contact_case_builds_its_model_with_the_defaults() {
        let c = case(
            r#"{"name": "pinch", "params": {"model": "point_friction", "mu": 0.5, "edges": 4,
                "gamma": 9}, "contacts": [{"position": [1, 0, 0], "normal": [-1, 0, 0]},
                {"position": [-1, 0, 0], "normal": [1, 0, 0]}]}"#,
        )
        .unwrap();
        let model = c.params.as_ref().unwrap().model().unwrap();
        assert_eq!(
            model.contact,
            FrictionModel::PointFriction { mu: 0.5, edges: 4 }
        );
        assert_eq!(model.reference_point, Vector3::zeros());
        assert_eq!(model.torque_scale, 1.0);
        // Two contacts, four cone edges each.
        assert_eq!(c.grasp_map().unwrap().wrenches().len(), 8);
    }

    #[test]
    fn bad_cases_name_the_field() {
        let unknown = case(r#"{"params": {"model": "frictionless", "torque_scal": 1}}"#);
        assert!(
            unknown
                .unwrap_err()
                .to_string()
                .contains("unknown field `torque_scal`")
        );
        let short = case(r#"{"wrenches": [[1, 2, 3]]}"#)
            .unwrap_err()
            .to_string();
        assert!(short.contains("invalid length 3"), "{short}");
        let soft = case(r#"{"params": {"model": "soft_finger", "mu": 1, "edges": 8}}"#).unwrap();
        let err = soft.params.unwrap().model().unwrap_err().to_string();
        assert_eq!(
            err,
            "params.gamma: missing (the soft_finger model needs it)"
        );
        let bare = case(r#"{"contacts": []}"#)
            .unwrap()
            .grasp_map()
            .unwrap_err();
        assert_eq!(bare.to_string(), "`contacts` given without `params`");
        assert!(matches!(
            case("{}").unwrap().grasp_map(),
            Err(CaseError::Empty)
        ));
        let mu = case(r#"{"params": {"model": "point_friction", "mu": -1, "edges": 8}}"#).unwrap();
        let err = mu.params.unwrap().model().unwrap_err().to_string();
        assert!(err.starts_with("params: ") && err.contains("mu"), "{err}");
    }
}
