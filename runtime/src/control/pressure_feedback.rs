//! High-pass filtered pressure feedback (thesis chapter 6 intro, section 6.1, Fig. 6.1/6.2).
//!
//! The fed-back pressure p (p4, the rod-side / pilot pressure) passes the filter of eq. 6.2,
//!
//! ```text
//! G_f(s) = K_f s / (s/omega_f + 1)        [K_f] = m^4 s^2/kg = m^3/Pa
//! ```
//!
//! whose output is a flow Q_f [m^3/s] (m^3/Pa * 1/s * Pa). In Fig. 6.1/6.2 it is subtracted from
//! the flow reference Q4_ref; the pressure-compensated valve turns flow into spool opening with
//! its rated flow per unit opening Q_rated (25 l/min, section 2.2.1), so in spool units
//! `u_comp = Q_f / Q_rated` and `u = u_ref + u_comp`. Sign: in the lowering direction u < 0; a
//! falling pressure (dp/dt < 0) gives u_comp < 0 and so opens the valve further, a rising one
//! closes it (chapter 6 intro).
//!
//! Realisation: G_f(s) = K_f omega_f (1 - omega_f/(s + omega_f)), i.e. with the low-passed
//! pressure x, `x' = omega_f (p - x)` and `Q_f = K_f omega_f (p - x)`. The state is advanced
//! exactly for an input that is linear over the step (p(t + tau) = p + a tau): with z = p - x,
//! `z' = a - omega_f z`, so `z(h) = z0 e^(-omega_f h) + (a/omega_f)(1 - e^(-omega_f h))`.
//! Any partition of a piecewise-linear input therefore gives the same state up to rounding.

use crate::param;
use crate::params::{build, Param};

/// Parameters of the feedback, with the experiment-B defaults (Table 7.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HighPassFeedback {
    /// Filter gain K_f [m^4 s^2/kg] (eq. 6.2, 6.6).
    pub k_f: f64,
    /// Filter corner frequency omega_f [rad/s] (eq. 6.2, 6.7).
    pub omega_f: f64,
    /// Valve flow per unit spool opening [m^3/s] (rated flow 25 l/min, section 2.2.1).
    pub q_rated: f64,
}

/// The feedback's parameters: name, default, unit, range, source and field.
#[rustfmt::skip]
pub const FEEDBACK_PARAMS: [Param<HighPassFeedback>; 3] = [
    param!("K_f", k_f, 1.24e-11, "m4.s2/kg", "", [0.0, 1e-8],
        "Filter gain K_f of G_f(s) = K_f s/(s/omega_f + 1) (eq. 6.2)",
        "Table 7.2, experiment B (corrected filter of section 6.2)"),
    param!("omega_f", omega_f, 35.8, "rad/s", "", [1e-3, 1e5],
        "Filter corner frequency omega_f (eq. 6.2)", "Table 7.2, experiment B"),
    param!("Q_rated", q_rated, 25.0 / 60_000.0, "m3/s", "l/min", [1e-6, 1.0],
        "Valve flow per unit spool opening; turns the feedback flow into spool opening",
        "Rated flow of the PVG32 linear flow spool, 25 l/min (section 2.2.1)"),
];

impl Default for HighPassFeedback {
    /// The defaults of [`FEEDBACK_PARAMS`].
    fn default() -> Self {
        let zero = HighPassFeedback { k_f: 0.0, omega_f: 0.0, q_rated: 0.0 };
        build(zero, &FEEDBACK_PARAMS, |k| FEEDBACK_PARAMS[k].spec.default)
    }
}

impl HighPassFeedback {
    /// Feedback flow Q_f = K_f omega_f (p - x) [m^3/s] for pressure p and filter state x.
    pub fn flow(&self, p: f64, x: f64) -> f64 {
        self.k_f * self.omega_f * (p - x)
    }

    /// Spool compensation u_comp = Q_f / Q_rated [-].
    /// The filter state's derivative x' = omega_f (p - x) (the realisation of eq. 6.2 above).
    pub fn state_derivative(&self, p: f64, x: f64) -> f64 {
        self.omega_f * (p - x)
    }

    pub fn u_comp(&self, p: f64, x: f64) -> f64 {
        self.flow(p, x) / self.q_rated
    }

    /// Filter state after a step h for the input p(t + tau) = p0 + a tau, exactly.
    pub fn advance(&self, x: f64, p0: f64, a: f64, h: f64) -> f64 {
        let w = self.omega_f;
        let decay = (-w * h).exp();
        // 1 - e^(-w h) without cancellation for small w h.
        let rise = -(-w * h).exp_m1();
        let z = (p0 - x) * decay + a / w * rise;
        p0 + a * h - z
    }

    /// Frequency response of u_comp/p at omega [rad/s]: (K_f/Q_rated) j w / (j w/omega_f + 1),
    /// returned as (gain [1/Pa], phase [rad]).
    pub fn frequency_response(&self, omega: f64) -> (f64, f64) {
        let r = omega / self.omega_f;
        let gain = self.k_f / self.q_rated * omega / (1.0 + r * r).sqrt();
        (gain, std::f64::consts::FRAC_PI_2 - r.atan())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::unit;

    /// Dimensional check of eq. 6.2 in spool units: [K_f][omega_f][p] / [Q_rated] = 1.
    #[test]
    fn compensation_is_dimensionless() {
        let exps = |name: &str| unit(name).expect("declared unit").base;
        let (k, w, p, q) = (exps("m4.s2/kg"), exps("1/s"), exps("Pa"), exps("m3/s"));
        let total: Vec<i32> = (0..8).map(|i| k[i] + w[i] + p[i] - q[i]).collect();
        assert_eq!(total, vec![0; 8]);
    }

    /// The exact step against the closed-form solution of x' = w (p0 + a t - x) from x(0) = x0:
    /// x(t) = p0 + a t - a/w + (x0 - p0 + a/w) e^(-w t).
    #[test]
    fn advance_matches_closed_form() {
        let f = HighPassFeedback::default();
        let (x0, p0, a, w) = (3e6, 5e6, -2e7, f.omega_f);
        for h in [1e-6, 1e-3, 0.05, 1.0] {
            let expected = p0 + a * h - a / w + (x0 - p0 + a / w) * (-w * h).exp();
            let got = f.advance(x0, p0, a, h);
            // Rounding only: a few ulps of the 1e7 Pa magnitudes involved.
            assert!((got - expected).abs() <= 1e-8 * p0.abs(), "h = {h}: {got} vs {expected}");
        }
    }

    /// Splitting a ramp into parts gives the same state as one step (exact discretisation).
    #[test]
    fn any_partition_gives_the_same_state() {
        let f = HighPassFeedback::default();
        let (x0, p0, a) = (4e6, 4.5e6, 3e6);
        let one = f.advance(x0, p0, a, 0.1);
        let mut x = x0;
        let mut p = p0;
        for _ in 0..1000 {
            x = f.advance(x, p, a, 1e-4);
            p += a * 1e-4;
        }
        assert!((x - one).abs() <= 1e-12 * one.abs(), "{x} vs {one}");
    }

    /// A pressure falling at a constant rate gives, in steady state, u_comp = K_f a / Q_rated
    /// (the derivative action of eq. 6.2 at s -> 0), negative: the valve opens further.
    #[test]
    fn falling_pressure_opens_the_valve() {
        let f = HighPassFeedback::default();
        let a = -10e5; // -10 bar/s
        let t = 1.0; // 36 time constants: e^-36 is negligible
        let x = f.advance(5e6, 5e6, a, t);
        let u = f.u_comp(5e6 + a * t, x);
        let expected = f.k_f * a / f.q_rated;
        assert!(u < 0.0);
        assert!((u - expected).abs() <= 1e-9 * expected.abs(), "{u} vs {expected}");
    }
}
