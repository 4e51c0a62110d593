//! Dense LU factorisation with partial (row) pivoting, in place and allocation-free, for the
//! real and the complex iteration matrix of Radau IIA.
//!
//! `PA = LU` with unit lower `L` stored below the diagonal and `U` on and above it, as LAPACK's
//! `getrf`; `piv[k]` is the row swapped with row `k` at elimination step `k`. Matrices are
//! column-major slices of length `n²` (`a[i + j n]` is row `i`, column `j`, the layout of
//! `DMatrix::as_slice`) with `n = piv.len()`. A complex matrix and a complex right-hand side are
//! stored as separate real and imaginary parts (split storage), so that the inner loops are
//! plain real multiply-adds over contiguous column slices, without shuffles or bounds checks.
//! The complex arithmetic is written out exactly as `num_complex` evaluates it (product
//! `(ac - bd, ad + bc)`, quotient by `c² + d²`), pivots by `|re| + |im|`.

/// Factorises the real `n × n` matrix `a` in place, `n = piv.len()`. Returns `false` if a
/// pivot is zero or not finite (singular matrix).
pub(crate) fn factor(a: &mut [f64], piv: &mut [usize]) -> bool {
    let n = piv.len();
    assert_eq!(a.len(), n * n, "matrix is not n × n");
    for k in 0..n {
        let p = match pivot(&a[k * n..(k + 1) * n], None, k) {
            Some(p) => p,
            None => return false,
        };
        piv[k] = p;
        if p != k {
            for c in a.chunks_exact_mut(n) {
                c.swap(p, k);
            }
        }
        let (left, right) = a.split_at_mut((k + 1) * n);
        let colk = &mut left[k * n + k..];
        let inv = 1.0 / colk[0];
        let lk = &mut colk[1..];
        for l in lk.iter_mut() {
            *l *= inv;
        }
        for colj in right.chunks_exact_mut(n) {
            let (head, tail) = colj.split_at_mut(k + 1);
            let akj = head[k];
            if akj != 0.0 {
                for (aij, &lik) in tail.iter_mut().zip(lk.iter()) {
                    *aij -= lik * akj;
                }
            }
        }
    }
    true
}

/// Solves `A x = b` in place (`b` becomes `x`) with the factors from [`factor`]; an empty
/// system (n = 0) has nothing to solve.
pub(crate) fn solve(lu: &[f64], piv: &[usize], b: &mut [f64]) {
    let n = piv.len();
    assert!(lu.len() == n * n && b.len() == n, "dimensions differ");
    if n == 0 {
        return;
    }
    for (k, &p) in piv.iter().enumerate() {
        b.swap(k, p);
    }
    for (j, col) in lu.chunks_exact(n).enumerate() {
        let bj = b[j];
        for i in j + 1..n {
            b[i] -= col[i] * bj;
        }
    }
    for (j, col) in lu.chunks_exact(n).enumerate().rev() {
        let bj = b[j] / col[j];
        b[j] = bj;
        for i in 0..j {
            b[i] -= col[i] * bj;
        }
    }
}

/// Factorises the complex `n × n` matrix `re + i·im` in place (split storage, module doc).
/// Returns `false` if a pivot is zero or not finite.
pub(crate) fn factor_complex(re: &mut [f64], im: &mut [f64], piv: &mut [usize]) -> bool {
    let n = piv.len();
    assert!(re.len() == n * n && im.len() == n * n, "matrix is not n × n");
    for k in 0..n {
        let p = match pivot(&re[k * n..(k + 1) * n], Some(&im[k * n..(k + 1) * n]), k) {
            Some(p) => p,
            None => return false,
        };
        piv[k] = p;
        if p != k {
            for c in re.chunks_exact_mut(n).chain(im.chunks_exact_mut(n)) {
                c.swap(p, k);
            }
        }
        let (left_r, right_r) = re.split_at_mut((k + 1) * n);
        let (left_i, right_i) = im.split_at_mut((k + 1) * n);
        let (colk_r, colk_i) = (&mut left_r[k * n + k..], &mut left_i[k * n + k..]);
        // 1 / (c + id) = (c - id) / (c² + d²), as num_complex divides.
        let (c, d) = (colk_r[0], colk_i[0]);
        let ns = c * c + d * d;
        let (inv_r, inv_i) = ((1.0 * c + 0.0 * d) / ns, (0.0 * c - 1.0 * d) / ns);
        let (lk_r, lk_i) = (&mut colk_r[1..], &mut colk_i[1..]);
        for (lr, li) in lk_r.iter_mut().zip(lk_i.iter_mut()) {
            let (a, b) = (*lr, *li);
            *lr = a * inv_r - b * inv_i;
            *li = b * inv_r + a * inv_i;
        }
        for (colj_r, colj_i) in right_r.chunks_exact_mut(n).zip(right_i.chunks_exact_mut(n)) {
            let (head_r, tail_r) = colj_r.split_at_mut(k + 1);
            let (head_i, tail_i) = colj_i.split_at_mut(k + 1);
            let (ar, ai) = (head_r[k], head_i[k]);
            if ar != 0.0 || ai != 0.0 {
                let rows = tail_r.iter_mut().zip(tail_i.iter_mut()).zip(lk_r.iter().zip(lk_i.iter()));
                for ((xr, xi), (&lr, &li)) in rows {
                    *xr -= lr * ar - li * ai;
                    *xi -= lr * ai + li * ar;
                }
            }
        }
    }
    true
}

/// Solves `A x = b` in place for the complex factors of [`factor_complex`]; `b = br + i·bi`
/// becomes `x` (nothing to do for n = 0).
pub(crate) fn solve_complex(re: &[f64], im: &[f64], piv: &[usize], br: &mut [f64], bi: &mut [f64]) {
    let n = piv.len();
    assert!(re.len() == n * n && im.len() == n * n && br.len() == n && bi.len() == n, "dimensions differ");
    if n == 0 {
        return;
    }
    for (k, &p) in piv.iter().enumerate() {
        br.swap(k, p);
        bi.swap(k, p);
    }
    for (j, (col_r, col_i)) in re.chunks_exact(n).zip(im.chunks_exact(n)).enumerate() {
        let (head_r, tail_r) = br.split_at_mut(j + 1);
        let (head_i, tail_i) = bi.split_at_mut(j + 1);
        let (xr, xi) = (head_r[j], head_i[j]);
        if xr != 0.0 || xi != 0.0 {
            let rows = tail_r.iter_mut().zip(tail_i.iter_mut()).zip(col_r[j + 1..].iter().zip(&col_i[j + 1..]));
            for ((yr, yi), (&lr, &li)) in rows {
                *yr -= lr * xr - li * xi;
                *yi -= lr * xi + li * xr;
            }
        }
    }
    for (j, (col_r, col_i)) in re.chunks_exact(n).zip(im.chunks_exact(n)).enumerate().rev() {
        let (head_r, tail_r) = br.split_at_mut(j);
        let (head_i, tail_i) = bi.split_at_mut(j);
        // (a + ib) / (c + id) = ((ac + bd) + i(bc - ad)) / (c² + d²), as num_complex divides.
        let (a, b, c, d) = (tail_r[0], tail_i[0], col_r[j], col_i[j]);
        let ns = c * c + d * d;
        let (xr, xi) = ((a * c + b * d) / ns, (b * c - a * d) / ns);
        tail_r[0] = xr;
        tail_i[0] = xi;
        let rows = head_r.iter_mut().zip(head_i.iter_mut()).zip(col_r.iter().zip(col_i));
        for ((yr, yi), (&ur, &ui)) in rows {
            *yr -= ur * xr - ui * xi;
            *yi -= ur * xi + ui * xr;
        }
    }
}

/// Row of the largest `|re| + |im|` in `col[k..]` (first on ties), `None` if it is zero or not
/// finite.
fn pivot(col_r: &[f64], col_i: Option<&[f64]>, k: usize) -> Option<usize> {
    let norm1 = |i: usize| col_r[i].abs() + col_i.map_or(0.0, |c| c[i].abs());
    let mut p = k;
    let mut pmax = norm1(k);
    for i in k + 1..col_r.len() {
        let v = norm1(i);
        if v > pmax {
            pmax = v;
            p = i;
        }
    }
    (pmax != 0.0 && pmax.is_finite()).then_some(p)
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
        let bc: Vec<Complex<f64>> = (0..3).map(|i| (0..3).map(|j| ac[(i, j)] * xc[j]).sum()).collect();
        let (mut re, mut im) = (ac.map(|v| v.re), ac.map(|v| v.im));
        let (mut br, mut bi): (Vec<f64>, Vec<f64>) = bc.iter().map(|v| (v.re, v.im)).unzip();
        assert!(factor_complex(re.as_mut_slice(), im.as_mut_slice(), &mut piv));
        solve_complex(re.as_slice(), im.as_slice(), &piv, &mut br, &mut bi);
        for i in 0..3 {
            assert!((Complex::new(br[i], bi[i]) - xc[i]).norm() < 1e-13);
        }
        let mut singular = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(!factor(singular.as_mut_slice(), &mut piv[..2]));
        let (mut singular, mut zero_im) = (DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]), DMatrix::zeros(2, 2));
        assert!(!factor_complex(singular.as_mut_slice(), zero_im.as_mut_slice(), &mut piv[..2]));
    }

    /// The split complex routines give bit for bit what generic `Complex<f64>` arithmetic
    /// gives (same operations in the same order), on a dense 6x6 matrix with pivoting.
    #[test]
    fn split_complex_matches_complex_arithmetic() {
        let n = 6;
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let a: Vec<Complex<f64>> = (0..n * n).map(|_| Complex::new(rnd(), rnd())).collect();
        let b: Vec<Complex<f64>> = (0..n).map(|_| Complex::new(rnd(), rnd())).collect();
        // Reference: the same algorithm on Complex<f64>.
        let (mut lu, mut x, mut piv_ref) = (a.clone(), b.clone(), vec![0; n]);
        for k in 0..n {
            let p = (k..n).fold(k, |p, i| if lu[i + k * n].l1_norm() > lu[p + k * n].l1_norm() { i } else { p });
            piv_ref[k] = p;
            for j in 0..n {
                lu.swap(k + j * n, p + j * n);
            }
            let inv = Complex::new(1.0, 0.0) / lu[k + k * n];
            for i in k + 1..n {
                lu[i + k * n] *= inv;
            }
            for j in k + 1..n {
                let akj = lu[k + j * n];
                for i in k + 1..n {
                    let l = lu[i + k * n];
                    lu[i + j * n] -= l * akj;
                }
            }
        }
        for (k, &p) in piv_ref.iter().enumerate() {
            x.swap(k, p);
        }
        for j in 0..n {
            for i in j + 1..n {
                let t = lu[i + j * n] * x[j];
                x[i] -= t;
            }
        }
        for j in (0..n).rev() {
            x[j] = x[j] / lu[j + j * n];
            for i in 0..j {
                let t = lu[i + j * n] * x[j];
                x[i] -= t;
            }
        }
        let (mut re, mut im): (Vec<f64>, Vec<f64>) = a.iter().map(|v| (v.re, v.im)).unzip();
        let (mut br, mut bi): (Vec<f64>, Vec<f64>) = b.iter().map(|v| (v.re, v.im)).unzip();
        let mut piv = vec![0; n];
        assert!(factor_complex(&mut re, &mut im, &mut piv));
        solve_complex(&re, &im, &piv, &mut br, &mut bi);
        assert_eq!(piv, piv_ref);
        for i in 0..n * n {
            assert_eq!((re[i].to_bits(), im[i].to_bits()), (lu[i].re.to_bits(), lu[i].im.to_bits()), "LU {i}");
        }
        for i in 0..n {
            assert_eq!((br[i].to_bits(), bi[i].to_bits()), (x[i].re.to_bits(), x[i].im.to_bits()), "x {i}");
        }
    }
}
