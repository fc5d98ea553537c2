//! Trials on known geometry: contact positions and normals, non-penetration, contact models,
//! every object at its reference pose, empty trials and bad input.

use graspopt_sim::contact::{ContactPoint, surface_model};
use graspopt_sim::hand::{
    BarrettOracle, CONTACT_TOLERANCE, Hand, LinkGeometry, LinkShape, LinkSpec, ParallelJawOracle,
    advance_until_contact, clear_hand, finish_grasp, hand_by_name,
};
use graspopt_sim::mesh::{self, TriangleMesh};
use graspopt_sim::pose::{TrialSpace, reference_pose};
use graspopt_sim::scene;
use graspopt_sim::{
    ContactModel, ContactModelSettings, NoiseSettings, Object, SimError, TrialOutcome, run_trial,
};
use nalgebra::{Isometry3, Point3, Translation3, Vector3};

const SPHERE_RADIUS: f64 = 0.035;

fn sphere_centre() -> Point3<f64> {
    Point3::new(0.0, 0.0, SPHERE_RADIUS)
}

pub(crate) fn trial(object: &Object, hand: &dyn Hand, pose: &Isometry3<f64>) -> TrialOutcome {
    run_trial(object, hand, pose, &ContactModelSettings::default()).unwrap()
}

/// Angle between two vectors in degrees, accurate for tiny angles.
fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

/// Distance from a point to a link's box (0 inside), for an independent penetration check.
fn point_box_distance(p: &Point3<f64>, link: &Isometry3<f64>, half: &Vector3<f64>) -> f64 {
    let local = link.inverse_transform_point(p);
    let clamped = Point3::new(
        local.x.clamp(-half.x, half.x),
        local.y.clamp(-half.y, half.y),
        local.z.clamp(-half.z, half.z),
    );
    (local - clamped).norm()
}

/// The sphere grasped by the three fingertips, the approach axis through its centre. The pose
/// is 35 mm before the reference pose, where each finger touches with its distal link only
/// (one contact region per finger). At the reference pose itself F1 and F2 touch with both
/// links, two separate regions, whose mean point lies inside the sphere (a question for the
/// contact models, not for this test of exact contacts).
#[test]
fn sphere_grasped_at_its_centre() {
    let sphere = Object::by_name("sphere").unwrap();
    let hand = BarrettOracle::default();
    let pose = TrialSpace::approach_1d(&sphere)
        .palm_pose(&[-0.035])
        .unwrap();
    // The approach axis passes through the sphere's centre.
    let axis_point = pose.inverse_transform_point(&sphere_centre());
    assert!(axis_point.x.abs() < 1e-12 && axis_point.y.abs() < 1e-12);
    let out = trial(&sphere, &hand, &pose);
    assert_eq!(out.fingers_in_contact(), 3, "{:?}", out.grasp.joints);
    assert_eq!(
        out.grasp.link_touching,
        [false, false, true, false, true, false, true],
        "fingertips only"
    );
    let c = sphere_centre();
    for f in &out.fingers {
        assert!(
            f.cloud.len() >= 3,
            "finger {:?}: a cloud, not a point ({})",
            f.finger,
            f.cloud.len()
        );
        for p in &f.cloud.points {
            let r = (p.position - c).norm();
            assert!(
                (r - SPHERE_RADIUS).abs() <= 1e-6 * SPHERE_RADIUS,
                "off the surface by {}",
                r - SPHERE_RADIUS
            );
            assert!((p.normal.norm() - 1.0).abs() < 1e-12);
            assert!(
                angle_deg(&p.normal, &(c - p.position)) < 1e-6,
                "normal not towards the centre"
            );
        }
        let m = f.mean_point().unwrap();
        assert!(angle_deg(&m.normal, &(c - m.position)) < 1.0);
        for s in f.models.get(ContactModel::Surface) {
            assert!(((s.position - c).norm() - SPHERE_RADIUS).abs() <= 1e-6 * SPHERE_RADIUS);
            assert!(
                angle_deg(&s.normal, &(c - s.position)) < 1e-6,
                "surface-model normal not radial"
            );
        }
    }
    // No link penetrates: an independent box-vs-sphere distance for every link.
    for (spec, link) in hand.links().iter().zip(&out.grasp.link_poses) {
        if let LinkShape::Box { half_extents } = spec.shape {
            let gap = point_box_distance(&c, link, &half_extents) - SPHERE_RADIUS;
            assert!(gap >= -1e-9, "{} penetrates by {}", spec.name, -gap);
            assert!(
                gap <= CONTACT_TOLERANCE
                    || !out.grasp.link_touching.iter().any(|t| *t)
                    || gap > 0.0
            );
        }
    }
    for (i, d) in out.grasp.link_distances.iter().enumerate() {
        assert!(*d > 0.0, "link {i} intersects");
        if out.grasp.link_touching[i] {
            assert!(*d <= CONTACT_TOLERANCE);
        }
    }
    // By symmetry F1 and F2 close identically.
    assert!((out.grasp.joints[1] - out.grasp.joints[3]).abs() < 1e-9);
}

/// The BH8's coupled distal angle (OpenRAVE's mimic `medial * 0.33333 + 0.8727`, at most the
/// distal limit of 90 degrees).
fn coupled_distal(medial: f64) -> f64 {
    (medial / 3.0 + 0.8727).min(std::f64::consts::FRAC_PI_2)
}

#[test]
fn barrett_coupling_and_breakaway() {
    let sphere = Object::by_name("sphere").unwrap();
    let hand = BarrettOracle::default();
    let space = TrialSpace::approach_1d(&sphere);
    // Fingertips: the sphere between the open fingertips, the distal link stops the finger
    // (coupled: medial / 3 plus the fixed 0.8727 rad bend). Farther, the open hand's bent
    // fingertips meet the sphere first (see the approach scan test below).
    let far = trial(&sphere, &hand, &space.palm_pose(&[-0.035]).unwrap());
    for f in 0..3 {
        let (m, d) = (far.grasp.joints[1 + 2 * f], far.grasp.joints[2 + 2 * f]);
        assert!(
            m > 0.0 && (d - coupled_distal(m)).abs() < 1e-12,
            "finger {f}: {m} {d}"
        );
        assert!(
            far.grasp.link_touching[2 + 2 * f],
            "distal of finger {f} touches"
        );
    }
    // Near: the medial link is blocked and the distal continues past the coupling ratio.
    let near = trial(&sphere, &hand, &space.palm_pose(&[0.0]).unwrap());
    for f in 0..3 {
        let (m, d) = (near.grasp.joints[1 + 2 * f], near.grasp.joints[2 + 2 * f]);
        assert!(
            near.grasp.link_touching[1 + 2 * f],
            "medial of finger {f} touches"
        );
        assert!(
            d > coupled_distal(m) + 1e-3,
            "finger {f}: distal {d} continued beyond the coupling {}",
            coupled_distal(m)
        );
    }
}

#[test]
fn surface_model_on_a_flat_face_and_on_a_sphere() {
    let settings = ContactModelSettings::default();
    // Cuboid: a small cloud on the +y face (y = 0.025, object frame = world here).
    let cuboid = Object::by_name("cuboid").unwrap();
    let cloud: Vec<ContactPoint> = [(-0.004, 0.05), (0.003, 0.052), (0.0, 0.047), (0.002, 0.049)]
        .iter()
        .map(|&(x, z)| ContactPoint {
            position: Point3::new(x, 0.025, z),
            normal: -Vector3::y(),
            weight: 1.0,
        })
        .collect();
    let surf = surface_model(&cloud, &cuboid, &settings);
    assert_eq!(surf.len(), 21);
    for s in &surf {
        assert!((s.normal + Vector3::y()).norm() < 1e-12, "{:?}", s.normal);
        assert!((s.position.y - 0.025).abs() < 1e-12);
    }
    // Sphere: a cloud around a point of the surface; every surface-model normal is radial.
    let sphere = Object::by_name("sphere").unwrap();
    let c = sphere_centre();
    let dir = Vector3::new(-1.0, 0.3, 0.2).normalize();
    let cloud: Vec<ContactPoint> = [0.0, 0.05, -0.05]
        .iter()
        .map(|&e| {
            let d = (dir + Vector3::new(0.0, e, -e)).normalize();
            ContactPoint {
                position: c + d * SPHERE_RADIUS,
                normal: -d,
                weight: 1.0,
            }
        })
        .collect();
    let surf = surface_model(&cloud, &sphere, &settings);
    assert_eq!(surf.len(), 21);
    for s in &surf {
        assert!(((s.position - c).norm() - SPHERE_RADIUS).abs() < 1e-12);
        assert!(angle_deg(&s.normal, &(c - s.position)) < 1e-6);
    }
    // Circular patch: flat, on the plane through the mean point, all with the mean normal.
    let m = graspopt_sim::contact::mean_point(&cloud).unwrap();
    let patch = graspopt_sim::contact::circular_patch(&cloud, &settings);
    assert_eq!(patch.len(), 21);
    for p in &patch {
        assert_eq!(p.normal, m.normal);
        assert!((p.position - m.position).dot(&m.normal).abs() < 1e-15);
        assert!((p.position - m.position).norm() < settings.radius);
    }
}

#[test]
fn parallel_jaw_on_the_cuboid_faces() {
    let cuboid = Object::by_name("cuboid").unwrap();
    let hand = ParallelJawOracle::default();
    let out = trial(&cuboid, &hand, &reference_pose(&cuboid));
    assert_eq!(out.fingers_in_contact(), 2);
    for (f, expect) in out.fingers.iter().zip([Vector3::y(), -Vector3::y()]) {
        for p in f.models.get(ContactModel::Surface) {
            assert!(
                (p.normal - expect).norm() < 1e-9,
                "{:?} vs {expect:?}",
                p.normal
            );
            assert!((p.position.y.abs() - 0.025).abs() < 1e-9);
        }
        // The region: the face under the jaw and the side faces' strips under it, with the jaw's
        // normal, and where it wraps around the jaw's edges, pieces with the side faces' normals.
        let total: f64 = f.cloud.points.iter().map(|p| p.weight).sum();
        let mut on_face = 0.0;
        for p in &f.cloud.points {
            assert!((p.position.y.abs() - 0.025).abs() <= 1e-3);
            if (p.normal - expect).norm() < 1e-9 {
                on_face += p.weight;
            }
        }
        assert!(on_face >= 0.95 * total, "{on_face} of {total}");
        assert_eq!(f.models.get(ContactModel::Surface).len(), 21);
    }
}

#[test]
fn every_object_is_touched_at_its_reference_pose() {
    let hand = BarrettOracle::default();
    for name in Object::names() {
        let o = Object::by_name(name).unwrap();
        let out = trial(&o, &hand, &reference_pose(&o));
        assert!(
            out.fingers_in_contact() >= 2,
            "{name}: {} fingers",
            out.fingers_in_contact()
        );
        assert!(out.touched());
        // Every raw contact lies on the object's surface; on the round objects its normal is the
        // opposite of the outward surface normal there, and each finger's mean normal points
        // into the object (on the faceted round objects a point's normal may be the link face's,
        // where a facet edge or the rim touches it). A finger touching with two links averages
        // two regions' normals: on the wine glass a finger of the bent BH8 meets it with its
        // medial and distal links, 26 degrees from the normal under its mean point.
        let round = matches!(name, "sphere" | "cylinder");
        let smooth = matches!(name, "sphere" | "cylinder" | "mug" | "wine_glass");
        for f in &out.fingers {
            if smooth && let Some(m) = f.mean_point() {
                let sp = o.closest_point(&m.position).unwrap();
                assert!(
                    m.normal.dot(&sp.outward_normal) < -0.8,
                    "{name}: mean normal {:?} against {:?}",
                    m.normal,
                    sp.outward_normal
                );
            }
            for p in &f.cloud.points {
                let sp = o.closest_point(&p.position).unwrap();
                assert!(
                    sp.signed_distance.abs() < 1e-9,
                    "{name}: contact off the surface by {}",
                    sp.signed_distance
                );
                assert!((p.normal.norm() - 1.0).abs() < 1e-12);
                if round {
                    assert!(
                        (p.normal + sp.outward_normal).norm() < 1e-9,
                        "{name}: normal must point into the object"
                    );
                }
            }
        }
        assert!(
            out.grasp.link_distances.iter().all(|d| *d > 0.0),
            "{name}: a link intersects"
        );
    }
}

#[test]
fn gripper_touches_the_objects_it_can_reach() {
    let hand = hand_by_name("parallel_jaw").unwrap();
    for name in Object::names() {
        let o = Object::by_name(name).unwrap();
        let out = trial(
            &o,
            hand.as_ref(),
            &(reference_pose(&o) * Translation3::new(0.0, 0.0, 0.02)),
        );
        assert!(out.fingers_in_contact() >= 1, "{name}");
    }
}

#[test]
fn a_far_pose_touches_nothing() {
    let cyl = Object::by_name("cylinder").unwrap();
    let far = reference_pose(&cyl) * Translation3::new(0.0, 0.0, -0.5);
    for hand in [
        hand_by_name("barrett").unwrap(),
        hand_by_name("parallel_jaw").unwrap(),
    ] {
        let out = trial(&cyl, hand.as_ref(), &far);
        assert!(!out.touched());
        assert_eq!(out.fingers_in_contact(), 0);
        for f in out.fingers.iter().chain([&out.palm]) {
            assert!(
                f.cloud.is_empty()
                    && ContactModel::ALL
                        .iter()
                        .all(|&m| f.models.get(m).is_empty())
            );
        }
        assert!(out.contacts(ContactModel::Surface, true).is_empty());
        assert_eq!(out.grasp.retreat, 0.0);
        // Every finger joint closed to its limit (the spread is not a closing joint).
        let limits = hand.joint_limits();
        for ((name, j), (_, hi)) in hand
            .joint_names()
            .iter()
            .zip(&out.grasp.joints)
            .zip(&limits)
        {
            // (The spread joints, F2's mimicking F1's, hold their open value.)
            if !name.ends_with("spread") {
                assert!((j - hi).abs() < 1e-12, "joint {name} = {j}, limit {hi}");
            }
        }
    }
}

#[test]
fn a_hand_placed_inside_the_object_retreats() {
    let sphere = Object::by_name("sphere").unwrap();
    let hand = BarrettOracle::default();
    let inside = reference_pose(&sphere) * Translation3::new(0.0, 0.0, 0.05);
    let out = trial(&sphere, &hand, &inside);
    assert!(out.grasp.retreat > 0.03, "retreat {}", out.grasp.retreat);
    assert!(out.palm.touches(), "the palm rests on the sphere");
    assert!(out.grasp.link_distances.iter().all(|d| *d > 0.0));
}

#[test]
fn bad_input_gives_clear_errors() {
    let sphere = Object::by_name("sphere").unwrap();
    let hand = BarrettOracle::default();
    let mut nan = reference_pose(&sphere);
    nan.translation.vector.x = f64::NAN;
    let e = run_trial(&sphere, &hand, &nan, &ContactModelSettings::default()).unwrap_err();
    assert!(matches!(e, SimError::NonFinite { .. }), "{e}");
    assert!(e.to_string().contains("pose"));

    let e = Object::by_name("banana").unwrap_err();
    assert!(
        e.to_string().contains("banana") && e.to_string().contains("cylinder"),
        "{e}"
    );
    assert!(hand_by_name("shadow").is_err());

    let e = Object::from_mesh("empty", TriangleMesh::default()).unwrap_err();
    assert!(matches!(e, SimError::EmptyMesh { .. }), "{e}");
    let mut open = mesh::box_mesh(&Vector3::new(0.02, 0.02, 0.02));
    open.triangles.truncate(10);
    let e = Object::from_mesh("open box", open).unwrap_err();
    assert!(matches!(e, SimError::NotWatertight { .. }), "{e}");
    assert!(e.to_string().contains("open box"));

    let bad = ContactModelSettings {
        radius: -1.0,
        ..Default::default()
    };
    assert!(run_trial(&sphere, &hand, &reference_pose(&sphere), &bad).is_err());
    assert!(BarrettOracle::new(4.0).is_err());
    assert!(hand.link_poses(&[0.0; 3]).is_err());
    assert!(sphere.clone().with_pose(nan).is_err());
}

#[test]
fn a_non_convex_user_mesh_works_through_the_mesh_path() {
    // An L-shaped prism (not convex: collision uses the triangle mesh itself).
    let l = [
        (0.03, -0.03),
        (0.03, 0.0),
        (0.0, 0.0),
        (0.0, 0.03),
        (-0.03, 0.03),
        (-0.03, -0.03),
    ];
    // Star-shaped about the origin? No (the notch); build it as an explicit closed mesh.
    let n = l.len() as u32;
    let mut m = TriangleMesh::default();
    for &(x, y) in &l {
        m.vertices.push(Point3::new(x, y, 0.0));
    }
    for &(x, y) in &l {
        m.vertices.push(Point3::new(x, y, 0.08));
    }
    // Caps (fan from the convex corner 4, whose diagonals stay inside the L), then the sides.
    for i in 0..n {
        let j = (i + 1) % n;
        if i != 4 && j != 4 {
            m.triangles.push([4, j, i]);
            m.triangles.push([n + 4, n + i, n + j]);
        }
        m.triangles.push([i, j, n + j]);
        m.triangles.push([i, n + j, n + i]);
    }
    let o = Object::from_mesh("l_prism", m).unwrap();
    let hand = BarrettOracle::default();
    let out = trial(&o, &hand, &reference_pose(&o));
    assert!(out.fingers_in_contact() >= 2);
    assert!(out.grasp.link_distances.iter().all(|d| *d > 0.0));
}

#[test]
fn noise_is_seeded_and_keeps_normals_unit() {
    let mug = Object::by_name("mug").unwrap();
    let hand = BarrettOracle::default();
    let pose = reference_pose(&mug);
    let noisy = |seed| ContactModelSettings {
        noise: Some(NoiseSettings {
            position_std: 5e-4,
            normal_std: 0.05,
            seed,
        }),
        ..Default::default()
    };
    let a = run_trial(&mug, &hand, &pose, &noisy(1)).unwrap();
    let b = run_trial(&mug, &hand, &pose, &noisy(1)).unwrap();
    let c = run_trial(&mug, &hand, &pose, &noisy(2)).unwrap();
    let clean = trial(&mug, &hand, &pose);
    assert_eq!(a, b);
    assert_ne!(
        a.contacts(ContactModel::Surface, false),
        c.contacts(ContactModel::Surface, false)
    );
    assert_ne!(
        a.contacts(ContactModel::MeanPoint, false),
        clean.contacts(ContactModel::MeanPoint, false)
    );
    assert_eq!(
        a.fingers[0].cloud, clean.fingers[0].cloud,
        "raw clouds stay noise-free"
    );
    for p in a.contacts(ContactModel::Surface, true) {
        assert!((p.normal.norm() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn each_contact_model_keeps_its_noise_stream() {
    // Finger f's model with noise key k draws from stream 3 (f + 1) + k, as before the models
    // were registered: the noisy outputs of earlier versions stay the same.
    let mug = Object::by_name("mug").unwrap();
    let hand = BarrettOracle::default();
    let pose = reference_pose(&mug);
    let noise = NoiseSettings {
        position_std: 5e-4,
        normal_std: 0.05,
        seed: 11,
    };
    let settings = ContactModelSettings {
        noise: Some(noise),
        ..Default::default()
    };
    let noisy = run_trial(&mug, &hand, &pose, &settings).unwrap();
    let clean = trial(&mug, &hand, &pose);
    for (f, (a, b)) in noisy.fingers.iter().zip(&clean.fingers).enumerate() {
        for (model, key) in [
            (ContactModel::MeanPoint, 0),
            (ContactModel::CircularPatch, 1),
            (ContactModel::Surface, 2),
        ] {
            let mut expect = b.contacts(model);
            graspopt_sim::contact::add_noise(&mut expect, &noise, 3 * (f as u64 + 1) + key);
            assert_eq!(a.contacts(model), expect, "finger {f} {model}");
        }
    }
}

#[test]
fn scene_meshes_and_json() {
    let mug = Object::by_name("mug").unwrap();
    let hand = BarrettOracle::default();
    let out = trial(&mug, &hand, &reference_pose(&mug));
    let meshes = scene::scene_meshes(&mug, &hand, &out.grasp).unwrap();
    assert_eq!(meshes.len(), 1 + hand.links().len());
    for m in &meshes[1..] {
        m.mesh.validate_closed(&m.name).unwrap();
    }
    assert!(meshes[0].mesh.triangles.len() > 100);
    let json = serde_json::to_string(&out).unwrap();
    let back: TrialOutcome = serde_json::from_str(&json).unwrap();
    assert_eq!(back.fingers.len(), 3);
    assert_eq!(back.grasp.joints, out.grasp.joints);
}

#[test]
fn knuckle_posts_join_the_barrett_palm_to_each_finger() {
    let mug = Object::by_name("mug").unwrap();
    let hand = BarrettOracle::default();
    let out = trial(&mug, &hand, &reference_pose(&mug));
    let posts = scene::knuckle_posts(&hand, &out.grasp);
    // One post per finger, each a closed cylinder standing on the palm's top face.
    assert_eq!(posts.len(), 3);
    let palm = hand
        .links()
        .iter()
        .position(|l| l.finger.is_none())
        .unwrap();
    let palm_pose = out.grasp.link_poses[palm];
    let top = hand.links()[palm]
        .shape
        .mesh()
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::NEG_INFINITY, f64::max);
    for (k, post) in posts.iter().enumerate() {
        post.validate_closed(&format!("post {k}")).unwrap();
        // In the palm's frame, the post's lowest point is on the palm's top face.
        let lowest = post
            .vertices
            .iter()
            .map(|v| (palm_pose.inverse() * v).z)
            .fold(f64::INFINITY, f64::min);
        assert!((lowest - top).abs() < 1e-9, "post {k}: {lowest} vs {top}");
    }
    // A grasp whose link poses do not match the hand has no palm pose: no posts.
    let mut bare = out.grasp.clone();
    bare.link_poses.clear();
    assert!(scene::knuckle_posts(&hand, &bare).is_empty());
}

#[test]
fn two_dimensional_space_covers_touching_and_empty_trials() {
    let sphere = Object::by_name("sphere").unwrap();
    let hand = BarrettOracle::default();
    let space = TrialSpace::approach_vertical_2d(&sphere);
    let (lo, hi) = (space.params[1].lower, space.params[1].upper);
    let mut touched = 0;
    let mut empty = 0;
    for i in 0..5 {
        let v = lo + (hi - lo) * i as f64 / 4.0;
        for a in [space.params[0].lower, 0.0] {
            let out = trial(&sphere, &hand, &space.palm_pose(&[a, v]).unwrap());
            if out.touched() {
                touched += 1;
            } else {
                empty += 1;
            }
        }
    }
    assert!(
        touched >= 3 && empty >= 1,
        "touched {touched}, empty {empty}"
    );
}

/// A one-finger pusher: a new hand is a new implementation of the trait, built from the helpers.
#[derive(Debug)]
struct Pusher {
    links: Vec<LinkSpec>,
    geometry: LinkGeometry,
}

impl Pusher {
    fn new() -> Self {
        let boxed = |name: &str, finger, h: [f64; 3]| LinkSpec {
            name: name.to_string(),
            finger,
            shape: LinkShape::Box {
                half_extents: Vector3::from(h),
            },
        };
        let links = vec![
            boxed("palm", None, [0.03, 0.03, 0.005]),
            boxed("pad", Some(0), [0.01, 0.005, 0.03]),
        ];
        let geometry = LinkGeometry::new(&links);
        Self { links, geometry }
    }
}

impl Hand for Pusher {
    fn name(&self) -> &str {
        "pusher"
    }
    fn links(&self) -> &[LinkSpec] {
        &self.links
    }
    fn finger_count(&self) -> usize {
        1
    }
    fn joint_names(&self) -> Vec<String> {
        vec!["push".to_string()]
    }
    fn joint_limits(&self) -> Vec<(f64, f64)> {
        vec![(0.0, 0.1)]
    }
    fn open_configuration(&self) -> Vec<f64> {
        vec![0.0]
    }
    fn link_poses(&self, joints: &[f64]) -> Result<Vec<Isometry3<f64>>, SimError> {
        let &[t] = joints else {
            return Err(SimError::InvalidInput("pusher has one joint".to_string()));
        };
        Ok(vec![
            Isometry3::translation(0.0, 0.0, -0.005),
            Isometry3::translation(0.0, -0.06 + t, 0.03),
        ])
    }
    fn close(
        &self,
        object: &Object,
        palm_pose: &Isometry3<f64>,
    ) -> Result<graspopt_sim::Grasp, SimError> {
        let (palm, retreat) = clear_hand(self, &self.geometry, object, palm_pose)?;
        let adv = advance_until_contact(
            |t| {
                Ok(vec![self.geometry.distance(
                    object,
                    1,
                    &(palm * self.link_poses(&[t])?[1]),
                )?])
            },
            0.0,
            0.1,
            &[1.0],
        )?;
        finish_grasp(
            self,
            &self.geometry,
            object,
            palm_pose,
            palm,
            retreat,
            vec![adv.t],
        )
    }
}

#[test]
fn a_new_hand_is_a_new_impl() {
    let cuboid = Object::by_name("cuboid").unwrap();
    let out = trial(&cuboid, &Pusher::new(), &reference_pose(&cuboid));
    assert_eq!(out.fingers_in_contact(), 1);
    // The pad travels from y = -0.055 to the face at y = -0.025, stopping within the tolerance.
    let gap = out.grasp.link_distances[1];
    assert!(gap > 0.0 && gap <= CONTACT_TOLERANCE);
    assert!((out.grasp.joints[0] - (0.06 - 0.005 - 0.025 - gap)).abs() < 1e-9);
    // Nearly all of the region is the face under the pad, with the face's normal.
    let cloud = &out.fingers[0].cloud.points;
    let total: f64 = cloud.iter().map(|p| p.weight).sum();
    let on_face: f64 = cloud
        .iter()
        .filter(|p| (p.normal - Vector3::y()).norm() < 1e-12)
        .map(|p| p.weight)
        .sum();
    assert!(on_face >= 0.95 * total, "{on_face} of {total}");
}

#[test]
fn barrett_with_spread_closes_without_penetrating() {
    for spread in [std::f64::consts::FRAC_PI_2, std::f64::consts::PI] {
        let hand = BarrettOracle::new(spread).unwrap();
        for name in ["cylinder", "sphere", "mug"] {
            let o = Object::by_name(name).unwrap();
            let out = trial(&o, &hand, &reference_pose(&o));
            assert!(out.touched(), "{name} spread {spread}");
            assert!(
                out.grasp.link_distances.iter().all(|d| *d > 0.0),
                "{name} spread {spread}"
            );
            assert!((out.grasp.joints[0] - spread).abs() < 1e-15);
        }
    }
}

#[test]
fn sphere_approach_scan_spans_empty_fingertip_and_wrapping_grasps() {
    // The thesis's 1D scans: along the approach axis the hand goes from touching nothing to
    // fingertip contacts to wrapping the object with the palm against it.
    //
    // The open BH8's distal links are bent 50 degrees inwards: its fingertips come within 5 mm
    // of the approach axis (0.05 - 0.059 sin 50deg), 0.183 m above the palm. From -0.135 to
    // -0.045 the open hand would intersect the sphere and is retreated until F3's fingertip
    // (on the axis's plane; F1/F2 are 25 mm to the side) touches it: one finger. The three
    // fingers close on the sphere from -0.04 on, once it lies inside the open fingertips: 60 mm
    // of the range on this 5 mm grid (more than 100 mm with straight fingers).
    let sphere = Object::by_name("sphere").unwrap();
    let hand = BarrettOracle::default();
    let space = TrialSpace::approach_1d(&sphere);
    let (lo, hi) = (space.params[0].lower, space.params[0].upper);
    let n = 37;
    let mut three = Vec::new();
    let mut stopped_by_f3 = Vec::new();
    for i in 0..n {
        let a = lo + (hi - lo) * i as f64 / (n - 1) as f64;
        let out = trial(&sphere, &hand, &space.palm_pose(&[a]).unwrap());
        if out.grasp.retreat > 0.0 && out.fingers_in_contact() == 1 {
            assert!(out.fingers[2].touches(), "at {a}: F3 is the finger");
            stopped_by_f3.push(a - out.grasp.retreat);
        }
        if i == 0 {
            assert!(
                !out.touched(),
                "the far end of the default range touches nothing"
            );
        }
        if i == n - 1 {
            assert!(
                out.palm.touches(),
                "the near end presses the palm on the sphere"
            );
        }
        if out.fingers_in_contact() == 3 {
            three.push(a);
        }
    }
    let span = three.last().unwrap() - three.first().unwrap();
    assert!(span >= 0.05, "three-finger contacts over {span} m only");
    // Every retreated single-finger trial is the same placement (F3's tip on the sphere).
    assert!(stopped_by_f3.len() >= 15, "{stopped_by_f3:?}");
    for a in &stopped_by_f3 {
        assert!((a - stopped_by_f3[0]).abs() < 1e-6, "{stopped_by_f3:?}");
    }
    assert_eq!(
        three.len() as f64,
        1.0 + (span / ((hi - lo) / (n - 1) as f64)).round(),
        "contiguous"
    );
}
