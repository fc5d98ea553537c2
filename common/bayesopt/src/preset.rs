//! Named sets of engine settings, and the methods a run can use: the engine with one of them,
//! or uniform random search.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::benchmark::recommended_settings;
use crate::error::BoError;
use crate::optimizer::Settings;

/// A named set of the engine's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Preset {
    /// The thesis's method (Matern 3/2, EI with `xi = sigma_f^2 / 100`, DIRECT, stop when EI
    /// vanishes) with the bad tail of the scores compressed logarithmically
    /// ([`Settings::for_grasps`]). The best measured on the seven objects (docs/benchmarks.md).
    Grasp,
    /// The settings measured on the BO suite's ten test functions against egobox-ego
    /// ([`recommended_settings`]; for noise-free objectives).
    Benchmark,
    /// The thesis's settings as written ([`Settings::default`]).
    Thesis,
}

impl Preset {
    /// Every preset, in the order they are listed to users.
    pub const ALL: [Preset; 3] = [Preset::Grasp, Preset::Benchmark, Preset::Thesis];

    /// The settings (the direction, `minimize`, as in [`Settings::default`]).
    pub fn settings(self) -> Settings {
        match self {
            Preset::Grasp => Settings::for_grasps(),
            Preset::Benchmark => recommended_settings(),
            Preset::Thesis => Settings::default(),
        }
    }

    /// `grasp`, `benchmark` or `thesis`.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Grasp => "grasp",
            Preset::Benchmark => "benchmark",
            Preset::Thesis => "thesis",
        }
    }

    /// The preset named `name` (one of [`Preset::name`]).
    pub fn from_name(name: &str) -> Result<Self, BoError> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| {
                BoError::InvalidSetting(format!(
                    "unknown engine settings '{name}' (known: grasp, benchmark, thesis)"
                ))
            })
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = BoError;
    fn from_str(s: &str) -> Result<Self, BoError> {
        Preset::from_name(s)
    }
}

/// How the points of a run are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Method {
    /// The engine with the preset's settings.
    Bo(Preset),
    /// Uniform random search.
    Random,
}

impl Method {
    /// The methods users name: `bo` (the engine with [`Preset::Benchmark`]), `bo-thesis`
    /// ([`Preset::Thesis`]), `bo-grasp` ([`Preset::Grasp`], the planner agent's) and `random`.
    pub const NAMED: [Method; 4] = [
        Method::Bo(Preset::Benchmark),
        Method::Bo(Preset::Thesis),
        Method::Bo(Preset::Grasp),
        Method::Random,
    ];

    /// Parses `bo`, `bo-thesis` (or `thesis`), `bo-grasp` or `random`, in any case.
    pub fn from_name(name: &str) -> Result<Self, BoError> {
        match name.to_ascii_lowercase().as_str() {
            "bo" => Ok(Method::Bo(Preset::Benchmark)),
            "bo-thesis" | "thesis" => Ok(Method::Bo(Preset::Thesis)),
            "bo-grasp" => Ok(Method::Bo(Preset::Grasp)),
            "random" => Ok(Method::Random),
            other => Err(BoError::InvalidSetting(format!(
                "unknown method '{other}' (known: {})",
                Method::NAMED.map(Method::name).join(", ")
            ))),
        }
    }

    /// The name [`Method::from_name`] reads: `bo`, `bo-thesis`, `bo-grasp` or `random`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Bo(Preset::Benchmark) => "bo",
            Method::Bo(Preset::Thesis) => "bo-thesis",
            Method::Bo(Preset::Grasp) => "bo-grasp",
            Method::Random => "random",
        }
    }

    /// One line for a user: what the method is.
    pub fn description(self) -> &'static str {
        match self {
            Method::Bo(Preset::Benchmark) => "The engine with its recommended settings",
            Method::Bo(Preset::Thesis) => {
                "The engine with the thesis settings as written (EI xi = sigma_f^2 / 100)"
            }
            Method::Bo(Preset::Grasp) => "The engine with the settings for grasp scores",
            Method::Random => "Uniform random search",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = BoError;
    fn from_str(s: &str) -> Result<Self, BoError> {
        Method::from_name(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for p in Preset::ALL {
            assert_eq!(p.name().parse::<Preset>().unwrap(), p);
        }
        for m in Method::NAMED {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
        }
        assert_eq!(
            Method::from_name("Thesis").unwrap(),
            Method::Bo(Preset::Thesis)
        );
        assert_eq!(
            "bo-x".parse::<Method>().unwrap_err().to_string(),
            "invalid setting: unknown method 'bo-x' (known: bo, bo-thesis, bo-grasp, random)"
        );
        assert!("Grasp".parse::<Preset>().is_err());
    }

    #[test]
    fn presets_are_the_settings_they_name() {
        assert_eq!(Preset::Thesis.settings(), Settings::default());
        assert_eq!(Preset::Benchmark.settings(), recommended_settings());
        assert_eq!(Preset::Grasp.settings(), Settings::for_grasps());
        assert_ne!(Preset::Grasp.settings(), Preset::Thesis.settings());
    }
}
