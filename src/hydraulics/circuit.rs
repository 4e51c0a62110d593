//! The hydraulic circuit of Fig. 2.8 as an ODE with a mechanical port.
//!
//! Supply -> PCV (Q1) -> line 1 (p1) -> main spool: P->A (Q2) into line 2 (p2) -> CBV (Q3) ->
//! line 3 + piston-side chamber (p3); rod-side chamber + line 4 (p4) -> B->T (Q4) for `u > 0`,
//! mirrored for `u < 0`. The CBV pilot is p4; the compensator senses p2 or p4.
//!
//! States (see [`STATE_NAMES`]): the four pressures, the main spool position and the
//! load-holding valve opening. Line 3 and the piston-side chamber form one volume, as do the
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
use super::solve::bisect;
use super::supply::Supply;

/// Number of continuous states.
pub const N_STATES: usize = 6;
/// Index of p1, compensated pressure in line 1 (Pa).
pub const P1: usize = 0;
/// Index of p2, line 2 between DCV port A and CBV (Pa).
pub const P2: usize = 1;
/// Index of p3, line 3 and piston-side chamber (Pa).
pub const P3: usize = 2;
/// Index of p4, rod-side chamber and line 4, CBV pilot (Pa).
pub const P4: usize = 3;
/// Index of the main spool position `x_v` (m).
pub const X_V: usize = 4;
/// Index of the load-holding valve opening `u_cbv` (-).
pub const U_CBV: usize = 5;
/// Structured names of the states, in state order.
pub const STATE_NAMES: [&str; N_STATES] = ["p1", "p2", "p3", "p4", "valve.x_v", "cbv.u_cbv"];

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
pub struct Eval {
    /// State derivatives.
    pub dx: State,
    /// Flows `[Q1, Q2, Q3, Q4]` (m^3/s) numbered and signed as in the thesis: Q1 supply ->
    /// line 1 (PCV), Q2 valve -> line 2, Q3 line 2 -> line 3 (CBV), Q4 line 4 -> valve.
    pub q: [f64; 4],
    /// Leakages to tank `[Q_LP, Q_LA, Q_LB]` (m^3/s), eq. 2.46-2.48.
    pub q_leak: [f64; 3],
    /// Main spool opening `u` (eq. 2.44).
    pub u: f64,
    /// PCV opening `u_pcv` (eq. 2.49).
    pub u_pcv: f64,
    /// Check valve opening `u_cv` (eq. 2.55).
    pub u_cv: f64,
    /// Static load-holding opening of eq. 2.56 (the input of the lag 2.57).
    pub u_cbv_static: f64,
    /// Load-sensing pressure `p_x` (Pa).
    pub p_x: f64,
    /// Pressure force `F1 - F2` (N), eq. 2.60-2.61.
    pub f_pressure: f64,
    /// Friction `F_fr` (N), with the sign of `v`.
    pub f_friction: f64,
    /// End-stop force (N).
    pub f_stop: f64,
    /// Net force of the cylinder on the mechanics (N, positive extending):
    /// `f_pressure - f_friction + f_stop`.
    pub force: f64,
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
    /// - line 1 (`V_L1`): `Q1 - Q_P - Q_LP`, `Q_P` = Q2 for `u >= 0`, -Q4 for `u < 0`;
    /// - line 2 (`V_L2`): `Q2 - Q3 - Q_LA`;
    /// - line 3 + chamber A (`V_L3 + V_CH1 + A x`): `Q3 - A v` (eq. 2.70);
    /// - chamber B + line 4 (`V_L4 + V_CH2 + mu_c A (s_c - x)`): `mu_c A v - Q4 - Q_LB` (2.71).
    ///
    /// The geometric chamber volumes are kept above 10 % of the dead volume, a guard that only
    /// matters for strokes far outside the end stops.
    pub fn evaluate(&self, s: &State, u_ref: f64, x: f64, v: f64) -> Eval {
        let [p1, p2, p3, p4, x_v, u_cbv] = *s;
        let (p_s, p_t, p_tr) = (self.supply.p_s, self.supply.p_t, self.p_tr);
        let (cyl, fl, ln) = (&self.cylinder, &self.fluid, &self.lines);

        let u = self.dcv.opening(x_v);
        let p_x = Dcv::ls_pressure(u, p2, p4, p_t);
        let u_pcv = self.pcv.opening(p1, p_x);
        let q1 = self.pcv.flow(u_pcv, p_s, p1, p_tr);
        let [q2, q4] = self.dcv.flows(u, p1, p2, p4, p_t, p_tr);
        let q_leak @ [q_lp, q_la, q_lb] = self.dcv.leakages(p1, p2, p4, p_t);
        let u_cv = self.cbv.check_opening(p2, p3);
        let u_cbv_static = self.cbv.holding_opening(p3, p4, p_t);
        let q3 = self.cbv.flow(u_cv, u_cbv, p2, p3, p_tr);
        let q_p = if u >= 0.0 { q2 } else { -q4 };

        let (a, b) = (cyl.area_a(), cyl.area_b());
        let v3 = (ln.v_l3 + cyl.volume_a(x)).max(ln.v_l3 + 0.1 * cyl.v_dead_a);
        let v4 = (ln.v_l4 + cyl.volume_b(x)).max(ln.v_l4 + 0.1 * cyl.v_dead_b);
        let mut dx = [0.0; N_STATES];
        dx[P1] = fl.pressure_rate(p1, q1 - q_p - q_lp, ln.v_l1, 0.0, 0.0);
        dx[P2] = fl.pressure_rate(p2, q2 - q3 - q_la, ln.v_l2, 0.0, ln.hose_compliance(ln.v_l2));
        dx[P3] = fl.pressure_rate(p3, q3, v3, a * v, ln.hose_compliance(ln.v_l3));
        dx[P4] = fl.pressure_rate(p4, -q4 - q_lb, v4, -b * v, ln.hose_compliance(ln.v_l4));
        dx[X_V] = self.dcv.spool_rate(x_v, u_ref);
        dx[U_CBV] = self.cbv.holding_rate(u_cbv, u_cbv_static);

        let f_pressure = cyl.pressure_force(p3, p4);
        let f_friction = self.friction.force(cyl, v, x, p3, p4);
        let f_stop = cyl.end_stop_force(x, v);
        Eval {
            dx,
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
    /// leakage, `Q1(p1) = Q_LP(p1)` (p1 slightly below `p_T + p_pcv + p_fc,pcv`).
    pub fn equilibrium(&self, f_load: f64) -> Result<State, EquilibriumError> {
        let (p_s, p_t) = (self.supply.p_s, self.supply.p_t);
        let cyl = &self.cylinder;
        if f_load < 0.0 {
            return Err(EquilibriumError::TensileLoad);
        }
        let p4 = p_t;
        let p3 = (f_load + p4 * cyl.area_b()) / cyl.area_a();
        if self.cbv.holding_opening(p3, p4, p_t) > 0.0 {
            // largest p3 with a closed valve, eq. 2.56 with u_cbv = 0
            let p3_max = self.cbv.p_set + (1.0 + self.cbv.mu_p) * p_t - self.cbv.mu_p * p4;
            return Err(EquilibriumError::CbvOpens {
                max_load: p3_max * cyl.area_a() - p4 * cyl.area_b(),
            });
        }
        let p1 = bisect(
            |p1| {
                let q1 = self.pcv.flow(self.pcv.opening(p1, p_t), p_s, p1, self.p_tr);
                q1 - self.dcv.leakages(p1, p_t, p_t, p_t)[0]
            },
            p_t,
            p_s,
            1e-12 * p_s,
        );
        let mut s = [0.0; N_STATES];
        s[P1] = p1;
        s[P2] = p_t;
        s[P3] = p3;
        s[P4] = p4;
        Ok(s)
    }
}
