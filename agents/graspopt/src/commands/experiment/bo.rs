//! `graspopt experiment bo`: the thesis's Bayesian-optimisation experiments (sections 4.6-4.8)
//! in the simulator, over seeds, into a folder of CSV and SVG files with a markdown report:
//!
//! - 4.16-4.17: 1D runs on the sphere and the star prism with the chosen engine (two random
//!   points, stop when EI vanishes): the model that chose each trial (samples, GP mean,
//!   two-sigma band, EI), four of them drawn;
//! - 4.18-4.24: the samples of a 2D run on each object over the grid scan;
//! - Table 4.1: grid size against BO trials, in total (until the engine's stopping rule) and
//!   to within 5/10/20% of the grid maximum, medians over seeds, beside random search and the
//!   thesis's figures;
//! - 4.25-4.27: best so far against trials, BO against random search, mean and spread over
//!   seeds, on every object; and the same in the 6D pose space (no grid in 6D).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use graspopt_bayesopt::Preset;
use graspopt_experiment::bo_study::{BoRequest, BoStudy, MAX_BUDGET, MAX_SEEDS, MAX_WORKERS};
use graspopt_experiment::bo_study::{ModelCapChoice, Part};

use crate::commands::setup::{contact_model, count};
use crate::out::outln;
use graspopt_sim::ContactModel;

#[derive(Args, Debug)]
pub struct BoArgs {
    /// Output folder.
    #[arg(long, default_value = "results/experiment-bo")]
    pub out: PathBuf,
    /// Hand: a built-in name (see `graspopt hands`) or a URDF file.
    #[arg(long, default_value = "barrett")]
    pub hand: String,
    /// Seeds per method and object.
    #[arg(long, default_value_t = 10, value_parser = count::<u64>(1, MAX_SEEDS))]
    pub seeds: u64,
    /// The first seed (seeds run from it upwards).
    #[arg(long, default_value_t = 0, value_parser = count::<u64>(0, u64::MAX))]
    pub first_seed: u64,
    /// Trials per 2D run (the thesis compared over 100).
    #[arg(long, default_value_t = 100, value_parser = count::<usize>(1, MAX_BUDGET as u64))]
    pub budget: usize,
    /// Trials per 6D run.
    #[arg(long, default_value_t = 100, value_parser = count::<usize>(1, MAX_BUDGET as u64))]
    pub budget_6d: usize,
    /// Grid of the 2D reference scan, approach x vertical (the thesis's 2,211 points); one
    /// count is used for both axes, as in `graspopt scan`.
    #[arg(long, default_value = "67,33")]
    pub steps: String,
    /// Objects of the 2D and 6D parts, comma-separated (default: the seven of the thesis);
    /// the 1D part always runs on the sphere and the star prism, as the thesis's figures.
    #[arg(long, value_delimiter = ',')]
    pub objects: Vec<String>,
    /// Parts to run: 1d (figs 4.16-4.17), 2d (4.18-4.27, Table 4.1), 6d.
    #[arg(long, value_delimiter = ',', default_values = Part::ALL.map(|p| p.name()), value_parser = part_parser())]
    pub parts: Vec<Part>,
    /// The engine's settings: grasp (the thesis's with the misses' scores compressed),
    /// benchmark (for noise-free test functions) or thesis (as written).
    #[arg(long, default_value = "grasp", value_parser = preset_parser())]
    pub engine: Preset,
    /// The engine's model cap (observations the GP conditions on): `preset` (the engine's
    /// own), `none` (every observation, the exact GP) or a number (at least 8), to run the
    /// large-n mode inside short runs.
    #[arg(long, default_value = "preset", value_parser = model_cap_parser)]
    pub model_cap: ModelCapChoice,
    /// Trials in flight in the 2D and 6D runs (1: one at a time, as the thesis; W: the engine
    /// proposes each trial with the other W - 1 pending).
    #[arg(long, default_value_t = 1, value_parser = count::<usize>(1, MAX_WORKERS as u64))]
    pub workers: usize,
    /// Contact model scored: surface, patch or mean.
    #[arg(long, default_value = "surface", value_parser = contact_model())]
    pub contacts: ContactModel,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0, value_parser = count::<usize>(0, u64::MAX))]
    pub threads: usize,
}

/// `--parts`: each one of [`Part::ALL`], parsed by [`Part::from_name`].
fn part_parser() -> impl TypedValueParser<Value = Part> {
    PossibleValuesParser::new(Part::ALL.map(|p| p.name()))
        .try_map(|name| Part::from_name(&name).ok_or("unknown part: expected 1d, 2d or 6d"))
}

/// `--engine`: one of the presets, parsed by [`Preset::from_name`].
fn preset_parser() -> impl TypedValueParser<Value = Preset> {
    PossibleValuesParser::new(Preset::ALL.map(|p| p.name()))
        .try_map(|name| Preset::from_name(&name))
}

/// `--model-cap`: `preset`, `none` or a number.
fn model_cap_parser(text: &str) -> Result<ModelCapChoice, String> {
    match text {
        "preset" => Ok(ModelCapChoice::Preset),
        "none" => Ok(ModelCapChoice::Exact),
        n => n
            .parse()
            .map(ModelCapChoice::Size)
            .map_err(|_| format!("expected preset, none or a number of observations, got '{n}'")),
    }
}

pub(super) fn bo(args: &BoArgs) -> Result<()> {
    let study = BoStudy::plan(&BoRequest {
        hand: args.hand.clone(),
        seeds: args.seeds,
        first_seed: args.first_seed,
        budget: args.budget,
        budget_6d: args.budget_6d,
        steps: args.steps.clone(),
        objects: args.objects.clone(),
        parts: args.parts.clone(),
        engine: args.engine,
        model_cap: args.model_cap,
        workers: args.workers,
        contacts: args.contacts,
        threads: args.threads,
    })?;
    let path = graspopt_report::experiment::bo::write_bo_study(
        &args.out,
        &study,
        args.contacts.name(),
        &mut |part, object| eprintln!("{} {object}: done", part.name()),
    )?;
    outln!("{}", path.display())?;
    Ok(())
}
