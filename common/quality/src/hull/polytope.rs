//! A simplicial convex polytope in R^D grown one point at a time (beneath-beyond).
//!
//! Each facet is a (D-1)-simplex with an outward unit normal and offset
//! (`normal . x = offset` on the facet), and its D neighbours: `neighbors[i]` is the
//! facet across the ridge opposite `verts[i]`. Adding a point beyond some facets removes
//! the facets it sees and cones the horizon ridges to it. Orientation comes from an
//! interior point fixed at construction (the centroid of the initial simplex), which
//! stays interior as the polytope only grows.
//!
//! Points within `eps` of a facet's hyperplane count as not beyond it, so coplanar input
//! (a cube's 32 vertices per facet, duplicated contacts) yields a consistent
//! triangulation rather than slivers.

use nalgebra::SVector;

/// Index of a facet in [`Polytope::facets`].
pub type FacetId = u32;

/// Largest dimension supported.
const MAX_DIMENSION: usize = 16;
/// A cone facet's plane computed from its neighbours' must pass through its vertices
/// within this fraction of the visibility tolerance.
const RESIDUAL_TOLERANCE: f64 = 0.01;

/// One simplicial facet.
#[derive(Debug, Clone)]
pub struct Facet<const D: usize> {
    pub verts: [u32; D],
    pub neighbors: [FacetId; D],
    pub normal: SVector<f64, D>,
    pub offset: f64,
    pub alive: bool,
}

impl<const D: usize> Facet<D> {
    /// Signed distance of `p` above the facet's hyperplane (positive: beyond).
    #[inline]
    pub fn distance(&self, p: &SVector<f64, D>) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// The polytope over a borrowed point set.
pub struct Polytope<'a, const D: usize> {
    pub points: &'a [SVector<f64, D>],
    pub facets: Vec<Facet<D>>,
    pub interior: SVector<f64, D>,
    /// Visibility tolerance (absolute).
    pub eps: f64,
    stamp: Vec<u32>,
    epoch: u32,
    slot_of: Vec<u32>,
    visible: Vec<FacetId>,
    horizon: Vec<(FacetId, usize)>,
    cone: Vec<[FacetId; D]>,
}

/// Failure to build or grow the polytope (degenerate geometry in floating point).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Degenerate;

impl<'a, const D: usize> Polytope<'a, D> {
    /// The simplex on `simplex` (D+1 affinely independent point indices).
    pub fn simplex(
        points: &'a [SVector<f64, D>],
        simplex: &[usize],
        eps: f64,
    ) -> Result<Self, Degenerate> {
        const { assert!(D >= 2 && D <= MAX_DIMENSION) };
        if simplex.len() != D + 1 {
            return Err(Degenerate);
        }
        let interior = simplex.iter().map(|&i| points[i]).sum::<SVector<f64, D>>() / (D + 1) as f64;
        let mut poly = Self {
            points,
            facets: Vec::with_capacity(64 * D * D),
            interior,
            eps,
            stamp: Vec::new(),
            epoch: 0,
            slot_of: Vec::new(),
            visible: Vec::new(),
            horizon: Vec::new(),
            cone: Vec::new(),
        };
        // Facet f omits simplex[f]; across the ridge opposite vertex simplex[g] lies facet g.
        for f in 0..=D {
            let mut verts = [0u32; D];
            let mut neighbors = [0u32; D];
            let others = simplex.iter().enumerate().filter(|&(g, _)| g != f);
            for (k, (g, &v)) in others.enumerate() {
                verts[k] = v as u32;
                neighbors[k] = g as FacetId;
            }
            let (normal, offset) = poly.hyperplane(&verts).ok_or(Degenerate)?;
            poly.facets.push(Facet {
                verts,
                neighbors,
                normal,
                offset,
                alive: true,
            });
        }
        poly.stamp = vec![0; poly.facets.len()];
        poly.slot_of = vec![0; poly.facets.len()];
        Ok(poly)
    }

    /// The hyperplane through the facet's vertices, oriented away from the interior.
    fn hyperplane(&self, verts: &[u32; D]) -> Option<(SVector<f64, D>, f64)> {
        let v0 = self.points[verts[0] as usize];
        let mut basis: [SVector<f64, D>; D] = [SVector::zeros(); D];
        for k in 1..D {
            let e = self.points[verts[k] as usize] - v0;
            let scale = e.norm();
            let mut q = e;
            for _ in 0..2 {
                for b in &basis[..k - 1] {
                    q -= b * b.dot(&q);
                }
            }
            let n = q.norm();
            if n <= 1e-14 * scale || n == 0.0 {
                return None;
            }
            basis[k - 1] = q / n;
        }
        let mut normal = v0 - self.interior;
        for _ in 0..2 {
            for b in &basis[..D - 1] {
                normal -= b * b.dot(&normal);
            }
        }
        let n = normal.norm();
        if n == 0.0 || !n.is_finite() {
            return None;
        }
        normal /= n;
        // Offset as the mean over the vertices, which spreads the rounding evenly.
        let offset = verts
            .iter()
            .map(|&v| normal.dot(&self.points[v as usize]))
            .sum::<f64>()
            / D as f64;
        Some((normal, offset))
    }

    /// Ids of the live facets.
    pub fn live_facets(&self) -> impl Iterator<Item = FacetId> + '_ {
        (0..self.facets.len() as FacetId).filter(|&f| self.facets[f as usize].alive)
    }

    /// The facets removed by the last [`Polytope::add_point`].
    pub fn last_visible(&self) -> &[FacetId] {
        &self.visible
    }

    /// Adds point `p`, which must lie beyond facet `seed` (by more than `eps`). Returns
    /// the range of the new facets' ids; the removed ones are in [`Self::last_visible`].
    pub fn add_point(
        &mut self,
        p: usize,
        seed: FacetId,
    ) -> Result<std::ops::Range<FacetId>, Degenerate> {
        let point = self.points[p];
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.epoch = 1;
        }
        let epoch = self.epoch;
        // Visible set by breadth-first search from the seed; `slot_of` holds each
        // visible facet's position in the list.
        self.visible.clear();
        self.horizon.clear();
        self.visible.push(seed);
        self.stamp[seed as usize] = epoch;
        self.slot_of[seed as usize] = 0;
        let mut head = 0;
        while head < self.visible.len() {
            let f = self.visible[head] as usize;
            head += 1;
            for slot in 0..D {
                let g = self.facets[f].neighbors[slot] as usize;
                if self.stamp[g] == epoch {
                    continue;
                }
                if self.facets[g].distance(&point) > self.eps {
                    self.stamp[g] = epoch;
                    self.slot_of[g] = self.visible.len() as u32;
                    self.visible.push(g as FacetId);
                }
            }
        }
        // Cone each horizon ridge to the new point; `cone[i][slot]` is the new facet on
        // the ridge opposite `slot` of the i-th visible facet.
        let first = self.facets.len() as FacetId;
        self.cone.clear();
        self.cone.resize(self.visible.len(), [FacetId::MAX; D]);
        for i in 0..self.visible.len() {
            let f = self.visible[i];
            for slot in 0..D {
                let outer = self.facets[f as usize].neighbors[slot];
                if self.stamp[outer as usize] == epoch {
                    continue;
                }
                let id = self.facets.len() as FacetId;
                let mut verts = self.facets[f as usize].verts;
                // The apex already on the horizon: rounding made the polytope non-convex
                // there; a facet with a repeated vertex would break the topology.
                if verts.contains(&(p as u32)) {
                    return Err(Degenerate);
                }
                verts[slot] = p as u32;
                let (normal, offset) = self.cone_hyperplane(f, outer, &point, &verts)?;
                let mut neighbors = [FacetId::MAX; D];
                neighbors[slot] = outer;
                let outer_facet = &mut self.facets[outer as usize];
                let k = outer_facet
                    .neighbors
                    .iter()
                    .position(|&n| n == f)
                    .ok_or(Degenerate)?;
                outer_facet.neighbors[k] = id;
                self.facets.push(Facet {
                    verts,
                    neighbors,
                    normal,
                    offset,
                    alive: true,
                });
                self.stamp.push(0);
                self.slot_of.push(0);
                self.cone[i][slot] = id;
                self.horizon.push((f, slot));
            }
        }
        // Link the new facets with each other. The new facet on horizon ridge (F, s)
        // meets, across its ridge opposite F.verts[t], the new facet found by turning
        // around the (D-3)-face sigma = F.verts minus {F.verts[s], F.verts[t]} through
        // visible facets until the horizon is reached again.
        for h in 0..self.horizon.len() {
            let (f, s) = self.horizon[h];
            let g = self.cone[self.slot_of[f as usize] as usize][s];
            for t in 0..D {
                if t == s || self.facets[g as usize].neighbors[t] != FacetId::MAX {
                    continue;
                }
                let mut cur = f;
                let mut a = self.facets[f as usize].verts[s];
                let mut b = self.facets[f as usize].verts[t];
                let mut steps = 0;
                let (other, other_slot) = loop {
                    steps += 1;
                    if steps > 4 * self.visible.len() + 8 {
                        return Err(Degenerate);
                    }
                    let cf = &self.facets[cur as usize];
                    let slot_b = cf.verts.iter().position(|&v| v == b).ok_or(Degenerate)?;
                    let next = cf.neighbors[slot_b];
                    if self.stamp[next as usize] != epoch || next >= first {
                        // (cur, slot_b) is a horizon ridge: its cone facet holds
                        // sigma + {a, p}, and meets ours across the ridge opposite a.
                        let slot_a = cf.verts.iter().position(|&v| v == a).ok_or(Degenerate)?;
                        let other = self.cone[self.slot_of[cur as usize] as usize][slot_b];
                        break (other, slot_a);
                    }
                    let nf = &self.facets[next as usize];
                    let back = nf
                        .neighbors
                        .iter()
                        .position(|&n| n == cur)
                        .ok_or(Degenerate)?;
                    b = a;
                    a = nf.verts[back];
                    cur = next;
                };
                if other == FacetId::MAX || other == g {
                    return Err(Degenerate);
                }
                self.facets[g as usize].neighbors[t] = other;
                self.facets[other as usize].neighbors[other_slot] = g;
            }
        }
        for &f in &self.visible {
            self.facets[f as usize].alive = false;
        }
        Ok(first..self.facets.len() as FacetId)
    }

    /// The hyperplane of the new facet `verts` on the horizon ridge between the visible
    /// facet `inner` and the hidden facet `outer`. Every hyperplane through that ridge
    /// has its normal in the span of the two facets' normals, so with `d1`, `d2` the
    /// heights of the apex above them, `d1 n2 - d2 n1` is the normal. Checked against the
    /// facet's vertices; when they disagree (nearly parallel normals), recomputed from
    /// the vertices.
    fn cone_hyperplane(
        &self,
        inner: FacetId,
        outer: FacetId,
        apex: &SVector<f64, D>,
        verts: &[u32; D],
    ) -> Result<(SVector<f64, D>, f64), Degenerate> {
        let f1 = &self.facets[inner as usize];
        let f2 = &self.facets[outer as usize];
        let d1 = f1.distance(apex);
        let d2 = f2.distance(apex);
        let mut normal = f2.normal * d1 - f1.normal * d2;
        let norm = normal.norm();
        if norm > 0.0 && norm.is_finite() {
            normal /= norm;
            let offset = normal.dot(apex);
            let tolerance = RESIDUAL_TOLERANCE * self.eps;
            let fits = normal.dot(&self.interior) < offset
                && verts
                    .iter()
                    .all(|&v| (normal.dot(&self.points[v as usize]) - offset).abs() <= tolerance);
            if fits {
                return Ok((normal, offset));
            }
        }
        self.hyperplane(verts).ok_or(Degenerate)
    }

    /// The volume of the polytope: the sum over facets of the simplices they span with
    /// the interior point.
    pub fn volume(&self) -> f64 {
        let mut factorial = 1.0;
        for k in 2..=D {
            factorial *= k as f64;
        }
        let mut total = 0.0;
        for f in self.facets.iter().filter(|f| f.alive) {
            let mut m = [[0.0f64; D]; D];
            for (row, &v) in m.iter_mut().zip(&f.verts) {
                let d = self.points[v as usize] - self.interior;
                row.copy_from_slice(d.as_slice());
            }
            total += determinant(m).abs();
        }
        total / factorial
    }
}

/// Determinant by Gaussian elimination with partial pivoting.
fn determinant<const D: usize>(mut m: [[f64; D]; D]) -> f64 {
    let mut det = 1.0;
    for col in 0..D {
        let mut pivot = col;
        for row in col + 1..D {
            if m[row][col].abs() > m[pivot][col].abs() {
                pivot = row;
            }
        }
        if m[pivot][col] == 0.0 {
            return 0.0;
        }
        if pivot != col {
            m.swap(pivot, col);
            det = -det;
        }
        let p = m[col][col];
        det *= p;
        for row in col + 1..D {
            let factor = m[row][col] / p;
            if factor != 0.0 {
                let pivot_row = m[col];
                for (x, y) in m[row][col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= factor * y;
                }
            }
        }
    }
    det
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn tetrahedron_volume_and_growth() {
        let pts = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(1.0, 1.0, 1.0),
        ];
        let mut poly = Polytope::simplex(&pts, &[0, 1, 2, 3], 1e-12).unwrap();
        assert!((poly.volume() - 1.0 / 6.0).abs() < 1e-15);
        // The point (1,1,1) sees the facet x+y+z=1 only.
        let seed = poly
            .live_facets()
            .find(|&f| poly.facets[f as usize].distance(&pts[4]) > 0.0)
            .unwrap();
        let new = poly.add_point(4, seed).unwrap();
        assert_eq!(new.len(), 3);
        assert_eq!(poly.last_visible().len(), 1);
        // Volume of conv = 1/6 + volume of the tetrahedron (1,0,0),(0,1,0),(0,0,1),(1,1,1).
        assert!((poly.volume() - (1.0 / 6.0 + 1.0 / 3.0)).abs() < 1e-14);
        // Every live facet's neighbours are live and point back.
        for f in poly.live_facets() {
            for &g in &poly.facets[f as usize].neighbors {
                assert!(poly.facets[g as usize].alive);
                assert!(poly.facets[g as usize].neighbors.contains(&f));
            }
        }
    }

    #[test]
    fn determinant_of_known_matrices() {
        assert_eq!(determinant([[2.0, 0.0], [0.0, 3.0]]), 6.0);
        assert_eq!(determinant([[0.0, 1.0], [1.0, 0.0]]), -1.0);
        assert_eq!(determinant([[1.0, 2.0], [2.0, 4.0]]), 0.0);
    }
}
