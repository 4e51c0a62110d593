//! Dense LU factorisation with partial (row) pivoting, in place and allocation-free.
//!
//! `PA = LU` with unit lower `L` stored below the diagonal and `U` on and above it, as LAPACK's
//! `getrf`; `piv[k]` is the row swapped with row `k` at elimination step `k`. Generic over the
//! scalar so that Radau IIA's real (`f64`) and complex (`Complex<f64>`) systems share one code.

use nalgebra::{ComplexField, DMatrix};

/// Factorises `a` in place. Returns `false` if a pivot is zero or not finite (singular matrix).
pub(crate) fn factor<T: ComplexField<RealField = f64> + Copy>(a: &mut DMatrix<T>, piv: &mut [usize]) -> bool {
    let n = a.nrows();
    for k in 0..n {
        let mut p = k;
        let mut pmax = a[(k, k)].norm1();
        for i in k + 1..n {
            let v = a[(i, k)].norm1();
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
            a.swap_rows(p, k);
        }
        let inv = T::one() / a[(k, k)];
        for i in k + 1..n {
            a[(i, k)] *= inv;
        }
        for j in k + 1..n {
            let akj = a[(k, j)];
            if akj != T::zero() {
                for i in k + 1..n {
                    let lik = a[(i, k)];
                    a[(i, j)] -= lik * akj;
                }
            }
        }
    }
    true
}

/// Solves `A x = b` in place (`b` becomes `x`) with the factors from [`factor`].
pub(crate) fn solve<T: ComplexField<RealField = f64> + Copy>(lu: &DMatrix<T>, piv: &[usize], b: &mut [T]) {
    let n = lu.nrows();
    for (k, &p) in piv.iter().enumerate() {
        b.swap(k, p);
    }
    for j in 0..n {
        let bj = b[j];
        if bj != T::zero() {
            for i in j + 1..n {
                b[i] -= lu[(i, j)] * bj;
            }
        }
    }
    for j in (0..n).rev() {
        b[j] /= lu[(j, j)];
        let bj = b[j];
        for i in 0..j {
            b[i] -= lu[(i, j)] * bj;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Complex;

    /// A permuted, non-symmetric 3x3 system with a known solution: residual at round-off level.
    #[test]
    fn solves_real_and_complex_systems() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 4.0, 1.0, -1.0, 1.0, -3.0, 2.0]);
        let x = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[(i, j)] * x[j]).sum()).collect();
        let (mut lu, mut piv, mut y) = (a.clone(), [0usize; 3], b.clone());
        assert!(factor(&mut lu, &mut piv));
        solve(&lu, &piv, &mut y);
        for i in 0..3 {
            assert!((y[i] - x[i]).abs() < 1e-14);
        }
        let ac = a.map(|v| Complex::new(v, 0.5 * v + 1.0));
        let xc = [Complex::new(1.0, 1.0), Complex::new(0.0, -2.0), Complex::new(3.0, 0.0)];
        let bc: Vec<_> = (0..3).map(|i| (0..3).map(|j| ac[(i, j)] * xc[j]).sum()).collect();
        let (mut luc, mut yc) = (ac, bc);
        assert!(factor(&mut luc, &mut piv));
        solve(&luc, &piv, &mut yc);
        for i in 0..3 {
            assert!((yc[i] - xc[i]).norm() < 1e-13);
        }
        let mut singular = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(!factor(&mut singular, &mut piv[..2]));
    }
}
