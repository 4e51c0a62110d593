//! The HydraulicBoom FMU model: the circuit of thesis Fig. 2.8 ([`crate::hydraulics::circuit`])
//! driving the boom, rigid (sections 2.1.1-2.1.2, [`crate::mechanics::rigid_boom`]) or lumped
//! flexible (2.1.4, 3.1.2, [`crate::mechanics::flexible_boom`]), advanced inside fmi2DoStep by
//! the stiff Radau IIA integrator ([`crate::solver`]).
//!
//! States: the circuit's five (p2..p4, spool position, load-holding opening; p1 is quasi-static,
//! [`Circuit::line1_pressure`]), then the boom's
//! generalised coordinates q and velocities q_dot (rigid: the stroke; flexible: the absolute
//! angle of each section). The operator's reference `valve.u_ref` is linear over a step with the
//! slope the master passes with fmi2SetRealInputDerivatives (held without one).

pub use super::boom::Boom;
use super::circuit::{CIRCUIT_SCALE, ME_TOLERANCE};
use super::port::Ramp;
use super::terminals;
use super::exposed::{BOOM_DERIVATIVES, CIRCUIT_DERIVATIVES, PLANT_STATES};
use super::table::{
    out, TableBuilder, CIRCUIT_LOCALS, CIRCUIT_OUTPUTS, FLEXIBLE_SWITCH, N_BOOM_ROWS, SOLVER_VARIABLES, START_P4,
    START_STROKE, TIP_DEFLECTION, U_REF_INPUT,
};
use crate::fmu::driver::Step;
use crate::fmu::{ContinuousState, Log, Model, ModelInfo, Seeds, StepError, StepStart, Value, Values, Variable};
use crate::hydraulics::circuit::{self, Circuit, N_STATES as N_CIRCUIT};
use crate::hydraulics::params::PARAMS;
use crate::mechanics::flexible_boom::{FlexibleBoom, MAX_SECTIONS};
use crate::scalar::{Dual64, DualSVec64, Scalar};
use nalgebra::{Const, DMatrix, U1};
use crate::solver::{OdeSystem, SecondOrder};

/// Value references (stable across releases: append, never renumber).
pub mod vr {
    pub use crate::models::vr::*;
}

#[rustfmt::skip]
const OWN: [Variable; 38] = TableBuilder::new(&[U_REF_INPUT])
    .vars(&CIRCUIT_OUTPUTS)
    .vars(&[
        out("cylinder.x", vr::X, "m", "mm", "Cylinder stroke"),
        out("cylinder.v", vr::V, "m/s", "mm/s", "Cylinder velocity, > 0 extending"),
        out("cylinder.F", vr::F, "N", "kN", "Force on the rod: pressure forces - friction + end stops"),
        out("cylinder.F_fr", vr::F_FR, "N", "kN", "Friction force, with the sign of the velocity"),
        out("boom.theta", vr::THETA, "rad", "deg", "Boom angle theta2 to the horizontal, > 0 up"),
        out("boom.omega", vr::OMEGA, "rad/s", "deg/s", "Boom angular velocity"),
        out("payload.x", vr::PAYLOAD_X, "m", "mm", "Payload mass centre, horizontal, from the lower cylinder pin"),
        out("payload.y", vr::PAYLOAD_Y, "m", "mm", "Payload mass centre, vertical, from the lower cylinder pin"),
    ])
    .vars(&CIRCUIT_LOCALS)
    .vars(&SOLVER_VARIABLES)
    .vars(&[
        Variable::param(vr::X0, START_STROKE).fixed(),
        Variable::param(vr::START_P4, START_P4).fixed(),
        FLEXIBLE_SWITCH,
        TIP_DEFLECTION,
    ])
    .build();

const N_VARS: usize = OWN.len() + PARAMS.len() + N_BOOM_ROWS + PLANT_STATES.len();

/// The table: own variables, the section angles and rates, every hydraulic, boom and beam
/// parameter (fixed: set them before initialisation ends), the states' derivatives.
const TABLE: [Variable; N_VARS] = TableBuilder::new(&OWN)
    .sections()
    .hydraulics(PARAMS, 0, PARAMS.len())
    .boom_params()
    .vars(&CIRCUIT_DERIVATIVES)
    .vars(&BOOM_DERIVATIVES)
    .build();

const DOCUMENTATION: &str = r#"<p>The circuit of thesis Fig. 2.8: supply, pressure compensator (eq. 2.49, 2.50),
PVG32 main spool with dead band and first-order dynamics (eq. 2.40-2.48; with <code>valve.omega_loop</code> &gt; 0 the
PVES's own position loop, speed-limited by the reaction times of Table 4.2), counterbalance valve with check valve and
piloted load-holding valve (eq. 2.55-2.59), asymmetric cylinder with end stops and friction (eq. 2.60-2.65), line
volumes with hose compliance (eq. 5.2) and entrained air near vacuum, line 1 (compensator to spool)
quasi-static; driving the boom, by default the lumped flexible
arm of sections 2.1.4 and 3.1.2 (<code>boom.n2</code> + <code>boom.n3</code> sections, eq. 2.34-2.39), or with
<code>boom.flexible</code> = false the rigid boom of sections 2.1.1-2.1.2 (kinematics eq. 2.1-2.15, kinetics eq.
2.16-2.19) as one degree of freedom in the cylinder stroke. A stiff Radau IIA (order 5) integrator advances the
circuit's five states and the boom's coordinates and velocities (rigid: the stroke; flexible: one angle per section)
inside fmi2DoStep with the tolerance of fmi2SetupExperiment; the flexible arm costs about ten times the rigid
boom's time (see the speed table of boomsim's docs/performance.md).</p>
<p>The simulation starts at rest at <code>start.x</code> with the load held by the closed CBV and all pressures in
static equilibrium, so a closed spool gives no start-up transient. Outputs do not depend directly on the input (the
spool has dynamics), so the FMU can be coupled to a controller without an algebraic loop.</p>
<p>Model Exchange: the importer's integrator gets the same states in every configuration (FMI 2.0 fixes their number;
the table above lists them): the circuit's five, then the section angles <code>boom.section[k].phi</code> and their rates
<code>boom.section[k].omega</code>. Slots beyond the last section repeat it, with its derivative; the rigid boom is
its angle theta2 in every slot (Co-Simulation integrates it in the stroke). Three event indicators mark where the
right-hand side jumps: the spool reference through zero (the dead band) and the spool at either edge of the dead
band (the load-sensing switch), readable as <code>event.spool_reference</code>, <code>event.dead_band_upper</code> and
<code>event.dead_band_lower</code>; elsewhere the model is continuous (regularised orifices and friction, end stops as
stiff springs), except that with <code>valve.omega_loop</code> &gt; 0 the spool's speed limit switches where a
saturated spool passes neutral, inside the dead band, where no oil flows. Directional derivatives are exact (forward-mode dual numbers through the same equations).</p>"#;

/// Circuit + boom as one ODE, with the operator's reference held.
#[derive(Debug, Clone)]
pub struct Plant {
    pub circuit: Circuit,
    pub boom: Boom,
    /// The operator's reference over the step.
    pub u_ref: Ramp,
}

impl OdeSystem for Plant {
    fn dim(&self) -> usize {
        N_CIRCUIT + 2 * self.boom.mechanics().dof()
    }

    fn rhs(&self, t: f64, s: &[f64], dx: &mut [f64]) {
        self.rhs_with(self.u_ref.at(t), s, dx);
    }

    /// The flexible boom's Jacobian from its structure ([`Plant::flexible_jacobian`]); the
    /// rigid boom's by the integrator's finite differences.
    fn jacobian(&self, t: f64, s: &[f64], jac: &mut DMatrix<f64>) -> bool {
        match &self.boom {
            Boom::Flexible(arm) => self.flexible_jacobian(arm, self.u_ref.at(t), s, jac),
            Boom::Rigid(_) => false,
        }
    }

    /// dq/dt = q_dot: the integrator eliminates the coordinates from its linear systems.
    fn second_order(&self) -> Option<SecondOrder> {
        let dof = self.boom.mechanics().dof();
        Some(SecondOrder { pos: N_CIRCUIT, vel: N_CIRCUIT + dof, len: dof })
    }
}

impl Plant {
    /// The right-hand side with the operator's reference `u_ref`.
    pub fn rhs_with<T: Scalar>(&self, u_ref: T, s: &[T], dx: &mut [T]) {
        let dof = self.boom.mechanics().dof();
        let (c, boom) = s.split_at(N_CIRCUIT);
        let (q, qd) = boom.split_at(dof);
        let c: &[T; N_CIRCUIT] = c.try_into().expect("circuit slice");
        let (dc, dboom) = dx.split_at_mut(N_CIRCUIT);
        let (dq, dqd) = dboom.split_at_mut(dof);
        dq.copy_from_slice(qd);
        let mut force = |x, v| {
            let e = self.circuit.evaluate(c, u_ref, x, v);
            dc.copy_from_slice(&e.dx);
            e.force
        };
        self.boom.kinetics().accelerations(q, qd, &mut force, dqd);
    }

    /// The Jacobian of [`Self::rhs_with`] for the flexible boom `arm` (issue 48): the circuit
    /// sees the arm only through the stroke x and its rate v, and the arm the circuit only through
    /// the cylinder force F, so the chain rule joins the circuit's derivatives with respect to its
    /// states, x and v (exact, dual numbers in all seven directions at once) and the arm's closed
    /// form ([`FlexibleBoom::acceleration_jacobian`], eq. 2.34-2.39 with 2.1-2.5):
    /// d/dq = d/dx g^T + d/dv (H q_dot)^T, d/dq_dot = d/dv g^T, and d q_ddot / d(circuit) =
    /// d q_ddot / dF dF / d(circuit). The rows of q are dq/dt = q_dot. `false` (the integrator's
    /// finite differences) if the arm's mass matrix is singular.
    fn flexible_jacobian(&self, arm: &FlexibleBoom, u_ref: f64, s: &[f64], jac: &mut DMatrix<f64>) -> bool {
        type Seeded = DualSVec64<{ N_CIRCUIT + 2 }>;
        const X: usize = N_CIRCUIT;
        const V: usize = N_CIRCUIT + 1;
        let n = arm.sections();
        let (c, boom) = s.split_at(N_CIRCUIT);
        let (q, qd) = boom.split_at(n);
        let seeded = |value: f64, i: usize| Seeded::from_re(value).derivative(i);
        let mut circuit = None;
        let mut force = |x, v| {
            let e = self.circuit.evaluate(&std::array::from_fn(|i| seeded(c[i], i)), Seeded::from(u_ref), seeded(x, X), seeded(v, V));
            let force = e.force.re;
            circuit = Some(e);
            force
        };
        let (Some(a), Some(e)) = (arm.acceleration_jacobian(q, qd, &mut force), circuit) else {
            return false;
        };
        let gradient = |y: Seeded| -> [f64; N_CIRCUIT + 2] { y.eps.unwrap_generic(Const, U1).into() };
        let (dx, f) = (e.dx.map(gradient), gradient(e.force));
        let (g, h_qd, rows) = (&a.gradient, &a.rate_gradient, &a.rows);
        let (dim, vel, cols) = (N_CIRCUIT + 2 * n, N_CIRCUIT + n, 2 * n + 1);
        let jac = jac.as_mut_slice();
        // Each column z as a direction of the circuit's inputs (a circuit state; q_k through
        // x and v; q_dot_k through v): its derivatives along it, then the accelerations' from the
        // arm's own column `arm` and the force's.
        for (z, col) in jac.chunks_exact_mut(dim).enumerate() {
            // The arm's column is z - N_CIRCUIT: q_k, then q_dot_k.
            let arm = z.checked_sub(N_CIRCUIT);
            let along = |d: &[f64; N_CIRCUIT + 2]| match arm {
                None => d[z],
                Some(k) if k < n => d[X] * g[k] + d[V] * h_qd[k],
                Some(k) => d[V] * g[k - n],
            };
            for (ci, d) in col.iter_mut().zip(&dx) {
                *ci = along(d);
            }
            col[N_CIRCUIT..vel].fill(0.0);
            if let Some(k) = arm.filter(|&k| k >= n) {
                // dq/dt = q_dot.
                col[N_CIRCUIT + k - n] = 1.0;
            }
            let d_force = along(&f);
            for (ci, row) in col[vel..].iter_mut().zip(rows.chunks_exact(cols)) {
                *ci = arm.map_or(0.0, |a| row[a]) + row[2 * n] * d_force;
            }
        }
        true
    }

    /// The derivatives `dx` of the Model Exchange states at the plant state `s` (native
    /// coordinates) with the reference `u_ref`. No allocation: Model Exchange calls this for
    /// every right-hand side of its integrator.
    fn me_rhs<T: Scalar>(&self, u_ref: T, s: &[T], dx: &mut [T]) {
        let mut ds = [T::from(0.0); N_CIRCUIT + 2 * MAX_SECTIONS];
        let ds = &mut ds[..s.len()];
        self.rhs_with(u_ref, s, ds);
        let dof = self.boom.mechanics().dof();
        let (q, qd) = s[N_CIRCUIT..].split_at(dof);
        dx[..N_CIRCUIT].copy_from_slice(&ds[..N_CIRCUIT]);
        self.boom.me_derivatives(q, qd, &ds[N_CIRCUIT + dof..], &mut dx[N_CIRCUIT..]);
    }

    /// The outputs (circuit, stroke and velocity, boom) at the plant state `s` with the
    /// reference `u_ref`, as (value reference, value).
    pub fn output_rows<T: Scalar>(&self, u_ref: T, s: &[T]) -> impl Iterator<Item = (u32, T)> {
        let k = self.boom.kinetics();
        let (c, boom) = s.split_at(N_CIRCUIT);
        let (q, qd) = boom.split_at(self.boom.mechanics().dof());
        let c: &[T; N_CIRCUIT] = c.try_into().expect("circuit slice");
        let (x, v) = (k.stroke(q), k.stroke_rate(q, qd));
        let e = self.circuit.evaluate(c, u_ref, x, v);
        let stroke = [(vr::X, x), (vr::V, v)];
        let boom = self.boom.output_rows(q, qd, [vr::THETA, vr::OMEGA, vr::PAYLOAD_X, vr::PAYLOAD_Y]);
        super::circuit::circuit_rows(c, &e).into_iter().chain(stroke).chain(boom)
    }

    /// The plant from the FMU's parameter values; refuses inconsistent combinations.
    pub fn from_values(values: &Values) -> Result<Self, String> {
        let circuit = super::circuit::circuit_from_values(values)?;
        let boom = Boom::from_values(values, circuit.cylinder.stroke)?;
        Ok(Plant { circuit, boom, u_ref: Ramp::new(0.0, values.real(vr::U_REF), 0.0) })
    }

    /// Static equilibrium at stroke `x0`: the load held at rest by the closed CBV, the rod side
    /// at tank pressure or trapped at `p4` (see [`crate::hydraulics::circuit::Circuit::equilibrium`]).
    pub fn equilibrium(&self, x0: f64, p4: Option<f64>) -> Result<Vec<f64>, String> {
        let stroke = self.circuit.cylinder.stroke;
        if !(0.0..=stroke).contains(&x0) {
            return Err(format!("start.x = {x0} is outside the stroke [0, {stroke}] m (cylinder.stroke)"));
        }
        let b = self.boom.mechanics();
        let rest = b.equilibrium(x0).map_err(|e| format!("no boom equilibrium at start.x = {x0} m: {e}"))?;
        let c = self.circuit.equilibrium(rest.f_cyl, p4).map_err(|e| {
            format!(
                "no static equilibrium at start.x = {x0} m with the load of {:.0} N and start.p4 = {} Pa (payload.m, cbv.p_set): {e}",
                rest.f_cyl,
                p4.unwrap_or(self.circuit.supply.p_t)
            )
        })?;
        let mut s = c.to_vec();
        s.extend_from_slice(&rest.q);
        s.resize(self.dim(), 0.0);
        Ok(s)
    }

    /// Typical magnitude of each state (atol = rtol x scale).
    pub fn state_scale(&self) -> Vec<f64> {
        CIRCUIT_SCALE.iter().copied().chain(self.boom.scale()).collect()
    }
}

/// The HydraulicBoom model: plant and state.
#[derive(Debug, Clone)]
pub struct HydraulicBoom {
    plant: Plant,
    state: Vec<f64>,
}

impl HydraulicBoom {
    /// The model with the plant of `values` and the given state (the equilibrium if `None`).
    fn with_state(values: &Values, state: Option<&[f64]>) -> Result<Self, String> {
        let plant = Plant::from_values(values)?;
        let state = super::plant::checked_state(plant.dim(), state, || {
            plant.equilibrium(values.real(vr::X0), super::table::trapped_p4(values))
        })?;
        Ok(HydraulicBoom { plant, state })
    }
}

impl Model for HydraulicBoom {
    const INFO: ModelInfo = ModelInfo {
        identifier: "HydraulicBoom",
        description:
            "Pressure-compensated valve, counterbalance valve, cylinder and rigid or lumped flexible boom (thesis Fig. 2.8, section 2.1)",
        interpolated_inputs: &[vr::U_REF],
        documentation: DOCUMENTATION,
        terminals: &[terminals::VALVE, terminals::PRESSURE],
        log_categories: super::circuit::LOG_CATEGORIES,
        ..super::plant::MODEL_INFO
    };
    const VARIABLES: &'static [Variable] = &TABLE;
    const STATES: &'static [ContinuousState] = &PLANT_STATES;
    const MODEL_EXCHANGE_TOLERANCE: Option<f64> = Some(ME_TOLERANCE);
    const EVENT_INDICATORS: &'static [u32] = super::circuit::EVENT_INDICATORS;

    fn configurations() -> Vec<Vec<(u32, Value)>> {
        super::boom::boom_configurations()
    }

    fn initialize(values: &Values) -> Result<Self, String> {
        Self::with_state(values, None)
    }

    fn continuous_states(&self, x: &mut [f64]) {
        let (c, boom) = self.state.split_at(N_CIRCUIT);
        let (q, qd) = boom.split_at(self.plant.boom.mechanics().dof());
        x[..N_CIRCUIT].copy_from_slice(c);
        self.plant.boom.me_states(q, qd, &mut x[N_CIRCUIT..]);
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        let dof = self.plant.boom.mechanics().dof();
        let (c, boom) = self.state.split_at_mut(N_CIRCUIT);
        let (q, qd) = boom.split_at_mut(dof);
        self.plant.boom.read_me_states(&x[N_CIRCUIT..], q, qd)?;
        c.copy_from_slice(&x[..N_CIRCUIT]);
        Ok(())
    }

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        super::circuit::event_indicators(&self.plant.circuit, self.state[circuit::X_V], values.real(vr::U_REF), z);
    }

    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        self.plant.me_rhs(values.real(vr::U_REF), &self.state, dx);
    }

    const DIRECTIONAL_DERIVATIVES: bool = true;

    /// The plant evaluated once in dual numbers from its Model Exchange states and the input,
    /// each carrying its seed: the derivatives and outputs carry the directional derivative,
    /// exact to round-off (padded state slots are copies the model does not read: zero).
    fn directional_derivative(&self, values: &Values, seeds: Seeds<'_>) -> Result<(), String> {
        let mut x = [0.0; PLANT_STATES.len()];
        self.continuous_states(&mut x);
        let x = super::exposed::seeded_states(&PLANT_STATES, &x, seeds.knowns);
        let u_ref = super::exposed::seeded(seeds.knowns, vr::U_REF, values.real(vr::U_REF));
        let mut s = [Dual64::from(0.0); N_CIRCUIT + 2 * MAX_SECTIONS];
        let s = &mut s[..self.state.len()];
        s[..N_CIRCUIT].copy_from_slice(&x[..N_CIRCUIT]);
        let (q, qd) = s[N_CIRCUIT..].split_at_mut(self.plant.boom.mechanics().dof());
        self.plant.boom.read_me_states(&x[N_CIRCUIT..], q, qd)?;
        let mut dx = [Dual64::from(0.0); PLANT_STATES.len()];
        self.plant.me_rhs(u_ref, s, &mut dx);
        let derivatives = PLANT_STATES.iter().zip(dx).map(|(st, d)| (st.derivative, d));
        let rows: Vec<(u32, Dual64)> = self.plant.output_rows(u_ref, s).chain(derivatives).collect();
        super::exposed::pick_derivatives(&rows, seeds)
    }

    fn outputs(&self, values: &mut Values) {
        for (r, y) in self.plant.output_rows(values.real(vr::U_REF), &self.state) {
            values.set_real(r, y);
        }
    }

    type Ode = Plant;

    const INTERMEDIATE_INPUTS: &'static [u32] = &[vr::U_REF];

    const LOOKAHEAD: bool = true;

    fn intermediate_inputs(plant: &mut Plant, t: f64, samples: &[(f64, &[f64]); 3]) {
        plant.u_ref = plant.u_ref.through(t, samples.map(|(ts, u)| (ts, u[0])));
    }

    fn step_event_indicators(plant: &Plant, t: f64, x: &[f64], z: &mut [f64]) {
        super::circuit::event_indicators(&plant.circuit, x[circuit::X_V], plant.u_ref.at(t), z);
    }

    fn begin_step(&mut self, step: &StepStart<'_>, _log: &mut dyn Log) -> Result<Step<'_, Plant>, StepError> {
        self.plant.u_ref = Ramp::read(step, vr::U_REF);
        Ok(Step::Integrate(&mut self.plant, &mut self.state))
    }

    fn scale(plant: &Plant) -> Vec<f64> {
        plant.state_scale()
    }

    fn state(&self) -> &[f64] {
        &self.state
    }

    fn restore(values: &Values, _head: &[f64], state: &[f64]) -> Result<Self, String> {
        Self::with_state(values, Some(state))
    }
}
