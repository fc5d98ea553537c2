//! Small dense linear algebra on flat row-major `Vec<f64>`: Cholesky with jitter retry,
//! triangular solves and the inverse from a Cholesky factor. Written for speed at n <= a few
//! hundred (the GP sizes of Bayesian optimisation).

use crate::error::{BoError, Result};

/// Smallest jitter tried when a factorisation fails (grows x10 per retry).
pub const JITTER_START: f64 = 1e-8;
/// Largest jitter tried before giving up.
pub const JITTER_MAX: f64 = 1e-2;

/// Dot product with four independent accumulators (lets the compiler pipeline/vectorise the
/// reduction, about 4x faster than a single serial sum).
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let chunks = n / 4;
    for c in 0..chunks {
        let i = 4 * c;
        acc[0] += a[i] * b[i];
        acc[1] += a[i + 1] * b[i + 1];
        acc[2] += a[i + 2] * b[i + 2];
        acc[3] += a[i + 3] * b[i + 3];
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for i in 4 * chunks..n {
        s += a[i] * b[i];
    }
    s
}

/// In-place Cholesky of the symmetric matrix `a` (n x n, row-major, lower triangle used);
/// on success the lower triangle holds L with A = L L^T and the upper triangle is zeroed.
/// Returns false when A is not (numerically) positive definite.
pub fn cholesky_in_place(a: &mut [f64], n: usize) -> bool {
    for i in 0..n {
        for j in 0..=i {
            let (ri, rj) = (i * n, j * n);
            let s = a[ri + j] - dot(&a[ri..ri + j], &a[rj..rj + j]);
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return false;
                }
                a[ri + i] = s.sqrt();
            } else {
                a[ri + j] = s / a[rj + j];
            }
        }
        for j in i + 1..n {
            a[i * n + j] = 0.0;
        }
    }
    true
}

/// Cholesky of `k` (not modified) with jitter retry: tries `k`, then `k + jitter I` with jitter
/// 1e-8, 1e-7, ... up to 1e-2 (times the mean diagonal). Returns (L, jitter used).
pub fn cholesky_jitter(k: &[f64], n: usize) -> Result<(Vec<f64>, f64)> {
    let mut l = k.to_vec();
    if cholesky_in_place(&mut l, n) {
        return Ok((l, 0.0));
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
        l.copy_from_slice(k);
        for i in 0..n {
            l[i * n + i] += jitter * scale;
        }
        if cholesky_in_place(&mut l, n) {
            return Ok((l, jitter * scale));
        }
        jitter *= 10.0;
    }
    Err(BoError::CholeskyFailed { jitter: JITTER_MAX })
}

/// Solve L x = b in place (L lower triangular, row-major).
pub fn solve_lower_in_place(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let s = b[i] - dot(&l[i * n..i * n + i], &b[..i]);
        b[i] = s / l[i * n + i];
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
    // Linv lower triangular, row-major: solve L Linv = I column by column, stored transposed
    // (row c of `lt` is column c of Linv) for contiguous access.
    let mut lt = vec![0.0; n * n];
    for c in 0..n {
        let col = &mut lt[c * n..(c + 1) * n];
        col[c] = 1.0 / l[c * n + c];
        for i in c + 1..n {
            let s = -dot(&l[i * n + c..i * n + i], &col[c..i]);
            col[i] = s / l[i * n + i];
        }
    }
    // A^{-1}_{ij} = sum_k Linv_{ki} Linv_{kj} = dot(lt row i, lt row j) over k >= max(i, j).
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let a = &lt[i * n..(i + 1) * n];
            let b = &lt[j * n..(j + 1) * n];
            let s = dot(&a[i..n], &b[i..n]);
            inv[i * n + j] = s;
            inv[j * n + i] = s;
        }
    }
    inv
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
}
