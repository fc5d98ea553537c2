//! Geometry helpers of the object's parts: the cylinder's projection and ray cast, rings of
//! revolved shapes, and user meshes checked and turned into parts.

use super::*;

/// Closest point on the surface of a cylinder (axis `y`), outward normal there, and whether `p`
/// is inside.
pub(super) fn project_on_cylinder(r: f64, hh: f64, p: Vector) -> (Vector, Vector, bool) {
    let rho = p.x.hypot(p.z);
    let radial = if rho > 1e-300 {
        Vector::new(p.x / rho, 0.0, p.z / rho)
    } else {
        Vector::X
    };
    let sy = if p.y >= 0.0 { 1.0 } else { -1.0 };
    let inside = rho <= r && p.y.abs() <= hh;
    if inside {
        let to_side = r - rho;
        let to_cap = hh - p.y.abs();
        if to_side <= to_cap {
            (Vector::new(radial.x * r, p.y, radial.z * r), radial, true)
        } else {
            (
                Vector::new(p.x, sy * hh, p.z),
                Vector::new(0.0, sy, 0.0),
                true,
            )
        }
    } else {
        let cr = rho.min(r);
        let cy = p.y.clamp(-hh, hh);
        let q = Vector::new(radial.x * cr, cy, radial.z * cr);
        let n = if p.y.abs() - hh > rho - r {
            Vector::new(0.0, sy, 0.0)
        } else {
            radial
        };
        (q, n, false)
    }
}

/// First `t >= 0` where the ray `o + t d` crosses the surface of a cylinder (axis `y`), analytic
/// (parry's generic cylinder ray cast runs GJK).
pub(super) fn ray_cylinder(r: f64, hh: f64, o: Vector, d: Vector) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut consider = |t: f64| {
        if t >= 0.0 && t.is_finite() && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    };
    let a = d.x * d.x + d.z * d.z;
    if a > 1e-300 {
        let b = o.x * d.x + o.z * d.z;
        let c = o.x * o.x + o.z * o.z - r * r;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            for t in [(-b - sq) / a, (-b + sq) / a] {
                if (o.y + t * d.y).abs() <= hh {
                    consider(t);
                }
            }
        }
    }
    if d.y.abs() > 1e-300 {
        for y in [-hh, hh] {
            let t = (y - o.y) / d.y;
            let (x, z) = (o.x + t * d.x, o.z + t * d.z);
            if x * x + z * z <= r * r {
                consider(t);
            }
        }
    }
    best
}

/// Points of a horizontal ring of `segments` points (the same angles as [`mesh::revolve`]).
pub(super) fn ring(r: f64, z: f64, segments: usize) -> Vec<Point3<f64>> {
    (0..segments)
        .map(|s| {
            let a = std::f64::consts::TAU * s as f64 / segments as f64;
            Point3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// Query part and collision pieces of a user mesh: its convex hull when the mesh is convex
/// (hull volume within 0.1 % of the mesh's), else the mesh itself (correct but slower).
pub(super) fn user_parts(mesh: TriangleMesh, name: &str) -> Result<(Part, Vec<CollisionPart>)> {
    let volume = mesh.signed_volume();
    let hull = CollisionPart::hull(&mesh.vertices, name).ok().filter(|h| {
        let hv = h.shape.mass_properties(1.0).mass();
        (hv - volume).abs() <= 1e-3 * volume.abs()
    });
    let part = mesh_part(mesh, name)?;
    let coll = match hull {
        Some(h) => h,
        None => match &part.geom {
            PartGeom::Mesh(m) => {
                CollisionPart::new(SharedShape::new(m.shape.clone()), Isometry3::identity())
            }
            _ => {
                return Err(SimError::InvalidInput(format!(
                    "mesh `{name}` has no triangle mesh part"
                )));
            }
        },
    };
    Ok((part, vec![coll]))
}

/// The bounding radius (half the bounding box's diagonal, metres) a user mesh may have: from
/// a 1 cm marble to a 1 m box, what the hands here can close on.
pub const PLAUSIBLE_RADIUS: (f64, f64) = (0.005, 0.5);

/// Refuses a user mesh whose size is implausible for a hand, naming a unit scale that fits.
pub(super) fn check_plausible_size(mesh: &TriangleMesh, name: &str, scale: f64) -> Result<()> {
    let Some((lo, hi)) = mesh.bounds() else {
        return Ok(());
    };
    let radius = (hi - lo).norm() / 2.0;
    let (min, max) = PLAUSIBLE_RADIUS;
    if (min..=max).contains(&radius) {
        return Ok(());
    }
    // The factor from a unit to metres is the scale the file needs if it is in that unit:
    // the one whose scaling of the file's own size (`radius / scale`) is plausible.
    let units = [
        (0.001, "millimetres"),
        (0.01, "centimetres"),
        (0.0254, "inches"),
        (1.0, "metres"),
        (1000.0, "kilometres"),
    ];
    let in_file = radius / scale;
    let advice = units
        .iter()
        .find(|(f, _)| *f != scale && (min..=max).contains(&(in_file * f)))
        .map(|(f, unit)| format!("if the file is in {unit}, scale it by {f} (--mesh-scale {f})"))
        .unwrap_or_else(|| {
            "give the factor from the file's units to metres (--mesh-scale S)".to_string()
        });
    let scaled = if scale == 1.0 {
        String::new()
    } else {
        format!(" after scaling by {scale}")
    };
    Err(SimError::ImplausibleSize {
        name: name.to_string(),
        radius,
        scaled,
        min,
        max,
        advice,
    })
}

/// A mesh part (identity frame) from a closed, outward mesh.
pub(super) fn mesh_part(mesh: TriangleMesh, name: &str) -> Result<Part> {
    mesh.validate_closed(name)?;
    let vertices: Vec<Vector> = mesh.vertices.iter().map(p2g).collect();
    let normals = (0..mesh.triangles.len())
        .map(|i| v2g(&mesh.triangle_normal(i)))
        .collect();
    let shape = TriMesh::with_flags(vertices, mesh.triangles.clone(), TriMeshFlags::ORIENTED)
        .map_err(|e| SimError::NotWatertight {
            name: name.to_string(),
            reason: e.to_string(),
        })?;
    Ok(Part::new(
        PartGeom::Mesh(Box::new(MeshGeom {
            shape,
            mesh,
            normals,
        })),
        Isometry3::identity(),
    ))
}
