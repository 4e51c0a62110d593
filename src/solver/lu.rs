//! Dense LU factorisation with partial (row) pivoting, in place and allocation-free.
//!
//! `PA = LU` with unit lower `L` stored below the diagonal and `U` on and above it, as LAPACK's
//! `getrf`; `piv[k]` is the row swapped with row `k` at elimination step `k`. Generic over the
//! scalar so that Radau IIA's real (`f64`) and complex (`Complex<f64>`) systems share one code.
//!
//! Matrices are column-major slices of length `n²` (`a[i + j n]` is row `i`, column `j`, the
//! layout of `DMatrix::as_slice`), with `n = piv.len()`. The loops run over contiguous column
//! slices (right-looking elimination, column-oriented substitution), so the compiler sees
//! neither index arithmetic nor bounds checks in the inner loops.

use nalgebra::ComplexField;

/// Factorises the `n × n` column-major matrix `a` in place, `n = piv.len()`. Returns `false` if
/// a pivot is zero or not finite (singular matrix).
pub(crate) fn factor<T: ComplexField<RealField = f64> + Copy>(a: &mut [T], piv: &mut [usize]) -> bool {
    let n = piv.len();
    assert_eq!(a.len(), n * n, "matrix is not n × n");
    for k in 0..n {
        // Pivot: the largest |re| + |im| in column k on or below the diagonal (first on ties).
        let colk = &a[k * n..(k + 1) * n];
        let mut p = k;
        let mut pmax = colk[k].norm1();
        for (i, v) in colk.iter().enumerate().skip(k + 1) {
            let v = v.norm1();
            if v > pmax {
                pmax = v;
                p = i;
            }
        }
        if pmax == 0.0 || !pmax.is_finite() {
            return false;
        }
        piv[k] = p;
        if p != k {
            for c in a.chunks_exact_mut(n) {
                c.swap(p, k);
            }
        }
        let (left, right) = a.split_at_mut((k + 1) * n);
        let colk = &mut left[k * n..];
        let inv = T::one() / colk[k];
        for l in &mut colk[k + 1..] {
            *l *= inv;
        }
        let colk = &*colk;
        for colj in right.chunks_exact_mut(n) {
            let akj = colj[k];
            if akj != T::zero() {
                for i in k + 1..n {
                    colj[i] -= colk[i] * akj;
                }
            }
        }
    }
    true
}

/// Solves `A x = b` in place (`b` becomes `x`) with the factors from [`factor`].
pub(crate) fn solve<T: ComplexField<RealField = f64> + Copy>(lu: &[T], piv: &[usize], b: &mut [T]) {
    let n = piv.len();
    assert!(lu.len() == n * n && b.len() == n, "dimensions differ");
    for (k, &p) in piv.iter().enumerate() {
        b.swap(k, p);
    }
    for j in 0..n {
        let col = &lu[j * n..(j + 1) * n];
        let bj = b[j];
        if bj != T::zero() {
            for i in j + 1..n {
                b[i] -= col[i] * bj;
            }
        }
    }
    for j in (0..n).rev() {
        let col = &lu[j * n..(j + 1) * n];
        let bj = b[j] / col[j];
        b[j] = bj;
        for i in 0..j {
            b[i] -= col[i] * bj;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Complex, DMatrix};

    /// A permuted, non-symmetric 3x3 system with a known solution: residual at round-off level.
    #[test]
    fn solves_real_and_complex_systems() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 4.0, 1.0, -1.0, 1.0, -3.0, 2.0]);
        let x = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[(i, j)] * x[j]).sum()).collect();
        let (mut lu, mut piv, mut y) = (a.clone(), [0usize; 3], b.clone());
        assert!(factor(lu.as_mut_slice(), &mut piv));
        solve(lu.as_slice(), &piv, &mut y);
        for i in 0..3 {
            assert!((y[i] - x[i]).abs() < 1e-14);
        }
        let ac = a.map(|v| Complex::new(v, 0.5 * v + 1.0));
        let xc = [Complex::new(1.0, 1.0), Complex::new(0.0, -2.0), Complex::new(3.0, 0.0)];
        let bc: Vec<_> = (0..3).map(|i| (0..3).map(|j| ac[(i, j)] * xc[j]).sum()).collect();
        let (mut luc, mut yc) = (ac, bc);
        assert!(factor(luc.as_mut_slice(), &mut piv));
        solve(luc.as_slice(), &piv, &mut yc);
        for i in 0..3 {
            assert!((yc[i] - xc[i]).norm() < 1e-13);
        }
        let mut singular = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(!factor(singular.as_mut_slice(), &mut piv[..2]));
    }
}
