//! One FMU instance: variable values, model, time and state machine, in safe Rust.
//! [`super::api`] wraps these methods in the C ABI.

use super::driver::{Driven, Ended, Intermediate, MAX_EVENT_INDICATORS};
use super::log::{num, Logger, Status};
use super::machine::{Interface, Mode};
use super::model::{activations, clock_row, initial_unknown, Log, Model, Seeds, StepError, ACTIVATION_TOLERANCE};
use super::variables::{fmi_name, BaseType, Causality, Initial, Kind, Value, Values, Variability, Variable};
use super::version::Version;
use std::borrow::Cow;

/// Relative tolerance for matching the master's communication point with the instance time.
pub const TIME_MATCH_RTOL: f64 = 1e-9;

/// Relative tolerances the plants' integrator is used with: a tolerance of fmi2SetupExperiment
/// (fmi3EnterInitializationMode)
/// outside is clamped into it with a warning. Below 1e-12 the error estimates of a stiff solver
/// in f64 (unit round-off 1.1e-16, times the condition of the Newton matrices) are round-off;
/// above 1e-2 the error control no longer bounds a relative error worth the name.
pub const TOLERANCE_RANGE: (f64, f64) = (1e-12, 1e-2);

/// The value reference of the independent variable `time` of FMI 3.0 (FMI 3.0, 2.4.7.4: exactly
/// one variable has causality="independent"). It is not a row of the tables (FMI 2.0 declares
/// no independent variable), so it lies far above every table's references.
pub const INDEPENDENT_VR: u32 = 1_000_000;

/// FMI 3.0's intermediateUpdate callback (fmi3IntermediateUpdateCallback): instanceEnvironment,
/// intermediateUpdateTime, intermediateVariableSetRequested, intermediateVariableGetAllowed,
/// intermediateStepFinished, canReturnEarly, earlyReturnRequested, earlyReturnTime.
pub type IntermediateUpdate =
    unsafe extern "C" fn(*mut std::ffi::c_void, f64, bool, bool, bool, bool, *mut bool, *mut f64);

/// A master's intermediate update (FMI 3.0, 4.2.3): its callback and environment, and the
/// intermediate inputs it sets (`requiredIntermediateVariables`).
#[derive(Clone)]
pub struct Master {
    pub callback: IntermediateUpdate,
    pub environment: *mut std::ffi::c_void,
    pub inputs: Vec<u32>,
}

/// What a call did besides succeeding: a warning to log with status Warning.
pub type Warning = Option<String>;

/// A live instance. `#[repr(C)]` so that `magic` is first: it tells a boomsim instance of this
/// model from any other pointer an importer might pass.
#[repr(C)]
pub struct Instance<M: Model> {
    pub(crate) magic: u64,
    pub log: Logger,
    /// The FMI version the instance was created through (its function and type names).
    pub version: Version,
    /// Model Exchange or Co-Simulation, as instantiated.
    pub interface: Interface,
    /// FMI 3.0 Co-Simulation with Event Mode (`eventModeUsed`): initialisation ends in Event
    /// Mode, and fmi3EnterEventMode / fmi3EnterStepMode move between it and Step Mode.
    pub event_mode_used: bool,
    /// FMI 3.0 Co-Simulation with `earlyReturnAllowed`: a step ends early at the first root of
    /// the model's event indicators.
    pub early_return_allowed: bool,
    /// Where the last step ended before its communication step's end, at an event or where the
    /// master asked (FMI 3.0: `earlyReturn`; `eventHandlingNeeded` for an event with Event Mode).
    pub ended: Option<Ended>,
    /// FMI 3.0 Co-Simulation: the master's intermediate update, if it provides one.
    pub master: Option<Master>,
    /// In Intermediate Update Mode: whether the master may set the intermediate inputs now.
    pub set_requested: bool,
    pub core: Core<M>,
    /// Storage behind the pointers the last fmi2GetString / fmi3GetString returned.
    pub(crate) strings: Vec<std::ffi::CString>,
    /// The model's GUID (FMI 3.0: instantiation token), computed once at instantiation (FMU state
    /// bytes carry it, so a state of one version is refused by the other).
    pub guid: String,
    /// Per table row: whether it is the `der()` variable of a continuous state.
    pub(crate) derivative_rows: Vec<bool>,
    /// The FMU states this instance allocated and the importer has not freed yet; freed with the
    /// instance (FMI 2.0, 2.1.5; FMI 3.0, 2.3.1: freeing the instance frees all its memory).
    pub(crate) fmu_states: Vec<*mut Core<M>>,
}

/// Everything an FMU state captures: the instance less its name and logger.
#[derive(Clone)]
pub struct Core<M: Model> {
    pub mode: Mode,
    pub values: Values,
    /// First derivatives of Real inputs (fmi2SetRealInputDerivatives), per table row.
    pub input_derivatives: Vec<f64>,
    /// The model with the driver's integrator, built when initialisation ends; boxed, so that a
    /// doStep that takes it out of the instance and puts it back ([`Instance::begin_step`])
    /// moves a pointer, not the model (with the flexible arm, copying it was 15 % of a doStep).
    pub model: Option<Box<Driven<M>>>,
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    pub last_successful_time: f64,
    /// The activations of the model's Clock made since initialisation: the index of the one due
    /// next (FMI 3.0, 2.2.8.2: a periodic Clock is activated once at each of its times).
    pub activations: u64,
    /// Whether outputs reflect the current state and inputs.
    pub outputs_current: bool,
    /// Whether the `der()` variables do too (computed when one is read: a Co-Simulation step
    /// does not pay a right-hand side for values few importers read).
    pub derivatives_current: bool,
}

impl<M: Model> Core<M> {
    /// The state right after fmi2Instantiate: start values, time 0.
    pub fn new() -> Self {
        Core {
            mode: Mode::Instantiated,
            values: Values::new(M::VARIABLES),
            input_derivatives: vec![0.0; M::VARIABLES.len()],
            model: None,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            tolerance: None,
            last_successful_time: 0.0,
            activations: 0,
            outputs_current: false,
            derivatives_current: false,
        }
    }
}

impl<M: Model> Default for Core<M> {
    fn default() -> Self {
        Self::new()
    }
}

/// The time of activation `k` (from 0) of the model's Clock in an experiment from `start`, and
/// how far a time may lie from it and still be on it: [`ACTIVATION_TOLERANCE`] of the interval,
/// or four ulps of the time where those are more (a start time of 1e9 s: 0.9 us); `None`
/// without a Clock.
pub(crate) fn activation<M: Model>(start: f64, k: u64) -> Option<(f64, f64)> {
    let (first, interval) = activations::<M>(start)?;
    let t = first + k as f64 * interval;
    Some((t, (ACTIVATION_TOLERANCE * interval).max(4.0 * f64::EPSILON * t.abs())))
}

/// Why the Clock's activation `k`, due at `due`, cannot be passed: the importer has not made it.
fn skipped<M: Model>(k: u64, due: f64, what: &str) -> String {
    let clock = clock_row::<M>().map_or("", |i| M::VARIABLES[i].name);
    format!(
        "{what} would skip activation {} of Clock \"{clock}\" at t = {}, which was not made: at each of its times the \
         importer enters Event Mode, activates it (fmi3SetClock) and ends the instant (fmi3UpdateDiscreteStates) \
         (FMI 3.0, 2.2.8.2: a periodic Clock is activated at every one of its times)",
        k + 1,
        num(due)
    )
}

/// Whether two values are the same bit for bit (0.0 and -0.0 differ: a model may tell them apart).
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Real(x), Value::Real(y)) => x.to_bits() == y.to_bits(),
        _ => a == b,
    }
}

/// Whether the model's Clock is active.
fn clock_active<M: Model>(values: &Values) -> bool {
    clock_row::<M>().is_some_and(|i| *values.at(i) == Value::Clock(true))
}

/// Writes the outputs and locals of `model` (the integrator's counters and the event indicators'
/// variables included).
fn write_outputs<M: Model>(model: &Driven<M>, values: &mut Values) {
    model.outputs(values);
    const { assert!(M::EVENT_INDICATORS.len() <= MAX_EVENT_INDICATORS) };
    let z = &mut [0.0; MAX_EVENT_INDICATORS][..M::EVENT_INDICATORS.len()];
    model.event_indicators(values, z);
    for (&r, &z) in M::EVENT_INDICATORS.iter().zip(z.iter()) {
        values.set_real(r, z);
    }
}

/// The values a model built from `values` starts with: the values with its outputs, locals,
/// continuous states and their derivatives written (the InitialUnknowns among them).
pub(crate) fn start_values<M: Model>(values: &Values) -> Result<Values, String> {
    let model = Driven::new(M::initialize(values)?);
    let mut v = values.clone();
    write_outputs(&model, &mut v);
    let mut x = vec![0.0; M::STATES.len()];
    model.continuous_states(&mut x);
    let mut dx = vec![0.0; M::STATES.len()];
    model.derivatives(values, &mut dx);
    for ((s, x), d) in M::STATES.iter().zip(x).zip(dx) {
        v.set_real(s.state, x);
        v.set_real(s.derivative, d);
    }
    Ok(v)
}

/// The values of `unknowns` (InitialUnknowns) that a model built from `values` starts with.
fn initial_values<M: Model>(values: &Values, unknowns: &[u32]) -> Result<Vec<f64>, String> {
    let v = start_values::<M>(values)?;
    Ok(unknowns.iter().map(|&r| v.real(r)).collect())
}

/// A model-facing [`Log`] that writes through the instance logger.
struct ModelLog<'a>(&'a Logger);

impl Log for ModelLog<'_> {
    fn enabled(&self, category: &str) -> bool {
        self.0.category_enabled(category)
    }
    fn info(&mut self, category: &str, message: &str) {
        self.0.info(category, message);
    }
    fn warning(&mut self, message: &str) {
        self.0.status(Status::Warning, message);
    }
}

/// FNV-1a, for the per-model magic numbers.
const fn fnv1a(bytes: &[u8], seed: u64) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325 ^ seed;
    let mut i = 0;
    while i < bytes.len() {
        h ^= bytes[i] as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
        i += 1;
    }
    h
}

impl<M: Model> Instance<M> {
    /// Tag of a live instance of model `M` created through FMI `version`: an instance of one
    /// version passed to the other's functions is refused like any foreign pointer.
    pub const fn magic(version: Version) -> u64 {
        let seed = match version {
            Version::Fmi2 => 0x1157,
            Version::Fmi3 => 0x3157,
        };
        fnv1a(M::INFO.identifier.as_bytes(), seed)
    }

    /// A freshly instantiated instance.
    pub fn new(log: Logger, guid: String, version: Version, interface: Interface) -> Self {
        Instance {
            magic: Self::magic(version),
            log,
            version,
            interface,
            event_mode_used: false,
            early_return_allowed: false,
            ended: None,
            master: None,
            set_requested: false,
            core: Core::new(),
            strings: Vec::new(),
            guid,
            derivative_rows: M::VARIABLES.iter().map(|v| M::STATES.iter().any(|s| s.derivative == v.vr)).collect(),
            fmu_states: Vec::new(),
        }
    }

    /// fmi2SetupExperiment. A tolerance outside [`TOLERANCE_RANGE`] is clamped into it (warning);
    /// in Model Exchange, one looser than [`Model::MODEL_EXCHANGE_TOLERANCE`] is kept with a warning.
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Result<Warning, String> {
        if !start.is_finite() {
            return Err(format!("startTime = {} must be finite", num(start)));
        }
        let (lo, hi) = TOLERANCE_RANGE;
        let mut warning = None;
        let tolerance = match tolerance {
            Some(tol) if !(tol > 0.0 && tol.is_finite()) => {
                return Err(format!("tolerance = {} is not a relative tolerance (a finite number > 0)", num(tol)))
            }
            Some(tol) if !(lo..=hi).contains(&tol) => {
                let used = tol.clamp(lo, hi);
                warning = Some(format!(
                    "tolerance = {} is outside the integrator's range [{}, {}]; using {}",
                    num(tol),
                    num(lo),
                    num(hi),
                    num(used)
                ));
                Some(used)
            }
            tol => tol,
        };
        if let (Interface::ModelExchange, Some(tol), Some(needed)) =
            (self.interface, tolerance, M::MODEL_EXCHANGE_TOLERANCE)
        {
            if tol > needed {
                let looser = format!(
                    "tolerance = {} is looser than the {} this model needs in Model Exchange: BDF integrators such as \
                     CVode give wrong, even non-physical, pressures at looser ones (boomsim's docs/interfaces.md); set \
                     the tolerance to {} or less",
                    num(tol),
                    num(needed),
                    num(needed)
                );
                warning = Some(match warning {
                    Some(w) => format!("{w}; {looser}"),
                    None => looser,
                });
            }
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop >= start) {
                return Err(format!("stopTime = {} must be finite and >= startTime = {}", num(stop), num(start)));
            }
        }
        let c = &mut self.core;
        c.tolerance = tolerance;
        c.start_time = start;
        c.stop_time = stop;
        c.time = start;
        c.last_successful_time = start;
        Ok(warning)
    }

    /// fmi2EnterInitializationMode.
    pub fn enter_initialization_mode(&mut self) {
        self.core.mode = Mode::InitializationMode;
        self.core.outputs_current = false;
        self.core.derivatives_current = false;
    }

    /// fmi2ExitInitializationMode: builds the model from the final parameters and inputs; then
    /// Co-Simulation steps, Model Exchange is in Event Mode.
    pub fn exit_initialization_mode(&mut self) -> Result<(), String> {
        let c = &mut self.core;
        if self.interface == Interface::ModelExchange {
            M::model_exchange_check(&c.values)?;
        }
        let model = Driven::new(M::initialize(&c.values)?);
        write_outputs(&model, &mut c.values);
        c.model = Some(Box::new(model));
        c.outputs_current = true;
        c.derivatives_current = false;
        c.last_successful_time = c.time;
        c.mode = match self.interface {
            Interface::CoSimulation if !self.event_mode_used => Mode::StepComplete,
            _ => Mode::EventMode,
        };
        Ok(())
    }

    /// The model, built when initialisation ended.
    fn model(&mut self) -> Result<&mut Driven<M>, String> {
        self.core.model.as_deref_mut().ok_or_else(|| "the model is not initialised".to_string())
    }

    /// fmi2SetTime: the time of the next states and derivatives. A time past the stop time is
    /// accepted: variable-step integrators (CVode in fmpy) evaluate beyond their last output time
    /// and interpolate back, and the models are autonomous (time enters only through the
    /// inputs), so their equations hold at any time.
    pub fn set_time(&mut self, t: f64) -> Result<(), String> {
        if !(t >= self.core.start_time && t.is_finite()) {
            // FMI 3.0, 3.2.1 (fmi3SetTime): time "must be larger or equal to startTime"; FMI 2.0
            // alike: the model has no states before its start.
            return Err(format!(
                "time = {} is outside its valid range [{}, inf) (the start time)",
                num(t),
                num(self.core.start_time)
            ));
        }
        if let Some((due, near)) = activation::<M>(self.core.start_time, self.core.activations) {
            if t > due + near {
                return Err(skipped::<M>(self.core.activations, due, &format!("time = {}", num(t))));
            }
        }
        self.core.time = t;
        self.core.outputs_current = false;
        self.core.derivatives_current = false;
        Ok(())
    }

    /// The importer's `nx` against the number of continuous states.
    pub(crate) fn check_states(nx: usize) -> Result<(), String> {
        Self::check_count("nx", nx, M::STATES.len(), "continuous states")
    }

    /// An array length the importer announces (`what` = `n`) against the model's `expected` `of`.
    pub(crate) fn check_count(what: &str, n: usize, expected: usize, of: &str) -> Result<(), String> {
        if n == expected {
            return Ok(());
        }
        Err(format!("{what} = {n}, but {} has {expected} {of} (modelDescription.xml)", M::INFO.identifier))
    }

    /// `f` of the model: the one built at initialisation, or in Initialization Mode one built from
    /// the values set so far (the one fmi2ExitInitializationMode would start from).
    fn with_model<R>(&self, f: impl FnOnce(&M, &Values) -> R) -> Result<R, String> {
        let c = &self.core;
        match &c.model {
            Some(model) if c.mode != Mode::InitializationMode => Ok(f(model, &c.values)),
            _ => Ok(f(&M::initialize(&c.values)?, &c.values)),
        }
    }

    /// fmi2SetContinuousStates: all or nothing.
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        Self::check_states(x.len())?;
        if let Some(k) = x.iter().position(|x| !x.is_finite()) {
            return Err(format!("{} = {} is not a finite number", self.state_name(k), num(x[k])));
        }
        let model = self.model()?;
        let before = model.clone();
        if let Err(e) = model.set_continuous_states(x) {
            *model = before;
            return Err(e);
        }
        self.core.outputs_current = false;
        self.core.derivatives_current = false;
        Ok(())
    }

    /// The continuous states of the model built at initialisation.
    fn exposed_states(&self) -> Vec<f64> {
        let mut x = vec![0.0; M::STATES.len()];
        if let Some(m) = &self.core.model {
            m.continuous_states(&mut x);
        }
        x
    }

    /// fmi2GetContinuousStates (in Initialization Mode: those the values set so far give).
    pub fn continuous_states(&mut self, x: &mut [f64]) -> Result<(), String> {
        Self::check_states(x.len())?;
        self.with_model(|m, _| m.continuous_states(x))
    }

    /// fmi2GetEventIndicators (in Initialization Mode: those the values set so far give).
    pub fn event_indicators(&mut self, z: &mut [f64]) -> Result<(), String> {
        Self::check_count("ni", z.len(), self.event_indicator_count(), "event indicators")?;
        self.with_model(|m, values| m.event_indicators(values, z))
    }

    /// The number of event indicators (FMI 2.0 `numberOfEventIndicators`, FMI 3.0 the
    /// `<EventIndicator>` elements): [`Model::EVENT_INDICATORS`].
    pub fn event_indicator_count(&self) -> usize {
        M::EVENT_INDICATORS.len()
    }

    /// fmi2GetDerivatives (FMI 3.0 also in Initialization Mode: those the values set so far give).
    /// `Ok(Some(why))`: not finite at these states (status Discard).
    pub fn derivatives(&mut self, dx: &mut [f64]) -> Result<Warning, String> {
        Self::check_states(dx.len())?;
        if self.core.mode == Mode::InitializationMode {
            self.with_model(|m, values| m.derivatives(values, dx))?;
        } else {
            let model = self.core.model.as_ref().ok_or("the model is not initialised")?;
            model.derivatives(&self.core.values, dx);
        }
        Ok(dx.iter().position(|d| !d.is_finite()).map(|k| {
            format!(
                "der({}) = {} at t = {}: the states are outside the model's valid range; retry with a smaller step",
                self.state_name(k),
                num(dx[k]),
                num(self.core.time)
            )
        }))
    }

    /// fmi2GetDirectionalDerivative (FMI 2.0, 2.1.9; FMI 3.0, 2.3.11), by mode: in
    /// Initialization Mode the unknowns are the Real InitialUnknowns and the knowns the Real
    /// variables that may be set there (inputs, `initial="exact"` parameters and start values);
    /// after it the unknowns are the outputs and the `der()` variables of `<Derivatives>` (Step
    /// Mode too: "if <Derivatives> is present, also the variables listed here"), the knowns the
    /// Real inputs and, in Model Exchange, the continuous states.
    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seeds: &[f64],
        out: &mut [f64],
    ) -> Result<(), String> {
        let init = self.core.mode == Mode::InitializationMode;
        let me = self.interface == Interface::ModelExchange;
        for &vr in unknowns {
            let (i, v) = self.lookup(vr, BaseType::Real)?;
            let ok = if init {
                initial_unknown::<M>(v)
            } else {
                v.causality == Causality::Output || self.derivative_rows[i]
            };
            if !ok {
                let what = if init { "an InitialUnknown" } else { "an output or a derivative" };
                return Err(format!("unknown \"{}\" (vr {vr}) is not {what} of ModelStructure", v.name));
            }
        }
        for (&vr, &dv) in knowns.iter().zip(seeds) {
            let (_, v) = self.lookup(vr, BaseType::Real)?;
            let state = M::STATES.iter().any(|s| s.state == vr);
            let input = v.causality == Causality::Input;
            let ok = if init { settable(v, false, Mode::InitializationMode).is_ok() } else { input || (me && state) };
            if !ok {
                let what = match (init, me) {
                    (true, _) => "an input or a variable with initial=\"exact\"",
                    (false, true) => "an input or a continuous state",
                    (false, false) => "an input",
                };
                return Err(format!("known \"{}\" (vr {vr}) is not {what}", v.name));
            }
            if !dv.is_finite() {
                return Err(format!(
                    "{} of \"{}\" = {} is not a finite number",
                    self.version.argument("dvKnown"),
                    v.name,
                    num(dv)
                ));
            }
        }
        if init {
            self.initial_derivative(unknowns, knowns, seeds, out)?;
        } else {
            let model = self.core.model.as_ref().ok_or("the model is not initialised")?;
            let knowns: Vec<(u32, f64)> = knowns.iter().copied().zip(seeds.iter().copied()).collect();
            model.directional_derivative(&self.core.values, Seeds { knowns: &knowns, unknowns, out: &mut *out })?;
        }
        if let Some(k) = out.iter().position(|x| !x.is_finite()) {
            return Err(format!(
                "the derivative of \"{}\" is not finite at these states",
                self.name(unknowns[k]).unwrap_or("?")
            ));
        }
        Ok(())
    }

    /// The directional derivative in Initialization Mode, where the start state is computed
    /// from the parameters by [`Model::initialize`] (not a function of dual numbers): the sum
    /// over the seeded knowns of the seed times a difference quotient in that known (FMI 2.0,
    /// 2.1.9: "may compute the directional derivatives by numerical differentiation"). Central
    /// with a step of 6e-6 of the known's magnitude (cube root of the unit round-off: truncation
    /// and round-off errors balance at ~1e-10 relative; a known at or near 0 counts with a
    /// thousandth of its range), one-sided (error ~6e-6 relative) where it sits at a bound.
    fn initial_derivative(
        &self,
        unknowns: &[u32],
        knowns: &[u32],
        seeds: &[f64],
        out: &mut [f64],
    ) -> Result<(), String> {
        let values = &self.core.values;
        out.fill(0.0);
        let mut base = None;
        for (&r, &seed) in knowns.iter().zip(seeds).filter(|(_, d)| **d != 0.0) {
            let (i, var) = self.lookup(r, BaseType::Real)?;
            let (x, width) = match var.kind {
                Kind::Real { min, max, .. } if (max - min).is_finite() => (values.real(r), 1e-3 * (max - min)),
                _ => (values.real(r), 1.0),
            };
            let h = f64::EPSILON.cbrt() * x.abs().max(width);
            let at = |x: f64| -> Result<Vec<f64>, String> {
                let x = Value::Real(x);
                in_range(var, &x)?;
                let mut v = values.clone();
                v.put(i, x);
                initial_values::<M>(&v, unknowns)
            };
            let (hi, lo, span) = match (at(x + h), at(x - h)) {
                (Ok(p), Ok(m)) => (p, m, 2.0 * h),
                (Ok(p), Err(_)) => (p, base.get_or_insert(initial_values::<M>(values, unknowns)?).clone(), h),
                (Err(_), Ok(m)) => (base.get_or_insert(initial_values::<M>(values, unknowns)?).clone(), m, h),
                (Err(e), Err(_)) => return Err(format!("no start state near these values: {e}")),
            };
            for ((o, a), b) in out.iter_mut().zip(hi).zip(lo) {
                *o += seed * (a - b) / span;
            }
        }
        Ok(())
    }

    /// The name of the `k`-th continuous state.
    fn state_name(&self, k: usize) -> &'static str {
        self.name(M::STATES[k].state).unwrap_or("?")
    }

    /// Brings outputs up to date before a get. A value that is not finite is refused by the get
    /// that asks for it, not by the read of another variable: a step never ends on one
    /// ([`Instance::end_step`]), but a value set since may lead to one.
    fn refresh_outputs(&mut self) -> Result<(), String> {
        self.write_current_outputs().map(drop)
    }

    /// Writes the outputs unless they are current: the table index of the first Real written
    /// that is not a finite number.
    fn write_current_outputs(&mut self) -> Result<Option<usize>, String> {
        let c = &mut self.core;
        if c.outputs_current {
            return Ok(None);
        }
        c.values.take_non_finite();
        if c.mode == Mode::InitializationMode {
            // Initial outputs follow from the values set so far.
            write_outputs(&Driven::new(M::initialize(&c.values)?), &mut c.values);
        } else if let Some(model) = c.model.as_mut() {
            if clock_active::<M>(&c.values) {
                model.evaluate_partition(&c.values);
            }
            write_outputs(model, &mut c.values);
        }
        c.outputs_current = true;
        c.derivatives_current = false;
        Ok(c.values.take_non_finite())
    }

    /// Writes the outputs of the state a step reached; `Err` names what left the model's domain
    /// ([`Model::in_domain`]) or the first Real that is not a finite number: such a step is not
    /// done.
    fn outputs_at_step_end(&mut self) -> Result<(), String> {
        let non_finite = self.write_current_outputs()?;
        let c = &mut self.core;
        let outside = c.model.as_ref().map_or(Ok(()), |m| m.in_domain());
        if non_finite.is_none() && outside.is_ok() {
            return Ok(());
        }
        c.outputs_current = false;
        let Some(i) = non_finite else {
            return Err(format!("{} at t = {}", outside.err().unwrap_or_default(), num(c.time)));
        };
        let x = if let Value::Real(x) = c.values.at(i) { *x } else { f64::NAN };
        Err(format!("{} = {} at t = {}: the model left its valid range", M::VARIABLES[i].name, num(x), num(c.time)))
    }

    /// Writes the `der()` variables from the current states and inputs (in Initialization Mode,
    /// those the values set so far give).
    fn refresh_derivatives(&mut self) -> Result<(), String> {
        let mut dx = vec![0.0; M::STATES.len()];
        self.with_model(|m, values| m.derivatives(values, &mut dx))?;
        for (s, d) in M::STATES.iter().zip(dx) {
            self.core.values.set_real(s.derivative, d);
        }
        self.core.derivatives_current = true;
        Ok(())
    }

    /// Looks up a value reference and checks its type.
    fn lookup(&self, vr: u32, wanted: BaseType) -> Result<(usize, &'static Variable), String> {
        let (i, v) = self.variable(vr)?;
        if self.version.accessed_as(v.base_type()) != wanted {
            return Err(self.type_mismatch(vr, self.version.type_name(wanted)));
        }
        Ok((i, v))
    }

    /// The table row of a value reference.
    fn variable(&self, vr: u32) -> Result<(usize, &'static Variable), String> {
        if self.version == Version::Fmi3 && vr == INDEPENDENT_VR {
            return Err(format!(
                "\"time\" (vr {vr}) is the independent variable, a Float64 that can only be read (fmi3EnterInitializationMode, fmi3SetTime and fmi3DoStep move it)"
            ));
        }
        let i = self
            .core
            .values
            .position(vr)
            .ok_or_else(|| format!("unknown value reference {vr}: {} has no such variable", M::INFO.identifier))?;
        Ok((i, &M::VARIABLES[i]))
    }

    /// Why `vr` cannot be accessed as a `wanted` (a type name of this version): unknown, or of
    /// another type.
    pub fn type_mismatch(&self, vr: u32, wanted: &str) -> String {
        match self.variable(vr) {
            Err(e) => e,
            Ok((_, v)) => {
                format!(
                    "variable \"{}\" (vr {vr}) is a {}, not a {wanted}",
                    v.name,
                    self.version.type_name(v.base_type())
                )
            }
        }
    }

    /// Reads values of one type: `read` converts a stored value.
    pub fn get<T>(
        &mut self,
        vrs: &[u32],
        out: &mut [T],
        wanted: BaseType,
        read: impl Fn(&Value) -> T,
    ) -> Result<(), String> {
        self.refresh_outputs()?;
        for (k, &vr) in vrs.iter().enumerate() {
            if self.version == Version::Fmi3 && vr == INDEPENDENT_VR && wanted == BaseType::Real {
                out[k] = read(&Value::Real(self.core.time));
                continue;
            }
            let (i, v) = self.lookup(vr, wanted)?;
            self.clocked_access(v)?;
            if self.derivative_rows[i] && !self.core.derivatives_current {
                self.refresh_derivatives()?;
            }
            let value = self.core.values.at(i);
            if let Value::Real(x) = value {
                // Never a non-finite value with fmi2OK (a model evaluated outside its range).
                if !x.is_finite() {
                    return Err(format!(
                        "{} = {} at t = {} is not a finite number",
                        v.name,
                        num(*x),
                        num(self.core.time)
                    ));
                }
            }
            out[k] = read(value);
        }
        Ok(())
    }

    /// Writes values, all or nothing: every value is checked (type, settability, range) before
    /// any is stored.
    pub fn set(&mut self, vrs: &[u32], wanted: BaseType, new: Vec<Value>) -> Result<(), String> {
        let mut checked = Vec::with_capacity(vrs.len());
        let mut states: Option<Vec<f64>> = None;
        for (&vr, value) in vrs.iter().zip(new) {
            let (i, v) = self.lookup(vr, wanted)?;
            self.clocked_access(v)?;
            let state = M::STATES.iter().position(|s| s.state == vr);
            match self.core.mode {
                Mode::IntermediateUpdate => self.intermediate_settable(v)?,
                mode => settable(v, state.is_some(), mode)?,
            }
            in_range(v, &value)?;
            if let (Mode::ContinuousTimeMode, Some(k), Value::Real(x)) = (self.core.mode, state, &value) {
                let x0 = states.get_or_insert_with(|| self.exposed_states());
                x0[k] = *x;
            }
            checked.push((i, value));
        }
        if let Some(x) = states {
            // FMI 2.0, 3.2.3 rule 5: a continuous-time state set by its value reference is a new
            // state, as fmi2SetContinuousStates would set it (checked by the model the same way,
            // and refused the same way: nothing is set).
            self.set_continuous_states(&x)?;
        }
        let tunes = matches!(self.core.mode, Mode::StepComplete | Mode::EventMode)
            && checked.iter().any(|&(i, _)| M::VARIABLES[i].causality == Causality::Parameter);
        let before = tunes.then(|| self.core.values.clone());
        let mut changed = false;
        for (i, value) in checked {
            changed |= !same(self.core.values.at(i), &value);
            self.core.values.put(i, value);
        }
        if let Some(before) = before {
            let c = &mut self.core;
            if let Err(e) = c.model.as_mut().map_or(Ok(()), |m| m.retune(&c.values)) {
                c.values = before;
                return Err(e);
            }
        }
        if let Some(model) = self.core.model.as_mut() {
            if self.core.mode == Mode::StepComplete {
                model.inputs_set(vrs);
            }
            if changed {
                model.inputs_changed();
            }
        }
        self.core.outputs_current = false;
        self.core.derivatives_current = false;
        Ok(())
    }

    /// FMI 3.0, 4.2.3: in Intermediate Update Mode the master sets the intermediate inputs it
    /// required, and only when the callback requests them (`intermediateVariableSetRequested`).
    fn intermediate_settable(&self, v: &Variable) -> Result<(), String> {
        let inputs = self.master.as_ref().map_or(&[][..], |m| &m.inputs[..]);
        if !inputs.contains(&v.vr) {
            let names: Vec<&str> = inputs.iter().filter_map(|&r| self.name(r)).collect();
            return Err(format!(
                "cannot set \"{}\" in Intermediate Update Mode: only the requiredIntermediateVariables of \
                 fmi3InstantiateCoSimulation may be set there ({}; FMI 3.0, 4.2.3)",
                v.name,
                if names.is_empty() { "none".to_string() } else { names.join(", ") }
            ));
        }
        if !self.set_requested {
            return Err(format!(
                "cannot set \"{}\" now: this intermediate update did not request inputs \
                 (intermediateVariableSetRequested = false; FMI 3.0, 4.2.3)",
                v.name
            ));
        }
        Ok(())
    }

    /// FMI 3.0, 2.2.8.3: a clocked variable is set and read only while its Clock is active, or in
    /// Initialization Mode (and before it, where its start value may be set).
    fn clocked_access(&self, v: &Variable) -> Result<(), String> {
        let before = matches!(self.core.mode, Mode::Instantiated | Mode::InitializationMode);
        if !v.clocked || before || clock_active::<M>(&self.core.values) {
            return Ok(());
        }
        let clock = clock_row::<M>().map_or("", |i| M::VARIABLES[i].name);
        Err(format!(
            "\"{}\" is clocked by \"{clock}\", which is not active: a clocked variable is set and read only while its \
             Clock is active (fmi3SetClock in Event Mode) or in Initialization Mode (FMI 3.0, 2.2.8.3)",
            v.name
        ))
    }

    /// Whether the model's Clock is active.
    pub fn clock_active(&self) -> bool {
        clock_active::<M>(&self.core.values)
    }

    /// fmi3SetClock: activates the model's input Clock for this instant of Event Mode, at one of
    /// its times (FMI 3.0, 2.2.8.2; within [`ACTIVATION_TOLERANCE`]). It cannot be deactivated
    /// (`canBeDeactivated="false"`): fmi3UpdateDiscreteStates does that (FMI 3.0, 2.3.5).
    pub fn set_clocks(&mut self, vrs: &[u32], active: &[bool]) -> Result<(), String> {
        let mut rows = Vec::with_capacity(vrs.len());
        for (&vr, &on) in vrs.iter().zip(active) {
            let (i, v) = self.lookup(vr, BaseType::Clock)?;
            if !on {
                return Err(format!(
                    "cannot deactivate Clock \"{}\": it has canBeDeactivated=\"false\"; fmi3UpdateDiscreteStates \
                     deactivates it (FMI 3.0, 2.3.5)",
                    v.name
                ));
            }
            if *self.core.values.at(i) == Value::Clock(true) {
                continue; // set again in the same instant: the same activation
            }
            let (t, start) = (self.core.time, self.core.start_time);
            let (first, interval) = activations::<M>(start).ok_or("no Clock")?;
            let k = ((t - first) / interval).round().max(0.0) as u64;
            let on = activation::<M>(start, k).is_some_and(|(t_k, near)| (t - t_k).abs() <= near);
            if !on {
                return Err(format!(
                    "Clock \"{}\" activated at t = {}, which is none of its times {} + i {} s, i = 0, 1, ... (a \
                     constant Clock, FMI 3.0, 2.2.8.2)",
                    v.name,
                    num(t),
                    num(first),
                    num(interval)
                ));
            }
            let made = self.core.activations;
            if k < made {
                return Err(format!(
                    "Clock \"{}\" was activated at t = {} already (activation {}); a periodic Clock is activated once \
                     at each of its times (FMI 3.0, 2.2.8.2), so this would advance its model partition twice",
                    v.name,
                    num(t),
                    k + 1
                ));
            }
            if k > made {
                let due = first + made as f64 * interval;
                return Err(skipped::<M>(made, due, &format!("activating Clock \"{}\" at t = {}", v.name, num(t))));
            }
            if !rows.contains(&i) {
                rows.push(i);
            }
        }
        for i in rows {
            self.core.values.put(i, Value::Clock(true));
            self.core.activations += 1;
        }
        self.core.outputs_current = false;
        Ok(())
    }

    /// The interval and shift of the Clock `vr` (its constant timing).
    pub fn clock_timing(&self, vr: u32) -> Result<(f64, f64), String> {
        match self.lookup(vr, BaseType::Clock)?.1.kind {
            Kind::Clock { interval, shift } => Ok((interval, shift)),
            _ => Err(self.type_mismatch(vr, "Clock")),
        }
    }

    /// fmi3UpdateDiscreteStates: ends the instant. With the Clock active, its model partition is
    /// computed (if no read did it) and its clocked states become the previous values, and the
    /// Clock is deactivated (FMI 3.0, 2.3.5).
    pub fn update_discrete_states(&mut self) -> Result<(), String> {
        let Some(row) = clock_row::<M>().filter(|_| clock_active::<M>(&self.core.values)) else {
            return Ok(());
        };
        self.refresh_outputs()?;
        self.model()?.update_previous();
        self.core.values.put(row, Value::Clock(false));
        self.core.outputs_current = false;
        Ok(())
    }

    /// fmi2SetRealInputDerivatives (first order only), for the inputs the model interpolates.
    pub fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Result<(), String> {
        let info = &M::INFO;
        if !info.can_interpolate_inputs() {
            return Err(format!("{} does not interpolate inputs (canInterpolateInputs=\"false\")", info.identifier));
        }
        let mut checked = Vec::with_capacity(vrs.len());
        for ((&vr, &order), &d) in vrs.iter().zip(orders).zip(values) {
            let (i, v) = self.lookup(vr, BaseType::Real)?;
            if !info.interpolated_inputs.contains(&vr) {
                let names: Vec<&str> = info.interpolated_inputs.iter().filter_map(|&r| self.name(r)).collect();
                return Err(format!(
                    "variable \"{}\" has no derivative in {}; derivatives can be set for {}",
                    v.name,
                    info.identifier,
                    names.join(", ")
                ));
            }
            if order != 1 {
                return Err(format!("derivative order {order} of \"{}\" is outside its valid range [1, 1]", v.name));
            }
            if !d.is_finite() {
                return Err(format!("derivative of \"{}\" = {d} must be finite", v.name));
            }
            checked.push((i, d));
        }
        for (i, d) in checked {
            self.core.input_derivatives[i] = d;
        }
        Ok(())
    }

    /// The name of a value reference.
    fn name(&self, vr: u32) -> Option<&'static str> {
        self.core.values.position(vr).map(|i| M::VARIABLES[i].name)
    }

    /// fmi2DoStep. `Ok(Step::Done(warning))`: step done; `Ok(Step::Discarded(why))`: stopped
    /// at the last good time.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<Step, String> {
        let mut begun = self.begin_step(t, h)?;
        let c = &self.core;
        let result = begun.run((&c.values, &c.input_derivatives), &mut ModelLog(&self.log), None);
        self.end_step(begun, result)
    }

    /// The start of doStep: the checks of its arguments, and the step's inputs with the model,
    /// which leaves the instance until [`Instance::end_step`] (so that the instance can be called
    /// while the step runs: FMI 3.0 intermediate update).
    pub fn begin_step(&mut self, t: f64, h: f64) -> Result<Begun<M>, String> {
        self.ended = None;
        let c = &mut self.core;
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!("communicationStepSize = {} is outside its valid range (0, inf)", num(h)));
        }
        let eps = TIME_MATCH_RTOL * c.time.abs().max(1.0);
        if !((t - c.time).abs() <= eps) {
            return Err(format!(
                "currentCommunicationPoint = {} does not match the instance time {} (tolerance {})",
                num(t),
                num(c.time),
                num(eps)
            ));
        }
        if let Some(stop) = c.stop_time {
            if t + h > stop + TIME_MATCH_RTOL * stop.abs().max(1.0) {
                return Err(format!(
                    "a step to t = {} would pass the stop time {} set in {}",
                    num(t + h),
                    num(stop),
                    self.version.function("fmi2SetupExperiment")
                ));
            }
        }
        if let Some((due, near)) = activation::<M>(c.start_time, c.activations) {
            if c.time >= due - near {
                return Err(skipped::<M>(c.activations, due, &format!("a step from t = {}", num(t))));
            }
            if t + h > due + near {
                return Err(format!(
                    "a step to t = {} would pass the Clock's activation at t = {}: step to it and activate the \
                     Clock in Event Mode (FMI 3.0, 2.2.8.2: the importer activates a time-based Clock at its times)",
                    num(t + h),
                    num(due)
                ));
            }
        }
        let tolerance = c.tolerance.unwrap_or(M::INFO.default_tolerance);
        // The model steps from the instance's own clock to the master's t + h: a master that
        // accumulates t_k + h instead of k h (rounding-level differences, accepted above) then
        // still continues exactly where the last step ended, so results do not depend on it.
        let (start, end) = (c.time, t + h);
        if end <= start {
            return Err(format!(
                "communicationStepSize = {} does not advance the instance time {}",
                num(h),
                num(start)
            ));
        }
        let model = c.model.take().ok_or("the model is not initialised")?;
        let (slopes, warning) =
            bounded_slopes(&c.values, &c.input_derivatives, M::INFO.interpolated_inputs, end - start);
        Ok(Begun {
            // FMI 3.0, 2.2.4: after fmi3Discard "the FMU is in the same state as before the call".
            before: (self.version == Version::Fmi3).then(|| model.clone()),
            model,
            // Only a slope bounded to its input's range is the step's own (no allocation else).
            bounded: matches!(slopes, Cow::Owned(_)).then(|| slopes.into_owned()),
            warning,
            span: (t, h, start, end, tolerance),
            early_return: self.early_return_allowed && !M::EVENT_INDICATORS.is_empty(),
            reach: c.stop_time.unwrap_or(f64::INFINITY),
        })
    }

    /// The end of doStep: the model back in the instance at the time the step reached, the
    /// inputs there, the outputs.
    pub fn end_step(&mut self, begun: Begun<M>, result: Result<Option<Ended>, StepError>) -> Result<Step, String> {
        let Begun { model, before, bounded, warning, span: (t, h, start, end, _), .. } = begun;
        let c = &mut self.core;
        c.outputs_current = false;
        c.derivatives_current = false;
        if c.mode != Mode::StepComplete {
            // A call of the master's from intermediate update failed (the instance is Terminated).
            c.model = Some(before.unwrap_or(model));
            return Err(format!("the step from t = {} stopped: a call in intermediate update failed", num(t)));
        }
        let ended = match result {
            Ok(ended) => ended,
            Err(e) => {
                let why = format!(
                    "step from t = {} with h = {} stopped at t = {}: {}",
                    num(t),
                    num(h),
                    num(e.time),
                    e.message
                );
                if let Some(before) = before {
                    c.model = Some(before);
                    return Ok(Step::Discarded(format!(
                        "{why}; the instance is back at t = {} (retry with a smaller step)",
                        num(start)
                    )));
                }
                // FMI 2.0, 4.2.3: Discard leaves the slave at the last good time (fmi2LastSuccessfulTime),
                // in state StepFailed.
                c.model = Some(model);
                c.time = e.time;
                c.last_successful_time = e.time;
                c.mode = Mode::StepFailed;
                return Ok(Step::Discarded(why));
            }
        };
        // The step ends where it ended early, but not before the master's communication point:
        // a step from the instance's clock, a rounding error before it (accepted above), may
        // find an event right at its start (an input set across an indicator's zero), and FMI
        // 3.0 wants lastSuccessfulTime >= currentCommunicationPoint (4.2.1).
        let end = ended.map_or(end, |e| e.t.max(t));
        // Inputs with a derivative follow their ramp to the new communication point (only
        // interpolated inputs accept derivatives).
        let slopes = bounded.as_deref().unwrap_or(&c.input_derivatives);
        let mut ramped = Vec::new();
        for &r in M::INFO.interpolated_inputs {
            let Some(i) = c.values.position(r) else { continue };
            if let (Value::Real(x), Kind::Real { min, max, .. }, true) =
                (c.values.at(i), M::VARIABLES[i].kind, slopes[i] != 0.0)
            {
                // A slope bounded to reach a bound ends there, not a rounding error outside.
                let x_end = (x + slopes[i] * (end - start)).clamp(min, max);
                ramped.push((i, *x));
                c.values.put(i, Value::Real(x_end));
            }
        }
        let times_before = (c.time, c.last_successful_time);
        (c.time, c.last_successful_time) = (end, end);
        c.model = Some(model);
        // A step whose state has an output that is not a finite number is not done, whether or
        // not the master reads one (issue 46): FMI 3.0 discards it (2.2.4: the instance is as
        // before the call), FMI 2.0, which keeps no state from before the step, ends in Error.
        if let Err(e) = self.outputs_at_step_end() {
            let why = format!("the step from t = {} with h = {} reached {e}", num(t), num(h));
            let c = &mut self.core;
            let Some(before) = before else {
                c.mode = Mode::Error;
                return Err(why);
            };
            c.model = Some(before);
            ramped.into_iter().for_each(|(i, x)| c.values.put(i, Value::Real(x)));
            (c.time, c.last_successful_time) = times_before;
            return Ok(Step::Discarded(format!("{why}; the instance is back at t = {}", num(start))));
        }
        self.ended = ended;
        if let Some(Ended { t, event }) = ended {
            let why = if event { "an event indicator changed sign" } else { "the master asked" };
            self.log.info("logEvents", &format!("{why}: the step ended at t = {}", num(t)));
        }
        Ok(Step::Done(warning))
    }
}

/// A step between [`Instance::begin_step`] and [`Instance::end_step`]: the model, its state
/// before the step (FMI 3.0), the input slopes where bounded to their range.
pub struct Begun<M: Model> {
    model: Box<Driven<M>>,
    before: Option<Box<Driven<M>>>,
    bounded: Option<Vec<f64>>,
    warning: Warning,
    /// The master's t and h, the instance's start and end time, the tolerance.
    span: (f64, f64, f64, f64, f64),
    early_return: bool,
    /// How far the integrator may step past the step's end (the stop time).
    reach: f64,
}

impl<M: Model> Begun<M> {
    /// Integrates the step (the driver, [`Driven::step`]) from the instance's values and input
    /// derivatives at its start, with the master's intermediate update.
    pub fn run(
        &mut self,
        (values, input_derivatives): (&Values, &[f64]),
        log: &mut dyn Log,
        master: Option<&mut dyn Intermediate>,
    ) -> Result<Option<Ended>, StepError> {
        let (_, h, start, end, tolerance) = self.span;
        let mut slopes = Cow::Borrowed(self.bounded.as_deref().unwrap_or(input_derivatives));
        let mut master = master;
        // A model that steps in closed form takes each intermediate input linear over the step,
        // to the master's value at its end: the slope the master would have passed to FMI 2.0
        // (over its communication step h).
        let closed_form = M::CLOSED_FORM && !M::INTERMEDIATE_INPUTS.is_empty();
        if let Some(m) = master.take_if(|_| closed_form) {
            let vrs = M::INTERMEDIATE_INPUTS;
            let mut at_end = vec![0.0; vrs.len()];
            if m.inputs(end, vrs, &mut at_end).is_ok() {
                for (&r, u) in vrs.iter().zip(at_end) {
                    if let Some(i) = values.position(r) {
                        slopes.to_mut()[i] = (u - values.real(r)) / h;
                    }
                }
            }
        }
        // Past the step's end only where nothing within the step asks for its time: no event
        // search, no master's intermediate inputs, no input ramp (a ramp's next slope is the
        // master's).
        let reach = (!self.early_return && master.is_none() && slopes.iter().all(|&d| d == 0.0)).then_some(self.reach);
        self.model.step(values, &slopes, (start, end - start, tolerance), log, (self.early_return, reach), master)
    }
}

/// The outcome of a step that was carried out.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Done, perhaps with a warning.
    Done(Warning),
    /// Stopped at the last good state, with the reason.
    Discarded(String),
}

/// The slopes of the interpolated `inputs` (value references) a step of length `h` uses: a slope
/// that would carry an input out of its declared range within the step is reduced so that the
/// input reaches the bound at the step end (it is linear in between), with a warning naming it.
/// The master's slopes stay as set.
pub fn bounded_slopes<'a>(values: &Values, slopes: &'a [f64], inputs: &[u32], h: f64) -> (Cow<'a, [f64]>, Warning) {
    let mut out = Cow::Borrowed(slopes);
    let mut warnings = Vec::new();
    for i in inputs.iter().filter_map(|&r| values.position(r)) {
        let d = slopes[i];
        let (Kind::Real { min, max, unit, .. }, Value::Real(x), true) =
            (values.table()[i].kind, values.at(i), d != 0.0)
        else {
            continue;
        };
        let bounded = bounded_slope(*x, d, h, (min, max));
        if bounded != d {
            warnings.push(format!(
                "{} = {} with derivative {} leaves its range [{}, {}] {unit} within the step of {} s: it stops at the bound",
                values.table()[i].name,
                num(*x),
                num(d),
                num(min),
                num(max),
                num(h)
            ));
            out.to_mut()[i] = bounded;
        }
    }
    (out, (!warnings.is_empty()).then(|| warnings.join("; ")))
}

/// The slope of a ramp from `x` over `h` that stays in `[min, max]`: `d` if `x + d h` is inside,
/// else the slope reaching the nearer bound at the end of the step.
/// A step too short to divide by (a denormal `h`) leaves the input where it is.
pub fn bounded_slope(x: f64, d: f64, h: f64, (min, max): (f64, f64)) -> f64 {
    let end = x + d * h;
    let slope = if end > max {
        (max - x) / h
    } else if end < min {
        (min - x) / h
    } else {
        d
    };
    if slope.is_finite() {
        slope
    } else {
        0.0
    }
}

/// FMI 2.0 section 2.2.7 and the state tables (3.2.3, 4.2.4): which variables may be set in
/// which state; `continuous_state`: `v` is a continuous-time state.
fn settable(v: &Variable, continuous_state: bool, state: Mode) -> Result<(), String> {
    let input = v.causality == Causality::Input;
    let ok = v.variability != Variability::Constant
        && match state {
            Mode::Instantiated => v.initial != Initial::Calculated || input,
            Mode::InitializationMode => v.initial == Initial::Exact || input,
            Mode::StepComplete | Mode::EventMode => {
                input || (v.causality == Causality::Parameter && v.variability == Variability::Tunable)
            }
            // FMI 2.0 rule 5 (clarified in 2.0.1), FMI 3.0.2 3.2.1: continuous inputs and
            // continuous-time states.
            Mode::ContinuousTimeMode => (input && v.variability == Variability::Continuous) || continuous_state,
            _ => false,
        };
    if ok {
        return Ok(());
    }
    let rule = match state {
        Mode::StepComplete | Mode::EventMode => "after initialisation only inputs and tunable parameters may be set",
        Mode::ContinuousTimeMode => "in Continuous-Time Mode only continuous inputs and continuous states may be set",
        Mode::Instantiated | Mode::InitializationMode => "only parameters and inputs may be set",
        _ => "no variable may be set in this state",
    };
    Err(format!(
        "cannot set \"{}\" (causality={}, variability={}) in state {state:?}: {rule}",
        v.name,
        fmi_name(v.causality),
        fmi_name(v.variability)
    ))
}

/// Checks a new value against the variable's declared range; NaN and infinities are refused.
pub fn in_range(v: &Variable, value: &Value) -> Result<(), String> {
    match (v.kind, value) {
        (Kind::Real { min, max, unit, .. }, Value::Real(x)) => {
            // Formatted only for an error; the dimensionless unit "1" is not written.
            let range = || {
                format!("[{}, {}]{}", num(min), num(max), if unit == "1" { String::new() } else { format!(" {unit}") })
            };
            if !x.is_finite() {
                return Err(format!("{} = {x} is not a finite number; valid range {}", v.name, range()));
            }
            if *x < min || *x > max {
                return Err(format!("{} = {} is outside its valid range {}", v.name, num(*x), range()));
            }
        }
        (Kind::Integer { min, max, .. }, Value::Integer(x)) => {
            if *x < min || *x > max {
                return Err(format!("{} = {x} is outside its valid range [{min}, {max}]", v.name));
            }
        }
        (Kind::Enumeration { ty, .. }, Value::Integer(x)) => {
            if ty.item(i64::from(*x)).is_none() {
                return Err(format!("{} = {x} is no item of {}; valid: {}", v.name, ty.name, ty.listed()));
            }
        }
        _ => {}
    }
    Ok(())
}
