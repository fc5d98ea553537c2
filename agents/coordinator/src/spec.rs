//! What a run is and where it is recorded: the run spec, resuming (conflicting flags, a
//! raised budget), the trial space, and opening the run in the journal with the state
//! rebuilt from it. Journal glue: no network.

use std::collections::BTreeMap;

use anyhow::{Context, bail};
use graspopt_bus::now_ms;
use graspopt_journal::{Journal, RunLifecycle, RunRecord, TrialState, event_kind};
use graspopt_protocol::{ObjectEstimate, PlannerMethod, RunId};
use graspopt_sim::{Object, ParamKind, ParamSpec, TrialSpace};
use serde::{Deserialize, Serialize};

use crate::state::{RunState, Trial, TrialPhase};

/// What a run is: recorded in the journal when the run is created, and taken from there when
/// it resumes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// The object the run is about (perception must agree).
    pub object: String,
    pub hand: String,
    pub params: Vec<ParamKind>,
    /// `[lower, upper]` per parameter; `None`: the simulator's defaults for the object.
    pub bounds: Option<Vec<[f64; 2]>>,
    /// Number of trials.
    pub trials: u64,
    pub seed: u64,
    pub method: PlannerMethod,
    /// Size of the initial design (space-filling, not model-based) (`None`: the engine's default).
    pub initial: Option<u32>,
    /// How the tool that created the run set up the other agents (the object's mesh, the
    /// scoring, perception's noise), kept so that resuming the run restores them. Opaque to
    /// the coordinator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settings: Option<serde_json::Value>,
}

impl RunSpec {
    /// The recorded bounds as ranges of the parameters (none when the run recorded no
    /// bounds: the simulator's defaults).
    pub fn ranges(&self) -> Vec<ParamSpec> {
        let Some(bounds) = &self.bounds else {
            return Vec::new();
        };
        self.params
            .iter()
            .zip(bounds)
            .map(|(&kind, b)| ParamSpec {
                kind,
                lower: b[0],
                upper: b[1],
            })
            .collect()
    }
}

/// The bounds of a space's parameters, as a run spec records them.
pub fn bounds_of(space: &TrialSpace) -> Vec<[f64; 2]> {
    space.bounds().iter().map(|b| [b.0, b.1]).collect()
}

/// The ranges given for a run being resumed (`--range`) that contradict its record, each
/// described as the other flags' are: a range must be the recorded bounds of one of the
/// run's parameters.
pub fn range_conflicts(recorded: &RunSpec, ranges: &[ParamSpec]) -> Vec<String> {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9;
    let names: Vec<&str> = recorded.params.iter().map(|k| k.name()).collect();
    let mut out = Vec::new();
    for r in ranges {
        let Some(i) = recorded.params.iter().position(|k| *k == r.kind) else {
            out.push(format!(
                "--range {r} (the run's parameters are {})",
                names.join(", ")
            ));
            continue;
        };
        match recorded.bounds.as_ref().and_then(|b| b.get(i)) {
            None => out.push(format!(
                "--range {r} (the run has the simulator's default range of {})",
                r.kind
            )),
            Some(b) if !(same(b[0], r.lower) && same(b[1], r.upper)) => {
                let had = ParamSpec {
                    lower: b[0],
                    upper: b[1],
                    ..*r
                };
                out.push(format!("--range {r} (the run has {had})"));
            }
            Some(_) => {}
        }
    }
    out
}

/// The run's recorded spec in the journal at `path`, if the file and the run exist.
pub fn recorded_spec(path: &std::path::Path, run: &RunId) -> anyhow::Result<Option<RunSpec>> {
    if !path.exists() {
        return Ok(None);
    }
    let journal = Journal::open(path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    let Some(record) = journal.run(run.as_str())? else {
        return Ok(None);
    };
    let spec = serde_json::from_str::<RunSpec>(&record.config_json)
        .with_context(|| format!("run {run:?}: journal holds an unreadable run spec"))?;
    Ok(Some(spec))
}

/// The run ids the journal at `path` holds, oldest first (none if there is no such file).
pub fn recorded_runs(path: &std::path::Path) -> anyhow::Result<Vec<String>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let journal = Journal::open(path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    Ok(journal.runs()?.into_iter().map(|r| r.run_id).collect())
}

/// `"a", "b"`: run ids quoted, for messages.
pub fn quoted_runs(ids: &[String]) -> String {
    ids.iter()
        .map(|id| format!("{id:?}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The run a `--resume` without `--run` continues: the only run of the journal at `path`
/// (`None` when there is no such file or it holds no run). A journal of several runs is an
/// error that lists them.
pub fn sole_run(path: &std::path::Path) -> anyhow::Result<Option<RunId>> {
    let runs = recorded_runs(path)?;
    match runs.as_slice() {
        [] => Ok(None),
        [one] => Ok(Some(RunId::new(one)?)),
        _ => bail!(
            "the journal {} holds {} runs ({}): say which to resume with --run",
            path.display(),
            runs.len(),
            quoted_runs(&runs)
        ),
    }
}

/// Flags given on the command line that contradict the record of a run being resumed,
/// each described as `--flag given (the run has recorded)`.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Conflicts(pub Vec<String>);

impl Conflicts {
    /// Notes `--flag` (underscores written as dashes) if it was given (`explicit(flag)`)
    /// with a value other than the recorded one.
    pub fn check<T: PartialEq + std::fmt::Display>(
        &mut self,
        explicit: &dyn Fn(&str) -> bool,
        flag: &str,
        given: T,
        recorded: T,
    ) {
        if explicit(flag) && given != recorded {
            let flag = flag.replace('_', "-");
            self.0
                .push(format!("--{flag} {given} (the run has {recorded})"));
        }
    }
}

/// The flags given on the command line (`explicit(name)`: `--name` was given; `object`,
/// `hand`, `params`, `trials`, `seed`, `method`, `initial`) whose values in `given`
/// contradict the recorded spec of a run being resumed. A larger budget is not a
/// contradiction: resuming may raise it.
pub fn resume_conflicts(
    recorded: &RunSpec,
    given: &RunSpec,
    explicit: &dyn Fn(&str) -> bool,
) -> Conflicts {
    let mut c = Conflicts::default();
    c.check(explicit, "object", &given.object, &recorded.object);
    c.check(explicit, "hand", &given.hand, &recorded.hand);
    let params = |s: &RunSpec| param_names(s).join(",");
    c.check(explicit, "params", params(given), params(recorded));
    c.check(explicit, "seed", given.seed, recorded.seed);
    let method = |s: &RunSpec| format!("{:?}", s.method).to_lowercase();
    c.check(explicit, "method", method(given), method(recorded));
    let initial = |s: &RunSpec| {
        s.initial
            .map_or("the engine's default".to_string(), |n| n.to_string())
    };
    c.check(explicit, "initial", initial(given), initial(recorded));
    if explicit("trials") && given.trials < recorded.trials {
        c.0.push(format!(
            "--trials {} (the run has a budget of {}; resuming can raise it, not lower it)",
            given.trials, recorded.trials
        ));
    }
    c
}

impl Conflicts {
    /// The error for a resumed run whose flags contradict its record (`None`: none do).
    pub fn into_error(self, run: &RunId) -> Option<anyhow::Error> {
        (!self.0.is_empty()).then(|| {
            anyhow::anyhow!(
                "run {run:?} was recorded with other settings: {}. Drop these flags to resume it, or start a new run (another --run id)",
                self.0.join("; ")
            )
        })
    }
}

/// The spec a resumed run continues with: the recorded one, with the budget raised when
/// `--trials` asks for more. Contradicting flags (see [`resume_conflicts`]) are an error
/// naming them, since the run's trials were made with the recorded values.
pub fn reconcile(
    run: &RunId,
    recorded: &RunSpec,
    given: &RunSpec,
    explicit: &dyn Fn(&str) -> bool,
) -> anyhow::Result<RunSpec> {
    if let Some(e) = resume_conflicts(recorded, given, explicit).into_error(run) {
        return Err(e);
    }
    let mut spec = recorded.clone();
    if explicit("trials") {
        spec.trials = spec.trials.max(given.trials);
    }
    Ok(spec)
}

/// The trial space of a run on an object estimate.
pub fn trial_space(
    spec: &RunSpec,
    estimate: &ObjectEstimate,
) -> anyhow::Result<(TrialSpace, Vec<[f64; 2]>)> {
    let object = graspopt_convert::object_from_estimate(estimate)
        .context("coordinator: the object estimate")?;
    let mut space = TrialSpace::with_params(&object, &spec.params).context("run spec")?;
    if let Some(bounds) = &spec.bounds {
        for (i, p) in space.params.iter_mut().enumerate() {
            let b = bounds
                .get(i)
                .with_context(|| format!("run spec: no bounds for parameter {i}"))?;
            (p.lower, p.upper) = (b[0], b[1]);
        }
        space = TrialSpace::new(space.reference, space.params).context("run spec")?;
    }
    let bounds = bounds_of(&space);
    Ok((space, bounds))
}

/// Parameter names, as the journal and CSV show them.
pub fn param_names(spec: &RunSpec) -> Vec<String> {
    spec.params
        .iter()
        .map(|k| {
            serde_json::to_value(k)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| format!("{k:?}"))
        })
        .collect()
}

/// Opens (or creates) the run in the journal and rebuilds the state from it. Resuming uses
/// the recorded spec, with the budget raised if `spec` asks for more trials (pass the result
/// of [`reconcile`]). Not resuming, a recorded run that issued no trial is started afresh
/// with `spec`; one that has trials is an error.
pub fn open_run(
    journal: &mut Journal,
    run: &RunId,
    spec: &RunSpec,
    resume: bool,
) -> anyhow::Result<(RunSpec, RunState)> {
    let place = journal
        .path()
        .map_or_else(|| "the journal".to_string(), |p| p.display().to_string());
    let mut existing = journal.run(run.as_str())?;
    if existing.is_some() && !resume {
        // A start that stopped before its first trial (a wrong address, say) leaves its run
        // recorded with nothing in it: the same command starts it afresh.
        if journal.remove_unstarted_run(run.as_str())? {
            tracing::warn!(
                "coordinator: run {run:?} is in {place} without any trial (an earlier start issued none): starting it afresh"
            );
            existing = None;
        } else {
            let trials = journal.trials(run.as_str())?.len();
            bail!(
                "run {run:?} already exists in {place} with {trials} trial{}: resume it (--resume; for a launched run, graspopt launch --resume FILE) or choose another run id",
                if trials == 1 { "" } else { "s" }
            );
        }
    }
    let spec = match existing {
        Some(record) => continue_run(journal, run, spec, &record)?,
        None => {
            if resume {
                // A supervised coordinator is restarted with the same command line, so
                // `--resume` also starts a run that was never recorded; it says so.
                tracing::warn!(
                    "coordinator: run {run:?} is not in {place} yet: --resume starts it"
                );
            }
            journal.create_run(&RunRecord {
                run_id: run.as_str().to_string(),
                created_ms: now_ms(),
                config_json: serde_json::to_string(spec)?,
                param_names: param_names(spec),
                status: RunLifecycle::Running,
            })?;
            spec.clone()
        }
    };
    let state = rebuild_state(journal, run, spec.trials)?;
    Ok((spec, state))
}

/// The spec of a recorded run being resumed: its record, with the budget raised (and
/// recorded) when `spec` asks for more trials; the run is marked running again.
fn continue_run(
    journal: &mut Journal,
    run: &RunId,
    spec: &RunSpec,
    record: &RunRecord,
) -> anyhow::Result<RunSpec> {
    let recorded = serde_json::from_str::<RunSpec>(&record.config_json)
        .with_context(|| format!("run {run:?}: journal holds an unreadable run spec"))?;
    // A resumed run keeps its record; only its budget may grow (see `reconcile`).
    let spec = if spec.trials > recorded.trials {
        let before = recorded.trials;
        let raised = RunSpec {
            trials: spec.trials,
            ..recorded
        };
        journal.set_run_config(run.as_str(), &serde_json::to_string(&raised)?)?;
        tracing::warn!(
            "coordinator: run {run:?}: budget raised from {before} to {} trials",
            raised.trials
        );
        raised
    } else {
        recorded
    };
    if record.status != RunLifecycle::Running {
        journal.set_run_status(run.as_str(), RunLifecycle::Running, now_ms())?;
    }
    Ok(spec)
}

/// The state of the run as the journal records it, with a budget of `budget` trials.
fn rebuild_state(journal: &Journal, run: &RunId, budget: u64) -> anyhow::Result<RunState> {
    let mut state = RunState::new(budget);
    let mut rows = journal.trials(run.as_str())?;
    // Who each attempt went to, so that late results of attempts issued before a restart
    // are still accepted.
    let mut issued: BTreeMap<u64, BTreeMap<u32, String>> = BTreeMap::new();
    // Where each completed trial's result stands in the journal's events.
    let mut completed_at: BTreeMap<u64, i64> = BTreeMap::new();
    for e in journal.events(run.as_str())? {
        if e.kind == event_kind::ISSUED || e.kind == event_kind::REISSUED {
            issued
                .entry(e.trial_id)
                .or_default()
                .insert(e.attempt, e.worker.clone());
        } else if e.kind == event_kind::RESULT {
            completed_at.entry(e.trial_id).or_insert(e.seq);
        }
    }
    // Observations in completion order, as the planner first saw them: the order the results
    // were recorded in. Their millisecond times tie when workers answer together, and a tie
    // broken otherwise (by trial id) gave the planner a history its saved engine was not
    // told, which it then rebuilt.
    rows.sort_by_key(|r| {
        (
            completed_at.get(&r.trial_id).copied().unwrap_or(i64::MAX),
            r.trial_id,
        )
    });
    for row in &rows {
        let phase = match row.state {
            TrialState::Completed => TrialPhase::Completed {
                score: row.score.unwrap_or(f64::NAN),
            },
            TrialState::Failed => TrialPhase::Failed {
                error: row.error.clone().unwrap_or_default(),
            },
            TrialState::Running => TrialPhase::Queued {
                reason: Some("coordinator restarted".into()),
            },
        };
        let trial = Trial {
            params: row.params.clone(),
            attempts: row.attempts,
            issued_to: issued.remove(&row.trial_id).unwrap_or_default(),
            phase,
        };
        state.restore_trial(row.trial_id, trial);
        if let (TrialState::Completed, Some(score)) = (&row.state, row.score) {
            state.observe(
                row.trial_id,
                row.params.clone(),
                score,
                row.metrics.as_ref().and_then(|m| m.flag("force_closure")),
                row.forces.as_ref(),
            );
        }
    }
    Ok(state)
}

/// The run a coordinator started on its own serves (`graspopt agent coordinator`): `run`,
/// or with `resume` and no run id given explicitly (`explicit("run")`), the only run of the
/// journal; its spec is `given`, or with `resume` the recorded one reconciled with `given`
/// (contrary explicit settings refused, `ranges` among them when `explicit("range")`). A run
/// not recorded yet is started, so that a supervised coordinator can be restarted with one
/// command line; it records the bounds of `object`'s space with `ranges` in place unless
/// `given` has bounds. The journal's folder is created.
///
/// The budget `trials` must be 1 to [`MAX_TRIALS`].
pub fn standalone_run(
    run: &str,
    config: &crate::CoordinatorConfig,
    given: RunSpec,
    object: &Object,
    ranges: &[ParamSpec],
    resume: bool,
    explicit: &dyn Fn(&str) -> bool,
) -> anyhow::Result<(RunId, RunSpec)> {
    check_trials(given.trials)?;
    let mut run_id = RunId::new(run)?;
    if resume
        && !explicit("run")
        && let Some(only) = sole_run(&config.journal_path(&run_id))?
    {
        run_id = only;
    }
    let journal = config.journal_path(&run_id);
    let recorded = if resume {
        recorded_spec(&journal, &run_id)?
    } else {
        None
    };
    let spec = match recorded {
        Some(recorded) => {
            let mut c = resume_conflicts(&recorded, &given, explicit);
            if explicit("range") {
                c.0.extend(range_conflicts(&recorded, ranges));
            }
            if let Some(e) = c.into_error(&run_id) {
                return Err(e);
            }
            reconcile(&run_id, &recorded, &given, explicit)?
        }
        None => RunSpec {
            bounds: match given.bounds {
                Some(b) => Some(b),
                None => Some(bounds_of(&TrialSpace::with_ranges(
                    object,
                    &given.params,
                    ranges,
                )?)),
            },
            ..given
        },
    };
    if let Some(dir) = journal.parent()
        && !dir.as_os_str().is_empty()
    {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    }
    Ok((run_id, spec))
}

/// The largest trial budget of a run: a billion trials, days of the fastest pipeline
/// measured (`graspopt bench coordinator`); larger numbers are typos, and trial ids are
/// SQLite integers.
pub const MAX_TRIALS: u64 = 1_000_000_000;

/// Refuses a trial budget of 0 or over [`MAX_TRIALS`], naming `--trials`.
pub fn check_trials(trials: u64) -> anyhow::Result<()> {
    anyhow::ensure!(
        (1..=MAX_TRIALS).contains(&trials),
        "--trials is {trials}: it must be between 1 and {MAX_TRIALS}"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::Disposition;
    use graspopt_journal::TrialIssue;
    use graspopt_protocol::TrialResult;

    fn spec(trials: u64) -> RunSpec {
        RunSpec {
            object: "sphere".into(),
            hand: "barrett".into(),
            params: vec![ParamKind::Approach],
            bounds: None,
            trials,
            seed: 1,
            method: PlannerMethod::Random,
            initial: None,
            settings: None,
        }
    }

    #[test]
    fn resuming_keeps_the_record_names_contradicting_flags_and_may_raise_the_budget() {
        let run = RunId::new("r").unwrap();
        let recorded = spec(20);
        let given = RunSpec {
            object: "mug".into(),
            seed: 4,
            ..spec(10)
        };
        // Flags left at their defaults are not contradictions: the record wins.
        let none = |_: &str| false;
        assert_eq!(reconcile(&run, &recorded, &given, &none).unwrap(), recorded);
        // Given explicitly, they are, each named with both values.
        let all = |_: &str| true;
        let e = reconcile(&run, &recorded, &given, &all)
            .unwrap_err()
            .to_string();
        for part in [
            "--object mug (the run has sphere)",
            "--seed 4 (the run has 1)",
            "--trials 10 (the run has a budget of 20",
        ] {
            assert!(e.contains(part), "{part:?} not in {e}");
        }
        assert!(!e.contains("--hand"), "{e}");
        // A larger budget is taken; the rest stays recorded.
        let trials_only = |f: &str| f == "trials";
        let raised = reconcile(&run, &recorded, &spec(35), &trials_only).unwrap();
        assert_eq!(raised.trials, 35);
        assert_eq!(
            RunSpec {
                trials: 20,
                ..raised
            },
            recorded
        );
    }

    #[test]
    fn open_run_raises_a_finished_runs_budget() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        // Resuming a run never recorded starts it (a supervised restart's command line).
        let (started, _) = open_run(&mut journal, &run, &spec(5), true).unwrap();
        assert_eq!(started.trials, 5);
        journal
            .set_run_status("r", RunLifecycle::Finished, 10)
            .unwrap();
        let (resumed, state) = open_run(&mut journal, &run, &spec(8), true).unwrap();
        assert_eq!(resumed.trials, 8);
        assert!(!state.finished());
        let record = journal.run("r").unwrap().unwrap();
        assert_eq!(record.status, RunLifecycle::Running);
        let stored: RunSpec = serde_json::from_str(&record.config_json).unwrap();
        assert_eq!(stored.trials, 8);
        // The same budget again (or less) leaves the record as it is.
        let (again, _) = open_run(&mut journal, &run, &spec(3), true).unwrap();
        assert_eq!(again.trials, 8);
    }

    /// A resumed run gives the planner its observations in the order their results were
    /// recorded, also when they were recorded in the same millisecond.
    #[test]
    fn a_resumed_run_keeps_the_order_results_were_recorded_in() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        let spec = spec(5);
        open_run(&mut journal, &run, &spec, false).unwrap();
        for id in 1..=4 {
            journal
                .record_issue(&TrialIssue {
                    params: vec![0.01 * id as f64],
                    ..issue(id)
                })
                .unwrap();
        }
        // Recorded in one millisecond, in another order than the trial ids.
        for id in [3, 1, 4, 2] {
            let r = crate::state::tests::result(id, "a", 0.1 * id as f64);
            journal
                .record_result(&crate::core::journal_result(&r, 50))
                .unwrap();
        }
        let (_, state) = open_run(&mut journal, &run, &spec, true).unwrap();
        let order: Vec<(f64, f64)> = state.observations().iter().map(|o| (o.x[0], o.y)).collect();
        let recorded = [3, 1, 4, 2].map(|id: u64| (0.01 * id as f64, 0.1 * id as f64));
        assert_eq!(order, recorded);
    }

    /// A standalone coordinator's new run records its bounds (a range in place of its
    /// parameter's default); resumed, it keeps them, and a range that contradicts them is
    /// refused with the recorded one.
    #[test]
    fn a_run_records_its_ranges_and_a_contrary_range_is_refused_on_resume() {
        let dir = tempfile::tempdir().unwrap();
        let config = crate::CoordinatorConfig {
            journal: dir.path().join("journal.sqlite"),
            ..Default::default()
        };
        let sphere = Object::by_name("sphere").unwrap();
        let rz = ParamSpec::parse_range("rz=-3:3").unwrap();
        let given = RunSpec {
            params: vec![ParamKind::Approach, ParamKind::RotZ],
            ..spec(4)
        };
        let none = |_: &str| false;
        let (run, started) =
            standalone_run("r", &config, given.clone(), &sphere, &[rz], false, &none).unwrap();
        let approach = TrialSpace::full_6d(&sphere).params[0];
        assert_eq!(
            started.bounds,
            Some(vec![[approach.lower, approach.upper], [-3.0, 3.0]])
        );
        assert_eq!(started.ranges()[1], rz);
        let mut journal = Journal::open(&config.journal).unwrap();
        open_run(&mut journal, &run, &started, false).unwrap();
        drop(journal);
        // Resumed without ranges, or with the recorded one: the record's bounds.
        let range = |f: &str| f == "range";
        for ranges in [&[][..], &[rz][..]] {
            let (_, resumed) =
                standalone_run("r", &config, given.clone(), &sphere, ranges, true, &range).unwrap();
            assert_eq!(resumed.bounds, started.bounds);
        }
        let other = ParamSpec::parse_range("rz=-2:2").unwrap();
        let lateral = ParamSpec::parse_range("lateral=-0.1:0.1").unwrap();
        let e = standalone_run(
            "r",
            &config,
            given,
            &sphere,
            &[other, lateral],
            true,
            &range,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("--range rz=-2:2 (the run has rz=-3:3)"), "{e}");
        assert!(
            e.contains("--range lateral=-0.1:0.1 (the run's parameters are approach, rz)"),
            "{e}"
        );
        // A run recorded before runs recorded their bounds has the simulator's defaults.
        let old = spec(4);
        assert_eq!(
            range_conflicts(&old, &[ParamSpec::parse_range("x=-0.1:0").unwrap()]),
            ["--range approach=-0.1:0 (the run has the simulator's default range of approach)"]
        );
        assert!(old.ranges().is_empty());
    }

    /// A trial issued for run `r`, attempt 1.
    fn issue(trial_id: u64) -> TrialIssue {
        TrialIssue {
            run_id: "r".into(),
            trial_id,
            attempt: 1,
            params: vec![0.01],
            worker: "a".into(),
            at_ms: 10,
            lease_until_ms: 1000,
            reason: None,
        }
    }

    /// A run stopped before its first trial (a wrong address) is started afresh by the same
    /// command, with the settings given now; once a trial is issued, it must be resumed.
    #[test]
    fn a_run_without_trials_starts_afresh_and_one_with_trials_must_be_resumed() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        open_run(&mut journal, &run, &spec(5), false).unwrap();
        journal.set_planner_state("r", &[1, 2, 3], 5).unwrap();
        journal
            .set_run_status("r", RunLifecycle::Stopped, 10)
            .unwrap();
        let (again, state) = open_run(&mut journal, &run, &spec(7), false).unwrap();
        assert_eq!(again, spec(7));
        assert_eq!(state.trial_count(), 0);
        let record = journal.run("r").unwrap().unwrap();
        assert_eq!(record.status, RunLifecycle::Running);
        assert_eq!(
            serde_json::from_str::<RunSpec>(&record.config_json).unwrap(),
            spec(7)
        );
        assert_eq!(journal.planner_state("r").unwrap(), None);
        journal.record_issue(&issue(1)).unwrap();
        let e = open_run(&mut journal, &run, &spec(7), false).unwrap_err();
        let e = e.to_string();
        assert!(
            e.contains("run \"r\" already exists") && e.contains("with 1 trial:"),
            "{e}"
        );
        assert!(e.contains("--resume"), "{e}");
        assert_eq!(journal.trials("r").unwrap().len(), 1);
    }

    /// A coordinator restarted with `--resume` still accepts the late result of an attempt
    /// issued before the restart (who got each attempt comes back from the journal's events).
    #[test]
    fn a_resumed_run_accepts_results_of_attempts_issued_before_the_restart() {
        let mut journal = Journal::open_in_memory().unwrap();
        let run = RunId::new("r").unwrap();
        let spec = spec(2);
        open_run(&mut journal, &run, &spec, false).unwrap();
        for (attempt, worker) in [(1, "a"), (2, "b")] {
            journal
                .record_issue(&TrialIssue {
                    attempt,
                    worker: worker.into(),
                    at_ms: 10 * attempt as i64,
                    ..issue(1)
                })
                .unwrap();
        }
        let (_, mut state) = open_run(&mut journal, &run, &spec, true).unwrap();
        let result = |attempt: u32, worker: &str| TrialResult {
            attempt,
            ..crate::state::tests::result(1, worker, 0.5)
        };
        assert!(!state.was_issued(&result(1, "b")));
        assert!(state.was_issued(&result(2, "b")));
        assert_eq!(state.on_result(&result(1, "a"), 0), Disposition::Completed);
    }
}
