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

use std::hint::select_unpredictable;

use nalgebra::SVector;

use super::ridges::{MAX_FACETS, RidgeTable, vertex_keys};

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
    visible: Vec<FacetId>,
    /// Horizon ridges of the current step: (visible facet, slot of the hidden neighbour).
    horizon: Vec<(FacetId, u32)>,
    ridges: RidgeTable,
    /// The ridge-hashing key words of every point.
    keys: Vec<[u64; 2]>,
}

/// Most facets, live and removed, one polytope may create. A facet takes about 140
/// bytes with its bookkeeping, so this bounds a polytope near 700 MB. Full hulls of
/// large, rounded wrench sets (dense friction cones, surface patches) can need far more
/// (three contacts with 1,024-edge cones: over 24 GB); they are refused with
/// [`PolytopeError::TooManyFacets`] instead of exhausting memory.
pub const FACET_LIMIT: usize = 5_000_000;

/// Failure to build or grow the polytope.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PolytopeError {
    /// Degenerate geometry in floating point.
    Degenerate,
    /// Growing it would create more than [`FACET_LIMIT`] facets.
    TooManyFacets,
}

impl<'a, const D: usize> Polytope<'a, D> {
    /// The simplex on `simplex` (D+1 affinely independent point indices).
    pub fn simplex(
        points: &'a [SVector<f64, D>],
        simplex: &[usize],
        eps: f64,
    ) -> Result<Self, PolytopeError> {
        const { assert!(D >= 2 && D <= MAX_DIMENSION) };
        if simplex.len() != D + 1 {
            return Err(PolytopeError::Degenerate);
        }
        let interior = simplex.iter().map(|&i| points[i]).sum::<SVector<f64, D>>() / (D + 1) as f64;
        let mut poly = Self {
            points,
            facets: Vec::with_capacity(128 * D * D),
            interior,
            eps,
            stamp: Vec::new(),
            epoch: 0,
            visible: Vec::new(),
            horizon: Vec::new(),
            ridges: RidgeTable::default(),
            keys: (0..points.len() as u32).map(vertex_keys).collect(),
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
            let (normal, offset) = poly.hyperplane(&verts).ok_or(PolytopeError::Degenerate)?;
            poly.facets.push(Facet {
                verts,
                neighbors,
                normal,
                offset,
                alive: true,
            });
        }
        poly.stamp = Vec::with_capacity(poly.facets.capacity());
        poly.stamp.resize(poly.facets.len(), 0);
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
    ///
    /// The loops avoid data-dependent branches where they can (appends advance a length
    /// by a 0/1 flag): whether a neighbour is visible, whether a ridge is on the horizon
    /// and whether a ridge's partner has been seen are coin flips that a branch
    /// predictor cannot learn, and mispredictions were a third of the time.
    pub fn add_point(
        &mut self,
        p: usize,
        seed: FacetId,
    ) -> Result<std::ops::Range<FacetId>, PolytopeError> {
        let point = self.points[p];
        let epoch = self.next_epoch();
        self.find_visible(&point, seed, epoch);
        let ridges = self.find_horizon(epoch);
        if self.facets.len() + ridges > FACET_LIMIT {
            return Err(PolytopeError::TooManyFacets);
        }
        let first = self.facets.len() as FacetId;
        self.cone_horizon(p, &point)?;
        self.link_new_facets(first)?;
        for &f in &self.visible {
            self.facets[f as usize].alive = false;
        }
        Ok(first..self.facets.len() as FacetId)
    }

    /// The stamp of a new step (the stamps are cleared when it wraps around).
    fn next_epoch(&mut self) -> u32 {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.epoch = 1;
        }
        self.epoch
    }

    /// The facets `point` sees, into `self.visible`, by breadth-first search from `seed`;
    /// each is stamped with `epoch`. Stamps never exceed the current epoch, so `max`
    /// marks a facet exactly when it is taken.
    fn find_visible(&mut self, point: &SVector<f64, D>, seed: FacetId, epoch: u32) {
        self.visible.clear();
        self.visible.push(seed);
        self.stamp[seed as usize] = epoch;
        let mut len = 1;
        let mut head = 0;
        while head < len {
            let f = self.visible[head] as usize;
            head += 1;
            if self.visible.len() < len + D {
                self.visible.resize(2 * (len + D), 0);
            }
            for g in self.facets[f].neighbors {
                let fresh = self.stamp[g as usize] != epoch;
                let beyond = self.facets[g as usize].distance(point) > self.eps;
                let take = fresh & beyond;
                self.visible[len] = g;
                len += take as usize;
                let stamp = &mut self.stamp[g as usize];
                *stamp = (*stamp).max(epoch * take as u32);
            }
        }
        self.visible.truncate(len);
    }

    /// The horizon, into `self.horizon`: the ridges between a visible facet (stamped with
    /// `epoch`) and a hidden one. Returns their number.
    fn find_horizon(&mut self, epoch: u32) -> usize {
        self.horizon.clear();
        self.horizon.resize(self.visible.len() * D, (0, 0));
        let mut ridges = 0;
        for &f in &self.visible {
            for (slot, &g) in self.facets[f as usize].neighbors.iter().enumerate() {
                self.horizon[ridges] = (f, slot as u32);
                ridges += (self.stamp[g as usize] != epoch) as usize;
            }
        }
        self.horizon.truncate(ridges);
        ridges
    }

    /// Cones each horizon ridge to point `p` (at `point`): one new facet each, linked to
    /// the hidden facet across the ridge (not yet to each other).
    fn cone_horizon(&mut self, p: usize, point: &SVector<f64, D>) -> Result<(), PolytopeError> {
        for i in 0..self.horizon.len() {
            let (f, slot) = self.horizon[i];
            let slot = slot as usize;
            let outer = self.facets[f as usize].neighbors[slot];
            let id = self.facets.len() as FacetId;
            let mut verts = self.facets[f as usize].verts;
            // The apex already on the horizon: rounding made the polytope non-convex
            // there; a facet with a repeated vertex would break the topology.
            if verts.contains(&(p as u32)) {
                return Err(PolytopeError::Degenerate);
            }
            verts[slot] = p as u32;
            let (normal, offset) = self.cone_hyperplane(f, outer, point, &verts)?;
            let mut neighbors = [FacetId::MAX; D];
            neighbors[slot] = outer;
            let outer_facet = &mut self.facets[outer as usize];
            let back = position(&outer_facet.neighbors, f).ok_or(PolytopeError::Degenerate)?;
            outer_facet.neighbors[back] = id;
            self.facets.push(Facet {
                verts,
                neighbors,
                normal,
                offset,
                alive: true,
            });
            self.stamp.push(0);
        }
        Ok(())
    }

    /// Links the new facets `first..` (the cones from the added point over the horizon,
    /// in the order of `self.horizon`) with each other: two of them are neighbours
    /// across a ridge through the apex, matched by the ridge's vertex set in a hash
    /// table. Unmatched offers write `FacetId::MAX` over `FacetId::MAX`, so the loop has
    /// no branch on the outcome.
    fn link_new_facets(&mut self, first: FacetId) -> Result<(), PolytopeError> {
        let end = self.facets.len() as FacetId;
        if end >= MAX_FACETS {
            return Err(PolytopeError::Degenerate);
        }
        self.ridges.begin((end - first) as usize * (D - 1));
        for (g, &(_, apex_slot)) in (first..end).zip(&self.horizon) {
            let verts = self.facets[g as usize].verts;
            let keys = verts.map(|v| self.keys[v as usize]);
            let sum = keys.iter().fold([0u64; 2], |a, k| {
                [a[0].wrapping_add(k[0]), a[1].wrapping_add(k[1])]
            });
            for j in 0..D - 1 {
                // Every slot but the apex's (that ridge is the horizon ridge).
                let t = j + (j >= apex_slot as usize) as usize;
                let ridge = [
                    sum[0].wrapping_sub(keys[t][0]),
                    sum[1].wrapping_sub(keys[t][1]),
                ];
                let (h, u) = self.ridges.offer(ridge, g, t as u32);
                let matched = h != FacetId::MAX;
                self.facets[g as usize].neighbors[t] = h;
                let (target, slot, value) =
                    select_unpredictable(matched, (h, u, g), (g, t as u32, FacetId::MAX));
                self.facets[target as usize].neighbors[slot as usize] = value;
            }
        }
        if self.ridges.complete() {
            Ok(())
        } else {
            Err(PolytopeError::Degenerate)
        }
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
    ) -> Result<(SVector<f64, D>, f64), PolytopeError> {
        let f1 = &self.facets[inner as usize];
        let f2 = &self.facets[outer as usize];
        let d1 = f1.distance(apex);
        let d2 = f2.distance(apex);
        let mut normal = f2.normal * d1 - f1.normal * d2;
        let norm = normal.norm();
        if norm > 0.0 && norm.is_finite() {
            normal *= norm.recip();
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
        self.hyperplane(verts).ok_or(PolytopeError::Degenerate)
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

/// The slot holding `id`, without a data-dependent branch.
#[inline]
fn position<const D: usize>(ids: &[FacetId; D], id: FacetId) -> Option<usize> {
    let slot = (0..D).fold(D, |found, k| if ids[k] == id { k } else { found });
    (slot < D).then_some(slot)
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
    fn growth_keeps_the_topology_consistent() {
        // Random points on and inside a sphere in 5D, added in order: after every step
        // each live facet's neighbours are live, point back, and share all vertices
        // but one with it; every input point ends up inside.
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x2545_f491_4f6c_dd1d);
        let mut uniform = move || rng.random_range(-0.5..0.5);
        let pts: Vec<SVector<f64, 5>> = (0..80)
            .map(|i| {
                let p = SVector::<f64, 5>::from_fn(|_, _| uniform());
                if i % 3 == 0 { p } else { p / p.norm() }
            })
            .collect();
        let basis = super::super::affine::affine_basis(&pts);
        let mut poly = Polytope::simplex(&pts, &basis.indices, 1e-12).unwrap();
        for (i, p) in pts.iter().enumerate() {
            let Some(seed) = poly
                .live_facets()
                .find(|&f| poly.facets[f as usize].distance(p) > 1e-12)
            else {
                continue;
            };
            poly.add_point(i, seed).unwrap();
            for f in poly.live_facets() {
                let facet = &poly.facets[f as usize];
                for (slot, &g) in facet.neighbors.iter().enumerate() {
                    let other = &poly.facets[g as usize];
                    assert!(other.alive && other.neighbors.contains(&f));
                    let shared = facet.verts.iter().filter(|v| other.verts.contains(v));
                    assert_eq!(shared.count(), 4);
                    assert!(!other.verts.contains(&facet.verts[slot]));
                }
            }
        }
        for f in poly.live_facets() {
            for p in &pts {
                assert!(poly.facets[f as usize].distance(p) <= 1e-9);
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
