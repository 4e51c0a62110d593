//! The misuse catalogue of the FMI 2.0 Co-Simulation interface: every row is one wrong call (a
//! function in a state where FMI 2.0.4 section 4.2.4 forbids it, a NULL pointer where 2.1 forbids
//! one, an unknown or mistyped value reference, a value outside its declared range, a bad time or
//! step, a foreign or corrupted FMU state, ...), made at one point of a normal simulation. Each
//! row asserts
//! - the status the standard (or the declared range) calls for,
//! - a logged message that names the function and what was wrong,
//! - that the instance is still usable: the rest of the normal simulation, run after the wrong
//!   call, gives bit-identical outputs to an instance that never saw it (principle 4: a refused
//!   call changes nothing).
//!
//! The normal simulation is the controller's (fast, every FMI feature); rows for what only the
//! plants have live in `tests/hardening.rs`.

use crate::common;

use boomsim::fmi2::api;
use boomsim::fmu::guid::guid;
use boomsim::fmi2::types::*;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::{HydraulicBoom, PressureFeedbackController as Pfc};
use crate::common::{forge, forge_bytes, forge_value, payload_offset, time_offset, Slave};
use std::ffi::CString;
use std::ptr::{null, null_mut};

const OK: fmi2Status = fmi2Status::OK;
const WARN: fmi2Status = fmi2Status::Warning;
const ERR: fmi2Status = fmi2Status::Error;

/// Where in the normal simulation the wrong call is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum At {
    /// After fmi2Instantiate.
    Instantiated,
    /// After fmi2EnterInitializationMode and the start values.
    Initialization,
    /// After two steps.
    Stepping,
    /// After fmi2Terminate (usable again after fmi2Reset).
    Terminated,
}

/// One wrong call: where, what, the expected status and words of the logged message.
struct Row {
    at: At,
    what: &'static str,
    call: fn(&Slave<Pfc>) -> fmi2Status,
    status: fmi2Status,
    says: &'static [&'static str],
}

const STOP: f64 = 1.0;
const H: f64 = 1e-3;

/// The normal simulation from `from` on: setup (stop time 1 s), initialisation with p and u_ref,
/// six steps with a moving pressure and a slope, terminate; the outputs after each step.
fn normal(s: &Slave<Pfc>, from: At) -> Vec<f64> {
    let mut out = Vec::new();
    unsafe {
        if from <= At::Instantiated {
            assert_eq!(api::setup_experiment::<Pfc>(s.c, 1, 1e-6, 0.0, 1, STOP), OK);
            assert_eq!(api::enter_initialization_mode::<Pfc>(s.c), OK);
            assert_eq!(s.set_real(vr::P, 40e5), OK);
            assert_eq!(s.set_real(vr::U_REF, -0.1), OK);
        }
        if from <= At::Initialization {
            assert_eq!(api::exit_initialization_mode::<Pfc>(s.c), OK);
            for k in 0..2 {
                assert_eq!(s.set_real(vr::P, 40e5 + 1e5 * k as f64), OK);
                assert_eq!(s.step(k as f64 * H, H), OK);
            }
        }
        for k in 2..8 {
            assert_eq!(s.set_real(vr::P, 40e5 + 1e5 * k as f64), OK);
            assert_eq!(s.set_slope(vr::P, 1e6), OK);
            assert_eq!(s.step(k as f64 * H, H), OK);
            out.push(s.real(vr::U));
            out.push(s.real(vr::U_COMP));
        }
        assert_eq!(api::terminate::<Pfc>(s.c), OK);
    }
    out
}

/// The normal simulation up to `at` (the part before the wrong call).
fn prepare(s: &Slave<Pfc>, at: At) {
    unsafe {
        if at >= At::Initialization {
            assert_eq!(api::setup_experiment::<Pfc>(s.c, 1, 1e-6, 0.0, 1, STOP), OK);
            assert_eq!(api::enter_initialization_mode::<Pfc>(s.c), OK);
            assert_eq!(s.set_real(vr::P, 40e5), OK);
            assert_eq!(s.set_real(vr::U_REF, -0.1), OK);
        }
        if at >= At::Stepping {
            assert_eq!(api::exit_initialization_mode::<Pfc>(s.c), OK);
            for k in 0..2 {
                assert_eq!(s.set_real(vr::P, 40e5 + 1e5 * k as f64), OK);
                assert_eq!(s.step(k as f64 * H, H), OK);
            }
        }
        if at == At::Terminated {
            normal(s, At::Stepping);
        }
    }
}

fn set_real(s: &Slave<Pfc>, vr: u32, x: f64) -> fmi2Status {
    s.set_real(vr, x)
}
fn setup(s: &Slave<Pfc>, tol: f64, start: f64, stop: f64) -> fmi2Status {
    unsafe { api::setup_experiment::<Pfc>(s.c, 1, tol, start, 1, stop) }
}
fn step(s: &Slave<Pfc>, t: f64, h: f64) -> fmi2Status {
    s.step(t, h)
}
fn get_u(s: &Slave<Pfc>) -> fmi2Status {
    let mut x = 0.0;
    unsafe { api::get_real::<Pfc>(s.c, &vr::U, 1, &mut x) }
}
fn derivative(s: &Slave<Pfc>, vr: u32, order: i32, d: f64) -> fmi2Status {
    unsafe { api::set_real_input_derivatives::<Pfc>(s.c, &vr, 1, &order, &d) }
}
fn categories(s: &Slave<Pfc>, names: &[&str]) -> fmi2Status {
    let c: Vec<CString> = names.iter().map(|n| CString::new(*n).unwrap()).collect();
    let p: Vec<fmi2String> = c.iter().map(|n| n.as_ptr()).collect();
    unsafe { api::set_debug_logging::<Pfc>(s.c, 1, p.len(), p.as_ptr()) }
}

/// A serialised state of this instance, with `edit` applied to the bytes.
fn serialised(s: &Slave<Pfc>, edit: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let mut b = common::serialized(s);
    edit(&mut b);
    b
}

fn deserialise(s: &Slave<Pfc>, b: &[u8]) -> fmi2Status {
    let mut st: fmi2FMUstate = null_mut();
    let status = unsafe { api::deserialize_fmu_state::<Pfc>(s.c, b.as_ptr() as *const fmi2Byte, b.len(), &mut st) };
    if !st.is_null() {
        unsafe { api::free_fmu_state::<Pfc>(s.c, &mut st) };
    }
    status
}

/// The catalogue.
#[rustfmt::skip]
const ROWS: &[Row] = &[
    // Calls in the wrong state (FMI 2.0.4, Fig. 10 / 4.2.4).
    Row { at: At::Instantiated, what: "doStep before initialisation", call: |s| step(s, 0.0, H), status: ERR, says: &["fmi2DoStep", "Instantiated"] },
    Row { at: At::Instantiated, what: "getReal before initialisation", call: get_u, status: ERR, says: &["fmi2GetReal", "Instantiated"] },
    Row { at: At::Instantiated, what: "exitInitializationMode first", call: |s| unsafe { api::exit_initialization_mode::<Pfc>(s.c) }, status: ERR, says: &["fmi2ExitInitializationMode", "Instantiated"] },
    Row { at: At::Instantiated, what: "terminate before initialisation", call: |s| unsafe { api::terminate::<Pfc>(s.c) }, status: ERR, says: &["fmi2Terminate", "Instantiated"] },
    Row { at: At::Instantiated, what: "getRealStatus before a step", call: |s| { let mut t = 0.0; unsafe { api::get_real_status::<Pfc>(s.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) } }, status: ERR, says: &["fmi2GetRealStatus", "Instantiated"] },
    Row { at: At::Instantiated, what: "getRealOutputDerivatives before initialisation", call: |s| unsafe { api::get_real_output_derivatives::<Pfc>(s.c) }, status: ERR, says: &["fmi2GetRealOutputDerivatives", "Instantiated"] },
    Row { at: At::Instantiated, what: "cancelStep (no asynchronous step)", call: |s| unsafe { api::cancel_step::<Pfc>(s.c) }, status: ERR, says: &["fmi2CancelStep"] },
    Row { at: At::Initialization, what: "setupExperiment in initialisation", call: |s| setup(s, 1e-6, 0.0, STOP), status: ERR, says: &["fmi2SetupExperiment", "InitializationMode"] },
    Row { at: At::Initialization, what: "enterInitializationMode twice", call: |s| unsafe { api::enter_initialization_mode::<Pfc>(s.c) }, status: ERR, says: &["fmi2EnterInitializationMode", "InitializationMode"] },
    Row { at: At::Initialization, what: "doStep in initialisation", call: |s| step(s, 0.0, H), status: ERR, says: &["fmi2DoStep", "InitializationMode"] },
    Row { at: At::Initialization, what: "getBooleanStatus in initialisation", call: |s| { let mut b = 0; unsafe { api::get_boolean_status::<Pfc>(s.c, FMI2_TERMINATED, &mut b) } }, status: ERR, says: &["fmi2GetBooleanStatus", "InitializationMode"] },
    Row { at: At::Initialization, what: "terminate in initialisation", call: |s| unsafe { api::terminate::<Pfc>(s.c) }, status: ERR, says: &["fmi2Terminate", "InitializationMode"] },
    Row { at: At::Stepping, what: "setupExperiment after initialisation", call: |s| setup(s, 1e-6, 0.0, STOP), status: ERR, says: &["fmi2SetupExperiment", "StepComplete"] },
    Row { at: At::Stepping, what: "enterInitializationMode after initialisation", call: |s| unsafe { api::enter_initialization_mode::<Pfc>(s.c) }, status: ERR, says: &["fmi2EnterInitializationMode", "StepComplete"] },
    Row { at: At::Stepping, what: "exitInitializationMode twice", call: |s| unsafe { api::exit_initialization_mode::<Pfc>(s.c) }, status: ERR, says: &["fmi2ExitInitializationMode", "StepComplete"] },
    Row { at: At::Stepping, what: "cancelStep after a synchronous step", call: |s| unsafe { api::cancel_step::<Pfc>(s.c) }, status: ERR, says: &["fmi2CancelStep", "StepComplete"] },
    Row { at: At::Terminated, what: "doStep after terminate", call: |s| step(s, 8.0 * H, H), status: ERR, says: &["fmi2DoStep", "Terminated"] },
    Row { at: At::Terminated, what: "setReal of an input after terminate", call: |s| set_real(s, vr::P, 1e5), status: ERR, says: &["fmi2SetReal", "Terminated"] },
    Row { at: At::Terminated, what: "terminate twice", call: |s| unsafe { api::terminate::<Pfc>(s.c) }, status: ERR, says: &["fmi2Terminate", "Terminated"] },
    Row { at: At::Terminated, what: "setRealInputDerivatives after terminate", call: |s| derivative(s, vr::P, 1, 1.0), status: ERR, says: &["fmi2SetRealInputDerivatives", "Terminated"] },
    // Counts larger than the arrays (one element each here): refused before an array is read,
    // naming the count and its limit (the standard makes a wrong count the importer's error;
    // the FMU's promise is never to crash on one).
    Row { at: At::Stepping, what: "setReal nvr = SIZE_MAX", call: |s| unsafe { api::set_real::<Pfc>(s.c, &vr::P, usize::MAX, &1e5) }, status: ERR, says: &["fmi2SetReal", "vr: 18446744073709551615 elements announced, but at most"] },
    Row { at: At::Stepping, what: "getReal nvr = SIZE_MAX", call: |s| unsafe { api::get_real::<Pfc>(s.c, &vr::U, usize::MAX, &mut 0.0) }, status: ERR, says: &["fmi2GetReal", "18446744073709551615 elements announced"] },
    Row { at: At::Stepping, what: "getString nvr = SIZE_MAX", call: |s| unsafe { api::get_string::<Pfc>(s.c, &vr::U, usize::MAX, &mut null()) }, status: ERR, says: &["fmi2GetString", "18446744073709551615 elements announced"] },
    Row { at: At::Stepping, what: "setRealInputDerivatives nvr = SIZE_MAX", call: |s| unsafe { api::set_real_input_derivatives::<Pfc>(s.c, &vr::P, usize::MAX, &1, &1.0) }, status: ERR, says: &["fmi2SetRealInputDerivatives", "18446744073709551615 elements announced"] },
    Row { at: At::Stepping, what: "setDebugLogging nCategories = SIZE_MAX", call: |s| unsafe { api::set_debug_logging::<Pfc>(s.c, 1, usize::MAX, &c"logAll".as_ptr()) }, status: ERR, says: &["fmi2SetDebugLogging", "categories: 18446744073709551615 elements announced"] },
    Row { at: At::Stepping, what: "deSerializeFMUstate size = SIZE_MAX", call: |s| { let b = common::serialized(s); let mut st = null_mut(); unsafe { api::deserialize_fmu_state::<Pfc>(s.c, b.as_ptr() as *const fmi2Byte, usize::MAX, &mut st) } }, status: ERR, says: &["fmi2DeSerializeFMUstate", "size = 18446744073709551615 bytes, but the state's header announces"] },
    // fmi2SetupExperiment arguments.
    Row { at: At::Instantiated, what: "tolerance NaN", call: |s| setup(s, f64::NAN, 0.0, STOP), status: ERR, says: &["tolerance = NaN"] },
    Row { at: At::Instantiated, what: "tolerance 0", call: |s| setup(s, 0.0, 0.0, STOP), status: ERR, says: &["tolerance = 0"] },
    Row { at: At::Instantiated, what: "tolerance -1e-6", call: |s| setup(s, -1e-6, 0.0, STOP), status: ERR, says: &["tolerance = -1e-6"] },
    Row { at: At::Instantiated, what: "tolerance 1e-20: clamped", call: |s| setup(s, 1e-20, 0.0, STOP), status: WARN, says: &["tolerance = 1e-20", "[1e-12, 0.01]", "using 1e-12"] },
    Row { at: At::Instantiated, what: "tolerance 0.5: clamped", call: |s| setup(s, 0.5, 0.0, STOP), status: WARN, says: &["tolerance = 0.5", "using 0.01"] },
    Row { at: At::Instantiated, what: "tolerance +Inf", call: |s| setup(s, f64::INFINITY, 0.0, STOP), status: ERR, says: &["tolerance = inf"] },
    Row { at: At::Instantiated, what: "startTime NaN", call: |s| setup(s, 1e-6, f64::NAN, STOP), status: ERR, says: &["startTime = NaN"] },
    Row { at: At::Instantiated, what: "stopTime before startTime", call: |s| setup(s, 1e-6, 2.0, 1.0), status: ERR, says: &["stopTime = 1", "startTime = 2"] },
    Row { at: At::Instantiated, what: "stopTime +Inf", call: |s| setup(s, 1e-6, 0.0, f64::INFINITY), status: ERR, says: &["stopTime = inf"] },
    // fmi2DoStep arguments.
    Row { at: At::Stepping, what: "h = 0", call: |s| step(s, 2.0 * H, 0.0), status: ERR, says: &["communicationStepSize = 0", "(0, inf)"] },
    Row { at: At::Stepping, what: "h < 0", call: |s| step(s, 2.0 * H, -H), status: ERR, says: &["communicationStepSize = -0.001"] },
    Row { at: At::Stepping, what: "h NaN", call: |s| step(s, 2.0 * H, f64::NAN), status: ERR, says: &["communicationStepSize = NaN"] },
    Row { at: At::Stepping, what: "h = 1e300, past the stop time", call: |s| step(s, 2.0 * H, 1e300), status: ERR, says: &["t = 1e300", "stop time 1"] },
    Row { at: At::Stepping, what: "h +Inf", call: |s| step(s, 2.0 * H, f64::INFINITY), status: ERR, says: &["communicationStepSize = inf"] },
    Row { at: At::Stepping, what: "communication point ahead of the instance", call: |s| step(s, 0.5, H), status: ERR, says: &["currentCommunicationPoint = 0.5", "instance time 0.002"] },
    Row { at: At::Stepping, what: "communication point behind the instance", call: |s| step(s, 0.0, H), status: ERR, says: &["currentCommunicationPoint = 0", "instance time 0.002"] },
    Row { at: At::Stepping, what: "communication point NaN", call: |s| step(s, f64::NAN, H), status: ERR, says: &["currentCommunicationPoint = NaN"] },
    Row { at: At::Stepping, what: "a step past the stop time", call: |s| step(s, 2.0 * H, STOP), status: ERR, says: &["stop time 1"] },
    // Values: unknown references, wrong types, ranges, causality (2.2.7).
    Row { at: At::Initialization, what: "setReal of an unknown vr", call: |s| set_real(s, 999, 1.0), status: ERR, says: &["unknown value reference 999"] },
    Row { at: At::Stepping, what: "getReal of an unknown vr", call: |s| { let mut x = 0.0; unsafe { api::get_real::<Pfc>(s.c, &4242, 1, &mut x) } }, status: ERR, says: &["unknown value reference 4242"] },
    Row { at: At::Stepping, what: "getInteger of a Real", call: |s| { let mut i = 0; unsafe { api::get_integer::<Pfc>(s.c, &vr::U, 1, &mut i) } }, status: ERR, says: &["\"u\"", "Real, not a Integer"] },
    Row { at: At::Stepping, what: "getBoolean of a Real", call: |s| { let mut b = 0; unsafe { api::get_boolean::<Pfc>(s.c, &vr::U, 1, &mut b) } }, status: ERR, says: &["\"u\"", "not a Boolean"] },
    Row { at: At::Stepping, what: "getString of a Real", call: |s| { let mut p: fmi2String = null(); unsafe { api::get_string::<Pfc>(s.c, &vr::U, 1, &mut p) } }, status: ERR, says: &["\"u\"", "not a String"] },
    Row { at: At::Initialization, what: "setInteger of a Real", call: |s| unsafe { api::set_integer::<Pfc>(s.c, &vr::K_F, 1, &3) }, status: ERR, says: &["\"K_f\"", "not a Integer"] },
    Row { at: At::Initialization, what: "setString of a Real", call: |s| { let t = CString::new("1").unwrap(); unsafe { api::set_string::<Pfc>(s.c, &vr::K_F, 1, &t.as_ptr()) } }, status: ERR, says: &["\"K_f\"", "not a String"] },
    Row { at: At::Initialization, what: "setBoolean 7", call: |s| unsafe { api::set_boolean::<Pfc>(s.c, &vr::ENABLE, 1, &7) }, status: ERR, says: &["7 is not an fmi2Boolean"] },
    Row { at: At::Initialization, what: "K_f NaN", call: |s| set_real(s, vr::K_F, f64::NAN), status: ERR, says: &["K_f = NaN", "valid range [0,"] },
    Row { at: At::Initialization, what: "K_f below its minimum", call: |s| set_real(s, vr::K_F, -1e-12), status: ERR, says: &["K_f = -1e-12", "outside its valid range"] },
    Row { at: At::Initialization, what: "omega_f +Inf", call: |s| set_real(s, vr::OMEGA_F, f64::INFINITY), status: ERR, says: &["omega_f = inf", "not a finite number"] },
    Row { at: At::Initialization, what: "p -Inf", call: |s| set_real(s, vr::P, f64::NEG_INFINITY), status: ERR, says: &["p = -inf", "[-1e8, 1e8] Pa"] },
    Row { at: At::Stepping, what: "p above 1000 bar", call: |s| set_real(s, vr::P, 1e300), status: ERR, says: &["p = 1e300", "[-1e8, 1e8] Pa"] },
    Row { at: At::Stepping, what: "u_ref above 1", call: |s| set_real(s, vr::U_REF, 1.5), status: ERR, says: &["u_ref = 1.5", "[-1, 1]"] },
    Row { at: At::Stepping, what: "u_ref -DBL_MAX", call: |s| set_real(s, vr::U_REF, f64::MIN), status: ERR, says: &["u_ref = -1.7976931348623157e308"] },
    Row { at: At::Initialization, what: "setReal of an output", call: |s| set_real(s, vr::U, 0.1), status: ERR, says: &["cannot set \"u\"", "causality=output"] },
    Row { at: At::Stepping, what: "setReal of a local", call: |s| set_real(s, vr::P_LP, 1e5), status: ERR, says: &["cannot set \"filter.p_lp\"", "causality=local"] },
    Row { at: At::Stepping, what: "fixed parameter after initialisation", call: |s| set_real(s, vr::Q_RATED, 1e-3), status: ERR, says: &["cannot set \"Q_rated\"", "variability=fixed"] },
    Row { at: At::Stepping, what: "fixed Boolean after initialisation", call: |s| unsafe { api::set_boolean::<Pfc>(s.c, &vr::EXTRAPOLATION, 1, &1) }, status: ERR, says: &["p.extrapolation", "variability=fixed"] },
    Row { at: At::Stepping, what: "tunable u_min = u_max", call: |s| set_real(s, vr::U_MIN, 1.0), status: ERR, says: &["u_min = 1 must be less than u_max = 1"] },
    Row { at: At::Stepping, what: "a batch with one bad value", call: |s| { let (r, x) = ([vr::U_REF, vr::K_F], [0.5, -1.0]); unsafe { api::set_real::<Pfc>(s.c, r.as_ptr(), 2, x.as_ptr()) } }, status: ERR, says: &["K_f = -1"] },
    // NULL pointers where 2.1 forbids them.
    Row { at: At::Initialization, what: "setReal with vr NULL", call: |s| unsafe { api::set_real::<Pfc>(s.c, null(), 1, &1.0) }, status: ERR, says: &["vr is NULL", "1 elements"] },
    Row { at: At::Initialization, what: "setReal with value NULL", call: |s| unsafe { api::set_real::<Pfc>(s.c, &vr::P, 1, null()) }, status: ERR, says: &["value is NULL"] },
    Row { at: At::Stepping, what: "getReal into NULL", call: |s| unsafe { api::get_real::<Pfc>(s.c, &vr::U, 1, null_mut()) }, status: ERR, says: &["value is NULL"] },
    Row { at: At::Stepping, what: "getString into NULL", call: |s| unsafe { api::get_string::<Pfc>(s.c, &vr::U, 1, null_mut()) }, status: ERR, says: &["value is NULL"] },
    Row { at: At::Stepping, what: "getRealStatus into NULL", call: |s| unsafe { api::get_real_status::<Pfc>(s.c, FMI2_LAST_SUCCESSFUL_TIME, null_mut()) }, status: ERR, says: &["value is NULL"] },
    Row { at: At::Stepping, what: "setDebugLogging with categories NULL", call: |s| unsafe { api::set_debug_logging::<Pfc>(s.c, 1, 2, null()) }, status: ERR, says: &["categories is NULL"] },
    Row { at: At::Stepping, what: "getFMUstate into NULL", call: |s| unsafe { api::get_fmu_state::<Pfc>(s.c, null_mut()) }, status: ERR, says: &["fmi2GetFMUstate", "FMUstate is NULL"] },
    Row { at: At::Stepping, what: "setFMUstate NULL", call: |s| unsafe { api::set_fmu_state::<Pfc>(s.c, null_mut()) }, status: ERR, says: &["fmi2SetFMUstate", "NULL"] },
    Row { at: At::Stepping, what: "serializedFMUstateSize into NULL", call: |s| { let mut st: fmi2FMUstate = null_mut(); unsafe { api::get_fmu_state::<Pfc>(s.c, &mut st); let r = api::serialized_fmu_state_size::<Pfc>(s.c, st, null_mut()); api::free_fmu_state::<Pfc>(s.c, &mut st); r } }, status: ERR, says: &["size is NULL"] },
    Row { at: At::Stepping, what: "deserialise from NULL bytes", call: |s| { let mut st: fmi2FMUstate = null_mut(); unsafe { api::deserialize_fmu_state::<Pfc>(s.c, null(), 100, &mut st) } }, status: ERR, says: &["serializedState is NULL"] },
    // Log categories (2.1.5).
    Row { at: At::Stepping, what: "an unknown log category", call: |s| categories(s, &["logNothing"]), status: ERR, says: &["unknown log category \"logNothing\"", "logFmiCalls"] },
    // Status queries (4.2.3) and unsupported functions.
    Row { at: At::Stepping, what: "getRealStatus of fmi2DoStepStatus", call: |s| { let mut t = 0.0; unsafe { api::get_real_status::<Pfc>(s.c, FMI2_DO_STEP_STATUS, &mut t) } }, status: ERR, says: &["status kind 0", "fmi2LastSuccessfulTime"] },
    Row { at: At::Stepping, what: "getBooleanStatus of fmi2PendingStatus", call: |s| { let mut b = 0; unsafe { api::get_boolean_status::<Pfc>(s.c, FMI2_PENDING_STATUS, &mut b) } }, status: ERR, says: &["status kind 1", "fmi2Terminated"] },
    Row { at: At::Stepping, what: "getStatus", call: |s| unsafe { api::get_status::<Pfc>(s.c) }, status: ERR, says: &["fmi2GetStatus", "not supported"] },
    Row { at: At::Stepping, what: "getIntegerStatus", call: |s| unsafe { api::get_integer_status::<Pfc>(s.c) }, status: ERR, says: &["fmi2GetIntegerStatus", "not supported"] },
    Row { at: At::Stepping, what: "getStringStatus", call: |s| unsafe { api::get_string_status::<Pfc>(s.c) }, status: ERR, says: &["fmi2GetStringStatus", "not supported"] },
    Row { at: At::Stepping, what: "getRealOutputDerivatives", call: |s| unsafe { api::get_real_output_derivatives::<Pfc>(s.c) }, status: ERR, says: &["maxOutputDerivativeOrder"] },
    Row { at: At::Stepping, what: "getDirectionalDerivative", call: |s| { let (u, k, dv, mut o) = (vr::U, vr::P, 1.0, 0.0); unsafe { api::get_directional_derivative::<Pfc>(s.c, &u, 1, &k, 1, &dv, &mut o) } }, status: ERR, says: &["providesDirectionalDerivative"] },
    // Input derivatives (4.2.1).
    Row { at: At::Stepping, what: "input derivative of order 2", call: |s| derivative(s, vr::P, 2, 1.0), status: ERR, says: &["derivative order 2 of \"p\"", "[1, 1]"] },
    Row { at: At::Stepping, what: "input derivative of an output", call: |s| derivative(s, vr::U, 1, 1.0), status: ERR, says: &["\"u\"", "derivatives can be set for u_ref, p"] },
    Row { at: At::Stepping, what: "input derivative NaN", call: |s| derivative(s, vr::P, 1, f64::NAN), status: ERR, says: &["derivative of \"p\" = NaN"] },
    Row { at: At::Stepping, what: "input derivative of an unknown vr", call: |s| derivative(s, 77, 1, 1.0), status: ERR, says: &["unknown value reference 77"] },
    // FMU states (2.1.8): foreign, freed, corrupted, forged.
    Row { at: At::Stepping, what: "setFMUstate with a foreign pointer", call: |s| { let junk = [0u64; 64]; unsafe { api::set_fmu_state::<Pfc>(s.c, junk.as_ptr() as fmi2FMUstate) } }, status: ERR, says: &["not a state of this instance"] },
    Row { at: At::Stepping, what: "freeFMUstate of a foreign pointer", call: |s| { let junk = [0u64; 64]; let mut p = junk.as_ptr() as fmi2FMUstate; unsafe { api::free_fmu_state::<Pfc>(s.c, &mut p) } }, status: ERR, says: &["fmi2FreeFMUstate", "not a state of this instance"] },
    Row { at: At::Stepping, what: "setFMUstate with a freed state", call: |s| unsafe { let mut st: fmi2FMUstate = null_mut(); api::get_fmu_state::<Pfc>(s.c, &mut st); let freed = st; api::free_fmu_state::<Pfc>(s.c, &mut st); api::set_fmu_state::<Pfc>(s.c, freed) }, status: ERR, says: &["freed"] },
    Row { at: At::Stepping, what: "setFMUstate with another instance's state", call: |s| { let o = Slave::<Pfc>::new("other"); let mut st: fmi2FMUstate = null_mut(); unsafe { api::get_fmu_state::<Pfc>(o.c, &mut st); api::set_fmu_state::<Pfc>(s.c, st) } }, status: ERR, says: &["not a state of this instance"] },
    Row { at: At::Stepping, what: "getFMUstate overwriting a foreign pointer", call: |s| { let junk = [0u64; 64]; let mut p = junk.as_ptr() as fmi2FMUstate; unsafe { api::get_fmu_state::<Pfc>(s.c, &mut p) } }, status: ERR, says: &["fmi2GetFMUstate", "not a state of this instance"] },
    Row { at: At::Stepping, what: "serialise into a buffer of the wrong size", call: |s| unsafe { let mut st: fmi2FMUstate = null_mut(); api::get_fmu_state::<Pfc>(s.c, &mut st); let mut b = [0 as fmi2Byte; 16]; let r = api::serialize_fmu_state::<Pfc>(s.c, st, b.as_mut_ptr(), 16); api::free_fmu_state::<Pfc>(s.c, &mut st); r }, status: ERR, says: &["size = 16 bytes"] },
    Row { at: At::Stepping, what: "deserialise a flipped byte", call: |s| deserialise(s, &serialised(s, |b| b[40] ^= 1)), status: ERR, says: &["checksum"] },
    Row { at: At::Stepping, what: "deserialise a truncated state", call: |s| deserialise(s, &serialised(s, |b| b.truncate(b.len() - 9))), status: ERR, says: &["fmi2DeSerializeFMUstate"] },
    Row { at: At::Stepping, what: "deserialise a state of another model", call: |s| { let o = Slave::<HydraulicBoom>::new("plant"); let mut st: fmi2FMUstate = null_mut(); let mut n = 0; unsafe { api::get_fmu_state::<HydraulicBoom>(o.c, &mut st); api::serialized_fmu_state_size::<HydraulicBoom>(o.c, st, &mut n); let mut b = vec![0 as fmi2Byte; n]; api::serialize_fmu_state::<HydraulicBoom>(o.c, st, b.as_mut_ptr(), n); deserialise(s, &b.iter().map(|&x| x as u8).collect::<Vec<_>>()) } }, status: ERR, says: &["belongs to the FMU with GUID"] },
    Row { at: At::Stepping, what: "deserialise a forged K_f = NaN", call: |s| deserialise(s, &serialised(s, |b| forge_value::<Pfc>(b, 4, f64::NAN))), status: ERR, says: &["K_f = NaN"] },
    Row { at: At::Stepping, what: "deserialise a forged u_max = NaN", call: |s| deserialise(s, &serialised(s, |b| forge_value::<Pfc>(b, 9, f64::NAN))), status: ERR, says: &["u_max = NaN"] },
    Row { at: At::Stepping, what: "deserialise a forged p = 1e308", call: |s| deserialise(s, &serialised(s, |b| forge_value::<Pfc>(b, 1, 1e308))), status: ERR, says: &["p = 1e308", "outside its valid range"] },
    // An FMU state records the FMI version and interface of the instance that took it, and is
    // taken only in the states that version and interface have (issue 46: a state re-checksummed
    // into FMI 3.0's Intermediate Update Mode left an FMI 2.0 instance refusing every call,
    // fmi2FreeInstance included).
    Row { at: At::Stepping, what: "deserialise a state forged into Intermediate Update Mode", call: |s| deserialise(s, &serialised(s, |b| { let at = payload_offset(b) + 2; forge_bytes(b, at, &[9]) })), status: ERR, says: &["IntermediateUpdate", "FMI 2.0 CoSimulation"] },
    Row { at: At::Stepping, what: "deserialise a state forged as an FMI 3.0 instance's", call: |s| deserialise(s, &serialised(s, |b| { let at = payload_offset(b); forge_bytes(b, at, &[1]) })), status: ERR, says: &["taken by an FMI 3.0 CoSimulation instance", "this instance is an FMI 2.0 CoSimulation instance"] },
    Row { at: At::Stepping, what: "deserialise a state forged as a Model Exchange instance's", call: |s| deserialise(s, &serialised(s, |b| { let at = payload_offset(b) + 1; forge_bytes(b, at, &[0]) })), status: ERR, says: &["taken by an FMI 2.0 ModelExchange instance"] },
    Row { at: At::Stepping, what: "deserialise a forged time NaN", call: |s| deserialise(s, &serialised(s, |b| { let at = time_offset(b); forge(b, at, f64::NAN) })), status: ERR, says: &["inconsistent times", "time NaN"] },
];

#[test]
fn every_wrong_call_is_refused_with_a_reason_and_changes_nothing() {
    assert!(ROWS.len() >= 60, "the catalogue has {} rows", ROWS.len());
    let reference = {
        let s = Slave::<Pfc>::new("reference");
        normal(&s, At::Instantiated)
    };
    let mut failures = Vec::new();
    for row in ROWS {
        let s = Slave::<Pfc>::new("misuse");
        prepare(&s, row.at);
        s.take_messages();
        let status = (row.call)(&s);
        let messages = s.take_messages();
        let text = messages.iter().map(|m| m.2.as_str()).collect::<Vec<_>>().join(" | ");
        if status != row.status {
            failures.push(format!("{}: status {status:?}, expected {:?} ({text})", row.what, row.status));
            continue;
        }
        if let Some(word) = row.says.iter().find(|w| !text.contains(**w)) {
            failures.push(format!("{}: the message lacks {word:?}: {text}", row.what));
            continue;
        }
        // Still usable: the rest of the normal simulation (after fmi2Reset when terminated).
        let outputs = if row.at == At::Terminated {
            assert_eq!(unsafe { api::reset::<Pfc>(s.c) }, OK);
            normal(&s, At::Instantiated)
        } else {
            let expected_rest = &reference[..];
            let rest = normal(&s, row.at);
            assert_eq!(rest.len(), expected_rest.len());
            rest
        };
        if outputs.iter().map(|x| x.to_bits()).ne(reference.iter().map(|x| x.to_bits())) {
            failures.push(format!("{}: the instance changed: {outputs:?} != {reference:?}", row.what));
        }
    }
    assert!(failures.is_empty(), "{} of {} rows failed:\n{}", failures.len(), ROWS.len(), failures.join("\n"));
    // docs/conformance.md states the size of the catalogue: it must be this one.
    let n = ROWS.len() + INSTANTIATION.len();
    let page = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/conformance.md")).unwrap();
    let row = format!("| misuse catalogue | {n} wrong calls");
    assert!(page.contains(&row), "docs/conformance.md: the catalogue has {n} rows");
}

/// fmi2Instantiate's refusals (2.1.5): NULL, with a message where there is a logger.
#[rustfmt::skip]
const INSTANTIATION: &[(&str, &str, std::os::raw::c_int, &str)] = &[
    ("wrong GUID", "{00000000-0000-0000-0000-000000000000}", FMI2_COSIMULATION, "does not match this binary's GUID"),
    ("fmuType -1", "", -1, "fmuType = -1"),
    ("fmuType 7", "", 7, "fmuType = 7"),
    ("empty instance name", "", FMI2_COSIMULATION, "instanceName"),
];

#[test]
fn instantiation_refuses_with_a_reason() {
    for &(what, g, fmu_type, says) in INSTANTIATION {
        let g = if g.is_empty() { guid::<Pfc>() } else { g.to_owned() };
        let name = if what == "empty instance name" { "" } else { "x" };
        let e = Slave::<Pfc>::try_new(name, &g, fmu_type).err().unwrap_or_else(|| panic!("{what}: instantiated"));
        assert!(e.iter().any(|m| m.contains(says)), "{what}: {e:?}");
    }
    // No callbacks at all, or no GUID: NULL, nothing to log to.
    let (n, g) = (CString::new("x").unwrap(), CString::new(guid::<Pfc>()).unwrap());
    assert!(unsafe { api::instantiate::<Pfc>(n.as_ptr(), 1, g.as_ptr(), null(), null(), 0, 0) }.is_null());
    let messages = common::Messages::default();
    let cb = common::callbacks(&messages);
    assert!(unsafe { api::instantiate::<Pfc>(n.as_ptr(), 1, null(), null(), &cb, 0, 0) }.is_null());
    assert!(messages.lock().unwrap()[0].2.contains("fmuGUID = None"));
}

/// Calls on NULL or foreign instance pointers return fmi2Error and never touch the memory beyond
/// the tag check (fmi2FreeInstance ignores them).
#[test]
fn null_and_foreign_instances_are_refused() {
    let junk = [0u64; 64];
    for c in [null_mut(), junk.as_ptr() as fmi2Component] {
        let mut x = 0.0;
        unsafe {
            assert_eq!(api::do_step::<Pfc>(c, 0.0, H, 1), ERR);
            assert_eq!(api::get_real::<Pfc>(c, &vr::U, 1, &mut x), ERR);
            assert_eq!(api::set_real::<Pfc>(c, &vr::P, 1, &1.0), ERR);
            assert_eq!(api::terminate::<Pfc>(c), ERR);
            api::free_instance::<Pfc>(c);
        }
    }
}
