//! The planner's engines and their saved state (`engine_state`): what a reply carries so
//! that a planner without the run's engine continues exactly (see the crate documentation).

use graspopt_bayesopt::baseline::RandomSearch;
use graspopt_bayesopt::optimizer::{Optimizer, Settings};
use graspopt_protocol::{Observation, PlannerMethod, RunId, SuggestRequest};
use serde::{Deserialize, Serialize};

use crate::PlannerError;

/// Why a saved state is not used.
fn state(why: impl Into<String>) -> PlannerError {
    PlannerError::State(why.into())
}

#[derive(Serialize, Deserialize)]
pub(crate) enum Engine {
    Bo(Box<Optimizer>),
    Random(RandomSearch),
}

pub(crate) struct Warm {
    pub(crate) run_id: RunId,
    pub(crate) method: PlannerMethod,
    pub(crate) bounds: Vec<[f64; 2]>,
    pub(crate) seed: u64,
    pub(crate) initial: Option<u32>,
    pub(crate) told: Vec<Observation>,
    pub(crate) engine: Engine,
}

/// What `engine_state` holds after its header: the engine with what it was built for and a
/// digest of the observations it was told (the request carries those; the digest shows
/// they are the same). (`E`: the engine, or a reference to it when saving.)
#[derive(Serialize, Deserialize)]
struct SavedEngine<E> {
    run_id: RunId,
    method: PlannerMethod,
    bounds: Vec<[f64; 2]>,
    seed: u64,
    initial: Option<u32>,
    told: u64,
    told_digest: u64,
    engine: E,
}

/// The layout of [`SavedEngine`] and of the engines in it. Bump it when `Optimizer`,
/// `RandomSearch` or their settings change shape (the test
/// `the_saved_engine_layout_is_pinned` fails until then): bincode reads fields by position,
/// so a state of another layout would be misread rather than refused.
pub(crate) const STATE_FORMAT: u32 = 2;

/// Starts every `engine_state`, then an FNV-1a checksum of the rest (8 bytes, little
/// endian), then the bincode of a [`SavedEngine`]. A state of another format or graspopt
/// version, or a damaged one, is not read: the history is used instead.
pub(crate) fn state_header() -> Vec<u8> {
    format!(
        "graspopt-engine {STATE_FORMAT} {}\n",
        env!("CARGO_PKG_VERSION")
    )
    .into_bytes()
}

fn state_config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<{ graspopt_protocol::codec::MAX_PAYLOAD }>()
}

pub(crate) const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

pub(crate) fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// FNV-1a over the bits of every coordinate and value, in order.
fn digest(observations: &[Observation]) -> u64 {
    observations.iter().fold(FNV_OFFSET, |h, o| {
        let h =
            o.x.iter()
                .chain(std::iter::once(&o.y))
                .fold(h, |h, v| fnv(h, &v.to_bits().to_le_bytes()));
        fnv(h, &[0xff])
    })
}

fn same_values(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

/// The engine settings for a request: the ones a rebuilt engine gets, and the only ones a
/// restored engine may have.
pub(crate) fn bo_settings(req: &SuggestRequest) -> Settings {
    Settings {
        n_init: req.initial.map(|n| n as usize),
        ..Settings::for_grasps()
    }
}

impl Warm {
    /// Whether `req` continues this engine's run and history.
    pub(crate) fn continued_by(&self, req: &SuggestRequest) -> bool {
        self.run_id == req.run_id
            && self.method == req.method
            && self.bounds == req.bounds
            && self.seed == req.seed
            && self.initial == req.initial
            && req.observations.len() >= self.told.len()
            && req.observations[..self.told.len()] == self.told[..]
    }

    /// The `engine_state` of this engine.
    pub(crate) fn save(&self) -> Result<Vec<u8>, PlannerError> {
        let saved = SavedEngine {
            run_id: self.run_id.clone(),
            method: self.method,
            bounds: self.bounds.clone(),
            seed: self.seed,
            initial: self.initial,
            told: self.told.len() as u64,
            told_digest: digest(&self.told),
            engine: &self.engine,
        };
        let body = bincode::serde::encode_to_vec(&saved, state_config())
            .map_err(|e| PlannerError::State(format!("cannot encode the engine state: {e}")))?;
        let mut out = state_header();
        out.extend_from_slice(&fnv(FNV_OFFSET, &body).to_le_bytes());
        out.extend_from_slice(&body);
        Ok(out)
    }

    /// The engine `bytes` hold, if it is intact, of this format and version, and `req`
    /// continues it with the settings a rebuilt engine would have.
    pub(crate) fn restore(bytes: &[u8], req: &SuggestRequest) -> Result<Warm, PlannerError> {
        let rest = bytes
            .strip_prefix(state_header().as_slice())
            .ok_or_else(|| {
                state("it was saved in another format or by another graspopt version")
            })?;
        let (sum, body) = rest
            .split_first_chunk::<8>()
            .ok_or_else(|| state("it is truncated"))?;
        if u64::from_le_bytes(*sum) != fnv(FNV_OFFSET, body) {
            return Err(state("it is damaged (checksum)"));
        }
        let (saved, used): (SavedEngine<Engine>, usize) =
            bincode::serde::decode_from_slice(body, state_config())
                .map_err(|e| state(format!("it does not decode: {e}")))?;
        if used != body.len() {
            return Err(state(format!("{} bytes follow it", body.len() - used)));
        }
        let told = usize::try_from(saved.told)
            .ok()
            .filter(|&n| n <= req.observations.len())
            .ok_or_else(|| state("it was told more observations than the request holds"))?;
        let history = &req.observations[..told];
        if digest(history) != saved.told_digest {
            return Err(state(
                "the request's history does not start with its observations",
            ));
        }
        let engine_bounds: Vec<[f64; 2]> = match (&saved.engine, saved.method) {
            (Engine::Bo(opt), PlannerMethod::Bo) => {
                if *opt.settings() != bo_settings(req) || opt.seed() != req.seed {
                    return Err(state("its engine has other settings or another seed"));
                }
                opt.check_state()
                    .map_err(|e| state(format!("it is inconsistent: {e}")))?;
                let same = opt.len() == told
                    && opt.observations().zip(history).all(|((x, y), o)| {
                        same_values(y, o.y)
                            && x.len() == o.x.len()
                            && x.iter().zip(&o.x).all(|(a, b)| same_values(*a, *b))
                    });
                if !same {
                    return Err(state("its engine was told other observations"));
                }
                opt.bounds().into_iter().map(|(l, u)| [l, u]).collect()
            }
            (Engine::Random(r), PlannerMethod::Random) => {
                r.check_state()
                    .map_err(|e| state(format!("it is inconsistent: {e}")))?;
                if r.observation_count() != told {
                    return Err(state("its engine was told another number of observations"));
                }
                r.bounds().into_iter().map(|(l, u)| [l, u]).collect()
            }
            _ => return Err(state("its engine is not of its method")),
        };
        if engine_bounds != saved.bounds {
            return Err(state("its engine has other bounds"));
        }
        let warm = Warm {
            run_id: saved.run_id,
            method: saved.method,
            bounds: saved.bounds,
            seed: saved.seed,
            initial: saved.initial,
            told: history.to_vec(),
            engine: saved.engine,
        };
        if !warm.continued_by(req) {
            return Err(state(
                "it belongs to another run, method, space, seed or design",
            ));
        }
        Ok(warm)
    }
}
