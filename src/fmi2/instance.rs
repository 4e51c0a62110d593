//! One FMU instance: variable values, model, time and state machine, in safe Rust.
//! [`super::api`] wraps these methods in the C ABI.

use super::log::Logger;
use super::model::{Log, Model};
use super::state::State;
use super::types::fmi2Status;
use super::variables::{fmi_name, BaseType, Causality, Initial, Kind, Value, Values, Variability, Variable};

/// Relative tolerance for matching the master's communication point with the instance time.
pub const TIME_MATCH_RTOL: f64 = 1e-9;

/// A live instance. `#[repr(C)]` so that `magic` is first: it tells a boomsim instance of this
/// model from any other pointer an importer might pass.
#[repr(C)]
pub struct Instance<M: Model> {
    pub(crate) magic: u64,
    pub log: Logger,
    pub core: Core<M>,
    /// Storage behind the pointers the last fmi2GetString returned.
    pub(crate) strings: Vec<std::ffi::CString>,
}

/// Everything an FMU state captures: the instance less its name and logger.
#[derive(Clone)]
pub struct Core<M: Model> {
    pub state: State,
    pub values: Values,
    /// First derivatives of Real inputs (fmi2SetRealInputDerivatives), per table row.
    pub input_derivatives: Vec<f64>,
    /// The model, built when initialisation ends.
    pub model: Option<M>,
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    pub last_successful_time: f64,
    /// Whether outputs reflect the current state and inputs.
    pub outputs_current: bool,
}

impl<M: Model> Core<M> {
    /// The state right after fmi2Instantiate: start values, time 0.
    pub fn new() -> Self {
        Core {
            state: State::Instantiated,
            values: Values::new(M::VARIABLES),
            input_derivatives: vec![0.0; M::VARIABLES.len()],
            model: None,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            tolerance: None,
            last_successful_time: 0.0,
            outputs_current: false,
        }
    }
}

impl<M: Model> Default for Core<M> {
    fn default() -> Self {
        Self::new()
    }
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
        self.0.status(fmi2Status::Warning, message);
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
    /// Tag of a live instance of model `M`.
    pub const MAGIC: u64 = fnv1a(M::INFO.identifier.as_bytes(), 0x1157);
    /// Tag of an FMU state of model `M`.
    pub const STATE_MAGIC: u64 = fnv1a(M::INFO.identifier.as_bytes(), 0x57a7e);

    /// A freshly instantiated slave.
    pub fn new(log: Logger) -> Self {
        Instance { magic: Self::MAGIC, log, core: Core::new(), strings: Vec::new() }
    }

    /// fmi2SetupExperiment.
    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start: f64, stop: Option<f64>) -> Result<(), String> {
        if !start.is_finite() {
            return Err(format!("startTime = {start} must be finite"));
        }
        if let Some(tol) = tolerance {
            if !(tol > 0.0 && tol < 1.0) {
                return Err(format!("tolerance = {tol} is outside its valid range (0, 1)"));
            }
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop >= start) {
                return Err(format!("stopTime = {stop} must be finite and >= startTime = {start}"));
            }
        }
        let c = &mut self.core;
        c.tolerance = tolerance;
        c.start_time = start;
        c.stop_time = stop;
        c.time = start;
        c.last_successful_time = start;
        Ok(())
    }

    /// fmi2EnterInitializationMode.
    pub fn enter_initialization_mode(&mut self) {
        self.core.state = State::InitializationMode;
        self.core.outputs_current = false;
    }

    /// fmi2ExitInitializationMode: builds the model from the final parameters and inputs.
    pub fn exit_initialization_mode(&mut self) -> Result<(), String> {
        let c = &mut self.core;
        let model = M::initialize(&c.values)?;
        model.outputs(&mut c.values);
        c.model = Some(model);
        c.outputs_current = true;
        c.last_successful_time = c.time;
        c.state = State::StepComplete;
        Ok(())
    }

    /// Brings outputs up to date before a get.
    fn refresh_outputs(&mut self) -> Result<(), String> {
        let c = &mut self.core;
        if c.outputs_current {
            return Ok(());
        }
        if c.state == State::InitializationMode {
            // Initial outputs follow from the values set so far.
            M::initialize(&c.values)?.outputs(&mut c.values);
        } else if let Some(model) = &c.model {
            model.outputs(&mut c.values);
        }
        c.outputs_current = true;
        Ok(())
    }

    /// Looks up a value reference and checks its type.
    fn lookup(&self, vr: u32, wanted: BaseType) -> Result<(usize, &'static Variable), String> {
        let i = self
            .core
            .values
            .position(vr)
            .ok_or_else(|| format!("unknown value reference {vr}: {} has no such variable", M::INFO.identifier))?;
        let v = &M::VARIABLES[i];
        if v.base_type() != wanted {
            return Err(format!("variable \"{}\" (vr {vr}) is a {:?}, not a {wanted:?}", v.name, v.base_type()));
        }
        Ok((i, v))
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
            let (i, _) = self.lookup(vr, wanted)?;
            out[k] = read(self.core.values.at(i));
        }
        Ok(())
    }

    /// Writes values, all or nothing: every value is checked (type, settability, range) before
    /// any is stored.
    pub fn set(&mut self, vrs: &[u32], new: Vec<Value>) -> Result<(), String> {
        let mut checked = Vec::with_capacity(vrs.len());
        for (&vr, value) in vrs.iter().zip(new) {
            let (i, v) = self.lookup(vr, value.base_type())?;
            settable(v, self.core.state)?;
            in_range(v, &value)?;
            checked.push((i, value));
        }
        let tunes = self.core.state == State::StepComplete
            && checked.iter().any(|&(i, _)| M::VARIABLES[i].causality == Causality::Parameter);
        let before = tunes.then(|| self.core.values.clone());
        for (i, value) in checked {
            self.core.values.put(i, value);
        }
        if let Some(before) = before {
            let c = &mut self.core;
            if let Err(e) = c.model.as_mut().map_or(Ok(()), |m| m.retune(&c.values)) {
                c.values = before;
                return Err(e);
            }
        }
        if let (State::StepComplete, Some(model)) = (self.core.state, self.core.model.as_mut()) {
            model.inputs_set(vrs);
        }
        self.core.outputs_current = false;
        Ok(())
    }

    /// fmi2SetRealInputDerivatives (first order only).
    pub fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Result<(), String> {
        if !M::INFO.can_interpolate_inputs {
            return Err(format!("{} does not interpolate inputs (canInterpolateInputs=\"false\")", M::INFO.identifier));
        }
        let mut checked = Vec::with_capacity(vrs.len());
        for ((&vr, &order), &d) in vrs.iter().zip(orders).zip(values) {
            let (i, v) = self.lookup(vr, BaseType::Real)?;
            if v.causality != Causality::Input {
                return Err(format!("variable \"{}\" is not an input; derivatives can only be set for inputs", v.name));
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

    /// fmi2DoStep. `Ok(None)`: step done; `Ok(Some(why))`: discarded at the last good time.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<Option<String>, String> {
        let c = &mut self.core;
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!("communicationStepSize = {h} is outside its valid range (0, inf)"));
        }
        let eps = TIME_MATCH_RTOL * c.time.abs().max(1.0);
        if !((t - c.time).abs() <= eps) {
            return Err(format!(
                "currentCommunicationPoint = {t} does not match the instance time {} (tolerance {eps:e})",
                c.time
            ));
        }
        if let Some(stop) = c.stop_time {
            if t + h > stop + TIME_MATCH_RTOL * stop.abs().max(1.0) {
                return Err(format!(
                    "a step to t = {} would pass the stop time {stop} set in fmi2SetupExperiment",
                    t + h
                ));
            }
        }
        let tolerance = c.tolerance.unwrap_or(M::INFO.default_tolerance);
        let model = c.model.as_mut().ok_or("the model is not initialised")?;
        // The model steps from the instance's own clock to the master's t + h: a master that
        // accumulates t_k + h instead of k h (rounding-level differences, accepted above) then
        // still continues exactly where the last step ended, so results do not depend on it.
        let (start, end) = (c.time, t + h);
        if end <= start {
            return Err(format!("communicationStepSize = {h} does not advance the instance time {start}"));
        }
        let result =
            model.do_step(&c.values, &c.input_derivatives, start, end - start, tolerance, &mut ModelLog(&self.log));
        c.outputs_current = false;
        match result {
            Ok(()) => {
                // Inputs with a derivative follow their ramp to the new communication point
                // (only models that interpolate inputs accept derivatives).
                let ramps = if M::INFO.can_interpolate_inputs { c.input_derivatives.as_slice() } else { &[] };
                for (i, &d) in ramps.iter().enumerate() {
                    if let (Value::Real(x), true) = (c.values.at(i), d != 0.0) {
                        c.values.put(i, Value::Real(x + d * h));
                    }
                }
                c.time = t + h;
                c.last_successful_time = c.time;
                Ok(None)
            }
            Err(e) => {
                c.time = e.time;
                c.last_successful_time = e.time;
                c.state = State::StepFailed;
                Ok(Some(format!("step from t = {t} with h = {h} stopped at t = {}: {}", e.time, e.message)))
            }
        }
    }
}

/// FMI 2.0 section 2.2.7: which variables may be set in which state.
fn settable(v: &Variable, state: State) -> Result<(), String> {
    let input = v.causality == Causality::Input;
    let ok = v.variability != Variability::Constant
        && match state {
            State::Instantiated => v.initial != Initial::Calculated || input,
            State::InitializationMode => v.initial == Initial::Exact || input,
            State::StepComplete => {
                input || (v.causality == Causality::Parameter && v.variability == Variability::Tunable)
            }
            _ => false,
        };
    if ok {
        return Ok(());
    }
    let rule = match state {
        State::StepComplete => "after initialisation only inputs and tunable parameters may be set",
        State::Instantiated | State::InitializationMode => "only parameters and inputs may be set",
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
fn in_range(v: &Variable, value: &Value) -> Result<(), String> {
    match (v.kind, value) {
        (Kind::Real { min, max, unit, .. }, Value::Real(x)) => {
            if !x.is_finite() {
                return Err(format!("{} = {x} is not a finite number; valid range [{min}, {max}] {unit}", v.name));
            }
            if *x < min || *x > max {
                return Err(format!("{} = {x} is outside its valid range [{min}, {max}] {unit}", v.name));
            }
        }
        (Kind::Integer { min, max, .. }, Value::Integer(x)) => {
            if *x < min || *x > max {
                return Err(format!("{} = {x} is outside its valid range [{min}, {max}]", v.name));
            }
        }
        _ => {}
    }
    Ok(())
}
