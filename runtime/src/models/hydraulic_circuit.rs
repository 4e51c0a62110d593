//! The HydraulicCircuit FMU model: the circuit of thesis Fig. 2.8 ([`crate::hydraulics::circuit`])
//! with a mechanical port instead of the boom ([`super::port`]), for coupling to external
//! mechanics such as [`super::BoomMechanics`].
//!
//! States: the circuit's five (p2..p4, spool position, load-holding opening; p1 is quasi-static,
//! [`Circuit::line1_pressure`]); with the TLM port
//! also the rod's stroke and velocity. Plain port: the stroke follows the velocity input within a
//! step, x(t) = x_k + integral of v, v(t) = v_k + v' (t - t_k) (v' from
//! fmi2SetRealInputDerivatives, 0 holds v), so chamber volumes and piston flows agree. The
//! stroke input takes a derivative too (FMI 2.0 `canInterpolateInputs` is for every continuous
//! input): like every interpolated input, x then continues along it to the next communication
//! point, but within a step the circuit uses the integral of v, whose slope is the velocity the
//! master sends with x.

use super::circuit::{CIRCUIT_SCALE, ME_TOLERANCE};
use super::port::{self, Coupling, Ramp, FORCE_RANGE};
use super::terminals;
use super::exposed::{CIRCUIT_DERIVATIVES, CIRCUIT_STATES};
use super::table::{
    out, TableBuilder, CIRCUIT_LOCALS, CIRCUIT_OUTPUTS, SOLVER_VARIABLES, START_P4, START_STROKE, U_REF_INPUT,
};
use crate::fmu::driver::Step;
use crate::fmu::{ContinuousState, Log, Model, ModelInfo, Seeds, StepError, StepStart, Value, Values, Variable};
use crate::hydraulics::circuit::{self, Circuit, N_STATES as N_CIRCUIT};
use crate::hydraulics::params::PARAMS;
use crate::params::{ParamSpec, ParamType};
use crate::scalar::Dual64;
use crate::solver::{OdeSystem, SecondOrder};

/// Value references: HydraulicBoom's for the same names ([`super::vr::vr`]), the port's
/// ([`port::vr`]; its `F` is `port.F`).
pub mod vr {
    pub use crate::models::port::vr::{ALPHA, COUPLING, C_H, C_M, M, START_F, Z_C};
    pub use crate::models::vr::*;
    /// Stroke and velocity the circuit uses (the plain inputs, or the TLM rod's states).
    pub const PORT_X: u32 = 87;
    pub const PORT_V: u32 = 88;
}

const PORT_MASS: ParamSpec = ParamSpec {
    name: "port.m",
    default: 5.0,
    unit: "kg",
    display_unit: "",
    min: 1e-3,
    max: 1e5,
    description: "TLM port: mass the circuit integrates at the rod (rod + piston); the mechanics keeps its own",
    source: "cylinder.m_rod, 5 kg (thesis nomenclature); 0.03 % of the rigid boom's 16.9 t effective mass at 480 mm",
    ty: ParamType::Real,
};

/// Default: the rigid boom's holding force at the 480 mm start stroke (23 751 N; test
/// `start_force_default_holds_the_rigid_boom`).
const START_FORCE: ParamSpec = ParamSpec {
    name: "start.F",
    default: 23_750.0,
    unit: "N",
    display_unit: "kN",
    min: 0.0,
    max: 1e7,
    description: "Load on the rod at the start, held by the closed CBV (the mechanics' static force at start.x: BoomMechanics' start.F)",
    source: "rigid boom of the thesis at start.x = 480 mm (flexible: 23 819 N)",
    ty: ParamType::Real,
};

#[rustfmt::skip]
const OWN: [Variable; 42] = TableBuilder::new(&[U_REF_INPUT])
    .vars(&CIRCUIT_OUTPUTS)
    .vars(&[
        Variable::real_input("cylinder.x", vr::X, 0.480, "m", "mm", (-1.0, 10.0),
            "Plain port: cylinder stroke from the mechanics (at the step start)"),
        Variable::real_input("cylinder.v", vr::V, 0.0, "m/s", "mm/s", (-10.0, 10.0),
            "Plain port: cylinder velocity from the mechanics, > 0 extending (linear over a step with its derivative)"),
        out("cylinder.F", vr::F, "N", "kN", "Force on the rod: pressure forces - friction (at port.x, port.v); the end stops are the mechanics'")
            .depends(&[vr::X, vr::V]),
        out("cylinder.F_fr", vr::F_FR, "N", "kN", "Friction force, with the sign of the velocity").depends(&[vr::X, vr::V]),
    ])
    .vars(&CIRCUIT_LOCALS)
    .vars(&SOLVER_VARIABLES)
    .vars(&[
        Variable::param(vr::X0, START_STROKE).fixed(),
        Variable::param(vr::START_P4, START_P4).fixed(),
        port::COUPLING,
        Variable::param(vr::Z_C, port::Z_C).fixed(),
        Variable::param(vr::ALPHA, port::ALPHA).fixed(),
        Variable::param(vr::M, PORT_MASS).fixed(),
        Variable::param(vr::START_F, START_FORCE).fixed(),
        Variable::real_input("port.c_m", vr::C_M, START_FORCE.default, "N", "kN", FORCE_RANGE,
            "TLM port: wave from the mechanics, c_m = F_M - Z_c v_M (linear over a step with its derivative)"),
        // Plain port: the wave and the line force are cylinder.F, so they depend on x and v.
        out("port.c_h", vr::C_H, "N", "kN", "TLM port: wave to the mechanics, c_h = F_H + Z_c v_H at the step end")
            .depends(&[vr::X, vr::V]),
        port::PORT_F.depends(&[vr::X, vr::V]),
        out("port.x", vr::PORT_X, "m", "mm", "Stroke the circuit uses: cylinder.x ramped with cylinder.v (plain), the rod's (TLM)")
            .depends(&[vr::X]),
        out("port.v", vr::PORT_V, "m/s", "mm/s", "Velocity the circuit uses: cylinder.v (plain), the rod's (TLM)")
            .depends(&[vr::V]),
    ])
    .build();

const N_VARS: usize = OWN.len() + PARAMS.len() + CIRCUIT_DERIVATIVES.len();
const TABLE: [Variable; N_VARS] =
    TableBuilder::new(&OWN).hydraulics(PARAMS, 0, PARAMS.len()).vars(&CIRCUIT_DERIVATIVES).build();

const DOCUMENTATION: &str = concat!(
    r#"<p>The circuit of thesis Fig. 2.8 (valves, cylinder, lines; the same parameters, names and value
references as HydraulicBoom) with a mechanical port instead of the boom, advanced inside fmi2DoStep by the Radau IIA
integrator. <code>port.coupling</code> selects the port:</p>
<ul><li><b>0, plain</b>: inputs <code>cylinder.x</code>, <code>cylinder.v</code> (set the slope of v with
fmi2SetRealInputDerivatives for a velocity linear over the step; x follows its integral), output
<code>cylinder.F</code>. Exact, but the mechanics sees a force one step old: stable while &omega;h &lt; 2 for every
mode the oil column couples to the mechanics.</li>
<li><b>1, TLM</b>: a transmission line with impedance Z<sub>c</sub> (<code>port.Z_c</code>) and a delay of one
communication step. The circuit integrates the rod mass <code>port.m</code> pushed by the cylinder and held back by
the line force F<sub>H</sub> = c<sub>m</sub> + Z<sub>c</sub>v<sub>H</sub>, and emits c<sub>h</sub> = F<sub>H</sub> +
Z<sub>c</sub>v<sub>H</sub>; the mechanics is pushed by F<sub>M</sub> = c<sub>h</sub> &minus; Z<sub>c</sub>v<sub>M</sub>
and emits c<sub>m</sub> = F<sub>M</sub> &minus; Z<sub>c</sub>v<sub>M</sub>. Passive at any step; it adds a spring
Z<sub>c</sub>/h and a mass Z<sub>c</sub>h at the pin.</li></ul>
<p>The cylinder's end stops are not in the port force: they are the contact of piston and barrel, and belong to
the mechanics (BoomMechanics has them; mechanics of your own keeps the stroke within [0, <code>cylinder.stroke</code>]).
The circuit starts in the static equilibrium that holds <code>start.F</code> with the CBV closed (set it to the
mechanics' static cylinder force at the start).</p>"#,
    "<p>Model Exchange runs the plain port (<code>port.coupling</code> = 0): the TLM port is a delay line of one \
communication step, which Model Exchange does not have.</p>",
    port::coupling_recipe!()
);

/// The circuit with its port, as one ODE over a step.
#[derive(Debug, Clone)]
pub struct PortedCircuit {
    pub circuit: Circuit,
    pub coupling: Coupling,
    /// TLM rod mass (kg).
    pub m: f64,
    /// The operator's reference over the step.
    pub u_ref: Ramp,
    /// Plain: stroke at the step start and the velocity over the step.
    pub x0: f64,
    pub v: Ramp,
    /// TLM: the wave from the mechanics over the step.
    pub c_m: Ramp,
}

impl PortedCircuit {
    /// Stroke and velocity at `t` for state `s`.
    pub fn motion(&self, t: f64, s: &[f64]) -> (f64, f64) {
        match self.coupling {
            Coupling::Plain => (self.x0 + self.v.integral(t), self.v.at(t)),
            Coupling::Tlm { .. } => (s[N_CIRCUIT], s[N_CIRCUIT + 1]),
        }
    }

    /// The circuit's evaluation and the line force at `t`, state `s`.
    fn evaluate(&self, t: f64, s: &[f64]) -> (circuit::Eval, f64) {
        let (x, v) = self.motion(t, s);
        let e = self.circuit.evaluate(s[..N_CIRCUIT].try_into().expect("circuit slice"), self.u_ref.at(t), x, v);
        let f_line = match self.coupling {
            Coupling::Plain => e.force,
            Coupling::Tlm { z_c, .. } => self.c_m.at(t) + z_c * v,
        };
        (e, f_line)
    }
}

impl OdeSystem for PortedCircuit {
    fn dim(&self) -> usize {
        match self.coupling {
            Coupling::Plain => N_CIRCUIT,
            Coupling::Tlm { .. } => N_CIRCUIT + 2,
        }
    }

    fn rhs(&self, t: f64, s: &[f64], dx: &mut [f64]) {
        let (e, f_line) = self.evaluate(t, s);
        dx[..N_CIRCUIT].copy_from_slice(&e.dx);
        if let Coupling::Tlm { .. } = self.coupling {
            dx[N_CIRCUIT] = s[N_CIRCUIT + 1];
            dx[N_CIRCUIT + 1] = (e.force - f_line) / self.m;
        }
    }

    /// The local rod's dx/dt = v (TLM): the integrator eliminates x from its linear systems.
    fn second_order(&self) -> Option<SecondOrder> {
        match self.coupling {
            Coupling::Plain => None,
            Coupling::Tlm { .. } => Some(SecondOrder { pos: N_CIRCUIT, vel: N_CIRCUIT + 1, len: 1 }),
        }
    }
}

/// The HydraulicCircuit model: ported circuit and state.
#[derive(Debug, Clone)]
pub struct HydraulicCircuit {
    sys: PortedCircuit,
    /// Time of the state (the start of the next step).
    t: f64,
    /// The wave emitted at `t` (TLM).
    c_h: f64,
    state: Vec<f64>,
}

impl HydraulicCircuit {
    /// The model at time `t` with the received wave `c_m`, the emitted `c_h` and the given state
    /// (the equilibrium holding start.F if `None`).
    fn with_state(values: &Values, state: Option<&[f64]>, t: f64, [c_m, c_h]: [f64; 2]) -> Result<Self, String> {
        let mut circuit = super::circuit::circuit_from_values(values)?;
        // The end stops are the piston's contact with the barrel: mechanics, on the other side of
        // the cut (BoomMechanics applies them), so the port force is pressure forces - friction.
        (circuit.cylinder.k_stop, circuit.cylinder.c_stop) = (0.0, 0.0);
        let x0 = values.real(vr::X0);
        let stroke = circuit.cylinder.stroke;
        let sys = PortedCircuit {
            circuit,
            coupling: Coupling::from_values(values),
            m: values.real(vr::M),
            u_ref: Ramp::new(t, values.real(vr::U_REF), 0.0),
            x0: values.real(vr::X),
            v: Ramp::new(t, values.real(vr::V), 0.0),
            c_m: Ramp::new(t, c_m, 0.0),
        };
        let state = super::plant::checked_state(sys.dim(), state, || {
            if !(0.0..=stroke).contains(&x0) {
                return Err(format!("start.x = {x0} is outside the stroke [0, {stroke}] m (cylinder.stroke)"));
            }
            let f = values.real(vr::START_F);
            let c = sys.circuit.equilibrium(f, super::table::trapped_p4(values)).map_err(|e| {
                format!(
                    "no static equilibrium with start.F = {f:.0} N and start.p4 (payload on the CBV, cbv.p_set): {e}"
                )
            })?;
            let rod = if sys.dim() > N_CIRCUIT { vec![x0, 0.0] } else { vec![] };
            Ok([&c[..], &rod].concat())
        })?;
        Ok(HydraulicCircuit { sys, t, c_h, state })
    }

    /// Typical magnitude of each of `n` states (atol = rtol x scale): the circuit's scales, 1 mm
    /// and 1 mm/s for the rod.
    fn state_scale(n: usize) -> Vec<f64> {
        CIRCUIT_SCALE.iter().chain(&[1e-3, 1e-3]).take(n).copied().collect()
    }
}

impl Model for HydraulicCircuit {
    const INFO: ModelInfo = ModelInfo {
        identifier: "HydraulicCircuit",
        description: "Pressure-compensated valve, counterbalance valve and cylinder with a mechanical port (plain or TLM) for external mechanics (thesis Fig. 2.8)",
        // cylinder.x follows the integral of cylinder.v within a step: it has no slope of its own.
        interpolated_inputs: &[vr::U_REF, vr::X, vr::V, vr::C_M],
        documentation: DOCUMENTATION,
        terminals: &[terminals::ROD, terminals::ROD_TLM, terminals::VALVE, terminals::PRESSURE],
        log_categories: super::circuit::LOG_CATEGORIES,
        ..super::plant::MODEL_INFO
    };
    const VARIABLES: &'static [Variable] = &TABLE;
    const STATES: &'static [ContinuousState] = &CIRCUIT_STATES;
    const MODEL_EXCHANGE_TOLERANCE: Option<f64> = Some(ME_TOLERANCE);
    const EVENT_INDICATORS: &'static [u32] = super::circuit::EVENT_INDICATORS;
    const DIRECTIONAL_DERIVATIVES: bool = true;

    fn configurations() -> Vec<Vec<(u32, Value)>> {
        port::configurations()
    }

    fn model_exchange_check(values: &Values) -> Result<(), String> {
        port::model_exchange_check(values)
    }

    fn initialize(values: &Values) -> Result<Self, String> {
        let f = values.real(vr::START_F);
        Self::with_state(values, None, 0.0, [f, f])
    }

    fn continuous_states(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.state[..N_CIRCUIT]);
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        self.state[..N_CIRCUIT].copy_from_slice(x);
        Ok(())
    }

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        super::circuit::event_indicators(&self.sys.circuit, self.state[circuit::X_V], values.real(vr::U_REF), z);
    }

    /// The plain port's circuit evaluated once in dual numbers, each state and input carrying
    /// its seed: the derivatives and outputs carry the directional derivative, exact to
    /// round-off. The TLM port's outputs are sampled at communication points: not provided.
    fn directional_derivative(&self, values: &Values, seeds: Seeds<'_>) -> Result<(), String> {
        port::directional_derivative_check(self.sys.coupling)?;
        let seed = |r: u32, x: f64| super::exposed::seeded(seeds.knowns, r, x);
        let states: &[f64; N_CIRCUIT] = self.state[..N_CIRCUIT].try_into().expect("circuit");
        let c = super::exposed::seeded_states(&CIRCUIT_STATES, states, seeds.knowns);
        let [u_ref, x, v] = [vr::U_REF, vr::X, vr::V].map(|r| seed(r, values.real(r)));
        let e = self.sys.circuit.evaluate(&c, u_ref, x, v);
        let port = [(vr::C_H, e.force), (port::vr::F, e.force), (vr::PORT_X, x), (vr::PORT_V, v)];
        let derivatives = CIRCUIT_STATES.iter().zip(e.dx).map(|(s, d)| (s.derivative, d));
        let rows: Vec<(u32, Dual64)> =
            super::circuit::circuit_rows(&c, &e).into_iter().chain(port).chain(derivatives).collect();
        super::exposed::pick_derivatives(&rows, seeds)
    }

    /// The plain port's circuit at the stroke and velocity inputs.
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        let c = self.state[..N_CIRCUIT].try_into().expect("circuit slice");
        let e = self.sys.circuit.evaluate(c, values.real(vr::U_REF), values.real(vr::X), values.real(vr::V));
        dx.copy_from_slice(&e.dx);
    }

    fn outputs(&self, values: &mut Values) {
        let mut sys = self.sys.clone();
        sys.u_ref = Ramp::new(self.t, values.real(vr::U_REF), 0.0);
        if sys.coupling == Coupling::Plain {
            (sys.x0, sys.v) = (values.real(vr::X), Ramp::new(self.t, values.real(vr::V), 0.0));
        }
        let s = &self.state;
        let (x, v) = sys.motion(self.t, s);
        let (e, f_line) = sys.evaluate(self.t, s);
        let c_h = if sys.coupling == Coupling::Plain { f_line } else { self.c_h };
        super::circuit::circuit_outputs(s[..N_CIRCUIT].try_into().expect("circuit slice"), &e, values);
        for (r, y) in [(vr::C_H, c_h), (port::vr::F, f_line), (vr::PORT_X, x), (vr::PORT_V, v)] {
            values.set_real(r, y);
        }
    }

    type Ode = PortedCircuit;

    /// cylinder.x follows the integral of cylinder.v within a step, as with input derivatives.
    const INTERMEDIATE_INPUTS: &'static [u32] = &[vr::U_REF, vr::V, vr::C_M];

    fn intermediate_inputs(sys: &mut PortedCircuit, t: f64, samples: &[(f64, &[f64]); 3]) {
        let input = |k: usize| samples.map(|(ts, u)| (ts, u[k]));
        sys.u_ref = sys.u_ref.through(t, input(0));
        // The stroke at t, from which the new velocity integrates.
        sys.x0 += sys.v.integral(t);
        sys.v = sys.v.through(t, input(1));
        sys.c_m = sys.c_m.through(t, input(2));
    }

    fn step_event_indicators(sys: &PortedCircuit, t: f64, x: &[f64], z: &mut [f64]) {
        super::circuit::event_indicators(&sys.circuit, x[circuit::X_V], sys.u_ref.at(t), z);
    }

    fn begin_step(&mut self, step: &StepStart<'_>, _log: &mut dyn Log) -> Result<Step<'_, PortedCircuit>, StepError> {
        let sys = &mut self.sys;
        sys.u_ref = Ramp::read(step, vr::U_REF);
        sys.x0 = step.values.real(vr::X);
        sys.v = Ramp::read(step, vr::V);
        sys.c_m = Ramp::read(step, vr::C_M);
        Ok(Step::Integrate(&mut self.sys, &mut self.state))
    }

    fn scale(sys: &PortedCircuit) -> Vec<f64> {
        Self::state_scale(sys.dim())
    }

    /// The TLM port emits its wave from the state reached.
    fn communication_point(&mut self, t: f64) {
        self.t = t;
        let (_, v) = self.sys.motion(self.t, &self.state);
        self.c_h = self.sys.coupling.emit(self.c_h, self.sys.evaluate(self.t, &self.state).1, v);
    }

    fn state(&self) -> &[f64] {
        &self.state
    }

    /// Time, received wave and emitted wave.
    const HEAD: usize = 3;

    fn head(&self) -> Vec<f64> {
        vec![self.t, self.sys.c_m.at(self.t), self.c_h]
    }

    fn restore(values: &Values, head: &[f64], state: &[f64]) -> Result<Self, String> {
        Self::with_state(values, Some(state), head[0], [head[1], head[2]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::params::BoomParams;
    use crate::mechanics::rigid_boom::RigidBoom;

    /// start.F's default against the rigid boom's static cylinder force at the default start
    /// stroke; 1 N: the default is rounded to 10 N.
    #[test]
    fn start_force_default_holds_the_rigid_boom() {
        let stroke = Circuit::default().cylinder.stroke;
        let f = RigidBoom::new(&BoomParams::default(), stroke).unwrap().static_force(START_STROKE.default);
        assert!((f - START_FORCE.default).abs() < 10.0, "{f} N");
    }
}
