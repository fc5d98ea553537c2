//! `TrialSettings` -> `Evaluator`: what the CLI, the runner and a run's record build from.

use graspopt_sim::{ContactModel, ParamKind, TrialSpace};
use graspopt_trial::{Evaluator, Metric, ReferenceFrame, TrialSettings};

#[test]
fn an_evaluator_from_settings_scores_as_the_settings_say() {
    let settings = TrialSettings {
        object: "sphere".into(),
        contacts: ContactModel::MeanPoint,
        metric: Metric::Epsilon,
        frame: ReferenceFrame::World,
        torque_scale: Some(0.05),
        ..TrialSettings::default()
    };
    let ev =
        Evaluator::from_settings(&settings, &[ParamKind::Vertical, ParamKind::Approach]).unwrap();
    assert_eq!(ev.object.name(), "sphere");
    assert_eq!(ev.hand.name(), "barrett");
    assert_eq!(ev.score.contacts, ContactModel::MeanPoint);
    assert_eq!(ev.score.metric, Metric::Epsilon);
    assert_eq!(ev.score.frame, ReferenceFrame::World);
    assert_eq!(ev.score.torque_scale, Some(0.05));
    let full = TrialSpace::full_6d(&ev.object);
    assert_eq!(ev.space.params, vec![full.params[2], full.params[0]]);
    // The same trial as an evaluator set up by hand.
    let mut by_hand = Evaluator::new(
        ev.object.clone(),
        graspopt_sim::hand::hand_by_name("barrett").unwrap(),
        ev.space.clone(),
    );
    by_hand.score = ev.score;
    let p = [0.0, 0.01];
    assert_eq!(
        ev.evaluate(&p).unwrap().score,
        by_hand.evaluate(&p).unwrap().score
    );
}

#[test]
fn bad_settings_are_refused_by_name() {
    let bad_scale = TrialSettings {
        torque_scale: Some(-1.0),
        ..TrialSettings::default()
    };
    let err = Evaluator::from_settings(&bad_scale, &[ParamKind::Approach]).unwrap_err();
    assert!(err.to_string().contains("torque scale"), "{err}");
    let no_mesh = TrialSettings {
        mesh: Some("/nonexistent.stl".into()),
        ..TrialSettings::default()
    };
    let err = Evaluator::from_settings(&no_mesh, &[ParamKind::Approach]).unwrap_err();
    assert!(
        err.to_string()
            .contains("cannot load the mesh /nonexistent.stl"),
        "{err}"
    );
    let no_object = TrialSettings {
        object: "teapot".into(),
        ..TrialSettings::default()
    };
    let err = Evaluator::from_settings(&no_object, &[ParamKind::Approach]).unwrap_err();
    assert!(err.to_string().contains("unknown object `teapot`"), "{err}");
}

#[test]
fn names_of_metrics_frames_and_contact_models_parse_back() {
    for m in [Metric::Bw, Metric::Epsilon, Metric::Volume] {
        assert_eq!(Metric::parse(m.name()).unwrap(), m);
    }
    assert_eq!(Metric::parse("ls").unwrap(), Metric::Epsilon);
    for f in ReferenceFrame::NAMED {
        assert_eq!(ReferenceFrame::parse(f.name()).unwrap(), f);
    }
    assert!(ReferenceFrame::parse("point").is_err());
    for c in ContactModel::ALL {
        assert_eq!(ContactModel::parse(c.name()).unwrap(), c);
    }
    let err = ContactModel::parse("blob").unwrap_err().to_string();
    assert!(err.contains("unknown contact model \"blob\""), "{err}");
}
