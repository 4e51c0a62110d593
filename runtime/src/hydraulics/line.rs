//! Hydraulic volumes: pressure build-up `dp/dt = (sum Q - dV/dt) / C` (the continuity equation
//! behind eq. 2.70-2.71 with `C = V / beta`), extended with the hose compliance of eq. 5.2 /
//! Table 5.2 and an entrained-air model that keeps every pressure above absolute zero, and
//! continued below it for the states an integrator tries ([`Fluid::pressure_rate`]).
//!
//! Pressures are gauge (Pa); absolute zero is `-P_ATM`.

use crate::scalar::{Dual64, Scalar};
use crate::units::P_ATM;

/// Absolute pressure (Pa) below which the equations are continued ([`Fluid::bulk_modulus`],
/// [`Fluid::pressure_rate`]): the physics never gets there (the air law holds every pressure
/// above absolute zero; the lowest in the thesis' experiments and the lowering runs of
/// scripts/me_trial_states.py is 2.5 kPa), only an integrator's trial state does. Above it every
/// value is the law's, bit for bit.
const P_ABS_MIN: f64 = 1e-3;

/// Time constant (s) with which a pressure below [`P_ABS_MIN`] relaxes back to it
/// ([`Fluid::pressure_rate`]).
const TAU_VACUUM: f64 = 1e-3;

/// Hydraulic fluid: oil with a small amount of entrained (undissolved) air.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fluid {
    /// Oil bulk modulus `beta` (Pa), 1300 MPa (parameter list, "oil stiffness").
    pub beta: f64,
    /// Volume of free air per volume of oil at atmospheric pressure (-). The thesis assumes a
    /// constant bulk modulus (section 2 assumptions) and has no gas model; see [`Fluid::bulk_modulus`].
    pub air_fraction: f64,
}

impl Fluid {
    /// Volume of the oil-air mixture per volume the same oil mass occupies at 0 bar gauge
    /// without air: `phi(p) = exp(-p / beta) + x0 * P_ATM / p_abs` (constant-bulk-modulus oil
    /// plus isothermal ideal-gas air, `x0` = [`Fluid::air_fraction`]). The oil mass in a volume V
    /// is proportional to `V / phi(p)`.
    pub fn volume_ratio(&self, p: f64) -> f64 {
        let p_abs = (p + P_ATM).max(P_ABS_MIN);
        (-p / self.beta).exp() + self.air_fraction * P_ATM / p_abs
    }

    /// Effective bulk modulus `beta_e = -phi / phi'` of the mixture (Pa):
    /// `beta_e = p_abs (e p_abs + a) / (e p_abs^2 / beta + a)` with `e = exp(-p / beta)`,
    /// `a = x0 * P_ATM`.
    ///
    /// Deviation from the thesis (constant `beta`): the air term models cavitation/air release
    /// physically. It softens the oil most at low pressure: by [`AIR_PRESSURES`]'s amounts,
    /// which docs/models.md quotes (checked by a test); as `p_abs -> 0` the free air
    /// expands without bound and `beta_e -> p_abs`, so `dp/dt -> 0` smoothly and a pressure
    /// never reaches absolute zero (vapour pressure of the oil is neglected against it). With
    /// `x0 = 0` it is exactly `beta`.
    ///
    /// Below [`P_ABS_MIN`] absolute (only an integrator's trial state gets there) the law is
    /// continued by the exponential that meets it with value and slope there,
    /// `beta_e(P_ABS_MIN) exp(k (p_abs - P_ABS_MIN))` with `k = beta_e' / beta_e` at
    /// `P_ABS_MIN` (about `1 / P_ABS_MIN`): positive, continuously differentiable, and falling to
    /// 0 within a few mPa below it, the limit the law itself tends to (free air that takes up any
    /// volume change without a change of pressure). See [`Fluid::pressure_rate`].
    pub fn bulk_modulus<T: Scalar>(&self, p: T) -> T {
        if p.re() + P_ATM >= P_ABS_MIN {
            return self.mixture(p);
        }
        let at = self.mixture(Dual64::new(P_ABS_MIN - P_ATM, 1.0));
        ((p + (P_ATM - P_ABS_MIN)) * (at.eps / at.re)).exp() * at.re
    }

    /// The mixture law of [`Fluid::bulk_modulus`] at gauge pressure `p`, for `p_abs > 0`.
    fn mixture<T: Scalar>(&self, p: T) -> T {
        let p_abs = p + P_ATM;
        let e = exp_small(-p / self.beta);
        let a = self.air_fraction * P_ATM;
        p_abs * (e * p_abs + a) / (e * p_abs * p_abs / self.beta + a)
    }

    /// Pressure rate of a volume (Pa/s):
    /// `dp/dt = (q_net - dv_dt) / (V / beta_e(p) + c_wall)` with `V = v0 + c_wall * p`.
    ///
    /// `q_net`: sum of volume flows into the volume (m^3/s); `v0`: volume at 0 bar gauge (m^3);
    /// `dv_dt`: rate of the mechanically driven part of the volume (piston, m^3/s); `c_wall`:
    /// wall compliance `dV/dp` of hoses (m^3/Pa, eq. 5.2), 0 for rigid walls. Taking the volume
    /// at its pressure, `v0 + c_wall * p`, makes the law conserve oil mass exactly: the state
    /// equation `V(p, x) = m * phi(p)` differentiated in time gives this rate with `dm/dt`
    /// equal to `q_net / phi(p)`.
    ///
    /// Below [`P_ABS_MIN`] absolute, the states that an importer's integrator tries and the
    /// physics never reaches, the rate is continued (issue 49): the flow term with the continued
    /// `beta_e`, written `(q_net - dv_dt) beta_e / (V + c_wall beta_e)` (the same number, finite
    /// as `beta_e -> 0`), plus a relaxation back to `P_ABS_MIN`, `d^2 / ((d + P_ABS_MIN) tau)`
    /// with the depth `d = P_ABS_MIN - p_abs` and `tau` = [`TAU_VACUUM`]. Cavitation-consistent:
    /// oil cannot hold a tension, so a pressure below vacuum is a cavity that opens at once (the
    /// flows then change its size, not the pressure: the flow term vanishes with `beta_e`), and
    /// the pressure returns to vacuum. The relaxation starts with zero value and slope (the rate
    /// is continuously differentiable in `p`), grows as `d / tau` for `d >> P_ABS_MIN`, and
    /// dominates the flow term, which is below `|q_net - dv_dt| P_ABS_MIN / V` there, for any
    /// flow a trial state gives: every state has a finite rate, and one below vacuum is pulled
    /// back. Nothing above `P_ABS_MIN` changes. tau = 1 ms is slower than the oil's own pressure
    /// modes (time constants down to microseconds), so the continuation adds no stiffness, and
    /// fast against the motion (periods of 0.3 s). The alternative, Model Exchange answering such
    /// a state with Discard (FMI 2.0, 2.1.3), made fmpy's CVode stop: its right-hand-side
    /// callback takes a Discard for an unrecoverable failure.
    pub fn pressure_rate<T: Scalar>(&self, p: T, q_net: T, v0: T, dv_dt: T, c_wall: f64) -> T {
        let v = v0 + p * c_wall;
        if p.re() + P_ATM >= P_ABS_MIN {
            return (q_net - dv_dt) / (v / self.mixture(p) + c_wall);
        }
        let beta_e = self.bulk_modulus(p);
        let d = -(p + (P_ATM - P_ABS_MIN));
        (q_net - dv_dt) * beta_e / (v + beta_e * c_wall) + d * d / ((d + P_ABS_MIN) * TAU_VACUUM)
    }
}

/// Gauge pressures (Pa) at which docs/models.md states how much the default air softens the oil.
pub const AIR_PRESSURES: [f64; 4] = [45e5, 10e5, 1e5, 0.0];

/// `exp(x)`, by its Taylor polynomial of degree 8 for `|x| <= 1/16` (truncation below
/// `(1/16)^9 / 9! < 1e-16`, under half an ulp of the result, so the result is within an ulp or
/// two of `f64::exp` there), by `f64::exp` elsewhere. The oil's `exp(-p / beta)` only leaves the
/// polynomial's range above 81 MPa, so the pressure rates avoid the libm call (a measurable
/// part of every right-hand side).
fn exp_small<T: Scalar>(x: T) -> T {
    if x.abs() <= 0.0625 {
        const C: [f64; 9] =
            [1.0, 1.0, 1.0 / 2.0, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0, 1.0 / 40320.0];
        C.iter().rev().fold(T::from(0.0), |acc, &c| acc * x + c)
    } else {
        x.exp()
    }
}

/// Line volumes of Fig. 2.8 (section 5.1.1) and the hose compliance (eq. 5.2, Table 5.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lines {
    /// Line 2 (DCV port A to CBV, hose H1), `V_L2` 100 cm^3.
    pub v_l2: f64,
    /// Line 3 (CBV to piston-side chamber, hose H2), `V_L3` 150 cm^3.
    pub v_l3: f64,
    /// Line 4 (rod-side chamber to DCV port B, hoses H1 + H3), `V_L4` 200 cm^3.
    pub v_l4: f64,
    /// Hose compliance per hose volume `C_w / V` (1/Pa), 0.00065 1/bar (eq. 5.2); 0 switches
    /// the hose compliance off (the rigid model of chapter 3).
    pub c_hose: f64,
}

impl Lines {
    /// Wall compliance `C_w = c_hose * V` of a hose of volume `v` (m^3/Pa), eq. 5.2.
    pub fn hose_compliance(&self, v: f64) -> f64 {
        self.c_hose * v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::{bar, lpm, CM3};

    fn fluid() -> Fluid {
        Fluid { beta: 1300e6, air_fraction: 1e-3 }
    }

    /// The polynomial of `exp_small` against `f64::exp` over its range and at the switch:
    /// within 2 ulp (4.5e-16 relative).
    #[test]
    fn exp_small_matches_exp() {
        for i in -2000..=2000 {
            let x = 0.0625 * i as f64 / 2000.0;
            for x in [x, x * (1.0 + 1e-15), x * (1.0 - 1e-15)] {
                let (a, b) = (exp_small(x), x.exp());
                assert!((a - b).abs() <= 4.5e-16 * b, "x = {x}: {a} vs {b}");
            }
        }
        for x in [-1.0_f64, -0.07, 0.07, 3.0] {
            assert_eq!(exp_small(x), x.exp());
        }
    }

    #[test]
    fn bulk_modulus_limits() {
        let f = fluid();
        // Without air the law is the thesis' constant bulk modulus.
        let oil = Fluid { air_fraction: 0.0, ..f };
        for p in [-0.5e5, 0.0, bar(50.0), bar(300.0)] {
            assert!((oil.bulk_modulus(p) / 1300e6 - 1.0).abs() < 1e-12);
        }
        // At high pressure the air is negligible: the air term of 1/beta_e is
        // x0 P_ATM / p_abs^2, relative to 1/beta it is 1.3e9 * 1e-3 * 101325 / p_abs^2.
        let p = bar(100.0);
        let expected_rel = 1300e6 * 1e-3 * P_ATM / (p + P_ATM).powi(2);
        let rel = 1.0 - f.bulk_modulus(p) / 1300e6;
        assert!((rel / expected_rel - 1.0).abs() < 0.02, "{rel} vs {expected_rel}");
        // Near absolute zero beta_e -> p_abs.
        let p_abs = 0.05;
        assert!((f.bulk_modulus(-P_ATM + p_abs) / p_abs - 1.0).abs() < 1e-3);
    }

    /// The model notes (docs/models.md) state the default air's effect at [`AIR_PRESSURES`]:
    /// each number there is `1 - beta_e(p) / beta` of the law, rounded as printed (the sentence once
    /// said 1 % at 10 bar, a tenth of what the law gives).
    #[test]
    fn the_model_notes_state_what_the_air_law_gives() {
        let f = crate::hydraulics::circuit::Circuit::default().fluid;
        let notes = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/models.md")).unwrap();
        let line = notes.lines().find(|l| l.contains("softens the oil by")).expect("the Cavitation note");
        let stated: Vec<f64> = line
            .split("softens the oil by ")
            .nth(1)
            .unwrap()
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .filter_map(|w| w.parse().ok())
            .collect();
        // "a %, b %, c % and d % at 45, 10, 1 and 0 bar": the reductions, then the pressures.
        assert_eq!(stated.len(), 2 * AIR_PRESSURES.len(), "{line}");
        for (k, &p) in AIR_PRESSURES.iter().enumerate() {
            let reduction = 100.0 * (1.0 - f.bulk_modulus(p) / f.beta);
            let printed: f64 =
                if reduction < 10.0 { format!("{reduction:.1}") } else { format!("{reduction:.0}") }.parse().unwrap();
            assert_eq!(stated[k], printed, "at {} bar: the law gives {reduction} %", p / 1e5);
            assert_eq!(stated[AIR_PRESSURES.len() + k], p / 1e5);
        }
        // the comparison with Simscape's default air content, 0.5 %
        let line = notes.lines().find(|l| l.contains("0.5 % would soften it by")).expect("the 0.5 % comparison");
        let stated: f64 = line.split("soften it by ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
        let simscape = Fluid { air_fraction: 5e-3, ..f };
        let reduction = 100.0 * (1.0 - simscape.bulk_modulus(AIR_PRESSURES[0]) / f.beta);
        assert_eq!(stated, format!("{reduction:.1}").parse::<f64>().unwrap(), "the law gives {reduction} %");
    }

    /// The continuation below [`P_ABS_MIN`] (issue 49). Continuously differentiable there: the
    /// bulk modulus and the pressure rate 1e-10 Pa below and at the threshold, value and slope
    /// (dual parts) within 1e-3 relative, the slopes also within the relaxation's own slope there,
    /// below `2 delta / (P_ABS_MIN tau)` = 2e-4 /s at `delta` = 1e-10 Pa (the flow terms' are
    /// 0.06 to 11 /s). Below vacuum, for suction, no flow and inflow
    /// far beyond the circuit's (+-100 l/min, a piston at 1 m/s), the rate is positive (back
    /// towards vacuum), finite and within `d / tau + |q| P_ABS_MIN / V`.
    #[test]
    fn continued_below_vacuum() {
        let f = fluid();
        let (v0, c_wall) = (300.0 * CM3, 0.00065e-5 * 150.0 * CM3);
        let at = P_ABS_MIN - P_ATM;
        let relaxation_slope = 2.0 * 1e-10 / (P_ABS_MIN * TAU_VACUUM);
        let close = |a: Dual64, b: Dual64| {
            (a.re - b.re).abs() <= 1e-3 * a.re.abs()
                && (a.eps - b.eps).abs() <= 1e-3 * a.eps.abs() + relaxation_slope
        };
        let (k, below) = (f.bulk_modulus(Dual64::new(at, 1.0)), f.bulk_modulus(Dual64::new(at - 1e-10, 1.0)));
        assert!(close(k, below), "{k:?} vs {below:?}");
        for q in [-lpm(100.0), -lpm(1.0), 0.0, lpm(1.0), lpm(100.0), 3.3e-3] {
            let rate = |p: Dual64| f.pressure_rate(p, Dual64::from(q), Dual64::from(v0), Dual64::from(0.0), c_wall);
            let (k, below) = (rate(Dual64::new(at, 1.0)), rate(Dual64::new(at - 1e-10, 1.0)));
            if q != 0.0 {
                assert!(close(k, below), "q = {q}: {k:?} vs {below:?}");
            }
            for depth in [1e-3, 1.0, 1e3, 1e5, 1e7] {
                let p = -P_ATM - depth;
                let r = f.pressure_rate(p, q, v0, 0.0, c_wall);
                let bound = (depth + P_ABS_MIN) / TAU_VACUUM + q.abs() * P_ABS_MIN / (v0 + c_wall * p);
                assert!(r > 0.0 && r <= bound, "q = {q}, {depth} Pa below vacuum: {r} (bound {bound})");
            }
        }
    }

    /// Oil mass conservation and the vacuum bound: integrate a volume driven by a prescribed
    /// flow and piston motion (including strong suction) with RK4 and compare the oil mass
    /// `V / phi(p)` with the integral of `q / phi(p)`.
    #[test]
    fn mass_conservation_and_no_vacuum() {
        let f = fluid();
        let lines = Lines { v_l2: 100.0 * CM3, v_l3: 0.0, v_l4: 0.0, c_hose: 0.00065e-5 };
        let c_wall = lines.hose_compliance(lines.v_l2);
        let v0_dead = lines.v_l2;
        let area = 3.3e-3;
        // piston stroke x(t) = 0.05 sin(2 pi t); inflow: 20 l/min, then strong suction of
        // -40 l/min from t = 0.5 s (drains the volume to vacuum), then refill from t = 1.5 s.
        let x = |t: f64| 0.05 * (2.0 * std::f64::consts::PI * t).sin();
        let xdot = |t: f64| 0.05 * 2.0 * std::f64::consts::PI * (2.0 * std::f64::consts::PI * t).cos();
        let q = |t: f64| {
            if t < 0.5 {
                lpm(20.0)
            } else if t < 1.5 {
                -lpm(40.0)
            } else {
                lpm(30.0)
            }
        };
        let vmech = |t: f64| v0_dead + area * (x(t) + 0.1);
        // state: [p, integral of q/phi]
        let rhs = |t: f64, s: [f64; 2]| {
            let dp = f.pressure_rate(s[0], q(t), vmech(t), area * xdot(t), c_wall);
            [dp, q(t) / f.volume_ratio(s[0])]
        };
        let mass = |t: f64, p: f64| (vmech(t) + c_wall * p) / f.volume_ratio(p);
        let (mut t, dt) = (0.0, 1e-6);
        let mut s = [bar(10.0), 0.0];
        let m0 = mass(0.0, s[0]);
        let mut p_min = f64::INFINITY;
        while t < 2.0 - 0.5 * dt {
            let k1 = rhs(t, s);
            let a = |s: [f64; 2], k: [f64; 2], h: f64| [s[0] + h * k[0], s[1] + h * k[1]];
            let k2 = rhs(t + 0.5 * dt, a(s, k1, 0.5 * dt));
            let k3 = rhs(t + 0.5 * dt, a(s, k2, 0.5 * dt));
            let k4 = rhs(t + dt, a(s, k3, dt));
            for i in 0..2 {
                s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += dt;
            p_min = p_min.min(s[0]);
            // mass balance at every step; RK4 with 1 us steps: error far below 1e-9 of the mass
            let err = (mass(t, s[0]) - m0 - s[1]).abs() / m0;
            assert!(err < 1e-9, "mass error {err} at t = {t}");
        }
        // strong suction really reached near-vacuum, but never absolute zero
        assert!(p_min > -P_ATM, "p_min = {p_min}");
        assert!(p_min < -0.9 * P_ATM, "suction too weak for the test: p_min = {p_min}");
    }
}
