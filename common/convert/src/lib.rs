//! Conversions between the wire messages of `graspopt-protocol` (plain arrays, so that agents
//! in other languages can write them) and the nalgebra / simulator / quality types the
//! algorithm crates use. Agents convert here and nowhere else.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

use graspopt_protocol::{
    CloudPoint, ContactClouds, FingerCloud, FingertipWrench, ForceAnalysis, MeshData, MetricValue,
    MetricValues, ObjectEstimate, Pose, RunId,
};
use graspopt_quality::forces::Resisting;
use graspopt_quality::metrics::{Metrics, Value};
use graspopt_sim::{ContactPoint, Object, SimError, TrialOutcome, TriangleMesh};
use graspopt_trial::fingertips::SensorReading;
use graspopt_trial::forces::GraspForces;
use graspopt_trial::measured::{self, MeasuredTrial};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

/// A wire pose as an isometry (the quaternion is renormalised).
pub fn isometry(pose: &Pose) -> Isometry3<f64> {
    let [w, x, y, z] = pose.rotation;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    let [tx, ty, tz] = pose.translation;
    Isometry3::from_parts(Translation3::new(tx, ty, tz), q)
}

/// An isometry as a wire pose.
pub fn pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose {
        translation: [t.x, t.y, t.z],
        rotation: [q.w, q.i, q.j, q.k],
    }
}

/// The object an estimate describes, placed at the estimated pose.
pub fn object_from_estimate(estimate: &ObjectEstimate) -> Result<Object, SimError> {
    let object = match &estimate.mesh {
        Some(mesh) => {
            let vertices = mesh
                .vertices
                .iter()
                .map(|v| Point3::new(v[0], v[1], v[2]))
                .collect();
            Object::from_mesh(
                &estimate.object,
                TriangleMesh::new(vertices, mesh.triangles.clone()),
            )?
        }
        None => Object::by_name(&estimate.object)?,
    };
    object.with_pose(isometry(&estimate.pose))
}

/// The mesh to send with an object that is not built in (its surface in its own frame).
pub fn mesh_data(object: &Object) -> MeshData {
    let local = object.surface_mesh().transformed(&object.pose().inverse());
    MeshData {
        vertices: local.vertices.iter().map(|p| [p.x, p.y, p.z]).collect(),
        triangles: local.triangles.clone(),
    }
}

fn cloud_point(c: &ContactPoint) -> CloudPoint {
    CloudPoint {
        p: [c.position.x, c.position.y, c.position.z],
        n: [c.normal.x, c.normal.y, c.normal.z],
        w: c.weight,
    }
}

fn contact_point(c: &CloudPoint) -> ContactPoint {
    ContactPoint {
        position: Point3::new(c.p[0], c.p[1], c.p[2]),
        normal: Vector3::new(c.n[0], c.n[1], c.n[2]),
        weight: c.w,
    }
}

/// Identifies one trial attempt on the wire.
#[derive(Debug, Clone)]
pub struct TrialTag {
    pub run_id: RunId,
    pub trial_id: u64,
    pub attempt: u32,
    pub worker: String,
}

/// The clouds message of a simulated trial (raw clouds only; models are the metric's job).
pub fn clouds_from_outcome(tag: &TrialTag, outcome: &TrialOutcome, at_ms: i64) -> ContactClouds {
    let measured = MeasuredTrial::from_outcome(outcome);
    ContactClouds {
        run_id: tag.run_id.clone(),
        trial_id: tag.trial_id,
        attempt: tag.attempt,
        worker: tag.worker.clone(),
        hand: measured.hand.clone(),
        palm_pose: pose(&measured.palm_pose),
        fingers: measured
            .fingers
            .iter()
            .map(|f| FingerCloud {
                finger: f.finger.map(|i| i as u32),
                links: f.links.clone(),
                points: f.points.iter().map(cloud_point).collect(),
            })
            .collect(),
        min_gap: measured.min_gap,
        error: None,
        executed_ms: at_ms,
    }
}

/// What the hand measured, from its message.
pub fn measured_from_clouds(clouds: &ContactClouds) -> MeasuredTrial {
    MeasuredTrial {
        hand: clouds.hand.clone(),
        palm_pose: isometry(&clouds.palm_pose),
        fingers: clouds
            .fingers
            .iter()
            .map(|f| measured::FingerCloud {
                finger: f.finger.map(|i| i as usize),
                links: f.links.clone(),
                points: f.points.iter().map(contact_point).collect(),
            })
            .collect(),
        min_gap: clouds.min_gap,
    }
}

/// A fingertip sensor's reading from its message.
pub fn sensor_reading(w: &FingertipWrench) -> SensorReading {
    SensorReading {
        finger: w.finger as usize,
        link: w.link.clone(),
        sensor_pose: isometry(&w.sensor_pose),
        surface: w.surface,
        reading: graspopt_sensing::FingertipWrench {
            force: Vector3::from(w.force),
            torque: Vector3::from(w.torque),
        },
    }
}

/// A fingertip sensor's reading as a message, read at `stamp_ms` (the inverse of
/// [`sensor_reading`]).
pub fn fingertip_wrench(sensor: &SensorReading, stamp_ms: i64) -> FingertipWrench {
    FingertipWrench {
        finger: sensor.finger as u32,
        link: sensor.link.clone(),
        sensor_pose: pose(&sensor.sensor_pose),
        surface: sensor.surface,
        force: sensor.reading.force.into(),
        torque: sensor.reading.torque.into(),
        stamp_ms,
    }
}

/// A trial's force analysis on the wire.
pub fn force_analysis(g: &GraspForces) -> ForceAnalysis {
    let (resisting_norm, resisting_max, unavailable) = match &g.resisting {
        Resisting::Forces { norm, .. } => (Some(*norm), g.resisting_max(), None),
        Resisting::CannotResist { .. } => (None, None, None),
        Resisting::Unavailable { reason } => (None, None, Some(reason.clone())),
    };
    ForceAnalysis {
        external: g.external.into(),
        resisting_norm,
        resisting_max,
        net_wrench: g.measured.as_ref().map(|m| m.net.into()),
        slip_margins: g
            .measured
            .as_ref()
            .map(|m| m.margins.iter().map(|s| s.friction).collect())
            .unwrap_or_default(),
        unavailable,
    }
}

/// A metric value on the wire.
pub fn metric_value(v: Value) -> MetricValue {
    match v {
        Value::Count(n) => MetricValue::Count(n),
        Value::Flag(b) => MetricValue::Flag(b),
        Value::Real(x) => MetricValue::Real(x),
    }
}

/// Metric values on the wire: every entry of the metric table by its key, in table order.
pub fn metric_values(m: &Metrics) -> MetricValues {
    MetricValues::new(
        m.iter()
            .map(|(def, v)| (def.key.to_string(), v.map(metric_value)))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metric_values_carry_every_metric_of_the_table_by_key() {
        use graspopt_quality::metrics::{MetricsOptions, TABLE, evaluate_wrenches};
        let w: Vec<graspopt_quality::Wrench> = (0..12)
            .map(|k| {
                graspopt_quality::Wrench::from_fn(|i, _| {
                    f64::from(u8::from(i == k / 2)) * [-1.0, 1.0][k % 2]
                })
            })
            .collect();
        let m = evaluate_wrenches(&w, &MetricsOptions::without_volume()).unwrap();
        let wire = metric_values(&m);
        let keys: Vec<&str> = wire.iter().map(|(k, _)| k).collect();
        assert_eq!(keys, TABLE.map(|d| d.key));
        assert_eq!(wire.count("rank"), Some(6));
        assert_eq!(wire.flag("force_closure"), Some(true));
        assert_eq!(wire.real("bw"), Some(m.bw()));
        assert_eq!(wire.get("volume"), None);
    }

    #[test]
    fn poses_round_trip() {
        let iso = Isometry3::from_parts(
            Translation3::new(0.1, -0.2, 0.3),
            UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1),
        );
        let back = isometry(&pose(&iso));
        assert!((back.to_homogeneous() - iso.to_homogeneous()).norm() < 1e-12);
        assert!(pose(&iso).validate("pose").is_ok());
    }

    #[test]
    fn fingertip_readings_round_trip_through_their_message() {
        let sensor = SensorReading {
            finger: 2,
            link: "tip2".into(),
            sensor_pose: Isometry3::from_parts(
                Translation3::new(0.1, 0.0, 0.2),
                UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3),
            ),
            surface: graspopt_sensing::FingertipSurface::Sphere {
                center: [0.0, 0.0, 0.015],
                radius: 0.012,
                base_z: None,
            },
            reading: graspopt_sensing::FingertipWrench {
                force: Vector3::new(0.5, -1.0, -2.0),
                torque: Vector3::new(1e-3, 2e-3, 0.0),
            },
        };
        let w = fingertip_wrench(&sensor, 42);
        assert_eq!(
            (w.finger, w.link.as_str(), w.force, w.torque, w.stamp_ms),
            (2, "tip2", [0.5, -1.0, -2.0], [1e-3, 2e-3, 0.0], 42)
        );
        let back = sensor_reading(&w);
        assert_eq!(
            (back.finger, &back.link, back.surface),
            (2, &sensor.link, sensor.surface)
        );
        assert_eq!(back.reading, sensor.reading);
        let d = back.sensor_pose.to_homogeneous() - sensor.sensor_pose.to_homogeneous();
        assert!(d.norm() < 1e-12);
    }

    #[test]
    fn an_estimate_places_the_named_object() {
        let iso = Isometry3::translation(0.01, 0.0, 0.0);
        let estimate = ObjectEstimate {
            run_id: RunId::new("r").unwrap(),
            object: "cuboid".into(),
            mesh: None,
            pose: pose(&iso),
            seq: 1,
            stamp_ms: 0,
            source: "test".into(),
        };
        let placed = object_from_estimate(&estimate).unwrap();
        let base = Object::by_name("cuboid").unwrap();
        let shift = placed.centre_of_mass() - base.centre_of_mass();
        assert!((shift - Vector3::new(0.01, 0.0, 0.0)).norm() < 1e-12);
        let mut bad = estimate.clone();
        bad.object = "teapot".into();
        assert!(object_from_estimate(&bad).is_err());
    }

    #[test]
    fn least_forces_that_are_unavailable_say_why_on_the_wire() {
        let external = graspopt_quality::Wrench::new(0.0, 0.0, -4.905, 0.0, 0.0, 0.0);
        let why = "the conic solver stopped without an answer";
        let unknown = GraspForces {
            external,
            resisting: Resisting::Unavailable { reason: why.into() },
            measured: None,
        };
        let f = force_analysis(&unknown);
        assert_eq!(f.unavailable.as_deref(), Some(why));
        assert_eq!(
            (f.resisting_norm, f.resisting_max, f.can_resist()),
            (None, None, None)
        );
        assert_eq!(f.external, [0.0, 0.0, -4.905, 0.0, 0.0, 0.0]);
        let forces = graspopt_quality::ContactForces::without_torsion(vec![
            Vector3::new(3.0, 0.0, 4.0),
            Vector3::new(0.0, 1.0, 0.0),
        ]);
        let held = GraspForces {
            resisting: Resisting::Forces {
                forces,
                norm: 26f64.sqrt(),
            },
            ..unknown
        };
        let f = force_analysis(&held);
        assert_eq!(
            (f.resisting_norm, f.resisting_max),
            (Some(26f64.sqrt()), Some(5.0))
        );
        assert_eq!(
            (f.unavailable.as_deref(), f.can_resist()),
            (None, Some(true))
        );
    }

    #[test]
    fn a_mesh_estimate_rebuilds_the_object() {
        let base = Object::by_name("cuboid").unwrap();
        let estimate = ObjectEstimate {
            run_id: RunId::new("r").unwrap(),
            object: "my_box".into(),
            mesh: Some(mesh_data(&base)),
            pose: Pose::IDENTITY,
            seq: 1,
            stamp_ms: 0,
            source: "test".into(),
        };
        let rebuilt = object_from_estimate(&estimate).unwrap();
        assert!((rebuilt.centre_of_mass() - base.centre_of_mass()).norm() < 1e-9);
    }
}
