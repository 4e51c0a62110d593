//! The hydraulic circuit of Fig. 2.8 as an ODE with a mechanical port.
//!
//! Supply -> PCV (Q1) -> line 1 (p1) -> main spool: P->A (Q2) into line 2 (p2) -> CBV (Q3) ->
//! line 3 + piston-side chamber (p3); rod-side chamber + line 4 (p4) -> B->T (Q4) for `u > 0`,
//! mirrored for `u < 0`. The CBV pilot is p4; the compensator senses p2 or p4.
//!
//! States (see [`STATE_NAMES`]): the pressures p2..p4, the main spool position and the
//! load-holding valve opening. Line 1 (p1, between compensator and spool) is quasi-static
//! ([`Circuit::line1_pressure`]). Line 3 and the piston-side chamber form one volume, as do the
//! rod-side chamber and line 4: nothing restricts flow between them, and the thesis uses one
//! pressure for each (p3, p4 in eq. 2.69-2.71, the Fig. 3.16 model and the logged rig data). The
//! check valve (2.55) and the PCV (2.49) are static, as in the thesis.
//!
//! The mechanics drive the port with stroke `x` and velocity `v`; the circuit returns the
//! force on the rod. Everything is evaluated on the stack (no allocation).

use super::cbv::Cbv;
use super::cylinder::Cylinder;
use super::dcv::Dcv;
use super::friction::Friction;
use super::line::{Fluid, Lines};
use super::pcv::Pcv;
use super::solve::falling_root;
use super::supply::Supply;
use crate::scalar::{max, Dual64, Scalar};

/// Number of continuous states.
pub const N_STATES: usize = 5;
/// Index of p2, line 2 between DCV port A and CBV (Pa).
pub const P2: usize = 0;
/// Index of p3, line 3 and piston-side chamber (Pa).
pub const P3: usize = 1;
/// Index of p4, rod-side chamber and line 4, CBV pilot (Pa).
pub const P4: usize = 2;
/// Index of the main spool position `x_v` (m).
pub const X_V: usize = 3;
/// Index of the load-holding valve opening `u_cbv` (-).
pub const U_CBV: usize = 4;
/// Structured names of the states, in state order.
pub const STATE_NAMES: [&str; N_STATES] = ["p2", "p3", "p4", "valve.x_v", "cbv.u_cbv"];

/// Circuit state vector, laid out as [`STATE_NAMES`].
pub type State = [f64; N_STATES];

/// All component parameters of the circuit (SI). `Default` gives the thesis values; the
/// parameters are listed with names, units and ranges in [`super::params::PARAMS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circuit {
    pub supply: Supply,
    pub pcv: Pcv,
    pub dcv: Dcv,
    pub cbv: Cbv,
    pub cylinder: Cylinder,
    pub friction: Friction,
    pub fluid: Fluid,
    pub lines: Lines,
    /// Transition pressure of the regularised orifice root (Pa), see
    /// [`super::orifice::reg_sqrt`].
    pub p_tr: f64,
}

/// Everything the circuit computes at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eval<T = f64> {
    /// State derivatives.
    pub dx: [T; N_STATES],
    /// Pressure p1 in line 1 (Pa), quasi-static ([`Circuit::line1_pressure`]).
    pub p1: T,
    /// Flows `[Q1, Q2, Q3, Q4]` (m^3/s) numbered and signed as in the thesis: Q1 supply ->
    /// line 1 (PCV), Q2 valve -> line 2, Q3 line 2 -> line 3 (CBV), Q4 line 4 -> valve.
    pub q: [T; 4],
    /// Leakages to tank `[Q_LP, Q_LA, Q_LB]` (m^3/s), eq. 2.46-2.48.
    pub q_leak: [T; 3],
    /// Main spool opening `u` (eq. 2.44).
    pub u: T,
    /// PCV opening `u_pcv` (eq. 2.49).
    pub u_pcv: T,
    /// Check valve opening `u_cv` (eq. 2.55).
    pub u_cv: T,
    /// Static load-holding opening of eq. 2.56 (the input of the lag 2.57).
    pub u_cbv_static: T,
    /// Load-sensing pressure `p_x` (Pa).
    pub p_x: T,
    /// Pressure force `F1 - F2` (N), eq. 2.60-2.61.
    pub f_pressure: T,
    /// Friction `F_fr` (N), with the sign of `v`.
    pub f_friction: T,
    /// End-stop force (N).
    pub f_stop: T,
    /// Net force of the cylinder on the mechanics (N, positive extending):
    /// `f_pressure - f_friction + f_stop`.
    pub force: T,
}

/// The compensator and the net flow of line 1 at one pressure p1 ([`Circuit::line1`]).
struct Line1<T> {
    u_pcv: T,
    q1: T,
    /// `Q1 - Q_P - Q_LP`, the net flow into line 1.
    net: T,
}

/// Why [`Circuit::equilibrium`] has no static solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EquilibriumError {
    /// The load pulls the rod out (`f_load < 0`); with the rod side drained by leakage only the
    /// end stop could hold it.
    TensileLoad,
    /// The piston pressure needed exceeds the load-holding setting: the CBV opens and the load
    /// sinks. `max_load` is the largest load the closed CBV holds (N).
    CbvOpens { max_load: f64 },
}

impl std::fmt::Display for EquilibriumError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::TensileLoad => write!(f, "a tensile load cannot be held by the closed circuit"),
            Self::CbvOpens { max_load } => {
                write!(f, "load exceeds what the closed CBV holds ({max_load:.0} N)")
            }
        }
    }
}

impl std::error::Error for EquilibriumError {}

impl Circuit {
    /// Evaluates the circuit at state `s` for the operator's spool reference `u_ref` in
    /// [-1, 1] and the rod's stroke `x` (m) and velocity `v` (m/s).
    ///
    /// Pressure rates (continuity, [`Fluid::pressure_rate`]; hose compliance on lines 2-4):
    /// - line 1: quasi-static, `Q1 - Q_P - Q_LP = 0` ([`Circuit::line1_pressure`]);
    /// - line 2 (`V_L2`): `Q2 - Q3 - Q_LA`;
    /// - line 3 + chamber A (`V_L3 + V_CH1 + A x`): `Q3 - A v` (eq. 2.70);
    /// - chamber B + line 4 (`V_L4 + V_CH2 + mu_c A (s_c - x)`): `mu_c A v - Q4 - Q_LB` (2.71).
    ///
    /// The geometric chamber volumes are kept above 10 % of the dead volume, a guard that only
    /// matters for strokes far outside the end stops.
    pub fn evaluate<T: Scalar>(&self, s: &[T; N_STATES], u_ref: T, x: T, v: T) -> Eval<T> {
        let [p2, p3, p4, x_v, u_cbv] = *s;
        let (p_t, p_tr) = (self.supply.p_t, self.p_tr);
        let (cyl, fl, ln) = (&self.cylinder, &self.fluid, &self.lines);

        let u = self.dcv.opening(x_v);
        let p_x = Dcv::ls_pressure(u, p2, p4, p_t);
        let p1 = self.line1_pressure(u, p2, p4, p_x);
        let Line1 { u_pcv, q1, .. } = self.line1(p1, u, p2, p4, p_x);
        let [q2, q4] = self.dcv.flows(u, p1, p2, p4, p_t, p_tr);
        let q_leak @ [_, q_la, q_lb] = self.dcv.leakages(p1, p2, p4, p_t);
        let u_cv = self.cbv.check_opening(p2, p3);
        let u_cbv_static = self.cbv.holding_opening(p3, p4, p_t);
        let q3 = self.cbv.flow(u_cv, u_cbv, p2, p3, p_tr);

        let (a, b) = (cyl.area_a(), cyl.area_b());
        let v3 = max(cyl.volume_a(x) + ln.v_l3, ln.v_l3 + 0.1 * cyl.v_dead_a);
        let v4 = max(cyl.volume_b(x) + ln.v_l4, ln.v_l4 + 0.1 * cyl.v_dead_b);
        let (zero, mut dx) = (T::from(0.0), [T::from(0.0); N_STATES]);
        dx[P2] = fl.pressure_rate(p2, q2 - q3 - q_la, T::from(ln.v_l2), zero, ln.hose_compliance(ln.v_l2));
        dx[P3] = fl.pressure_rate(p3, q3, v3, v * a, ln.hose_compliance(ln.v_l3));
        dx[P4] = fl.pressure_rate(p4, -q4 - q_lb, v4, v * (-b), ln.hose_compliance(ln.v_l4));
        dx[X_V] = self.dcv.spool_rate(x_v, u_ref);
        dx[U_CBV] = self.cbv.holding_rate(u_cbv, u_cbv_static);

        let f_pressure = cyl.pressure_force(p3, p4);
        let f_friction = self.friction.force(cyl, v, x, p3, p4);
        let f_stop = cyl.end_stop_force(x, v);
        Eval {
            dx,
            p1,
            q: [q1, q2, q3, q4],
            q_leak,
            u,
            u_pcv,
            u_cv,
            u_cbv_static,
            p_x,
            f_pressure,
            f_friction,
            f_stop,
            force: f_pressure - f_friction + f_stop,
        }
    }

    /// The flows of line 1 at pressure `p1`: the compensator's (eq. 2.49, 2.50), the spool's
    /// ([`Dcv::p_flow`]) and the P-port leakage (eq. 2.48).
    fn line1<S: Scalar>(&self, p1: S, u: S, p2: S, p4: S, p_x: S) -> Line1<S> {
        let u_pcv = self.pcv.opening(p1, p_x);
        let q1 = self.pcv.flow(u_pcv, self.supply.p_s, p1, self.p_tr);
        let q_p = self.dcv.p_flow(u, p1, p2, p4, self.p_tr);
        Line1 { u_pcv, q1, net: q1 - q_p - self.dcv.leakages(p1, p2, p4, self.supply.p_t)[0] }
    }

    /// Pressure p1 of line 1, quasi-static: the root of its continuity, `Q1 - Q_P - Q_LP = 0`.
    ///
    /// Deviation from the thesis, which integrates line 1's continuity over `V_L1` = 2 cm^3
    /// (parameter list; section 2.2.1's compensator and eq. 2.48 as here): that volume behind a
    /// compensator whose opening swings fully over `p_fc,pcv` = 1 bar is a pressure mode of
    /// time constant `V_L1 / (beta |d(net flow)/dp1|)`, 1e-8 s while the compensator regulates
    /// and below 1e-5 s through an open spool (`tests::line1_is_a_fast_mode`), three to five
    /// decades faster than anything the thesis measures; only with spool and compensator both
    /// closed does it leak down over 37 ms, 0.03 cm^3 of compressed oil that the spool's next
    /// opening passes in microseconds. Integrated, it made BDF integrators at importers'
    /// tolerances (CVode, rtol 1e-4) overshoot p1 by thousands of bar through the compensator's
    /// kinks (docs/interfaces.md's tolerance table); its quasi-static limit is the same circuit without
    /// that mode, and `line.v_l1` is no parameter any more.
    ///
    /// The root is unique: the net flow falls with p1 (the compensator closes and its drop
    /// shrinks, the spool and the leakage pass more) except where the compensator closes on
    /// reverse flow (p1 above both p_s and p_x + p_pcv), and there every flow leaves line 1. It
    /// is bracketed by the lowest of p_T, p2, p4 (everything flows in) and the highest of p_s,
    /// p2, p4, p_x + p_pcv + p_fc,pcv (everything flows out), and found by Newton's method
    /// safeguarded by bisection ([`falling_root`]). Dual parts (exact Jacobians) follow from the implicit function
    /// theorem.
    pub fn line1_pressure<T: Scalar>(&self, u: T, p2: T, p4: T, p_x: T) -> T {
        let (u_re, p2_re, p4_re, p_x_re) = (u.re(), p2.re(), p4.re(), p_x.re());
        let net = |p1: f64| {
            let c = Dual64::from;
            let n = self.line1(Dual64::new(p1, 1.0), c(u_re), c(p2_re), c(p4_re), c(p_x_re)).net;
            (n.re, n.eps)
        };
        let (p_s, p_t) = (self.supply.p_s, self.supply.p_t);
        let lo = p_t.min(p2_re).min(p4_re);
        let hi = p_s.max(p2_re).max(p4_re).max(p_x_re + self.pcv.p_spring + self.pcv.p_fc);
        // Start where the compensator passes what leaves line 1 at its closing pressure `top`,
        // its opening falling linearly over p_fc (eq. 2.49): the root while it regulates, to the
        // little that the spool's flow changes over p_fc.
        let top = (p_x_re + self.pcv.p_spring + self.pcv.p_fc).clamp(lo, hi);
        let leaving = -self.line1(top, u_re, p2_re, p4_re, p_x_re).net;
        let open = self.pcv.flow(1.0, p_s, top, self.p_tr);
        let (p1, hi) = if leaving > 0.0 && open > 0.0 {
            ((top - self.pcv.p_fc * (leaving / open).min(1.0)).max(lo), top)
        } else {
            (top, hi)
        };
        // Newton's next step below 1e-10 of p_s (2 mPa; the step that the dual correction below
        // takes then leaves an error of order (2 mPa)^2 |g''/g'|, far below round-off), or the
        // bracket within 4 ulp of p_s.
        let (p1, g, dg) = falling_root(net, lo, hi, p1, 1e-10 * p_s, 4.0 * f64::EPSILON * p_s);
        if dg >= 0.0 {
            return T::from(p1);
        }
        // The last Newton step; with dual numbers, its dual part is the implicit derivative
        // -(d net / d(u, p2, p4, p_x)) / (d net / d p1). A number without one (f64) has it
        // already: the real parts of the evaluation below are g, bit for bit.
        if T::NDERIV == 0 {
            return T::from(p1 - g / dg);
        }
        let p1 = T::from(p1);
        p1 - self.line1(p1, u, p2, p4, p_x).net / dg
    }

    /// State derivatives only, see [`Circuit::evaluate`].
    pub fn derivatives(&self, s: &State, u_ref: f64, x: f64, v: f64) -> State {
        self.evaluate(s, u_ref, x, v).dx
    }

    /// Static equilibrium with the spool in neutral (`u_ref = 0`), the rod at rest and the load
    /// `f_load` (N, compressive, i.e. the force the load pushes the rod in with) held by the
    /// closed CBV, so a simulation started there has no start-up transient.
    ///
    /// The leakages of eq. 2.46-2.47 drain lines 2 and 4 to tank (`p2 = p4 = p_T`); the piston
    /// side carries the load, `p3 = (f_load + p4 mu_c A) / A` (friction is zero at rest); the
    /// compensator, sensing tank in neutral, throttles the supply until it just feeds the P-port
    /// leakage, `Q1(p1) = Q_LP(p1)` (p1 slightly below `p_T + p_pcv + p_fc,pcv`; line 1 is
    /// quasi-static, so any state has it).
    ///
    /// `p4_trapped`: a rod side pre-charged above tank instead (the rig's runs started from
    /// such pressures, thesis section 6.2 and chapter 8). The balance is the same; only the
    /// rod side's leakage to tank is left, `dp4/dt = -dQ_L (p4 - p_T) / C4`, a drift of about a
    /// minute's time constant.
    pub fn equilibrium(&self, f_load: f64, p4_trapped: Option<f64>) -> Result<State, EquilibriumError> {
        let p_t = self.supply.p_t;
        let cyl = &self.cylinder;
        if f_load < 0.0 {
            return Err(EquilibriumError::TensileLoad);
        }
        let p4 = p4_trapped.unwrap_or(p_t);
        let p3 = (f_load + p4 * cyl.area_b()) / cyl.area_a();
        if self.cbv.holding_opening(p3, p4, p_t) > 0.0 {
            // largest p3 with a closed valve, eq. 2.56 with u_cbv = 0
            let p3_max = self.cbv.p_set + (1.0 + self.cbv.mu_p) * p_t - self.cbv.mu_p * p4;
            return Err(EquilibriumError::CbvOpens { max_load: p3_max * cyl.area_a() - p4 * cyl.area_b() });
        }
        let mut s = [0.0; N_STATES];
        s[P2] = p_t;
        s[P3] = p3;
        s[P4] = p4;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::{bar, lpm, LPM, P_ATM};
    use nalgebra::{SMatrix, SVector};

    /// The equilibrium state is stationary: the pressure rates vanish, line 1 balances (its
    /// quasi-static p1 is a root to 4 ulp of p_s, 2e-8 Pa, where the compensator's slope of
    /// 1e-7 m^3/(s Pa) leaves 2e-15 m^3/s of the 3e-8 m^3/s P-port leakage: 1e-6 relative
    /// allows for that), the spool and the CBV stay closed and the cylinder force equals the load.
    #[test]
    fn equilibrium_is_stationary() {
        let c = Circuit::default();
        for f_load in [0.0, 10e3, 30e3, 60e3] {
            let s = c.equilibrium(f_load, None).unwrap();
            let e = c.evaluate(&s, 0.0, 0.25, 0.0);
            assert!((s[P3] - f_load / c.cylinder.area_a()).abs() < 1e-6);
            assert_eq!(e.dx[P2], 0.0);
            assert_eq!(e.dx[P3], 0.0);
            assert_eq!(e.dx[P4], 0.0);
            assert_eq!(e.dx[X_V], 0.0);
            assert_eq!(e.dx[U_CBV], 0.0);
            assert!((e.q[0] - e.q_leak[0]).abs() < 1e-6 * e.q_leak[0]);
            assert_eq!(e.force, f_load);
            // p1 just below p_T + p_pcv + p_fc,pcv where the compensator closes
            assert!(e.p1 < bar(8.0) && e.p1 > bar(7.99));
        }
        // p_set 210 bar on the piston holds 69.7 kN at most
        let max = c.cylinder.area_a() * bar(210.0);
        assert!(
            matches!(c.equilibrium(max + 1.0, None), Err(EquilibriumError::CbvOpens { max_load }) if (max_load - max).abs() < 1e-6)
        );
        assert_eq!(c.equilibrium(-1.0, None), Err(EquilibriumError::TensileLoad));
    }

    /// A rod side trapped at 10 bar: p3 carries the load on top of it (eq. 2.85,
    /// p3 = p4 mu_c + F / A); everything is at rest except the rod side's leakage to tank,
    /// dp4/dt = -dQ_L (p4 - p_T) / (V4 / beta_e(p4) + C_w4) (eq. 2.47 into the line's
    /// continuity equation, V4 at its pressure), to 1e-12 relative.
    #[test]
    fn a_trapped_rod_side_only_leaks() {
        let c = Circuit::default();
        let (f_load, p4, x) = (30e3, bar(10.0), 0.25);
        let s = c.equilibrium(f_load, Some(p4)).unwrap();
        let cyl = &c.cylinder;
        let mu_c = cyl.area_b() / cyl.area_a();
        assert!((s[P3] - (p4 * mu_c + f_load / cyl.area_a())).abs() < 1e-9 * s[P3]);
        assert_eq!(s[P4], p4);
        let e = c.evaluate(&s, 0.0, x, 0.0);
        assert_eq!((e.dx[P3], e.dx[X_V], e.dx[U_CBV]), (0.0, 0.0, 0.0));
        assert_eq!(e.force, f_load);
        let v4 = c.lines.v_l4 + cyl.volume_b(x);
        let leak = c.dcv.dq_leak * (p4 - c.supply.p_t);
        // The hose's volume at its pressure, V = V4 + C_w p (eq. 5.2), as Fluid::pressure_rate.
        let c_w = c.lines.hose_compliance(c.lines.v_l4);
        let expected = -leak / ((v4 + c_w * p4) / c.fluid.bulk_modulus(p4) + c_w);
        assert!((e.dx[P4] / expected - 1.0).abs() < 1e-12, "{} vs {expected}", e.dx[P4]);
        // The time constant of that drift: about a minute (docs/models.md, "Pre-charged starts").
        let tau = -(p4 - c.supply.p_t) / e.dx[P4];
        assert!((20.0..200.0).contains(&tau), "{tau} s");
    }

    /// Steady motion of the whole circuit for a constant load `f_load` and spool reference
    /// `u`: solves dp2..dp4 = 0 (with u_cbv at its static opening; line 1 is quasi-static) and
    /// force = f_load for (p2, p3, p4, v) by Newton's method with a difference Jacobian and
    /// backtracking. Unknowns in bar and mm/s; residuals are the net volume flows (l/min) and the
    /// force imbalance (kN).
    fn steady_motion(c: &Circuit, u: f64, f_load: f64, x: f64) -> (State, f64) {
        let cyl = &c.cylinder;
        let (a, b) = (cyl.area_a(), cyl.area_b());
        let k1u = c.dcv.k1() * u;
        let volumes = [c.lines.v_l2, c.lines.v_l3 + cyl.volume_a(x), c.lines.v_l4 + cyl.volume_b(x)];
        let state_of = |z: &SVector<f64, 4>| {
            let mut s = [0.0; N_STATES];
            for i in 0..3 {
                s[P2 + i] = z[i] * 1e5;
            }
            s[X_V] = c.dcv.spool_reference(u);
            s[U_CBV] = c.cbv.holding_opening(s[P3], s[P4], c.supply.p_t);
            s
        };
        let residual = |z: &SVector<f64, 4>| {
            let s = state_of(z);
            let e = c.evaluate(&s, u, x, z[3] * 1e-3);
            let mut r = SVector::<f64, 4>::zeros();
            for i in 0..3 {
                r[i] = e.dx[P2 + i] * volumes[i] / c.fluid.beta / LPM;
            }
            r[3] = (e.force - f_load) * 1e-3;
            r
        };
        // initial guess: ideal compensated flow through the spool, orifice laws inverted
        let v = 1.017 * u * c.dcv.q_rated / if u > 0.0 { a } else { b };
        let f_fr = (v.signum()) * (a * c.friction.p_static + c.friction.c_p_bak * f_load);
        let mut z = if u > 0.0 {
            let p4 = (b * v / k1u).powi(2);
            let p3 = (f_load + f_fr + p4 * b) / a;
            let p2 = p3 + c.cbv.p_cv + bar(0.1);
            SVector::<f64, 4>::new(p2 / 1e5, p3 / 1e5, p4 / 1e5, v * 1e3)
        } else {
            let p2 = (a * v / k1u).powi(2);
            let u_cbv = (a * v).abs() / (c.cbv.k2() * bar(100.0).sqrt());
            // mu_p p4 + p3 = p_set + p_fo u_cbv and p3 A - p4 B = F + F_fr
            let rhs = c.cbv.p_set + c.cbv.p_fo_cbv * u_cbv;
            let p4 = (rhs * a - f_load - f_fr) / (c.cbv.mu_p * a + b);
            let p3 = rhs - c.cbv.mu_p * p4;
            SVector::<f64, 4>::new(p2 / 1e5, p3 / 1e5, p4 / 1e5, v * 1e3)
        };
        let mut r = residual(&z);
        for _ in 0..100 {
            if r.norm() < 1e-10 {
                return (state_of(&z), z[3] * 1e-3);
            }
            let mut j = SMatrix::<f64, 4, 4>::zeros();
            for k in 0..4 {
                let h = 1e-7 * z[k].abs().max(1e-3);
                let mut zp = z;
                zp[k] += h;
                j.set_column(k, &((residual(&zp) - r) / h));
            }
            let dz = j.lu().solve(&(-r)).expect("singular Jacobian");
            let mut step = 1.0;
            loop {
                let zn = z + dz * step;
                let rn = residual(&zn);
                if rn.norm() < r.norm() || step < 1e-6 {
                    z = zn;
                    r = rn;
                    break;
                }
                step *= 0.5;
            }
        }
        panic!("steady motion did not converge for u = {u}, F = {f_load}: {z:?}, {r:?}");
    }

    /// Load independence of the pressure-compensated flow in the complete circuit (with CBV,
    /// leakage and friction): lifting (u > 0, flow into port A) and lowering through the CBV
    /// (u < 0, flow into port B) at several loads. Expected: Q = u * 25 l/min times
    /// `sqrt(dp_dcv / 7.72 bar)`, where the compensator keeps dp_dcv within its spring band
    /// [7, 8] bar; the loads vary dp_dcv by less than p_fc * u_pcv <= 0.1 bar (u_pcv <= 0.1 when
    /// the PCV drops >= 40 bar at <= 25.5 l/min), i.e. < 0.7 % of the flow.
    #[test]
    fn compensated_flow_in_circuit() {
        let c = Circuit::default();
        let lo = (bar(7.0) / c.dcv.dp_rated).sqrt();
        let hi = (bar(8.0) / c.dcv.dp_rated).sqrt();
        for u in [0.05, 0.1, 0.5, -0.05, -0.1, -0.5] {
            let mut ratios = Vec::new();
            for f_load in [5e3, 15e3, 30e3, 45e3] {
                let (s, v) = steady_motion(&c, u, f_load, 0.25);
                let e = c.evaluate(&s, u, 0.25, v);
                let q_dcv = if u > 0.0 { e.q[1] } else { e.q[3] };
                let ratio = q_dcv / (u * lpm(25.0));
                println!(
                    "u {u:5}, F {:4.0} kN: Q = {:7.4} l/min (ratio {ratio:.5}), v = {:8.3} mm/s, \
                     p1..p4 = {:6.1} {:6.1} {:6.1} {:6.1} bar, u_cbv = {:.4}",
                    f_load / 1e3,
                    q_dcv / LPM,
                    v * 1e3,
                    e.p1 / 1e5,
                    s[P2] / 1e5,
                    s[P3] / 1e5,
                    s[P4] / 1e5,
                    s[U_CBV]
                );
                assert!(ratio > lo && ratio < hi, "u {u}, F {f_load}: ratio {ratio}");
                assert!(c.supply.p_s - e.p1 >= bar(40.0));
                ratios.push(ratio);
            }
            let spread =
                ratios.iter().cloned().fold(f64::MIN, f64::max) - ratios.iter().cloned().fold(f64::MAX, f64::min);
            assert!(spread < 0.007, "u {u}: load dependence {spread}");
        }
    }

    /// Strong suction on the piston side (spool closed, CBV closed, rod pulled out fast):
    /// near absolute zero the pressure rate is proportional to the absolute pressure, so the
    /// pressure decays towards vacuum without reaching it; every output stays finite for
    /// states far outside the physical range.
    #[test]
    fn suction_and_robustness() {
        let c = Circuit::default();
        let mut s = c.equilibrium(0.0, None).unwrap();
        let (x, v) = (0.25, 0.5);
        let v3 = c.lines.v_l3 + c.cylinder.volume_a(x);
        for p_abs in [1e3, 10.0, 1.0, 0.1] {
            s[P3] = -P_ATM + p_abs;
            let e = c.evaluate(&s, 0.0, x, v);
            assert!(e.dx[P3] < 0.0);
            // beta_e <= p_abs (1 + p_abs / a), a = x0 P_ATM, so |dp/dt| <= beta_e A v / V -> 0
            // with p_abs (1e-3 margin: the hose volume at vacuum is 1e-4 smaller than at 0 bar)
            let beta_bound = p_abs * (1.0 + p_abs / (c.fluid.air_fraction * P_ATM));
            let bound = 1.001 * beta_bound * c.cylinder.area_a() * v / v3;
            assert!(-e.dx[P3] <= bound, "p_abs {p_abs}: {}", e.dx[P3]);
        }
        for p in [-1e7, -P_ATM, 0.0, 1e9] {
            for xv in [-1.0, 0.0, 1.0] {
                for (x, v) in [(-1.0, -10.0), (0.25, 0.0), (2.0, 10.0)] {
                    let s = [p, p, p, xv, 2.0];
                    for u_ref in [-5.0, 0.0, 5.0] {
                        let e = c.evaluate(&s, u_ref, x, v);
                        assert!(e.dx.iter().all(|d| d.is_finite()), "{s:?} {x} {v}");
                        assert!(e.force.is_finite() && e.p1.is_finite() && e.q.iter().all(|q| q.is_finite()));
                    }
                }
            }
        }
    }

    /// States across the spool's range (closed, partly and fully open both ways) and the
    /// pressures of lowering and lifting, with the load-sensing pressure they give.
    fn line1_cases(c: &Circuit) -> Vec<[f64; N_STATES]> {
        let mut cases = Vec::new();
        for x_v in [0.0, 1.5e-3, -1.5e-3, 3e-3, -3e-3, 7e-3, -7e-3] {
            // lowering, lifting, a high load, and the rod side above the supply pressure (a rod
            // driven in: the compensator passes oil back to the supply, line 1's root at p_s)
            for (p2, p3, p4) in
                [(0.0, 70.0, 0.0), (1.0, 100.0, 40.0), (80.0, 75.0, 2.0), (3.0, 230.0, 180.0), (0.6, 0.6, 201.3)]
            {
                cases.push([bar(p2), bar(p3), bar(p4), x_v, 0.3]);
            }
        }
        cases.push(c.equilibrium(30e3, None).unwrap());
        cases
    }

    /// Line 1 balances at every state: Q1 = Q_P + Q_LP (its continuity, eq. 2.48-2.50 with the
    /// spool's P flow of eq. 2.45) to round-off of the flows through it (1e-9 of their sum: the
    /// root is found to 4 ulp of p_s, and the compensator's slope turns that into 1e-15 m^3/s),
    /// and the dual part of p1 is the implicit derivative dp1/dp4, checked against a central
    /// difference (1 Pa steps on a quadratic: 1e-6 relative) where the compensator regulates.
    #[test]
    fn line1_balances_with_exact_derivatives() {
        let c = Circuit::default();
        for s in line1_cases(&c) {
            let e = c.evaluate(&s, 0.0, 0.25, 0.0);
            let q_p = if e.u >= 0.0 { e.q[1] } else { -e.q[3] };
            let flows = e.q[0].abs() + q_p.abs() + e.q_leak[0].abs();
            assert!((e.q[0] - q_p - e.q_leak[0]).abs() <= 1e-9 * flows, "{s:?}: p1 {}", e.p1);
            if e.u_pcv > 0.01 && e.u_pcv < 0.99 {
                let dual: [Dual64; N_STATES] =
                    std::array::from_fn(|k| Dual64::new(s[k], if k == P4 { 1.0 } else { 0.0 }));
                let d = Dual64::from;
                let exact = c.evaluate(&dual, d(0.0), d(0.25), d(0.0)).p1.eps;
                let p1_at = |dp4: f64| {
                    let mut t = s;
                    t[P4] += dp4;
                    c.evaluate(&t, 0.0, 0.25, 0.0).p1
                };
                let central = (p1_at(1.0) - p1_at(-1.0)) / 2.0;
                assert!((exact - central).abs() <= 1e-6 * central.abs().max(1.0), "{s:?}: {exact} vs {central}");
            }
        }
    }

    /// Why line 1 may be quasi-static: integrated over the thesis' V_L1 = 2 cm^3, its pressure
    /// relaxes with time constant V_L1 / (beta_e(p1) |d(Q1 - Q_P - Q_LP)/dp1|), below 10 us at
    /// every state above where the spool or the compensator is open, and 1e-8 s while the
    /// compensator regulates. Only with both closed (the spool in its dead band, p1 above the
    /// compensator's closing pressure) is it slower, 37 ms of P-port leakage (V_L1 / (beta
    /// dQ_L)), which quasi-statically is instantaneous: 0.03 cm^3 of oil compressed by 180 bar.
    #[test]
    fn line1_is_a_fast_mode() {
        // V_L1, volume between compensator and main spool (the thesis' parameter list)
        const V_L1: f64 = 2.0 * crate::units::CM3;
        let c = Circuit::default();
        let tau = |s: &[f64; N_STATES], p1: f64| {
            let u = c.dcv.opening(s[X_V]);
            let p_x = Dcv::ls_pressure(u, s[P2], s[P4], c.supply.p_t);
            let d = Dual64::from;
            let net = c.line1(Dual64::new(p1, 1.0), d(u), d(s[P2]), d(s[P4]), d(p_x)).net;
            (V_L1 / c.fluid.bulk_modulus(p1) / -net.eps, c.pcv.opening(p1, p_x))
        };
        for s in line1_cases(&c) {
            let e = c.evaluate(&s, 0.0, 0.25, 0.0);
            let (t, u_pcv) = tau(&s, e.p1);
            if e.u != 0.0 || u_pcv > 0.0 {
                assert!(t < 1e-5, "{s:?}: {t} s");
            }
            if u_pcv > 0.0 && u_pcv < 1.0 {
                assert!(t < 1e-7, "{s:?}: {t} s");
            }
        }
        let closed = [0.0, bar(70.0), 0.0, 0.0, 0.0];
        let (t, u_pcv) = tau(&closed, bar(180.0));
        assert_eq!(u_pcv, 0.0);
        assert!((t - V_L1 / (c.fluid.bulk_modulus(bar(180.0)) * c.dcv.dq_leak)).abs() < 1e-9 * t);
        assert!((0.030..0.045).contains(&t), "{t} s");
        let compressed = V_L1 * bar(180.0) / c.fluid.bulk_modulus(bar(180.0));
        assert!((0.02e-6..0.04e-6).contains(&compressed), "{compressed} m^3");
    }
}
