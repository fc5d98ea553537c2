//! The contact regions checked against geometry and against each other.

use super::*;

use crate::contact::{DEFAULT_RESOLUTION, mean_point};
use crate::hand::{LinkShape, LinkSpec};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// The region of one box link (half extents `half`) at `pose` against `object`; with
/// `as_mesh`, the same box given as a convex mesh (parry's general path, not the closed form).
fn box_region_of(
    object: &Object,
    half: Vector3<f64>,
    pose: &Isometry3<f64>,
    resolution: f64,
    as_mesh: bool,
) -> Vec<ContactPoint> {
    let shape = if as_mesh {
        LinkShape::Mesh {
            mesh: crate::mesh::box_mesh(&half),
        }
    } else {
        LinkShape::Box { half_extents: half }
    };
    let links = [LinkSpec {
        name: "pad".into(),
        finger: Some(0),
        shape,
    }];
    let settings = CloudSettings {
        resolution,
        ..CloudSettings::default()
    };
    link_cloud(object, &LinkGeometry::new(&links), 0, pose, &settings).unwrap()
}

fn box_region(
    object: &Object,
    half: Vector3<f64>,
    pose: &Isometry3<f64>,
    resolution: f64,
) -> Vec<ContactPoint> {
    box_region_of(object, half, pose, resolution, false)
}

fn total_area(cloud: &[ContactPoint]) -> f64 {
    cloud.iter().map(|p| p.weight).sum()
}

#[test]
fn a_box_pressed_on_a_cube_face_gives_the_offset_rectangle() {
    // The cuboid's top face is z = 0.12 over [-0.03, 0.03] x [-0.025, 0.025]. A pad of
    // 10 x 20 mm rests 0.2 mm above it at (0.005, -0.004): the region is the footprint
    // grown by rho = sqrt(d_c^2 - g^2) with rounded corners, centred under the pad.
    let cube = Object::by_name("cuboid").unwrap();
    let (a, b, hz, g, d_c): (f64, f64, f64, f64, f64) = (0.005, 0.01, 0.002, 2e-4, 1e-3);
    let pose = Isometry3::translation(0.005, -0.004, 0.12 + g + hz);
    let rho = (d_c * d_c - g * g).sqrt();
    let area = 4.0 * a * b + 4.0 * (a + b) * rho + std::f64::consts::PI * rho * rho;
    // A box link in closed form: exact at any resolution. The same box as a convex mesh
    // (the general path): straight sides exact, rounded corners second order.
    for as_mesh in [false, true] {
        let mut errors = Vec::new();
        for resolution in [DEFAULT_RESOLUTION, DEFAULT_RESOLUTION / 2.0] {
            let cloud = box_region_of(&cube, Vector3::new(a, b, hz), &pose, resolution, as_mesh);
            let m = mean_point(&cloud).unwrap();
            let rel = (total_area(&cloud) - area).abs() / area;
            assert!(rel < 1e-4, "area {} vs {area}: {rel:e}", total_area(&cloud));
            errors.push(rel);
            assert!(
                (m.position - Point3::new(0.005, -0.004, 0.12)).norm() < 1e-8,
                "{:?}",
                m.position
            );
            let worst = cloud
                .iter()
                .map(|p| (p.normal + Vector3::z()).norm())
                .fold(0.0, f64::max);
            assert!(worst < 1e-12, "mesh {as_mesh}: normal off by {worst:e}");
        }
        if as_mesh {
            assert!(errors[1] < errors[0] / 3.0, "{errors:?}");
        } else {
            assert!(errors.iter().all(|e| *e < 1e-13), "{errors:?}");
        }
    }
    // A pad wider than the face covers it all, and the side faces' strips within d_c
    // below the top edges: every piece is clipped where the distance is linear, so the
    // area and the centroid are exact to round-off.
    let pose = Isometry3::translation(0.0, 0.0, 0.12 + g + hz);
    let cloud = box_region(&cube, Vector3::new(0.04, 0.04, hz), &pose, 1e-3);
    let (top, strips) = (0.06 * 0.05, 2.0 * (0.06 + 0.05) * (d_c - g));
    let area = top + strips;
    assert!((total_area(&cloud) - area).abs() < 1e-12 * area);
    let z = (top * 0.12 + strips * (0.12 - (d_c - g) / 2.0)) / area;
    let m = mean_point(&cloud).unwrap();
    assert!(
        (m.position - Point3::new(0.0, 0.0, z)).norm() < 1e-14,
        "{m:?}"
    );
    // Object edges against the pad's face: the pad's normal everywhere.
    assert!(
        cloud
            .iter()
            .all(|p| (p.normal + Vector3::z()).norm() < 1e-12)
    );
}

#[test]
fn an_object_edge_against_a_link_face_takes_the_link_face_normal() {
    // A pad tilted 30 degrees about y touches the cuboid's top edge x = 0.03, z = 0.12
    // with the middle of its face, 0.2 mm away. The region: strips along the edge on the
    // top face (length L1 = (d_c - g) / sin 30) and the side face (L2 = (d_c - g) / cos 30)
    // and a right triangle with these legs on each end face; all with the pad's normal.
    let cube = Object::by_name("cuboid").unwrap();
    let (hz, g, d_c): (f64, f64, f64) = (0.002, 2e-4, 1e-3);
    let alpha = 30f64.to_radians();
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), alpha);
    let z_link = rot * Vector3::z();
    let centre = Vector3::new(0.03, 0.0, 0.12) + z_link * (g + hz);
    let pose = Isometry3::from_parts(Translation3::from(centre), rot);
    let cloud = box_region(
        &cube,
        Vector3::new(0.01, 0.04, hz),
        &pose,
        DEFAULT_RESOLUTION,
    );
    let (l1, l2) = ((d_c - g) / alpha.sin(), (d_c - g) / alpha.cos());
    let area = 0.05 * (l1 + l2) + l1 * l2;
    assert!(
        (total_area(&cloud) - area).abs() < 1e-12 * area,
        "{} vs {area}",
        total_area(&cloud)
    );
    for p in &cloud {
        assert!((p.normal + z_link).norm() < 1e-12, "{p:?}");
    }
    // The same edge against the pad's own edge (the pad moved so that its edge is
    // closest): the region beyond the pad's edge takes the object's face normals.
    let pose = Isometry3::from_parts(
        Translation3::from(centre + rot * Vector3::x() * 0.0099),
        rot,
    );
    let cloud = box_region(
        &cube,
        Vector3::new(0.01, 0.04, hz),
        &pose,
        DEFAULT_RESOLUTION,
    );
    assert!(
        cloud
            .iter()
            .any(|p| (p.normal + Vector3::z()).norm() < 1e-12
                || (p.normal + Vector3::x()).norm() < 1e-12)
    );
}

#[test]
fn the_closed_form_box_region_matches_a_fine_subdivision_of_the_same_box_as_a_mesh() {
    // Random pads near the cuboid's top corner (face, edge and corner cells, tilted both
    // ways): the closed form and the general path (the box as a convex mesh, subdivided
    // to 25 micrometres) agree on the area, the centroid and the mean normal.
    use rand::{RngExt, SeedableRng};
    let cube = Object::by_name("cuboid").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let half = Vector3::new(0.004, 0.006, 0.002);
    let mut compared = 0;
    for _ in 0..24 {
        let axis = Vector3::new(rng.random::<f64>(), rng.random(), rng.random()) * 2.0
            - Vector3::repeat(1.0);
        let rot = UnitQuaternion::from_scaled_axis(axis * 0.6);
        let corner = Vector3::new(0.03, 0.025, 0.12);
        let offset = Vector3::new(rng.random::<f64>(), rng.random(), 0.0) * 0.008
            - Vector3::new(0.004, 0.004, 0.0);
        // Lift the pad until its lowest point is 0 to 0.8 mm above the top face.
        let mut pose = Isometry3::from_parts(Translation3::from(corner + offset), rot);
        let lowest = crate::mesh::box_mesh(&half)
            .vertices
            .iter()
            .map(|v| (pose * v).z)
            .fold(f64::INFINITY, f64::min);
        pose.translation.vector.z += 0.12 - lowest + rng.random::<f64>() * 8e-4;
        let exact = box_region_of(&cube, half, &pose, DEFAULT_RESOLUTION, false);
        let fine = box_region_of(&cube, half, &pose, 2.5e-5, true);
        let (ae, af) = (total_area(&exact), total_area(&fine));
        if ae == 0.0 && af == 0.0 {
            continue;
        }
        compared += 1;
        assert!((ae - af).abs() <= 1e-3 * ae, "area {ae:e} vs {af:e}");
        let (me, mf) = (mean_point(&exact).unwrap(), mean_point(&fine).unwrap());
        assert!(
            (me.position - mf.position).norm() < 2e-6,
            "{me:?} vs {mf:?}"
        );
        assert!((me.normal - mf.normal).norm() < 2e-3, "{me:?} vs {mf:?}");
    }
    assert!(compared >= 12, "only {compared} pads touched the cube");
}

#[test]
fn closed_form_distances_to_boxes_balls_and_cylinders_match_parry() {
    use parry3d_f64::shape::{Ball, Cuboid, Cylinder, Shape};
    use rand::{RngExt, SeedableRng};
    let object = Object::by_name("cuboid").unwrap();
    let (part, part_pose, patches) = object.surface_patches().next().unwrap();
    let patch = &patches[0];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let shapes: [Box<dyn Shape>; 3] = [
        Box::new(Cuboid::new(Vector::new(0.004, 0.01, 0.002))),
        Box::new(Ball::new(0.006)),
        Box::new(Cylinder::new(0.003, 0.02)),
    ];
    for shape in &shapes {
        let link = Pose::from_parts(
            Vector::new(0.01, -0.02, 0.03),
            parry3d_f64::math::Rotation::from_scaled_axis(Vector::new(0.3, -1.1, 0.7)),
        );
        let builder = |query| RegionBuilder {
            object: &object,
            part,
            part_pose,
            shape: shape.as_ref(),
            link,
            query,
            d_c: 1e-3,
            h: DEFAULT_RESOLUTION,
        };
        let closed = builder(LinkQuery::new(shape.as_ref(), &link));
        assert!(!matches!(closed.query, LinkQuery::General));
        let parry = builder(LinkQuery::General);
        let (mut near, mut smooth) = (0, 0);
        for _ in 0..4000 {
            let offset =
                Vector::new(rng.random(), rng.random(), rng.random()) * 0.05 - Vector::splat(0.025);
            let q = link.translation + offset;
            let (a, b) = (closed.probe(patch, q), parry.probe(patch, q));
            assert!((a.d - b.d).abs() < 1e-9, "{} vs {} at {q:?}", a.d, b.d);
            if a.d > 1e-6 {
                assert!((a.u - b.u).length() < 1e-6, "{:?} vs {:?}", a.u, b.u);
            }
            if a.d > 1e-6 && a.d <= 1e-3 {
                near += 1;
                smooth += usize::from(a.smooth);
                // Parry's ray cast on a cylinder (a support map) returns the ray's own
                // direction at the rim: there the closest point tells.
                let expected = match shape.as_cylinder() {
                    Some(c) => {
                        let y = link.inverse_transform_point(q - a.u * a.d);
                        let on_rim = (y.x.hypot(y.z) - c.radius).abs() < 1e-9
                            && (y.y.abs() - c.half_height).abs() < 1e-9;
                        !on_rim
                    }
                    None => b.smooth,
                };
                assert_eq!(a.smooth, expected, "{:?} at {q:?}", shape.shape_type());
            }
        }
        assert!(near > 20 && smooth > 0, "{near} near, {smooth} smooth");
    }
}
