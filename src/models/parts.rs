//! What the hydraulic and mechanical FMU models share: the const builders of their variable
//! tables (the physical parameters with the same names and value references in every model), the
//! circuit and boom built from parameter values, the boom's outputs and the tolerance scales.

use crate::fmi2::log::num;
use crate::fmi2::{Log, StepError, Value, Values, Variable};
use crate::hydraulics::circuit::{self, Circuit, Eval, N_STATES as N_CIRCUIT};
use crate::hydraulics::params::Param;
use crate::mechanics::flexible_boom::{FlexibleBoom, MAX_SECTIONS};
use crate::mechanics::params::{BeamParams, BoomParams, BEAM_SPECS, SPECS as BOOM_SPECS};
use crate::mechanics::rigid_boom::RigidBoom;
use crate::mechanics::BoomMechanics;
use crate::params::ParamSpec;
use crate::solver::{OdeSystem, Radau5, SolverStats};

/// Value references shared by every model that has the variable (stable: append, never renumber).
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
    pub const FLEXIBLE: u32 = 31;
    pub const TIP_DEFLECTION: u32 = 40;
    /// Section angles: `SECTIONS + i` is `boom.section[i + 1].phi`.
    pub const SECTIONS: u32 = 41;
    /// Section rates: `SECTION_RATES + i` is `boom.section[i + 1].omega`.
    pub const SECTION_RATES: u32 = 300;
    /// Derivatives of the continuous states: `DERIVATIVES + k` is der() of state k of
    /// HydraulicBoom's layout ([`crate::models::states`]).
    pub const DERIVATIVES: u32 = 400;
    /// Hydraulic parameters: `HYDRAULICS + index` in [`crate::hydraulics::params::PARAMS`].
    pub const HYDRAULICS: u32 = 100;
    /// Boom parameters: `BOOM + index` in [`crate::mechanics::params::SPECS`].
    pub const BOOM: u32 = 200;
    /// Flexible-beam parameters: `BEAM + index` in [`crate::mechanics::params::BEAM_SPECS`].
    pub const BEAM: u32 = 250;
}

/// A continuous Real output.
pub(crate) const fn out(
    name: &'static str,
    r: u32,
    unit: &'static str,
    display: &'static str,
    d: &'static str,
) -> Variable {
    Variable::real_output(name, r, unit, display, d)
}

/// `valve.u_ref`, the operator's spool reference.
pub(crate) const U_REF_INPUT: Variable = Variable::real_input(
    "valve.u_ref",
    vr::U_REF,
    0.0,
    "1",
    "%",
    (-1.0, 1.0),
    "Operator's spool reference; > 0 lifts (P->A), < 0 lowers through the CBV",
);

/// The circuit's outputs p1..Q4 (value references 1-11).
#[rustfmt::skip]
pub(crate) const CIRCUIT_OUTPUTS: [Variable; 11] = [
    out("p1", vr::P1, "Pa", "bar", "Compensated pressure after the PCV (line 1), gauge"),
    out("p2", vr::P2, "Pa", "bar", "Line 2 pressure, DCV port A to CBV, gauge"),
    out("p3", vr::P3, "Pa", "bar", "Piston-side chamber pressure (line 3), gauge"),
    out("p4", vr::P4, "Pa", "bar", "Rod-side chamber pressure (line 4, CBV pilot), gauge"),
    out("valve.u", vr::U, "1", "%", "Main spool opening u (eq. 2.44)"),
    out("cbv.u_cv", vr::U_CV, "1", "%", "Check valve opening (eq. 2.55)"),
    out("cbv.u_cbv", vr::U_CBV, "1", "%", "Load-holding valve opening (eq. 2.56, 2.57)"),
    out("Q1", vr::Q1, "m3/s", "l/min", "PCV flow, supply to line 1 (eq. 2.50)"),
    out("Q2", vr::Q2, "m3/s", "l/min", "DCV flow into line 2, P->A / A->T (eq. 2.40, 2.42)"),
    out("Q3", vr::Q3, "m3/s", "l/min", "CBV flow, line 2 to line 3 (eq. 2.58, 2.59)"),
    out("Q4", vr::Q4, "m3/s", "l/min", "DCV flow out of line 4, B->T / P->B (eq. 2.41, 2.43)"),
];

/// The circuit's locals: spool position, compensator opening, load-sensing pressure.
#[rustfmt::skip]
pub(crate) const CIRCUIT_LOCALS: [Variable; 3] = [
    Variable::real_local("valve.x_v", vr::X_V, "m", "mm", "Main spool position (state of eq. 2.45)"),
    Variable::real_local("pcv.u", vr::U_PCV, "1", "%", "Pressure compensator opening (eq. 2.49)"),
    Variable::real_local("valve.p_x", vr::P_X, "Pa", "bar", "Load-sensing pressure p_x, gauge"),
];

/// The integrator's counters.
#[rustfmt::skip]
pub(crate) const SOLVER_LOCALS: [Variable; 4] = [
    Variable::real_local("solver.steps", vr::SOLVER_STEPS, "1", "", "Accepted integrator steps since initialisation"),
    Variable::real_local("solver.rejected_steps", vr::SOLVER_REJECTED, "1", "", "Rejected integrator steps"),
    Variable::real_local("solver.rhs_evals", vr::SOLVER_RHS, "1", "", "Right-hand-side evaluations"),
    Variable::real_local("solver.jacobian_evals", vr::SOLVER_JACOBIANS, "1", "", "Jacobian evaluations"),
];

pub(crate) const START_STROKE: ParamSpec = ParamSpec {
    name: "start.x",
    default: 0.480,
    unit: "m",
    display_unit: "mm",
    min: 0.0,
    max: 10.0,
    description: "Initial stroke; the load starts at rest, held by the closed CBV, pressures in equilibrium",
    source: "Start stroke of the experiments, 480 mm (sections 6.2, chapter 7)",
};

pub(crate) const FLEXIBLE_SWITCH: Variable = Variable::bool_param(
    "boom.flexible",
    vr::FLEXIBLE,
    true,
    "Lumped flexible arm (boom.n2 + boom.n3 sections, eq. 2.34-2.39); false: rigid boom",
)
.fixed();

pub(crate) const TIP_DEFLECTION: Variable = out(
    "boom.tip_deflection",
    vr::TIP_DEFLECTION,
    "m",
    "mm",
    "Deflection of the arm's end normal to the rigid boom line at the same cylinder length, > 0 up (0 when rigid)",
);

/// Names of the section-angle outputs (structured names, 1-based as in the thesis).
const SECTION_NAMES: [&str; MAX_SECTIONS] = [
    "boom.section[1].phi",
    "boom.section[2].phi",
    "boom.section[3].phi",
    "boom.section[4].phi",
    "boom.section[5].phi",
    "boom.section[6].phi",
    "boom.section[7].phi",
    "boom.section[8].phi",
    "boom.section[9].phi",
    "boom.section[10].phi",
    "boom.section[11].phi",
    "boom.section[12].phi",
    "boom.section[13].phi",
    "boom.section[14].phi",
    "boom.section[15].phi",
    "boom.section[16].phi",
    "boom.section[17].phi",
    "boom.section[18].phi",
    "boom.section[19].phi",
    "boom.section[20].phi",
    "boom.section[21].phi",
    "boom.section[22].phi",
    "boom.section[23].phi",
    "boom.section[24].phi",
    "boom.section[25].phi",
    "boom.section[26].phi",
    "boom.section[27].phi",
    "boom.section[28].phi",
    "boom.section[29].phi",
    "boom.section[30].phi",
    "boom.section[31].phi",
    "boom.section[32].phi",
];

/// Parameters that count or select (a model index, section counts): exposed as Integers.
const SELECTORS: [&str; 3] = ["friction.model", "boom.n2", "boom.n3"];

const fn str_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
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

/// Index of the circuit parameter `name` in [`crate::hydraulics::params::PARAMS`] (compile-time
/// error if there is none).
pub(crate) const fn param_index(name: &str) -> usize {
    let params = crate::hydraulics::params::PARAMS;
    let mut k = 0;
    while !str_eq(params[k].spec.name, name) {
        k += 1;
    }
    k
}

const fn is_selector(name: &str) -> bool {
    let mut i = 0;
    while i < SELECTORS.len() {
        if str_eq(name, SELECTORS[i]) {
            return true;
        }
        i += 1;
    }
    false
}

/// The FMU variable of a physical parameter: fixed, an Integer where it counts or selects.
const fn param(r: u32, p: ParamSpec) -> Variable {
    if is_selector(p.name) {
        Variable::int_param(p.name, r, p.default as i32, (p.min as i32, p.max as i32), p.description)
    } else {
        Variable::param(r, p).fixed()
    }
}

/// The value of parameter `p` with value reference `r`, as a number.
pub(crate) fn param_value(values: &Values, r: u32, p: &ParamSpec) -> f64 {
    if is_selector(p.name) {
        values.integer(r) as f64
    } else {
        values.real(r)
    }
}

/// A table under construction: `N` rows, the first `len` filled.
pub(crate) struct TableBuilder<const N: usize> {
    rows: [Variable; N],
    len: usize,
}

impl<const N: usize> TableBuilder<N> {
    /// A table starting with `vars`.
    pub(crate) const fn new(vars: &[Variable]) -> Self {
        Self { rows: [vars[0]; N], len: 0 }.vars(vars)
    }

    /// Appends `vars`.
    pub(crate) const fn vars(mut self, vars: &[Variable]) -> Self {
        let mut k = 0;
        while k < vars.len() {
            self.rows[self.len] = vars[k];
            (self.len, k) = (self.len + 1, k + 1);
        }
        self
    }

    /// Appends the parameters `specs`, value references `base + index`.
    pub(crate) const fn params(mut self, base: u32, specs: &[ParamSpec]) -> Self {
        let mut k = 0;
        while k < specs.len() {
            self.rows[self.len] = param(base + k as u32, specs[k]);
            (self.len, k) = (self.len + 1, k + 1);
        }
        self
    }

    /// Appends the circuit parameters `params[from..to]` at their [`vr::HYDRAULICS`] references.
    pub(crate) const fn hydraulics(mut self, params: &[Param], from: usize, to: usize) -> Self {
        let mut k = from;
        while k < to {
            self.rows[self.len] = param(vr::HYDRAULICS + k as u32, params[k].spec);
            (self.len, k) = (self.len + 1, k + 1);
        }
        self
    }

    /// Appends the boom and flexible-beam parameters.
    pub(crate) const fn boom_params(self) -> Self {
        self.params(vr::BOOM, BOOM_SPECS).params(vr::BEAM, BEAM_SPECS)
    }

    /// Appends the section-angle and section-rate outputs.
    pub(crate) const fn sections(mut self) -> Self {
        let mut k = 0;
        while k < MAX_SECTIONS {
            self.rows[self.len] = out(
                SECTION_NAMES[k],
                vr::SECTIONS + k as u32,
                "rad",
                "deg",
                "Absolute angle of the arm section (from the joint outwards); beyond the last section, the last one's",
            );
            (self.len, k) = (self.len + 1, k + 1);
        }
        self.vars(&super::states::SECTION_RATES)
    }

    /// The finished table; fails to compile unless every row is filled.
    pub(crate) const fn build(self) -> [Variable; N] {
        assert!(self.len == N, "variable table: row count differs from its length");
        self.rows
    }
}

/// Number of boom parameters, flexible-beam parameters and section angles and rates (table rows).
pub(crate) const N_BOOM_ROWS: usize = BOOM_SPECS.len() + BEAM_SPECS.len() + 2 * MAX_SECTIONS;

/// The circuit from the parameter values at [`vr::HYDRAULICS`]; refuses inconsistent combinations.
pub(crate) fn circuit_from_values(values: &Values) -> Result<Circuit, String> {
    let mut circuit = Circuit::default();
    for (k, p) in crate::hydraulics::params::PARAMS.iter().enumerate() {
        (p.set)(&mut circuit, param_value(values, vr::HYDRAULICS + k as u32, &p.spec));
    }
    let cyl = &circuit.cylinder;
    if cyl.d_rod >= cyl.d_piston {
        return Err(format!("cylinder.d_rod = {} must be less than cylinder.d_piston = {}", cyl.d_rod, cyl.d_piston));
    }
    if circuit.dcv.x_db >= circuit.dcv.x_max {
        return Err(format!("valve.x_db = {} must be less than valve.x_max = {}", circuit.dcv.x_db, circuit.dcv.x_max));
    }
    Ok(circuit)
}

/// The parameter settings that change a boom model's equations: rigid, the default flexible
/// arm (4 + 5 sections), and the most sections (16 + 16, every Model Exchange slot live).
pub(crate) fn boom_configurations() -> Vec<Vec<(u32, Value)>> {
    let beam = |name| vr::BEAM + BEAM_SPECS.iter().position(|s| s.name == name).expect("beam parameter") as u32;
    vec![
        vec![(vr::FLEXIBLE, Value::Boolean(false))],
        vec![],
        vec![(beam("boom.n2"), Value::Integer(16)), (beam("boom.n3"), Value::Integer(16))],
    ]
}

/// The boom the cylinder drives.
#[derive(Debug, Clone)]
pub enum Boom {
    Rigid(RigidBoom),
    Flexible(FlexibleBoom),
}

impl Boom {
    /// The boom of the parameter values (boom, beam, `boom.flexible`) for a cylinder `stroke`.
    pub(crate) fn from_values(values: &Values, stroke: f64) -> Result<Self, String> {
        let lookup = |specs: &[ParamSpec], base: u32, name: &str| {
            let k = specs.iter().position(|s| s.name == name).expect("parameter name");
            param_value(values, base + k as u32, &specs[k])
        };
        let params = BoomParams::from_lookup(|n| lookup(BOOM_SPECS, vr::BOOM, n));
        let boom = if values.boolean(vr::FLEXIBLE) {
            let beam = BeamParams::from_lookup(|n| lookup(BEAM_SPECS, vr::BEAM, n));
            FlexibleBoom::new(&params, &beam, stroke).map(Boom::Flexible)
        } else {
            RigidBoom::new(&params, stroke).map(Boom::Rigid)
        };
        boom.map_err(|e| format!("boom geometry (boom.*, cylinder.l_retracted, cylinder.stroke): {e}"))
    }

    /// The boom's mechanics.
    pub fn mechanics(&self) -> &dyn BoomMechanics {
        match self {
            Boom::Rigid(b) => b,
            Boom::Flexible(b) => b,
        }
    }

    /// Typical magnitudes of q and q_dot (atol = rtol x scale). Rigid: 1 mm and 1 mm/s of
    /// stroke. Flexible: 2 mrad for the section angles (1 mm of stroke through the cylinder's
    /// lever about B, dx/dtheta2 = 0.55 m at 465 mm; away from the horizontal rtol |q| binds
    /// anyway) and 0.1 rad/s for their rates, the boom's angular rate while lowering (U peaks at
    /// 0.24 rad/s). Convergence study (scenario U, 15 s, against rtol 1e-9): every output stays as
    /// close to the reference as with 2 mrad/s (pressures within 28 Pa, stroke 2e-8 m, tip
    /// deflection 1e-7 m, section angles 5e-8 rad, regression metrics to 5 digits, both at a Newton
    /// tolerance of 1e-3), while the tighter scale made the integrator resolve the beam's chatter
    /// during cylinder stiction (v < v_s) to 1e-9 rad/s at a third more steps.
    pub(crate) fn scale(&self) -> impl Iterator<Item = f64> {
        let dof = self.mechanics().dof();
        let (q, qd) = if let Boom::Rigid(_) = self { (1e-3, 1e-3) } else { (2e-3, 0.1) };
        std::iter::repeat_n(q, dof).chain(std::iter::repeat_n(qd, dof))
    }

    /// The boom's Model Exchange states ([`crate::models::states`]) at coordinates `q`,
    /// velocities `qd`: the section angles and rates, the slots beyond the last section the last
    /// one's. Rigid: the boom angle theta2(l_cyl) and its rate theta2' v (eq. 2.7 in closed form,
    /// [`crate::mechanics::kinematics::Triangle::theta2_derivatives`]) in every slot.
    pub(crate) fn me_states(&self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let (phi, omega) = out.split_at_mut(MAX_SECTIONS);
        match self {
            Boom::Rigid(b) => {
                let (theta, d1, _) = b.kinematics().triangle().theta2_derivatives(b.l_cyl(q[0]));
                phi.fill(theta);
                omega.fill(d1 * qd[0]);
            }
            Boom::Flexible(_) => {
                for k in 0..MAX_SECTIONS {
                    let i = k.min(q.len() - 1);
                    (phi[k], omega[k]) = (q[i], qd[i]);
                }
            }
        }
    }

    /// Coordinates `q` and velocities `qd` from the boom's Model Exchange states `x` (the slots
    /// of the sections the boom has; the others are the importer's copies of the last one).
    pub(crate) fn read_me_states(&self, x: &[f64], q: &mut [f64], qd: &mut [f64]) -> Result<(), String> {
        let (phi, omega) = x.split_at(MAX_SECTIONS);
        match self {
            Boom::Rigid(b) => {
                let t = b.kinematics().triangle();
                let l = t.l_cyl(phi[0]).ok_or_else(|| {
                    let (lo, hi) = t.theta2_range();
                    format!(
                        "boom.section[1].phi = {} rad is outside ({}, {}) rad, where the cylinder triangle closes (rigid boom)",
                        num(phi[0]),
                        num(lo),
                        num(hi)
                    )
                })?;
                let (_, d1, _) = t.theta2_derivatives(l);
                (q[0], qd[0]) = (l - b.l_cyl(0.0), omega[0] / d1);
            }
            Boom::Flexible(_) => {
                let n = q.len();
                q.copy_from_slice(&phi[..n]);
                qd.copy_from_slice(&omega[..n]);
            }
        }
        Ok(())
    }

    /// The derivatives of the Model Exchange states from the velocities `qd` and accelerations
    /// `qdd` at `q`. Rigid: dtheta2/dt = theta2' v, domega/dt = theta2'' v^2 + theta2' a.
    pub(crate) fn me_derivatives(&self, q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        let (dphi, domega) = out.split_at_mut(MAX_SECTIONS);
        match self {
            Boom::Rigid(b) => {
                let (_, d1, d2) = b.kinematics().triangle().theta2_derivatives(b.l_cyl(q[0]));
                let v = qd[0];
                dphi.fill(d1 * v);
                domega.fill(d2 * v * v + d1 * qdd[0]);
            }
            Boom::Flexible(_) => {
                for k in 0..MAX_SECTIONS {
                    let i = k.min(q.len() - 1);
                    (dphi[k], domega[k]) = (qd[i], qdd[i]);
                }
            }
        }
    }

    /// Writes the boom outputs (angle, angular velocity, payload, tip deflection, section angles)
    /// at coordinates `q`, velocities `qd`; `theta`, `omega` and the payload use the value
    /// references `r = [theta, omega, payload.x, payload.y]` of the model.
    pub(crate) fn outputs(&self, q: &[f64], qd: &[f64], r: [u32; 4], values: &mut Values) {
        let b = self.mechanics();
        let (theta, omega, tip) = match self {
            Boom::Rigid(rb) => {
                let st = rb.state(b.stroke(q), b.stroke_rate(q, qd));
                (st.theta2, st.theta2_dot, 0.0)
            }
            Boom::Flexible(f) => (q[0], qd[0], f.tip_deflection(q)),
        };
        let payload = b.payload(q);
        for (r, x) in r.into_iter().zip([theta, omega, payload.x, payload.y]) {
            values.set_real(r, x);
        }
        values.set_real(vr::TIP_DEFLECTION, tip);
        let mut sections = [0.0; 2 * MAX_SECTIONS];
        self.me_states(q, qd, &mut sections);
        let refs = (vr::SECTIONS..).take(MAX_SECTIONS).chain((vr::SECTION_RATES..).take(MAX_SECTIONS));
        for (r, x) in refs.zip(sections) {
            values.set_real(r, x);
        }
    }
}

/// Scales of the circuit states for the absolute tolerance `atol_i = rtol * scale_i`: 1 bar,
/// 1 mm of spool travel, full valve opening.
pub(crate) const CIRCUIT_SCALE: [f64; N_CIRCUIT] = [1e5, 1e5, 1e5, 1e5, 1e-3, 1.0];

/// Writes the circuit's outputs and locals (p1..Q4, cylinder.F, cylinder.F_fr, spool, compensator,
/// load-sensing pressure) for state `c` and its evaluation `e`.
pub(crate) fn circuit_outputs(c: &circuit::State, e: &Eval, values: &mut Values) {
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
        (vr::F, e.force),
        (vr::F_FR, e.f_friction),
        (vr::X_V, c[circuit::X_V]),
        (vr::U_PCV, e.u_pcv),
        (vr::P_X, e.p_x),
    ];
    for (r, x) in outputs {
        values.set_real(r, x);
    }
}

/// Writes the integrator's counters.
pub(crate) fn solver_outputs(stats: &SolverStats, values: &mut Values) {
    values.set_real(vr::SOLVER_STEPS, stats.accepted_steps as f64);
    values.set_real(vr::SOLVER_REJECTED, stats.rejected_steps as f64);
    values.set_real(vr::SOLVER_RHS, stats.rhs_evals as f64);
    values.set_real(vr::SOLVER_JACOBIANS, stats.jacobian_evals as f64);
}

/// `state` if given and `dim` finite numbers, else `start()`.
pub(crate) fn checked_state(
    dim: usize,
    state: Option<&[f64]>,
    start: impl FnOnce() -> Result<Vec<f64>, String>,
) -> Result<Vec<f64>, String> {
    match state {
        None => start(),
        Some(s) if s.len() == dim && s.iter().all(|x| x.is_finite()) => Ok(s.to_vec()),
        Some(s) => Err(format!("expected {dim} finite states, got {}", s.len())),
    }
}

/// Advances `state` of `sys` from `t` to `t + h` with relative tolerance `rtol` and absolute
/// tolerances `rtol * scale` (evaluated only when `rtol` changes), logging the integrator
/// statistics of the step.
#[allow(clippy::too_many_arguments)]
pub(crate) fn advance<S: OdeSystem>(
    solver: &mut Radau5,
    sys: &S,
    state: &mut [f64],
    t: f64,
    h: f64,
    rtol: f64,
    scale: impl FnOnce() -> Vec<f64>,
    log: &mut dyn Log,
) -> Result<(), StepError> {
    let fail = |time, message: String| StepError { time, message };
    solver.set_tolerance(rtol, scale).map_err(|e| fail(t, e.to_string()))?;
    let before = *solver.stats();
    solver.integrate(sys, t, state, t + h).map_err(|e| fail(e.t, e.to_string()))?;
    log_step(log, t + h, &before, solver.stats());
    Ok(())
}

/// What the plant models (HydraulicBoom, HydraulicCircuit, BoomMechanics) share in their
/// [`ModelInfo`]: the thesis' 15 s experiments at 1 ms, rtol 1e-6, the solver log category.
pub(crate) const PLANT_INFO: crate::fmi2::ModelInfo = crate::fmi2::ModelInfo {
    identifier: "",
    description: "",
    version: env!("CARGO_PKG_VERSION"),
    start_time: 0.0,
    stop_time: 15.0,
    step_size: 1e-3,
    default_tolerance: 1e-6,
    log_categories: &[("logSolver", "Integrator statistics per communication step")],
    interpolated_inputs: &[],
    documentation: "",
};

/// A saved model: `head` (time, port values), the state, the integrator's state.
pub(crate) fn save(head: &[f64], state: &[f64], solver: &Radau5) -> Vec<f64> {
    [head, state, &solver.save_state()].concat()
}

/// A saved model's parts: head, state, integrator state.
type Saved<'a> = (&'a [f64], &'a [f64], &'a [f64]);

/// The parts of a model saved by [`save`] with `n_head` leading numbers: the state dimension n is
/// the one for which head + n + the integrator's saved length add up to the total.
pub(crate) fn split_saved(saved: &[f64], n_head: usize) -> Result<Saved<'_>, String> {
    let rest = saved.len().checked_sub(n_head).ok_or("the saved model state is too short")?;
    let n = (0..=rest)
        .find(|&n| n + Radau5::saved_len(n) >= rest)
        .filter(|&n| n + Radau5::saved_len(n) == rest)
        .ok_or_else(|| format!("{} numbers are no saved model state", saved.len()))?;
    let (head, rest) = saved.split_at(n_head);
    let (state, solver) = rest.split_at(n);
    Ok((head, state, solver))
}

/// Logs the integrator statistics of the step that ended at `t` (category `logSolver`).
fn log_step(log: &mut dyn Log, t: f64, before: &SolverStats, after: &SolverStats) {
    if !log.enabled("logSolver") {
        return;
    }
    log.info(
        "logSolver",
        &format!(
            "t = {t}: {} steps ({} rejected), {} RHS, {} Jacobians",
            after.accepted_steps - before.accepted_steps,
            after.rejected_steps - before.rejected_steps,
            after.rhs_evals - before.rhs_evals,
            after.jacobian_evals - before.jacobian_evals
        ),
    );
}
