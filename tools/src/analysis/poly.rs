//! Real polynomials in ascending powers, with complex evaluation and roots (companion matrix
//! eigenvalues with nalgebra, polished by Newton steps).

use nalgebra::{Complex, DMatrix, Schur};
use std::ops::{Add, Mul, Neg, Sub};

/// `c[0] + c[1] s + c[2] s^2 + ...`; trailing zero coefficients are dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct Poly(Vec<f64>);

impl Poly {
    /// The polynomial with ascending coefficients `c`.
    pub fn new(c: &[f64]) -> Self {
        let mut v = c.to_vec();
        while v.len() > 1 && v.last() == Some(&0.0) {
            v.pop();
        }
        if v.is_empty() {
            v.push(0.0);
        }
        Poly(v)
    }

    /// Ascending coefficients.
    pub fn coeffs(&self) -> &[f64] {
        &self.0
    }

    pub fn degree(&self) -> usize {
        self.0.len() - 1
    }

    /// `c * p`.
    pub fn scale(&self, c: f64) -> Self {
        Poly::new(&self.0.iter().map(|a| a * c).collect::<Vec<_>>())
    }

    /// Value at real `x` (Horner).
    pub fn eval(&self, x: f64) -> f64 {
        self.0.iter().rev().fold(0.0, |acc, &a| acc * x + a)
    }

    /// Value at complex `s` (Horner).
    pub fn eval_c(&self, s: Complex<f64>) -> Complex<f64> {
        self.0.iter().rev().fold(Complex::new(0.0, 0.0), |acc, &a| acc * s + a)
    }

    /// Derivative.
    pub fn derivative(&self) -> Self {
        Poly::new(&self.0.iter().enumerate().skip(1).map(|(k, a)| k as f64 * a).collect::<Vec<_>>())
    }

    /// `p(j w) = re(w) + j im(w)` as two real polynomials in `w`.
    pub fn on_imaginary_axis(&self) -> (Poly, Poly) {
        let (mut re, mut im) = (vec![0.0; self.0.len()], vec![0.0; self.0.len()]);
        for (k, &a) in self.0.iter().enumerate() {
            // j^k = 1, j, -1, -j
            match k % 4 {
                0 => re[k] = a,
                1 => im[k] = a,
                2 => re[k] = -a,
                _ => im[k] = -a,
            }
        }
        (Poly::new(&re), Poly::new(&im))
    }

    /// All complex roots. The variable is scaled by `|c0 / cn|^(1/n)` before the companion
    /// matrix is formed, so coefficients spanning many decades (hydraulic capacitances ~1e-13
    /// next to unit gains) stay well conditioned; each root is then polished by Newton steps
    /// on the original polynomial. Roots at zero (vanishing low coefficients) are split off.
    pub fn roots(&self) -> Vec<Complex<f64>> {
        let zeros = self.0.iter().take_while(|&&a| a == 0.0).count().min(self.degree());
        let c = &self.0[zeros..];
        let n = c.len() - 1;
        let mut roots = vec![Complex::new(0.0, 0.0); zeros];
        if n == 0 {
            return roots;
        }
        let scale = (c[0] / c[n]).abs().powf(1.0 / n as f64);
        // q(z) = p(scale z) / (c_n scale^n), monic
        let q: Vec<f64> = (0..n).map(|k| c[k] * scale.powi(k as i32 - n as i32) / c[n]).collect();
        let mut m = DMatrix::<f64>::zeros(n, n);
        for k in 0..n {
            m[(0, k)] = -q[n - 1 - k];
            if k + 1 < n {
                m[(k + 1, k)] = 1.0;
            }
        }
        let d = self.derivative();
        for z in eigenvalues(m).iter() {
            let mut s = z * scale;
            for _ in 0..3 {
                let ds = d.eval_c(s);
                if ds.norm() == 0.0 {
                    break;
                }
                let step = self.eval_c(s) / ds;
                if !step.re.is_finite() || !step.im.is_finite() {
                    break;
                }
                // Accept a Newton step only when it reduces the residual (clustered roots).
                let next = s - step;
                if self.eval_c(next).norm() < self.eval_c(s).norm() {
                    s = next;
                }
            }
            roots.push(s);
        }
        roots
    }

    /// Real roots in `(lo, hi)`: roots whose imaginary part is below `1e-6` of their modulus.
    pub fn real_roots_in(&self, lo: f64, hi: f64) -> Vec<f64> {
        let mut r: Vec<f64> = self
            .roots()
            .into_iter()
            .filter(|z| z.im.abs() <= 1e-6 * z.norm().max(f64::MIN_POSITIVE))
            .map(|z| z.re)
            .filter(|&x| x > lo && x < hi)
            .collect();
        r.sort_by(f64::total_cmp);
        r.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        r
    }
}

/// `D^-1 M D` with the diagonal `D` of powers of two that makes each row and its column about
/// equally large (Parlett & Reinsch 1969, "Balancing a matrix for calculation of eigenvalues and
/// eigenvectors", Numer. Math. 13; the balancing LAPACK's dgeev does first): the same
/// eigenvalues, exactly (powers of two), computed with errors relative to the balanced norm.
/// The plant's Jacobians mix 1e13 Pa/s per m^3 with 1e-6 rad/s per Pa; unbalanced, Francis QR
/// moved their slow oscillatory eigenvalues by 10 % (against LAPACK, tests/python/test_linearize.py).
fn balanced(mut m: DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    loop {
        let mut done = true;
        for i in 0..n {
            let c: f64 = (0..n).filter(|&j| j != i).map(|j| m[(j, i)].abs()).sum();
            let r: f64 = (0..n).filter(|&j| j != i).map(|j| m[(i, j)].abs()).sum();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            // f: the power of two with c f^2 within a factor 4 of r; scaling row i by 1/f and
            // column i by f makes the off-diagonal norms r/f and c f.
            let (mut f, mut cf2, s) = (1.0, c, c + r);
            while cf2 < r / 2.0 {
                f *= 2.0;
                cf2 *= 4.0;
            }
            while cf2 >= r * 2.0 {
                f /= 2.0;
                cf2 /= 4.0;
            }
            if (cf2 + r) / f < 0.95 * s {
                done = false;
                m.row_mut(i).scale_mut(1.0 / f);
                m.column_mut(i).scale_mut(f);
            }
        }
        if done {
            return m;
        }
    }
}

/// Eigenvalues of `m` by nalgebra's Schur decomposition with an iteration limit. Francis QR
/// can stall on symmetric companion matrices such as `[[0, 1], [1, 0]]` (nalgebra's
/// `complex_eigenvalues` then never returns), so on failure the spectrum is shifted,
/// `eig(M + sigma I) - sigma`, which breaks the symmetry of the eigenvalue magnitudes.
pub(crate) fn eigenvalues(m: DMatrix<f64>) -> Vec<Complex<f64>> {
    let m = balanced(m);
    let n = m.nrows();
    let norm = m.norm().max(1.0);
    for sigma in [0.0, 0.137, -0.291, 0.613, -1.07] {
        let shifted = &m + DMatrix::<f64>::identity(n, n) * (sigma * norm);
        if let Some(schur) = Schur::try_new(shifted, f64::EPSILON, 1000 * n) {
            return schur.complex_eigenvalues().iter().map(|z| z - sigma * norm).collect();
        }
    }
    panic!("the Schur decomposition of a {n}x{n} matrix did not converge")
}

impl Add for &Poly {
    type Output = Poly;
    fn add(self, o: &Poly) -> Poly {
        let n = self.0.len().max(o.0.len());
        let get = |p: &Poly, k: usize| p.0.get(k).copied().unwrap_or(0.0);
        Poly::new(&(0..n).map(|k| get(self, k) + get(o, k)).collect::<Vec<_>>())
    }
}

impl Sub for &Poly {
    type Output = Poly;
    fn sub(self, o: &Poly) -> Poly {
        self + &-o
    }
}

impl Neg for &Poly {
    type Output = Poly;
    fn neg(self) -> Poly {
        self.scale(-1.0)
    }
}

impl Mul for &Poly {
    type Output = Poly;
    fn mul(self, o: &Poly) -> Poly {
        let mut c = vec![0.0; self.0.len() + o.0.len() - 1];
        for (i, a) in self.0.iter().enumerate() {
            for (k, b) in o.0.iter().enumerate() {
                c[i + k] += a * b;
            }
        }
        Poly::new(&c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (s + 1)(s + 2)(s^2 + 2s + 5) = s^4 + 5s^3 + 13s^2 + 19s + 10: roots -1, -2, -1 +- 2j
    /// (exact by construction); 1e-10 covers rounding of the eigenvalue solver.
    #[test]
    fn roots_of_known_product() {
        let p = &(&Poly::new(&[1.0, 1.0]) * &Poly::new(&[2.0, 1.0])) * &Poly::new(&[5.0, 2.0, 1.0]);
        assert_eq!(p.coeffs(), &[10.0, 19.0, 13.0, 5.0, 1.0]);
        let mut r = p.roots();
        r.sort_by(|a, b| a.im.total_cmp(&b.im).then(a.re.total_cmp(&b.re)));
        let expected = [(-1.0, -2.0), (-2.0, 0.0), (-1.0, 0.0), (-1.0, 2.0)];
        for (z, (re, im)) in r.iter().zip(expected) {
            assert!((z.re - re).abs() < 1e-10 && (z.im - im).abs() < 1e-10, "{r:?}");
        }
    }

    /// Badly scaled coefficients (a hydraulic characteristic polynomial, roots -50, -3e3 and
    /// 1e2 +- 8e2 j scaled by 1e-13) keep 1e-9 relative accuracy thanks to the scaling.
    #[test]
    fn roots_badly_scaled() {
        let lin = |r: f64| Poly::new(&[-r, 1.0]);
        let quad = Poly::new(&[1e2 * 1e2 + 8e2 * 8e2, -2e2, 1.0]);
        let p = (&(&lin(-50.0) * &lin(-3e3)) * &quad).scale(1e-13);
        let r = p.roots();
        for want in [Complex::new(-50.0, 0.0), Complex::new(-3e3, 0.0), Complex::new(1e2, 8e2)] {
            assert!(r.iter().any(|z| (z - want).norm() < 1e-9 * want.norm()), "{want} not in {r:?}");
        }
        assert_eq!(Poly::new(&[0.0, 0.0, 1.0]).roots().len(), 2);
        // w^2 - 1: the companion matrix [[0, 1], [1, 0]] stalls unshifted QR
        let mut r: Vec<f64> = Poly::new(&[-1.0, 0.0, 1.0]).roots().iter().map(|z| z.re).collect();
        r.sort_by(f64::total_cmp);
        assert_eq!(r, [-1.0, 1.0]);
    }

    /// p(j w) split into real and imaginary polynomials, against complex evaluation.
    #[test]
    fn imaginary_axis_split() {
        let p = Poly::new(&[1.0, -2.0, 3.0, 4.0, -5.0]);
        let (re, im) = p.on_imaginary_axis();
        for w in [0.3, 1.7, 12.0] {
            let z = p.eval_c(Complex::new(0.0, w));
            assert!((z.re - re.eval(w)).abs() < 1e-9 * z.norm() && (z.im - im.eval(w)).abs() < 1e-9 * z.norm());
        }
    }
}
