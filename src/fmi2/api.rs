//! The 44 FMI 2.0 functions (25 common, 9 Co-Simulation, 10 Model Exchange), generic over the
//! model. The export macro
//! ([`crate::export_fmu`]) forwards each `#[no_mangle] extern "C"` symbol here.
//!
//! Every function checks its pointers and the state machine, catches panics, and reports
//! failures through the logger with the instance name (ARCHITECTURE.md, principle 4).
#![allow(clippy::missing_safety_doc)]

use super::fmu_state;
use super::guid::guid;
use super::instance::{Core, Instance, Step, Warning};
use super::log::{Logger, LOG_FMI_CALLS};
use super::model::Model;
use super::state::{allowed, describe, Interface, Rule, State};
use super::types::*;
use super::variables::{BaseType, Value};
use std::ffi::{CStr, CString};
use std::os::raw::{c_char, c_int};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The instance behind a component pointer, if it is one of ours for this model.
unsafe fn instance<'a, M: Model>(c: fmi2Component) -> Option<&'a mut Instance<M>> {
    let inst = (c as *mut Instance<M>).as_mut()?;
    (inst.magic == Instance::<M>::MAGIC).then_some(inst)
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_default()
}

/// Runs `body` for a valid instance in an allowed state; errors are logged, panics caught.
fn call<M: Model>(
    c: fmi2Component,
    function: &str,
    rule: Rule,
    body: impl FnOnce(&mut Instance<M>) -> Result<fmi2Status, String>,
) -> fmi2Status {
    // SAFETY: FMI requires `c` to be a pointer returned by fmi2Instantiate; a null or foreign
    // pointer is detected by the magic tag where the memory is readable.
    let Some(inst) = (unsafe { instance::<M>(c) }) else {
        return fmi2Status::Error;
    };
    let result = catch_unwind(AssertUnwindSafe(|| {
        if inst.log.is_enabled(LOG_FMI_CALLS) {
            inst.log.info("logFmiCalls", function);
        }
        if let Some(interface) = rule.interface.filter(|&i| i != inst.interface) {
            return Err(format!(
                "a {interface:?} function, but this instance was instantiated for {:?}",
                inst.interface
            ));
        }
        let state = inst.core.state;
        if rule.states & state.bit() == 0 {
            return Err(format!("illegal call in state {state:?}; it is allowed in: {}", describe(rule.states)));
        }
        body(inst)
    }));
    match result {
        Ok(Ok(status)) => status,
        Ok(Err(message)) => {
            inst.log.status(fmi2Status::Error, &format!("{function}: {message}"));
            fmi2Status::Error
        }
        Err(p) => {
            inst.core.state = State::Error;
            let m = format!(
                "{function}: internal error: {}; the instance is now in the Error state (fmi2Reset or fmi2FreeInstance)",
                panic_text(p.as_ref())
            );
            inst.log.status(fmi2Status::Error, &m);
            fmi2Status::Error
        }
    }
}

/// fmi2Warning with the message logged if there is one, else fmi2OK.
fn warn<M: Model>(inst: &Instance<M>, function: &str, warning: Warning) -> fmi2Status {
    match warning {
        Some(w) => {
            inst.log.status(fmi2Status::Warning, &format!("{function}: {w}"));
            fmi2Status::Warning
        }
        None => fmi2Status::OK,
    }
}

/// A slice from a C array; NULL is an error unless `n` is 0.
unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err(format!("{what} is NULL but {n} elements were announced"))
    } else {
        Ok(std::slice::from_raw_parts(p, n))
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if p.is_null() {
        Err(format!("{what} is NULL but {n} elements were announced"))
    } else {
        Ok(std::slice::from_raw_parts_mut(p, n))
    }
}

unsafe fn text<'a>(p: fmi2String) -> Option<&'a str> {
    (!p.is_null()).then(|| CStr::from_ptr(p).to_str().ok()).flatten()
}

pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

/// fmi2Instantiate. The memory callbacks may be NULL: the FMU declares
/// `canNotUseMemoryManagementFunctions="true"` and never calls them (FMI 2.0.4, 2.1.5: an importer
/// may then pass NULL; hosts built on the FMI Library and some Reference-FMUs tools do). A NULL
/// logger is accepted too: the instance then runs silently, its statuses still tell every failure
/// (FMI 2.0 requires a logger; refusing would leave the importer without any reason at all).
pub unsafe fn instantiate<M: Model>(
    name: fmi2String,
    fmu_type: c_int,
    fmu_guid: fmi2String,
    _resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    catch_unwind(|| {
        let f = functions.as_ref().copied()?;
        let instance_name = text(name).unwrap_or("");
        let logger = Logger::new(f.logger, f.componentEnvironment, instance_name, M::INFO.log_categories, logging_on != 0);
        let fail = |message: String| {
            logger.status(fmi2Status::Error, &format!("fmi2Instantiate: {message}"));
            None
        };
        let expected = guid::<M>();
        if instance_name.is_empty() {
            return fail("instanceName must be a non-empty UTF-8 string".into());
        }
        let interface = match fmu_type {
            FMI2_MODEL_EXCHANGE => Interface::ModelExchange,
            FMI2_COSIMULATION => Interface::CoSimulation,
            _ => {
                return fail(format!(
                    "fmuType = {fmu_type} is outside its valid range: fmi2ModelExchange (0) or fmi2CoSimulation (1)"
                ))
            }
        };
        match text(fmu_guid) {
            Some(g) if g == expected => {}
            g => {
                return fail(format!(
                    "fmuGUID = {g:?} does not match this binary's GUID {expected}: modelDescription.xml and binary come from different builds"
                ))
            }
        }
        Some(Box::into_raw(Box::new(Instance::<M>::new(logger, expected, interface))) as fmi2Component)
    })
    .ok()
    .flatten()
    .unwrap_or(std::ptr::null_mut())
}

/// fmi2FreeInstance, with every FMU state of the instance the importer did not free.
pub unsafe fn free_instance<M: Model>(c: fmi2Component) {
    let status = call::<M>(c, "fmi2FreeInstance", allowed::FREE_INSTANCE, |_| Ok(fmi2Status::OK));
    if status == fmi2Status::OK {
        let mut inst = Box::from_raw(c as *mut Instance<M>);
        inst.magic = 0;
        for s in inst.fmu_states.drain(..) {
            drop(Box::from_raw(s));
        }
    }
}

pub unsafe fn set_debug_logging<M: Model>(
    c: fmi2Component,
    on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    call::<M>(c, "fmi2SetDebugLogging", allowed::SET_DEBUG_LOGGING, |inst| {
        let names = slice(categories, n, "categories")?
            .iter()
            .map(|&p| text(p).ok_or_else(|| "a category name is NULL or not UTF-8".to_string()))
            .collect::<Result<Vec<_>, _>>()?;
        inst.log.set_debug_logging(on != 0, &names)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn setup_experiment<M: Model>(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: f64,
    start: f64,
    stop_defined: fmi2Boolean,
    stop: f64,
) -> fmi2Status {
    call::<M>(c, "fmi2SetupExperiment", allowed::SETUP_EXPERIMENT, |inst| {
        let warning = inst.setup_experiment(
            (tolerance_defined != 0).then_some(tolerance),
            start,
            (stop_defined != 0).then_some(stop),
        )?;
        Ok(warn(inst, "fmi2SetupExperiment", warning))
    })
}

pub unsafe fn enter_initialization_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    call::<M>(c, "fmi2EnterInitializationMode", allowed::ENTER_INITIALIZATION_MODE, |inst| {
        inst.enter_initialization_mode();
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn exit_initialization_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    call::<M>(c, "fmi2ExitInitializationMode", allowed::EXIT_INITIALIZATION_MODE, |inst| {
        inst.exit_initialization_mode()?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn terminate<M: Model>(c: fmi2Component) -> fmi2Status {
    call::<M>(c, "fmi2Terminate", allowed::TERMINATE, |inst| {
        inst.core.state = State::Terminated;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn reset<M: Model>(c: fmi2Component) -> fmi2Status {
    call::<M>(c, "fmi2Reset", allowed::RESET, |inst| {
        inst.core = Core::new();
        Ok(fmi2Status::OK)
    })
}

/// Shared body of the four getters.
unsafe fn get<M: Model, T>(
    c: fmi2Component,
    function: &str,
    vr: *const fmi2ValueReference,
    n: usize,
    out: *mut T,
    wanted: BaseType,
    read: impl Fn(&Value) -> T,
) -> fmi2Status {
    call::<M>(c, function, allowed::GET, |inst| {
        let vrs = slice(vr, n, "vr")?;
        let out = slice_mut(out, n, "value")?;
        inst.get(vrs, out, wanted, read)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_real<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut f64) -> fmi2Status {
    get::<M, f64>(
        c,
        "fmi2GetReal",
        vr,
        n,
        value,
        BaseType::Real,
        |v| if let Value::Real(x) = v { *x } else { f64::NAN },
    )
}

pub unsafe fn get_integer<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut c_int) -> fmi2Status {
    get::<M, c_int>(c, "fmi2GetInteger", vr, n, value, BaseType::Integer, |v| {
        if let Value::Integer(x) = v {
            *x
        } else {
            0
        }
    })
}

pub unsafe fn get_boolean<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut c_int) -> fmi2Status {
    get::<M, c_int>(c, "fmi2GetBoolean", vr, n, value, BaseType::Boolean, |v| {
        matches!(v, Value::Boolean(true)) as c_int
    })
}

pub unsafe fn get_string<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut fmi2String) -> fmi2Status {
    call::<M>(c, "fmi2GetString", allowed::GET, |inst| {
        let vrs = slice(vr, n, "vr")?;
        let out = slice_mut(value, n, "value")?;
        let mut texts = vec![CString::default(); n];
        inst.get(vrs, &mut texts, BaseType::String, |v| match v {
            Value::String(s) => CString::new(s.replace('\0', " ")).unwrap_or_default(),
            _ => CString::default(),
        })?;
        // The pointers stay valid until the next fmi2GetString on this instance (FMI 2.0, 2.1.7).
        inst.strings = texts;
        out.iter_mut().zip(&inst.strings).for_each(|(o, s)| *o = s.as_ptr());
        Ok(fmi2Status::OK)
    })
}

/// Shared body of the four setters.
unsafe fn set<M: Model, T: Copy>(
    c: fmi2Component,
    function: &str,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const T,
    convert: impl Fn(T) -> Result<Value, String>,
) -> fmi2Status {
    let rule = if function == "fmi2SetReal" { allowed::SET_REAL } else { allowed::SET_DISCRETE };
    call::<M>(c, function, rule, |inst| {
        let vrs = slice(vr, n, "vr")?;
        let values = slice(value, n, "value")?.iter().map(|&x| convert(x)).collect::<Result<Vec<_>, _>>()?;
        inst.set(vrs, values)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn set_real<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const f64) -> fmi2Status {
    set::<M, f64>(c, "fmi2SetReal", vr, n, value, |x| Ok(Value::Real(x)))
}

pub unsafe fn set_integer<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const c_int) -> fmi2Status {
    set::<M, c_int>(c, "fmi2SetInteger", vr, n, value, |x| Ok(Value::Integer(x)))
}

pub unsafe fn set_boolean<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const c_int) -> fmi2Status {
    set::<M, c_int>(c, "fmi2SetBoolean", vr, n, value, |x| match x {
        FMI2_FALSE => Ok(Value::Boolean(false)),
        FMI2_TRUE => Ok(Value::Boolean(true)),
        _ => Err(format!("{x} is not an fmi2Boolean; valid values are fmi2False (0) and fmi2True (1)")),
    })
}

pub unsafe fn set_string<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const fmi2String) -> fmi2Status {
    set::<M, fmi2String>(c, "fmi2SetString", vr, n, value, |p| {
        text(p).map(|s| Value::String(s.to_owned())).ok_or_else(|| "a string value is NULL or not UTF-8".into())
    })
}

pub unsafe fn get_fmu_state<M: Model>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    call::<M>(c, "fmi2GetFMUstate", allowed::FMU_STATE, |inst| {
        let out = state.as_mut().ok_or("FMUstate is NULL")?;
        if out.is_null() {
            *out = new_fmu_state(inst, inst.core.clone());
        } else {
            // FMI 2.0, 2.1.8: a non-NULL *FMUstate is a state of this instance, to overwrite.
            let core = inst.core.clone();
            *own_fmu_state(inst, *out)? = core;
        }
        Ok(fmi2Status::OK)
    })
}

/// A new FMU state of `inst` holding `core`, registered so that fmi2FreeInstance frees it.
fn new_fmu_state<M: Model>(inst: &mut Instance<M>, core: Core<M>) -> fmi2FMUstate {
    let s = Box::into_raw(Box::new(core));
    inst.fmu_states.push(s);
    s as fmi2FMUstate
}

/// The FMU state behind a pointer if this instance allocated it and it was not freed: found in
/// the instance's list, so no pointer the importer passes is dereferenced unless it is ours.
fn own_fmu_state<'a, M: Model>(inst: &Instance<M>, s: fmi2FMUstate) -> Result<&'a mut Core<M>, String> {
    let p = s as *mut Core<M>;
    if s.is_null() || !inst.fmu_states.contains(&p) {
        return Err(format!(
            "FMUstate {s:p} is NULL, freed, or not a state of this instance of {} (fmi2GetFMUstate or fmi2DeSerializeFMUstate of this instance make one)",
            M::INFO.identifier
        ));
    }
    // SAFETY: the pointer is one this instance allocated and has not freed.
    Ok(unsafe { &mut *p })
}

pub unsafe fn set_fmu_state<M: Model>(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    call::<M>(c, "fmi2SetFMUstate", allowed::FMU_STATE, |inst| {
        inst.core = own_fmu_state(inst, state)?.clone();
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn free_fmu_state<M: Model>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    call::<M>(c, "fmi2FreeFMUstate", allowed::FMU_STATE, |inst| {
        let p = state.as_mut().ok_or("FMUstate is NULL")?;
        if p.is_null() {
            return Ok(fmi2Status::OK);
        }
        let s = own_fmu_state(inst, *p)? as *mut Core<M>;
        inst.fmu_states.retain(|&x| x != s);
        drop(Box::from_raw(s));
        *p = std::ptr::null_mut();
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn serialized_fmu_state_size<M: Model>(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    call::<M>(c, "fmi2SerializedFMUstateSize", allowed::FMU_STATE, |inst| {
        let out = size.as_mut().ok_or("size is NULL")?;
        *out = fmu_state::serialize(own_fmu_state(inst, state)?, &inst.guid).len();
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn serialize_fmu_state<M: Model>(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    call::<M>(c, "fmi2SerializeFMUstate", allowed::FMU_STATE, |inst| {
        let data = fmu_state::serialize(own_fmu_state(inst, state)?, &inst.guid);
        if data.len() != size {
            return Err(format!(
                "size = {size} bytes, but the state needs {} (fmi2SerializedFMUstateSize)",
                data.len()
            ));
        }
        slice_mut(bytes as *mut u8, size, "serializedState")?.copy_from_slice(&data);
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn deserialize_fmu_state<M: Model>(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    call::<M>(c, "fmi2DeSerializeFMUstate", allowed::FMU_STATE, |inst| {
        let data = slice(bytes as *const u8, size, "serializedState")?;
        let out = state.as_mut().ok_or("FMUstate is NULL")?;
        let core = fmu_state::deserialize::<M>(data, &inst.guid)?;
        if let Some(other) = core.state.interface().filter(|&i| i != inst.interface) {
            return Err(format!(
                "the state was saved by a {other:?} instance (state {:?}); this instance is {:?}",
                core.state, inst.interface
            ));
        }
        *out = new_fmu_state(inst, core);
        Ok(fmi2Status::OK)
    })
}

/// Shared body of the functions boomsim does not provide.
fn unsupported<M: Model>(c: fmi2Component, function: &str, rule: Rule, why: &str) -> fmi2Status {
    call::<M>(c, function, rule, |_| Err(format!("not supported: {why}")))
}

/// fmi2GetDirectionalDerivative (FMI 2.0, 2.1.9), for the models that provide it.
pub unsafe fn get_directional_derivative<M: Model>(
    c: fmi2Component,
    unknown: *const u32,
    n_unknown: usize,
    known: *const u32,
    n_known: usize,
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> fmi2Status {
    if !M::DIRECTIONAL_DERIVATIVES {
        return unsupported::<M>(
            c,
            "fmi2GetDirectionalDerivative",
            allowed::DIRECTIONAL_DERIVATIVE,
            "providesDirectionalDerivative=\"false\"",
        );
    }
    call::<M>(c, "fmi2GetDirectionalDerivative", allowed::DIRECTIONAL_DERIVATIVE, |inst| {
        let unknowns = slice(unknown, n_unknown, "vUnknown_ref")?;
        let knowns = slice(known, n_known, "vKnown_ref")?;
        let seeds = slice(dv_known, n_known, "dvKnown")?;
        let out = slice_mut(dv_unknown, n_unknown, "dvUnknown")?;
        inst.directional_derivative(unknowns, knowns, seeds, out)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn set_real_input_derivatives<M: Model>(
    c: fmi2Component,
    vr: *const u32,
    n: usize,
    order: *const c_int,
    value: *const f64,
) -> fmi2Status {
    call::<M>(c, "fmi2SetRealInputDerivatives", allowed::SET_INPUT_DERIVATIVES, |inst| {
        inst.set_input_derivatives(slice(vr, n, "vr")?, slice(order, n, "order")?, slice(value, n, "value")?)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_real_output_derivatives<M: Model>(c: fmi2Component) -> fmi2Status {
    unsupported::<M>(
        c,
        "fmi2GetRealOutputDerivatives",
        allowed::GET_OUTPUT_DERIVATIVES,
        "maxOutputDerivativeOrder=\"0\"",
    )
}

pub unsafe fn do_step<M: Model>(c: fmi2Component, t: f64, h: f64, _no_set_prior: fmi2Boolean) -> fmi2Status {
    call::<M>(c, "fmi2DoStep", allowed::DO_STEP, |inst| match inst.do_step(t, h)? {
        Step::Done(warning) => Ok(warn(inst, "fmi2DoStep", warning)),
        Step::Discarded(why) => {
            inst.log.status(fmi2Status::Discard, &format!("fmi2DoStep: {why}"));
            Ok(fmi2Status::Discard)
        }
    })
}

pub unsafe fn cancel_step<M: Model>(c: fmi2Component) -> fmi2Status {
    unsupported::<M>(
        c,
        "fmi2CancelStep",
        allowed::CANCEL_STEP,
        "doStep is synchronous (canRunAsynchronuously=\"false\")",
    )
}

pub unsafe fn get_status<M: Model>(c: fmi2Component) -> fmi2Status {
    unsupported::<M>(c, "fmi2GetStatus", allowed::GET_STATUS, "no fmi2Status kind is defined for a synchronous slave")
}

pub unsafe fn get_integer_status<M: Model>(c: fmi2Component) -> fmi2Status {
    unsupported::<M>(c, "fmi2GetIntegerStatus", allowed::GET_STATUS, "FMI 2.0 defines no integer status")
}

pub unsafe fn get_string_status<M: Model>(c: fmi2Component) -> fmi2Status {
    unsupported::<M>(
        c,
        "fmi2GetStringStatus",
        allowed::GET_STATUS,
        "no string status (fmi2PendingStatus needs an asynchronous doStep)",
    )
}

pub unsafe fn get_real_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut f64) -> fmi2Status {
    call::<M>(c, "fmi2GetRealStatus", allowed::GET_STATUS, |inst| {
        if kind != FMI2_LAST_SUCCESSFUL_TIME {
            return Err(format!("status kind {kind} is not available; only fmi2LastSuccessfulTime (2) is"));
        }
        *value.as_mut().ok_or("value is NULL")? = inst.core.last_successful_time;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_boolean_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut fmi2Boolean) -> fmi2Status {
    call::<M>(c, "fmi2GetBooleanStatus", allowed::GET_STATUS, |inst| {
        if kind != FMI2_TERMINATED {
            return Err(format!("status kind {kind} is not available; only fmi2Terminated (3) is"));
        }
        // The slave asks to end the simulation only once a step has failed.
        *value.as_mut().ok_or("value is NULL")? = (inst.core.state == State::StepFailed) as fmi2Boolean;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn enter_event_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    call::<M>(c, "fmi2EnterEventMode", allowed::ENTER_EVENT_MODE, |inst| {
        inst.core.state = State::EventMode;
        Ok(fmi2Status::OK)
    })
}

/// fmi2NewDiscreteStates. The models have no discrete states and no time events; at a state
/// event (an event indicator changed sign) nothing is reinitialised either: the right-hand side
/// changes branch by itself, and the event only lets the integrator restart there. So the event
/// iteration ends at once.
pub unsafe fn new_discrete_states<M: Model>(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status {
    call::<M>(c, "fmi2NewDiscreteStates", allowed::NEW_DISCRETE_STATES, |_| {
        *info.as_mut().ok_or("fmi2EventInfo is NULL")? = fmi2EventInfo::default();
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn enter_continuous_time_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    call::<M>(c, "fmi2EnterContinuousTimeMode", allowed::ENTER_CONTINUOUS_TIME_MODE, |inst| {
        inst.core.state = State::ContinuousTimeMode;
        Ok(fmi2Status::OK)
    })
}

/// fmi2CompletedIntegratorStep: no step events (`completedIntegratorStepNotNeeded="true"`).
pub unsafe fn completed_integrator_step<M: Model>(
    c: fmi2Component,
    _no_set_prior: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate: *mut fmi2Boolean,
) -> fmi2Status {
    call::<M>(c, "fmi2CompletedIntegratorStep", allowed::COMPLETED_INTEGRATOR_STEP, |inst| {
        let enter = enter_event_mode.as_mut().ok_or("enterEventMode is NULL")?;
        let term = terminate.as_mut().ok_or("terminateSimulation is NULL")?;
        (*enter, *term) = (FMI2_FALSE, FMI2_FALSE);
        inst.core.last_successful_time = inst.core.time;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn set_time<M: Model>(c: fmi2Component, time: f64) -> fmi2Status {
    call::<M>(c, "fmi2SetTime", allowed::SET_TIME, |inst| {
        inst.set_time(time)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn set_continuous_states<M: Model>(c: fmi2Component, x: *const f64, nx: usize) -> fmi2Status {
    call::<M>(c, "fmi2SetContinuousStates", allowed::SET_CONTINUOUS_STATES, |inst| {
        inst.set_continuous_states(slice(x, nx, "x")?)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_continuous_states<M: Model>(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status {
    call::<M>(c, "fmi2GetContinuousStates", allowed::GET_CONTINUOUS_STATES, |inst| {
        inst.continuous_states(slice_mut(x, nx, "x")?)?;
        Ok(fmi2Status::OK)
    })
}

/// fmi2GetDerivatives; fmi2Discard (FMI 2.0, 2.1.3: retry with a smaller step) where the
/// states are outside the model's domain.
pub unsafe fn get_derivatives<M: Model>(c: fmi2Component, dx: *mut f64, nx: usize) -> fmi2Status {
    call::<M>(c, "fmi2GetDerivatives", allowed::GET_DERIVATIVES, |inst| {
        match inst.derivatives(slice_mut(dx, nx, "derivatives")?)? {
            None => Ok(fmi2Status::OK),
            Some(why) => {
                inst.log.status(fmi2Status::Discard, &format!("fmi2GetDerivatives: {why}"));
                Ok(fmi2Status::Discard)
            }
        }
    })
}

pub unsafe fn get_event_indicators<M: Model>(c: fmi2Component, z: *mut f64, ni: usize) -> fmi2Status {
    call::<M>(c, "fmi2GetEventIndicators", allowed::GET_EVENT_INDICATORS, |inst| {
        inst.event_indicators(slice_mut(z, ni, "eventIndicators")?)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_nominals_of_continuous_states<M: Model>(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status {
    call::<M>(c, "fmi2GetNominalsOfContinuousStates", allowed::GET_NOMINALS, |_| {
        let out = slice_mut(x, nx, "x_nominal")?;
        Instance::<M>::check_states(nx)?;
        out.iter_mut().zip(M::STATES).for_each(|(o, s)| *o = s.nominal);
        Ok(fmi2Status::OK)
    })
}
