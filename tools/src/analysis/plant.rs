//! The load transfer function `H(s)` (eq. 2.81) and the uncompensated closed loop (eq. 2.82).
//!
//! `H(s) = mu_c A_c V_c(s) / P4(s)` follows from eq. 2.74, 2.75, 2.77, 2.78: with
//! `K_c = K_qu / p_fo + K_qp` (pressure-flow gain of p3) and
//! `K_e = K_qu / p_fo (1 + mu_p / mu_c) + K_qp`,
//! `kappa = mu_c^2 K_e`, `tau = C1 / K_e`, `omega_n = A_c / sqrt(C1 m)`,
//! `zeta = sqrt(m / C1) K_c / (2 A_c)` — the printed coefficients, re-derived and confirmed.

use super::operating_point::{Linearised, OperatingPoint};
use super::tf::Tf;

/// Parameters of `H(s) = kappa (tau s + 1) / (s^2 / omega_n^2 + 2 zeta s / omega_n + 1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HParams {
    /// Static flow-pressure gain (m^4 s/kg = m^3/(s Pa)).
    pub kappa: f64,
    /// Zero time constant (s).
    pub tau: f64,
    /// Natural frequency of the load on the piston-side compliance (rad/s).
    pub omega_n: f64,
    /// Damping ratio (-).
    pub zeta: f64,
}

impl HParams {
    /// Eq. 2.81 at the linearisation `lin` of `op`.
    pub fn new(op: &OperatingPoint, lin: &Linearised) -> Self {
        let k_c = lin.k_qu / op.p_fo + lin.k_qp;
        let k_e = lin.k_qu / op.p_fo * (1.0 + op.mu_p / op.mu_c) + lin.k_qp;
        HParams {
            kappa: op.mu_c * op.mu_c * k_e,
            tau: lin.c1 / k_e,
            omega_n: op.area / (lin.c1 * op.mass).sqrt(),
            zeta: (op.mass / lin.c1).sqrt() * k_c / (2.0 * op.area),
        }
    }

    /// `H(s)` (eq. 2.81, 6.1).
    pub fn h(&self) -> Tf {
        let w = self.omega_n;
        Tf::new(&[self.kappa, self.kappa * self.tau], &[1.0, 2.0 * self.zeta / w, 1.0 / (w * w)])
    }
}

/// `C2 s + H(s)`: the rod-side admittance `Q4 / P4` (eq. 2.76 with `mu_c A_c V_c = H P4`).
pub fn admittance(c2: f64, h: &Tf) -> Tf {
    Tf::new(&[0.0, c2], &[1.0]).plus(h)
}

/// The uncompensated closed loop `mu_c A_c V_c / Q4 = H / (C2 s + H)` (eq. 2.82, Fig. 2.19).
pub fn closed_loop(c2: f64, h: &Tf) -> Tf {
    // H / (C2 s + H) = N_H / (C2 s D_H + N_H): the admittance's numerator.
    Tf { num: h.num.clone(), den: admittance(c2, h).num }
}

/// Coefficients `[b0, b1]`, `[a0, a1, a2, a3]` of eq. 2.82 as printed in the thesis.
pub fn closed_loop_coefficients(op: &OperatingPoint, lin: &Linearised) -> ([f64; 2], [f64; 4]) {
    let k_e = lin.k_qu / op.p_fo * (1.0 + op.mu_p / op.mu_c) + lin.k_qp;
    let k_c = lin.k_qu / op.p_fo + lin.k_qp;
    let mu2 = op.mu_c * op.mu_c;
    let a2c = op.area * op.area;
    (
        [mu2 * k_e, mu2 * lin.c1],
        [mu2 * k_e, mu2 * lin.c1 + lin.c2, op.mass * lin.c2 * k_c / a2c, op.mass * lin.c1 * lin.c2 / a2c],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Complex;

    /// H(s) from the block algebra of eq. 2.74-2.78 solved numerically at test frequencies
    /// (a 2x2 linear solve for P3, V_c per unit P4), against the closed form of eq. 2.81.
    /// Tolerance 1e-9 relative: both are exact up to rounding.
    #[test]
    fn h_matches_the_linear_equations() {
        let op = OperatingPoint::default();
        let lin = op.linearise().unwrap();
        let h = HParams::new(&op, &lin).h();
        for w in [0.1, 10.0, 83.82, 500.0, 1e4] {
            let s = Complex::new(0.0, w);
            // eq. 2.74: m s V = mu_c A P4 - A P3; eq. 2.75 with 2.77, 2.78:
            // C1 s P3 = A V - K_qu/p_fo (mu_p P4 + P3) - K_qp P3. Unknowns P3, V with P4 = 1.
            let (a11, a12, r1) = (Complex::new(op.area, 0.0), s * op.mass, Complex::new(op.mu_c * op.area, 0.0));
            let a21 = s * lin.c1 + lin.k_qu / op.p_fo + lin.k_qp;
            let (a22, r2) = (Complex::new(-op.area, 0.0), Complex::new(-lin.k_qu / op.p_fo * op.mu_p, 0.0));
            let det = a11 * a22 - a12 * a21;
            let v = (a11 * r2 - a21 * r1) / det;
            let want = v * op.mu_c * op.area;
            let got = h.at(w);
            assert!((got - want).norm() < 1e-9 * want.norm(), "w = {w}: {got} vs {want}");
        }
    }

    /// The printed coefficients b0, b1, a0..a3 of eq. 2.82 equal the polynomial algebra of
    /// H / (C2 s + H) after normalising both to a0 (1e-12 relative: rounding).
    #[test]
    fn closed_loop_coefficients_match_eq_2_82() {
        let op = OperatingPoint::default();
        let lin = op.linearise().unwrap();
        let g = closed_loop(lin.c2, &HParams::new(&op, &lin).h());
        let (b, a) = closed_loop_coefficients(&op, &lin);
        let (d0, a0) = (g.den.coeffs()[0], a[0]);
        for (k, ak) in a.iter().enumerate() {
            assert!((g.den.coeffs()[k] / d0 - ak / a0).abs() < 1e-12 * (ak / a0).abs(), "a{k}");
        }
        for (k, bk) in b.iter().enumerate() {
            assert!((g.num.coeffs()[k] / d0 - bk / a0).abs() < 1e-12 * (bk / a0).abs(), "b{k}");
        }
        assert!((g.dc_gain() - 1.0).abs() < 1e-12);
    }
}
