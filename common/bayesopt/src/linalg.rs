//! Small dense linear algebra on flat row-major `Vec<f64>`: Cholesky with jitter retry,
//! triangular solves and the inverse from a Cholesky factor. Written for speed at n <= a few
//! hundred (the GP sizes of Bayesian optimisation).

use crate::error::{BoError, Result};

/// Smallest jitter tried when a factorisation fails (grows x10 per retry).
pub const JITTER_START: f64 = 1e-8;
/// Largest jitter tried before giving up.
pub const JITTER_MAX: f64 = 1e-2;

/// Dot product with four independent accumulators (lets the compiler pipeline/vectorise the
/// reduction, about 4x faster than a single serial sum): accumulator `k` sums the products of the
/// elements `4 c + k` of the complete blocks of four, then the remainder is added serially to
/// `(acc0 + acc1) + (acc2 + acc3)`. Other routines of this module reproduce this exact order.
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let full = n / 4 * 4;
    let mut s = blocked_partial_sum(&a[..full], &b[..full]);
    for (x, y) in a[full..n].iter().zip(&b[full..n]) {
        s += x * y;
    }
    s
}

/// The blocked part of [`dot`], `(acc0 + acc1) + (acc2 + acc3)`, over the complete blocks of
/// four of `a` and `b` (equal lengths).
#[inline]
fn blocked_partial_sum(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        acc[0] += x[0] * y[0];
        acc[1] += x[1] * y[1];
        acc[2] += x[2] * y[2];
        acc[3] += x[3] * y[3];
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// In-place Cholesky of the symmetric matrix `a` (n x n, row-major, lower triangle used);
/// on success the lower triangle holds L with A = L L^T and the upper triangle is zeroed.
/// Returns false when A is not (numerically) positive definite.
///
/// Column by column (Crout order): `L_ij = (A_ij - <L_i,0..j, L_j,0..j>) / L_jj`. The entries of
/// one column are independent dot products, so the processor overlaps them instead of waiting
/// for each entry of a row before starting the next (the row-by-row order is latency bound);
/// every entry is computed with exactly the same operations as row by row.
pub fn cholesky_in_place(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let rj = j * n;
        let s = a[rj + j] - dot(&a[rj..rj + j], &a[rj..rj + j]);
        if s <= 0.0 || !s.is_finite() {
            return false;
        }
        let djj = s.sqrt();
        a[rj + j] = djj;
        let (head, tail) = a.split_at_mut((j + 1) * n);
        let lj = &head[rj..rj + j];
        for row in tail.chunks_exact_mut(n) {
            let s = row[j] - dot(&row[..j], lj);
            row[j] = s / djj;
        }
    }
    for i in 0..n {
        a[i * n + i + 1..(i + 1) * n].fill(0.0);
    }
    true
}

/// Cholesky of `k` (not modified) with jitter retry: tries `k`, then `k + jitter I` with jitter
/// 1e-8, 1e-7, ... up to 1e-2 (times the mean diagonal). Returns (L, jitter used).
pub fn cholesky_jitter(k: &[f64], n: usize) -> Result<(Vec<f64>, f64)> {
    let mut l = Vec::new();
    let jitter = cholesky_jitter_into(k, n, &mut l)?;
    Ok((l, jitter))
}

/// [`cholesky_jitter`] writing L into `l` (resized to n x n; no allocation when it already
/// has the capacity). Returns the jitter used.
pub fn cholesky_jitter_into(k: &[f64], n: usize, l: &mut Vec<f64>) -> Result<f64> {
    l.clear();
    l.extend_from_slice(&k[..n * n]);
    if cholesky_in_place(l, n) {
        return Ok(0.0);
    }
    let scale = if n == 0 {
        1.0
    } else {
        (0..n).map(|i| k[i * n + i].abs()).sum::<f64>() / n as f64
    };
    let scale = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let mut jitter = JITTER_START;
    while jitter <= JITTER_MAX * 1.0001 {
        l.copy_from_slice(&k[..n * n]);
        for i in 0..n {
            l[i * n + i] += jitter * scale;
        }
        if cholesky_in_place(l, n) {
            return Ok(jitter * scale);
        }
        jitter *= 10.0;
    }
    Err(BoError::CholeskyFailed { jitter: JITTER_MAX })
}

/// Solve L x = b in place (L lower triangular, row-major).
///
/// Forward substitution `x_i = (b_i - <L_i,0..i, x_0..i>) / L_ii` with the dot product of
/// [`dot`]. For the four rows `4 q .. 4 q + 3`, the blocked part of that dot product (the four
/// partial sums over the complete blocks of four, i.e. over `x_0..4q`) only involves unknowns
/// already solved, so the four are computed together (independent chains that the processor
/// overlaps) before the rows' remainders are added one row at a time. Same operations in the
/// same order as row by row, hence bit-identical, but not latency bound.
pub fn solve_lower_in_place(l: &[f64], n: usize, b: &mut [f64]) {
    solve_lower_rows_from(l, n, b, 0);
}

/// Rows `from..n` of [`solve_lower_in_place`], `b[..from]` holding the solution's first
/// entries already (the result is then the same as solving from scratch).
pub fn solve_lower_rows_from(l: &[f64], n: usize, b: &mut [f64], from: usize) {
    for q0 in (from / 4 * 4..n).step_by(4) {
        let rows = q0.max(from)..(q0 + 4).min(n);
        let mut partial = [0.0f64; 4];
        for (p, i) in partial.iter_mut().zip(rows.clone()) {
            *p = blocked_partial_sum(&l[i * n..i * n + q0], &b[..q0]);
        }
        for (p, i) in partial.iter().zip(rows) {
            let mut s = *p;
            for (lk, bk) in l[i * n + q0..i * n + i].iter().zip(&b[q0..i]) {
                s += lk * bk;
            }
            b[i] = (b[i] - s) / l[i * n + i];
        }
    }
}

/// Solve L^T x = b in place (L lower triangular, row-major).
pub fn solve_upper_t_in_place(l: &[f64], n: usize, b: &mut [f64]) {
    for i in (0..n).rev() {
        let xi = b[i] / l[i * n + i];
        b[i] = xi;
        let row = &l[i * n..i * n + i];
        for (bk, lk) in b[..i].iter_mut().zip(row.iter()) {
            *bk -= lk * xi;
        }
    }
}

/// A^{-1} from the Cholesky factor L of A (full symmetric n x n, row-major).
pub fn inverse_from_cholesky(l: &[f64], n: usize) -> Vec<f64> {
    let mut lt = Vec::new();
    let mut inv = Vec::new();
    inverse_lower_from_cholesky_into(l, n, &mut lt, &mut inv);
    for i in 0..n {
        for j in 0..i {
            inv[j * n + i] = inv[i * n + j];
        }
    }
    inv
}

/// The lower triangle (with the diagonal) of A^{-1} from the Cholesky factor L of A, written
/// into `inv` (resized to n x n; the strict upper triangle is not written); `lt` is scratch
/// (n x n). No allocation when both already have the capacity.
pub fn inverse_lower_from_cholesky_into(
    l: &[f64],
    n: usize,
    lt: &mut Vec<f64>,
    inv: &mut Vec<f64>,
) {
    // Linv lower triangular: solve L Linv = I column by column, stored transposed (row c of
    // `lt` is column c of Linv) for contiguous access. Filled row by row of Linv (all columns
    // c < i for row i): these forward substitutions are independent of each other, so they
    // overlap, while each entry is computed exactly as column by column.
    // Only the entries written below are read (row c of `lt` from index c on), so the
    // buffers are resized without clearing.
    lt.resize(n * n, 0.0);
    for i in 0..n {
        let li = &l[i * n..i * n + i];
        let dii = l[i * n + i];
        for c in 0..i {
            let col = &lt[c * n..(c + 1) * n];
            let s = -dot(&li[c..i], &col[c..i]);
            lt[c * n + i] = s / dii;
        }
        lt[i * n + i] = 1.0 / dii;
    }
    // A^{-1}_{ij} = sum_k Linv_{ki} Linv_{kj} = dot(lt row i, lt row j) over k >= max(i, j).
    inv.resize(n * n, 0.0);
    for i in 0..n {
        let a = &lt[i * n + i..(i + 1) * n];
        let out = &mut inv[i * n..i * n + i + 1];
        for (j, o) in out.iter_mut().enumerate() {
            *o = dot(a, &lt[j * n + i..(j + 1) * n]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solve_inverse() {
        let a = vec![4.0, 2.0, 0.4, 2.0, 5.0, 1.0, 0.4, 1.0, 3.0];
        let (l, j) = cholesky_jitter(&a, 3).unwrap();
        assert_eq!(j, 0.0);
        // L L^T == A
        for i in 0..3 {
            for k in 0..3 {
                let s: f64 = (0..3).map(|m| l[i * 3 + m] * l[k * 3 + m]).sum();
                assert!((s - a[i * 3 + k]).abs() < 1e-12);
            }
        }
        let mut b = vec![1.0, 2.0, 3.0];
        solve_lower_in_place(&l, 3, &mut b);
        solve_upper_t_in_place(&l, 3, &mut b);
        for i in 0..3 {
            let s: f64 = (0..3).map(|m| a[i * 3 + m] * b[m]).sum();
            assert!((s - (i as f64 + 1.0)).abs() < 1e-12);
        }
        let inv = inverse_from_cholesky(&l, 3);
        for i in 0..3 {
            for k in 0..3 {
                let s: f64 = (0..3).map(|m| a[i * 3 + m] * inv[m * 3 + k]).sum();
                let e = if i == k { 1.0 } else { 0.0 };
                assert!((s - e).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn jitter_rescues_duplicate_rows_and_fails_on_nan() {
        let a = vec![1.0, 1.0, 1.0, 1.0];
        let (_, j) = cholesky_jitter(&a, 2).unwrap();
        assert!(j > 0.0);
        let bad = vec![f64::NAN, 0.0, 0.0, 1.0];
        assert!(cholesky_jitter(&bad, 2).is_err());
    }

    /// The straightforward loop orders (row-by-row Cholesky, row-by-row forward substitution,
    /// column-by-column inverse) with the same dot product: the reordered routines must agree
    /// with them bit for bit.
    fn reference_cholesky(a: &mut [f64], n: usize) {
        for i in 0..n {
            for j in 0..=i {
                let s = a[i * n + j] - dot(&a[i * n..i * n + j], &a[j * n..j * n + j]);
                a[i * n + j] = if i == j { s.sqrt() } else { s / a[j * n + j] };
            }
            for j in i + 1..n {
                a[i * n + j] = 0.0;
            }
        }
    }

    fn reference_solve_lower(l: &[f64], n: usize, b: &mut [f64]) {
        for i in 0..n {
            let s = b[i] - dot(&l[i * n..i * n + i], &b[..i]);
            b[i] = s / l[i * n + i];
        }
    }

    fn reference_inverse(l: &[f64], n: usize) -> Vec<f64> {
        let mut lt = vec![0.0; n * n];
        for c in 0..n {
            let col = &mut lt[c * n..(c + 1) * n];
            col[c] = 1.0 / l[c * n + c];
            for i in c + 1..n {
                let s = -dot(&l[i * n + c..i * n + i], &col[c..i]);
                col[i] = s / l[i * n + i];
            }
        }
        let mut inv = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let s = dot(&lt[i * n + i..(i + 1) * n], &lt[j * n + i..(j + 1) * n]);
                inv[i * n + j] = s;
                inv[j * n + i] = s;
            }
        }
        inv
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn reordered_routines_are_bit_identical_to_the_plain_loops() {
        let mut rng = crate::rng::Rng::new(11);
        for n in [1, 2, 3, 4, 5, 7, 8, 13, 32, 45] {
            // A random SPD matrix: B B^T + n I.
            let b: Vec<f64> = (0..n * n).map(|_| rng.uniform() - 0.5).collect();
            let mut a = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    a[i * n + j] = dot(&b[i * n..(i + 1) * n], &b[j * n..(j + 1) * n]);
                }
                a[i * n + i] += n as f64;
            }
            let mut l_ref = a.clone();
            reference_cholesky(&mut l_ref, n);
            let (l, jitter) = cholesky_jitter(&a, n).unwrap();
            assert_eq!(jitter, 0.0);
            assert_eq!(bits(&l), bits(&l_ref), "cholesky n={n}");
            assert_eq!(
                bits(&inverse_from_cholesky(&l, n)),
                bits(&reference_inverse(&l, n)),
                "inverse n={n}"
            );
            let rhs: Vec<f64> = (0..n).map(|_| rng.uniform()).collect();
            let mut x_ref = rhs.clone();
            reference_solve_lower(&l, n, &mut x_ref);
            let mut x = rhs.clone();
            solve_lower_in_place(&l, n, &mut x);
            assert_eq!(bits(&x), bits(&x_ref), "solve n={n}");
            for from in 0..=n {
                let mut y = rhs.clone();
                y[..from].copy_from_slice(&x_ref[..from]);
                solve_lower_rows_from(&l, n, &mut y, from);
                assert_eq!(bits(&y), bits(&x_ref), "solve from {from}, n={n}");
            }
        }
    }
}
