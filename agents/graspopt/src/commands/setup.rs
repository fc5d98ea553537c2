//! The flags every simulated-trial command shares (`trial`, `scan`, later `run`): which
//! object, hand, contact model, metric and reference frame. One flag set for every tool.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{ContactModel, Object, ParamKind, ParamSpec, TrialSpace};
use graspopt_trial::{Evaluator, Metric, ReferenceFrame};

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
    /// The object named by the flags.
    pub fn object(&self) -> Result<Object> {
        match &self.mesh {
            Some(path) => Object::from_file_scaled(path, self.mesh_scale)
                .with_context(|| format!("cannot load the mesh {}", path.display())),
            None => Ok(Object::by_name(&self.object)?),
        }
    }

    /// An evaluator over the trial space with the given parameters (full default bounds).
    pub fn evaluator(&self, kinds: &[ParamKind]) -> Result<Evaluator> {
        let object = self.object()?;
        let space = space_for(&object, kinds)?;
        let hand = hand_by_name(&self.hand)?;
        let mut ev = Evaluator::new(object, hand, space);
        ev.score.contacts = self.contacts.into();
        ev.score.metric = Metric::parse(&self.metric)?;
        ev.score.frame = match self.frame {
            Frame::Object => ReferenceFrame::Object,
            Frame::World => ReferenceFrame::World,
            Frame::Palm => ReferenceFrame::Palm,
        };
        if let Some(rho) = self.torque_scale {
            if !(rho.is_finite() && rho > 0.0) {
                bail!("--torque-scale must be a positive length in metres, got {rho}");
            }
            ev.score.torque_scale = Some(rho);
        }
        Ok(ev)
    }
}

/// Parameter names users type: the thesis's x (approach) and y (vertical), plus the rest.
pub fn param_kind(name: &str) -> Result<ParamKind> {
    Ok(match name.trim() {
        "x" | "approach" => ParamKind::Approach,
        "lateral" | "z" => ParamKind::Lateral,
        "y" | "vertical" => ParamKind::Vertical,
        "rx" | "roll" => ParamKind::RotX,
        "ry" | "pitch" => ParamKind::RotY,
        "rz" | "yaw" => ParamKind::RotZ,
        other => bail!(
            "unknown trial parameter {other:?}: expected x (approach), y (vertical), lateral, rx, ry or rz"
        ),
    })
}

/// The object's default trial space restricted to `kinds`, in that order.
pub fn space_for(object: &Object, kinds: &[ParamKind]) -> Result<TrialSpace> {
    let full = TrialSpace::full_6d(object);
    let params: Vec<ParamSpec> = kinds
        .iter()
        .map(|k| {
            full.params
                .iter()
                .find(|p| p.kind == *k)
                .copied()
                .with_context(|| format!("no bounds for {}", k.name()))
        })
        .collect::<Result<_>>()?;
    Ok(TrialSpace::new(full.reference, params)?)
}
