//! The rows the FMU models' variable tables share and the const builders that assemble a table:
//! the circuit's outputs, the physical parameters with the same names and value references in
//! every model, the boom's section outputs.

use super::vr;
use crate::fmu::{Values, Variable};
use crate::hydraulics::Circuit;
use crate::mechanics::flexible_boom::MAX_SECTIONS;
use crate::mechanics::params::{BEAM_PARAMS, BOOM_PARAMS};
use crate::params::{Param, ParamSpec, ParamType};

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

/// The circuit's locals: spool position, compensator opening, load-sensing pressure, and the
/// event indicators ([`super::circuit::event_indicators`]; FMI 3.0 lists them as
/// ModelStructure `<EventIndicator>`).
#[rustfmt::skip]
pub(crate) const CIRCUIT_LOCALS: [Variable; 6] = [
    Variable::real_local("valve.x_v", vr::X_V, "m", "mm", "Main spool position (state of eq. 2.45)"),
    Variable::real_local("pcv.u", vr::U_PCV, "1", "%", "Pressure compensator opening (eq. 2.49)"),
    Variable::real_local("valve.p_x", vr::P_X, "Pa", "bar", "Load-sensing pressure p_x, gauge"),
    Variable::real_local("event.spool_reference", vr::EVENT_U_REF, "1", "%",
        "Event indicator u_ref: at 0 the spool demand jumps between -x_db and +x_db (eq. 2.45)"),
    Variable::real_local("event.dead_band_upper", vr::EVENT_DEAD_BAND_UPPER, "m", "mm",
        "Event indicator x_v - x_db: at 0 the load-sensing pressure switches between p2 and tank"),
    Variable::real_local("event.dead_band_lower", vr::EVENT_DEAD_BAND_LOWER, "m", "mm",
        "Event indicator x_v + x_db: at 0 the load-sensing pressure switches between p4 and tank"),
];

pub(crate) use crate::fmu::driver::SOLVER_VARIABLES;

pub(crate) const START_STROKE: ParamSpec = ParamSpec {
    name: "start.x",
    default: 0.480,
    unit: "m",
    display_unit: "mm",
    min: 0.0,
    max: 10.0,
    description: "Initial stroke; the load starts at rest, held by the closed CBV, pressures in equilibrium",
    source: "Start stroke of the experiments, 480 mm (sections 6.2, chapter 7)",
    ty: ParamType::Real,
};

pub(crate) const START_P4: ParamSpec = ParamSpec {
    name: "start.p4",
    default: 0.0,
    unit: "Pa",
    display_unit: "bar",
    min: 0.0,
    max: 100e5,
    description: "Initial rod-side pressure (line 4), gauge, trapped by the closed spool; p3 carries the load on top of it (eq. 2.85). Above tank pressure it bleeds to tank through the spool's leakage (eq. 2.47), over about a minute",
    source: "0: tank pressure, the valve's leakage equilibrium; the thesis' simulations of section 6.2 start at p4 = 1 bar",
    ty: ParamType::Real,
};

/// The trapped rod-side pressure of `start.p4`: `None` at 0 (tank pressure, the leakage
/// equilibrium, whatever `supply.p_t` is).
pub(crate) fn trapped_p4(values: &Values) -> Option<f64> {
    let p4 = values.real(vr::START_P4);
    (p4 != 0.0).then_some(p4)
}

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

/// The FMU variable of a physical parameter: fixed; an Integer where it counts, an Enumeration
/// where it chooses.
const fn param(r: u32, p: ParamSpec) -> Variable {
    match p.ty {
        ParamType::Real => Variable::param(r, p).fixed(),
        ParamType::Count => {
            Variable::int_param(p.name, r, p.default as i32, (p.min as i32, p.max as i32), p.description)
        }
        ParamType::Choice(ty) => Variable::enum_param(p.name, r, p.default as i32, ty, p.description),
    }
}

/// The value of parameter `p` with value reference `r`, as a number.
pub(crate) fn param_value(values: &Values, r: u32, p: &ParamSpec) -> f64 {
    match p.ty {
        ParamType::Real => values.real(r),
        ParamType::Count | ParamType::Choice(_) => values.integer(r) as f64,
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

    /// Appends the parameters `params`, value references `base + index`.
    pub(crate) const fn params<T>(mut self, base: u32, params: &[Param<T>]) -> Self {
        let mut k = 0;
        while k < params.len() {
            self.rows[self.len] = param(base + k as u32, params[k].spec);
            (self.len, k) = (self.len + 1, k + 1);
        }
        self
    }

    /// Appends the circuit parameters `params[from..to]` at their [`vr::hydraulic`] references.
    pub(crate) const fn hydraulics(mut self, params: &[Param<Circuit>], from: usize, to: usize) -> Self {
        let mut k = from;
        while k < to {
            self.rows[self.len] = param(vr::hydraulic(k), params[k].spec);
            (self.len, k) = (self.len + 1, k + 1);
        }
        self
    }

    /// Appends the boom and flexible-beam parameters.
    pub(crate) const fn boom_params(self) -> Self {
        self.params(vr::BOOM, BOOM_PARAMS).params(vr::BEAM, BEAM_PARAMS)
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
        self.vars(&SECTION_RATES)
    }

    /// The finished table; fails to compile unless every row is filled.
    pub(crate) const fn build(self) -> [Variable; N] {
        assert!(self.len == N, "variable table: row count differs from its length");
        self.rows
    }
}

/// Number of boom parameters, flexible-beam parameters and section angles and rates (table rows).
pub(crate) const N_BOOM_ROWS: usize = BOOM_PARAMS.len() + BEAM_PARAMS.len() + 2 * MAX_SECTIONS;

/// The section rates, outputs and Model Exchange states (structured names, 1-based).
pub(crate) const SECTION_RATES: [Variable; MAX_SECTIONS] = [
    out("boom.section[1].omega", vr::SECTION_RATES, "rad/s", "deg/s", RATE),
    out("boom.section[2].omega", vr::SECTION_RATES + 1, "rad/s", "deg/s", RATE),
    out("boom.section[3].omega", vr::SECTION_RATES + 2, "rad/s", "deg/s", RATE),
    out("boom.section[4].omega", vr::SECTION_RATES + 3, "rad/s", "deg/s", RATE),
    out("boom.section[5].omega", vr::SECTION_RATES + 4, "rad/s", "deg/s", RATE),
    out("boom.section[6].omega", vr::SECTION_RATES + 5, "rad/s", "deg/s", RATE),
    out("boom.section[7].omega", vr::SECTION_RATES + 6, "rad/s", "deg/s", RATE),
    out("boom.section[8].omega", vr::SECTION_RATES + 7, "rad/s", "deg/s", RATE),
    out("boom.section[9].omega", vr::SECTION_RATES + 8, "rad/s", "deg/s", RATE),
    out("boom.section[10].omega", vr::SECTION_RATES + 9, "rad/s", "deg/s", RATE),
    out("boom.section[11].omega", vr::SECTION_RATES + 10, "rad/s", "deg/s", RATE),
    out("boom.section[12].omega", vr::SECTION_RATES + 11, "rad/s", "deg/s", RATE),
    out("boom.section[13].omega", vr::SECTION_RATES + 12, "rad/s", "deg/s", RATE),
    out("boom.section[14].omega", vr::SECTION_RATES + 13, "rad/s", "deg/s", RATE),
    out("boom.section[15].omega", vr::SECTION_RATES + 14, "rad/s", "deg/s", RATE),
    out("boom.section[16].omega", vr::SECTION_RATES + 15, "rad/s", "deg/s", RATE),
    out("boom.section[17].omega", vr::SECTION_RATES + 16, "rad/s", "deg/s", RATE),
    out("boom.section[18].omega", vr::SECTION_RATES + 17, "rad/s", "deg/s", RATE),
    out("boom.section[19].omega", vr::SECTION_RATES + 18, "rad/s", "deg/s", RATE),
    out("boom.section[20].omega", vr::SECTION_RATES + 19, "rad/s", "deg/s", RATE),
    out("boom.section[21].omega", vr::SECTION_RATES + 20, "rad/s", "deg/s", RATE),
    out("boom.section[22].omega", vr::SECTION_RATES + 21, "rad/s", "deg/s", RATE),
    out("boom.section[23].omega", vr::SECTION_RATES + 22, "rad/s", "deg/s", RATE),
    out("boom.section[24].omega", vr::SECTION_RATES + 23, "rad/s", "deg/s", RATE),
    out("boom.section[25].omega", vr::SECTION_RATES + 24, "rad/s", "deg/s", RATE),
    out("boom.section[26].omega", vr::SECTION_RATES + 25, "rad/s", "deg/s", RATE),
    out("boom.section[27].omega", vr::SECTION_RATES + 26, "rad/s", "deg/s", RATE),
    out("boom.section[28].omega", vr::SECTION_RATES + 27, "rad/s", "deg/s", RATE),
    out("boom.section[29].omega", vr::SECTION_RATES + 28, "rad/s", "deg/s", RATE),
    out("boom.section[30].omega", vr::SECTION_RATES + 29, "rad/s", "deg/s", RATE),
    out("boom.section[31].omega", vr::SECTION_RATES + 30, "rad/s", "deg/s", RATE),
    out("boom.section[32].omega", vr::SECTION_RATES + 31, "rad/s", "deg/s", RATE),
];

const RATE: &str = "Absolute angular velocity of the arm section; beyond the last section, the last one's";
