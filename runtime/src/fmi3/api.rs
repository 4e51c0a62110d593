//! The FMI 3.0 functions of Model Exchange and Co-Simulation (and, refused, those of Scheduled
//! Execution, clocks and early return), generic over the model. The export macro
//! ([`crate::export_fmi3`]) forwards each symbol here; what FMI 2.0 does alike is in
//! [`crate::fmu::calls`], called with the function's FMI 3.0 name and its rule of [`allowed`].
#![allow(clippy::missing_safety_doc, clippy::too_many_arguments)]

use super::machine::{allowed, Interface, Mode, Rule};
use super::types::*;
use crate::fmu::calls::{self, call, slice, slice_mut, Call};
use crate::fmu::guid::token;
use crate::fmu::instance::{Instance, Master};
use crate::fmu::log::{num, Logger};
use crate::fmu::model::{clock_row, has_event_mode, Model};
use crate::fmu::variables::{BaseType, Value};
use crate::fmu::version::Version;
use std::ffi::CStr;
use std::os::raw::c_char;
use std::panic::catch_unwind;

/// The FMI 3.0 function `function` with its rule.
const fn at(function: &'static str, rule: Rule) -> Call {
    Call { version: Version::Fmi3, function, rule }
}

/// The importer's fmi3LogMessageCallback and its instance environment.
struct Sink(fmi3LogMessageCallback, fmi3InstanceEnvironment);

// SAFETY: the environment pointer is only handed back to the importer's callback, which FMI
// requires to be callable for this instance from whichever thread uses the instance.
unsafe impl Send for Sink {}

impl crate::fmu::log::Sink for Sink {
    fn emit(&self, _instance: &CStr, status: fmi3Status, category: &CStr, message: &CStr) {
        if let Some(log) = self.0 {
            // SAFETY: the callback of fmi3FunctionTypes.h with two NUL-terminated strings.
            unsafe { log(self.1, status, category.as_ptr(), message.as_ptr()) };
        }
    }
}

pub fn get_version() -> *const c_char {
    c"3.0".as_ptr()
}

/// The checks and the logger both instantiation functions share; `more` checks the rest.
/// A NULL `logMessage` is accepted: the instance runs silently, its statuses still tell every
/// failure.
unsafe fn instantiate<M: Model>(
    function: &str,
    (interface, event_mode_used, early_return_allowed): (Interface, bool, bool),
    (name, instantiation_token): (fmi3String, fmi3String),
    logging_on: bool,
    (environment, log_message): (fmi3InstanceEnvironment, fmi3LogMessageCallback),
    more: impl FnOnce() -> Result<Option<Master>, String>,
) -> fmi3Instance {
    catch_unwind(std::panic::AssertUnwindSafe(|| {
        let sink = Box::new(Sink(log_message, environment));
        let logger = Logger::new(Some(sink), calls::text(name).unwrap_or(""), M::INFO.log_categories, logging_on);
        let expected = token::<M>();
        let checked = calls::instance_name(name)
            .and_then(|_| {
                calls::check_identity(instantiation_token, "instantiationToken", "instantiationToken", &expected)
            })
            .and_then(|_| more());
        match checked {
            Ok(master) => calls::new_instance::<M>(logger, expected, Version::Fmi3, interface, |i| {
                (i.event_mode_used, i.early_return_allowed, i.master) = (event_mode_used, early_return_allowed, master);
            }),
            Err(message) => {
                logger.status(fmi3Status::Error, &format!("{function}: {message}"));
                std::ptr::null_mut()
            }
        }
    }))
    .unwrap_or(std::ptr::null_mut())
}

pub unsafe fn instantiate_model_exchange<M: Model>(
    name: fmi3String,
    instantiation_token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
) -> fmi3Instance {
    let f = "fmi3InstantiateModelExchange";
    instantiate::<M>(
        f,
        (Interface::ModelExchange, false, false),
        (name, instantiation_token),
        logging_on,
        (environment, log_message),
        || Ok(None),
    )
}

/// fmi3InstantiateCoSimulation: `eventModeUsed` for a model with a Clock (required) or event
/// indicators (`hasEventMode="true"`), else refused; `earlyReturnAllowed` makes a model with event
/// indicators end a step at their first root (`mightReturnEarlyFromDoStep="true"`); an
/// `intermediateUpdate` callback is called in every step of a model with intermediate inputs
/// (`providesIntermediateUpdate="true"`), which sets the `requiredIntermediateVariables` there.
pub unsafe fn instantiate_co_simulation<M: Model>(
    name: fmi3String,
    instantiation_token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    event_mode_used: fmi3Boolean,
    early_return_allowed: fmi3Boolean,
    required_intermediate_variables: *const fmi3ValueReference,
    n_required_intermediate_variables: usize,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
    intermediate_update: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let more = || {
        let mut master = None;
        if clock_row::<M>().is_some() && !event_mode_used {
            return Err(
                "eventModeUsed = false, but the FMU has a Clock, which needs Event Mode (FMI 3.0, 2.3.1: \"For FMUs \
                 that have clocks, eventModeUsed = fmi3True is required\")"
                    .into(),
            );
        }
        if !has_event_mode::<M>() && event_mode_used {
            return Err(
                "eventModeUsed = true, but the FMU has no event mode in Co-Simulation (hasEventMode=\"false\")".into(),
            );
        }
        let limit = (M::INTERMEDIATE_INPUTS.len(), "the model's intermediate inputs");
        let inputs = calls::slice(
            required_intermediate_variables,
            n_required_intermediate_variables,
            limit,
            "requiredIntermediateVariables",
        )?;
        if let Some(&r) = inputs.iter().find(|r| !M::INTERMEDIATE_INPUTS.contains(r)) {
            let intermediate = M::VARIABLES.iter().filter(|v| M::INTERMEDIATE_INPUTS.contains(&v.vr));
            let names: Vec<&str> = intermediate.map(|v| v.name).collect();
            return Err(format!(
                "requiredIntermediateVariables names value reference {r}, which has no intermediateUpdate=\"true\"; \
                 valid: {}",
                if names.is_empty() { "none (providesIntermediateUpdate=\"false\")".into() } else { names.join(", ") }
            ));
        }
        match intermediate_update {
            Some(callback) if !M::INTERMEDIATE_INPUTS.is_empty() => {
                master = Some(Master { callback, environment, inputs: inputs.to_vec() });
            }
            None if !inputs.is_empty() => {
                return Err("requiredIntermediateVariables are given, but intermediateUpdate is NULL".into());
            }
            _ => {}
        }
        Ok(master)
    };
    let f = "fmi3InstantiateCoSimulation";
    instantiate::<M>(
        f,
        (Interface::CoSimulation, event_mode_used, early_return_allowed),
        (name, instantiation_token),
        logging_on,
        (environment, log_message),
        more,
    )
}

/// fmi3InstantiateScheduledExecution: not provided (no `<ScheduledExecution>` element); NULL.
pub unsafe fn instantiate_scheduled_execution<M: Model>(
    name: fmi3String,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
) -> fmi3Instance {
    let sink = Box::new(Sink(log_message, environment));
    let logger = Logger::new(Some(sink), calls::text(name).unwrap_or(""), M::INFO.log_categories, logging_on);
    logger.status(
        fmi3Status::Error,
        "fmi3InstantiateScheduledExecution: not supported: the FMU provides Model Exchange and Co-Simulation only",
    );
    std::ptr::null_mut()
}

pub unsafe fn free_instance<M: Model>(c: fmi3Instance) {
    calls::free_instance::<M>(c, at("fmi3FreeInstance", allowed::FREE_INSTANCE))
}

pub unsafe fn set_debug_logging<M: Model>(
    c: fmi3Instance,
    on: fmi3Boolean,
    n: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    calls::set_debug_logging::<M>(c, at("fmi3SetDebugLogging", allowed::SET_DEBUG_LOGGING), on, n, categories)
}

/// fmi3EnterInitializationMode: the experiment (FMI 2.0's fmi2SetupExperiment) and the mode.
pub unsafe fn enter_initialization_mode<M: Model>(
    c: fmi3Instance,
    tolerance_defined: fmi3Boolean,
    tolerance: f64,
    start: f64,
    stop_defined: fmi3Boolean,
    stop: f64,
) -> fmi3Status {
    let f = at("fmi3EnterInitializationMode", allowed::ENTER_INITIALIZATION_MODE);
    call::<M>(c, f, |inst| {
        let status = calls::setup_experiment(
            inst,
            f.function,
            tolerance_defined.then_some(tolerance),
            start,
            stop_defined.then_some(stop),
        )?;
        inst.enter_initialization_mode();
        Ok(status)
    })
}

pub unsafe fn exit_initialization_mode<M: Model>(c: fmi3Instance) -> fmi3Status {
    calls::exit_initialization_mode::<M>(c, at("fmi3ExitInitializationMode", allowed::EXIT_INITIALIZATION_MODE))
}

/// fmi3EnterEventMode: Model Exchange from Continuous-Time Mode, Co-Simulation from Step Mode
/// when instantiated with `eventModeUsed` (4.2.2).
pub unsafe fn enter_event_mode<M: Model>(c: fmi3Instance) -> fmi3Status {
    call::<M>(c, at("fmi3EnterEventMode", allowed::ENTER_EVENT_MODE), |inst| {
        if inst.interface == Interface::CoSimulation && !inst.event_mode_used {
            return Err("not supported: the instance was instantiated with eventModeUsed = false".into());
        }
        inst.core.mode = Mode::EventMode;
        Ok(fmi3Status::OK)
    })
}

pub unsafe fn terminate<M: Model>(c: fmi3Instance) -> fmi3Status {
    calls::enter::<M>(c, at("fmi3Terminate", allowed::TERMINATE), Mode::Terminated)
}

pub unsafe fn reset<M: Model>(c: fmi3Instance) -> fmi3Status {
    calls::reset::<M>(c, at("fmi3Reset", allowed::RESET))
}

/// The variables are scalars: `nValues` must equal `nValueReferences`.
fn scalar_count(n_vr: usize, n_values: usize) -> Result<(), String> {
    if n_vr == n_values {
        return Ok(());
    }
    Err(format!(
        "nValues = {n_values}, but the {n_vr} value references name {n_vr} values (every variable is a scalar)"
    ))
}

/// A getter whose `nValues` is checked first.
unsafe fn get<M: Model, T>(
    c: fmi3Instance,
    f: Call,
    (vr, n, out, n_values): (*const u32, usize, *mut T, usize),
    wanted: BaseType,
    read: impl Fn(&Value) -> T,
) -> fmi3Status {
    if let Err(e) = scalar_count(n, n_values) {
        return call::<M>(c, f, |_| Err(e));
    }
    calls::get::<M, T>(c, f, vr, n, out, wanted, read)
}

/// A setter whose `nValues` is checked first.
unsafe fn set<M: Model, T: Copy>(
    c: fmi3Instance,
    f: Call,
    (vr, n, value, n_values): (*const u32, usize, *const T, usize),
    wanted: BaseType,
    convert: impl Fn(T) -> Result<Value, String>,
) -> fmi3Status {
    if let Err(e) = scalar_count(n, n_values) {
        return call::<M>(c, f, |_| Err(e));
    }
    calls::set::<M, T>(c, f, (vr, n, value), wanted, convert)
}

pub unsafe fn get_float64<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *mut f64, nv: usize) -> fmi3Status {
    get::<M, f64>(c, at("fmi3GetFloat64", allowed::GET), (vr, n, v, nv), BaseType::Real, calls::real)
}

pub unsafe fn get_int32<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *mut i32, nv: usize) -> fmi3Status {
    get::<M, i32>(c, at("fmi3GetInt32", allowed::GET), (vr, n, v, nv), BaseType::Integer, calls::integer)
}

/// fmi3GetInt64: the Enumerations (FMI 3.0, 2.4.7.4), the only Int64 variables.
pub unsafe fn get_int64<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *mut i64, nv: usize) -> fmi3Status {
    get::<M, i64>(c, at("fmi3GetInt64", allowed::GET), (vr, n, v, nv), BaseType::Enumeration, |v| {
        i64::from(calls::integer(v))
    })
}

pub unsafe fn get_boolean<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *mut bool, nv: usize) -> fmi3Status {
    get::<M, bool>(c, at("fmi3GetBoolean", allowed::GET), (vr, n, v, nv), BaseType::Boolean, |v| {
        matches!(v, Value::Boolean(true))
    })
}

pub unsafe fn get_string<M: Model>(
    c: fmi3Instance,
    vr: *const u32,
    n: usize,
    v: *mut fmi3String,
    nv: usize,
) -> fmi3Status {
    let f = at("fmi3GetString", allowed::GET);
    if let Err(e) = scalar_count(n, nv) {
        return call::<M>(c, f, |_| Err(e));
    }
    calls::get_string::<M>(c, f, vr, n, v)
}

pub unsafe fn set_float64<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *const f64, nv: usize) -> fmi3Status {
    set::<M, f64>(c, at("fmi3SetFloat64", allowed::SET_FLOAT64), (vr, n, v, nv), BaseType::Real, |x| Ok(Value::Real(x)))
}

pub unsafe fn set_int32<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *const i32, nv: usize) -> fmi3Status {
    set::<M, i32>(c, at("fmi3SetInt32", allowed::SET_DISCRETE), (vr, n, v, nv), BaseType::Integer, |x| {
        Ok(Value::Integer(x))
    })
}

/// fmi3SetInt64: the Enumerations. A value beyond the Int32 range is no item of any of them.
pub unsafe fn set_int64<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *const i64, nv: usize) -> fmi3Status {
    set::<M, i64>(c, at("fmi3SetInt64", allowed::SET_DISCRETE), (vr, n, v, nv), BaseType::Enumeration, |x| {
        i32::try_from(x).map(Value::Integer).map_err(|_| format!("{x} is no item of an Enumeration (each starts at 0)"))
    })
}

/// fmi3SetBoolean: the C `bool`s are read as bytes, so a value other than 0 or 1 is refused
/// instead of being undefined behaviour.
pub unsafe fn set_boolean<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *const u8, nv: usize) -> fmi3Status {
    set::<M, u8>(c, at("fmi3SetBoolean", allowed::SET_DISCRETE), (vr, n, v, nv), BaseType::Boolean, |x| {
        c_bool(x, "an fmi3Boolean", ("false", "true")).map(Value::Boolean)
    })
}

/// A C `bool` read as a byte: 0 or 1, anything else refused naming the type and its two values.
fn c_bool(x: u8, what: &str, (no, yes): (&str, &str)) -> Result<bool, String> {
    match x {
        0 | 1 => Ok(x == 1),
        _ => Err(format!("{x} is not {what}; valid values are {no} (0) and {yes} (1)")),
    }
}

pub unsafe fn set_string<M: Model>(
    c: fmi3Instance,
    vr: *const u32,
    n: usize,
    v: *const fmi3String,
    nv: usize,
) -> fmi3Status {
    let f = at("fmi3SetString", allowed::SET_DISCRETE);
    set::<M, fmi3String>(c, f, (vr, n, v, nv), BaseType::String, |p| calls::string_value(p))
}

/// The get and set functions of the types no variable has (Float32, Int8 ... UInt32, UInt64,
/// Binary, Clock): the first value reference is named with its variable's actual type; none is OK.
pub unsafe fn other_type<M: Model>(
    c: fmi3Instance,
    function: &'static str,
    set: bool,
    vr: *const u32,
    n: usize,
    ty: &str,
) -> fmi3Status {
    let rule = if set { allowed::SET_DISCRETE } else { allowed::GET };
    call::<M>(c, at(function, rule), |inst: &mut Instance<M>| {
        match slice(vr, n, calls::references::<M>(Version::Fmi3), "valueReferences")?.first() {
            Some(&r) => Err(inst.type_mismatch(r, ty)),
            None => Ok(fmi3Status::OK),
        }
    })
}

/// fmi3GetClock: whether the Clock is active (FMI 3.0, 2.3.5).
pub unsafe fn get_clock<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *mut bool) -> fmi3Status {
    let f = at("fmi3GetClock", allowed::GET_CLOCK);
    calls::get::<M, bool>(c, f, vr, n, v, BaseType::Clock, |v| matches!(v, Value::Clock(true)))
}

/// fmi3SetClock: activates input Clocks (FMI 3.0, 2.3.5). The C `bool`s are read as bytes, as in
/// fmi3SetBoolean.
pub unsafe fn set_clock<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, v: *const u8) -> fmi3Status {
    call::<M>(c, at("fmi3SetClock", allowed::SET_CLOCK), |inst| {
        let limit = calls::references::<M>(Version::Fmi3);
        let vrs = slice(vr, n, limit, "valueReferences")?;
        let active = slice(v, n, limit, "values")?
            .iter()
            .map(|&b| c_bool(b, "an fmi3Clock", ("fmi3ClockInactive", "fmi3ClockActive")))
            .collect::<Result<Vec<bool>, String>>()?;
        inst.set_clocks(vrs, &active)?;
        Ok(fmi3Status::OK)
    })
}

/// fmi3IntervalUnchanged: the only qualifier of a constant Clock (FMI 3.0, 2.2.8.4, the table of
/// allowed qualifiers, (2)).
const INTERVAL_UNCHANGED: fmi3IntervalQualifier = 1;

/// fmi3GetIntervalDecimal: a constant Clock's interval, always `fmi3IntervalUnchanged`.
pub unsafe fn get_interval_decimal<M: Model>(
    c: fmi3Instance,
    vr: *const u32,
    n: usize,
    intervals: *mut f64,
    qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    let f = at("fmi3GetIntervalDecimal", allowed::GET_INTERVAL);
    clock_timings::<M>(
        c,
        f,
        (vr, n),
        (intervals, "intervals"),
        |(interval, _)| interval,
        |limit| {
            slice_mut(qualifiers, n, limit, "qualifiers")?.fill(INTERVAL_UNCHANGED);
            Ok(())
        },
    )
}

/// A getter of the Clocks' constant timing: `pick` of (interval, shift) for each value reference
/// into `out`, after `more` (the other out-arguments).
unsafe fn clock_timings<M: Model>(
    c: fmi3Instance,
    f: Call,
    (vr, n): (*const u32, usize),
    (out, name): (*mut f64, &str),
    pick: impl Fn((f64, f64)) -> f64,
    more: impl FnOnce(calls::Limit) -> Result<(), String>,
) -> fmi3Status {
    call::<M>(c, f, |inst| {
        let limit = calls::references::<M>(Version::Fmi3);
        let vrs = slice(vr, n, limit, "valueReferences")?;
        let out = slice_mut(out, n, limit, name)?;
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = pick(inst.clock_timing(r)?);
        }
        more(limit)?;
        Ok(fmi3Status::OK)
    })
}

/// fmi3GetShiftDecimal: a constant Clock's shift (its first activation after the start time).
pub unsafe fn get_shift_decimal<M: Model>(c: fmi3Instance, vr: *const u32, n: usize, shifts: *mut f64) -> fmi3Status {
    let f = at("fmi3GetShiftDecimal", allowed::GET_SHIFT);
    clock_timings::<M>(c, f, (vr, n), (shifts, "shifts"), |(_, shift)| shift, |_| Ok(()))
}

/// The clock functions boomsim does not provide: for a model without a Clock, none; for a model
/// with its constant Clock, the fraction variants (`supportsFraction="false"`), the setters (the
/// interval and shift of a constant Clock are the modelDescription's) and Scheduled Execution's.
pub fn clock_unsupported<M: Model>(c: fmi3Instance, function: &'static str) -> fmi3Status {
    let why = match (clock_row::<M>(), function) {
        (None, _) => "the FMU has no clocks",
        (Some(_), f) if f.ends_with("Fraction") && f.starts_with("fmi3Get") => "supportsFraction=\"false\"",
        (Some(_), "fmi3ActivateModelPartition") => "the FMU provides no Scheduled Execution",
        (Some(_), _) => {
            "the Clock is constant (intervalVariability=\"constant\"): its interval and shift are the modelDescription's"
        }
    };
    calls::unsupported::<M>(c, at(function, allowed::UNSUPPORTED), why)
}

/// Functions boomsim does not provide, in any state.
pub fn unsupported<M: Model>(c: fmi3Instance, function: &'static str, why: &str) -> fmi3Status {
    calls::unsupported::<M>(c, at(function, allowed::UNSUPPORTED), why)
}

pub unsafe fn get_fmu_state<M: Model>(c: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    calls::get_fmu_state::<M>(c, at("fmi3GetFMUState", allowed::FMU_STATE), state)
}

pub unsafe fn set_fmu_state<M: Model>(c: fmi3Instance, state: fmi3FMUState) -> fmi3Status {
    calls::set_fmu_state::<M>(c, at("fmi3SetFMUState", allowed::FMU_STATE), state)
}

pub unsafe fn free_fmu_state<M: Model>(c: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    calls::free_fmu_state::<M>(c, at("fmi3FreeFMUState", allowed::FMU_STATE), state)
}

pub unsafe fn serialized_fmu_state_size<M: Model>(
    c: fmi3Instance,
    state: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    calls::serialized_fmu_state_size::<M>(c, at("fmi3SerializedFMUStateSize", allowed::FMU_STATE), state, size)
}

pub unsafe fn serialize_fmu_state<M: Model>(
    c: fmi3Instance,
    state: fmi3FMUState,
    bytes: *mut u8,
    size: usize,
) -> fmi3Status {
    calls::serialize_fmu_state::<M>(c, at("fmi3SerializeFMUState", allowed::FMU_STATE), state, bytes, size)
}

pub unsafe fn deserialize_fmu_state<M: Model>(
    c: fmi3Instance,
    bytes: *const u8,
    size: usize,
    state: *mut fmi3FMUState,
) -> fmi3Status {
    calls::deserialize_fmu_state::<M>(c, at("fmi3DeserializeFMUState", allowed::FMU_STATE), bytes, size, state)
}

/// The scalar counts of the derivative functions: `nSeed` and `nSensitivity` against the
/// references they go with.
fn derivative_counts(
    n_seed: usize,
    seeds_for: usize,
    n_sensitivity: usize,
    sensitivities_for: usize,
) -> Result<(), String> {
    if n_seed != seeds_for || n_sensitivity != sensitivities_for {
        return Err(format!(
            "nSeed = {n_seed} and nSensitivity = {n_sensitivity}, but the references name {seeds_for} and {sensitivities_for} scalars"
        ));
    }
    Ok(())
}

/// The arguments of fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative: the unknowns'
/// and the knowns' value references, the seeds and the sensitivities, each with its count.
pub struct Derivative {
    pub unknown: (*const u32, usize),
    pub known: (*const u32, usize),
    pub seed: (*const f64, usize),
    pub sensitivity: (*mut f64, usize),
}

/// fmi3GetDirectionalDerivative: the sensitivities of the unknowns to the seeded knowns.
pub unsafe fn get_directional_derivative<M: Model>(c: fmi3Instance, d: Derivative) -> fmi3Status {
    let f = at("fmi3GetDirectionalDerivative", allowed::DERIVATIVES);
    if let Err(e) = derivative_counts(d.seed.1, d.known.1, d.sensitivity.1, d.unknown.1) {
        return call::<M>(c, f, |_| Err(e));
    }
    calls::get_directional_derivative::<M>(c, f, d.unknown, d.known, d.seed.0, d.sensitivity.0)
}

/// fmi3GetAdjointDerivative: the seeds weight the unknowns, the sensitivities are per known
/// (the transposed Jacobian), from the same exact forward-mode derivatives, one column per known.
pub unsafe fn get_adjoint_derivative<M: Model>(c: fmi3Instance, d: Derivative) -> fmi3Status {
    let f = at("fmi3GetAdjointDerivative", allowed::DERIVATIVES);
    if !M::DIRECTIONAL_DERIVATIVES {
        return calls::unsupported::<M>(c, f, "providesAdjointDerivatives=\"false\"");
    }
    call::<M>(c, f, |inst| {
        derivative_counts(d.seed.1, d.unknown.1, d.sensitivity.1, d.known.1)?;
        let limit = calls::references::<M>(Version::Fmi3);
        let unknowns = slice(d.unknown.0, d.unknown.1, limit, "unknowns")?;
        let knowns = slice(d.known.0, d.known.1, limit, "knowns")?;
        let seeds = slice(d.seed.0, d.seed.1, limit, "seed")?;
        let out = slice_mut(d.sensitivity.0, d.sensitivity.1, limit, "sensitivity")?;
        if let Some(i) = seeds.iter().position(|s| !s.is_finite()) {
            return Err(format!("seed[{i}] = {} is not a finite number", num(seeds[i])));
        }
        // out[j] = sum over the unknowns i of seed[i] times d unknown_i / d known_j: one
        // forward-mode column per known, its references checked as for the directional one.
        let mut column = vec![0.0; unknowns.len()];
        for (o, &known) in out.iter_mut().zip(knowns) {
            inst.directional_derivative(unknowns, &[known], &[1.0], &mut column)?;
            *o = column.iter().zip(seeds).map(|(c, s)| c * s).sum();
        }
        Ok(fmi3Status::OK)
    })
}

/// fmi3UpdateDiscreteStates: the end of the instant: an active Clock's model partition is
/// computed and its clocked states become the previous values, and the Clock is deactivated
/// ([`Instance::update_discrete_states`]). No other discrete states, no time events (the Clock's
/// activations are the importer's: it knows their times from the Clock's constant interval), so
/// the event iteration ends at once and no continuous state changed.
pub unsafe fn update_discrete_states<M: Model>(
    c: fmi3Instance,
    (need_update, terminate, nominals_changed, values_changed, time_defined): (
        *mut bool,
        *mut bool,
        *mut bool,
        *mut bool,
        *mut bool,
    ),
    next_event_time: *mut f64,
) -> fmi3Status {
    call::<M>(c, at("fmi3UpdateDiscreteStates", allowed::UPDATE_DISCRETE_STATES), |inst| {
        let flags = [
            (need_update, "discreteStatesNeedUpdate"),
            (terminate, "terminateSimulation"),
            (nominals_changed, "nominalsOfContinuousStatesChanged"),
            (values_changed, "valuesOfContinuousStatesChanged"),
            (time_defined, "nextEventTimeDefined"),
        ];
        if let Some((_, name)) = flags.iter().find(|(p, _)| p.is_null()) {
            return Err(format!("{name} is NULL"));
        }
        let time = next_event_time.as_mut().ok_or("nextEventTime is NULL")?;
        inst.update_discrete_states()?;
        flags.iter().for_each(|(p, _)| **p = false);
        *time = 0.0;
        Ok(fmi3Status::OK)
    })
}

/// fmi3EnterContinuousTimeMode.
pub unsafe fn enter_continuous_time_mode<M: Model>(c: fmi3Instance) -> fmi3Status {
    let f = at("fmi3EnterContinuousTimeMode", allowed::ENTER_CONTINUOUS_TIME_MODE);
    leave_event_mode::<M>(c, f, Mode::ContinuousTimeMode)
}

/// Leaves Event Mode for `mode`. With the Clock still active the instant has not ended: refused
/// (FMI 3.0, 2.3.5: "Each super-dense time instant concludes with a call to
/// fmi3UpdateDiscreteStates", which deactivates the Clock; the standard leaves this call open).
unsafe fn leave_event_mode<M: Model>(c: fmi3Instance, f: Call, mode: Mode) -> fmi3Status {
    call::<M>(c, f, |inst| {
        if inst.clock_active() {
            return Err(
                "the Clock is active: end the instant with fmi3UpdateDiscreteStates first (FMI 3.0, 2.3.5)".into()
            );
        }
        inst.core.mode = mode;
        Ok(fmi3Status::OK)
    })
}

pub unsafe fn completed_integrator_step<M: Model>(
    c: fmi3Instance,
    enter_event_mode: *mut bool,
    terminate: *mut bool,
) -> fmi3Status {
    let f = at("fmi3CompletedIntegratorStep", allowed::COMPLETED_INTEGRATOR_STEP);
    calls::completed_integrator_step::<M, bool>(c, f, enter_event_mode, terminate)
}

pub unsafe fn set_time<M: Model>(c: fmi3Instance, time: f64) -> fmi3Status {
    calls::set_time::<M>(c, at("fmi3SetTime", allowed::SET_TIME), time)
}

pub unsafe fn set_continuous_states<M: Model>(c: fmi3Instance, x: *const f64, nx: usize) -> fmi3Status {
    calls::set_continuous_states::<M>(c, at("fmi3SetContinuousStates", allowed::SET_CONTINUOUS_STATES), x, nx)
}

pub unsafe fn get_continuous_states<M: Model>(c: fmi3Instance, x: *mut f64, nx: usize) -> fmi3Status {
    calls::get_continuous_states::<M>(c, at("fmi3GetContinuousStates", allowed::GET_CONTINUOUS_STATES), x, nx)
}

pub unsafe fn get_continuous_state_derivatives<M: Model>(c: fmi3Instance, dx: *mut f64, nx: usize) -> fmi3Status {
    let f = at("fmi3GetContinuousStateDerivatives", allowed::GET_CONTINUOUS_STATE_DERIVATIVES);
    calls::get_derivatives::<M>(c, f, dx, nx)
}

pub unsafe fn get_event_indicators<M: Model>(c: fmi3Instance, z: *mut f64, ni: usize) -> fmi3Status {
    calls::get_event_indicators::<M>(c, at("fmi3GetEventIndicators", allowed::GET_EVENT_INDICATORS), z, ni)
}

pub unsafe fn get_nominals_of_continuous_states<M: Model>(c: fmi3Instance, x: *mut f64, nx: usize) -> fmi3Status {
    let f = at("fmi3GetNominalsOfContinuousStates", allowed::GET_NOMINALS);
    calls::get_nominals_of_continuous_states::<M>(c, f, x, nx)
}

pub unsafe fn get_number_of_event_indicators<M: Model>(c: fmi3Instance, n: *mut usize) -> fmi3Status {
    call::<M>(c, at("fmi3GetNumberOfEventIndicators", allowed::GET_NUMBER_OF), |inst| {
        *n.as_mut().ok_or("nEventIndicators is NULL")? = inst.event_indicator_count();
        Ok(fmi3Status::OK)
    })
}

pub unsafe fn get_number_of_continuous_states<M: Model>(c: fmi3Instance, n: *mut usize) -> fmi3Status {
    call::<M>(c, at("fmi3GetNumberOfContinuousStates", allowed::GET_NUMBER_OF), |_| {
        *n.as_mut().ok_or("nContinuousStates is NULL")? = M::STATES.len();
        Ok(fmi3Status::OK)
    })
}

/// fmi3EnterStepMode: from Event Mode, which only a Co-Simulation instance with `eventModeUsed`
/// enters.
pub unsafe fn enter_step_mode<M: Model>(c: fmi3Instance) -> fmi3Status {
    leave_event_mode::<M>(c, at("fmi3EnterStepMode", allowed::ENTER_STEP_MODE), Mode::StepComplete)
}

pub unsafe fn get_output_derivatives<M: Model>(c: fmi3Instance) -> fmi3Status {
    let f = at("fmi3GetOutputDerivatives", allowed::GET_OUTPUT_DERIVATIVES);
    calls::unsupported::<M>(c, f, "maxOutputDerivativeOrder=\"0\"")
}

/// fmi3DoStep. The out-arguments are checked before the step: `earlyReturn` where the step ended
/// before `t + h` at an event (with `earlyReturnAllowed`) or where the master asked from its
/// intermediate update, `eventHandlingNeeded` where it ended at an event and the importer uses
/// Event Mode (4.2.3), `terminateSimulation` once a step was
/// discarded (the instance is then in Step Discarded), and the time the instance reached.
pub unsafe fn do_step<M: Model>(
    c: fmi3Instance,
    t: f64,
    h: f64,
    _no_set_prior: fmi3Boolean,
    (event_handling_needed, terminate, early_return): (*mut bool, *mut bool, *mut bool),
    last_successful_time: *mut f64,
) -> fmi3Status {
    let f = at("fmi3DoStep", allowed::DO_STEP);
    calls::call_reentrant::<M>(c, f, |c| {
        let event = event_handling_needed.as_mut().ok_or("eventHandlingNeeded is NULL")?;
        let term = terminate.as_mut().ok_or("terminateSimulation is NULL")?;
        let early = early_return.as_mut().ok_or("earlyReturn is NULL")?;
        let last = last_successful_time.as_mut().ok_or("lastSuccessfulTime is NULL")?;
        let status = calls::do_step_with_master::<M>(c, f, t, h);
        let inst = calls::borrow::<M>(c, f)?;
        *event = inst.ended.is_some_and(|e| e.event) && inst.event_mode_used;
        *early = inst.ended.is_some_and(|e| e.t < t + h);
        *term = inst.core.mode == Mode::StepFailed;
        *last = inst.core.last_successful_time;
        status
    })
}
