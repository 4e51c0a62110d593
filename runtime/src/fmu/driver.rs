//! The Co-Simulation driver: one for every model. A model states its ODE and state
//! ([`Model::begin_step`]); the driver integrates it over the communication step with the stiff
//! Radau IIA of [`crate::solver`] (adaptive, or real-time with a bounded cost per step; for a
//! model whose ODE depends on nothing but its inputs, [`Model::LOOKAHEAD`], the adaptive
//! integrator's last step may pass the communication point while no input changes), then
//! lets the model act at the communication point ([`Model::communication_point`]: the TLM wave),
//! writes the integrator's counters as outputs, and saves and restores the integrator with the
//! model in FMU states. No model owns a solver.
//!
//! The one special case is a model whose equations have a closed-form solution over a step:
//! the controller's first-order filter under a ramped input (eq. 6.2) is stepped exactly by the
//! model itself ([`Step::Done`]), which no integrator beats; such a model has no ODE state and
//! the driver no integrator for it: [`Model::CLOSED_FORM`] is a constant that the compiler folds,
//! so that the model's binary links no integrator either.

use super::model::{Log, Model, StepError, StepStart};
use super::variables::{Values, Variable};
use crate::solver::{Dense, OdeSystem, Radau5, SolverStats, Watch};
use std::ops::{Deref, DerefMut};

/// The driver's variables' value references (stable: append, never renumber).
pub mod vr {
    pub const SOLVER_STEPS: u32 = 23;
    pub const SOLVER_REJECTED: u32 = 24;
    pub const SOLVER_RHS: u32 = 25;
    pub const SOLVER_JACOBIANS: u32 = 26;
    /// The integrator's mode, the real-time mode's accuracy indicator, its budget per
    /// communication step, its inaccurate steps.
    pub const SOLVER_MODE: u32 = 33;
    pub const ACCURACY_LOSS: u32 = 34;
    pub const RHS_BUDGET: u32 = 35;
    pub const INACCURATE_STEPS: u32 = 36;
}

/// `solver.mode` of the real-time mode (0, the default, is the adaptive integrator).
pub const REALTIME: i32 = 1;

/// The integrator's mode and counters: the variables of every model the driver integrates.
#[rustfmt::skip]
pub const SOLVER_VARIABLES: [Variable; 8] = [
    Variable::real_local("solver.steps", vr::SOLVER_STEPS, "1", "", "Accepted integrator steps since initialisation"),
    Variable::real_local("solver.rejected_steps", vr::SOLVER_REJECTED, "1", "", "Rejected integrator steps"),
    Variable::real_local("solver.rhs_evals", vr::SOLVER_RHS, "1", "", "Right-hand-side evaluations"),
    Variable::real_local("solver.jacobian_evals", vr::SOLVER_JACOBIANS, "1", "", "Jacobian evaluations"),
    Variable::int_param("solver.mode", vr::SOLVER_MODE, 0, (0, 1),
        "Integrator of the Co-Simulation doStep (no effect in Model Exchange): 0 adaptive (error control with the \
         experiment's tolerance, as many steps as that needs), 1 real-time (the same within solver.rhs_budget \
         right-hand-side evaluations per communication step, a bounded cost: when the budget runs short, one closing \
         step of bounded work reaches the communication point and its accuracy is reported in solver.accuracy_loss \
         instead of a rejected step)"),
    Variable::int_param("solver.rhs_budget", vr::RHS_BUDGET, 400, (100, 1_000_000),
        "Real-time mode: right-hand-side evaluations (Jacobian columns included) per communication step, at most"),
    Variable::real_local("solver.accuracy_loss", vr::ACCURACY_LOSS, "1", "",
        "Real-time mode: local error estimate of the closing step of the last communication step, in units of the \
         tolerance (above 1: a step the adaptive mode would have rejected); 0 when no closing step was needed"),
    Variable::real_local("solver.inaccurate_steps", vr::INACCURATE_STEPS, "1", "",
        "Real-time mode: closing steps with solver.accuracy_loss above 1 since initialisation"),
];

/// What a model asks of the driver at the start of a communication step.
pub enum Step<'a, S> {
    /// Integrate `ode` from `state` (the model's, advanced in place) over the step.
    Integrate(&'a mut S, &'a mut [f64]),
    /// The model advanced itself over the step in closed form.
    Done,
}

/// The ODE of a model that steps in closed form: none.
impl OdeSystem for () {
    fn dim(&self) -> usize {
        0
    }

    fn rhs(&self, _t: f64, _x: &[f64], _dx: &mut [f64]) {}
}

/// A model with the driver's integrator (none for a model without ODE state).
#[derive(Debug)]
pub struct Driven<M> {
    model: M,
    solver: Option<Radau5>,
    /// Work space of the event search: a state on the integrator's continuous output.
    work: Vec<f64>,
}

impl<M: Model> Clone for Driven<M> {
    fn clone(&self) -> Self {
        Driven { model: self.model.clone(), solver: self.solver().cloned(), work: self.work.clone() }
    }
}

impl<M> Deref for Driven<M> {
    type Target = M;
    fn deref(&self) -> &M {
        &self.model
    }
}

impl<M> DerefMut for Driven<M> {
    fn deref_mut(&mut self) -> &mut M {
        &mut self.model
    }
}

impl<M: Model> Driven<M> {
    /// `model` with a fresh integrator for its ODE state.
    pub fn new(model: M) -> Self {
        let n = model.state().len();
        Driven { model, solver: (!M::CLOSED_FORM && n > 0).then(|| Radau5::new(n)), work: vec![0.0; n] }
    }

    /// The integrator; none for a closed-form model (known at compile time).
    fn solver(&self) -> Option<&Radau5> {
        self.solver.as_ref().filter(|_| !M::CLOSED_FORM)
    }

    /// Advances from `t` to `t + h`: inputs are `values` at `t`, changing with the given first
    /// derivatives (one per table row; zero unless set) where the model interpolates inputs.
    /// The relative tolerance is `tolerance`, the absolute ones `tolerance` times the model's
    /// [`Model::scale`] (evaluated only when the tolerance changes). `solver.mode` picks the
    /// integration: adaptive ([`Radau5::integrate`]: error control, steps rejected and repeated
    /// as needed) or real-time ([`Radau5::integrate_bounded`]: the same within
    /// `solver.rhs_budget` RHS evaluations, the accuracy of its closing step reported instead of
    /// enforced). Neither allocates.
    ///
    /// With `early_return`, the step ends at the first root of the model's event indicators
    /// within it ([`Model::step_event_indicators`], located on the integrator's continuous
    /// output): the state there has the indicators' new signs, so the next step starts past the
    /// event. With a `master` (FMI 3.0 intermediate update), the model's intermediate inputs
    /// take the values the master gives for the stage times of each attempted integrator step
    /// ([`Model::intermediate_inputs`]), and after each accepted step the master may ask the step
    /// to end at a time. Returns where the step ended, if not at `t + h`'s integration end: its
    /// time and whether it was at an event.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        values: &Values,
        input_derivatives: &[f64],
        (t, h, tolerance): (f64, f64, f64),
        log: &mut dyn Log,
        (early_return, reach): (bool, Option<f64>),
        master: Option<&mut dyn Intermediate>,
    ) -> Result<Option<Ended>, StepError> {
        let fail = |time, message: String| StepError { time, message };
        let start = StepStart { values, input_derivatives, t, h };
        let (end, ended) = match (self.model.begin_step(&start, log)?, self.solver.as_mut().filter(|_| !M::CLOSED_FORM))
        {
            (Step::Done, _) => return Ok(None),
            (Step::Integrate(ode, state), Some(solver)) => {
                solver.set_tolerance(tolerance, || M::scale(ode)).map_err(|e| fail(t, e.to_string()))?;
                let before = *solver.stats();
                let budget =
                    (values.integer(vr::SOLVER_MODE) == REALTIME).then(|| values.integer(vr::RHS_BUDGET) as u64);
                let roots = early_return.then(|| Roots::<M>::new(ode, t, state, &mut self.work));
                let mut watch = Watched::<M> { ode, roots, master, ended: None, requested: None };
                let reach = reach.filter(|_| M::LOOKAHEAD && budget.is_none());
                let reached = solver.integrate_until(&mut watch, (t, t + h), state, budget, reach);
                let end = reached.map_err(|e| fail(e.t, e.to_string()))?;
                log_step(log, end, &before, solver.stats());
                (end, watch.ended)
            }
            (Step::Integrate(..), None) => return Err(fail(t, "the model has no ODE state to integrate".into())),
        };
        self.model.communication_point(end);
        Ok(ended)
    }

    /// An input or parameter changed between steps: the next step starts from the state at its
    /// start (not from a step of the integrator's that passed it).
    pub fn inputs_changed(&mut self) {
        if let Some(solver) = self.solver.as_mut() {
            solver.inputs_changed();
        }
    }

    /// Writes the model's outputs and locals, and the integrator's counters.
    pub fn outputs(&self, values: &mut Values) {
        self.model.outputs(values);
        if let Some(solver) = self.solver() {
            let stats = solver.stats();
            values.set_real(vr::SOLVER_STEPS, stats.accepted_steps as f64);
            values.set_real(vr::SOLVER_REJECTED, stats.rejected_steps as f64);
            values.set_real(vr::SOLVER_RHS, stats.rhs_evals as f64);
            values.set_real(vr::SOLVER_JACOBIANS, stats.jacobian_evals as f64);
            values.set_real(vr::ACCURACY_LOSS, solver.accuracy_loss());
            values.set_real(vr::INACCURATE_STEPS, stats.inaccurate_steps as f64);
        }
    }

    /// The model and its integrator as numbers, for FMU state serialisation: the model's head
    /// ([`Model::head`]), its ODE state, the integrator's state.
    pub fn save(&self) -> Vec<f64> {
        let solver = self.solver().map(Radau5::save_state).unwrap_or_default();
        [&self.model.head()[..], self.model.state(), &solver].concat()
    }

    /// Restores a model saved by [`Driven::save`] under the given variable values.
    pub fn load(values: &Values, saved: &[f64]) -> Result<Self, String> {
        let (head, state, saved_solver) = match saved.len() == M::HEAD {
            true => (saved, &[][..], None),
            false if M::CLOSED_FORM => return Err(format!("{} numbers are no saved model state", saved.len())),
            false => split_saved(saved, M::HEAD).map(|(h, s, v)| (h, s, Some(v)))?,
        };
        let model = M::restore(values, head, state)?;
        if model.state().len() != state.len() {
            return Err(format!("{} numbers are no saved model state", saved.len()));
        }
        let solver = match saved_solver {
            Some(v) => {
                let mut solver = Radau5::new(state.len());
                solver.load_state(v).map_err(|e| e.to_string())?;
                Some(solver)
            }
            None => None,
        };
        let work = vec![0.0; state.len()];
        Ok(Driven { model, solver, work })
    }
}

/// Most event indicators a model may declare (the circuit has 3): kept on the stack.
pub const MAX_EVENT_INDICATORS: usize = 8;
/// Most intermediate inputs a model may declare (the circuit has 3), checked at compile time.
pub const MAX_INTERMEDIATE_INPUTS: usize = 4;

/// A master that sets inputs between communication points: FMI 3.0's intermediate update
/// (4.2.3), as the driver sees it.
pub trait Intermediate {
    /// Before an attempted integrator step, for each time at which it evaluates the model: the
    /// master's values of the inputs `vrs` at `t` into `out`.
    fn inputs(&mut self, t: f64, vrs: &[u32], out: &mut [f64]) -> Result<(), String>;

    /// After an accepted integrator step ending at `t`: the time at which the master asks the
    /// step to end, if it asks.
    fn accepted(&mut self, t: f64) -> Option<f64>;
}

/// Why a step ended before the end of its communication step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ended {
    pub t: f64,
    /// At a root of an event indicator (else where the master asked).
    pub event: bool,
}

/// The driver's watch of a step ([`Watch`]): the model's ODE, the search for event roots, the
/// master's intermediate update.
struct Watched<'a, 'b, M: Model> {
    ode: &'a mut M::Ode,
    roots: Option<Roots<'a, M>>,
    master: Option<&'b mut dyn Intermediate>,
    ended: Option<Ended>,
    /// The time the master asked the step to end at.
    requested: Option<f64>,
}

impl<M: Model> Watch for Watched<'_, '_, M> {
    type Ode = M::Ode;

    fn ode(&self) -> &M::Ode {
        self.ode
    }

    fn attempt(&mut self, t: f64, stages: [f64; 3]) {
        let Some(master) = self.master.as_mut() else { return };
        const { assert!(M::INTERMEDIATE_INPUTS.len() <= MAX_INTERMEDIATE_INPUTS) };
        let vrs = M::INTERMEDIATE_INPUTS;
        let mut u = [[0.0; MAX_INTERMEDIATE_INPUTS]; 3];
        for (&ts, u) in stages.iter().zip(&mut u) {
            // A failed call leaves the inputs as they were: the instance is Terminated, the
            // master's error logged, and the step fails when it ends.
            if master.inputs(ts, vrs, &mut u[..vrs.len()]).is_err() {
                return;
            }
        }
        let [a, b, c] = &u;
        M::intermediate_inputs(self.ode, t, &[(stages[0], &a[..]), (stages[1], &b[..]), (stages[2], &c[..])]);
    }

    /// An event root first; else the master, told of the accepted step, may ask for an end
    /// (within this step: there; later: at the step that reaches it; before it: at its start).
    fn accepted(&mut self, dense: &Dense<'_>) -> Option<f64> {
        if let Some(t) = self.roots.as_mut().and_then(|r| r.first(self.ode, dense)) {
            self.ended = Some(Ended { t, event: true });
            return Some(t);
        }
        let (a, b) = dense.span();
        if let Some(t) = self.master.as_mut().and_then(|m| m.accepted(b)) {
            self.requested = Some(t);
        }
        let t = self.requested.filter(|&t| t <= b)?.max(a);
        self.ended = Some(Ended { t, event: false });
        Some(t)
    }
}

/// The search for the first root of a model's event indicators within a step.
struct Roots<'a, M: Model> {
    /// The indicators at the start of the integrator's current step.
    z: [f64; MAX_EVENT_INDICATORS],
    /// Work space: a state on the continuous output (the driver's, so that a step allocates
    /// nothing).
    x: &'a mut [f64],
    _model: std::marker::PhantomData<M>,
}

impl<'a, M: Model> Roots<'a, M> {
    const N: usize = {
        assert!(M::EVENT_INDICATORS.len() <= MAX_EVENT_INDICATORS);
        M::EVENT_INDICATORS.len()
    };

    /// The search over a step of `ode` from `t` with state `x`, in the work space `work`.
    fn new(ode: &M::Ode, t: f64, x: &[f64], work: &'a mut [f64]) -> Self {
        let mut z = [0.0; MAX_EVENT_INDICATORS];
        M::step_event_indicators(ode, t, x, &mut z[..Self::N]);
        Roots { z, x: work, _model: std::marker::PhantomData }
    }

    /// The indicators at `t` on `dense`.
    fn at(&mut self, ode: &M::Ode, dense: &Dense<'_>, t: f64) -> [f64; MAX_EVENT_INDICATORS] {
        let mut z = [0.0; MAX_EVENT_INDICATORS];
        dense.at(t, self.x);
        M::step_event_indicators(ode, t, &self.x, &mut z[..Self::N]);
        z
    }

    /// The first root within the integrator's step `dense`, if an indicator changed sign in it:
    /// the bracket [a, b] of the first sign change shrunk to [`ROOT_TOLERANCE`] by secant
    /// (regula falsi on the indicator that crosses first) and bisection steps in turn (so that
    /// it halves at least every second step), and its right end returned: there the indicators
    /// have their new signs. Without a change the step's end indicators start the next step.
    fn first(&mut self, ode: &M::Ode, dense: &Dense<'_>) -> Option<f64> {
        let (mut a, mut b) = dense.span();
        let (mut za, mut zb) = (self.z, self.at(ode, dense, b));
        if !crossed(&za[..Self::N], &zb[..Self::N]) {
            self.z = zb;
            return None;
        }
        let tolerance = ROOT_TOLERANCE * b.abs().max(1.0);
        let mut secant = true;
        while b - a > tolerance {
            let w = b - a;
            let m = match secant {
                true => za[..Self::N]
                    .iter()
                    .zip(&zb[..Self::N])
                    .filter(|(&za, &zb)| crossed(&[za], &[zb]))
                    .map(|(&za, &zb)| a + w * za / (za - zb))
                    .fold(b, f64::min)
                    .clamp(a + 0.01 * w, b - 0.01 * w),
                false => a + 0.5 * w,
            };
            secant = !secant;
            let zm = self.at(ode, dense, m);
            if crossed(&za[..Self::N], &zm[..Self::N]) {
                (b, zb) = (m, zm);
            } else {
                (a, za) = (m, zm);
            }
        }
        self.z = zb;
        Some(b)
    }
}

/// How closely an event's time is located, relative to max(|t|, 1 s): a few hundred ulps.
pub const ROOT_TOLERANCE: f64 = 1e-13;

/// Whether some indicator changed sign from `before` to `after`, or reached 0 from a sign (one
/// that stays at 0, as the spool reference at rest, is no event).
fn crossed(before: &[f64], after: &[f64]) -> bool {
    before.iter().zip(after).any(|(&p, &q)| p * q < 0.0 || (p != 0.0 && q == 0.0))
}

/// A saved model's parts: head, state, integrator state.
type Saved<'a> = (&'a [f64], &'a [f64], &'a [f64]);

/// The parts of a model saved with `n_head` leading numbers: the state dimension n is the one
/// for which head + n + the integrator's saved length add up to the total.
fn split_saved(saved: &[f64], n_head: usize) -> Result<Saved<'_>, String> {
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
