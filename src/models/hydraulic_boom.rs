//! The HydraulicBoom FMU model: the circuit of thesis Fig. 2.8 ([`crate::hydraulics::circuit`])
//! driving the boom, rigid (sections 2.1.1-2.1.2, [`crate::mechanics::rigid_boom`]) or lumped
//! flexible (2.1.4, 3.1.2, [`crate::mechanics::flexible_boom`]), advanced inside fmi2DoStep by
//! the stiff Radau IIA integrator ([`crate::solver`]).
//!
//! States: the circuit's six (p1..p4, spool position, load-holding opening), then the boom's
//! generalised coordinates q and velocities q_dot (rigid: the stroke; flexible: the absolute
//! angle of each section). The operator's reference `valve.u_ref` is held over each step.

use super::parts::{self, out, TableBuilder, CIRCUIT_SCALE, FLEXIBLE_SWITCH, N_BOOM_ROWS, START_STROKE, TIP_DEFLECTION};
pub use super::parts::Boom;
use crate::fmi2::{Log, Model, ModelInfo, StepError, Values, Variable};
use crate::hydraulics::circuit::{self, Circuit, N_STATES as N_CIRCUIT};
use crate::hydraulics::params::PARAMS;
use crate::solver::{OdeSystem, Radau5};

/// Value references (stable across releases: append, never renumber).
pub mod vr {
    pub const U_REF: u32 = 0;
    pub const P1: u32 = 1;
    pub const P2: u32 = 2;
    pub const P3: u32 = 3;
    pub const P4: u32 = 4;
    pub const U: u32 = 5;
    pub const U_CV: u32 = 6;
    pub const U_CBV: u32 = 7;
    pub const Q1: u32 = 8;
    pub const Q2: u32 = 9;
    pub const Q3: u32 = 10;
    pub const Q4: u32 = 11;
    pub const X: u32 = 12;
    pub const V: u32 = 13;
    pub const F: u32 = 14;
    pub const F_FR: u32 = 15;
    pub const THETA: u32 = 16;
    pub const OMEGA: u32 = 17;
    pub const PAYLOAD_X: u32 = 18;
    pub const PAYLOAD_Y: u32 = 19;
    pub const X_V: u32 = 20;
    pub const U_PCV: u32 = 21;
    pub const P_X: u32 = 22;
    pub const SOLVER_STEPS: u32 = 23;
    pub const SOLVER_REJECTED: u32 = 24;
    pub const SOLVER_RHS: u32 = 25;
    pub const SOLVER_JACOBIANS: u32 = 26;
    pub use crate::models::parts::vr::*;
}

#[rustfmt::skip]
const OWN: [Variable; 30] = [
    Variable::real_input("valve.u_ref", vr::U_REF, 0.0, "1", "%", (-1.0, 1.0),
        "Operator's spool reference; > 0 lifts (P->A), < 0 lowers through the CBV"),
    out("p1", vr::P1, "Pa", "bar", "Compensated pressure after the PCV (line 1)"),
    out("p2", vr::P2, "Pa", "bar", "Line 2 pressure, DCV port A to CBV"),
    out("p3", vr::P3, "Pa", "bar", "Piston-side chamber pressure (line 3)"),
    out("p4", vr::P4, "Pa", "bar", "Rod-side chamber pressure (line 4, CBV pilot)"),
    out("valve.u", vr::U, "1", "%", "Main spool opening u (eq. 2.44)"),
    out("cbv.u_cv", vr::U_CV, "1", "%", "Check valve opening (eq. 2.55)"),
    out("cbv.u_cbv", vr::U_CBV, "1", "%", "Load-holding valve opening (eq. 2.56, 2.57)"),
    out("Q1", vr::Q1, "m3/s", "l/min", "PCV flow, supply to line 1 (eq. 2.50)"),
    out("Q2", vr::Q2, "m3/s", "l/min", "DCV flow into line 2, P->A / A->T (eq. 2.40, 2.42)"),
    out("Q3", vr::Q3, "m3/s", "l/min", "CBV flow, line 2 to line 3 (eq. 2.58, 2.59)"),
    out("Q4", vr::Q4, "m3/s", "l/min", "DCV flow out of line 4, B->T / P->B (eq. 2.41, 2.43)"),
    out("cylinder.x", vr::X, "m", "mm", "Cylinder stroke"),
    out("cylinder.v", vr::V, "m/s", "mm/s", "Cylinder velocity, > 0 extending"),
    out("cylinder.F", vr::F, "N", "kN", "Force on the rod: pressure forces - friction + end stops"),
    out("cylinder.F_fr", vr::F_FR, "N", "kN", "Friction force, with the sign of the velocity"),
    out("boom.theta", vr::THETA, "rad", "deg", "Boom angle theta2 to the horizontal, > 0 up"),
    out("boom.omega", vr::OMEGA, "rad/s", "deg/s", "Boom angular velocity"),
    out("payload.x", vr::PAYLOAD_X, "m", "mm", "Payload mass centre, horizontal, from the lower cylinder pin"),
    out("payload.y", vr::PAYLOAD_Y, "m", "mm", "Payload mass centre, vertical, from the lower cylinder pin"),
    Variable::real_local("valve.x_v", vr::X_V, "m", "mm", "Main spool position (state of eq. 2.45)"),
    Variable::real_local("pcv.u", vr::U_PCV, "1", "%", "Pressure compensator opening (eq. 2.49)"),
    Variable::real_local("valve.p_x", vr::P_X, "Pa", "bar", "Load-sensing pressure p_x"),
    Variable::real_local("solver.steps", vr::SOLVER_STEPS, "1", "", "Accepted integrator steps since initialisation"),
    Variable::real_local("solver.rejected_steps", vr::SOLVER_REJECTED, "1", "", "Rejected integrator steps"),
    Variable::real_local("solver.rhs_evals", vr::SOLVER_RHS, "1", "", "Right-hand-side evaluations"),
    Variable::real_local("solver.jacobian_evals", vr::SOLVER_JACOBIANS, "1", "", "Jacobian evaluations"),
    Variable::param(vr::X0, START_STROKE).fixed(),
    FLEXIBLE_SWITCH,
    TIP_DEFLECTION,
];

const N_VARS: usize = OWN.len() + PARAMS.len() + N_BOOM_ROWS;

/// The table: own variables, the section angles, then every hydraulic, boom and beam parameter
/// (fixed: set them before initialisation ends).
const TABLE: [Variable; N_VARS] =
    TableBuilder::new(&OWN).sections().hydraulics(PARAMS, 0, PARAMS.len()).boom_params().build();

const DOCUMENTATION: &str = r#"<p>The circuit of thesis Fig. 2.8: supply, pressure compensator (eq. 2.49, 2.50),
PVG32 main spool with dead band and first-order dynamics (eq. 2.40-2.48), counterbalance valve with check valve and
piloted load-holding valve (eq. 2.55-2.59), asymmetric cylinder with end stops and friction (eq. 2.60-2.65), line
volumes with hose compliance (eq. 5.2) and entrained air near vacuum; driving the rigid boom of sections 2.1.1-2.1.2
(kinematics eq. 2.1-2.15, kinetics eq. 2.16-2.19) as one degree of freedom in the cylinder stroke. A stiff Radau IIA
(order 5) integrator advances the eight states inside fmi2DoStep with the tolerance of fmi2SetupExperiment.</p>
<p>The simulation starts at rest at <code>start.x</code> with the load held by the closed CBV and all pressures in
static equilibrium, so a closed spool gives no start-up transient. Outputs do not depend directly on the input (the
spool has dynamics), so the FMU can be coupled to a controller without an algebraic loop.</p>"#;

/// Circuit + boom as one ODE, with the operator's reference held.
#[derive(Debug, Clone)]
pub struct Plant {
    pub circuit: Circuit,
    pub boom: Boom,
    pub u_ref: f64,
}

impl OdeSystem for Plant {
    fn dim(&self) -> usize {
        N_CIRCUIT + 2 * self.boom.mechanics().dof()
    }

    fn rhs(&self, _t: f64, s: &[f64], dx: &mut [f64]) {
        let b = self.boom.mechanics();
        let (c, boom) = s.split_at(N_CIRCUIT);
        let (q, qd) = boom.split_at(b.dof());
        let c: &circuit::State = c.try_into().expect("circuit slice");
        let e = self.circuit.evaluate(c, self.u_ref, b.stroke(q), b.stroke_rate(q, qd));
        let (dc, dboom) = dx.split_at_mut(N_CIRCUIT);
        dc.copy_from_slice(&e.dx);
        let (dq, dqd) = dboom.split_at_mut(b.dof());
        dq.copy_from_slice(qd);
        b.accelerations(q, qd, e.force, dqd);
    }
}

impl Plant {
    /// The plant from the FMU's parameter values; refuses inconsistent combinations.
    pub fn from_values(values: &Values) -> Result<Self, String> {
        let circuit = parts::circuit_from_values(values)?;
        let boom = Boom::from_values(values, circuit.cylinder.stroke)?;
        Ok(Plant { circuit, boom, u_ref: values.real(vr::U_REF) })
    }

    /// Static equilibrium at stroke `x0`: the load held at rest by the closed CBV.
    pub fn equilibrium(&self, x0: f64) -> Result<Vec<f64>, String> {
        let stroke = self.circuit.cylinder.stroke;
        if !(0.0..=stroke).contains(&x0) {
            return Err(format!("start.x = {x0} is outside the stroke [0, {stroke}] m (cylinder.stroke)"));
        }
        let b = self.boom.mechanics();
        let rest = b.equilibrium(x0).map_err(|e| format!("no boom equilibrium at start.x = {x0} m: {e}"))?;
        let c = self.circuit.equilibrium(rest.f_cyl).map_err(|e| {
            format!(
                "no static equilibrium at start.x = {x0} m with the load of {:.0} N (payload.m, cbv.p_set): {e}",
                rest.f_cyl
            )
        })?;
        let mut s = c.to_vec();
        s.extend_from_slice(&rest.q);
        s.resize(self.dim(), 0.0);
        Ok(s)
    }

    /// Typical magnitude of each state (atol = rtol x scale).
    pub fn state_scale(&self) -> Vec<f64> {
        self.atol(1.0)
    }

    /// Absolute tolerances for relative tolerance `rtol`.
    fn atol(&self, rtol: f64) -> Vec<f64> {
        CIRCUIT_SCALE.iter().map(|s| s * rtol).chain(self.boom.atol(rtol)).collect()
    }
}

/// The HydraulicBoom model: plant, state and integrator.
#[derive(Debug, Clone)]
pub struct HydraulicBoom {
    plant: Plant,
    state: Vec<f64>,
    solver: Radau5,
}

impl HydraulicBoom {
    /// The model with the plant of `values` and the given state (the equilibrium if `None`).
    fn with_state(values: &Values, state: Option<&[f64]>) -> Result<Self, String> {
        let plant = Plant::from_values(values)?;
        let state = match state {
            None => plant.equilibrium(values.real(vr::X0))?,
            Some(s) if s.len() == plant.dim() && s.iter().all(|x| x.is_finite()) => s.to_vec(),
            Some(s) => return Err(format!("expected {} finite states, got {}", plant.dim(), s.len())),
        };
        let solver = Radau5::new(plant.dim());
        Ok(HydraulicBoom { plant, state, solver })
    }
}

impl Model for HydraulicBoom {
    const INFO: ModelInfo = ModelInfo {
        identifier: "HydraulicBoom",
        description:
            "Pressure-compensated valve, counterbalance valve, cylinder and rigid boom (thesis Fig. 2.8, section 2.1)",
        version: "0.1.0",
        start_time: 0.0,
        stop_time: 15.0,
        step_size: 1e-3,
        default_tolerance: 1e-6,
        log_categories: &[("logSolver", "Integrator statistics per communication step")],
        can_interpolate_inputs: false,
        documentation: DOCUMENTATION,
    };
    const VARIABLES: &'static [Variable] = &TABLE;

    fn initialize(values: &Values) -> Result<Self, String> {
        Self::with_state(values, None)
    }

    fn retune(&mut self, _values: &Values) -> Result<(), String> {
        Ok(())
    }

    fn outputs(&self, values: &mut Values) {
        let s = &self.state;
        let b = self.plant.boom.mechanics();
        let (c, boom) = s.split_at(N_CIRCUIT);
        let (q, qd) = boom.split_at(b.dof());
        let (x, v) = (b.stroke(q), b.stroke_rate(q, qd));
        let e = self.plant.circuit.evaluate(c.try_into().expect("circuit slice"), values.real(vr::U_REF), x, v);
        let stats = self.solver.stats();
        let outputs = [
            (vr::P1, c[circuit::P1]),
            (vr::P2, c[circuit::P2]),
            (vr::P3, c[circuit::P3]),
            (vr::P4, c[circuit::P4]),
            (vr::U, e.u),
            (vr::U_CV, e.u_cv),
            (vr::U_CBV, c[circuit::U_CBV]),
            (vr::Q1, e.q[0]),
            (vr::Q2, e.q[1]),
            (vr::Q3, e.q[2]),
            (vr::Q4, e.q[3]),
            (vr::X, x),
            (vr::V, v),
            (vr::F, e.force),
            (vr::F_FR, e.f_friction),
            (vr::X_V, c[circuit::X_V]),
            (vr::U_PCV, e.u_pcv),
            (vr::P_X, e.p_x),
            (vr::SOLVER_STEPS, stats.accepted_steps as f64),
            (vr::SOLVER_REJECTED, stats.rejected_steps as f64),
            (vr::SOLVER_RHS, stats.rhs_evals as f64),
            (vr::SOLVER_JACOBIANS, stats.jacobian_evals as f64),
        ];
        for (r, x) in outputs {
            values.set_real(r, x);
        }
        self.plant.boom.outputs(q, qd, [vr::THETA, vr::OMEGA, vr::PAYLOAD_X, vr::PAYLOAD_Y], values);
    }

    fn do_step(
        &mut self,
        values: &Values,
        _input_derivatives: &[f64],
        t: f64,
        h: f64,
        tolerance: f64,
        log: &mut dyn Log,
    ) -> Result<(), StepError> {
        let fail = |time, message: String| StepError { time, message };
        self.plant.u_ref = values.real(vr::U_REF);
        let atol = self.plant.atol(tolerance);
        self.solver
            .set_rtol(tolerance)
            .and_then(|_| self.solver.set_atol(&atol))
            .map_err(|e| fail(t, e.to_string()))?;
        let before = *self.solver.stats();
        self.solver.integrate(&self.plant, t, &mut self.state, t + h).map_err(|e| fail(e.t, e.to_string()))?;
        parts::log_step(log, t + h, &before, self.solver.stats());
        Ok(())
    }

    fn save(&self) -> Vec<f64> {
        let mut v = self.state.clone();
        v.extend_from_slice(&self.solver.save_state());
        v
    }

    fn load(values: &Values, saved: &[f64]) -> Result<Self, String> {
        let n = saved.len().checked_sub(Radau5::STATE_LEN).ok_or("the saved model state is too short")?;
        let mut m = Self::with_state(values, Some(&saved[..n]))?;
        let solver_state = saved[n..].try_into().map_err(|_| "solver state length".to_string())?;
        m.solver.load_state(solver_state).map_err(|e| e.to_string())?;
        Ok(m)
    }
}
