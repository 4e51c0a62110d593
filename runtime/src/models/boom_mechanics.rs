//! The BoomMechanics FMU model: the rigid or lumped flexible boom of HydraulicBoom alone, driven
//! through the mechanical port ([`super::port`]) by the cylinder force (plain) or the TLM wave of
//! [`super::HydraulicCircuit`], advanced by the Radau IIA integrator.
//!
//! States: the boom's generalised coordinates and velocities (rigid: the stroke; flexible: the
//! section angles). The boom carries the rod and piston (mass and weight), as in HydraulicBoom,
//! and the cylinder's end stops: they are the contact of the piston with the barrel, mechanics on
//! this side of the cut, with the law and parameters of [`crate::hydraulics::cylinder`]
//! (`cylinder.k_stop`, `cylinder.c_stop`). HydraulicCircuit's port force has none, so the pair
//! coupled equals HydraulicBoom, and the boom alone with no force comes to rest on the bottom stop.

use super::boom::{boom_params, Boom};
use super::port::{self, Coupling, Ramp, FORCE_RANGE};
use super::exposed::{BOOM_DERIVATIVES, BOOM_STATES};
use super::terminals;
use super::table::{out, TableBuilder, FLEXIBLE_SWITCH, N_BOOM_ROWS, SOLVER_VARIABLES, START_STROKE, TIP_DEFLECTION};
use crate::fmu::driver::Step;
use crate::fmu::log::num;
use crate::fmu::{ContinuousState, Log, Model, ModelInfo, Seeds, StepError, StepStart, Value, Values, Variable};
use crate::hydraulics::circuit::Circuit;
use crate::hydraulics::cylinder::Cylinder;
use crate::hydraulics::params::PARAMS;
use crate::mechanics::flexible_boom::MAX_SECTIONS;
use crate::mechanics::kinematics::BoomKinematics;
use crate::mechanics::params::BoomParams;
use nalgebra::Vector2;
use crate::scalar::{Dual64, Scalar};
use crate::solver::{OdeSystem, SecondOrder};

/// Value references: HydraulicBoom's for the same names ([`super::vr::vr`]), the port's
/// ([`port::vr`]; its `F` is `port.F`).
pub mod vr {
    pub use crate::models::port::vr::{ALPHA, COUPLING, C_H, C_M, START_F, Z_C};
    pub use crate::models::vr::*;
    /// The rigid boom's geometry and mass ([`super::GEOMETRY`]): `GEOMETRY + k` is its row k.
    pub const GEOMETRY: u32 = 90;
}

/// The circuit parameters the boom uses (indices in [`PARAMS`]): the cylinder's stroke, its range
/// of motion, and its end stops.
const STROKE: usize = super::table::param_index("cylinder.stroke");
const K_STOP: usize = super::table::param_index("cylinder.k_stop");
const C_STOP: usize = super::table::param_index("cylinder.c_stop");

/// Unit and display unit of a length.
const LENGTH: (&str, &str) = ("m", "mm");

/// The rigid boom's geometry and mass, in the order of [`geometry`], computed from the parameters:
/// what another engine needs to build the same boom (boomsim.mujoco builds its MJCF from them).
#[rustfmt::skip]
const GEOMETRY: [Variable; 8] = [
    geometry_row("boom.joint.x", 0, LENGTH, "Boom joint B from the lower cylinder pin A, horizontal (s_AB, below eq. 2.10)"),
    geometry_row("boom.joint.y", 1, LENGTH, "Boom joint B from the lower cylinder pin A, vertical (s_AB, below eq. 2.10)"),
    geometry_row("boom.pin.x", 2, LENGTH, "Upper cylinder pin C from B along the arm's centre line (w1 cos phi2, eq. 2.1, 2.5)"),
    geometry_row("boom.pin.y", 3, LENGTH,
        "Upper cylinder pin C from B normal to the arm's centre line, > 0 up (-w1 sin phi2, eq. 2.1, 2.5)"),
    geometry_row("boom.cm.x", 4, LENGTH, "Mass centre D of arm and payload from B along the arm's centre line (e_cm, eq. 2.8)"),
    geometry_row("boom.cm.y", 5, LENGTH, "Mass centre D of arm and payload from B normal to the arm's centre line (e_cm, eq. 2.8)"),
    geometry_row("boom.m_D", 6, ("kg", ""), "Mass of arm and payload, m_D = m_arm + payload.m (eq. 2.8)"),
    geometry_row("boom.J_B", 7, ("kg.m2", ""), "Moment of inertia of arm and payload about the joint B (J_B, below eq. 2.18)"),
];

/// Row `k` of [`GEOMETRY`].
const fn geometry_row(name: &'static str, k: u32, (unit, display): (&'static str, &'static str), description: &'static str) -> Variable {
    out(name, vr::GEOMETRY + k, unit, display, description).calculated_parameter()
}

/// The values of [`GEOMETRY`] for the boom parameters `p`.
fn geometry(p: &BoomParams) -> [f64; 8] {
    let k = BoomKinematics::new(p);
    let (t, b) = (k.triangle(), k.body());
    let (joint, pin) = (k.point(0.0, Vector2::zeros()), t.upper_pin());
    [joint.x, joint.y, pin.x, pin.y, b.e_cm.x, b.e_cm.y, b.m_d, b.j_b]
}

#[rustfmt::skip]
const OWN: [Variable; 17] = [
    Variable::real_input("cylinder.F", vr::F, 0.0, "N", "kN", FORCE_RANGE,
        "Plain port: force on the rod from the circuit, pushing it out (linear over a step with its derivative)"),
    out("cylinder.x", vr::X, "m", "mm", "Cylinder stroke"),
    out("cylinder.v", vr::V, "m/s", "mm/s", "Cylinder velocity, > 0 extending"),
    out("boom.theta", vr::THETA, "rad", "deg", "Boom angle theta2 to the horizontal, > 0 up"),
    out("boom.omega", vr::OMEGA, "rad/s", "deg/s", "Boom angular velocity"),
    out("payload.x", vr::PAYLOAD_X, "m", "mm", "Payload mass centre, horizontal, from the lower cylinder pin"),
    out("payload.y", vr::PAYLOAD_Y, "m", "mm", "Payload mass centre, vertical, from the lower cylinder pin"),
    Variable::param(vr::X0, START_STROKE).fixed(),
    FLEXIBLE_SWITCH,
    TIP_DEFLECTION,
    port::COUPLING,
    Variable::param(vr::Z_C, port::Z_C).fixed(),
    Variable::param(vr::ALPHA, port::ALPHA).fixed(),
    out("start.F", vr::START_F, "N", "kN",
        "Cylinder force that holds the boom at rest at start.x (set HydraulicCircuit's start.F to it)"),
    Variable::real_input("port.c_h", vr::C_H, 0.0, "N", "kN", FORCE_RANGE,
        "TLM port: wave from the circuit, c_h = F_H + Z_c v_H (linear over a step with its derivative)"),
    // Plain port: the wave and the line force are the input cylinder.F.
    out("port.c_m", vr::C_M, "N", "kN", "TLM port: wave to the circuit, c_m = F_M - Z_c v_M at the step end")
        .depends(&[vr::F]),
    port::PORT_F.depends(&[vr::F]),
];

const N_VARS: usize = OWN.len() + GEOMETRY.len() + SOLVER_VARIABLES.len() + 3 + N_BOOM_ROWS + BOOM_DERIVATIVES.len();
const TABLE: [Variable; N_VARS] = TableBuilder::new(&OWN)
    .vars(&SOLVER_VARIABLES)
    .sections()
    .hydraulics(PARAMS, STROKE, STROKE + 1)
    .boom_params()
    .hydraulics(PARAMS, K_STOP, K_STOP + 1)
    .hydraulics(PARAMS, C_STOP, C_STOP + 1)
    .vars(&BOOM_DERIVATIVES)
    .vars(&GEOMETRY)
    .build();

const DOCUMENTATION: &str = concat!(
    r#"<p>The boom of HydraulicBoom without the hydraulics: rigid (sections 2.1.1-2.1.2) or lumped
flexible (2.1.4, 3.1.2), with the same parameters, names and value references, the rod and piston included. It
starts at rest at <code>start.x</code>; <code>start.F</code> is the cylinder force that holds it there.
<code>port.coupling</code> selects the port, as in HydraulicCircuit: <b>0, plain</b>: input <code>cylinder.F</code>
(linear over a step with fmi2SetRealInputDerivatives); <b>1, TLM</b>: input wave c<sub>h</sub>, the boom is pushed by
F<sub>M</sub> = c<sub>h</sub> &minus; Z<sub>c</sub>v<sub>M</sub> and emits c<sub>m</sub> = F<sub>M</sub> &minus;
Z<sub>c</sub>v<sub>M</sub> (<code>port.Z_c</code> equal in both FMUs). The cylinder's end stops act here
(<code>cylinder.k_stop</code>, <code>cylinder.c_stop</code>; HydraulicCircuit's port force has none): with no force
the boom comes to rest on the bottom stop. Outputs: stroke, velocity, boom angle, payload position, tip deflection
and section angles.</p>"#,
    "<p>Model Exchange runs the plain port (<code>port.coupling</code> = 0): the TLM port is a delay line of one \
communication step, which Model Exchange does not have.</p>",
    port::coupling_recipe!()
);

/// The boom driven through the port, as one ODE over a step.
#[derive(Debug, Clone)]
pub struct PortedBoom {
    pub boom: Boom,
    pub coupling: Coupling,
    /// Plain: the cylinder force; TLM: the wave c_h.
    pub input: Ramp,
    /// The cylinder whose end stops bound the stroke.
    pub cylinder: Cylinder,
}

impl PortedBoom {
    /// Port force pushing the rod out at `t` and stroke rate `v`.
    pub fn force(&self, t: f64, v: f64) -> f64 {
        match self.coupling {
            Coupling::Plain => self.input.at(t),
            Coupling::Tlm { z_c, .. } => self.input.at(t) - z_c * v,
        }
    }

    /// Everything that pushes the rod out at `t`, stroke `x`, rate `v`: port and end stops.
    fn rod_force(&self, t: f64, x: f64, v: f64) -> f64 {
        self.force(t, v) + self.cylinder.end_stop_force(x, v)
    }
}

impl PortedBoom {
    /// The derivatives `dx` of the Model Exchange states at `q`, `qd` under the plain port's
    /// force `f` and the end stops; allocation-free.
    fn me_rhs<T: Scalar>(&self, q: &[T], qd: &[T], f: T, dx: &mut [T]) {
        let mut qdd = [T::from(0.0); MAX_SECTIONS];
        let qdd = &mut qdd[..q.len()];
        self.boom.kinetics().accelerations(q, qd, &mut |x, v| f + self.cylinder.end_stop_force(x, v), qdd);
        self.boom.me_derivatives(q, qd, qdd, dx);
    }
}

impl OdeSystem for PortedBoom {
    fn dim(&self) -> usize {
        2 * self.boom.mechanics().dof()
    }

    fn rhs(&self, t: f64, s: &[f64], dx: &mut [f64]) {
        let b = self.boom.mechanics();
        let (q, qd) = s.split_at(b.dof());
        let (dq, dqd) = dx.split_at_mut(b.dof());
        dq.copy_from_slice(qd);
        b.accelerations(q, qd, &mut |x, v| self.rod_force(t, x, v), dqd);
    }

    /// dq/dt = q_dot: the integrator eliminates the coordinates from its linear systems.
    fn second_order(&self) -> Option<SecondOrder> {
        let dof = self.boom.mechanics().dof();
        Some(SecondOrder { pos: 0, vel: dof, len: dof })
    }
}

/// The BoomMechanics model: ported boom and state.
#[derive(Debug, Clone)]
pub struct BoomMechanics {
    sys: PortedBoom,
    /// Holding force at the start.
    f_start: f64,
    /// The values of [`GEOMETRY`].
    geometry: [f64; 8],
    t: f64,
    /// The wave emitted at `t` (TLM).
    c_m: f64,
    state: Vec<f64>,
}

impl BoomMechanics {
    /// The model at time `t` with the port input `input`, the emitted wave `c_m` and the given
    /// state (at rest at start.x if `None`).
    fn with_state(values: &Values, state: Option<&[f64]>, t: f64, [input, c_m]: [f64; 2]) -> Result<Self, String> {
        let mut circuit = Circuit::default();
        for k in [STROKE, K_STOP, C_STOP] {
            (PARAMS[k].set)(&mut circuit, values.real(vr::hydraulic(k)));
        }
        let (cylinder, stroke) = (circuit.cylinder, circuit.cylinder.stroke);
        let boom = Boom::from_values(values, stroke)?;
        let x0 = values.real(vr::X0);
        if !(0.0..=stroke).contains(&x0) {
            return Err(format!("start.x = {x0} is outside the stroke [0, {stroke}] m (cylinder.stroke)"));
        }
        let rest =
            boom.mechanics().equilibrium(x0).map_err(|e| format!("no boom equilibrium at start.x = {x0} m: {e}"))?;
        let input = Ramp::new(t, input, 0.0);
        let sys = PortedBoom { boom, coupling: Coupling::from_values(values), input, cylinder };
        let state =
            super::plant::checked_state(sys.dim(), state, || Ok([&rest.q[..], &vec![0.0; rest.q.len()]].concat()))?;
        Ok(BoomMechanics { sys, f_start: rest.f_cyl, geometry: geometry(&boom_params(values)), t, c_m, state })
    }

    /// The port input over the next step: `cylinder.F` (plain) or `port.c_h` (TLM).
    fn input_vr(&self) -> u32 {
        input_vr(self.sys.coupling)
    }
}

/// The port's input: the cylinder force (plain) or the wave c_h (TLM).
fn input_vr(coupling: Coupling) -> u32 {
    match coupling {
        Coupling::Plain => vr::F,
        Coupling::Tlm { .. } => vr::C_H,
    }
}

impl Model for BoomMechanics {
    const INFO: ModelInfo = ModelInfo {
        identifier: "BoomMechanics",
        description:
            "Rigid or lumped flexible boom with payload driven by the cylinder force or a TLM port (thesis section 2.1)",
        interpolated_inputs: &[vr::F, vr::C_H],
        documentation: DOCUMENTATION,
        terminals: &[terminals::ROD, terminals::ROD_TLM],
        ..super::plant::MODEL_INFO
    };
    const VARIABLES: &'static [Variable] = &TABLE;
    const STATES: &'static [ContinuousState] = &BOOM_STATES;

    /// Rigid and flexible boom, each with the plain and the TLM port.
    fn configurations() -> Vec<Vec<(u32, Value)>> {
        let ports = port::configurations();
        super::boom::boom_configurations()
            .iter()
            .flat_map(|b| ports.iter().map(move |p| [&b[..], p].concat()))
            .collect()
    }

    fn model_exchange_check(values: &Values) -> Result<(), String> {
        port::model_exchange_check(values)
    }

    /// The stroke within the cylinder's ([`Cylinder::stroke_domain`]): a force past the stops'
    /// strength (above 1.5 MN at the defaults) drives the piston through the barrel's end, and
    /// further on the rigid boom's triangle folds flat (dead centre), where the equations end.
    fn in_domain(&self) -> Result<(), String> {
        let b = self.sys.boom.mechanics();
        let x = b.stroke(&self.state[..b.dof()]);
        let (lo, hi) = self.sys.cylinder.stroke_domain();
        if (lo..=hi).contains(&x) {
            return Ok(());
        }
        Err(format!(
            "cylinder.x = {} m is past an end stop by more than the chamber's dead volume: the piston is through the cylinder's end (valid: [{}, {}] m, the strokes at which a chamber's volume is gone)",
            num(x),
            num(lo),
            num(hi)
        ))
    }

    fn continuous_states(&self, x: &mut [f64]) {
        let (q, qd) = self.state.split_at(self.sys.boom.mechanics().dof());
        self.sys.boom.me_states(q, qd, x);
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        let dof = self.sys.boom.mechanics().dof();
        let (q, qd) = self.state.split_at_mut(dof);
        self.sys.boom.read_me_states(x, q, qd)
    }

    /// The plain port: pushed by the input cylinder.F and the end stops.
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        let (q, qd) = self.state.split_at(self.sys.boom.mechanics().dof());
        self.sys.me_rhs(q, qd, values.real(vr::F), dx);
    }

    const DIRECTIONAL_DERIVATIVES: bool = true;

    /// The plain port's boom evaluated once in dual numbers from its Model Exchange states and
    /// the input cylinder.F, each carrying its seed: the derivatives and outputs carry the
    /// directional derivative, exact to round-off. The TLM port's wave is sampled at
    /// communication points: not provided.
    fn directional_derivative(&self, values: &Values, seeds: Seeds<'_>) -> Result<(), String> {
        port::directional_derivative_check(self.sys.coupling)?;
        let mut x = [0.0; BOOM_STATES.len()];
        self.continuous_states(&mut x);
        let x = super::exposed::seeded_states(&BOOM_STATES, &x, seeds.knowns);
        let f = super::exposed::seeded(seeds.knowns, vr::F, values.real(vr::F));
        let dof = self.sys.boom.mechanics().dof();
        let (mut q, mut qd) = ([Dual64::from(0.0); MAX_SECTIONS], [Dual64::from(0.0); MAX_SECTIONS]);
        let (q, qd) = (&mut q[..dof], &mut qd[..dof]);
        self.sys.boom.read_me_states(&x, q, qd)?;
        let mut dx = [Dual64::from(0.0); BOOM_STATES.len()];
        self.sys.me_rhs(q, qd, f, &mut dx);
        let k = self.sys.boom.kinetics();
        let port = [
            (vr::X, k.stroke(q)),
            (vr::V, k.stroke_rate(q, qd)),
            (vr::START_F, Dual64::from(self.f_start)),
            (vr::C_M, f),
            (port::vr::F, f),
        ];
        let boom = self.sys.boom.output_rows(q, qd, [vr::THETA, vr::OMEGA, vr::PAYLOAD_X, vr::PAYLOAD_Y]);
        let derivatives = BOOM_STATES.iter().zip(dx).map(|(s, d)| (s.derivative, d));
        let rows: Vec<(u32, Dual64)> = port.into_iter().chain(boom).chain(derivatives).collect();
        super::exposed::pick_derivatives(&rows, seeds)
    }

    /// Starts at rest; the TLM wave starts at the holding force (both sides at rest).
    fn initialize(values: &Values) -> Result<Self, String> {
        let mut m = Self::with_state(values, None, 0.0, [0.0, 0.0])?;
        m.sys.input.y0 = if m.sys.coupling == Coupling::Plain { values.real(vr::F) } else { m.f_start };
        m.c_m = m.f_start;
        Ok(m)
    }

    fn outputs(&self, values: &mut Values) {
        let mut sys = self.sys.clone();
        if sys.coupling == Coupling::Plain {
            sys.input = Ramp::new(self.t, values.real(vr::F), 0.0);
        }
        let b = sys.boom.mechanics();
        let (q, qd) = self.state.split_at(b.dof());
        let (x, v) = (b.stroke(q), b.stroke_rate(q, qd));
        let f = sys.force(self.t, v);
        let c_m = if sys.coupling == Coupling::Plain { f } else { self.c_m };
        for (r, y) in [(vr::X, x), (vr::V, v), (vr::START_F, self.f_start), (vr::C_M, c_m), (port::vr::F, f)] {
            values.set_real(r, y);
        }
        for (r, y) in (vr::GEOMETRY..).zip(self.geometry) {
            values.set_real(r, y);
        }
        sys.boom.outputs(q, qd, [vr::THETA, vr::OMEGA, vr::PAYLOAD_X, vr::PAYLOAD_Y], values);
    }

    type Ode = PortedBoom;

    const INTERMEDIATE_INPUTS: &'static [u32] = &[vr::F, vr::C_H];

    fn intermediate_inputs(sys: &mut PortedBoom, t: f64, samples: &[(f64, &[f64]); 3]) {
        let k = usize::from(input_vr(sys.coupling) == vr::C_H);
        sys.input = sys.input.through(t, samples.map(|(ts, u)| (ts, u[k])));
    }

    fn begin_step(&mut self, step: &StepStart<'_>, _log: &mut dyn Log) -> Result<Step<'_, PortedBoom>, StepError> {
        self.sys.input = Ramp::read(step, self.input_vr());
        Ok(Step::Integrate(&mut self.sys, &mut self.state))
    }

    fn scale(sys: &PortedBoom) -> Vec<f64> {
        sys.boom.scale().collect()
    }

    /// The TLM port emits its wave from the state reached.
    fn communication_point(&mut self, t: f64) {
        self.t = t;
        let (q, qd) = self.state.split_at(self.sys.boom.mechanics().dof());
        let v = self.sys.boom.mechanics().stroke_rate(q, qd);
        self.c_m = self.sys.coupling.emit(self.c_m, self.sys.force(self.t, v), -v);
    }

    fn state(&self) -> &[f64] {
        &self.state
    }

    /// Time, port input and emitted wave.
    const HEAD: usize = 3;

    fn head(&self) -> Vec<f64> {
        vec![self.t, self.sys.input.at(self.t), self.c_m]
    }

    fn restore(values: &Values, head: &[f64], state: &[f64]) -> Result<Self, String> {
        Self::with_state(values, Some(state), head[0], [head[1], head[2]])
    }
}
