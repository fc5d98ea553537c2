//! The flags every simulated-trial command shares (`trial`, `scan`, later `run`): which
//! object, hand, contact model, metric and reference frame. One flag set for every tool.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};
use graspopt_sim::{ContactModel, Object, ParamKind};
use graspopt_trial::{Evaluator, Metric, ReferenceFrame, TrialSettings};

#[derive(Args, Debug, Clone)]
pub struct SimArgs {
    /// Built-in object: sphere, wine_glass, cylinder, mug, cuboid, rotated_cuboid, star_prism.
    #[arg(long, default_value = "mug", conflicts_with = "mesh")]
    pub object: String,
    /// A user mesh (OBJ or STL, closed) instead of a built-in object.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// Factor from the mesh file's units to metres (0.001 for a mesh in millimetres).
    #[arg(long, default_value_t = 1.0, requires = "mesh")]
    pub mesh_scale: f64,
    /// Hand: a built-in name (barrett, parallel_jaw, franka_hand; see `graspopt hands`) or a
    /// URDF file (FILE.urdf, settings in FILE.toml beside it).
    #[arg(long, default_value = "barrett")]
    pub hand: String,
    /// Contact model: surface (thesis 2.3), patch (circular patch) or mean (mean point).
    #[arg(long, value_enum, default_value_t = Contacts::Surface)]
    pub contacts: Contacts,
    /// Metric scored: bw, epsilon (ls) or volume (gwv).
    #[arg(long, default_value = "bw")]
    pub metric: String,
    /// Reference point for torques: object (centre of mass), world or palm.
    #[arg(long, value_enum, default_value_t = Frame::Object)]
    pub frame: Frame,
    /// Torque scale in metres (default: the object's bounding radius).
    #[arg(long)]
    pub torque_scale: Option<f64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Contacts {
    Surface,
    Patch,
    Mean,
}

impl From<Contacts> for ContactModel {
    fn from(c: Contacts) -> Self {
        match c {
            Contacts::Surface => ContactModel::Surface,
            Contacts::Patch => ContactModel::CircularPatch,
            Contacts::Mean => ContactModel::MeanPoint,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Frame {
    Object,
    World,
    Palm,
}

impl SimArgs {
    /// The trial settings the flags name.
    pub fn settings(&self) -> Result<TrialSettings> {
        Ok(TrialSettings {
            object: self.object.clone(),
            mesh: self.mesh.clone(),
            mesh_scale: self.mesh_scale,
            hand: self.hand.clone(),
            contacts: self.contacts.into(),
            metric: Metric::parse(&self.metric)?,
            frame: match self.frame {
                Frame::Object => ReferenceFrame::Object,
                Frame::World => ReferenceFrame::World,
                Frame::Palm => ReferenceFrame::Palm,
            },
            torque_scale: self.torque_scale,
        })
    }

    /// The object named by the flags.
    pub fn object(&self) -> Result<Object> {
        Ok(graspopt_trial::settings::load_object(
            &self.object,
            self.mesh.as_deref(),
            self.mesh_scale,
        )?)
    }

    /// An evaluator over the trial space with the given parameters (full default bounds).
    pub fn evaluator(&self, kinds: &[ParamKind]) -> Result<Evaluator> {
        Ok(Evaluator::from_settings(&self.settings()?, kinds)?)
    }
}

/// Parameter names users type (see [`ParamKind::parse`]); for the callers that still use
/// anyhow's `Result`.
pub fn param_kind(name: &str) -> Result<ParamKind> {
    Ok(ParamKind::parse(name)?)
}
