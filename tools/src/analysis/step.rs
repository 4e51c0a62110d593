//! Unit step response of a strictly proper, stable transfer function in closed form, and its
//! 2 % settling time (Table 6.3).
//!
//! With distinct poles `p_i`, `y(t) = G(0) + sum_i r_i / p_i e^(p_i t)`, `r_i = N(p_i) / D'(p_i)`
//! (partial fractions of `G(s) / s`). Complex pairs contribute conjugate terms; the sum is real.

use super::tf::Tf;
use boomsim::hydraulics::solve::bisect;
use nalgebra::Complex;

/// The step response `y(t)` of `g` as a sum of modes.
#[derive(Debug, Clone)]
pub struct StepResponse {
    /// Final value `G(0)`.
    pub final_value: f64,
    /// (pole, coefficient `r / p`) of each mode.
    modes: Vec<(Complex<f64>, Complex<f64>)>,
}

impl StepResponse {
    /// `None` if `g` is not strictly proper, has a pole at the origin or is unstable.
    pub fn new(g: &Tf) -> Option<Self> {
        if g.num.degree() >= g.den.degree() || !g.is_stable() {
            return None;
        }
        let d = g.den.derivative();
        let modes = g.poles().into_iter().map(|p| (p, g.num.eval_c(p) / d.eval_c(p) / p)).collect();
        Some(StepResponse { final_value: g.dc_gain(), modes })
    }

    /// `y(t)`.
    pub fn at(&self, t: f64) -> f64 {
        self.final_value + self.modes.iter().map(|(p, c)| (c * (p * t).exp()).re).sum::<f64>()
    }

    /// 2 % settling time (s): the last time `|y - G(0)|` exceeds `band |G(0)|`. The modes'
    /// envelope `sum |c_i| e^(Re p_i t)` bounds the search; the last violation is found on a
    /// grid that resolves the fastest oscillation and refined by bisection.
    pub fn settling_time(&self, band: f64) -> f64 {
        let tol = band * self.final_value.abs();
        let envelope = |t: f64| self.modes.iter().map(|(p, c)| c.norm() * (p.re * t).exp()).sum::<f64>();
        let slowest = self.modes.iter().map(|(p, _)| -p.re).fold(f64::INFINITY, f64::min);
        let mut t_end = 1.0 / slowest;
        while envelope(t_end) > tol {
            t_end *= 1.5;
        }
        let fastest_osc = self.modes.iter().map(|(p, _)| p.im.abs()).fold(0.0, f64::max);
        let n = ((t_end * fastest_osc / 0.2).ceil() as usize).clamp(20_000, 2_000_000);
        let dt = t_end / n as f64;
        let out = |t: f64| (self.at(t) - self.final_value).abs() > tol;
        let Some(k) = (0..=n).rev().find(|&k| out(k as f64 * dt)) else { return 0.0 };
        let (a, b) = (k as f64 * dt, (k + 1) as f64 * dt);
        bisect(|t| (self.at(t) - self.final_value).abs() - tol, a, b, 1e-12 * b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Second-order system w^2 / (s^2 + 2 z w s + w^2): y(t) = 1 - e^(-z w t) / sqrt(1 - z^2)
    /// sin(w_d t + acos z) (textbook closed form); the settling time is where the response last
    /// leaves the 2 % band, checked against a brute-force scan of the closed form with 1e-6 s
    /// resolution (tolerance 2e-6 s).
    #[test]
    fn second_order_against_closed_form() {
        let (w, z) = (10.0, 0.3);
        let g = Tf::new(&[w * w], &[w * w, 2.0 * z * w, 1.0]);
        let y = StepResponse::new(&g).unwrap();
        let wd = w * (1.0 - z * z).sqrt();
        let exact = |t: f64| 1.0 - (-z * w * t).exp() / (1.0 - z * z).sqrt() * (wd * t + z.acos()).sin();
        for t in [0.0, 0.05, 0.1, 0.3, 1.0] {
            assert!((y.at(t) - exact(t)).abs() < 1e-12, "t = {t}");
        }
        let ts = y.settling_time(0.02);
        let last = (0..3_000_000).rev().map(|k| k as f64 * 1e-6).find(|&t| (exact(t) - 1.0).abs() > 0.02).unwrap();
        assert!((ts - last).abs() < 2e-6, "{ts} vs {last}");
        // the familiar estimate 4 / (z w) = 1.33 s is an upper bound of the same order
        assert!(ts < 4.0 / (z * w) && ts > 0.5 * 4.0 / (z * w));
    }

    #[test]
    fn refuses_unstable_and_improper() {
        assert!(StepResponse::new(&Tf::new(&[1.0], &[-1.0, 1.0])).is_none());
        assert!(StepResponse::new(&Tf::new(&[1.0, 1.0], &[1.0, 1.0])).is_none());
    }
}
