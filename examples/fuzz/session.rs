//! One sequence's instance: makes each call through the C ABI, checks the oracle on what it
//! returned and keeps track of the instance's state. The oracle (a violation fails the sequence):
//! - every function returns a valid fmi2Status (0..=4), and never fmi2OK or fmi2Warning for a
//!   NULL instance;
//! - fmi2GetReal with fmi2OK or fmi2Warning wrote finite numbers only, and so did
//!   fmi2GetContinuousStates, fmi2GetNominalsOfContinuousStates (positive, too),
//!   fmi2GetEventIndicators and fmi2GetDerivatives (Model Exchange), and
//!   fmi2GetDirectionalDerivative;
//!   fmi2GetRealStatus(fmi2LastSuccessfulTime) is the end of the last step the fuzzer saw succeed;
//! - a call that `machine2` says must fail returns fmi2Error, with a log message when the
//!   instance has a logger; one that `required` says must succeed returns fmi2OK or fmi2Warning;
//!   the expectations of the planner's probes (`watch`) hold;
//! - fmi2GetTypesPlatform is "default" and fmi2GetVersion "2.0";
//! - the logger gets the componentEnvironment given to fmi2Instantiate, a valid status,
//!   non-NULL strings and the format "%s" (checked in `callbacks`);
//! - fmi2OK never answers a freed, foreign or NULL FMU state, or a damaged serialized one (CRC
//!   not recomputed); fmi2GetFMUstate and fmi2DeSerializeFMUstate with fmi2OK return a new
//!   state, fmi2FreeFMUstate sets the pointer to NULL; fmi2GetString returns non-NULL strings.
//!
//! Crashes and hangs are caught by `batch`.

use crate::bookkeeping::{Bookkeeping, Target};
use crate::callbacks::LOG;
use crate::fmi2::{
    CallbackFunctions, Component, EventInfo, Fmi2, Library, Status, ERROR, LAST_SUCCESSFUL_TIME, MODEL_EXCHANGE, OK,
    WARNING,
};
use crate::fmu_states::{FmuStates, StateOutput};
use crate::ops::{Arr, Instantiation, Op, Text};
use crate::report::Report;
use crate::required::{self, Derivative};
use crate::sequence::{driven, Driven};
use crate::step_outputs;
use crate::view::{Phase, View};
use crate::watch::Seen;
use crate::wild::{instantiation, wild};
use std::ffi::CStr;
use std::os::raw::{c_char, c_int};
use std::ptr::{null, null_mut};

/// What a call wrote, for the oracle and the bookkeeping.
enum Output {
    Nothing,
    Text(*const c_char),
    Instance(Component),
    Reals(Vec<f64>),
    Strings(Vec<*const c_char>),
    Stateful(StateOutput),
    Real(f64),
}

/// One sequence's instance with the fuzzer's bookkeeping.
pub struct Session<'a> {
    fmi: &'a Fmi2,
    b: Bookkeeping<'a>,
    /// Callback structures of the instances, alive until the end of the sequence; boxed, since
    /// an FMU may keep the pointer and a Vec moves its elements.
    #[allow(clippy::vec_box)]
    callbacks: Vec<Box<CallbackFunctions>>,
}

driven!(Session, Op, instantiation, wild);

impl<'a> Session<'a> {
    pub fn new(library: &'a Library, report: &'a mut Report) -> Self {
        let b = Bookkeeping::new(&library.model, report, FmuStates::default());
        Session { fmi: &library.fmi, b, callbacks: Vec::new() }
    }

    /// Makes one call and checks the oracle.
    pub fn call(&mut self, op: Op, target: Target) -> Result<(), String> {
        let (c, on) = self.instance(target);
        match &op {
            Op::State(call) => self.report.begin(format_args!("{}{on}", call.describe(false))),
            Op::Oversized(o) => self.report.begin(format_args!("{}{on}", o.describe(false))),
            op => self.report.begin(format_args!("fmi2{op:?}{on}")),
        }
        let errors = LOG.with(|sink| sink.borrow().errors);
        // SAFETY: every pointer passed is NULL or points to as many elements as announced,
        // alive for the call (see `invoke`); the instance is one of the session's or NULL.
        let (status, output) = unsafe { self.invoke(c, &op) };
        self.report.end(status);
        if let Some(s) = status.filter(|s| !(0..=4).contains(s)) {
            return Err(format!("returned {}, which is not an fmi2Status (0..=4)", s as c_int));
        }
        if let Some(violation) = LOG.with(|sink| sink.borrow_mut().violation.take()) {
            return Err(violation);
        }
        if target == Target::Main && !c.is_null() {
            let logged = LOG.with(|sink| sink.borrow().errors) > errors;
            self.check_refusal(&op, status, logged)?;
        }
        let ok = matches!(status, Some(OK | WARNING));
        if target == Target::Main && !c.is_null() {
            self.check_required(&op, status, ok)?;
            self.see(if ok { seen(&op, &output) } else { Seen::Other })?;
        }
        match (target, output) {
            (Target::Main, output) => self.observe(op, status, ok, output),
            (Target::Null, _) if ok => Err("returned fmi2OK or fmi2Warning for a NULL instance".into()),
            (Target::Second, Output::Stateful(StateOutput::State(p))) if ok && !p.is_null() => {
                self.states.foreign.push(p);
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// `machine2`'s part of the oracle on a call to the main instance: a forbidden call returns
    /// fmi2Error (`logged`: with a log message of that status).
    fn check_refusal(&self, op: &Op, status: Option<Status>, logged: bool) -> Result<(), String> {
        let Some(why) = crate::machine2::forbidden(op, &self.view, self.me, self.model) else { return Ok(()) };
        let function = function(op);
        match status {
            Some(ERROR) if self.logger && !logged => {
                Err(format!("{function} returned fmi2Error without a log message ({why})"))
            }
            Some(ERROR) | None => Ok(()),
            Some(s) => Err(format!(
                "{function} returned {}, but the call must fail: {why}",
                crate::report::outcome(i64::from(s), false)
            )),
        }
    }

    /// `required`'s part of the oracle on a call to the main instance: the call must succeed.
    fn check_required(&self, op: &Op, status: Option<Status>, ok: bool) -> Result<(), String> {
        let (m, view, me) = (self.model, &self.view, self.me);
        let why = match op {
            Op::GetDirectionalDerivative { unknowns, knowns, dv_known, null_dv_unknown } => {
                let call =
                    Derivative { unknowns, knowns, seeds: dv_known, adjoint: false, outputs_right: !null_dv_unknown };
                required::derivative(&call, view, me, m)
            }
            Op::SetReal { vr, values } => required::state_set(vr, values, view, me, m),
            Op::GetDerivatives { n, null } | Op::GetNominalsOfContinuousStates { n, null } => {
                required::initialization_getter(*n, *null, view, me, m)
            }
            Op::State(call) => required::state_call(call, &self.states),
            _ => None,
        };
        match (why, status) {
            (Some(why), Some(s)) if !ok => Err(format!(
                "{} returned {}, but the call must succeed: {why}",
                function(op),
                crate::report::outcome(i64::from(s), false)
            )),
            _ => Ok(()),
        }
    }

    /// Passes the arguments of `op` through the C ABI; output buffers are temporaries of the call.
    unsafe fn invoke(&mut self, c: Component, op: &Op) -> (Option<Status>, Output) {
        let f = self.fmi;
        let status = |s| (Some(s), Output::Nothing);
        match op {
            Op::GetTypesPlatform => (None, Output::Text(f.fmi2GetTypesPlatform())),
            Op::GetVersion => (None, Output::Text(f.fmi2GetVersion())),
            Op::SetDebugLogging { logging_on, categories } => {
                let names = categories.map(Text::ptr);
                status(f.fmi2SetDebugLogging(c, *logging_on, names.len(), names.ptr()))
            }
            Op::Instantiate(spec) => (None, Output::Instance(self.instantiate(spec))),
            Op::FreeInstance { instance } => {
                f.fmi2FreeInstance(*instance);
                (None, Output::Nothing)
            }
            Op::SetupExperiment { tolerance_defined, tolerance, start, stop_defined, stop } => {
                status(f.fmi2SetupExperiment(c, *tolerance_defined, *tolerance, *start, *stop_defined, *stop))
            }
            Op::EnterInitializationMode => status(f.fmi2EnterInitializationMode(c)),
            Op::ExitInitializationMode => status(f.fmi2ExitInitializationMode(c)),
            Op::Terminate => status(f.fmi2Terminate(c)),
            Op::Reset => status(f.fmi2Reset(c)),
            Op::GetReal { vr, null_values } => {
                // NaN: a value the FMU does not write fails the finiteness check.
                let mut v = vec![f64::NAN; vr.len()];
                (Some(f.fmi2GetReal(c, vr.ptr(), vr.len(), out(&mut v, *null_values))), Output::Reals(v))
            }
            Op::GetInteger { vr, null_values } => {
                status(f.fmi2GetInteger(c, vr.ptr(), vr.len(), out(&mut vec![0; vr.len()], *null_values)))
            }
            Op::GetBoolean { vr, null_values } => {
                status(f.fmi2GetBoolean(c, vr.ptr(), vr.len(), out(&mut vec![0; vr.len()], *null_values)))
            }
            Op::GetString { vr, null_values } => {
                let mut v = vec![null(); vr.len()];
                (Some(f.fmi2GetString(c, vr.ptr(), vr.len(), out(&mut v, *null_values))), Output::Strings(v))
            }
            Op::SetReal { vr, values } => status(f.fmi2SetReal(c, vr.ptr(), same_len(vr, values), values.ptr())),
            Op::SetInteger { vr, values } => status(f.fmi2SetInteger(c, vr.ptr(), same_len(vr, values), values.ptr())),
            Op::SetBoolean { vr, values } => status(f.fmi2SetBoolean(c, vr.ptr(), same_len(vr, values), values.ptr())),
            Op::SetString { vr, values } => {
                let strings = values.map(Text::ptr);
                status(f.fmi2SetString(c, vr.ptr(), same_len(vr, values), strings.ptr()))
            }
            Op::State(call) => {
                let (s, output) = call.invoke(f, c);
                (Some(s), Output::Stateful(output))
            }
            Op::GetDirectionalDerivative { unknowns: u, knowns: k, dv_known, null_dv_unknown } => {
                let (n, mut dv) = (same_len(k, dv_known), vec![f64::NAN; u.len()]);
                let s = f.fmi2GetDirectionalDerivative(
                    c,
                    u.ptr(),
                    u.len(),
                    k.ptr(),
                    n,
                    dv_known.ptr(),
                    out(&mut dv, *null_dv_unknown),
                );
                (Some(s), Output::Reals(if *null_dv_unknown { Vec::new() } else { dv }))
            }
            Op::SetRealInputDerivatives { vr, orders, values } => {
                same_len(vr, orders);
                status(f.fmi2SetRealInputDerivatives(c, vr.ptr(), same_len(vr, values), orders.ptr(), values.ptr()))
            }
            Op::GetRealOutputDerivatives { vr, orders, null_values } => {
                let (n, mut v) = (same_len(vr, orders), vec![0.0; vr.len()]);
                status(f.fmi2GetRealOutputDerivatives(c, vr.ptr(), n, orders.ptr(), out(&mut v, *null_values)))
            }
            Op::DoStep { t, h, no_set_prior } => status(f.fmi2DoStep(c, *t, *h, *no_set_prior)),
            Op::CancelStep => status(f.fmi2CancelStep(c)),
            Op::GetStatus { kind, null_value } => status(f.fmi2GetStatus(c, *kind as u32, out(&mut [0], *null_value))),
            Op::GetRealStatus { kind, null_value } => {
                let mut v = [f64::NAN];
                (Some(f.fmi2GetRealStatus(c, *kind as u32, out(&mut v, *null_value))), Output::Real(v[0]))
            }
            Op::GetIntegerStatus { kind, null_value } => {
                status(f.fmi2GetIntegerStatus(c, *kind as u32, out(&mut [0], *null_value)))
            }
            Op::GetBooleanStatus { kind, null_value } => {
                status(f.fmi2GetBooleanStatus(c, *kind as u32, out(&mut [0], *null_value)))
            }
            Op::GetStringStatus { kind, null_value } => {
                status(f.fmi2GetStringStatus(c, *kind as u32, out(&mut [null()], *null_value)))
            }
            Op::EnterEventMode => status(f.fmi2EnterEventMode(c)),
            Op::NewDiscreteStates { null_info } => {
                status(f.fmi2NewDiscreteStates(c, out(&mut [EventInfo::default()], *null_info)))
            }
            Op::EnterContinuousTimeMode => status(f.fmi2EnterContinuousTimeMode(c)),
            Op::CompletedIntegratorStep { no_set_prior, null_flags } => {
                let (mut a, mut b) = ([0], [0]);
                status(f.fmi2CompletedIntegratorStep(
                    c,
                    *no_set_prior,
                    out(&mut a, *null_flags),
                    out(&mut b, *null_flags),
                ))
            }
            Op::SetTime { t } => status(f.fmi2SetTime(c, *t)),
            Op::SetContinuousStates { x } => status(f.fmi2SetContinuousStates(c, x.ptr(), x.len())),
            Op::GetDerivatives { n, null } => real_output(*n, *null, |p| f.fmi2GetDerivatives(c, p, *n)),
            Op::GetEventIndicators { n, null } => real_output(*n, *null, |p| f.fmi2GetEventIndicators(c, p, *n)),
            Op::GetContinuousStates { n, null } => real_output(*n, *null, |p| f.fmi2GetContinuousStates(c, p, *n)),
            Op::GetNominalsOfContinuousStates { n, null } => {
                real_output(*n, *null, |p| f.fmi2GetNominalsOfContinuousStates(c, p, *n))
            }
            Op::Oversized(o) => status(o.invoke2(f, c, self.model)),
        }
    }

    /// fmi2Instantiate; the callback structure stays alive until the end of the sequence.
    unsafe fn instantiate(&mut self, s: &Instantiation) -> Component {
        let functions = s.callbacks.map(|cb| Box::new(cb.functions()));
        let p = functions.as_deref().map_or(null(), |f| f as *const CallbackFunctions);
        let Instantiation { name, fmu_type, guid, resources, visible, logging_on, .. } = s;
        let c = self.fmi.fmi2Instantiate(
            name.ptr(),
            *fmu_type as u32,
            guid.ptr(),
            resources.ptr(),
            p,
            *visible,
            *logging_on,
        );
        self.callbacks.extend(functions);
        c
    }

    /// The oracle on what a call to the main instance returned, and the bookkeeping of its state.
    fn observe(&mut self, op: Op, status: Option<Status>, ok: bool, output: Output) -> Result<(), String> {
        let phase = self.view.phase;
        match (op, output) {
            (Op::GetTypesPlatform, Output::Text(p)) => expect_text(p, "default", "fmi2GetTypesPlatform")?,
            (Op::GetVersion, Output::Text(p)) => expect_text(p, "2.0", "fmi2GetVersion")?,
            (Op::Instantiate(spec), Output::Instance(c)) => {
                if !self.opened {
                    self.me = spec.fmu_type == MODEL_EXCHANGE;
                    self.report.me = self.me;
                    self.logger = spec.callbacks.is_some_and(|c| c.logger);
                }
                let adopt = self.adopt(c);
                self.adopted(c, adopt)?
            }
            (Op::FreeInstance { instance }, _) => self.freed(instance),
            (
                Op::SetReal { vr, .. }
                | Op::SetInteger { vr, .. }
                | Op::SetBoolean { vr, .. }
                | Op::SetString { vr, .. },
                _,
            ) if ok && required::tunes(&vr, self.model) => self.view.tuned = true,
            (Op::SetupExperiment { start, stop_defined, stop, .. }, _) if ok => {
                let v = &mut self.view;
                (v.time, v.start, v.stop, v.set_up) = (start, start, (stop_defined != 0).then_some(stop), true);
            }
            (Op::EnterInitializationMode, _) if ok => self.view.phase = Phase::Initialization,
            (Op::ExitInitializationMode, _) if ok => {
                self.view.phase = if self.me { Phase::EventMode } else { Phase::StepComplete }
            }
            (Op::EnterEventMode, _) if ok => self.view.phase = Phase::EventMode,
            (Op::EnterContinuousTimeMode, _) if ok => self.view.phase = Phase::ContinuousTime,
            (Op::SetTime { t }, _) if ok => self.view.time = t,
            (Op::GetDerivatives { .. }, Output::Reals(v)) if ok => finite(&v, "fmi2GetDerivatives")?,
            (Op::GetDirectionalDerivative { .. }, Output::Reals(v)) if ok => {
                finite(&v, "fmi2GetDirectionalDerivative")?
            }
            (Op::GetEventIndicators { .. }, Output::Reals(v)) if ok => finite(&v, "fmi2GetEventIndicators")?,
            (Op::GetContinuousStates { .. }, Output::Reals(v)) if ok => {
                finite(&v, "fmi2GetContinuousStates")?;
                (self.x, self.x_fresh) = (v, true);
            }
            (Op::GetNominalsOfContinuousStates { .. }, Output::Reals(v)) if ok => {
                if let Some(x) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                    return Err(format!("fmi2GetNominalsOfContinuousStates returned fmi2OK with a nominal {x}"));
                }
            }
            (Op::ExitInitializationMode, _) if phase == Phase::Initialization => self.view.phase = Phase::Broken,
            (Op::Terminate, _) if ok => self.view.phase = Phase::Terminated,
            (Op::Reset, _) if ok => self.view = View::fresh(),
            (Op::GetReal { vr, .. }, Output::Reals(values)) if ok => self.check_reals(&vr, &values)?,
            (Op::GetString { .. }, Output::Strings(p)) if ok && p.iter().any(|s| s.is_null()) => {
                return Err("fmi2GetString returned fmi2OK with a NULL string".into());
            }
            (Op::State(call), Output::Stateful(output)) if ok => {
                self.b.states.observe(call, output, &mut self.b.view)?
            }
            (Op::GetRealStatus { kind: LAST_SUCCESSFUL_TIME, .. }, Output::Real(t)) if ok => {
                self.view.synchronised(t)?
            }
            (Op::GetRealStatus { kind: LAST_SUCCESSFUL_TIME, .. }, _) if phase == Phase::Unknown => {
                self.view.phase = Phase::Broken;
            }
            (Op::DoStep { t, h, .. }, _) => {
                self.simulated += self.view.stepped(t, h, status);
                if ok {
                    self.read_after_step()?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// fmi2GetReal said fmi2OK or fmi2Warning: every value must be finite.
    fn check_reals(&self, vr: &Arr<u32>, values: &[f64]) -> Result<(), String> {
        match step_outputs::non_finite(self.model, vr.items(), values) {
            Some(what) => Err(format!("fmi2GetReal returned fmi2OK or fmi2Warning, but {what}")),
            None => Ok(()),
        }
    }

    /// fmi2DoStep returned fmi2OK or fmi2Warning: the outputs and locals are read (`step_outputs`).
    fn read_after_step(&mut self) -> Result<(), String> {
        let (f, c) = (self.fmi, self.c);
        // SAFETY: as many value references and values as announced, alive for the call.
        step_outputs::read(false, self.b.report, self.b.model, |vr, p| unsafe {
            f.fmi2GetReal(c, vr.as_ptr(), vr.len(), p)
        })
    }
}

/// The function an op calls, for messages.
fn function(op: &Op) -> String {
    match op {
        Op::Oversized(o) => o.function(false),
        Op::State(call) => call.name(false).to_owned(),
        op => format!("fmi2{op:?}").split([' ', '(']).next().unwrap_or_default().to_owned(),
    }
}

/// What the watch sees of a call that succeeded.
fn seen<'a>(op: &'a Op, output: &'a Output) -> Seen<'a> {
    match (op, output) {
        (Op::GetReal { vr: Arr::Items(vr), null_values: false }, Output::Reals(v)) => Seen::Read(vr, v),
        (Op::SetReal { vr: Arr::Items(vr), values: Arr::Items(v) }, _) => Seen::Set(vr, v),
        (Op::DoStep { .. }, _) => Seen::Stepped,
        (Op::GetEventIndicators { null: false, .. }, Output::Reals(v)) => Seen::EventIndicators(v),
        (Op::GetContinuousStates { null: false, .. }, Output::Reals(v)) => Seen::ContinuousStates(v),
        (Op::SetContinuousStates { x: Arr::Items(x) }, _) => Seen::SetStates(x),
        _ => Seen::Other,
    }
}

/// Calls `f` with a buffer of `n` NaNs (NULL for `null`): the status and what it holds after (a
/// value the FMU does not write fails the finiteness check).
pub unsafe fn reals(n: usize, null: bool, f: impl FnOnce(*mut f64) -> Status) -> (Option<Status>, Vec<f64>) {
    let mut v = vec![f64::NAN; n];
    let s = f(out(&mut v, null));
    (Some(s), if null { Vec::new() } else { v })
}

/// `reals` with its numbers as the call's output.
unsafe fn real_output(n: usize, null: bool, f: impl FnOnce(*mut f64) -> Status) -> (Option<Status>, Output) {
    let (s, v) = reals(n, null, f);
    (s, Output::Reals(v))
}

/// An fmi2OK answer of a Model Exchange getter holds finite numbers only.
fn finite(values: &[f64], function: &str) -> Result<(), String> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(format!("{function} returned fmi2OK or fmi2Warning, but element {i} is {}", values[i])),
        None => Ok(()),
    }
}

/// An output pointer to `buffer`, or NULL.
pub fn out<T>(buffer: &mut [T], null: bool) -> *mut T {
    if null {
        null_mut()
    } else {
        buffer.as_mut_ptr()
    }
}

/// The length of paired C arrays, which the fuzzer always makes announce the same.
fn same_len<A, B>(a: &Arr<A>, b: &Arr<B>) -> usize {
    assert_eq!(a.len(), b.len(), "fuzzer bug: paired arrays of different lengths");
    a.len()
}

/// Checks a string a function returned.
pub fn expect_text(p: *const c_char, expected: &str, function: &str) -> Result<(), String> {
    if p.is_null() {
        return Err(format!("{function} returned NULL"));
    }
    // SAFETY: a non-NULL pointer from the FMU to a NUL-terminated string (FMI 2.0, 2.1.4; so in FMI 3.0).
    let text = unsafe { CStr::from_ptr(p) };
    if text.to_bytes() != expected.as_bytes() {
        return Err(format!("{function} returned {text:?}, not {expected:?}"));
    }
    Ok(())
}
