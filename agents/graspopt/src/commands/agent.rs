//! `graspopt agent <kind>`: one agent as its own process, on the bus the flags describe.
//! Settings come from `--config FILE` (TOML, the agent's settings struct) and flags override
//! them.

use graspopt_runner::signal::shutdown_signal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use graspopt_bus::{Bus, BusArgs};
use graspopt_coordinator::{CoordinatorConfig, RunSpec};
use graspopt_protocol::RunId;
use serde::Serialize;
use serde::de::DeserializeOwned;

use super::run::Method;
use super::setup::{SimArgs, param_kind};
use crate::out::outln;

#[derive(Args, Debug)]
pub struct AgentArgs {
    #[command(subcommand)]
    pub kind: Kind,
}

#[derive(Args, Debug, Clone)]
pub struct Common {
    /// The run to join.
    #[arg(long, default_value = "run")]
    pub run: String,
    /// Settings file (TOML; its keys, with an example per agent: docs/agent-config.md).
    /// Flags given win over it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Agent id (unique per run and kind).
    #[arg(long)]
    pub id: Option<String>,
    #[command(flatten)]
    pub bus: BusArgs,
}

#[derive(Subcommand, Debug)]
pub enum Kind {
    /// Publishes the object estimate.
    Perception {
        #[command(flatten)]
        common: Common,
        /// Built-in object: sphere, wine_glass, cylinder, mug, cuboid, rotated_cuboid,
        /// star_prism (default: mug).
        #[arg(long)]
        object: Option<String>,
        /// A user mesh (OBJ/STL).
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// Factor from the mesh file's units to metres (0.001 for millimetres).
        #[arg(long, requires = "mesh")]
        mesh_scale: Option<f64>,
        /// Position error of the estimate, standard deviation per axis (metres; default 0).
        #[arg(long)]
        position_noise: Option<f64>,
        /// Orientation error of the estimate, standard deviation per axis (radians; default
        /// 0).
        #[arg(long)]
        rotation_noise: Option<f64>,
        /// Seed of the estimate's noise (default 0).
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Executes trials on the simulated hand.
    Hand {
        #[command(flatten)]
        common: Common,
        /// A built-in hand (see `graspopt hands`) or a URDF file.
        #[arg(long)]
        hand: Option<String>,
        /// Minimum trial duration (milliseconds).
        #[arg(long)]
        trial_cost_ms: Option<u64>,
        /// Answer trials from recorded contact data (JSON lines, `graspopt record` writes
        /// them) instead of simulating.
        #[arg(long, value_name = "FILE")]
        replay: Option<PathBuf>,
    },
    /// Scores contact clouds.
    Metric {
        #[command(flatten)]
        common: Common,
    },
    /// Proposes trials.
    Planner {
        #[command(flatten)]
        common: Common,
    },
    /// Owns the run and its journal.
    Coordinator {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        sim: SimArgs,
        /// The journal file (default: results/<run>/journal.sqlite, where `graspopt export`
        /// looks).
        #[arg(long)]
        journal: Option<PathBuf>,
        /// Number of trials (with --resume: raises the recorded budget).
        #[arg(long, default_value_t = 60)]
        trials: u64,
        /// Trial parameters, comma-separated: x (approach), y (vertical), lateral, rx, ry, rz.
        #[arg(
            long,
            visible_alias = "axes",
            default_value = "x,y",
            value_delimiter = ','
        )]
        params: Vec<String>,
        /// How trials are proposed.
        #[arg(long, value_enum, default_value_t = Method::Bo)]
        method: Method,
        /// Size of the initial design (space-filling, not model-based) (default: the
        /// engine's).
        #[arg(long)]
        initial: Option<u32>,
        /// Seed of the planner's random choices (the same seed proposes the same trials).
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Lease of a trial: re-issued if no result comes within this time (milliseconds;
        /// default 30000).
        #[arg(long)]
        lease_ms: Option<u64>,
        /// Continue the run recorded in the journal (its only run, unless --run names one),
        /// with its recorded settings. Without --resume, a run recorded with no trial (a
        /// start that stopped before its first) starts afresh.
        #[arg(long)]
        resume: bool,
    },
}

/// Reads a TOML settings file (defaults when none): keys left out keep their defaults, and a
/// key the settings do not have is refused, naming the keys of its table (the settings'
/// format: docs/agent-config.md).
pub fn load<T: DeserializeOwned + Serialize + Default>(path: Option<&Path>) -> Result<T> {
    let Some(p) = path else {
        return Ok(T::default());
    };
    let text = std::fs::read_to_string(p)
        .with_context(|| format!("cannot read the settings file {}", p.display()))?;
    let context = || format!("settings file {}", p.display());
    let table: toml::Table = toml::from_str(&text).with_context(context)?;
    // Every key, with `null` for the settings that are none by default.
    let known = serde_json::to_value(T::default())?;
    unknown_key(&table, &known, "")
        .map_or(Ok(()), |e| Err(anyhow::anyhow!(e)))
        .with_context(context)?;
    toml::from_str(&text).with_context(context)
}

/// The first key of `table` (at `path`, a dotted table name, empty at the top) that
/// `known` (the settings' defaults as JSON) does not have, as a message listing the keys
/// there; tables are checked recursively where the default is a table too.
fn unknown_key(table: &toml::Table, known: &serde_json::Value, path: &str) -> Option<String> {
    let serde_json::Value::Object(keys) = known else {
        return None;
    };
    for (key, value) in table {
        let Some(default) = keys.get(key) else {
            let names: Vec<&str> = keys.keys().map(String::as_str).collect();
            let place = if path.is_empty() {
                "at the top level".to_string()
            } else {
                format!("in [{path}]")
            };
            return Some(format!(
                "unknown key `{key}` {place}; the keys there are {}",
                names.join(", ")
            ));
        };
        if let toml::Value::Table(inner) = value {
            let inner_path = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            if let Some(e) = unknown_key(inner, default, &inner_path) {
                return Some(e);
            }
        }
    }
    None
}

async fn until_signal<F: std::future::Future<Output = Result<()>>>(agent: F) -> Result<()> {
    tokio::select! {
        r = agent => r,
        _ = shutdown_signal() => Ok(()),
    }
}

/// `graspopt agent`; `explicit(name)` says whether `--name` was given on the command line.
pub fn run(args: &AgentArgs, explicit: &dyn Fn(&str) -> bool) -> Result<ExitCode> {
    let runtime = tokio::runtime::Runtime::new()?;
    runtime.block_on(run_async(args, explicit))
}

async fn run_async(args: &AgentArgs, explicit: &dyn Fn(&str) -> bool) -> Result<ExitCode> {
    match &args.kind {
        Kind::Perception {
            common,
            object,
            mesh,
            mesh_scale,
            position_noise,
            rotation_noise,
            seed,
        } => {
            let mut c: graspopt_perception::PerceptionConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            if let Some(v) = object {
                c.object = v.clone();
            }
            if mesh.is_some() {
                c.mesh = mesh.clone();
            }
            c.mesh_scale = mesh_scale.unwrap_or(c.mesh_scale);
            c.position_noise = position_noise.unwrap_or(c.position_noise);
            c.rotation_noise = rotation_noise.unwrap_or(c.rotation_noise);
            c.seed = seed.unwrap_or(c.seed);
            let (bus, run) = join(common).await?;
            until_signal(graspopt_perception::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Hand {
            common,
            hand,
            trial_cost_ms,
            replay,
        } => {
            let mut c: graspopt_hand::HandConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            if let Some(v) = hand {
                c.hand = v.clone();
            }
            c.trial_cost_ms = trial_cost_ms.unwrap_or(c.trial_cost_ms);
            if replay.is_some() {
                c.replay = replay.clone();
            }
            let (bus, run) = join(common).await?;
            until_signal(graspopt_hand::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Metric { common } => {
            let mut c: graspopt_metric::MetricConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            let (bus, run) = join(common).await?;
            until_signal(graspopt_metric::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Planner { common } => {
            let mut c: graspopt_planner::PlannerConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            let (bus, run) = join(common).await?;
            until_signal(graspopt_planner::run(&bus, &run, &c)).await?;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Coordinator {
            common,
            sim,
            journal,
            trials,
            params,
            method,
            initial,
            seed,
            lease_ms,
            resume,
        } => {
            let mut c: CoordinatorConfig = load(common.config.as_deref())?;
            if let Some(v) = &common.id {
                c.id = v.clone();
            }
            if let Some(v) = journal {
                c.journal = v.clone();
            }
            c.lease_ms = lease_ms.unwrap_or(c.lease_ms);
            let kinds = params
                .iter()
                .map(|p| param_kind(p))
                .collect::<Result<Vec<_>>>()?;
            anyhow::ensure!(*trials >= 1, "--trials must be at least 1");
            let mut run_id = RunId::new(&common.run)?;
            // `--resume --journal FILE` continues the run of FILE: its id need not be given.
            if *resume
                && !explicit("run")
                && let Some(only) = graspopt_coordinator::sole_run(&c.journal_path(&run_id))?
            {
                run_id = only;
            }
            let given = RunSpec {
                object: sim.object()?.name().to_string(),
                hand: sim.hand.clone(),
                params: kinds,
                bounds: None,
                trials: *trials,
                seed: *seed,
                method: method.planner(),
                initial: *initial,
                settings: None,
            };
            let journal_path = c.journal_path(&run_id);
            // With --resume, the recorded run's settings win (flags that contradict them are
            // refused); a run not recorded yet is started, so that a supervised coordinator
            // can be restarted with one command line.
            let recorded = if *resume {
                graspopt_coordinator::recorded_spec(&journal_path, &run_id)?
            } else {
                None
            };
            let spec = match recorded {
                Some(recorded) => {
                    graspopt_coordinator::reconcile(&run_id, &recorded, &given, explicit)?
                }
                None => given,
            };
            if let Some(dir) = journal_path.parent()
                && !dir.as_os_str().is_empty()
            {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("cannot create the folder {}", dir.display()))?;
            }
            let bus = Bus::open(&common.bus).await?;
            let status = graspopt_coordinator::run_until(
                &bus,
                &run_id,
                &spec,
                &c,
                *resume,
                None,
                shutdown_signal(),
            )
            .await?;
            outln!("{}", serde_json::to_string(&status)?)?;
            // 130: the shell's code for a command stopped by Ctrl-C.
            Ok(if status.phase == graspopt_protocol::RunPhase::Finished {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(130)
            })
        }
    }
}

async fn join(common: &Common) -> Result<(Bus, RunId)> {
    let run = RunId::new(&common.run)?;
    let bus = Bus::open(&common.bus).await?;
    Ok((bus, run))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The TOML example under the heading `## {kind}` of docs/agent-config.md.
    fn documented(kind: &str) -> String {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/agent-config.md");
        let doc = std::fs::read_to_string(path).unwrap();
        let section = doc.split(&format!("\n## {kind}\n")).nth(1).unwrap();
        let block = section.split("```toml\n").nth(1).unwrap();
        block.split("```").next().unwrap().to_string()
    }

    fn load_text<T: DeserializeOwned + Serialize + Default>(name: &str, text: &str) -> Result<T> {
        let dir = std::env::temp_dir().join(format!("graspopt-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        load(Some(&path))
    }

    #[test]
    fn the_documented_settings_files_are_the_defaults() {
        fn check<T>(kind: &str)
        where
            T: DeserializeOwned + Serialize + Default + PartialEq + std::fmt::Debug,
        {
            let loaded: T = load_text(&format!("{kind}.toml"), &documented(kind))
                .unwrap_or_else(|e| panic!("{kind}: {e:#}"));
            assert_eq!(loaded, T::default(), "{kind}");
        }
        check::<graspopt_perception::PerceptionConfig>("perception");
        check::<graspopt_hand::HandConfig>("hand");
        check::<graspopt_metric::MetricConfig>("metric");
        check::<graspopt_planner::PlannerConfig>("planner");
        check::<CoordinatorConfig>("coordinator");
    }

    #[test]
    fn an_unknown_key_is_refused_with_the_keys_of_its_table() {
        let err = load_text::<graspopt_hand::HandConfig>("h.toml", "trial_cost = 5\n").unwrap_err();
        let msg = format!("{err:#}");
        assert!(msg.contains("h.toml"), "{msg}");
        assert!(
            msg.contains("unknown key `trial_cost` at the top level"),
            "{msg}"
        );
        assert!(
            msg.contains("hand, id, mesh, mesh_scale, object, replay, trial_cost_ms"),
            "{msg}"
        );
        // In a table, the table's own keys.
        let text = documented("metric").replace("include_palm = true", "include_palms = true");
        let err = load_text::<graspopt_metric::MetricConfig>("m.toml", &text).unwrap_err();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("unknown key `include_palms` in [score]"),
            "{msg}"
        );
        assert!(
            msg.contains("contacts, frame, include_palm, metric, model, torque_scale"),
            "{msg}"
        );
        let text = documented("metric").replace("resolution = ", "resolutoin = ");
        let msg = format!(
            "{:#}",
            load_text::<graspopt_metric::MetricConfig>("m.toml", &text).unwrap_err()
        );
        assert!(msg.contains("`resolutoin` in [contacts.cloud]"), "{msg}");
        // Keys left out keep their defaults; flags of other kinds are not keys.
        let c: graspopt_hand::HandConfig = load_text("h.toml", "trial_cost_ms = 5\n").unwrap();
        assert_eq!((c.trial_cost_ms, c.hand.as_str()), (5, "barrett"));
    }
}
