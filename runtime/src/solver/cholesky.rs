//! Dense Cholesky factorisation `A = L L^T` of a symmetric positive definite matrix, in place
//! and without pivoting, and the solution of `A X = B` for many right-hand sides at once: the
//! flexible boom's mass matrix and the columns of its Jacobian
//! ([`crate::mechanics::flexible_boom::FlexibleBoom::acceleration_jacobian`]).
//!
//! Matrices are row-major slices (`a[i n + k]` is row `i`, column `k`; for the symmetric `A`
//! the same as column-major); only the lower triangle of `A` is read, and `L` replaces it.
//! `B` is `n × m`, stored by rows, so that the inner loops run over the `m` right-hand sides.

/// Factorises `a` (`n × n`, `n = inv_diag.len()`) in place into `L` on and below the diagonal,
/// and writes `1 / L_jj` to `inv_diag`. Returns `false` if `a` is not (numerically) positive
/// definite.
pub(crate) fn factor(a: &mut [f64], inv_diag: &mut [f64]) -> bool {
    let n = inv_diag.len();
    assert_eq!(a.len(), n * n, "matrix is not n × n");
    for j in 0..n {
        let (row_j, below) = a[j * n..].split_at_mut(n);
        let d = row_j[j] - row_j[..j].iter().map(|l| l * l).sum::<f64>();
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        row_j[j] = d.sqrt();
        inv_diag[j] = 1.0 / row_j[j];
        for row_i in below.chunks_exact_mut(n) {
            let dot = row_i[..j].iter().zip(&row_j[..j]).map(|(a, b)| a * b).sum::<f64>();
            row_i[j] = (row_i[j] - dot) * inv_diag[j];
        }
    }
    true
}

/// Solves `A X = B` in place (`b` becomes `X`, `n × m` by rows, `m = b.len() / n`) with the
/// factors of [`factor`]: `L Y = B` from the first row down, then `L^T X = Y` from the last up,
/// each finished row eliminated from all the rows after it at once (independent updates, which
/// pipeline, rather than a chain of updates of one row).
pub(crate) fn solve_rows(l: &[f64], inv_diag: &[f64], b: &mut [f64]) {
    let n = inv_diag.len();
    assert!(l.len() == n * n && n > 0 && b.len() % n == 0, "dimensions differ");
    let m = b.len() / n;
    for i in 0..n {
        let (head, below) = b.split_at_mut((i + 1) * m);
        let row_i = &mut head[i * m..];
        row_i.iter_mut().for_each(|x| *x *= inv_diag[i]);
        for (k, row_k) in below.chunks_exact_mut(m).enumerate() {
            minus_times(row_k, l[(i + 1 + k) * n + i], row_i);
        }
    }
    for i in (0..n).rev() {
        let (above, rest) = b.split_at_mut(i * m);
        let row_i = &mut rest[..m];
        row_i.iter_mut().for_each(|x| *x *= inv_diag[i]);
        for (row_k, &l_ik) in above.chunks_exact_mut(m).zip(&l[i * n..i * n + i]) {
            minus_times(row_k, l_ik, row_i);
        }
    }
}

/// x -= a y.
fn minus_times(x: &mut [f64], a: f64, y: &[f64]) {
    x.iter_mut().zip(y).for_each(|(x, &y)| *x -= a * y);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A = L L^T for a chosen L: the factor returns L, and the solve returns the X that B was
    /// made from (B = A X), to round-off of the entries (|L| <= 3, |X| <= 2: 1e-13).
    #[test]
    fn factors_and_solves() {
        let n = 4;
        let l: Vec<f64> = (0..n * n).map(|e| if e % n <= e / n { 1.0 + ((e * 7) % 5) as f64 * 0.5 } else { 0.0 }).collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for k in 0..n {
                a[i * n + k] = (0..n).map(|j| l[i * n + j] * l[k * n + j]).sum();
            }
        }
        let m = 3;
        let x: Vec<f64> = (0..n * m).map(|e| ((e * 5) % 7) as f64 / 3.0 - 1.0).collect();
        let mut b: Vec<f64> = (0..n * m).map(|e| (0..n).map(|k| a[(e / m) * n + k] * x[k * m + e % m]).sum()).collect();
        let mut inv = vec![0.0; n];
        assert!(factor(&mut a, &mut inv));
        for i in 0..n {
            for k in 0..=i {
                assert!((a[i * n + k] - l[i * n + k]).abs() < 1e-13, "L[{i}][{k}]");
            }
        }
        solve_rows(&a, &inv, &mut b);
        assert!(b.iter().zip(&x).all(|(b, x)| (b - x).abs() < 1e-13), "{b:?} vs {x:?}");
        let mut indefinite = vec![1.0, 2.0, 2.0, 1.0];
        assert!(!factor(&mut indefinite, &mut [0.0; 2]));
    }
}
