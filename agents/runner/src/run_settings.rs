//! What a run is asked to do ([`RunSettings`], a plain struct: `graspopt run` fills it from
//! its flags, tests by hand), and how it becomes an [`Embedded`] run: a new one, or one
//! resumed from its results folder's journal with its recorded settings.

use std::path::{Path, PathBuf};

use graspopt_bus::BusConfig;
use graspopt_coordinator::{Conflicts, CoordinatorConfig, RunSpec};
use graspopt_protocol::{PlannerMethod, RunId};
use graspopt_sim::{ContactModel, ParamKind};
use graspopt_trial::{Evaluator, Metric, ReferenceFrame, TrialSettings};
use serde::{Deserialize, Serialize};

use crate::embedded::{Embedded, own_bus};
use crate::error::RunnerError;

type Result<T> = std::result::Result<T, RunnerError>;

/// An embedded run's settings. `explicit(name)` in [`RunSettings::resolve`] names them by
/// these field names (and the [`TrialSettings`] field names; `range` for its `ranges`).
#[derive(Debug, Clone)]
pub struct RunSettings {
    /// Run id (one key chunk).
    pub run: String,
    /// Object, hand and scoring.
    pub trial: TrialSettings,
    /// Simulated hand workers (0: only hands that attach from outside).
    pub workers: usize,
    /// What the simulated hands measure.
    pub sensing: graspopt_hand::Sensing,
    /// Trial budget.
    pub trials: u64,
    /// The trial parameters, in order.
    pub params: Vec<ParamKind>,
    pub method: PlannerMethod,
    /// Size of the initial design (`None`: the engine's).
    pub initial: Option<u32>,
    /// Seed of the planner and of perception's noise.
    pub seed: u64,
    /// Results folder (`None`: `results/<run>`).
    pub out: Option<PathBuf>,
    /// Continue the run recorded in the results folder's journal.
    pub resume: bool,
    /// Minimum duration of a simulated trial (milliseconds).
    pub trial_cost_ms: u64,
    /// Lease of a trial (milliseconds).
    pub lease_ms: u64,
    /// Perception's position error, standard deviation per axis (metres).
    pub position_noise: f64,
    /// Perception's orientation error, standard deviation per axis (radians).
    pub rotation_noise: f64,
    pub bus: BusConfig,
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            run: "run".into(),
            trial: TrialSettings::default(),
            workers: 3,
            sensing: graspopt_hand::Sensing::Clouds,
            trials: 60,
            params: vec![ParamKind::Approach, ParamKind::Vertical],
            method: PlannerMethod::Bo,
            initial: None,
            seed: 0,
            out: None,
            resume: false,
            trial_cost_ms: 0,
            lease_ms: 30_000,
            position_noise: 0.0,
            rotation_noise: 0.0,
            bus: BusConfig::default(),
        }
    }
}

/// The settings of an embedded run beyond its spec (the object's mesh, the scoring,
/// perception's noise), recorded in the run's spec so that a resumed run restores them.
/// The stored layout is unchanged since the first recorded runs: names, not enums.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct JournaledSettings {
    mesh: Option<PathBuf>,
    /// Runs recorded before `--mesh-scale` existed used their meshes in metres.
    #[serde(default = "unit_scale")]
    mesh_scale: f64,
    contacts: String,
    metric: String,
    frame: String,
    torque_scale: Option<f64>,
    position_noise: f64,
    rotation_noise: f64,
    /// How the run was executed (absent in runs recorded before they were kept): the
    /// proposals depend on the number of workers, so a resumed run keeps it unless
    /// `workers` is given.
    #[serde(default)]
    workers: Option<usize>,
    #[serde(default)]
    trial_cost_ms: Option<u64>,
    #[serde(default)]
    lease_ms: Option<u64>,
    /// The hand's URDF file, when the run's hand came from one (the spec records the hand's
    /// name, which no simulated worker can build from): absent for built-in hands.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hand_file: Option<PathBuf>,
    /// What the simulated hands measured (absent: clouds, as before hands could sense
    /// forces).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sensing: Option<String>,
}

fn unit_scale() -> f64 {
    1.0
}

/// `path` made absolute where it exists, so that a run resumed from another folder finds it.
fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

impl JournaledSettings {
    fn of(s: &RunSettings) -> JournaledSettings {
        JournaledSettings {
            mesh: s.trial.mesh.as_deref().map(canonical),
            mesh_scale: s.trial.mesh_scale,
            contacts: s.trial.contacts.name().into(),
            metric: s.trial.metric.name().into(),
            frame: s.trial.frame.name().into(),
            torque_scale: s.trial.torque_scale,
            position_noise: s.position_noise,
            rotation_noise: s.rotation_noise,
            workers: Some(s.workers),
            trial_cost_ms: Some(s.trial_cost_ms),
            lease_ms: Some(s.lease_ms),
            hand_file: graspopt_sim::builtin_hand(&s.trial.hand)
                .is_none()
                .then(|| canonical(Path::new(s.trial.hand.trim()))),
            sensing: (s.sensing != graspopt_hand::Sensing::Clouds)
                .then(|| s.sensing.name().to_string()),
        }
    }

    /// Notes the settings given explicitly that contradict the record.
    fn conflicts(
        &self,
        given: &JournaledSettings,
        c: &mut Conflicts,
        explicit: &dyn Fn(&str) -> bool,
    ) {
        let path = |m: &Option<PathBuf>| {
            m.as_ref()
                .map_or("none".into(), |p| p.display().to_string())
        };
        c.check(explicit, "mesh", path(&given.mesh), path(&self.mesh));
        c.check(explicit, "mesh_scale", given.mesh_scale, self.mesh_scale);
        c.check(explicit, "contacts", &given.contacts, &self.contacts);
        // Runs recorded before the names were canonical kept the alias typed (`ls`).
        let metric = |m: &str| Metric::parse(m).map_or_else(|_| m.to_string(), |m| m.name().into());
        c.check(
            explicit,
            "metric",
            metric(&given.metric),
            metric(&self.metric),
        );
        c.check(explicit, "frame", &given.frame, &self.frame);
        let sensing = |s: &Option<String>| s.clone().unwrap_or_else(|| "clouds".into());
        c.check(
            explicit,
            "sensing",
            sensing(&given.sensing),
            sensing(&self.sensing),
        );
        let scale = |t: Option<f64>| t.map_or("the object's radius".into(), |v| v.to_string());
        c.check(
            explicit,
            "torque_scale",
            scale(given.torque_scale),
            scale(self.torque_scale),
        );
        c.check(
            explicit,
            "position_noise",
            given.position_noise,
            self.position_noise,
        );
        c.check(
            explicit,
            "rotation_noise",
            given.rotation_noise,
            self.rotation_noise,
        );
    }

    /// `s` with these recorded settings, except the execution settings given explicitly.
    fn apply(
        &self,
        run: &RunId,
        s: &mut RunSettings,
        explicit: &dyn Fn(&str) -> bool,
    ) -> Result<()> {
        s.trial.mesh = self.mesh.clone();
        s.trial.mesh_scale = self.mesh_scale;
        if let Some(file) = self.hand_file.as_ref().filter(|_| !explicit("hand")) {
            if !file.exists() {
                return Err(RunnerError::HandFileGone {
                    run: run.clone(),
                    file: file.clone(),
                });
            }
            s.trial.hand = file.display().to_string();
        }
        let recorded = |what: String, source: Option<crate::error::Boxed>| RunnerError::Recorded {
            run: run.clone(),
            what,
            source,
        };
        s.sensing = match &self.sensing {
            None => graspopt_hand::Sensing::Clouds,
            Some(name) => graspopt_hand::Sensing::parse(name)
                .ok_or_else(|| recorded(format!("sensing {name:?}"), None))?,
        };
        s.trial.contacts = ContactModel::parse(&self.contacts)
            .map_err(|e| recorded("contact model".into(), Some(e.into())))?;
        s.trial.metric =
            Metric::parse(&self.metric).map_err(|e| recorded("metric".into(), Some(e.into())))?;
        s.trial.frame = ReferenceFrame::parse(&self.frame)
            .map_err(|e| recorded("frame".into(), Some(e.into())))?;
        s.trial.torque_scale = self.torque_scale;
        s.position_noise = self.position_noise;
        s.rotation_noise = self.rotation_noise;
        if let Some(v) = self.workers.filter(|_| !explicit("workers")) {
            s.workers = v;
        }
        if let Some(v) = self.trial_cost_ms.filter(|_| !explicit("trial_cost_ms")) {
            s.trial_cost_ms = v;
        }
        if let Some(v) = self.lease_ms.filter(|_| !explicit("lease_ms")) {
            s.lease_ms = v;
        }
        Ok(())
    }
}

impl RunSettings {
    /// The spec these settings ask for, of the hand called `hand` (its name: see
    /// [`graspopt_sim::hand_name`]), with `bounds` (a resumed run's recorded ones).
    fn spec(&self, object: String, hand: String, bounds: Option<Vec<[f64; 2]>>) -> Result<RunSpec> {
        Ok(RunSpec {
            object,
            hand,
            params: self.params.clone(),
            bounds,
            trials: self.trials,
            seed: self.seed,
            method: self.method,
            initial: self.initial,
            settings: Some(serde_json::to_value(JournaledSettings::of(self))?),
        })
    }

    /// The run these settings describe, nothing taken as given explicitly.
    pub fn embedded(&self) -> Result<Embedded> {
        self.resolve(&|_| false)
    }

    /// The run these settings describe. When resuming, the run's recorded settings replace
    /// the defaults; `explicit(name)` says whether a setting was given by the user, and a
    /// setting given that contradicts the record is an error. Nothing is written.
    pub fn resolve(&self, explicit: &dyn Fn(&str) -> bool) -> Result<Embedded> {
        let mut run = RunId::new(&self.run)?;
        let out = self
            .out
            .clone()
            .unwrap_or_else(|| Path::new("results").join(run.as_str()));
        // Resuming the run of a folder's journal: its id need not be given.
        if self.resume
            && !explicit("run")
            && let Some(only) = graspopt_coordinator::sole_run(&out.join("journal.sqlite"))
                .map_err(RunnerError::agent)?
        {
            run = only;
        }
        let resumed;
        let s = if self.resume {
            resumed = self.resumed(&run, &out, explicit)?;
            &resumed
        } else {
            check_folder_is_free(&out, &run)?;
            self
        };
        s.assemble(run, out)
    }

    fn assemble(&self, run: RunId, out: PathBuf) -> Result<Embedded> {
        if self.workers > graspopt_shm::DEFAULT_MAX_PUBLISHERS {
            return Err(RunnerError::TooManyWorkers {
                workers: self.workers,
                max: graspopt_shm::DEFAULT_MAX_PUBLISHERS,
            });
        }
        graspopt_coordinator::check_trials(self.trials).map_err(RunnerError::agent)?;
        let evaluator = Evaluator::from_settings(&self.trial, &self.params)?;
        let object = evaluator.object.name().to_string();
        let bus = own_bus(self.bus.clone(), &run)?;
        let perception = graspopt_perception::PerceptionConfig {
            object: object.clone(),
            mesh: self.trial.mesh.clone(),
            mesh_scale: self.trial.mesh_scale,
            position_noise: self.position_noise,
            rotation_noise: self.rotation_noise,
            seed: self.seed,
            period_ms: 500,
            ..Default::default()
        };
        let coordinator = CoordinatorConfig {
            journal: out.join("journal.sqlite"),
            lease_ms: self.lease_ms,
            ..Default::default()
        };
        // Checked before anything is written, so a refused run leaves no trace.
        if !(1..=graspopt_coordinator::MAX_WAIT_MS).contains(&self.lease_ms) {
            return Err(RunnerError::Lease {
                lease_ms: self.lease_ms,
                max: graspopt_coordinator::MAX_WAIT_MS,
            });
        }
        // A trial that outlasts its lease is re-issued before it can end, again and again.
        if self.trial_cost_ms >= self.lease_ms {
            return Err(RunnerError::TrialCost {
                trial_cost_ms: self.trial_cost_ms,
                lease_ms: self.lease_ms,
            });
        }
        perception.validate().map_err(RunnerError::Noise)?;
        Ok(Embedded {
            // The run's ranges are recorded with it (a resumed run keeps them).
            spec: self.spec(
                object,
                evaluator.hand.name().to_string(),
                Some(graspopt_coordinator::bounds_of(&evaluator.space)),
            )?,
            workers: self.workers,
            resume: self.resume,
            perception,
            metric: graspopt_metric::MetricConfig {
                score: evaluator.score,
                contacts: evaluator.contacts,
                ..Default::default()
            },
            hand: graspopt_hand::HandConfig {
                hand: self.trial.hand.clone(),
                sensing: self.sensing,
                trial_cost_ms: self.trial_cost_ms,
                ..Default::default()
            },
            coordinator,
            out,
            run,
            bus,
            evaluator,
        })
    }

    /// These settings with those recorded for `run` in `out`'s journal (see
    /// [`graspopt_coordinator::reconcile`]).
    fn resumed(
        &self,
        run: &RunId,
        out: &Path,
        explicit: &dyn Fn(&str) -> bool,
    ) -> Result<RunSettings> {
        let journal = out.join("journal.sqlite");
        if !journal.exists() {
            return Err(RunnerError::NoJournal { journal });
        }
        let recorded =
            graspopt_coordinator::journaled_spec(&journal, run).map_err(RunnerError::agent)?;
        let Some(recorded) = recorded else {
            let runs =
                graspopt_coordinator::journaled_runs(&journal).map_err(RunnerError::agent)?;
            let run = run.clone();
            if runs.is_empty() {
                return Err(RunnerError::NotRecorded { run, journal });
            }
            let runs = graspopt_coordinator::quoted_runs(&runs);
            return Err(RunnerError::OtherRuns { run, journal, runs });
        };
        let hand = graspopt_sim::hand_name(&self.trial.hand)?;
        let mut given = self.spec(self.trial.object.clone(), hand, recorded.bounds.clone())?;
        given.settings = None;
        let mut conflicts = graspopt_coordinator::resume_conflicts(&recorded, &given, explicit);
        let recorded_settings = recorded
            .settings
            .as_ref()
            .and_then(|v| serde_json::from_value::<JournaledSettings>(v.clone()).ok());
        if let Some(r) = &recorded_settings {
            r.conflicts(&JournaledSettings::of(self), &mut conflicts, explicit);
        }
        if explicit("range") {
            let contrary = graspopt_coordinator::range_conflicts(&recorded, &self.trial.ranges);
            conflicts.0.extend(contrary);
        }
        if let Some(e) = conflicts.into_error(run) {
            return Err(RunnerError::agent(e));
        }
        let spec = graspopt_coordinator::reconcile(run, &recorded, &given, explicit)
            .map_err(RunnerError::agent)?;
        let mut s = self.clone();
        s.run = run.as_str().to_string();
        // The recorded name; a hand given again (a file moved, say) is taken as given: its
        // name agreed with the record.
        if !explicit("hand") {
            s.trial.hand = spec.hand.clone();
        }
        s.params = spec.params.clone();
        s.trial.ranges = spec.ranges();
        s.trials = spec.trials;
        s.seed = spec.seed;
        s.method = spec.method;
        s.initial = spec.initial;
        if let Some(r) = &recorded_settings {
            r.apply(run, &mut s, explicit)?;
        }
        // A standalone coordinator's run has only the spec on record.
        if s.trial.mesh.is_none() {
            s.trial.object = spec.object.clone();
        }
        Ok(s)
    }
}

/// Refuses a new run in a results folder whose journal holds other runs: their
/// `trials.csv`, `trials.json` and `best.svg` would be overwritten.
fn check_folder_is_free(out: &Path, run: &RunId) -> Result<()> {
    let others: Vec<String> = graspopt_coordinator::journaled_runs(&out.join("journal.sqlite"))
        .map_err(RunnerError::agent)?
        .into_iter()
        .filter(|id| id != run.as_str())
        .collect();
    if !others.is_empty() {
        return Err(RunnerError::FolderTaken {
            out: out.to_path_buf(),
            runs: graspopt_coordinator::quoted_runs(&others),
            it: if others.len() == 1 { "it" } else { "one" },
            run_flag: if others.len() == 1 { "" } else { " --run ID" },
        });
    }
    Ok(())
}
