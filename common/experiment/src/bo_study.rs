//! The Bayesian-optimisation study of thesis sections 4.6-4.8 as data: the checked plan and,
//! per object, the results of its three parts. `graspopt experiment bo` lays them out
//! (graspopt-report).
//!
//! - 1D ([`BoStudy::one_d`], figures 4.16-4.17): a run along the approach axis (two random
//!   points, stop when EI vanishes) with the model that chose each trial, and a 201-point scan;
//! - 2D ([`BoStudy::two_d`], 4.18-4.27, Table 4.1): the grid scan, BO and random search over
//!   the seeds against the grid maximum;
//! - 6D ([`BoStudy::six_d`]): BO and random search in the pose space (no grid).

use graspopt_bayesopt::{MIN_MODEL_CAP, Method, ModelCap, Preset, Settings};
use graspopt_sim::{ContactModel, ParamKind};
use graspopt_trial::Evaluator;
use graspopt_trial::scan::ScanPoint;

use crate::compare::{Comparison, MethodSummary, compare};
use crate::error::ExperimentError;
use crate::scans::{Scan, evaluator, scan};
use crate::search::{SearchSettings, Trace};
use crate::snapshot::{Snapshot, run_with_snapshots};
use crate::target::median;

/// Thesis Table 4.1 (total, 5%, 10%, 20%), its rows read as shifted by one line (the text's
/// table starts with an unnamed row and ends with an empty one).
pub const THESIS_TABLE_4_1: [(&str, [u32; 4]); 7] = [
    ("sphere", [551, 14, 14, 14]),
    ("wine_glass", [306, 31, 19, 19]),
    ("cylinder", [485, 39, 20, 20]),
    ("mug", [331, 55, 55, 1]),
    ("cuboid", [564, 1, 1, 1]),
    ("rotated_cuboid", [388, 59, 59, 59]),
    ("star_prism", [402, 105, 105, 31]),
];

/// Figures 4.16-4.17: the figure and its object.
pub const ONE_D_FIGURES: [(&str, &str); 2] = [("4.16", "sphere"), ("4.17", "star_prism")];
/// Points of the 1D reference scan and of the model's grid.
pub const ONE_D_POINTS: usize = 201;
/// Trials of a 1D run at most (it stops when EI vanishes).
pub const ONE_D_BUDGET: usize = 40;

/// Largest accepted values of the sizes (beyond them a run takes hours or the grid does not
/// fit in memory).
pub const MAX_SEEDS: u64 = 1000;
pub const MAX_BUDGET: usize = 2000;
pub const MAX_STEPS: usize = 1000;
/// The most trials in flight of one run.
pub const MAX_WORKERS: usize = 256;

/// The parameters of the 2D part: approach x vertical.
pub const TWO_D: [ParamKind; 2] = [ParamKind::Approach, ParamKind::Vertical];
/// The parameters of the 6D part: three offsets and a rotation vector.
pub const SIX_D: [ParamKind; 6] = ParamKind::ALL;

/// A part of the study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    OneD,
    TwoD,
    SixD,
}

impl Part {
    /// Every part, in the order they run.
    pub const ALL: [Part; 3] = [Part::OneD, Part::TwoD, Part::SixD];

    /// The part named `name` (one of [`Part::name`]), if any.
    pub fn from_name(name: &str) -> Option<Part> {
        Part::ALL.into_iter().find(|p| p.name() == name)
    }

    /// `1d`, `2d` or `6d`.
    pub fn name(self) -> &'static str {
        match self {
            Part::OneD => "1d",
            Part::TwoD => "2d",
            Part::SixD => "6d",
        }
    }
}

/// The study as asked for (the flags of `graspopt experiment bo`), before [`BoStudy::plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct BoRequest {
    /// Hand: a built-in name or a URDF file.
    pub hand: String,
    pub seeds: u64,
    pub first_seed: u64,
    /// Trials per 2D run and per 6D run.
    pub budget: usize,
    pub budget_6d: usize,
    /// Grid of the 2D scan: one count for both axes or two, like `67,33`.
    pub steps: String,
    /// Objects of the 2D and 6D parts (empty: the seven of the thesis).
    pub objects: Vec<String>,
    pub parts: Vec<Part>,
    pub engine: Preset,
    /// The engine's model cap: the preset's, or another ([`ModelCapChoice`]).
    pub model_cap: ModelCapChoice,
    /// Trials in flight in the 2D and 6D runs (1: sequential; see
    /// [`SearchSettings::workers`]).
    pub workers: usize,
    pub contacts: ContactModel,
    /// Worker threads (0: all cores).
    pub threads: usize,
}

/// The model cap of the study's engine ([`Settings::model_cap`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ModelCapChoice {
    /// The preset's.
    #[default]
    Preset,
    /// None: every observation modelled (the exact GP).
    Exact,
    /// A cap of this many observations, with the default shares ([`ModelCap::of`]).
    Size(usize),
}

/// The checked plan of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct BoStudy {
    pub hand: String,
    pub engine: Preset,
    pub model_cap: ModelCapChoice,
    pub workers: usize,
    pub contacts: ContactModel,
    pub parts: Vec<Part>,
    /// The 2D grid, approach x vertical.
    pub steps: [usize; 2],
    /// Objects of the 2D and 6D parts, without repeats.
    pub objects: Vec<String>,
    pub seeds: Vec<u64>,
    pub budget: usize,
    pub budget_6d: usize,
    pub threads: usize,
}

/// The 1D part on one object.
#[derive(Debug, Clone, PartialEq)]
pub struct OneD {
    /// The scan along the approach axis ([`ONE_D_POINTS`] points).
    pub truth: Vec<ScanPoint>,
    /// The run.
    pub trace: Trace,
    /// The model that chose each trial.
    pub snaps: Vec<Snapshot>,
}

/// The 2D part on one object.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoD {
    /// The grid scan.
    pub scan: Scan,
    /// Its maximum, the reference of the comparison.
    pub reference: f64,
    /// BO and random search over the seeds.
    pub cmp: Comparison,
    /// Median over seeds of the trials until BO's stopping rule fired (the budget if never).
    pub median_total: f64,
    /// Seeds whose stopping rule fired within the budget.
    pub stopped: usize,
    /// Median over seeds of BO's best score.
    pub median_best: f64,
}

/// The 6D part on one object.
#[derive(Debug, Clone, PartialEq)]
pub struct SixD {
    /// BO and random search over the seeds, against the best any run found.
    pub cmp: Comparison,
    /// Per method (BO, random), the median best score after each of [`BoStudy::checkpoints_6d`].
    pub bo_medians: Vec<f64>,
    pub random_medians: Vec<f64>,
}

/// The summary of `method` in `cmp`.
pub fn summary(cmp: &Comparison, method: Method) -> Result<&MethodSummary, ExperimentError> {
    cmp.methods
        .iter()
        .find(|m| m.method == method)
        .ok_or_else(|| ExperimentError::Settings(format!("no runs of {method:?}")))
}

fn settings_error<T>(text: String) -> Result<T, ExperimentError> {
    Err(ExperimentError::Settings(text))
}

/// The grid of the 2D scan from `--steps` (one count for both axes, or two).
fn grid_steps(steps: &str) -> Result<[usize; 2], ExperimentError> {
    let counts: Vec<usize> = steps
        .split(',')
        .map(|s| s.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|e| {
            ExperimentError::Settings(format!(
                "--steps {:?}: expected counts like 67,33: {e}",
                steps
            ))
        })?;
    let [nx, ny] = match counts[..] {
        [n] => [n, n],
        [nx, ny] => [nx, ny],
        _ => {
            return settings_error(format!(
                "--steps {:?}: expected one count or two, like 67,33",
                steps
            ));
        }
    };
    if ![nx, ny].iter().all(|n| (2..=MAX_STEPS).contains(n)) {
        return settings_error(format!(
            "--steps {:?}: each count must be between 2 and {MAX_STEPS}",
            steps
        ));
    }
    Ok([nx, ny])
}

/// Each part's budget: more than the engine's initial design (a run no longer than it never
/// uses the model) and at most [`MAX_BUDGET`].
fn check_budgets(r: &BoRequest) -> Result<(), ExperimentError> {
    for (flag, budget, dim, part) in [
        ("--budget", r.budget, 2, Part::TwoD),
        ("--budget-6d", r.budget_6d, 6, Part::SixD),
    ] {
        let init = Settings::default_n_init(dim);
        if r.parts.contains(&part) && !(init < budget && budget <= MAX_BUDGET) {
            return settings_error(format!(
                "{flag} must be more than the engine's {init} initial-design trials in {dim}D and at most {MAX_BUDGET}, got {budget}"
            ));
        }
    }
    Ok(())
}

/// The objects of `--objects` (all built-in objects when none), each known, without
/// repeats.
fn object_names(objects: &[String]) -> Result<Vec<String>, ExperimentError> {
    let mut unique: Vec<String> = Vec::new();
    let named: Vec<String> = if objects.is_empty() {
        graspopt_sim::Object::names()
            .into_iter()
            .map(String::from)
            .collect()
    } else {
        objects.iter().map(|s| s.trim().to_string()).collect()
    };
    for o in named {
        if o.is_empty() {
            return settings_error("--objects has an empty name (two commas in a row?)".into());
        }
        graspopt_sim::Object::by_name(&o)?;
        if !unique.contains(&o) {
            unique.push(o);
        }
    }
    Ok(unique)
}

impl BoStudy {
    /// Checks the request (error messages name the flags of `graspopt experiment bo`).
    pub fn plan(r: &BoRequest) -> Result<BoStudy, ExperimentError> {
        if !(1..=MAX_SEEDS).contains(&r.seeds) {
            return settings_error(format!(
                "--seeds must be between 1 and {MAX_SEEDS}, got {}",
                r.seeds
            ));
        }
        let Some(end) = r.first_seed.checked_add(r.seeds) else {
            return settings_error("--first-seed + --seeds must stay below 2^64".into());
        };
        if !(1..=MAX_WORKERS).contains(&r.workers) {
            return settings_error(format!(
                "--workers must be between 1 and {MAX_WORKERS}, got {}",
                r.workers
            ));
        }
        if let ModelCapChoice::Size(n) = r.model_cap
            && n < MIN_MODEL_CAP
        {
            return settings_error(format!(
                "--model-cap must be at least {MIN_MODEL_CAP} observations, got {n}"
            ));
        }
        let [nx, ny] = grid_steps(&r.steps)?;
        check_budgets(r)?;
        let objects = object_names(&r.objects)?;
        Ok(BoStudy {
            hand: r.hand.clone(),
            engine: r.engine,
            model_cap: r.model_cap,
            workers: r.workers,
            contacts: r.contacts,
            parts: r.parts.clone(),
            steps: [nx, ny],
            objects,
            seeds: (r.first_seed..end).collect(),
            budget: r.budget,
            budget_6d: r.budget_6d,
            threads: r.threads,
        })
    }

    /// The engine's settings: the preset's, with the model cap of [`BoStudy::model_cap`].
    pub fn engine_settings(&self) -> Settings {
        let mut s = self.engine.settings();
        match self.model_cap {
            ModelCapChoice::Preset => {}
            ModelCapChoice::Exact => s.model_cap = None,
            ModelCapChoice::Size(n) => s.model_cap = Some(ModelCap::of(n)),
        }
        s
    }

    /// Whether the plan runs `part`.
    pub fn runs(&self, part: Part) -> bool {
        self.parts.contains(&part)
    }

    /// The evaluator of `object` over `kinds` with the plan's contact model.
    fn evaluator(&self, object: &str, kinds: &[ParamKind]) -> Result<Evaluator, ExperimentError> {
        let mut ev = evaluator(&self.hand, object, kinds)?;
        ev.score.contacts = self.contacts;
        Ok(ev)
    }

    /// Figures 4.16-4.17 on `object`: a 1D run (two random points, stop when EI vanishes) from
    /// the first seed, the model after each step, and the scan it is drawn over.
    pub fn one_d(&self, object: &str) -> Result<OneD, ExperimentError> {
        let ev = self.evaluator(object, &[ParamKind::Approach])?;
        let truth = scan(&ev, &[ONE_D_POINTS], self.threads)?.points;
        let settings = SearchSettings {
            method: Method::Bo(self.engine),
            budget: ONE_D_BUDGET,
            n_init: Some(2),
            stop_on_small_ei: true,
            engine: Some(self.engine_settings()),
            workers: 1,
        };
        let first = self.seeds.first().copied().unwrap_or_default();
        let (trace, snaps) = run_with_snapshots(&ev, &settings, first, ONE_D_POINTS)?;
        Ok(OneD {
            truth,
            trace,
            snaps,
        })
    }

    /// BO (with the plan's engine) and random search over the seeds on `ev`.
    fn bo_and_random(
        &self,
        ev: &Evaluator,
        budget: usize,
        reference: Option<f64>,
    ) -> Result<Comparison, ExperimentError> {
        let template = SearchSettings {
            method: Method::Bo(self.engine),
            budget,
            n_init: None,
            stop_on_small_ei: false,
            engine: Some(self.engine_settings()),
            workers: self.workers,
        };
        compare(
            ev,
            &[Method::Bo(self.engine), Method::Random],
            &self.seeds,
            &template,
            reference,
            self.threads,
        )
    }

    /// Figures 4.18-4.27 and Table 4.1 on `object`: the grid scan and BO versus random
    /// search against its maximum.
    pub fn two_d(&self, object: &str) -> Result<TwoD, ExperimentError> {
        let ev = self.evaluator(object, &TWO_D)?;
        let scan = scan(&ev, &self.steps, self.threads)?;
        let reference = scan
            .argmax()
            .ok_or_else(|| ExperimentError::Settings("empty scan".into()))?
            .score
            .score;
        let cmp = self.bo_and_random(&ev, self.budget, Some(reference))?;
        let bo = summary(&cmp, Method::Bo(self.engine))?;
        let totals: Vec<f64> = bo
            .traces
            .iter()
            .map(|t| t.ei_stop_at.unwrap_or(self.budget) as f64)
            .collect();
        let stopped = bo.traces.iter().filter(|t| t.ei_stop_at.is_some()).count();
        let finals: Vec<f64> = bo
            .traces
            .iter()
            .map(|t| t.best().map_or(f64::NAN, |b| b.1))
            .collect();
        let (median_total, median_best) = (
            median(&totals).unwrap_or(f64::NAN),
            median(&finals).unwrap_or(f64::NAN),
        );
        Ok(TwoD {
            scan,
            reference,
            cmp,
            median_total,
            stopped,
            median_best,
        })
    }

    /// The trial counts at which the 6D part reports the median best: 25, 50 and the budget
    /// (those within the budget, in order, without repeats).
    pub fn checkpoints_6d(&self) -> Vec<usize> {
        [25, 50, self.budget_6d]
            .into_iter()
            .filter(|&n| n <= self.budget_6d)
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect()
    }

    /// The 6D part on `object`: BO versus random search in the pose space.
    pub fn six_d(&self, object: &str) -> Result<SixD, ExperimentError> {
        let ev = self.evaluator(object, &SIX_D)?;
        let cmp = self.bo_and_random(&ev, self.budget_6d, None)?;
        let checkpoints = self.checkpoints_6d();
        let medians_at = |m: &MethodSummary| -> Vec<f64> {
            let curves: Vec<Vec<f64>> = m.traces.iter().map(|t| t.best_so_far()).collect();
            checkpoints
                .iter()
                .map(|&n| {
                    let v: Vec<f64> = curves
                        .iter()
                        .filter_map(|c| c.get(n - 1).copied())
                        .collect();
                    median(&v).unwrap_or(f64::NAN)
                })
                .collect()
        };
        let bo_medians = medians_at(summary(&cmp, Method::Bo(self.engine))?);
        let random_medians = medians_at(summary(&cmp, Method::Random)?);
        Ok(SixD {
            cmp,
            bo_medians,
            random_medians,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request() -> BoRequest {
        BoRequest {
            hand: "barrett".into(),
            seeds: 3,
            first_seed: 7,
            budget: 12,
            budget_6d: 40,
            steps: "5".into(),
            objects: vec!["sphere".into(), " mug".into(), "sphere".into()],
            parts: vec![Part::TwoD, Part::SixD],
            engine: Preset::Grasp,
            model_cap: ModelCapChoice::Preset,
            workers: 1,
            contacts: ContactModel::MeanPoint,
            threads: 1,
        }
    }

    #[test]
    fn the_model_cap_choice_sets_the_engines_cap() {
        let plan = |model_cap| {
            BoStudy::plan(&BoRequest {
                model_cap,
                ..request()
            })
            .unwrap()
            .engine_settings()
        };
        assert_eq!(plan(ModelCapChoice::Preset), Preset::Grasp.settings());
        assert_eq!(plan(ModelCapChoice::Exact).model_cap, None);
        assert_eq!(
            plan(ModelCapChoice::Size(30)).model_cap,
            Some(ModelCap::of(30))
        );
        assert_ne!(
            Preset::Grasp.settings().model_cap,
            Some(ModelCap::of(30)),
            "the test needs a cap other than the preset's"
        );
    }

    #[test]
    fn the_plan_expands_the_steps_and_seeds_and_drops_repeated_objects() {
        let plan = BoStudy::plan(&request()).unwrap();
        assert_eq!(plan.steps, [5, 5]);
        assert_eq!(plan.seeds, [7, 8, 9]);
        assert_eq!(plan.objects, ["sphere", "mug"]);
        assert!(plan.runs(Part::SixD) && !plan.runs(Part::OneD));
        assert_eq!(plan.checkpoints_6d(), [25, 40]);
        let all = BoStudy::plan(&BoRequest {
            objects: Vec::new(),
            budget_6d: 50,
            ..request()
        })
        .unwrap();
        assert_eq!(all.objects.len(), 7);
        assert_eq!(all.checkpoints_6d(), [25, 50]);
    }

    #[test]
    fn a_bad_plan_names_the_flag() {
        let msg = |r: BoRequest| BoStudy::plan(&r).unwrap_err().to_string();
        assert_eq!(
            msg(BoRequest {
                seeds: 0,
                ..request()
            }),
            "--seeds must be between 1 and 1000, got 0"
        );
        assert_eq!(
            msg(BoRequest {
                steps: "5,6,7".into(),
                ..request()
            }),
            "--steps \"5,6,7\": expected one count or two, like 67,33"
        );
        assert_eq!(
            msg(BoRequest {
                first_seed: u64::MAX,
                ..request()
            }),
            "--first-seed + --seeds must stay below 2^64"
        );
        assert_eq!(
            msg(BoRequest {
                workers: 0,
                ..request()
            }),
            "--workers must be between 1 and 256, got 0"
        );
        assert_eq!(
            msg(BoRequest {
                model_cap: ModelCapChoice::Size(7),
                ..request()
            }),
            "--model-cap must be at least 8 observations, got 7"
        );
        let budget = msg(BoRequest {
            budget: 5,
            ..request()
        });
        assert!(budget.starts_with("--budget must be more than"), "{budget}");
        // The 2D budget is not checked when the 2D part does not run.
        assert!(
            BoStudy::plan(&BoRequest {
                budget: 5,
                parts: vec![Part::OneD],
                ..request()
            })
            .is_ok()
        );
        assert!(
            msg(BoRequest {
                objects: vec!["teapot".into()],
                ..request()
            })
            .contains("teapot")
        );
    }

    #[test]
    fn the_two_d_part_compares_bo_and_random_against_the_grid_maximum() {
        let plan = BoStudy::plan(&BoRequest {
            seeds: 2,
            budget: 8,
            ..request()
        })
        .unwrap();
        let two = plan.two_d("sphere").unwrap();
        assert_eq!(two.scan.points.len(), 25);
        let top = two.scan.argmax().unwrap().score.score;
        assert_eq!(two.reference, top);
        assert_eq!(two.cmp.reference, top);
        let bo = summary(&two.cmp, Method::Bo(Preset::Grasp)).unwrap();
        assert_eq!(bo.traces.len(), 2);
        assert!(bo.traces.iter().all(|t| t.scores.len() == 8));
        assert!(summary(&two.cmp, Method::Random).is_ok());
    }
}
