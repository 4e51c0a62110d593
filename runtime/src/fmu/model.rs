//! The model contract: what a physics model provides so that [`crate::fmi2`] and
//! [`crate::fmi3`] can export it as Model Exchange (its continuous states, their derivatives, its
//! outputs, its event indicators) and as Co-Simulation (its ODE, which the one driver,
//! [`super::driver`], integrates).

use super::driver::Step;
use super::variables::{Causality, Initial, Kind, Value, Values, Variable};
use crate::solver::OdeSystem;

/// Static facts about a model, written to modelDescription.xml.
#[derive(Debug, Clone, Copy)]
pub struct ModelInfo {
    /// modelIdentifier: the .so name and the cdylib's `lib.name`.
    pub identifier: &'static str,
    pub description: &'static str,
    /// Model version; part of the GUID.
    pub version: &'static str,
    /// DefaultExperiment: start, stop, step size.
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
    /// Relative tolerance used when fmi2SetupExperiment defines none.
    pub default_tolerance: f64,
    /// The model's own log categories (name, description), beside the generic ones.
    pub log_categories: &'static [(&'static str, &'static str)],
    /// The Real inputs whose first derivative (fmi2SetRealInputDerivatives) doStep uses;
    /// `canInterpolateInputs` when there is one. Derivatives of other inputs are refused.
    pub interpolated_inputs: &'static [u32],
    /// HTML fragment for documentation/index.html: equations, sources, notes.
    pub documentation: &'static str,
    /// The ports an importer connects as a whole (terminalsAndIcons.xml of the FMI 3.0 .fmu).
    pub terminals: &'static [Terminal],
}

/// A terminal (FMI 3.0, section 2.4.9, "Terminals"): variables grouped into a port that an
/// importer connects to a terminal of another FMU member by member. Every member is a signal
/// (`variableKind="signal"`: connected values are equal; an output drives the input of the same
/// `memberName`, a parameter is set equal on both sides).
#[derive(Debug, Clone, Copy)]
pub struct Terminal {
    pub name: &'static str,
    /// `terminalKind`: vendor-specific kinds start with "_boomsim_" (the standard's advice).
    pub kind: &'static str,
    /// `matchingRule`: "plug" (every member present and matched by `memberName`).
    pub matching_rule: &'static str,
    pub description: &'static str,
    /// (`memberName`, value reference of the member variable).
    pub members: &'static [(&'static str, u32)],
}

impl ModelInfo {
    /// `canInterpolateInputs`: some input is linear over a step with its derivative.
    pub const fn can_interpolate_inputs(&self) -> bool {
        !self.interpolated_inputs.is_empty()
    }
}

/// A continuous state of Model Exchange: the value references of the state variable and of its
/// derivative (`der(...)`, a local Real), and the state's nominal value (its typical magnitude:
/// fmi2GetNominalsOfContinuousStates; importers scale absolute tolerances with it).
#[derive(Debug, Clone, Copy)]
pub struct ContinuousState {
    pub state: u32,
    pub derivative: u32,
    pub nominal: f64,
}

/// A failed step: how far the model got and why.
#[derive(Debug, Clone, PartialEq)]
pub struct StepError {
    /// Time of the last good state the model now holds.
    pub time: f64,
    pub message: String,
}

/// The start of a Co-Simulation step from `t` to `t + h`: the variable values at `t` and the
/// first derivatives of the inputs (one per table row, zero unless set) where the model
/// interpolates them.
pub struct StepStart<'a> {
    pub values: &'a Values,
    pub input_derivatives: &'a [f64],
    pub t: f64,
    pub h: f64,
}

/// The arguments of a directional derivative: the knowns with their seeds, the unknowns, and
/// where the unknowns' sensitivities go (one per unknown).
pub struct Seeds<'a> {
    pub knowns: &'a [(u32, f64)],
    pub unknowns: &'a [u32],
    pub out: &'a mut [f64],
}

/// What a model says while it steps, routed to a log category by the FMI layer.
pub trait Log {
    /// Whether messages of a category are delivered (skip formatting them when not).
    fn enabled(&self, category: &str) -> bool;
    /// Logs an info message in one of the model's own categories.
    fn info(&mut self, category: &str, message: &str);
    /// Logs a warning.
    fn warning(&mut self, message: &str);
}

/// A model exported as an FMI 2.0 and 3.0 Model Exchange and Co-Simulation FMU.
///
/// The FMI layer owns the variable values (`Values`) and the state machine; the model holds its
/// continuous state and reads parameters and inputs from `Values`. Model Exchange hands
/// [`Model::STATES`] and [`Model::derivatives`] to the importer's integrator; Co-Simulation
/// hands [`Model::begin_step`]'s ODE to the driver ([`super::driver::Driven`]), which integrates
/// it with [`crate::solver`]. The two see the same equations; their coordinates differ where
/// a model says so ([`Model::Ode`]).
pub trait Model: Clone + Send + Sized + 'static {
    const INFO: ModelInfo;
    /// The variable table (unique value references across all types).
    const VARIABLES: &'static [Variable];
    /// The continuous states in the order of fmi2GetContinuousStates. FMI 2.0 fixes their number
    /// in modelDescription.xml, so it is the same for every parameter value.
    const STATES: &'static [ContinuousState];

    /// The event indicators' variables (Real locals), in the order of fmi2GetEventIndicators:
    /// functions of states and inputs whose sign changes where the right-hand side jumps.
    /// FMI 2.0 counts them (`numberOfEventIndicators`), FMI 3.0 lists them (`<EventIndicator>`).
    /// Default: none.
    const EVENT_INDICATORS: &'static [u32] = &[];

    /// Parameter settings that change the model's equations (rigid/flexible, port couplings):
    /// ModelStructure's dependencies hold in each. Default: the start values only.
    fn configurations() -> Vec<Vec<(u32, Value)>> {
        vec![vec![]]
    }

    /// Refuses parameter values Model Exchange cannot run (a co-simulation-only coupling), with
    /// the reason. Default: all can.
    fn model_exchange_check(_values: &Values) -> Result<(), String> {
        Ok(())
    }

    /// Builds the model from final parameter and input values at the end of initialisation
    /// (and, in initialisation mode, to compute initial outputs). Returns a message naming the
    /// offending variables when their combination is inconsistent.
    fn initialize(values: &Values) -> Result<Self, String>;

    /// Re-reads tunable parameters changed between steps; keeps the continuous state. Default:
    /// the model has no tunable parameters.
    fn retune(&mut self, _values: &Values) -> Result<(), String> {
        Ok(())
    }

    /// Writes outputs and locals from the current state and inputs.
    fn outputs(&self, values: &mut Values);

    /// Whether the state a Co-Simulation step reached is inside the model's domain (checked at
    /// every step end with the outputs, so O(1)); `Err` names the variable, its value and its valid
    /// range, and the step is not done. Default: every state is.
    fn in_domain(&self) -> Result<(), String> {
        Ok(())
    }

    /// Writes the continuous states ([`Model::STATES`] order).
    fn continuous_states(&self, x: &mut [f64]);

    /// Takes new continuous states (fmi2SetContinuousStates, all finite); refuses states outside
    /// the model's domain, naming the state, its value and its valid range. An integrator's
    /// trial states are not outside it: the hydraulic plants' equations are defined for every
    /// finite state (pressures below vacuum included, [`crate::hydraulics::line`]), so they take
    /// any (FMI 2.0, 2.1.3 lists fmi2Discard for "a function outside of its domain", which then
    /// does not arise; FMI 3.0, 3.2.1: fmi3Discard only "if the FMU rejects any of the state
    /// values").
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String>;

    /// Writes the states' time derivatives at the current states with the inputs of `values`.
    /// A non-finite value tells the importer to retry with a smaller step (fmi2Discard).
    fn derivatives(&self, values: &Values, dx: &mut [f64]);

    /// Whether [`Model::directional_derivative`] is provided (`providesDirectionalDerivative`).
    const DIRECTIONAL_DERIVATIVES: bool = false;

    /// fmi2GetDirectionalDerivative at the current states and inputs: for each unknown (an
    /// output or a `der()` variable) the sum over the knowns (states and inputs, with their
    /// seeds) of its partial derivative times the seed, by exact forward-mode differentiation.
    /// The FMI layer has checked the references; `Err` names what the model cannot differentiate.
    fn directional_derivative(&self, _values: &Values, _seeds: Seeds<'_>) -> Result<(), String> {
        Err("providesDirectionalDerivative=\"false\"".into())
    }

    /// Writes the [`Model::EVENT_INDICATORS`] event indicators at the current states and inputs.
    fn event_indicators(&self, _values: &Values, _z: &mut [f64]) {}

    /// FMI 3.0 clocks (2.2.8.3): at an activation of the model's Clock, computes its model
    /// partition, the clocked states and outputs, from the previous values of the clocked states
    /// and the clocked inputs in `values` (f_disc and f_event). It may be called again in the same
    /// instant when the importer sets the inputs anew, so it always starts from the previous
    /// values. Default: the model has no Clock.
    fn evaluate_partition(&mut self, _values: &Values) {}

    /// The end of the instant of a Clock activation (fmi3UpdateDiscreteStates): the clocked
    /// states computed by [`Model::evaluate_partition`] become the previous values.
    fn update_previous(&mut self) {}

    /// The master set the variables `vrs` between two steps (inputs and tunable parameters,
    /// after [`Model::retune`]): a model that extrapolates an input takes a new value as a sample
    /// at the current time. Default: nothing to do.
    fn inputs_set(&mut self, _vrs: &[u32]) {}

    /// Whether the ODE of a step depends on nothing but the values at its start (no action at
    /// the communication point, no Clock). The driver may then integrate past the step's end,
    /// give the state there from the integrator's collocation polynomial, and continue from the
    /// step that passed it in the next doStep while no input changes: steps as long as the
    /// tolerance allows, not cut at each communication point. Default: no.
    const LOOKAHEAD: bool = false;

    /// The loosest relative tolerance a BDF integrator (CVode, DASSL) needs for the model in Model
    /// Exchange, as measured; an importer that sets a looser one gets a warning naming this one.
    /// Default: none (any tolerance).
    const MODEL_EXCHANGE_TOLERANCE: Option<f64> = None;

    /// The ODE Co-Simulation integrates: the same equations as [`Model::derivatives`], in the
    /// model's native coordinates (the rigid boom in its stroke, where Model Exchange exposes
    /// its angle; the flexible boom without the padded slots of Model Exchange's fixed layout).
    /// `()` for a model that steps in closed form.
    type Ode: OdeSystem;

    /// Co-Simulation: the [`Model::EVENT_INDICATORS`] of `ode` at time `t` and state `x` within
    /// a step (inputs following the step's ramps), where the driver looks for their roots to end
    /// a step early at an event (FMI 3.0, 4.2.3: early return). Default: none.
    fn step_event_indicators(_ode: &Self::Ode, _t: f64, _x: &[f64], _z: &mut [f64]) {}

    /// FMI 3.0 intermediate update (4.2.3): the Real inputs a master may set between
    /// communication points (`intermediateUpdate="true"`), each continuous over a step. Default:
    /// none (`providesIntermediateUpdate="false"`).
    const INTERMEDIATE_INPUTS: &'static [u32] = &[];

    /// Intermediate update: over the integrator's next attempted step from `t`, each of
    /// [`Model::INTERMEDIATE_INPUTS`] of `ode` takes the master's values at the step's stage
    /// times (`samples`: each time with the inputs in that order), linear between them from its
    /// value at `t` ([`super::super::models::port::Ramp::through`]).
    fn intermediate_inputs(_ode: &mut Self::Ode, _t: f64, _samples: &[(f64, &[f64]); 3]) {}

    /// Whether the model steps in closed form: no ODE state, [`Step::Done`] from every
    /// [`Model::begin_step`], and no integrator in its driver or its binary. Default: no.
    const CLOSED_FORM: bool = false;

    /// Co-Simulation, at the start of a step: takes the step's inputs and returns its ODE with
    /// its state for the driver to integrate, or steps itself in closed form ([`Step::Done`]).
    fn begin_step(&mut self, step: &StepStart<'_>, log: &mut dyn Log) -> Result<Step<'_, Self::Ode>, StepError>;

    /// Typical magnitude of each state of `ode` (absolute tolerance = rtol x scale). Default:
    /// none (a model without ODE state).
    fn scale(_ode: &Self::Ode) -> Vec<f64> {
        Vec::new()
    }

    /// After the driver reached the communication point `t`: what the model does there (the TLM
    /// port emits its wave). Default: nothing.
    fn communication_point(&mut self, _t: f64) {}

    /// The ODE state the driver integrates. Default: none (a model that steps in closed form).
    fn state(&self) -> &[f64] {
        &[]
    }

    /// The length of [`Model::head`].
    const HEAD: usize = 0;

    /// What a restored model needs beside its ODE state (time, port values, a closed-form
    /// model's whole state), for FMU states. Default: nothing.
    fn head(&self) -> Vec<f64> {
        Vec::new()
    }

    /// The model under the given variable values with a saved head and ODE state; refuses
    /// numbers that are no state of it.
    fn restore(values: &Values, head: &[f64], state: &[f64]) -> Result<Self, String>;
}

/// The table row of the model's Clock (FMI 3.0 only; at most one), if it has one: found at compile
/// time (it is asked on every step and output refresh).
pub fn clock_row<M: Model>() -> Option<usize> {
    const { clock_row_in(M::VARIABLES) }
}

/// Whether the model has Event Mode in FMI 3.0 Co-Simulation (`hasEventMode`): with a Clock
/// (required, 2.3.1) or event indicators (where a step may end early, 4.2.3).
pub const fn has_event_mode<M: Model>() -> bool {
    clock_row_in(M::VARIABLES).is_some() || !M::EVENT_INDICATORS.is_empty()
}

const fn clock_row_in(table: &[Variable]) -> Option<usize> {
    let mut i = 0;
    while i < table.len() {
        if matches!(table[i].kind, Kind::Clock { .. }) {
            return Some(i);
        }
        i += 1;
    }
    None
}

/// The activations of the model's Clock in an experiment from `start`: (the first, the interval)
/// (FMI 3.0, 2.2.8.2: t_i = t_start + shift + i interval).
pub fn activations<M: Model>(start: f64) -> Option<(f64, f64)> {
    match M::VARIABLES[clock_row::<M>()?].kind {
        Kind::Clock { interval, shift } => Some((start + shift, interval)),
        _ => None,
    }
}

/// How far a time may lie from an activation and still be on it, in intervals: far above the
/// rounding of a time summed from intervals, far below an interval.
pub const ACTIVATION_TOLERANCE: f64 = 1e-6;

/// FMI 2.0, 2.2.8 (FMI 3.0, 2.4.8 alike): whether `v` is an InitialUnknown of model `M`: an
/// output with initial approx or calculated, a calculated parameter, a continuous state with
/// initial approx or calculated, or a `der()` variable. Clocked variables are not listed (FMI 3.0,
/// 2.2.8.3: optional for them; fmpy's validation expects them absent).
pub fn initial_unknown<M: Model>(v: &Variable) -> bool {
    let state = M::STATES.iter().any(|s| s.state == v.vr && v.initial != Initial::Exact);
    let derivative = M::STATES.iter().any(|s| s.derivative == v.vr);
    derivative
        || state
        || (v.causality == Causality::Output && v.initial != Initial::Exact && !v.clocked)
        || v.causality == Causality::CalculatedParameter
}
