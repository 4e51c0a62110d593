//! The 44 FMI 2.0 functions (25 common, 9 Co-Simulation, 10 Model Exchange), generic over the
//! model. The export macro ([`crate::export_fmu`]) forwards each `#[no_mangle] extern "C"` symbol
//! here; what FMI 3.0 does alike is in [`crate::fmu::calls`], called with the function's FMI 2.0
//! name and its rule of [`allowed`].
#![allow(clippy::missing_safety_doc)]

use super::machine::{allowed, Interface, Mode, Rule};
use super::types::*;
use crate::fmu::calls::{self, call, slice, Call};
use crate::fmu::guid::guid;
use crate::fmu::log::Logger;
use crate::fmu::model::{clock_row, Model};
use crate::fmu::variables::{BaseType, Value};
use crate::fmu::version::Version;
use std::ffi::CStr;
use std::os::raw::{c_char, c_int};
use std::panic::catch_unwind;

/// The FMI 2.0 function `function` with its rule.
const fn at(function: &'static str, rule: Rule) -> Call {
    Call { version: Version::Fmi2, function, rule }
}

/// The importer's variadic fmi2CallbackLogger and its environment.
struct Sink(fmi2CallbackLogger, fmi2ComponentEnvironment);

// SAFETY: the environment pointer is only handed back to the importer's callback, which FMI
// requires to be callable for this instance from whichever thread uses the instance.
unsafe impl Send for Sink {}

impl crate::fmu::log::Sink for Sink {
    fn emit(&self, instance: &CStr, status: fmi2Status, category: &CStr, message: &CStr) {
        if let Some(log) = self.0 {
            // SAFETY: a printf-style callback with a "%s" format and one NUL-terminated string.
            unsafe {
                log(self.1, instance.as_ptr(), status as i32, category.as_ptr(), c"%s".as_ptr(), message.as_ptr())
            };
        }
    }
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
        let sink = Box::new(Sink(f.logger, f.componentEnvironment));
        let logger = Logger::new(Some(sink), calls::text(name).unwrap_or(""), M::INFO.log_categories, logging_on != 0);
        let fail = |message: String| {
            logger.status(fmi2Status::Error, &format!("fmi2Instantiate: {message}"));
            None
        };
        let expected = guid::<M>();
        if let Err(e) = calls::instance_name(name) {
            return fail(e);
        }
        if clock_row::<M>().is_some() {
            return fail(format!("{} is an FMI 3.0 FMU (it has a Clock, which FMI 2.0 lacks)", M::INFO.identifier));
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
        if let Err(e) = calls::check_identity(fmu_guid, "fmuGUID", "GUID", &expected) {
            return fail(e);
        }
        Some(calls::new_instance::<M>(logger, expected, Version::Fmi2, interface, |_| {}))
    })
    .ok()
    .flatten()
    .unwrap_or(std::ptr::null_mut())
}

/// fmi2FreeInstance, with every FMU state of the instance the importer did not free.
pub unsafe fn free_instance<M: Model>(c: fmi2Component) {
    calls::free_instance::<M>(c, at("fmi2FreeInstance", allowed::FREE_INSTANCE))
}

pub unsafe fn set_debug_logging<M: Model>(
    c: fmi2Component,
    on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    calls::set_debug_logging::<M>(c, at("fmi2SetDebugLogging", allowed::SET_DEBUG_LOGGING), on != 0, n, categories)
}

pub unsafe fn setup_experiment<M: Model>(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: f64,
    start: f64,
    stop_defined: fmi2Boolean,
    stop: f64,
) -> fmi2Status {
    let f = at("fmi2SetupExperiment", allowed::SETUP_EXPERIMENT);
    call::<M>(c, f, |inst| {
        let (tolerance, stop) = ((tolerance_defined != 0).then_some(tolerance), (stop_defined != 0).then_some(stop));
        calls::setup_experiment(inst, f.function, tolerance, start, stop)
    })
}

pub unsafe fn enter_initialization_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    calls::enter_initialization_mode::<M>(c, at("fmi2EnterInitializationMode", allowed::ENTER_INITIALIZATION_MODE))
}

pub unsafe fn exit_initialization_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    calls::exit_initialization_mode::<M>(c, at("fmi2ExitInitializationMode", allowed::EXIT_INITIALIZATION_MODE))
}

pub unsafe fn terminate<M: Model>(c: fmi2Component) -> fmi2Status {
    calls::enter::<M>(c, at("fmi2Terminate", allowed::TERMINATE), Mode::Terminated)
}

pub unsafe fn reset<M: Model>(c: fmi2Component) -> fmi2Status {
    calls::reset::<M>(c, at("fmi2Reset", allowed::RESET))
}

pub unsafe fn get_real<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut f64) -> fmi2Status {
    calls::get::<M, f64>(c, at("fmi2GetReal", allowed::GET), vr, n, value, BaseType::Real, calls::real)
}

pub unsafe fn get_integer<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut c_int) -> fmi2Status {
    calls::get::<M, c_int>(c, at("fmi2GetInteger", allowed::GET), vr, n, value, BaseType::Integer, calls::integer)
}

pub unsafe fn get_boolean<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut c_int) -> fmi2Status {
    calls::get::<M, c_int>(c, at("fmi2GetBoolean", allowed::GET), vr, n, value, BaseType::Boolean, |v| {
        matches!(v, Value::Boolean(true)) as c_int
    })
}

pub unsafe fn get_string<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *mut fmi2String) -> fmi2Status {
    calls::get_string::<M>(c, at("fmi2GetString", allowed::GET), vr, n, value)
}

pub unsafe fn set_real<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const f64) -> fmi2Status {
    let f = at("fmi2SetReal", allowed::SET_REAL);
    calls::set::<M, f64>(c, f, (vr, n, value), BaseType::Real, |x| Ok(Value::Real(x)))
}

pub unsafe fn set_integer<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const c_int) -> fmi2Status {
    let f = at("fmi2SetInteger", allowed::SET_DISCRETE);
    calls::set::<M, c_int>(c, f, (vr, n, value), BaseType::Integer, |x| Ok(Value::Integer(x)))
}

pub unsafe fn set_boolean<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const c_int) -> fmi2Status {
    let f = at("fmi2SetBoolean", allowed::SET_DISCRETE);
    calls::set::<M, c_int>(c, f, (vr, n, value), BaseType::Boolean, |x| match x {
        FMI2_FALSE => Ok(Value::Boolean(false)),
        FMI2_TRUE => Ok(Value::Boolean(true)),
        _ => Err(format!("{x} is not an fmi2Boolean; valid values are fmi2False (0) and fmi2True (1)")),
    })
}

pub unsafe fn set_string<M: Model>(c: fmi2Component, vr: *const u32, n: usize, value: *const fmi2String) -> fmi2Status {
    let f = at("fmi2SetString", allowed::SET_DISCRETE);
    calls::set::<M, fmi2String>(c, f, (vr, n, value), BaseType::String, |p| calls::string_value(p))
}

pub unsafe fn get_fmu_state<M: Model>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    calls::get_fmu_state::<M>(c, at("fmi2GetFMUstate", allowed::FMU_STATE), state)
}

pub unsafe fn set_fmu_state<M: Model>(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    calls::set_fmu_state::<M>(c, at("fmi2SetFMUstate", allowed::FMU_STATE), state)
}

pub unsafe fn free_fmu_state<M: Model>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    calls::free_fmu_state::<M>(c, at("fmi2FreeFMUstate", allowed::FMU_STATE), state)
}

pub unsafe fn serialized_fmu_state_size<M: Model>(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    calls::serialized_fmu_state_size::<M>(c, at("fmi2SerializedFMUstateSize", allowed::FMU_STATE), state, size)
}

pub unsafe fn serialize_fmu_state<M: Model>(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    calls::serialize_fmu_state::<M>(c, at("fmi2SerializeFMUstate", allowed::FMU_STATE), state, bytes as *mut u8, size)
}

pub unsafe fn deserialize_fmu_state<M: Model>(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    let f = at("fmi2DeSerializeFMUstate", allowed::FMU_STATE);
    calls::deserialize_fmu_state::<M>(c, f, bytes as *const u8, size, state)
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
    let f = at("fmi2GetDirectionalDerivative", allowed::DIRECTIONAL_DERIVATIVE);
    calls::get_directional_derivative::<M>(c, f, (unknown, n_unknown), (known, n_known), dv_known, dv_unknown)
}

pub unsafe fn set_real_input_derivatives<M: Model>(
    c: fmi2Component,
    vr: *const u32,
    n: usize,
    order: *const c_int,
    value: *const f64,
) -> fmi2Status {
    call::<M>(c, at("fmi2SetRealInputDerivatives", allowed::SET_INPUT_DERIVATIVES), |inst| {
        let limit = calls::references::<M>(Version::Fmi2);
        let (vr, order, value) =
            (slice(vr, n, limit, "vr")?, slice(order, n, limit, "order")?, slice(value, n, limit, "value")?);
        inst.set_input_derivatives(vr, order, value)?;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_real_output_derivatives<M: Model>(c: fmi2Component) -> fmi2Status {
    let f = at("fmi2GetRealOutputDerivatives", allowed::GET_OUTPUT_DERIVATIVES);
    calls::unsupported::<M>(c, f, "maxOutputDerivativeOrder=\"0\"")
}

pub unsafe fn do_step<M: Model>(c: fmi2Component, t: f64, h: f64, _no_set_prior: fmi2Boolean) -> fmi2Status {
    let f = at("fmi2DoStep", allowed::DO_STEP);
    call::<M>(c, f, |inst| calls::do_step(inst, f.function, t, h))
}

pub unsafe fn cancel_step<M: Model>(c: fmi2Component) -> fmi2Status {
    let f = at("fmi2CancelStep", allowed::CANCEL_STEP);
    calls::unsupported::<M>(c, f, "doStep is synchronous (canRunAsynchronuously=\"false\")")
}

pub unsafe fn get_status<M: Model>(c: fmi2Component) -> fmi2Status {
    let f = at("fmi2GetStatus", allowed::GET_STATUS);
    calls::unsupported::<M>(c, f, "no fmi2Status kind is defined for a synchronous slave")
}

pub unsafe fn get_integer_status<M: Model>(c: fmi2Component) -> fmi2Status {
    calls::unsupported::<M>(c, at("fmi2GetIntegerStatus", allowed::GET_STATUS), "FMI 2.0 defines no integer status")
}

pub unsafe fn get_string_status<M: Model>(c: fmi2Component) -> fmi2Status {
    let f = at("fmi2GetStringStatus", allowed::GET_STATUS);
    calls::unsupported::<M>(c, f, "no string status (fmi2PendingStatus needs an asynchronous doStep)")
}

pub unsafe fn get_real_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut f64) -> fmi2Status {
    call::<M>(c, at("fmi2GetRealStatus", allowed::GET_STATUS), |inst| {
        if kind != FMI2_LAST_SUCCESSFUL_TIME {
            return Err(format!("status kind {kind} is not available; only fmi2LastSuccessfulTime (2) is"));
        }
        *value.as_mut().ok_or("value is NULL")? = inst.core.last_successful_time;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn get_boolean_status<M: Model>(c: fmi2Component, kind: c_int, value: *mut fmi2Boolean) -> fmi2Status {
    call::<M>(c, at("fmi2GetBooleanStatus", allowed::GET_STATUS), |inst| {
        if kind != FMI2_TERMINATED {
            return Err(format!("status kind {kind} is not available; only fmi2Terminated (3) is"));
        }
        // The slave asks to end the simulation only once a step has failed.
        *value.as_mut().ok_or("value is NULL")? = (inst.core.mode == Mode::StepFailed) as fmi2Boolean;
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn enter_event_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    calls::enter::<M>(c, at("fmi2EnterEventMode", allowed::ENTER_EVENT_MODE), Mode::EventMode)
}

/// fmi2NewDiscreteStates. The models have no discrete states and no time events; at a state
/// event (an event indicator changed sign) nothing is reinitialised either: the right-hand side
/// changes branch by itself, and the event only lets the integrator restart there. So the event
/// iteration ends at once.
pub unsafe fn new_discrete_states<M: Model>(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status {
    call::<M>(c, at("fmi2NewDiscreteStates", allowed::NEW_DISCRETE_STATES), |_| {
        *info.as_mut().ok_or("fmi2EventInfo is NULL")? = fmi2EventInfo::default();
        Ok(fmi2Status::OK)
    })
}

pub unsafe fn enter_continuous_time_mode<M: Model>(c: fmi2Component) -> fmi2Status {
    let f = at("fmi2EnterContinuousTimeMode", allowed::ENTER_CONTINUOUS_TIME_MODE);
    calls::enter::<M>(c, f, Mode::ContinuousTimeMode)
}

/// fmi2CompletedIntegratorStep: no step events (`completedIntegratorStepNotNeeded="true"`).
pub unsafe fn completed_integrator_step<M: Model>(
    c: fmi2Component,
    _no_set_prior: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate: *mut fmi2Boolean,
) -> fmi2Status {
    let f = at("fmi2CompletedIntegratorStep", allowed::COMPLETED_INTEGRATOR_STEP);
    calls::completed_integrator_step::<M, fmi2Boolean>(c, f, enter_event_mode, terminate)
}

pub unsafe fn set_time<M: Model>(c: fmi2Component, time: f64) -> fmi2Status {
    calls::set_time::<M>(c, at("fmi2SetTime", allowed::SET_TIME), time)
}

pub unsafe fn set_continuous_states<M: Model>(c: fmi2Component, x: *const f64, nx: usize) -> fmi2Status {
    calls::set_continuous_states::<M>(c, at("fmi2SetContinuousStates", allowed::SET_CONTINUOUS_STATES), x, nx)
}

pub unsafe fn get_continuous_states<M: Model>(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status {
    calls::get_continuous_states::<M>(c, at("fmi2GetContinuousStates", allowed::GET_CONTINUOUS_STATES), x, nx)
}

/// fmi2GetDerivatives; fmi2Discard (FMI 2.0, 2.1.3: retry with a smaller step) where the
/// states are outside the model's domain.
pub unsafe fn get_derivatives<M: Model>(c: fmi2Component, dx: *mut f64, nx: usize) -> fmi2Status {
    calls::get_derivatives::<M>(c, at("fmi2GetDerivatives", allowed::GET_DERIVATIVES), dx, nx)
}

pub unsafe fn get_event_indicators<M: Model>(c: fmi2Component, z: *mut f64, ni: usize) -> fmi2Status {
    calls::get_event_indicators::<M>(c, at("fmi2GetEventIndicators", allowed::GET_EVENT_INDICATORS), z, ni)
}

pub unsafe fn get_nominals_of_continuous_states<M: Model>(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status {
    let f = at("fmi2GetNominalsOfContinuousStates", allowed::GET_NOMINALS);
    calls::get_nominals_of_continuous_states::<M>(c, f, x, nx)
}
