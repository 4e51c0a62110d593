//! One FMI 3.0 sequence's instance: makes each call through the C ABI, checks the oracle on what
//! it returned and keeps track of the instance's state. The oracle (a violation fails the sequence):
//! - every function returns a valid fmi3Status (0..=4), and never fmi3OK or fmi3Warning for a
//!   NULL instance;
//! - a call that `machine3` says the standard forbids in the instance's state (or whose
//!   arguments cannot be right) returns fmi3Error; one that `required` says must succeed returns
//!   fmi3OK or fmi3Warning; the expectations of the planner's probes (`watch`) hold;
//! - every fmi3Error and fmi3Discard of an instance with a logger comes with a logMessage call of
//!   that status during the call (discards only while logStatusDiscard or logAll is on), and so
//!   does an instantiation that returns NULL;
//! - an instantiation with the model description's token and valid arguments returns an
//!   instance, one with a wrong token NULL; fmi3InstantiateScheduledExecution returns NULL;
//! - after fmi3OK or fmi3Warning: Float64 outputs of every function finite (nominals positive,
//!   too), fmi3Boolean outputs 0 or 1, fmi3GetInt64's values items of their Enumerations
//!   (inside [min, max]), strings non-NULL, the numbers of continuous states and event
//!   indicators those of the XML; fmi3DoStep without early return or event handling and
//!   with lastSuccessfulTime = currentCommunicationPoint + communicationStepSize (Discard: in
//!   [currentCommunicationPoint, + communicationStepSize]); a Discard leaves the instance as it
//!   was (Step Mode, the same time) and a retry with a smaller step from that time is no error;
//! - after any fmi3Error of the main instance, it is in Terminated (FMI 3.0 2.3.1), where
//!   `machine3` allows only what Terminated allows;
//! - fmi3GetVersion is "3.0"; the logger gets the instanceEnvironment given at instantiation, a
//!   valid status and non-NULL strings (checked in `callbacks`);
//! - the FMU state checks of `fmu_states`.
//!
//! Crashes and hangs are caught by `batch`, leaks by `sequence`.

use crate::bookkeeping::{Bookkeeping, Target};
use crate::callbacks::{environment, last_error_says, log_message, LOG};
use crate::clock_rules;
use crate::fmi3::{Fmi3, Instance, Library, Status};
use crate::fmu_states::{FmuStates, StateOutput};
use crate::machine3::forbidden;
use crate::ops::{Arr, Text};
use crate::ops3::{Instantiation3, Interface3, Op3};
use crate::report::Report;
use crate::required::{self, Derivative};
use crate::sequence::{driven, Call, Driven};
use crate::session::{expect_text, out};
use crate::step_outputs;
use crate::view::{Phase, View};
use crate::watch::Seen;
use crate::wild3::{instantiation3, wild3};
use std::os::raw::c_char;
use std::ptr::{null, null_mut};

const OK: Status = 0;
const WARNING: Status = 1;
const DISCARD: Status = 2;
const ERROR: Status = 3;

/// What a call wrote.
enum Output {
    Nothing,
    Text(*const c_char),
    Instance(Instance),
    Reals(Vec<f64>),
    /// fmi3GetInt64's values.
    Int64s(Vec<i64>),
    /// fmi3Boolean outputs, as bytes.
    Flags(Vec<u8>),
    Strings(Vec<*const c_char>),
    Stateful(StateOutput),
    Count(usize),
    /// fmi3DoStep: eventHandlingNeeded, terminateSimulation, earlyReturn; lastSuccessfulTime.
    Step([u8; 3], f64),
    /// fmi3UpdateDiscreteStates: its five flags and nextEventTime.
    Event([u8; 5], f64),
}

/// One FMI 3.0 sequence's instance with the fuzzer's bookkeeping.
pub struct Session3<'a> {
    fmi: &'a Fmi3,
    b: Bookkeeping<'a>,
    /// The step size of the fmi3DoStep that returned fmi3Discard just before (at `view.time`).
    pub discarded: Option<f64>,
    /// Discards are delivered to the main instance's logMessage (logStatusDiscard, logAll).
    discards_logged: bool,
    all_logged: bool,
}

driven!(Session3, Op3, instantiation3, wild3);

impl<'a> Session3<'a> {
    pub fn new(library: &'a Library, report: &'a mut Report) -> Self {
        let b = Bookkeeping::new(&library.model, report, FmuStates { fmi3: true, ..FmuStates::default() });
        Session3 { fmi: &library.fmi, b, discarded: None, discards_logged: true, all_logged: false }
    }

    /// Makes one call and checks the oracle.
    pub fn call(&mut self, op: Op3, target: Target) -> Result<(), String> {
        let (c, on) = self.instance(target);
        self.report.begin(format_args!("{}{on}", op.describe()));
        let before = LOG.with(|sink| (sink.borrow().errors, sink.borrow().discards));
        // SAFETY: every pointer passed is NULL or points to as many elements as announced,
        // alive for the call; the instance is one of the session's or NULL.
        let (status, output) = unsafe { self.invoke(c, &op) };
        self.report.end(status);
        if let Some(s) = status.filter(|&s| s > 4) {
            return Err(format!("returned {s}, which is not an fmi3Status (0..=4)"));
        }
        let (errors, discards) = LOG.with(|sink| {
            let sink = sink.borrow();
            (sink.errors - before.0, sink.discards - before.1)
        });
        if let Some(violation) = LOG.with(|sink| sink.borrow_mut().violation.take()) {
            return Err(violation);
        }
        let ok = matches!(status, Some(OK | WARNING));
        if target == Target::Null {
            return if ok { Err("returned fmi3OK or fmi3Warning for a NULL instance".into()) } else { Ok(()) };
        }
        let live = target == Target::Main && !c.is_null() && op.takes_instance();
        if live {
            self.check_status(&op, status, (errors, discards))?;
            self.check_required(&op, status, ok)?;
            self.see(if ok { seen(&op, &output) } else { Seen::Other })?;
        }
        if !matches!(op, Op3::DoStep { .. }) {
            self.discarded = None;
        }
        match (target, output) {
            (Target::Main, output) => self.observe(op, status, ok, output, errors)?,
            (Target::Second, Output::Stateful(StateOutput::State(p))) if ok && !p.is_null() => self.states.foreign.push(p),
            _ => {}
        }
        if live && status == Some(ERROR) {
            // FMI 3.0 2.3.1: "If any function called in super state FMU State Settable returns
            // fmi3Error, the FMU enters state Terminated" (issue 25 item 5).
            self.view.phase = Phase::Terminated;
        }
        Ok(())
    }

    /// The state machine's and the logger's part of the oracle on a call to the main instance.
    fn check_status(&self, op: &Op3, status: Option<Status>, (errors, discards): (u64, u64)) -> Result<(), String> {
        if let (Some(why), Some(s)) = (forbidden(op, &self.view, (self.me, self.event_mode), self.model), status) {
            if s != ERROR {
                let call = op.describe();
                let function = call.split([' ', '(']).next().unwrap_or_default();
                return Err(format!("{function} returned {}, but the call must fail: {why}", name(s)));
            }
        }
        match status {
            Some(ERROR | 4) if self.logger && errors == 0 => Err("returned fmi3Error without a log message".into()),
            Some(DISCARD) if self.logger && (self.discards_logged || self.all_logged) && discards == 0 => {
                Err("returned fmi3Discard without a log message".into())
            }
            // The retry may fail on its own (the model leaving its range), but not as a call the
            // state forbids.
            Some(ERROR) if self.is_retry(op) && last_error_says("illegal call in state") => Err(format!(
                "{} was refused as illegal in its state, a retry with a smaller step after fmi3Discard, which leaves the instance in Step Mode at the step's start (FMI 3.0 4.2.1)",
                op.describe()
            )),
            _ => Ok(()),
        }
    }

    /// `required`'s part of the oracle on a call to the main instance: the call must succeed.
    fn check_required(&self, op: &Op3, status: Option<Status>, ok: bool) -> Result<(), String> {
        let (m, view, me) = (self.model, &self.view, self.me);
        let why = match op {
            Op3::Derivative { adjoint, unknowns, knowns, seed, n_sensitivity, null_sensitivity } => {
                let sensitivities = if *adjoint { knowns.len() } else { unknowns.len() };
                let outputs_right = !null_sensitivity && *n_sensitivity == sensitivities;
                let call = Derivative { unknowns, knowns, seeds: seed, adjoint: *adjoint, outputs_right };
                required::derivative(&call, view, me, m).filter(|_| !adjoint || m.adjoint)
            }
            Op3::SetFloat64 { vr, values } => required::state_set(vr, values, view, me, m),
            Op3::SetClock { .. } => clock_rules::required(op, view, m),
            Op3::State(call) => required::state_call(call, &self.states),
            _ => None,
        };
        match (why, status) {
            (Some(why), Some(s)) if !ok => Err(format!("{} returned {}, but the call must succeed: {why}", op.describe(), name(s))),
            _ => Ok(()),
        }
    }

    /// Whether `op` retries a discarded step: from the same time with a smaller step, in a view
    /// that is certain.
    fn is_retry(&self, op: &Op3) -> bool {
        let Op3::DoStep { t, h, .. } = *op else { return false };
        // A step below the time's resolution there cannot advance it (the FMU refuses it).
        let advances = h > 16.0 * f64::EPSILON * t.abs();
        self.discarded.is_some_and(|h0| self.view.phase == Phase::StepComplete && t == self.view.time && advances && h < h0)
    }

    /// Passes the arguments of `op` through the C ABI; output buffers are temporaries of the call.
    unsafe fn invoke(&mut self, c: Instance, op: &Op3) -> (Option<Status>, Output) {
        let f = self.fmi;
        let status = |s| (Some(s), Output::Nothing);
        match op {
            Op3::GetVersion => (None, Output::Text(f.fmi3GetVersion())),
            Op3::SetDebugLogging { logging_on, categories } => {
                let names = categories.map(Text::ptr);
                status(f.fmi3SetDebugLogging(c, *logging_on, names.len(), names.ptr()))
            }
            Op3::Instantiate(spec) => (None, Output::Instance(instantiate(self.fmi, spec))),
            Op3::FreeInstance { instance } => {
                f.fmi3FreeInstance(*instance);
                (None, Output::Nothing)
            }
            Op3::EnterInitializationMode(e) => status(f.fmi3EnterInitializationMode(
                c,
                e.tolerance_defined,
                e.tolerance,
                e.start,
                e.stop_defined,
                e.stop,
            )),
            Op3::ExitInitializationMode => status(f.fmi3ExitInitializationMode(c)),
            Op3::EnterEventMode => status(f.fmi3EnterEventMode(c)),
            Op3::Terminate => status(f.fmi3Terminate(c)),
            Op3::Reset => status(f.fmi3Reset(c)),
            Op3::GetFloat64 { vr, n_values, null_values } => {
                reals(*n_values, *null_values, |p| f.fmi3GetFloat64(c, vr.ptr(), vr.len(), p, *n_values))
            }
            Op3::GetInt32 { vr, n_values, null_values } => {
                let mut v = vec![0; *n_values];
                status(f.fmi3GetInt32(c, vr.ptr(), vr.len(), out(&mut v, *null_values), *n_values))
            }
            Op3::GetInt64 { vr, n_values, null_values } => {
                let mut v = vec![0; *n_values];
                let s = f.fmi3GetInt64(c, vr.ptr(), vr.len(), out(&mut v, *null_values), *n_values);
                (Some(s), Output::Int64s(if *null_values { Vec::new() } else { v }))
            }
            Op3::GetBoolean { vr, n_values, null_values } => {
                let mut v = vec![0u8; *n_values];
                let s = f.fmi3GetBoolean(c, vr.ptr(), vr.len(), out(&mut v, *null_values).cast(), *n_values);
                (Some(s), Output::Flags(if *null_values { Vec::new() } else { v }))
            }
            Op3::GetString { vr, n_values, null_values } => {
                let mut v = vec![null(); *n_values];
                let s = f.fmi3GetString(c, vr.ptr(), vr.len(), out(&mut v, *null_values), *n_values);
                (Some(s), Output::Strings(if *null_values { Vec::new() } else { v }))
            }
            Op3::SetFloat64 { vr, values } => status(f.fmi3SetFloat64(c, vr.ptr(), vr.len(), values.ptr(), values.len())),
            Op3::SetInt32 { vr, values } => status(f.fmi3SetInt32(c, vr.ptr(), vr.len(), values.ptr(), values.len())),
            Op3::SetInt64 { vr, values } => status(f.fmi3SetInt64(c, vr.ptr(), vr.len(), values.ptr(), values.len())),
            Op3::SetBoolean { vr, values } => {
                status(f.fmi3SetBoolean(c, vr.ptr(), vr.len(), values.ptr().cast(), values.len()))
            }
            Op3::SetString { vr, values } => {
                let strings = values.map(Text::ptr);
                status(f.fmi3SetString(c, vr.ptr(), vr.len(), strings.ptr(), strings.len()))
            }
            Op3::OtherType { ty, set, vr } => status(crate::refused::other_type(f, c, *ty, *set, vr)),
            Op3::Refused { function } => status(crate::refused::call(f, c, *function)),
            Op3::SetClock { vr, values } => status(f.fmi3SetClock(c, vr.ptr(), vr.len(), values.ptr().cast())),
            Op3::GetClock { vr, null_values } => {
                let mut v = vec![0u8; vr.len()];
                let s = f.fmi3GetClock(c, vr.ptr(), vr.len(), out(&mut v, *null_values).cast());
                (Some(s), Output::Flags(if *null_values { Vec::new() } else { v }))
            }
            Op3::State(call) => {
                let (s, output) = call.invoke(f, c);
                (Some(s), Output::Stateful(output))
            }
            Op3::Derivative { adjoint, unknowns: u, knowns: k, seed, n_sensitivity, null_sensitivity } => {
                let (n, (seeds, n_seed)) = (*n_sensitivity, (seed.ptr(), seed.len()));
                reals(n, *null_sensitivity, |p| match adjoint {
                    true => f.fmi3GetAdjointDerivative(c, u.ptr(), u.len(), k.ptr(), k.len(), seeds, n_seed, p, n),
                    false => f.fmi3GetDirectionalDerivative(c, u.ptr(), u.len(), k.ptr(), k.len(), seeds, n_seed, p, n),
                })
            }
            Op3::EnterStepMode => status(f.fmi3EnterStepMode(c)),
            Op3::DoStep { t, h, no_set_prior, null_outputs } => {
                let (mut flags, mut last) = ([0u8; 3], f64::NAN);
                let [a, b, e] = flags.each_mut().map(|p| if *null_outputs { null_mut() } else { p as *mut u8 });
                let s = f.fmi3DoStep(c, *t, *h, *no_set_prior, a.cast(), b.cast(), e.cast(), &mut last);
                (Some(s), Output::Step(flags, last))
            }
            Op3::UpdateDiscreteStates { null_flags } => {
                let (mut flags, mut next) = ([0u8; 5], 0.0);
                let p = flags.each_mut().map(|p| if *null_flags { null_mut() } else { p as *mut u8 });
                let s = f.fmi3UpdateDiscreteStates(c, p[0].cast(), p[1].cast(), p[2].cast(), p[3].cast(), p[4].cast(), &mut next);
                (Some(s), if *null_flags { Output::Nothing } else { Output::Event(flags, next) })
            }
            Op3::EnterContinuousTimeMode => status(f.fmi3EnterContinuousTimeMode(c)),
            Op3::CompletedIntegratorStep { no_set_prior, null_flags } => {
                let mut flags = [0u8; 2];
                let [a, b] = flags.each_mut().map(|p| if *null_flags { null_mut() } else { p as *mut u8 });
                let s = f.fmi3CompletedIntegratorStep(c, *no_set_prior, a.cast(), b.cast());
                (Some(s), Output::Flags(if *null_flags { Vec::new() } else { flags.to_vec() }))
            }
            Op3::SetTime { t } => status(f.fmi3SetTime(c, *t)),
            Op3::SetContinuousStates { x } => status(f.fmi3SetContinuousStates(c, x.ptr(), x.len())),
            Op3::GetContinuousStateDerivatives { n, null } => {
                reals(*n, *null, |p| f.fmi3GetContinuousStateDerivatives(c, p, *n))
            }
            Op3::GetEventIndicators { n, null } => reals(*n, *null, |p| f.fmi3GetEventIndicators(c, p, *n)),
            Op3::GetContinuousStates { n, null } => reals(*n, *null, |p| f.fmi3GetContinuousStates(c, p, *n)),
            Op3::GetNominalsOfContinuousStates { n, null } => {
                reals(*n, *null, |p| f.fmi3GetNominalsOfContinuousStates(c, p, *n))
            }
            Op3::GetNumberOfContinuousStates { null } => count(*null, |p| f.fmi3GetNumberOfContinuousStates(c, p)),
            Op3::GetNumberOfEventIndicators { null } => count(*null, |p| f.fmi3GetNumberOfEventIndicators(c, p)),
            Op3::Oversized(o) => status(o.invoke3(f, c, self.model)),
        }
    }

    /// The oracle on what a call to the main instance returned, and the bookkeeping of its state.
    fn observe(&mut self, op: Op3, status: Option<Status>, ok: bool, output: Output, errors: u64) -> Result<(), String> {
        let phase = self.view.phase;
        if ok {
            clock_rules::observe(&op, &mut self.b.view, self.b.model);
        }
        match (op, output) {
            (Op3::GetVersion, Output::Text(p)) => expect_text(p, "3.0", "fmi3GetVersion")?,
            (Op3::Instantiate(spec), Output::Instance(c)) => self.instantiated(&spec, c, errors)?,
            (Op3::FreeInstance { instance }, _) => self.freed(instance),
            (Op3::DoStep { t, h, .. }, Output::Step(flags, last)) => self.stepped(t, h, status, flags, last)?,
            (Op3::ExitInitializationMode, _) if status == Some(ERROR) && phase == Phase::Initialization => {
                self.view.phase = Phase::Broken
            }
            (_, _) if !ok => {}
            (op, _) if op.access().is_some_and(|a| a.set && required::tunes(a.vr, self.model)) => {
                self.view.tuned = true
            }
            (Op3::SetDebugLogging { logging_on, categories }, _) => self.debug_logging(logging_on, &categories),
            (Op3::EnterInitializationMode(e), _) => {
                let v = &mut self.view;
                (v.time, v.start, v.stop, v.set_up, v.phase) =
                    (e.start, e.start, e.stop_defined.then_some(e.stop), true, Phase::Initialization);
            }
            (Op3::ExitInitializationMode, _) => {
                self.view.phase = if self.me || self.event_mode { Phase::EventMode } else { Phase::StepComplete }
            }
            (Op3::EnterEventMode, _) => self.view.phase = Phase::EventMode,
            (Op3::EnterStepMode, _) => self.view.phase = Phase::StepComplete,
            (Op3::EnterContinuousTimeMode, _) => self.view.phase = Phase::ContinuousTime,
            (Op3::Terminate, _) => self.view.phase = Phase::Terminated,
            (Op3::Reset, _) => self.view = View::fresh(),
            (Op3::SetTime { t }, _) => self.view.time = t,
            (Op3::State(call), Output::Stateful(output)) => self.b.states.observe(call, output, &mut self.b.view)?,
            (Op3::GetFloat64 { vr, .. }, Output::Reals(v)) => {
                if let Some(what) = step_outputs::non_finite(self.model, vr.items(), &v) {
                    return Err(format!("fmi3GetFloat64 returned fmi3OK or fmi3Warning, but {what}"));
                }
            }
            (Op3::GetContinuousStates { .. }, Output::Reals(v)) => {
                finite(&v, "fmi3GetContinuousStates")?;
                (self.x, self.x_fresh) = (v, true);
            }
            (Op3::GetNominalsOfContinuousStates { .. }, Output::Reals(v)) => {
                if let Some(x) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                    return Err(format!("fmi3GetNominalsOfContinuousStates returned fmi3OK with a nominal {x}"));
                }
            }
            (op, Output::Reals(v)) => finite(&v, &op.describe())?,
            (Op3::GetInt64 { vr, .. }, Output::Int64s(v)) => {
                let no_item = |(r, x): (&u32, &i64)| self.model.variable(*r).is_some_and(|e| !e.holds(*x as f64));
                if let Some((r, x)) = vr.items().iter().zip(&v).find(|&p| no_item(p)) {
                    return Err(format!("fmi3GetInt64 returned fmi3OK with vr {r} = {x}, outside its range (no item)"));
                }
            }
            (op, Output::Flags(v)) if v.iter().any(|&b| b > 1) => {
                return Err(format!("{} returned an fmi3Boolean {v:?}, not false (0) or true (1)", op.describe()));
            }
            (_, Output::Event(flags, next)) if flags.iter().any(|&b| b > 1) || (flags[4] == 1 && !next.is_finite()) => {
                return Err(format!("fmi3UpdateDiscreteStates returned the flags {flags:?} and nextEventTime = {next}"));
            }
            (_, Output::Strings(p)) if p.iter().any(|s| s.is_null()) => {
                return Err("fmi3GetString returned fmi3OK with a NULL string".into());
            }
            (Op3::GetNumberOfContinuousStates { null: false }, Output::Count(n)) => {
                expect_count(n, self.model.states, "fmi3GetNumberOfContinuousStates", "ContinuousStateDerivative")?
            }
            (Op3::GetNumberOfEventIndicators { null: false }, Output::Count(n)) => {
                expect_count(n, self.model.event_indicators, "fmi3GetNumberOfEventIndicators", "EventIndicator")?
            }
            _ => {}
        }
        Ok(())
    }

    /// The main instance (checked against its arguments); else the second one, with an FMU state
    /// of it; else one to free right away.
    fn instantiated(&mut self, spec: &Instantiation3, c: Instance, errors: u64) -> Result<(), String> {
        let function = format!("fmi3Instantiate{:?}", spec.interface);
        let valid = crate::wild3::valid_instantiation(spec, self.model);
        if c.is_null() && spec.logger && errors == 0 {
            return Err(format!("{function} returned NULL without a log message"));
        }
        match (valid, c.is_null()) {
            (Some(true), true) => return Err(format!("{function} returned NULL for valid arguments")),
            (Some(false), false) => return Err(format!("{function} returned an instance for arguments it must refuse")),
            _ => {}
        }
        if !self.opened {
            self.me = spec.interface == Interface3::ModelExchange;
            let cs = !self.me;
            (self.event_mode, self.early_return) = (cs && spec.event_mode_used, cs && spec.early_return_allowed);
            self.report.me = self.me;
            (self.logger, self.all_logged) = (spec.logger, spec.logging_on);
        }
        let adopt = self.adopt(c);
        self.adopted(c, adopt)
    }

    /// fmi3SetDebugLogging succeeded: which of the categories that deliver discards are on.
    fn debug_logging(&mut self, on: bool, categories: &Arr<Text>) {
        let names: Vec<&[u8]> = match categories {
            Arr::Items(v) => v.iter().map(|t| match t {
                Text::Bytes(s) => s.to_bytes(),
                Text::Null => b"",
            }).collect(),
            Arr::Null(_) => Vec::new(),
        };
        if names.is_empty() {
            (self.discards_logged, self.all_logged) = (on, on);
        }
        for name in names {
            match name {
                b"logStatusDiscard" => self.discards_logged = on,
                b"logAll" => self.all_logged = on,
                _ => {}
            }
        }
    }

    /// fmi3DoStep(t, h) returned `status` with these outputs: the oracle and the view.
    fn stepped(&mut self, t: f64, h: f64, status: Option<Status>, [event, _, early]: [u8; 3], last: f64) -> Result<(), String> {
        let end = t + h;
        let near = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y.abs().max(1.0);
        // FMI 3.0, 4.2.3: an early return only with earlyReturnAllowed, inside the step; an event
        // only with eventModeUsed.
        match status {
            Some(OK | WARNING) if (early != 0 && !self.early_return) || (event != 0 && !self.event_mode) => {
                return Err(format!(
                    "fmi3DoStep returned eventHandlingNeeded = {event}, earlyReturn = {early}, but the instance has \
                     eventModeUsed = {}, earlyReturnAllowed = {}",
                    self.event_mode, self.early_return
                ));
            }
            // 4.2.1: with earlyReturn, lastSuccessfulTime may equal currentCommunicationPoint ("the
            // detection of an event at currentCommunicationPoint").
            Some(OK | WARNING) if early != 0 && !(last >= t && last < end) => {
                return Err(format!(
                    "fmi3DoStep returned earlyReturn with lastSuccessfulTime = {last}, outside [{t}, {end})"
                ));
            }
            Some(OK | WARNING) if early == 0 && !near(last, end) => {
                return Err(format!("fmi3DoStep returned fmi3OK with lastSuccessfulTime = {last}, not t + h = {end}"));
            }
            Some(DISCARD) if !(last >= t - 1e-9 * t.abs().max(1.0) && last <= end + 1e-9 * end.abs().max(1.0)) => {
                return Err(format!("fmi3DoStep returned fmi3Discard with lastSuccessfulTime = {last}, outside [{t}, {end}]"));
            }
            _ => {}
        }
        let before = self.view;
        // An early return ends the step at lastSuccessfulTime.
        let h = if early != 0 && matches!(status, Some(OK | WARNING)) { last - t } else { h };
        self.simulated += self.view.stepped(t, h, status);
        match status {
            // FMI 3.0 2.2.4, 4.2.1 (issue 25 item 6): the instance stays as before the call,
            // in Step Mode at t, so that a smaller step can be retried.
            Some(DISCARD) => (self.view, self.discarded) = (before, Some(h)),
            Some(OK | WARNING) => self.read_after_step()?,
            _ => {}
        }
        Ok(())
    }

    /// fmi3DoStep returned fmi3OK or fmi3Warning: the outputs and locals are read (`step_outputs`).
    fn read_after_step(&mut self) -> Result<(), String> {
        let (f, c) = (self.fmi, self.c);
        // SAFETY: as many value references and values as announced, alive for the call.
        step_outputs::read(true, self.b.report, self.b.model, |vr, p| unsafe {
            f.fmi3GetFloat64(c, vr.as_ptr(), vr.len(), p, vr.len())
        })
    }
}

/// What the watch sees of a call that succeeded.
fn seen<'a>(op: &'a Op3, output: &'a Output) -> Seen<'a> {
    match (op, output) {
        (Op3::GetFloat64 { vr: Arr::Items(vr), null_values: false, .. }, Output::Reals(v)) if v.len() == vr.len() => Seen::Read(vr, v),
        (Op3::SetFloat64 { vr: Arr::Items(vr), values: Arr::Items(v) }, _) => Seen::Set(vr, v),
        (Op3::DoStep { .. }, _) => Seen::Stepped,
        (Op3::GetEventIndicators { null: false, .. }, Output::Reals(v)) => Seen::EventIndicators(v),
        (Op3::GetContinuousStates { null: false, .. }, Output::Reals(v)) => Seen::ContinuousStates(v),
        (Op3::SetContinuousStates { x: Arr::Items(x) }, _) => Seen::SetStates(x),
        _ => Seen::Other,
    }
}

/// A status for people.
fn name(s: Status) -> String {
    crate::report::outcome(i64::from(s), true)
}

/// `session::reals` with its numbers as the call's output.
unsafe fn reals(n: usize, null: bool, f: impl FnOnce(*mut f64) -> Status) -> (Option<Status>, Output) {
    let (s, v) = crate::session::reals(n, null, f);
    (s, Output::Reals(v))
}

/// Calls `f` with a size_t*, NULL for `null`.
unsafe fn count(null: bool, f: impl FnOnce(*mut usize) -> Status) -> (Option<Status>, Output) {
    let mut n = usize::MAX;
    let s = f(if null { null_mut() } else { &mut n });
    (Some(s), Output::Count(n))
}

/// An fmi3OK answer holds finite numbers only.
fn finite(values: &[f64], function: &str) -> Result<(), String> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(format!("{function} returned fmi3OK or fmi3Warning, but element {i} is {}", values[i])),
        None => Ok(()),
    }
}

fn expect_count(n: usize, expected: usize, function: &str, element: &str) -> Result<(), String> {
    if n == expected {
        return Ok(());
    }
    Err(format!("{function} returned {n}, but the model description has {expected} {element} elements"))
}

/// fmi3InstantiateCoSimulation, fmi3InstantiateModelExchange or
/// fmi3InstantiateScheduledExecution.
pub unsafe fn instantiate(f: &Fmi3, s: &Instantiation3) -> Instance {
    let log = if s.logger { Some(log_message as unsafe extern "C" fn(_, _, _, _)) } else { None };
    let (name, token, resources) = (s.name.ptr(), s.token.ptr(), s.resources.ptr());
    let env = environment();
    match s.interface {
        Interface3::CoSimulation => {
            let r = &s.required_intermediate;
            let (event, early) = (s.event_mode_used, s.early_return_allowed);
            let (visible, on) = (s.visible, s.logging_on);
            f.fmi3InstantiateCoSimulation(name, token, resources, visible, on, event, early, r.ptr(), r.len(), env, log, None)
        }
        Interface3::ModelExchange => f.fmi3InstantiateModelExchange(name, token, resources, s.visible, s.logging_on, env, log),
        Interface3::ScheduledExecution => {
            f.fmi3InstantiateScheduledExecution(name, token, resources, s.visible, s.logging_on, env, log, None, None, None)
        }
    }
}
