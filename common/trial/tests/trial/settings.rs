//! A trial's settings as a user states them, turned into an evaluator.

use graspopt_sim::{ContactModel, ParamKind};
use graspopt_trial::{Evaluator, Metric, ReferenceFrame, TrialError, TrialSettings};

fn settings() -> TrialSettings {
    TrialSettings {
        object: "sphere".into(),
        mesh: None,
        mesh_scale: 1.0,
        hand: "barrett".into(),
        contacts: ContactModel::MeanPoint,
        metric: Metric::Epsilon,
        frame: ReferenceFrame::World,
        torque_scale: Some(0.05),
    }
}

#[test]
fn the_evaluator_carries_every_setting() {
    let ev =
        Evaluator::from_settings(&settings(), &[ParamKind::Vertical, ParamKind::Approach]).unwrap();
    assert_eq!(ev.object.name(), "sphere");
    assert_eq!(ev.hand.name(), "barrett");
    assert_eq!(ev.score.contacts, ContactModel::MeanPoint);
    assert_eq!(ev.score.metric, Metric::Epsilon);
    assert_eq!(ev.score.frame, ReferenceFrame::World);
    assert_eq!(ev.score.torque_scale, Some(0.05));
    let kinds: Vec<ParamKind> = ev.space.params.iter().map(|p| p.kind).collect();
    assert_eq!(kinds, [ParamKind::Vertical, ParamKind::Approach]);
}

#[test]
fn bad_settings_are_named() {
    let msg = |s: TrialSettings| {
        Evaluator::from_settings(&s, &[ParamKind::Approach])
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        msg(TrialSettings {
            torque_scale: Some(-1.0),
            ..settings()
        }),
        "--torque-scale must be a positive length in metres, got -1"
    );
    let missing = Evaluator::from_settings(
        &TrialSettings {
            mesh: Some("/nonexistent.stl".into()),
            ..settings()
        },
        &[],
    )
    .unwrap_err();
    assert!(matches!(missing, TrialError::Mesh { .. }), "{missing}");
    assert_eq!(missing.to_string(), "cannot load the mesh /nonexistent.stl");
    assert!(
        msg(TrialSettings {
            hand: "teapot".into(),
            ..settings()
        })
        .contains("teapot")
    );
}
