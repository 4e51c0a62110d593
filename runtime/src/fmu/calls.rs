//! The bodies of the C functions FMI 2.0 and FMI 3.0 have in common, generic over the model:
//! each adapter (`fmi2::api`, `fmi3::api`) forwards its symbol here with the function's name and
//! its rule of the adapter's state table ([`Call`]).
//!
//! Every function checks its pointers and the state machine, catches panics, and reports
//! failures through the logger with the instance name (ARCHITECTURE.md, principle 4).
#![allow(clippy::missing_safety_doc)]

use super::driver::Intermediate;
use super::instance::{Core, Instance, Master, Step, Warning};
use super::log::{Logger, Status, GENERIC_CATEGORIES, LOG_FMI_CALLS};
use super::machine::{describe, Interface, Mode, Rule};
use super::model::{Log, Model};
use super::snapshot;
use super::variables::{BaseType, Value, Values};
use super::version::Version;
use std::ffi::{CStr, CString};
use std::marker::PhantomData;
use std::os::raw::{c_char, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// An instance pointer as both versions pass it (fmi2Component, fmi3Instance).
pub type Handle = *mut c_void;
/// An FMU state pointer (fmi2FMUstate, fmi3FMUState).
pub type FmuState = *mut c_void;

/// One C function: the version whose symbol it is, its name and where it may be called.
#[derive(Debug, Clone, Copy)]
pub struct Call {
    pub version: Version,
    pub function: &'static str,
    pub rule: Rule,
}

/// The instance behind a pointer, if it is one of ours for this model and version.
unsafe fn instance<'a, M: Model>(c: Handle, version: Version) -> Option<&'a mut Instance<M>> {
    let inst = (c as *mut Instance<M>).as_mut()?;
    (inst.magic == Instance::<M>::magic(version)).then_some(inst)
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_default()
}

/// Runs `body` for a valid instance in an allowed state; errors are logged, panics caught.
pub fn call<M: Model>(c: Handle, f: Call, body: impl FnOnce(&mut Instance<M>) -> Result<Status, String>) -> Status {
    // SAFETY: `call_reentrant` gives `c` only after it found a valid instance there.
    call_reentrant::<M>(c, f, |c| body(unsafe { instance::<M>(c, f.version) }.ok_or("no instance")?))
}

/// [`call`] for a body that borrows the instance itself, anew for each of its phases, so that
/// the instance can be called between them (FMI 3.0 intermediate update: the master's callback,
/// inside doStep, calls the instance's setters). No borrow of the instance is held while `body`
/// runs.
pub fn call_reentrant<M: Model>(c: Handle, f: Call, body: impl FnOnce(Handle) -> Result<Status, String>) -> Status {
    // SAFETY: FMI requires `c` to be a pointer returned by instantiation; a null or foreign
    // pointer is detected by the magic tag where the memory is readable. Each borrow below ends
    // before the next begins.
    let borrow = || unsafe { instance::<M>(c, f.version) };
    let Some(inst) = borrow() else {
        return Status::Error;
    };
    let function = f.function;
    let result = catch_unwind(AssertUnwindSafe(|| {
        if inst.log.is_enabled(LOG_FMI_CALLS) {
            inst.log.info("logFmiCalls", function);
        }
        if let Some(interface) = f.rule.interface.filter(|&i| i != inst.interface) {
            return Err(format!(
                "a {interface:?} function, but this instance was instantiated for {:?}",
                inst.interface
            ));
        }
        let state = inst.core.mode;
        if f.rule.states & state.bit() == 0 {
            return Err(format!("illegal call in state {state:?}; it is allowed in: {}", describe(f.rule.states)));
        }
        body(c)
    }));
    let Some(inst) = borrow() else {
        return Status::Error;
    };
    match result {
        Ok(Ok(status)) => status,
        Ok(Err(message)) => {
            let m = format!("{function}: {message}{}", after_error(inst));
            inst.log.status(Status::Error, &m);
            Status::Error
        }
        Err(p) => {
            inst.core.mode = Mode::Error;
            let m = format!("{function}: internal error: {}{}", panic_text(p.as_ref()), after_error(inst));
            inst.log.status(Status::Error, &m);
            Status::Error
        }
    }
}

/// The state an error leaves, and what the message adds about it. FMI 3.0, 2.3.1: "If any
/// function called in super state FMU State Settable returns fmi3Error, the FMU enters state
/// Terminated". FMI 2.0 leaves the state after fmi2Error open (2.1.3: "it is possible to
/// restore a previously retrieved FMU state"): a refused call changes nothing there, and only
/// a broken model (a panic, a non-finite result) puts the instance in the Error state.
fn after_error<M: Model>(inst: &mut Instance<M>) -> String {
    let c = &mut inst.core;
    let v = inst.version;
    let (reset, restore, free) =
        (v.function("fmi2Reset"), v.function("fmi2SetFMUstate"), v.function("fmi2FreeInstance"));
    match (v, c.mode) {
        (Version::Fmi3, Mode::Terminated) => String::new(),
        (Version::Fmi3, _) => {
            c.mode = Mode::Terminated;
            format!("; the instance is now Terminated (FMI 3.0, 2.3.1; {reset}, {restore} or {free})")
        }
        (Version::Fmi2, Mode::Error) => {
            format!("; the instance is now in the Error state ({reset}, {restore} or {free})")
        }
        (Version::Fmi2, _) => String::new(),
    }
}

/// Status Warning with the message logged if there is one, else OK.
pub fn warn<M: Model>(inst: &Instance<M>, function: &str, warning: Warning) -> Status {
    match warning {
        Some(w) => {
            inst.log.status(Status::Warning, &format!("{function}: {w}"));
            Status::Warning
        }
        None => Status::OK,
    }
}

/// The most elements an array of a call may announce, and what bounds it (for the message).
/// FMI makes a count larger than its array the importer's error, but a count the model cannot use
/// is refused before the array is touched, so that it cannot make the FMU read or write past it.
pub type Limit<'a> = (usize, &'a str);

/// A slice from a C array of `n` elements; NULL is an error unless `n` is 0, and so is `n`
/// above the limit.
pub unsafe fn slice<'a, T>(p: *const T, n: usize, (max, of): Limit, what: &str) -> Result<&'a [T], String> {
    if n > max {
        Err(format!("{what}: {n} elements announced, but at most {max} are valid ({of})"))
    } else if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err(format!("{what} is NULL but {n} elements were announced"))
    } else {
        Ok(std::slice::from_raw_parts(p, n))
    }
}

/// A mutable slice from a C array of `n` elements, checked as [`slice`].
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, limit: Limit, what: &str) -> Result<&'a mut [T], String> {
    slice(p as *const T, n, limit, what)?;
    Ok(if n == 0 { &mut [] } else { std::slice::from_raw_parts_mut(p, n) })
}

/// The limit of a list of value references: one per variable (FMI 3.0: and `time`).
pub fn references<M: Model>(version: Version) -> Limit<'static> {
    match version {
        Version::Fmi2 => (M::VARIABLES.len(), "one per variable of the model"),
        Version::Fmi3 => (M::VARIABLES.len() + 1, "one per variable of the model and time"),
    }
}

/// The limit of an array of continuous states: the model's number.
pub fn states<M: Model>() -> Limit<'static> {
    (M::STATES.len(), "the model's continuous states")
}

/// A C string as UTF-8, if it is one.
pub unsafe fn text<'a>(p: *const c_char) -> Option<&'a str> {
    (!p.is_null()).then(|| CStr::from_ptr(p).to_str().ok()).flatten()
}

/// The instance name given at instantiation: non-empty UTF-8.
pub unsafe fn instance_name<'a>(name: *const c_char) -> Result<&'a str, String> {
    match text(name) {
        Some(n) if !n.is_empty() => Ok(n),
        _ => Err("instanceName must be a non-empty UTF-8 string".into()),
    }
}

/// The GUID (FMI 2.0) or instantiation token (FMI 3.0) the importer passes (`what` names the
/// argument, `kind` what it is) against the binary's.
pub unsafe fn check_identity(identity: *const c_char, what: &str, kind: &str, expected: &str) -> Result<(), String> {
    match text(identity) {
        Some(g) if g == expected => Ok(()),
        g => Err(format!(
            "{what} = {g:?} does not match this binary's {kind} {expected}: modelDescription.xml and binary come from different builds"
        )),
    }
}

/// A new instance on the heap, as the pointer instantiation returns, with `configure`'s settings
/// (FMI 3.0 Co-Simulation: Event Mode, early return, the master's intermediate update).
pub fn new_instance<M: Model>(
    log: Logger,
    guid: String,
    version: Version,
    interface: Interface,
    configure: impl FnOnce(&mut Instance<M>),
) -> Handle {
    let mut instance = Instance::<M>::new(log, guid, version, interface);
    configure(&mut instance);
    Box::into_raw(Box::new(instance)) as Handle
}

/// Frees an instance with every FMU state the importer did not free.
pub unsafe fn free_instance<M: Model>(c: Handle, f: Call) {
    if call::<M>(c, f, |_| Ok(Status::OK)) == Status::OK {
        let mut inst = Box::from_raw(c as *mut Instance<M>);
        inst.magic = 0;
        for s in inst.fmu_states.drain(..) {
            drop(Box::from_raw(s));
        }
    }
}

pub unsafe fn set_debug_logging<M: Model>(
    c: Handle,
    f: Call,
    on: bool,
    n: usize,
    categories: *const *const c_char,
) -> Status {
    call::<M>(c, f, |inst| {
        let limit = (M::INFO.log_categories.len() + GENERIC_CATEGORIES.len(), "the model's log categories");
        let names = slice(categories, n, limit, "categories")?
            .iter()
            .map(|&p| text(p).ok_or_else(|| "a category name is NULL or not UTF-8".to_string()))
            .collect::<Result<Vec<_>, _>>()?;
        inst.log.set_debug_logging(on, &names)?;
        Ok(Status::OK)
    })
}

/// The experiment (fmi2SetupExperiment; part of fmi3EnterInitializationMode).
pub fn setup_experiment<M: Model>(
    inst: &mut Instance<M>,
    function: &str,
    tolerance: Option<f64>,
    start: f64,
    stop: Option<f64>,
) -> Result<Status, String> {
    let warning = inst.setup_experiment(tolerance, start, stop)?;
    Ok(warn(inst, function, warning))
}

pub unsafe fn enter_initialization_mode<M: Model>(c: Handle, f: Call) -> Status {
    call::<M>(c, f, |inst| {
        inst.enter_initialization_mode();
        Ok(Status::OK)
    })
}

pub unsafe fn exit_initialization_mode<M: Model>(c: Handle, f: Call) -> Status {
    call::<M>(c, f, |inst| {
        inst.exit_initialization_mode()?;
        Ok(Status::OK)
    })
}

/// Moves to `state` (terminate, enter event mode, enter continuous-time mode).
pub unsafe fn enter<M: Model>(c: Handle, f: Call, state: Mode) -> Status {
    call::<M>(c, f, |inst| {
        inst.core.mode = state;
        Ok(Status::OK)
    })
}

pub unsafe fn reset<M: Model>(c: Handle, f: Call) -> Status {
    call::<M>(c, f, |inst| {
        inst.core = Core::new();
        Ok(Status::OK)
    })
}

/// Shared body of the getters of numbers and Booleans: `read` converts a stored value.
pub unsafe fn get<M: Model, T>(
    c: Handle,
    f: Call,
    vr: *const u32,
    n: usize,
    out: *mut T,
    wanted: BaseType,
    read: impl Fn(&Value) -> T,
) -> Status {
    call::<M>(c, f, |inst| {
        let vrs = slice(vr, n, references::<M>(inst.version), "vr")?;
        let out = slice_mut(out, n, references::<M>(inst.version), "value")?;
        inst.get(vrs, out, wanted, read)?;
        Ok(Status::OK)
    })
}

/// Reads a Real as a number (NaN never leaves: [`Instance::get`] refuses non-finite values).
pub fn real(v: &Value) -> f64 {
    if let Value::Real(x) = v {
        *x
    } else {
        f64::NAN
    }
}

/// Reads an Integer.
pub fn integer(v: &Value) -> i32 {
    if let Value::Integer(x) = v {
        *x
    } else {
        0
    }
}

pub unsafe fn get_string<M: Model>(c: Handle, f: Call, vr: *const u32, n: usize, value: *mut *const c_char) -> Status {
    call::<M>(c, f, |inst| {
        let vrs = slice(vr, n, references::<M>(inst.version), "vr")?;
        let out = slice_mut(value, n, references::<M>(inst.version), "value")?;
        let mut texts = vec![CString::default(); n];
        inst.get(vrs, &mut texts, BaseType::String, |v| match v {
            Value::String(s) => CString::new(s.replace('\0', " ")).unwrap_or_default(),
            _ => CString::default(),
        })?;
        // The pointers stay valid until the next GetString on this instance (FMI 2.0, 2.1.7).
        inst.strings = texts;
        out.iter_mut().zip(&inst.strings).for_each(|(o, s)| *o = s.as_ptr());
        Ok(Status::OK)
    })
}

/// Shared body of the setters of variables of type `wanted`: `convert` checks and wraps one C
/// value.
pub unsafe fn set<M: Model, T: Copy>(
    c: Handle,
    f: Call,
    (vr, n, value): (*const u32, usize, *const T),
    wanted: BaseType,
    convert: impl Fn(T) -> Result<Value, String>,
) -> Status {
    call::<M>(c, f, |inst| {
        let vrs = slice(vr, n, references::<M>(inst.version), "vr")?;
        let values = slice(value, n, references::<M>(inst.version), "value")?
            .iter()
            .map(|&x| convert(x))
            .collect::<Result<Vec<_>, _>>()?;
        inst.set(vrs, wanted, values)?;
        Ok(Status::OK)
    })
}

/// A string value of a setter.
pub unsafe fn string_value(p: *const c_char) -> Result<Value, String> {
    text(p).map(|s| Value::String(s.to_owned())).ok_or_else(|| "a string value is NULL or not UTF-8".into())
}

pub unsafe fn get_fmu_state<M: Model>(c: Handle, f: Call, state: *mut FmuState) -> Status {
    call::<M>(c, f, |inst| {
        let out = state.as_mut().ok_or("FMUstate is NULL")?;
        if out.is_null() {
            *out = new_fmu_state(inst, inst.core.clone());
        } else {
            // FMI 2.0, 2.1.8 (FMI 3.0, 2.3.6.3): a non-NULL *FMUstate is a state of this
            // instance, to overwrite.
            let core = inst.core.clone();
            *own_fmu_state(inst, *out)? = core;
        }
        Ok(Status::OK)
    })
}

/// A new FMU state of `inst` holding `core`, registered so that freeing the instance frees it.
fn new_fmu_state<M: Model>(inst: &mut Instance<M>, core: Core<M>) -> FmuState {
    let s = Box::into_raw(Box::new(core));
    inst.fmu_states.push(s);
    s as FmuState
}

/// The FMU state behind a pointer if this instance allocated it and it was not freed: found in
/// the instance's list, so no pointer the importer passes is dereferenced unless it is ours.
fn own_fmu_state<'a, M: Model>(inst: &Instance<M>, s: FmuState) -> Result<&'a mut Core<M>, String> {
    let p = s as *mut Core<M>;
    if s.is_null() || !inst.fmu_states.contains(&p) {
        let v = inst.version;
        return Err(format!(
            "FMUstate {s:p} is NULL, freed, or not a state of this instance of {} ({} or {} of this instance make one)",
            M::INFO.identifier,
            v.function("fmi2GetFMUstate"),
            v.function("fmi2DeSerializeFMUstate")
        ));
    }
    // SAFETY: the pointer is one this instance allocated and has not freed.
    Ok(unsafe { &mut *p })
}

pub unsafe fn set_fmu_state<M: Model>(c: Handle, f: Call, state: FmuState) -> Status {
    call::<M>(c, f, |inst| {
        inst.core = own_fmu_state(inst, state)?.clone();
        Ok(Status::OK)
    })
}

pub unsafe fn free_fmu_state<M: Model>(c: Handle, f: Call, state: *mut FmuState) -> Status {
    call::<M>(c, f, |inst| {
        let p = state.as_mut().ok_or("FMUstate is NULL")?;
        if p.is_null() {
            return Ok(Status::OK);
        }
        let s = own_fmu_state(inst, *p)? as *mut Core<M>;
        inst.fmu_states.retain(|&x| x != s);
        drop(Box::from_raw(s));
        *p = std::ptr::null_mut();
        Ok(Status::OK)
    })
}

pub unsafe fn serialized_fmu_state_size<M: Model>(c: Handle, f: Call, state: FmuState, size: *mut usize) -> Status {
    call::<M>(c, f, |inst| {
        let out = size.as_mut().ok_or("size is NULL")?;
        *out = snapshot::serialize(own_fmu_state(inst, state)?, &inst.guid, (inst.version, inst.interface)).len();
        Ok(Status::OK)
    })
}

pub unsafe fn serialize_fmu_state<M: Model>(
    c: Handle,
    f: Call,
    state: FmuState,
    bytes: *mut u8,
    size: usize,
) -> Status {
    call::<M>(c, f, |inst| {
        let data = snapshot::serialize(own_fmu_state(inst, state)?, &inst.guid, (inst.version, inst.interface));
        if data.len() != size {
            return Err(format!(
                "size = {size} bytes, but the state needs {} ({})",
                data.len(),
                inst.version.function("fmi2SerializedFMUstateSize")
            ));
        }
        slice_mut(bytes, size, (data.len(), "the state's size"), "serializedState")?.copy_from_slice(&data);
        Ok(Status::OK)
    })
}

pub unsafe fn deserialize_fmu_state<M: Model>(
    c: Handle,
    f: Call,
    bytes: *const u8,
    size: usize,
    state: *mut FmuState,
) -> Status {
    call::<M>(c, f, |inst| {
        // The bytes are read as far as the header first: `size` must be the length it announces.
        let head = snapshot::head_len(&inst.guid);
        let limit = (size.min(head), "the state's header");
        let prefix = slice(bytes, size.min(head), limit, "serializedState")?;
        let data = match snapshot::announced_len(prefix) {
            Some(n) if n != size => return Err(format!("size = {size} bytes, but the state's header announces {n}")),
            Some(_) => slice(bytes, size, (size, "the length the header announces"), "serializedState")?,
            // Not a header of this format: the prefix tells why.
            None => prefix,
        };
        let out = state.as_mut().ok_or("FMUstate is NULL")?;
        let core = snapshot::deserialize::<M>(data, &inst.guid, (inst.version, inst.interface))?;
        if core.mode == Mode::EventMode && inst.interface == Interface::CoSimulation && !inst.event_mode_used {
            return Err("the state was saved in Event Mode; this Co-Simulation instance has no Event Mode \
                        (eventModeUsed = false)"
                .into());
        }
        *out = new_fmu_state(inst, core);
        Ok(Status::OK)
    })
}

/// Shared body of the functions boomsim does not provide.
pub fn unsupported<M: Model>(c: Handle, f: Call, why: &str) -> Status {
    call::<M>(c, f, |_| Err(format!("not supported: {why}")))
}

/// The directional derivative (FMI 2.0, 2.1.9; FMI 3.0, 2.3.11), for the models that provide it.
pub unsafe fn get_directional_derivative<M: Model>(
    c: Handle,
    f: Call,
    (unknown, n_unknown): (*const u32, usize),
    (known, n_known): (*const u32, usize),
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> Status {
    if !M::DIRECTIONAL_DERIVATIVES {
        return unsupported::<M>(c, f, "providesDirectionalDerivative=\"false\"");
    }
    call::<M>(c, f, |inst| {
        let name = |fmi2| inst.version.argument(fmi2);
        let limit = references::<M>(inst.version);
        let unknowns = slice(unknown, n_unknown, limit, name("vUnknown_ref"))?;
        let knowns = slice(known, n_known, limit, name("vKnown_ref"))?;
        let seeds = slice(dv_known, n_known, limit, name("dvKnown"))?;
        let out = slice_mut(dv_unknown, n_unknown, limit, name("dvUnknown"))?;
        inst.directional_derivative(unknowns, knowns, seeds, out)?;
        Ok(Status::OK)
    })
}

/// doStep: OK or Warning when done, Discard (logged) when stopped at the last good time.
pub fn do_step<M: Model>(inst: &mut Instance<M>, function: &str, t: f64, h: f64) -> Result<Status, String> {
    let step = inst.do_step(t, h)?;
    Ok(step_status(inst, function, step))
}

/// The status of a step carried out, its warning or why it was discarded logged.
fn step_status<M: Model>(inst: &Instance<M>, function: &str, step: Step) -> Status {
    match step {
        Step::Done(warning) => warn(inst, function, warning),
        Step::Discarded(why) => {
            inst.log.status(Status::Discard, &format!("{function}: {why}"));
            Status::Discard
        }
    }
}

/// The instance behind `c` for one phase of a [`call_reentrant`] body.
///
/// # Safety
/// `c` was checked by `call_reentrant`; no other borrow of the instance may be alive.
pub unsafe fn borrow<'a, M: Model>(c: Handle, f: Call) -> Result<&'a mut Instance<M>, String> {
    instance::<M>(c, f.version).ok_or_else(|| "no instance".into())
}

/// FMI 3.0 doStep of an instance whose master provides intermediate update (4.2.3): the step
/// runs while the instance is free for the master's calls from its callback (the model and the
/// step's values are the step's own meanwhile, the model's log messages are kept and logged when
/// it ends); without a master, [`do_step`].
///
/// # Safety
/// As [`borrow`]: `c` was checked by `call_reentrant`, and no borrow of the instance is alive.
pub unsafe fn do_step_with_master<M: Model>(c: Handle, f: Call, t: f64, h: f64) -> Result<Status, String> {
    let inst = borrow::<M>(c, f)?;
    let Some(master) = inst.master.clone() else {
        return do_step(inst, f.function, t, h);
    };
    let mut begun = inst.begin_step(t, h)?;
    let mut log = KeptLog::new(&inst.log, M::INFO.log_categories);
    let (values, input_derivatives) = (inst.core.values.clone(), inst.core.input_derivatives.clone());
    let can_return_early = inst.early_return_allowed;
    let mut callback = Callback::<M> { c, f, values: &values, master, can_return_early, model: PhantomData };
    // No borrow of the instance while the step runs: the callback's calls borrow it.
    let result = begun.run((&values, &input_derivatives), &mut log, Some(&mut callback));
    let inst = borrow::<M>(c, f)?;
    log.replay(&inst.log);
    let step = inst.end_step(begun, result)?;
    Ok(step_status(inst, f.function, step))
}

/// The master's intermediateUpdate callback during one doStep (FMI 3.0, 4.2.3), through the
/// instance's handle: before each attempted integrator step it asks for the intermediate inputs
/// at the step's end (`intermediateVariableSetRequested`, tentative: `intermediateStepFinished`
/// false), after each accepted one it tells the time reached (`intermediateStepFinished`) and
/// takes an early-return request (`canReturnEarly` with `earlyReturnAllowed`). Outputs are not
/// offered (`intermediateVariableGetAllowed` false: no output has `intermediateUpdate="true"`).
struct Callback<'a, M: Model> {
    c: Handle,
    f: Call,
    master: Master,
    /// The variable values at the step's start (the inputs the master did not require).
    values: &'a Values,
    can_return_early: bool,
    model: PhantomData<M>,
}

impl<M: Model> Callback<'_, M> {
    /// Calls the master in Intermediate Update Mode at `t`; returns its early-return request.
    fn call(&mut self, t: f64, set_requested: bool, finished: bool) -> Result<Option<f64>, String> {
        // SAFETY: each borrow ends before the callback runs, and the callback's own calls end
        // before the next borrow.
        let inst = unsafe { borrow::<M>(self.c, self.f) }?;
        // After a failed call of the master's the instance is Terminated (FMI 3.0, 2.3.1) and
        // stays so: no further callback, whose success would otherwise hide the failure.
        if inst.core.mode != Mode::StepComplete {
            return Err("a call in intermediate update failed".into());
        }
        inst.core.mode = Mode::IntermediateUpdate;
        inst.set_requested = set_requested;
        let can_return_early = self.can_return_early && finished;
        let (mut requested, mut time) = (false, t);
        unsafe {
            (self.master.callback)(
                self.master.environment,
                t,
                set_requested,
                false,
                finished,
                can_return_early,
                &mut requested,
                &mut time,
            )
        };
        let inst = unsafe { borrow::<M>(self.c, self.f) }?;
        inst.set_requested = false;
        if inst.core.mode != Mode::IntermediateUpdate {
            return Err("a call in intermediate update failed".into());
        }
        inst.core.mode = Mode::StepComplete;
        Ok((requested && can_return_early && time.is_finite()).then_some(time))
    }
}

impl<M: Model> Intermediate for Callback<'_, M> {
    /// The master's values of the inputs it required, the step's start values of the others.
    fn inputs(&mut self, t: f64, vrs: &[u32], out: &mut [f64]) -> Result<(), String> {
        if !self.master.inputs.is_empty() {
            self.call(t, true, false)?;
        }
        let inst = unsafe { borrow::<M>(self.c, self.f) }?;
        for (&r, u) in vrs.iter().zip(out) {
            let values = if self.master.inputs.contains(&r) { &inst.core.values } else { self.values };
            *u = values.real(r);
        }
        Ok(())
    }

    fn accepted(&mut self, t: f64) -> Option<f64> {
        self.call(t, false, true).ok().flatten()
    }
}

/// A model's log during a step that runs without a borrow of the instance: the messages of its
/// enabled categories and its warnings, logged through the instance's logger when the step ends.
struct KeptLog {
    enabled: Vec<&'static str>,
    /// (category, or None for a warning; message).
    messages: Vec<(Option<&'static str>, String)>,
}

impl KeptLog {
    fn new(logger: &Logger, categories: &[(&'static str, &'static str)]) -> Self {
        let enabled = categories.iter().map(|&(c, _)| c).filter(|c| logger.category_enabled(c)).collect();
        KeptLog { enabled, messages: Vec::new() }
    }

    fn replay(self, logger: &Logger) {
        for (category, message) in self.messages {
            match category {
                Some(c) => logger.info(c, &message),
                None => logger.status(Status::Warning, &message),
            }
        }
    }
}

impl Log for KeptLog {
    fn enabled(&self, category: &str) -> bool {
        self.enabled.contains(&category)
    }
    fn info(&mut self, category: &str, message: &str) {
        if let Some(&c) = self.enabled.iter().find(|&&c| c == category) {
            self.messages.push((Some(c), message.to_owned()));
        }
    }
    fn warning(&mut self, message: &str) {
        self.messages.push((None, message.to_owned()));
    }
}

/// completedIntegratorStep: no step events (`completedIntegratorStepNotNeeded`,
/// `needsCompletedIntegratorStep="false"`), so neither flag is ever set.
pub unsafe fn completed_integrator_step<M: Model, B: From<bool>>(
    c: Handle,
    f: Call,
    enter_event_mode: *mut B,
    terminate: *mut B,
) -> Status {
    call::<M>(c, f, |inst| {
        let enter = enter_event_mode.as_mut().ok_or("enterEventMode is NULL")?;
        let term = terminate.as_mut().ok_or("terminateSimulation is NULL")?;
        (*enter, *term) = (B::from(false), B::from(false));
        inst.core.last_successful_time = inst.core.time;
        Ok(Status::OK)
    })
}

pub unsafe fn set_time<M: Model>(c: Handle, f: Call, time: f64) -> Status {
    call::<M>(c, f, |inst| {
        inst.set_time(time)?;
        Ok(Status::OK)
    })
}

/// The continuous states: any finite ones ([`Model::set_continuous_states`]).
pub unsafe fn set_continuous_states<M: Model>(c: Handle, f: Call, x: *const f64, nx: usize) -> Status {
    call::<M>(c, f, |inst| {
        Instance::<M>::check_states(nx)?;
        inst.set_continuous_states(slice(x, nx, states::<M>(), "x")?)?;
        Ok(Status::OK)
    })
}

pub unsafe fn get_continuous_states<M: Model>(c: Handle, f: Call, x: *mut f64, nx: usize) -> Status {
    call::<M>(c, f, |inst| {
        Instance::<M>::check_states(nx)?;
        inst.continuous_states(slice_mut(x, nx, states::<M>(), "x")?)?;
        Ok(Status::OK)
    })
}

/// The state derivatives; Discard (FMI 2.0, 2.1.3: retry with a smaller step) where the states
/// are outside the model's domain.
pub unsafe fn get_derivatives<M: Model>(c: Handle, f: Call, dx: *mut f64, nx: usize) -> Status {
    call::<M>(c, f, |inst| {
        Instance::<M>::check_states(nx)?;
        match inst.derivatives(slice_mut(dx, nx, states::<M>(), "derivatives")?)? {
            None => Ok(Status::OK),
            Some(why) => {
                inst.log.status(Status::Discard, &format!("{}: {why}", f.function));
                Ok(Status::Discard)
            }
        }
    })
}

pub unsafe fn get_event_indicators<M: Model>(c: Handle, f: Call, z: *mut f64, ni: usize) -> Status {
    call::<M>(c, f, |inst| {
        let limit = (M::EVENT_INDICATORS.len(), "the model's event indicators");
        Instance::<M>::check_count("ni", ni, limit.0, "event indicators")?;
        inst.event_indicators(slice_mut(z, ni, limit, "eventIndicators")?)?;
        Ok(Status::OK)
    })
}

pub unsafe fn get_nominals_of_continuous_states<M: Model>(c: Handle, f: Call, x: *mut f64, nx: usize) -> Status {
    call::<M>(c, f, |_| {
        Instance::<M>::check_states(nx)?;
        let out = slice_mut(x, nx, states::<M>(), "x_nominal")?;
        out.iter_mut().zip(M::STATES).for_each(|(o, s)| *o = s.nominal);
        Ok(Status::OK)
    })
}
