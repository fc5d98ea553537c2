//! The results folder of a run, from its journal: `trials.csv`, `trials.json`, and the
//! pictures `best.png`, `trials.svg` and `best.svg`.

use std::path::Path;

use crate::error::{ReportError, Result};
use graspopt_journal::{Journal, TrialRow};
use graspopt_pictures::chart;
use graspopt_protocol::named_params;
use graspopt_protocol::text::rounded;
use graspopt_sim::ParamKind;
use graspopt_trial::{Evaluator, Metric};

/// What the results of a run are written from.
pub struct RunFolder<'a> {
    /// The folder written to.
    pub out: &'a Path,
    /// The run's journal (SQLite).
    pub journal: &'a Path,
    /// The run's id.
    pub run: &'a str,
    /// The run's trial parameters, in order.
    pub params: &'a [ParamKind],
    /// The trials as simulated here (to draw the best one).
    pub evaluator: &'a Evaluator,
}

/// Writes `trials.csv`, `trials.json` and the pictures ([`write_pictures`]) of the run on
/// `object` from its journal.
pub fn write_results(folder: &RunFolder, object: &str) -> Result<()> {
    let journal = Journal::open(folder.journal)?;
    let csv = folder.out.join("trials.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&csv)?);
    graspopt_journal::export::write_csv(&journal, folder.run, &mut f)?;
    let json = folder.out.join("trials.json");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&json)?);
    graspopt_journal::export::write_json(&journal, folder.run, &mut f)?;
    write_pictures(folder, object, &journal.export(folder.run)?.trials)
}

/// The pictures of a run, from its trials: `best.png`, the best grasp drawn as `graspopt
/// trial --preview` draws it (simulated again at its parameters, on the object's true pose);
/// `trials.svg`, every trial on the parameter space (the first two parameters); `best.svg`,
/// each trial's score and the best so far, in the order the trials completed. Trials that
/// touched nothing are grey and never set a scale.
pub fn write_pictures(folder: &RunFolder, object: &str, trials: &[TrialRow]) -> Result<()> {
    let mut done: Vec<&TrialRow> = trials.iter().filter(|t| t.score.is_some()).collect();
    done.sort_by_key(|t| (t.completed_ms, t.trial_id));
    // A trial that touched nothing scores below every grasp: `None` on the pictures.
    let hit = |t: &TrialRow| t.score.filter(|_| t.contacts > 0);
    let scores: Vec<Option<f64>> = done.iter().map(|t| hit(t)).collect();
    let plot = chart::progress_plot(&format!("{object}: score by trial, best so far"), &scores);
    std::fs::write(folder.out.join("best.svg"), plot)?;

    let names: Vec<String> = folder
        .params
        .iter()
        .map(|k| match k {
            ParamKind::RotX | ParamKind::RotY | ParamKind::RotZ => format!("{} (rad)", k.name()),
            _ => format!("{} offset (m)", k.name()),
        })
        .collect();
    let labels: Vec<&str> = names.iter().map(String::as_str).collect();
    let shown = if names.len() > 2 {
        format!(" (the first two of {} parameters)", names.len())
    } else {
        String::new()
    };
    let points: Vec<(Vec<f64>, Option<f64>)> =
        done.iter().map(|t| (t.params.clone(), hit(t))).collect();
    let map = chart::trials_map(
        &format!(
            "{object}: {} trials on the parameter space{shown}",
            done.len()
        ),
        &labels,
        &folder.evaluator.space.bounds(),
        &points,
    );
    std::fs::write(folder.out.join("trials.svg"), map)?;

    let Some(best) = best_trial(&done) else {
        return Ok(());
    };
    let grasp =
        folder
            .evaluator
            .evaluate(&best.params)
            .map_err(|source| ReportError::Resimulate {
                trial: best.trial_id,
                source,
            })?;
    let title = best_title(folder.run, best, folder.params);
    crate::trial::preview_image(folder.evaluator, &grasp, &title)?
        .save_png(&folder.out.join("best.png"))
        .map_err(ReportError::picture)
}

/// The best of `done`, as the journal and the run's summary name it: the highest score, the
/// first trial among equal scores.
fn best_trial<'a>(done: &[&'a TrialRow]) -> Option<&'a TrialRow> {
    done.iter().copied().max_by(|a, b| {
        a.score
            .unwrap_or(f64::NAN)
            .total_cmp(&b.score.unwrap_or(f64::NAN))
            .then(b.trial_id.cmp(&a.trial_id))
    })
}

/// The title of `best.png`: `run "R": best trial N at x=..,y=..: score S, force closure`
/// (the score rounded as a person reads it).
fn best_title(run: &str, best: &TrialRow, params: &[ParamKind]) -> String {
    let words = match (&best.metrics, best.score) {
        (Some(m), Some(s)) if m.flag(Metric::ForceClosure.key()) == Some(true) => {
            format!("score {}, force closure", rounded(s))
        }
        (Some(_), Some(s)) => format!("score {}", rounded(s)),
        _ => "no contact".to_string(),
    };
    let short: Vec<String> = params.iter().map(|k| k.name().to_string()).collect();
    format!(
        "run {run:?}: best trial {} at {}: {words}",
        best.trial_id,
        named_params(&short, &best.params, ",")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_journal::{MetricValue, MetricValues, StoredTrialPhase};

    fn trial(trial_id: u64, score: f64) -> TrialRow {
        TrialRow {
            run_id: "run".into(),
            trial_id,
            state: StoredTrialPhase::Completed,
            attempts: 1,
            params: vec![0.01, -0.02],
            worker: "hand-1".into(),
            issued_ms: 0,
            lease_until_ms: 0,
            completed_ms: Some(1),
            result_attempt: Some(1),
            score: Some(score),
            metrics: None,
            contacts: 0,
            fingers_in_contact: 0,
            cloud_points: 0,
            details_json: None,
            error: None,
            forces: None,
        }
    }

    /// A replaying hand answers several trials with one recorded grasp: equal scores. The
    /// picture names the trial the summary and the journal name, the first of them.
    #[test]
    fn the_best_trial_of_equal_scores_is_the_first_as_in_the_journal() {
        let rows = [
            trial(1, 0.1),
            trial(2, 0.18),
            trial(11, 0.18),
            trial(12, 0.18),
        ];
        let done: Vec<&TrialRow> = rows.iter().collect();
        assert_eq!(best_trial(&done).map(|t| t.trial_id), Some(2));
    }

    #[test]
    fn the_best_picture_s_title_names_the_run_and_rounds_the_score() {
        let best = TrialRow {
            metrics: Some(
                MetricValues::default()
                    .with("rank", Some(MetricValue::Count(6)))
                    .with("force_closure", Some(MetricValue::Flag(true)))
                    .with("epsilon", Some(MetricValue::Real(0.1)))
                    .with("volume", None)
                    .with("distance", Some(MetricValue::Real(0.2)))
                    .with("bw", Some(MetricValue::Real(0.20025899065118113))),
            ),
            contacts: 3,
            fingers_in_contact: 3,
            cloud_points: 30,
            ..trial(12, 0.20025899065118113)
        };
        assert_eq!(
            best_title("run", &best, &[ParamKind::Approach, ParamKind::Vertical]),
            "run \"run\": best trial 12 at approach=0.01000,vertical=-0.02000: score 0.20026, force closure"
        );
    }
}
