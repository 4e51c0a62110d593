//! Rational transfer functions `N(s) / D(s)` with real coefficients.

use super::poly::Poly;
use nalgebra::Complex;
use std::ops::Mul;

#[derive(Debug, Clone, PartialEq)]
pub struct Tf {
    pub num: Poly,
    pub den: Poly,
}

impl Tf {
    /// `num / den` from ascending coefficients.
    pub fn new(num: &[f64], den: &[f64]) -> Self {
        Tf { num: Poly::new(num), den: Poly::new(den) }
    }

    /// First-order lag `1 / (s / omega + 1)` (the form of eq. 2.45, 2.57, 6.4).
    pub fn lag(omega: f64) -> Self {
        Tf::new(&[1.0], &[1.0, 1.0 / omega])
    }

    /// Value at `s`.
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        self.num.eval_c(s) / self.den.eval_c(s)
    }

    /// Frequency response `G(j w)`.
    pub fn at(&self, w: f64) -> Complex<f64> {
        self.eval(Complex::new(0.0, w))
    }

    /// Static gain `G(0)` (infinite for a pole at the origin).
    pub fn dc_gain(&self) -> f64 {
        self.num.eval(0.0) / self.den.eval(0.0)
    }

    /// Roots of the denominator.
    pub fn poles(&self) -> Vec<Complex<f64>> {
        self.den.roots()
    }

    /// Largest real part of the poles: < 0 means asymptotically stable.
    pub fn max_pole_re(&self) -> f64 {
        self.poles().iter().map(|p| p.re).fold(f64::NEG_INFINITY, f64::max)
    }

    /// Asymptotically stable: every pole in the open left half plane.
    pub fn is_stable(&self) -> bool {
        self.max_pole_re() < 0.0
    }

    /// `1 / G`.
    pub fn inv(&self) -> Tf {
        Tf { num: self.den.clone(), den: self.num.clone() }
    }

    /// `G1 + G2`.
    pub fn plus(&self, o: &Tf) -> Tf {
        Tf { num: &(&self.num * &o.den) + &(&o.num * &self.den), den: &self.den * &o.den }
    }
}

impl Mul for &Tf {
    type Output = Tf;
    fn mul(self, o: &Tf) -> Tf {
        Tf { num: &self.num * &o.num, den: &self.den * &o.den }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Algebra against hand-expanded results: 1/(s+1) + 1/(s+2) = (2s+3)/(s^2+3s+2), and
    /// 2/(s+1) * 1/(s+2) = 2/(s^2+3s+2) with DC gain 1, stable.
    #[test]
    fn algebra() {
        let (a, b) = (Tf::new(&[1.0], &[1.0, 1.0]), Tf::new(&[1.0], &[2.0, 1.0]));
        let sum = a.plus(&b);
        assert_eq!((sum.num.coeffs(), sum.den.coeffs()), (&[3.0, 2.0][..], &[2.0, 3.0, 1.0][..]));
        let prod = &Tf::new(&[2.0], &[1.0, 1.0]) * &b;
        assert_eq!((prod.num.coeffs(), prod.den.coeffs()), (&[2.0][..], &[2.0, 3.0, 1.0][..]));
        assert_eq!(prod.dc_gain(), 1.0);
        assert_eq!(prod.inv().den.coeffs(), &[2.0]);
        assert!(prod.is_stable() && !Tf::new(&[1.0], &[-1.0, 1.0]).is_stable());
        let g = Tf::lag(10.0).at(10.0);
        assert!((g.norm() - 0.5f64.sqrt()).abs() < 1e-15 && (g.arg() + std::f64::consts::FRAC_PI_4).abs() < 1e-15);
    }
}
