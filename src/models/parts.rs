//! What the hydraulic and mechanical FMU models share: the const builders of their variable
//! tables (the physical parameters with the same names and value references in every model), the
//! circuit and boom built from parameter values, the boom's outputs and the tolerance scales.

use crate::fmi2::{Log, Values, Variable};
use crate::hydraulics::circuit::{Circuit, N_STATES as N_CIRCUIT};
use crate::hydraulics::params::Param;
use crate::mechanics::flexible_boom::{FlexibleBoom, MAX_SECTIONS};
use crate::mechanics::params::{BeamParams, BoomParams, BEAM_SPECS, SPECS as BOOM_SPECS};
use crate::mechanics::rigid_boom::RigidBoom;
use crate::mechanics::BoomMechanics;
use crate::params::ParamSpec;
use crate::solver::SolverStats;

/// Value references shared by every model that has the variable (stable: append, never renumber).
pub mod vr {
    pub const X0: u32 = 30;
    pub const FLEXIBLE: u32 = 31;
    pub const TIP_DEFLECTION: u32 = 40;
    /// Section angles: `SECTIONS + i` is `boom.section[i + 1].phi`.
    pub const SECTIONS: u32 = 41;
    /// Hydraulic parameters: `HYDRAULICS + index` in [`crate::hydraulics::params::PARAMS`].
    pub const HYDRAULICS: u32 = 100;
    /// Boom parameters: `BOOM + index` in [`crate::mechanics::params::SPECS`].
    pub const BOOM: u32 = 200;
    /// Flexible-beam parameters: `BEAM + index` in [`crate::mechanics::params::BEAM_SPECS`].
    pub const BEAM: u32 = 250;
}

/// A continuous Real output.
pub(crate) const fn out(name: &'static str, r: u32, unit: &'static str, display: &'static str, d: &'static str) -> Variable {
    Variable::real_output(name, r, unit, display, d)
}

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

pub(crate) const fn str_eq(a: &str, b: &str) -> bool {
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

    /// Appends the section-angle outputs.
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
        self
    }

    /// The finished table; fails to compile unless every row is filled.
    pub(crate) const fn build(self) -> [Variable; N] {
        assert!(self.len == N, "variable table: row count differs from its length");
        self.rows
    }
}

/// Number of boom parameters, flexible-beam parameters and section outputs (table rows).
pub(crate) const N_BOOM_ROWS: usize = BOOM_SPECS.len() + BEAM_SPECS.len() + MAX_SECTIONS;

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
        return Err(format!(
            "valve.x_db = {} must be less than valve.x_max = {}",
            circuit.dcv.x_db, circuit.dcv.x_max
        ));
    }
    Ok(circuit)
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

    /// Absolute tolerances of q and q_dot for relative tolerance `rtol`: 1 mm and 1 mm/s of
    /// stroke (rigid); 0.1 mrad and 1 mrad/s of section angle (flexible: deflection angles are
    /// ~1 mrad).
    pub(crate) fn atol(&self, rtol: f64) -> impl Iterator<Item = f64> {
        let dof = self.mechanics().dof();
        let (q, qd) = if let Boom::Rigid(_) = self { (1e-3, 1e-3) } else { (1e-4, 1e-3) };
        std::iter::repeat_n(q * rtol, dof).chain(std::iter::repeat_n(qd * rtol, dof))
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
        for k in 0..MAX_SECTIONS {
            let phi = if let Boom::Flexible(_) = self { q[k.min(q.len() - 1)] } else { theta };
            values.set_real(vr::SECTIONS + k as u32, phi);
        }
    }
}

/// Scales of the circuit states for the absolute tolerance `atol_i = rtol * scale_i`: 1 bar,
/// 1 mm of spool travel, full valve opening.
pub(crate) const CIRCUIT_SCALE: [f64; N_CIRCUIT] = [1e5, 1e5, 1e5, 1e5, 1e-3, 1.0];

/// Logs the integrator statistics of the step that ended at `t` (category `logSolver`).
pub(crate) fn log_step(log: &mut dyn Log, t: f64, before: &SolverStats, after: &SolverStats) {
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
