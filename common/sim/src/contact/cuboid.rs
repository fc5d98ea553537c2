//! The exact contact region of a box link over a flat convex piece of the object's surface.
//!
//! The six planes of a box's faces (`l_i = +-h_i` in the link frame) cut space into 27 cells:
//! the box itself, six face cells, twelve edge cells and eight corner cells. In a face cell the
//! distance to the box is the height over that face (linear); in an edge cell it is the distance
//! to the edge's line; in a corner cell the distance to the corner. A flat convex polygon is cut
//! by the six planes into convex pieces, one per cell, and each piece is cut by the contact
//! distance `d_c` in closed form:
//!
//! - box cell: the whole piece (the link penetrates the object there);
//! - face cell: a half-plane (the plane at height `d_c` over the face);
//! - corner cell: a disc (the ball of radius `d_c` around the corner meets the plane in one);
//! - edge cell: an ellipse (the cylinder of radius `d_c` around the edge), which becomes a disc
//!   of radius `d_c` once the plane is shrunk along the edge's projection by `sin` of the angle
//!   between the edge and the plane; a strip when the edge is parallel to the plane.
//!
//! A convex polygon meets a disc in a region bounded by segments and arcs: its area and centroid
//! follow from Green's theorem over that boundary. Everything is exact to round-off, with no
//! resolution setting: the built-in hands' links are all boxes, and this replaced an adaptive
//! subdivision of the object's triangles that made the scored mug trial 4 to 5 times slower
//! (docs/benchmarks.md).

use std::f64::consts::{PI, TAU};

use parry3d_f64::math::Vector;

use crate::convert::{g2v, v2g};

/// The cell of a point around a box, per axis: -1 below `-h_i`, 0 between, +1 above `h_i`.
pub(super) type Cell = [i8; 3];

/// One piece of the region: its cell, area and centroid (link frame).
#[derive(Clone, Copy, Debug)]
pub(super) struct Piece {
    pub cell: Cell,
    pub area: f64,
    pub centroid: Vector,
}

/// Below this sine of the angle between an edge and the plane, the edge is parallel to it (the
/// ellipse's long axis then exceeds any object by many orders of magnitude).
const PARALLEL: f64 = 1e-12;

/// The part of the flat triangle `tri` (link frame) within `d_c` of the box of half extents
/// `half` centred on the origin, as pieces (one per cell the triangle crosses).
pub(super) fn region(tri: [Vector; 3], half: Vector, d_c: f64, out: &mut Vec<Piece>) {
    let lo = tri[0].min(tri[1]).min(tri[2]);
    let hi = tri[0].max(tri[1]).max(tri[2]);
    let reach = half + Vector::splat(d_c);
    if hi.cmplt(-reach).any() || lo.cmpgt(reach).any() {
        return;
    }
    let Some(normal) = (tri[1] - tri[0]).cross(tri[2] - tri[0]).try_normalize() else {
        return;
    };
    let mut pieces: Vec<(Vec<Vector>, Cell)> = vec![(tri.to_vec(), [0; 3])];
    for axis in 0..3 {
        let mut next = Vec::with_capacity(pieces.len() * 3);
        let e = Vector::AXES[axis];
        for (poly, cell) in pieces {
            for sign in [-1i8, 0, 1] {
                let part = match sign {
                    -1 => clip(&poly, e, -half[axis]),
                    0 => clip(&poly, e, half[axis]).and_then(|p| clip(&p, -e, half[axis])),
                    _ => clip(&poly, -e, -half[axis]),
                };
                if let Some(part) = part {
                    let mut c = cell;
                    c[axis] = sign;
                    next.push((part, c));
                }
            }
        }
        pieces = next;
    }
    for (poly, cell) in pieces {
        let within = match cell.iter().filter(|s| **s != 0).count() {
            0 => Some(poly),
            1 => {
                let axis = cell.iter().position(|s| *s != 0).unwrap_or(0);
                let e = Vector::AXES[axis] * f64::from(cell[axis]);
                clip(&poly, e, half[axis] + d_c)
            }
            _ => {
                // The edge's line (or the corner) and its direction.
                let corner = Vector::new(
                    f64::from(cell[0]) * half.x,
                    f64::from(cell[1]) * half.y,
                    f64::from(cell[2]) * half.z,
                );
                let edge = cell.iter().position(|s| *s == 0).map(|a| Vector::AXES[a]);
                if let Some((area, centroid)) = near_line(&poly, normal, corner, edge, d_c) {
                    out.push(Piece {
                        cell,
                        area,
                        centroid,
                    });
                }
                None
            }
        };
        if let Some(poly) = within
            && let Some((area, centroid)) = polygon_area(&poly)
        {
            out.push(Piece {
                cell,
                area,
                centroid,
            });
        }
    }
}

/// The part of the convex polygon `poly` where `n . x <= offset` (`None` when empty).
fn clip(poly: &[Vector], n: Vector, offset: f64) -> Option<Vec<Vector>> {
    let f: Vec<f64> = poly.iter().map(|p| n.dot(*p) - offset).collect();
    if f.iter().all(|v| *v <= 0.0) {
        return Some(poly.to_vec());
    }
    clip_where(poly, &f)
}

/// The part of the convex polygon `poly` where the linear interpolation of the values `f` at
/// its corners is at most 0 (`None` when empty).
pub(super) fn clip_where(poly: &[Vector], f: &[f64]) -> Option<Vec<Vector>> {
    if f.iter().all(|v| *v > 0.0) {
        return None;
    }
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let j = (i + 1) % poly.len();
        if f[i] <= 0.0 {
            out.push(poly[i]);
        }
        if (f[i] <= 0.0) != (f[j] <= 0.0) {
            let t = f[i] / (f[i] - f[j]);
            out.push(poly[i] + (poly[j] - poly[i]) * t);
        }
    }
    (out.len() >= 3).then_some(out)
}

/// Area and centroid of a planar convex polygon in 3D (`None` when degenerate).
pub(super) fn polygon_area(poly: &[Vector]) -> Option<(f64, Vector)> {
    let mut area = 0.0;
    let mut moment = Vector::ZERO;
    for k in 1..poly.len() - 1 {
        let a = 0.5 * (poly[k] - poly[0]).cross(poly[k + 1] - poly[0]).length();
        area += a;
        moment += (poly[0] + poly[k] + poly[k + 1]) * (a / 3.0);
    }
    (area > 0.0).then(|| (area, moment / area))
}

/// Two unit vectors spanning the plane orthogonal to the unit vector `n` (the contact models'
/// basis, [`super::plane_basis`]).
fn plane_basis(n: Vector) -> (Vector, Vector) {
    let (e1, e2) = super::plane_basis(&g2v(n));
    (v2g(&e1), v2g(&e2))
}

/// The part of the convex polygon `poly` (on the plane of unit normal `n`) within `r` of the
/// line through `at` along the unit vector `dir`, or of the point `at` when `dir` is `None`:
/// area and centroid.
fn near_line(
    poly: &[Vector],
    n: Vector,
    at: Vector,
    dir: Option<Vector>,
    r: f64,
) -> Option<(f64, Vector)> {
    let p0 = poly[0];
    let height = n.dot(at - p0);
    let Some(t) = dir else {
        // A ball meets the plane in a disc around the point's foot.
        if height.abs() >= r {
            return None;
        }
        let rho = ((r - height.abs()) * (r + height.abs())).sqrt();
        let centre = at - n * height;
        let (e1, e2) = plane_basis(n);
        let flat: Vec<[f64; 2]> = poly
            .iter()
            .map(|p| [(*p - centre).dot(e1), (*p - centre).dot(e2)])
            .collect();
        let (area, m) = disc_polygon(&flat, rho)?;
        return Some((area, centre + e1 * (m[0] / area) + e2 * (m[1] / area)));
    };
    let tn = t.dot(n);
    let s = tn.abs();
    let along = t - n * tn;
    if s <= PARALLEL {
        // The line is parallel to the plane: a strip of half width sqrt(r^2 - height^2).
        if height.abs() >= r {
            return None;
        }
        let w = ((r - height.abs()) * (r + height.abs())).sqrt();
        let e2 = n.cross(along.normalize());
        let c2 = e2.dot(at);
        let strip = clip(poly, e2, c2 + w).and_then(|p| clip(&p, -e2, w - c2))?;
        return polygon_area(&strip);
    }
    let (e1, e2) = match along.try_normalize() {
        Some(e1) if along.length() > PARALLEL => (e1, n.cross(e1)),
        _ => plane_basis(n),
    };
    // The line crosses the plane at `at + lambda t`; along e1 the ellipse's half axis is r / s,
    // so with x1 scaled by s it is a disc of radius r. The crossing in scaled coordinates,
    // without dividing by s: s * lambda = sign(t . n) * n . (p0 - at).
    let s_lambda = tn.signum() * n.dot(p0 - at);
    let centre = [
        s * (at - p0).dot(e1) + s_lambda * t.dot(e1),
        (at - p0).dot(e2),
    ];
    let flat: Vec<[f64; 2]> = poly
        .iter()
        .map(|p| {
            [
                s * (*p - p0).dot(e1) - centre[0],
                (*p - p0).dot(e2) - centre[1],
            ]
        })
        .collect();
    let (area, m) = disc_polygon(&flat, r)?;
    let x1 = (m[0] / area + centre[0]) / s;
    let x2 = m[1] / area + centre[1];
    Some((area / s, p0 + e1 * x1 + e2 * x2))
}

/// The convex polygon `poly` (2D, either orientation) intersected with the disc of radius `r`
/// centred on the origin: its area and first moments (`None` when empty).
fn disc_polygon(poly: &[[f64; 2]], r: f64) -> Option<(f64, [f64; 2])> {
    let signed: f64 = (0..poly.len())
        .map(|i| cross(poly[i], poly[(i + 1) % poly.len()]))
        .sum();
    let ccw: Vec<[f64; 2]> = if signed >= 0.0 {
        poly.to_vec()
    } else {
        poly.iter().rev().copied().collect()
    };
    // The polygon's edges clipped to the disc, in boundary order: (start, end, ends on the
    // circle).
    let mut segments: Vec<([f64; 2], [f64; 2], bool)> = Vec::with_capacity(ccw.len());
    for i in 0..ccw.len() {
        segments.extend(edge_in_disc(ccw[i], ccw[(i + 1) % ccw.len()], r));
    }
    let mut area = 0.0;
    let mut m = [0.0, 0.0];
    if segments.is_empty() {
        // The disc is inside the polygon, or they do not meet.
        let inside =
            (0..ccw.len()).all(|i| cross_at(ccw[i], ccw[(i + 1) % ccw.len()], [0.0, 0.0]) >= 0.0);
        return inside.then_some((PI * r * r, [0.0, 0.0]));
    }
    for k in 0..segments.len() {
        let (p, q, exits) = segments[k];
        area += 0.5 * cross(p, q);
        m[0] += (q[1] - p[1]) * (p[0] * p[0] + p[0] * q[0] + q[0] * q[0]) / 6.0;
        m[1] -= (q[0] - p[0]) * (p[1] * p[1] + p[1] * q[1] + q[1] * q[1]) / 6.0;
        if exits {
            // Along the circle, counter-clockwise, to where the boundary enters again.
            let next = segments[(k + 1) % segments.len()].0;
            let (a1, a2) = (q[1].atan2(q[0]), next[1].atan2(next[0]));
            let gap = ((next[0] - q[0]).powi(2) + (next[1] - q[1]).powi(2)).sqrt();
            let mut sweep = (a2 - a1).rem_euclid(TAU);
            if gap <= 1e-12 * r {
                sweep = 0.0;
            }
            let (b1, b2) = (a1, a1 + sweep);
            area += 0.5 * r * r * sweep;
            let r3 = 0.5 * r * r * r;
            let sx = |a: f64| a.sin() - a.sin().powi(3) / 3.0;
            let sy = |a: f64| -a.cos() + a.cos().powi(3) / 3.0;
            m[0] += r3 * (sx(b2) - sx(b1));
            m[1] += r3 * (sy(b2) - sy(b1));
        }
    }
    (area > 0.0).then_some((area, m))
}

/// The part of the edge `p -> q` inside the disc of radius `r` centred on the origin: its start,
/// its end and whether it ends on the circle (`None` when the edge misses the disc's interior).
fn edge_in_disc(p: [f64; 2], q: [f64; 2], r: f64) -> Option<([f64; 2], [f64; 2], bool)> {
    let d = [q[0] - p[0], q[1] - p[1]];
    let a = d[0] * d[0] + d[1] * d[1];
    if a == 0.0 {
        return None;
    }
    let b = p[0] * d[0] + p[1] * d[1];
    let c = p[0] * p[0] + p[1] * p[1] - r * r;
    let disc = b * b - a * c;
    if disc <= 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    // Roots without cancellation.
    let (t0, t1) = if b >= 0.0 {
        let t0 = (-b - sq) / a;
        (
            t0,
            if t0 != 0.0 {
                c / (a * t0)
            } else {
                (-b + sq) / a
            },
        )
    } else {
        let t1 = (-b + sq) / a;
        (
            if t1 != 0.0 {
                c / (a * t1)
            } else {
                (-b - sq) / a
            },
            t1,
        )
    };
    let (lo, hi) = (t0.max(0.0), t1.min(1.0));
    if lo >= hi {
        return None;
    }
    let at = |t: f64| [p[0] + d[0] * t, p[1] + d[1] * t];
    Some((at(lo), at(hi), t1 < 1.0))
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Whether `x` is left of (or on) the directed line `p -> q`, as a signed double area.
fn cross_at(p: [f64; 2], q: [f64; 2], x: [f64; 2]) -> f64 {
    cross([q[0] - p[0], q[1] - p[1]], [x[0] - p[0], x[1] - p[1]])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1.0)
    }

    #[test]
    fn a_disc_meets_squares_and_quadrants_as_geometry_says() {
        let square = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
        let (a, m) = disc_polygon(&square, 0.5).unwrap();
        assert!(close(a, PI * 0.25, 1e-14) && m[0].abs() < 1e-15 && m[1].abs() < 1e-15);
        let (a, _) = disc_polygon(&square, 10.0).unwrap();
        assert!(close(a, 4.0, 1e-14));
        // Half of the unit disc: centroid 4 / (3 pi) from the centre.
        let half = [[0.0, -2.0], [2.0, -2.0], [2.0, 2.0], [0.0, 2.0]];
        let (a, m) = disc_polygon(&half, 1.0).unwrap();
        assert!(close(a, PI / 2.0, 1e-14), "{a}");
        assert!(close(m[0] / a, 4.0 / (3.0 * PI), 1e-14) && m[1].abs() < 1e-15);
        // A quadrant, given clockwise.
        let quadrant = [[0.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 0.0]];
        let (a, m) = disc_polygon(&quadrant, 1.0).unwrap();
        assert!(close(a, PI / 4.0, 1e-14));
        assert!(
            close(m[0] / a, 4.0 / (3.0 * PI), 1e-14) && close(m[1] / a, 4.0 / (3.0 * PI), 1e-14)
        );
        // A thin sliver cut off the disc by a chord at x = 0.999: the disc minus a segment.
        let cut = [[-2.0, -2.0], [0.999, -2.0], [0.999, 2.0], [-2.0, 2.0]];
        let (a, _) = disc_polygon(&cut, 1.0).unwrap();
        let theta = 2.0 * 0.999f64.acos();
        assert!(close(a, PI - 0.5 * (theta - theta.sin()), 1e-12), "{a}");
        // Apart.
        assert!(disc_polygon(&[[2.0, 2.0], [3.0, 2.0], [2.0, 3.0]], 1.0).is_none());
    }

    #[test]
    fn an_edge_tilted_to_the_plane_reaches_an_ellipse() {
        // The plane z = 0, a line through the origin tilted by alpha from the plane: within r
        // of it lies the ellipse of half axes r / sin(alpha) (along the line's projection) and r.
        let big = [
            Vector::new(-1.0, -1.0, 0.0),
            Vector::new(1.0, -1.0, 0.0),
            Vector::new(1.0, 1.0, 0.0),
            Vector::new(-1.0, 1.0, 0.0),
        ];
        let r = 1e-3;
        for alpha in [1e-9f64, 1e-3, 0.3, 1.2, PI / 2.0] {
            let t = Vector::new(alpha.cos() * 0.6, alpha.cos() * 0.8, alpha.sin());
            let (area, centroid) = near_line(&big, Vector::Z, Vector::ZERO, Some(t), r).unwrap();
            let expected = if alpha < 1e-6 {
                // The ellipse is far longer than the square: a strip of width 2 r along
                // (0.6, 0.8), cut by y = +-1 into a parallelogram of area 2 r * 2 / 0.8.
                5.0 * r
            } else {
                PI * r * r / alpha.sin()
            };
            assert!(
                close(area, expected, 1e-12),
                "alpha {alpha}: {area} vs {expected}"
            );
            assert!(centroid.length() < 1e-12, "alpha {alpha}: {centroid:?}");
        }
        // Parallel to the plane at height 0.6 r: a strip of half width 0.8 r.
        let t = Vector::new(0.6, 0.8, 0.0);
        let (area, _) =
            near_line(&big, Vector::Z, Vector::new(0.0, 0.0, 0.6 * r), Some(t), r).unwrap();
        // Cut by y = +-1 into a parallelogram of area 1.6 r * 2 / 0.8.
        assert!(close(area, 4.0 * r, 1e-12), "{area}");
        // A corner 0.6 r above the plane: a disc of radius 0.8 r.
        let (area, centroid) =
            near_line(&big, Vector::Z, Vector::new(0.1, 0.2, 0.6 * r), None, r).unwrap();
        assert!(close(area, PI * 0.64 * r * r, 1e-12));
        assert!((centroid - Vector::new(0.1, 0.2, 0.0)).length() < 1e-14);
    }
}
