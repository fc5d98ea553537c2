//! `graspopt experiment sensing`: the force-sensing round trip on the seven objects
//! (`graspopt_experiment::sensing_study`), without noise and with the sensors' noise, as
//! markdown tables.

use anyhow::Result;
use clap::Args;
use graspopt_experiment::sensing_study::{SensingStudySettings, markdown_table, round_trip};
use graspopt_sensing::SensorNoise;

use crate::commands::setup::count;
use crate::out::outln;

#[derive(Args, Debug)]
pub struct SensingArgs {
    /// Random trials per object (approach distance and height; 1 to 100000).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    trials: u32,
    /// Seed of the trials and the noise.
    #[arg(long, default_value_t = 0, value_parser = count::<u64>(0, u64::MAX))]
    seed: u64,
    /// Force resolution of the noisy run (N; default 1/320, an ATI Nano17's).
    #[arg(long)]
    force_resolution: Option<f64>,
    /// Torque resolution of the noisy run (N m; default 1.5625e-5, 1/64 N mm).
    #[arg(long)]
    torque_resolution: Option<f64>,
    /// Sensor samples averaged per reading (1: single samples; at most 10000, 10 s of a
    /// 1 kHz sensor).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    samples: u32,
}

pub fn sensing(args: &SensingArgs) -> Result<()> {
    let mut noise = SensorNoise::default();
    noise.force_resolution = args.force_resolution.unwrap_or(noise.force_resolution);
    noise.torque_resolution = args.torque_resolution.unwrap_or(noise.torque_resolution);
    noise.validate()?;
    for (title, noise) in [
        ("without noise", SensorNoise::NONE),
        ("with sensor noise", noise),
    ] {
        let settings = SensingStudySettings {
            trials: args.trials as usize,
            seed: args.seed,
            noise,
            samples: args.samples,
            ..SensingStudySettings::default()
        };
        let rows = round_trip(&settings)?;
        outln!(
            "Force-sensing round trip {title} (force resolution {} N, torque resolution {} N m, {} samples averaged per reading), barrett_ft, {} trials per object, seed {}:\n",
            noise.force_resolution,
            noise.torque_resolution,
            args.samples,
            args.trials,
            args.seed
        )?;
        outln!("{}", markdown_table(&rows))?;
    }
    Ok(())
}
