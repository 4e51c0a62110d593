//! The HydraulicBoom FMU model: the circuit of thesis Fig. 2.8 ([`crate::hydraulics::circuit`])
//! driving the rigid boom of sections 2.1.1-2.1.2 ([`crate::mechanics::rigid_boom`]), advanced
//! inside fmi2DoStep by the stiff Radau IIA integrator ([`crate::solver`]).
//!
//! States: the circuit's six (p1..p4, spool position, load-holding opening) and the cylinder
//! stroke and velocity. The operator's reference `valve.u_ref` is held over each step.

use crate::fmi2::{Log, Model, ModelInfo, StepError, Values, Variable};
use crate::hydraulics::circuit::{self, Circuit, N_STATES as N_CIRCUIT};
use crate::hydraulics::params::PARAMS;
use crate::mechanics::params::{BoomParams, SPECS as BOOM_SPECS};
use crate::mechanics::rigid_boom::RigidBoom;
use crate::params::ParamSpec;
use crate::solver::{OdeSystem, Radau5};

/// Number of continuous states: the circuit's plus stroke and velocity.
pub const N_STATES: usize = N_CIRCUIT + 2;
const X: usize = N_CIRCUIT;
const V: usize = N_CIRCUIT + 1;

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
    pub const X0: u32 = 30;
    /// Hydraulic parameters: `HYDRAULICS + index` in [`crate::hydraulics::params::PARAMS`].
    pub const HYDRAULICS: u32 = 100;
    /// Boom parameters: `BOOM + index` in [`crate::mechanics::params::SPECS`].
    pub const BOOM: u32 = 200;
}

const START_STROKE: ParamSpec = ParamSpec {
    name: "start.x",
    default: 0.480,
    unit: "m",
    display_unit: "mm",
    min: 0.0,
    max: 10.0,
    description: "Initial stroke; the load starts at rest, held by the closed CBV, pressures in equilibrium",
    source: "Start stroke of the experiments, 480 mm (sections 6.2, chapter 7)",
};

const fn out(name: &'static str, r: u32, unit: &'static str, display: &'static str, d: &'static str) -> Variable {
    Variable::real_output(name, r, unit, display, d)
}

#[rustfmt::skip]
const OWN: [Variable; 28] = [
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
];

const N_VARS: usize = OWN.len() + PARAMS.len() + BOOM_SPECS.len();

/// Whether a hydraulic parameter selects a variant (an index): exposed as an Integer.
const fn is_selector(name: &str) -> bool {
    let (a, b) = (name.as_bytes(), b"friction.model");
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The FMU variable of hydraulic parameter `k`.
const fn hydraulic_param(k: usize) -> Variable {
    let (r, p) = (vr::HYDRAULICS + k as u32, PARAMS[k].spec);
    if is_selector(p.name) {
        Variable::int_param(p.name, r, p.default as i32, (p.min as i32, p.max as i32), p.description)
    } else {
        Variable::param(r, p).fixed()
    }
}

/// The table: own variables, then every hydraulic and boom parameter (fixed: set them before
/// initialisation ends).
const TABLE: [Variable; N_VARS] = {
    let mut t = [OWN[0]; N_VARS];
    let mut i = 0;
    while i < OWN.len() {
        t[i] = OWN[i];
        i += 1;
    }
    let mut k = 0;
    while k < PARAMS.len() {
        t[OWN.len() + k] = hydraulic_param(k);
        k += 1;
    }
    let mut k = 0;
    while k < BOOM_SPECS.len() {
        t[OWN.len() + PARAMS.len() + k] = Variable::param(vr::BOOM + k as u32, BOOM_SPECS[k]).fixed();
        k += 1;
    }
    t
};

/// Scales of the states for the absolute tolerance `atol_i = rtol * scale_i`: 1 bar, 1 mm of
/// spool travel, full valve opening, 1 mm of stroke, 1 mm/s.
const STATE_SCALE: [f64; N_STATES] = [1e5, 1e5, 1e5, 1e5, 1e-3, 1.0, 1e-3, 1e-3];

const DOCUMENTATION: &str = r#"<p>The circuit of thesis Fig. 2.8: supply, pressure compensator (eq. 2.49, 2.50),
PVG32 main spool with dead band and first-order dynamics (eq. 2.40-2.48), counterbalance valve with check valve and
piloted load-holding valve (eq. 2.55-2.59), asymmetric cylinder with end stops and friction (eq. 2.60-2.65), line
volumes with hose compliance (eq. 5.2) and entrained air near vacuum; driving the rigid boom of sections 2.1.1-2.1.2
(kinematics eq. 2.1-2.15, kinetics eq. 2.16-2.19) as one degree of freedom in the cylinder stroke. A stiff Radau IIA
(order 5) integrator advances the eight states inside fmi2DoStep with the tolerance of fmi2SetupExperiment.</p>
<p>The simulation starts at rest at <code>start.x</code> with the load held by the closed CBV and all pressures in
static equilibrium, so a closed spool gives no start-up transient. Outputs do not depend directly on the input (the
spool has dynamics), so the FMU can be coupled to a controller without an algebraic loop.</p>"#;

/// Circuit + rigid boom as one ODE, with the operator's reference held.
#[derive(Debug, Clone)]
pub struct RigidPlant {
    pub circuit: Circuit,
    pub boom: RigidBoom,
    pub u_ref: f64,
}

impl OdeSystem for RigidPlant {
    fn dim(&self) -> usize {
        N_STATES
    }

    fn rhs(&self, _t: f64, s: &[f64], dx: &mut [f64]) {
        let c: &circuit::State = s[..N_CIRCUIT].try_into().expect("circuit slice");
        let e = self.circuit.evaluate(c, self.u_ref, s[X], s[V]);
        dx[..N_CIRCUIT].copy_from_slice(&e.dx);
        dx[X] = s[V];
        dx[V] = self.boom.acceleration(s[X], s[V], e.force);
    }
}

impl RigidPlant {
    /// The plant from the FMU's parameter values; refuses inconsistent combinations.
    pub fn from_values(values: &Values) -> Result<Self, String> {
        let mut circuit = Circuit::default();
        for (k, p) in PARAMS.iter().enumerate() {
            let r = vr::HYDRAULICS + k as u32;
            (p.set)(&mut circuit, if is_selector(p.spec.name) { values.integer(r) as f64 } else { values.real(r) });
        }
        let cyl = &circuit.cylinder;
        if cyl.d_rod >= cyl.d_piston {
            return Err(format!(
                "cylinder.d_rod = {} must be less than cylinder.d_piston = {}",
                cyl.d_rod, cyl.d_piston
            ));
        }
        if circuit.dcv.x_db >= circuit.dcv.x_max {
            return Err(format!(
                "valve.x_db = {} must be less than valve.x_max = {}",
                circuit.dcv.x_db, circuit.dcv.x_max
            ));
        }
        let boom_vr = |name: &str| {
            let k = BOOM_SPECS.iter().position(|s| s.name == name).expect("boom parameter name");
            values.real(vr::BOOM + k as u32)
        };
        let boom = RigidBoom::new(&BoomParams::from_lookup(boom_vr), cyl.stroke)
            .map_err(|e| format!("boom geometry (boom.*, cylinder.l_retracted, cylinder.stroke): {e}"))?;
        Ok(RigidPlant { circuit, boom, u_ref: values.real(vr::U_REF) })
    }

    /// Static equilibrium at stroke `x0`: the load held at rest by the closed CBV.
    pub fn equilibrium(&self, x0: f64) -> Result<[f64; N_STATES], String> {
        let stroke = self.circuit.cylinder.stroke;
        if !(0.0..=stroke).contains(&x0) {
            return Err(format!("start.x = {x0} is outside the stroke [0, {stroke}] m (cylinder.stroke)"));
        }
        let f_load = self.boom.static_force(x0);
        let c = self.circuit.equilibrium(f_load).map_err(|e| {
            format!(
                "no static equilibrium at start.x = {x0} m with the load of {f_load:.0} N (payload.m, cbv.p_set): {e}"
            )
        })?;
        let mut s = [0.0; N_STATES];
        s[..N_CIRCUIT].copy_from_slice(&c);
        s[X] = x0;
        Ok(s)
    }
}

/// The HydraulicBoom model: plant, state and integrator.
#[derive(Debug, Clone)]
pub struct HydraulicBoom {
    plant: RigidPlant,
    state: [f64; N_STATES],
    solver: Radau5,
}

impl HydraulicBoom {
    fn with_state(values: &Values, state: [f64; N_STATES]) -> Result<Self, String> {
        let plant = RigidPlant::from_values(values)?;
        Ok(HydraulicBoom { plant, state, solver: Radau5::new(N_STATES) })
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
        let mut m = Self::with_state(values, [0.0; N_STATES])?;
        m.state = m.plant.equilibrium(values.real(vr::X0))?;
        Ok(m)
    }

    fn retune(&mut self, _values: &Values) -> Result<(), String> {
        Ok(())
    }

    fn outputs(&self, values: &mut Values) {
        let s = &self.state;
        let c: &circuit::State = s[..N_CIRCUIT].try_into().expect("circuit slice");
        let e = self.plant.circuit.evaluate(c, values.real(vr::U_REF), s[X], s[V]);
        let b = self.plant.boom.state(s[X], s[V]);
        let outputs = [
            (vr::P1, s[circuit::P1]),
            (vr::P2, s[circuit::P2]),
            (vr::P3, s[circuit::P3]),
            (vr::P4, s[circuit::P4]),
            (vr::U, e.u),
            (vr::U_CV, e.u_cv),
            (vr::U_CBV, s[circuit::U_CBV]),
            (vr::Q1, e.q[0]),
            (vr::Q2, e.q[1]),
            (vr::Q3, e.q[2]),
            (vr::Q4, e.q[3]),
            (vr::X, s[X]),
            (vr::V, s[V]),
            (vr::F, e.force),
            (vr::F_FR, e.f_friction),
            (vr::THETA, b.theta2),
            (vr::OMEGA, b.theta2_dot),
            (vr::PAYLOAD_X, b.payload.x),
            (vr::PAYLOAD_Y, b.payload.y),
            (vr::X_V, s[circuit::X_V]),
            (vr::U_PCV, e.u_pcv),
            (vr::P_X, e.p_x),
            (vr::SOLVER_STEPS, self.solver.stats().accepted_steps as f64),
            (vr::SOLVER_REJECTED, self.solver.stats().rejected_steps as f64),
            (vr::SOLVER_RHS, self.solver.stats().rhs_evals as f64),
            (vr::SOLVER_JACOBIANS, self.solver.stats().jacobian_evals as f64),
        ];
        for (r, x) in outputs {
            values.set_real(r, x);
        }
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
        let atol = STATE_SCALE.map(|s| s * tolerance);
        self.solver
            .set_rtol(tolerance)
            .and_then(|_| self.solver.set_atol(&atol))
            .map_err(|e| fail(t, e.to_string()))?;
        let before = *self.solver.stats();
        self.solver.integrate(&self.plant, t, &mut self.state, t + h).map_err(|e| fail(e.t, e.to_string()))?;
        let s = self.solver.stats();
        log.info(
            "logSolver",
            &format!(
                "t = {}: {} steps ({} rejected), {} RHS, {} Jacobians",
                t + h,
                s.accepted_steps - before.accepted_steps,
                s.rejected_steps - before.rejected_steps,
                s.rhs_evals - before.rhs_evals,
                s.jacobian_evals - before.jacobian_evals
            ),
        );
        Ok(())
    }

    fn save(&self) -> Vec<f64> {
        let mut v = self.state.to_vec();
        v.extend_from_slice(&self.solver.save_state());
        v
    }

    fn load(values: &Values, saved: &[f64]) -> Result<Self, String> {
        let state = saved.get(..N_STATES).filter(|s| s.iter().all(|x| x.is_finite()));
        let state = state.ok_or_else(|| format!("expected {N_STATES} finite states, got {saved:?}"))?;
        let mut m = Self::with_state(values, state.try_into().expect("length checked"))?;
        let solver_state =
            saved[N_STATES..].try_into().map_err(|_| format!("expected {} solver numbers", Radau5::STATE_LEN))?;
        m.solver.load_state(solver_state).map_err(|e| e.to_string())?;
        Ok(m)
    }
}
