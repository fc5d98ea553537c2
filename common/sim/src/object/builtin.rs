//! The thesis's seven objects, built from primitives and meshes.

use super::*;

/// An object's visual parts, its convex collision pieces and its pose on the table.
type Pieces = (Vec<Part>, Vec<CollisionPart>, Isometry3<f64>);

impl Object {
    /// A built-in object (errors only for [`ObjectKind::UserMesh`], which needs a mesh).
    pub fn builtin(kind: ObjectKind) -> Result<Object> {
        let (parts, collision, pose) = match kind {
            ObjectKind::Sphere => sphere()?,
            ObjectKind::Cylinder => cylinder()?,
            ObjectKind::Cuboid => cuboid(Isometry3::identity())?,
            ObjectKind::RotatedCuboid => cuboid(Isometry3::rotation(
                Vector3::z() * std::f64::consts::FRAC_PI_4,
            ))?,
            ObjectKind::WineGlass => wine_glass()?,
            ObjectKind::Mug => mug()?,
            ObjectKind::StarPrism => star_prism()?,
            ObjectKind::UserMesh => {
                return Err(SimError::InvalidInput(
                    "a user mesh object needs a mesh: use Object::from_mesh or Object::from_file"
                        .to_string(),
                ));
            }
        };
        Object::assemble(kind.name().to_string(), kind, parts, collision, pose)
    }
}

/// A pose `z` above the table.
fn up(z: f64) -> Isometry3<f64> {
    Isometry3::translation(0.0, 0.0, z)
}

/// The sphere: radius 3.5 cm, resting on the table.
fn sphere() -> Result<Pieces> {
    let local = up(0.035);
    let part = Part::new(PartGeom::Ball(Ball::new(0.035)), local);
    Ok((
        vec![part],
        vec![CollisionPart::new(SharedShape::ball(0.035), local)],
        Isometry3::identity(),
    ))
}

/// The upright cylinder: radius 3 cm, 12 cm tall.
fn cylinder() -> Result<Pieces> {
    // parry's cylinder axis is y: rotate it onto z.
    let local = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 0.06),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
    );
    let part = Part::new(PartGeom::Cylinder(Cylinder::new(0.06, 0.03)), local);
    Ok((
        vec![part],
        vec![CollisionPart::new(SharedShape::cylinder(0.06, 0.03), local)],
        Isometry3::identity(),
    ))
}

/// The cuboid, 6 x 5 x 12 cm, at `pose` (the rotated cuboid: turned 45 degrees about z).
fn cuboid(pose: Isometry3<f64>) -> Result<Pieces> {
    let local = up(0.06);
    let part = Part::new(
        PartGeom::Cuboid(Cuboid::new(Vector::new(0.03, 0.025, 0.06))),
        local,
    );
    let coll = CollisionPart::new(SharedShape::cuboid(0.03, 0.025, 0.06), local);
    Ok((vec![part], vec![coll], pose))
}

/// The wine glass: a surface of revolution, its collision pieces the frusta between its rings.
fn wine_glass() -> Result<Pieces> {
    let profile = [
        (0.0, 0.0),
        (0.035, 0.0),
        (0.035, 0.003),
        (0.02, 0.005),
        (0.006, 0.009),
        (0.005, 0.015),
        (0.005, 0.068),
        (0.012, 0.074),
        (0.024, 0.082),
        (0.033, 0.095),
        (0.037, 0.11),
        (0.036, 0.13),
        (0.033, 0.15),
        (0.0, 0.15),
    ];
    let part = mesh_part(mesh::revolve(&profile, ROUND_SEGMENTS), "wine_glass")?;
    // Convex pieces: the frusta between consecutive rings of the profile.
    let mut coll = Vec::new();
    for w in profile.windows(2) {
        let ((r0, z0), (r1, z1)) = (w[0], w[1]);
        if (z1 - z0).abs() > 1e-12 {
            let mut pts = ring(r0, z0, ROUND_SEGMENTS);
            pts.extend(ring(r1, z1, ROUND_SEGMENTS));
            coll.push(CollisionPart::hull(&pts, "wine_glass")?);
        }
    }
    Ok((vec![part], coll, Isometry3::identity()))
}

/// The mug: a revolved body with a tube handle, in convex pieces.
fn mug() -> Result<Pieces> {
    let (ro, ri, h, tb, seg) = (0.035, 0.031, 0.095, 0.006, 32);
    let body = mesh::revolve(
        &[(0.0, 0.0), (ro, 0.0), (ro, h), (ri, h), (ri, tb), (0.0, tb)],
        seg,
    );
    let n = 12;
    let sides = 10;
    let path: Vec<Point3<f64>> = (0..=n)
        .map(|j| {
            let phi = std::f64::consts::PI * j as f64 / n as f64;
            Point3::new(
                ro - 0.002 + 0.025 * phi.sin(),
                0.0,
                h / 2.0 + 0.028 * phi.cos(),
            )
        })
        .collect();
    let handle = mesh::tube(&path, 0.005, sides, &Vector3::y());
    let mut coll = Vec::new();
    // Bottom disc, then one convex block per wall segment.
    let mut pts = ring(ro, 0.0, seg);
    pts.extend(ring(ro, tb, seg));
    coll.push(CollisionPart::hull(&pts, "mug")?);
    let outer_lo = ring(ro, tb, seg);
    let outer_hi = ring(ro, h, seg);
    let inner_lo = ring(ri, tb, seg);
    let inner_hi = ring(ri, h, seg);
    for k in 0..seg {
        let k1 = (k + 1) % seg;
        let pts: Vec<Point3<f64>> = [&outer_lo, &outer_hi, &inner_lo, &inner_hi]
            .iter()
            .flat_map(|r| [r[k], r[k1]])
            .collect();
        coll.push(CollisionPart::hull(&pts, "mug")?);
    }
    // Handle: the hull of each pair of consecutive cross-section rings.
    for j in 0..n {
        let pts = &handle.vertices[j * sides..(j + 2) * sides];
        coll.push(CollisionPart::hull(pts, "mug handle")?);
    }
    Ok((
        vec![
            mesh_part(body, "mug body")?,
            mesh_part(handle, "mug handle")?,
        ],
        coll,
        Isometry3::identity(),
    ))
}

/// The five-pointed star prism, 10 cm tall.
fn star_prism() -> Result<Pieces> {
    let (outer, inner, h) = (0.04, 0.018, 0.10);
    let polygon: Vec<(f64, f64)> = (0..10)
        .map(|i| {
            let a = std::f64::consts::PI + std::f64::consts::PI * i as f64 / 5.0;
            let r = if i % 2 == 0 { outer } else { inner };
            (r * a.cos(), r * a.sin())
        })
        .collect();
    let prism = |idx: &[usize]| -> Vec<Point3<f64>> {
        idx.iter()
            .flat_map(|&i| {
                let (x, y) = polygon[i % 10];
                [Point3::new(x, y, 0.0), Point3::new(x, y, h)]
            })
            .collect()
    };
    // Convex pieces: the inner pentagon and the five triangular points.
    let mut coll = vec![CollisionPart::hull(&prism(&[1, 3, 5, 7, 9]), "star_prism")?];
    for t in (0..10).step_by(2) {
        coll.push(CollisionPart::hull(
            &prism(&[t + 9, t, t + 1]),
            "star_prism",
        )?);
    }
    Ok((
        vec![mesh_part(
            mesh::extrude_star_shaped(&polygon, 0.0, h),
            "star_prism",
        )?],
        coll,
        Isometry3::identity(),
    ))
}
