//! The FMI 3.0 C ABI in-process (`fmi3::api`, which the exported symbols call): the state machines
//! of FMI 3.0 (sections 3.2.4 and 4.2.4) table-driven, the misuse catalogue (wrong token, NULL
//! pointers, wrong state, NaN, out-of-range values, wrong types, corrupted serialised states),
//! and the same numbers as FMI 2.0 (a second path through the same model).

use crate::common;

use boomsim::fmi2::api as api2;
use boomsim::fmi2::types::{fmi2Byte, FMI2_COSIMULATION, FMI2_MODEL_EXCHANGE};
use boomsim::fmi3::api;
use boomsim::fmi3::types::*;
use boomsim::fmu::guid::{guid, token};
use boomsim::fmu::Model;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::{HydraulicBoom, HydraulicCircuit, PressureFeedbackController as Pfc};
use std::ffi::{CStr, CString};
use std::marker::PhantomData;
use std::os::raw::c_void;
use std::ptr::{null, null_mut};
use std::sync::Mutex;

const OK: fmi3Status = fmi3Status::OK;
const ERR: fmi3Status = fmi3Status::Error;

/// The arguments of fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative.
fn derivative(
    unknown: (*const u32, usize),
    known: (*const u32, usize),
    seed: (*const f64, usize),
    sensitivity: (*mut f64, usize),
) -> api::Derivative {
    api::Derivative { unknown, known, seed, sensitivity }
}

/// Messages received by the logger: (status, category, text).
type Messages = Mutex<Vec<(fmi3Status, String, String)>>;

unsafe extern "C" fn record(env: *mut c_void, status: fmi3Status, category: fmi3String, message: fmi3String) {
    let messages = &*(env as *const Messages);
    let text = |p| CStr::from_ptr(p).to_string_lossy().into_owned();
    messages.lock().unwrap().push((status, text(category), text(message)));
}

/// One FMI 3.0 instance of `M` with its recorded messages.
pub(crate) struct Inst<M: Model> {
    pub(crate) c: fmi3Instance,
    messages: Box<Messages>,
    _m: PhantomData<M>,
}

impl<M: Model> Inst<M> {
    /// Instantiates as Co-Simulation (`me` false) or Model Exchange with the right token.
    pub(crate) fn new(me: bool) -> Self {
        Self::try_new(me, &token::<M>(), (false, false)).expect("instantiation succeeds")
    }

    /// Instantiates with the given token (and, for CS, eventModeUsed and earlyReturnAllowed);
    /// `Err`: the messages.
    pub(crate) fn try_new(
        me: bool,
        token: &str,
        (event_mode_used, early_return_allowed): (bool, bool),
    ) -> Result<Self, Vec<String>> {
        let messages = Box::new(Messages::default());
        let env = &*messages as *const Messages as *mut c_void;
        let (n, t) = (CString::new("i3").unwrap(), CString::new(token).unwrap());
        let c = unsafe {
            if me {
                api::instantiate_model_exchange::<M>(n.as_ptr(), t.as_ptr(), null(), false, false, env, Some(record))
            } else {
                api::instantiate_co_simulation::<M>(
                    n.as_ptr(),
                    t.as_ptr(),
                    null(),
                    false,
                    false,
                    event_mode_used,
                    early_return_allowed,
                    null(),
                    0,
                    env,
                    Some(record),
                    None,
                )
            }
        };
        if c.is_null() {
            return Err(messages.lock().unwrap().iter().map(|m| m.2.clone()).collect());
        }
        Ok(Inst { c, messages, _m: PhantomData })
    }

    /// Initialised (stop time 1 s, the given Float64 values): CS in Step Mode, ME in Event Mode.
    pub(crate) fn initialized(me: bool, reals: &[(u32, f64)]) -> Self {
        let s = Self::new(me);
        unsafe {
            assert_eq!(api::enter_initialization_mode::<M>(s.c, false, 0.0, 0.0, true, 1.0), OK);
            for (r, x) in reals {
                assert_eq!(s.set(*r, *x), OK);
            }
            assert_eq!(api::exit_initialization_mode::<M>(s.c), OK);
        }
        s
    }

    pub(crate) fn set(&self, r: u32, x: f64) -> fmi3Status {
        unsafe { api::set_float64::<M>(self.c, &r, 1, &x, 1) }
    }

    pub(crate) fn get(&self, r: u32) -> f64 {
        let mut x = f64::NAN;
        assert_eq!(unsafe { api::get_float64::<M>(self.c, &r, 1, &mut x, 1) }, OK, "{:?}", self.last_error());
        x
    }

    pub(crate) fn step(&self, t: f64, h: f64) -> fmi3Status {
        let (mut e, mut term, mut early, mut last) = (true, true, true, f64::NAN);
        let status = unsafe { api::do_step::<M>(self.c, t, h, true, (&mut e, &mut term, &mut early), &mut last) };
        if status == OK {
            // FMI 3.0, 4.2.1: no event mode, no early return: the step reached t + h.
            assert!(!e && !term && !early && last == t + h, "out-arguments {e} {term} {early} {last}");
        }
        status
    }

    pub(crate) fn last_error(&self) -> String {
        let m = self.messages.lock().unwrap();
        m.iter().rev().find(|m| m.0 == ERR).map(|m| m.2.clone()).unwrap_or_default()
    }
}

impl<M: Model> Drop for Inst<M> {
    fn drop(&mut self) {
        unsafe { api::free_instance::<M>(self.c) }
    }
}

/// A state of the FMI 3.0 state machines this test reaches, by a letter.
const STATES: [(char, &str); 6] = [
    ('I', "Instantiated"),
    ('N', "InitializationMode"),
    ('S', "StepMode"),
    ('E', "EventMode"),
    ('C', "ContinuousTimeMode"),
    ('T', "Terminated"),
];

/// Brings a fresh controller instance into state `s` (CS: I N S T; ME: I N E C T).
fn reach(me: bool, s: char) -> Inst<Pfc> {
    let i = Inst::<Pfc>::new(me);
    unsafe {
        if s != 'I' {
            assert_eq!(api::enter_initialization_mode::<Pfc>(i.c, false, 0.0, 0.0, false, 0.0), OK);
        }
        if matches!(s, 'S' | 'E' | 'C' | 'T') {
            assert_eq!(api::exit_initialization_mode::<Pfc>(i.c), OK);
        }
        if s == 'C' || (s == 'T' && me) {
            assert_eq!(api::enter_continuous_time_mode::<Pfc>(i.c), OK);
        }
        if s == 'T' {
            assert_eq!(api::terminate::<Pfc>(i.c), OK);
        }
    }
    i
}

/// One function with valid arguments and the states where FMI 3.0 allows it, for Co-Simulation
/// and for Model Exchange (the state tables of FMI 3.0, 4.2.4 and 3.2.4, with this FMU's
/// capabilities: hasEventMode="false", no structural parameters, no clocks, no directional
/// derivatives of the controller).
struct Case {
    name: &'static str,
    call: fn(&Inst<Pfc>) -> fmi3Status,
    cs: &'static str,
    me: &'static str,
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "fmi3EnterInitializationMode",
            call: |i| unsafe { api::enter_initialization_mode::<Pfc>(i.c, false, 0.0, 0.0, false, 0.0) },
            cs: "I",
            me: "I",
        },
        Case {
            name: "fmi3ExitInitializationMode",
            call: |i| unsafe { api::exit_initialization_mode::<Pfc>(i.c) },
            cs: "N",
            me: "N",
        },
        Case { name: "fmi3EnterEventMode", call: |i| unsafe { api::enter_event_mode::<Pfc>(i.c) }, cs: "", me: "C" },
        Case { name: "fmi3Terminate", call: |i| unsafe { api::terminate::<Pfc>(i.c) }, cs: "S", me: "EC" },
        Case { name: "fmi3Reset", call: |i| unsafe { api::reset::<Pfc>(i.c) }, cs: "INST", me: "INECT" },
        Case {
            name: "fmi3SetDebugLogging",
            call: |i| unsafe { api::set_debug_logging::<Pfc>(i.c, true, 0, null()) },
            cs: "INST",
            me: "INECT",
        },
        Case {
            name: "fmi3GetFloat64",
            call: |i| unsafe { api::get_float64::<Pfc>(i.c, &vr::U, 1, &mut 0.0, 1) },
            cs: "NST",
            me: "NECT",
        },
        Case { name: "fmi3SetFloat64", call: |i| i.set(vr::P, 30e5), cs: "INS", me: "INEC" },
        Case {
            name: "fmi3GetBoolean",
            call: |i| unsafe { api::get_boolean::<Pfc>(i.c, &vr::ENABLE, 1, &mut false, 1) },
            cs: "NST",
            me: "NECT",
        },
        Case {
            name: "fmi3SetBoolean",
            call: |i| unsafe { api::set_boolean::<Pfc>(i.c, &vr::ENABLE, 1, &1, 1) },
            cs: "INS",
            me: "INE",
        },
        Case {
            name: "fmi3GetFMUState",
            call: |i| unsafe {
                let mut s = null_mut();
                let status = api::get_fmu_state::<Pfc>(i.c, &mut s);
                assert_eq!(api::free_fmu_state::<Pfc>(i.c, &mut s), OK);
                status
            },
            cs: "INST",
            me: "INECT",
        },
        Case { name: "fmi3DoStep", call: |i| i.step(0.0, 1e-3), cs: "S", me: "" },
        Case { name: "fmi3EnterStepMode", call: |i| unsafe { api::enter_step_mode::<Pfc>(i.c) }, cs: "", me: "" },
        Case {
            name: "fmi3GetOutputDerivatives",
            call: |i| unsafe { api::get_output_derivatives::<Pfc>(i.c) },
            cs: "",
            me: "",
        },
        Case {
            name: "fmi3EnterContinuousTimeMode",
            call: |i| unsafe { api::enter_continuous_time_mode::<Pfc>(i.c) },
            cs: "",
            me: "E",
        },
        Case {
            name: "fmi3UpdateDiscreteStates",
            call: |i| unsafe {
                let (mut a, mut b, mut c, mut d, mut e, mut t) = (true, true, true, true, true, 1.0);
                let status = api::update_discrete_states::<Pfc>(i.c, (&mut a, &mut b, &mut c, &mut d, &mut e), &mut t);
                assert!(status != OK || !(a || b || c || d || e), "nothing changes at an event");
                status
            },
            cs: "",
            me: "E",
        },
        Case {
            name: "fmi3CompletedIntegratorStep",
            call: |i| unsafe { api::completed_integrator_step::<Pfc>(i.c, &mut true, &mut true) },
            cs: "",
            me: "C",
        },
        // 3.2.1: Continuous-Time Mode only (Event Mode, 2.3.5, does not list it).
        Case { name: "fmi3SetTime", call: |i| unsafe { api::set_time::<Pfc>(i.c, 0.0) }, cs: "", me: "C" },
        Case {
            name: "fmi3SetContinuousStates",
            call: |i| unsafe { api::set_continuous_states::<Pfc>(i.c, &30e5, 1) },
            cs: "",
            me: "C",
        },
        Case {
            name: "fmi3GetContinuousStateDerivatives",
            call: |i| unsafe { api::get_continuous_state_derivatives::<Pfc>(i.c, &mut 0.0, 1) },
            cs: "",
            me: "NECT",
        },
        Case {
            name: "fmi3GetContinuousStates",
            call: |i| unsafe { api::get_continuous_states::<Pfc>(i.c, &mut 0.0, 1) },
            cs: "",
            me: "NECT",
        },
        Case {
            name: "fmi3GetNominalsOfContinuousStates",
            call: |i| unsafe { api::get_nominals_of_continuous_states::<Pfc>(i.c, &mut 0.0, 1) },
            cs: "",
            me: "NECT",
        },
        Case {
            name: "fmi3GetEventIndicators",
            call: |i| unsafe { api::get_event_indicators::<Pfc>(i.c, null_mut(), 0) },
            cs: "",
            me: "NECT",
        },
        Case {
            name: "fmi3GetNumberOfContinuousStates",
            call: |i| unsafe { api::get_number_of_continuous_states::<Pfc>(i.c, &mut 0) },
            cs: "",
            me: "INECT",
        },
        Case {
            name: "fmi3GetNumberOfEventIndicators",
            call: |i| unsafe { api::get_number_of_event_indicators::<Pfc>(i.c, &mut 0) },
            cs: "",
            me: "INECT",
        },
        Case {
            name: "fmi3GetDirectionalDerivative",
            call: |i| unsafe {
                let d = derivative((&vr::U, 1), (&vr::P, 1), (&1.0, 1), (&mut 0.0, 1));
                api::get_directional_derivative::<Pfc>(i.c, d)
            },
            cs: "",
            me: "",
        },
        Case {
            name: "fmi3EnterConfigurationMode",
            call: |i| api::unsupported::<Pfc>(i.c, "fmi3EnterConfigurationMode", "no structural parameters"),
            cs: "",
            me: "",
        },
    ]
}

/// Every function in every reachable state of both interfaces: OK where the table allows it,
/// else fmi3Error with a message naming the function and the reason (the state, the other
/// interface, or what is not provided); and the instance answers a legal call afterwards.
#[test]
fn every_function_in_every_state_follows_the_fmi3_state_machine() {
    let mut checked = 0;
    for case in cases() {
        for me in [false, true] {
            let allowed = if me { case.me } else { case.cs };
            let reachable = if me { "INECT" } else { "INST" };
            for (s, state) in STATES.iter().filter(|(s, _)| reachable.contains(*s)) {
                let i = reach(me, *s);
                let status = (case.call)(&i);
                let at = format!("{} in {state} ({})", case.name, if me { "ME" } else { "CS" });
                if allowed.contains(*s) {
                    assert_eq!(status, OK, "{at}: {}", i.last_error());
                } else {
                    assert_eq!(status, ERR, "{at} must be refused");
                    let m = i.last_error();
                    let why = ["illegal call in state", "function, but this instance", "not supported"];
                    assert!(m.starts_with(case.name) && why.iter().any(|w| m.contains(w)), "{at}: {m:?}");
                    // FMI 3.0, 2.3.1: "If any function called in super state FMU State Settable
                    // returns fmi3Error, the FMU enters state Terminated": setting an input (legal
                    // in every other state) is refused now, and fmi3Reset is legal there.
                    assert_eq!(i.set(vr::P, 30e5), ERR, "{at}: Terminated after the error");
                    assert!(i.last_error().contains("illegal call in state Terminated"), "{at}: {}", i.last_error());
                    assert_eq!(unsafe { api::reset::<Pfc>(i.c) }, OK, "{at}");
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, cases().len() * 9, "4 CS and 5 ME states per function");
}

/// FMI 3.0, 2.3.1: a token other than the modelDescription's (the FMI 2.0 GUID of the same
/// model too), an empty name, eventModeUsed without event mode: NULL with a message.
#[test]
fn instantiation_refuses_a_wrong_token_name_or_mode() {
    for wrong in ["{00000000-0000-0000-0000-000000000000}".to_string(), guid::<Pfc>()] {
        let e = Inst::<Pfc>::try_new(false, &wrong, (false, false)).err().expect("refused");
        assert!(e.iter().any(|m| m.contains("instantiationToken") && m.contains("does not match")), "{e:?}");
    }
    let e = Inst::<Pfc>::try_new(false, &token::<Pfc>(), (true, false)).err().expect("refused");
    assert!(e.iter().any(|m| m.contains("eventModeUsed") && m.contains("hasEventMode")), "{e:?}");
    let t = CString::new(token::<Pfc>()).unwrap();
    let c = unsafe {
        api::instantiate_model_exchange::<Pfc>(c"".as_ptr(), t.as_ptr(), null(), false, false, null_mut(), None)
    };
    assert!(c.is_null(), "an empty instance name is refused (silently: no logger)");
    let c = unsafe { api::instantiate_scheduled_execution::<Pfc>(c"se".as_ptr(), false, null_mut(), None) };
    assert!(c.is_null(), "no Scheduled Execution");
}

/// A NULL logMessage is tolerated: the instance runs, and refused calls still say fmi3Error.
#[test]
fn a_null_logger_is_tolerated() {
    let t = CString::new(token::<Pfc>()).unwrap();
    let c = unsafe {
        api::instantiate_co_simulation::<Pfc>(
            c"quiet".as_ptr(),
            t.as_ptr(),
            null(),
            false,
            true,
            false,
            false,
            null(),
            0,
            null_mut(),
            None,
            None,
        )
    };
    assert!(!c.is_null());
    unsafe {
        assert_eq!(api::do_step::<Pfc>(c, 0.0, 1e-3, true, (&mut false, &mut false, &mut false), &mut 0.0), ERR);
        // FMI 3.0, 2.3.1: the error left the instance Terminated; fmi3Reset starts it anew.
        assert_eq!(api::enter_initialization_mode::<Pfc>(c, false, 0.0, 0.0, false, 0.0), ERR);
        assert_eq!(api::reset::<Pfc>(c), OK);
        assert_eq!(api::enter_initialization_mode::<Pfc>(c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!(api::set_float64::<Pfc>(c, &vr::P, 1, &f64::NAN, 1), ERR);
        assert_eq!(api::exit_initialization_mode::<Pfc>(c), ERR, "Terminated after the error");
        api::free_instance::<Pfc>(c);
    }
}

/// Each wrong argument: fmi3Error, a message naming the variable, value or pointer, and the
/// instance Terminated (FMI 3.0, 2.3.1: "If any function called in super state FMU State
/// Settable returns fmi3Error, the FMU enters state Terminated"; a step is refused), from where
/// fmi3SetFMUState restores it (2.2.4: "it is possible to restore a previously retrieved FMU
/// state"): the next steps give the outputs of an untouched twin.
#[test]
fn misuse_answers_with_error_and_a_message_and_changes_nothing() {
    let setup = [(vr::P, 40e5), (vr::U_REF, -0.1)];
    let (i, twin) = (Inst::<Pfc>::initialized(false, &setup), Inst::<Pfc>::initialized(false, &setup));
    let mut saved = null_mut();
    assert_eq!(unsafe { api::get_fmu_state::<Pfc>(i.c, &mut saved) }, OK);
    let wrong: &[(&str, &dyn Fn() -> fmi3Status, &[&str])] = &[
        (
            "count past the arrays",
            &|| unsafe { api::set_float64::<Pfc>(i.c, &vr::P, usize::MAX, &1e5, usize::MAX) },
            &["vr: 18446744073709551615 elements announced, but at most"],
        ),
        (
            "get count past the arrays",
            &|| unsafe { api::get_float64::<Pfc>(i.c, &vr::U, usize::MAX, &mut 0.0, usize::MAX) },
            &["18446744073709551615 elements announced"],
        ),
        ("NaN", &|| i.set(vr::P, f64::NAN), &["p = NaN is not a finite number", "valid range [-1e8, 1e8] Pa"]),
        ("out of range", &|| i.set(vr::U_REF, 2.0), &["u_ref = 2 is outside its valid range [-1, 1]"]),
        ("not settable", &|| i.set(vr::U, 0.5), &["cannot set \"u\"", "causality=output"]),
        ("unknown vr", &|| i.set(999, 1.0), &["unknown value reference 999"]),
        ("vr NULL", &|| unsafe { api::get_float64::<Pfc>(i.c, null(), 1, &mut 0.0, 1) }, &["vr is NULL"]),
        ("values NULL", &|| unsafe { api::get_float64::<Pfc>(i.c, &vr::U, 1, null_mut(), 1) }, &["value is NULL"]),
        ("nValues", &|| unsafe { api::get_float64::<Pfc>(i.c, &vr::U, 1, &mut 0.0, 2) }, &["nValues = 2"]),
        (
            "Int32 of a Float64",
            &|| unsafe { api::get_int32::<Pfc>(i.c, &vr::U, 1, &mut 0, 1) },
            &["variable \"u\" (vr 2) is a Float64, not a Int32"],
        ),
        (
            "Float64 of a Boolean",
            &|| unsafe { api::get_float64::<Pfc>(i.c, &vr::ENABLE, 1, &mut 0.0, 1) },
            &["\"enable\" (vr 7) is a Boolean, not a Float64"],
        ),
        (
            "Int8",
            &|| unsafe { api::other_type::<Pfc>(i.c, "fmi3GetInt8", false, &vr::U, 1, "Int8") },
            &["fmi3GetInt8", "\"u\" (vr 2) is a Float64, not a Int8"],
        ),
        (
            "UInt64 unknown",
            &|| unsafe { api::other_type::<Pfc>(i.c, "fmi3SetUInt64", true, &77, 1, "UInt64") },
            &["unknown value reference 77"],
        ),
        ("bool 2", &|| unsafe { api::set_boolean::<Pfc>(i.c, &vr::ENABLE, 1, &2, 1) }, &["2 is not an fmi3Boolean"]),
        ("time set", &|| i.set(boomsim::fmu::instance::INDEPENDENT_VR, 1.0), &["\"time\"", "independent variable"]),
        (
            "doStep NULL",
            &|| unsafe { api::do_step::<Pfc>(i.c, 0.0, 1e-3, true, (null_mut(), &mut false, &mut false), &mut 0.0) },
            &["eventHandlingNeeded is NULL"],
        ),
        ("doStep time", &|| i.step(0.5, 1e-3), &["currentCommunicationPoint = 0.5"]),
        ("doStep h", &|| i.step(0.0, -1e-3), &["communicationStepSize = -0.001"]),
        ("past stop", &|| i.step(0.0, 2.0), &["stop time 1", "fmi3EnterInitializationMode"]),
        ("ME function", &|| unsafe { api::set_time::<Pfc>(i.c, 0.0) }, &["a ModelExchange function"]),
        (
            "adjoint",
            &|| unsafe {
                api::get_adjoint_derivative::<Pfc>(i.c, derivative((&vr::U, 1), (&vr::P, 1), (&1.0, 1), (&mut 0.0, 1)))
            },
            &["providesAdjointDerivatives=\"false\""],
        ),
        (
            "FMU state NULL",
            &|| unsafe { api::set_fmu_state::<Pfc>(i.c, null_mut()) },
            &["is NULL, freed, or not a state of this instance", "fmi3GetFMUState or fmi3DeserializeFMUState"],
        ),
    ];
    for (what, call, says) in wrong {
        assert_eq!(call(), ERR, "{what}");
        let m = i.last_error();
        assert!(says.iter().all(|s| m.contains(s)), "{what}: {m:?}");
        assert!(m.contains("the instance is now Terminated (FMI 3.0, 2.3.1"), "{what}: {m:?}");
        assert_eq!(i.step(0.0, 1e-3), ERR, "{what}: Terminated");
        assert_eq!(unsafe { api::set_fmu_state::<Pfc>(i.c, saved) }, OK, "{what}: restored");
    }
    assert_eq!(unsafe { api::free_fmu_state::<Pfc>(i.c, &mut saved) }, OK);
    for k in 0..3 {
        let t = k as f64 * 1e-3;
        assert_eq!((i.set(vr::P, 41e5), twin.set(vr::P, 41e5)), (OK, OK));
        assert_eq!((i.step(t, 1e-3), twin.step(t, 1e-3)), (OK, OK));
        assert_eq!(i.get(vr::U_COMP).to_bits(), twin.get(vr::U_COMP).to_bits(), "unchanged by the refused calls");
    }
    // FMI 3.0, 2.4.7.4: the independent variable reads the instance time, t + h of the last step.
    assert_eq!(i.get(boomsim::fmu::instance::INDEPENDENT_VR), 2e-3 + 1e-3);
}

/// The instance's current state, serialised (fmi3GetFMUState, size, serialise, free).
pub(crate) fn serialize<M: Model>(i: &Inst<M>) -> Vec<u8> {
    unsafe {
        let (mut s, mut n) = (null_mut(), 0);
        assert_eq!(api::get_fmu_state::<M>(i.c, &mut s), OK);
        assert_eq!(api::serialized_fmu_state_size::<M>(i.c, s, &mut n), OK);
        let mut b = vec![0u8; n];
        assert_eq!(api::serialize_fmu_state::<M>(i.c, s, b.as_mut_ptr(), n), OK);
        assert_eq!(api::free_fmu_state::<M>(i.c, &mut s), OK);
        b
    }
}

/// A state restored from bytes continues bit-identically; damaged, forged, truncated bytes and
/// a state of the FMI 2.0 interface of the same binary are refused with the reason.
#[test]
fn serialised_states_round_trip_and_corruption_is_refused() {
    let i = Inst::<Pfc>::initialized(false, &[(vr::P, 40e5)]);
    assert_eq!(i.step(0.0, 1e-3), OK);
    let bytes = serialize(&i);
    let expected = {
        assert_eq!((i.set(vr::P, 30e5), i.step(1e-3, 1e-3)), (OK, OK));
        i.get(vr::U_COMP)
    };
    let deserialize = |b: &[u8]| {
        let mut s = null_mut();
        let status = unsafe { api::deserialize_fmu_state::<Pfc>(i.c, b.as_ptr(), b.len(), &mut s) };
        (status, s)
    };
    let (status, mut s) = deserialize(&bytes);
    assert_eq!(status, OK);
    unsafe { assert_eq!(api::set_fmu_state::<Pfc>(i.c, s), OK) };
    assert_eq!((i.set(vr::P, 30e5), i.step(1e-3, 1e-3)), (OK, OK));
    assert_eq!(i.get(vr::U_COMP).to_bits(), expected.to_bits(), "restored and continued bit-identically");
    unsafe { assert_eq!(api::free_fmu_state::<Pfc>(i.c, &mut s), OK) };
    let mut flipped = bytes.clone();
    let at = flipped.len() / 2;
    flipped[at] ^= 1;
    let mut forged = bytes.clone();
    let time_at = common::time_offset(&forged);
    common::forge(&mut forged, time_at, f64::NAN);
    let fmi2_state = {
        let messages = Box::new(common::Messages::default());
        let cb = common::callbacks(&messages);
        let g = CString::new(guid::<Pfc>()).unwrap();
        unsafe {
            let c = api2::instantiate::<Pfc>(c"i2".as_ptr(), FMI2_COSIMULATION, g.as_ptr(), null(), &cb, 0, 0);
            let (mut s, mut n) = (null_mut(), 0);
            assert_eq!(api2::get_fmu_state::<Pfc>(c, &mut s), OK);
            assert_eq!(api2::serialized_fmu_state_size::<Pfc>(c, s, &mut n), OK);
            let mut b = vec![0u8; n];
            assert_eq!(api2::serialize_fmu_state::<Pfc>(c, s, b.as_mut_ptr() as *mut fmi2Byte, n), OK);
            // An FMI 3.0 instance pointer is not an FMI 2.0 one, and vice versa.
            assert_eq!(api2::set_fmu_state::<Pfc>(i.c, s), ERR);
            assert_eq!(api::set_fmu_state::<Pfc>(c, s), ERR);
            api2::free_instance::<Pfc>(c);
            b
        }
    };
    let refused: [(&str, &[u8], &str); 4] = [
        ("flipped", &flipped, "checksum mismatch"),
        ("forged time", &forged, "inconsistent times"),
        ("truncated", &bytes[..20], "too few for a serialised FMU state"),
        ("FMI 2.0", &fmi2_state, "belongs to the FMU with GUID"),
    ];
    for (what, b, says) in refused {
        assert_eq!(deserialize(b).0, ERR, "{what}");
        assert!(i.last_error().contains(says), "{what}: {}", i.last_error());
    }
}

/// The same controller through FMI 2.0 and FMI 3.0 with the same held inputs: bit-identical
/// outputs (one model, one solver; only the adapters differ).
#[test]
fn co_simulation_is_bit_identical_to_fmi2() {
    let three = Inst::<Pfc>::initialized(false, &[(vr::P, 40e5), (vr::U_REF, -0.2)]);
    let two = common::Slave::<Pfc>::initialized("two", &[(vr::P, 40e5), (vr::U_REF, -0.2)]);
    for k in 0..300 {
        let (t, p) = (k as f64 * 1e-3, 40e5 + 3e5 * (k as f64 * 0.05).sin());
        assert_eq!((three.set(vr::P, p), two.set_real(vr::P, p)), (OK, OK));
        assert_eq!((three.step(t, 1e-3), two.step(t, 1e-3)), (OK, OK));
        for r in [vr::U, vr::U_COMP, vr::P_LP] {
            assert_eq!(three.get(r).to_bits(), two.real(r).to_bits(), "vr {r} at step {k}");
        }
    }
}

/// Model Exchange: the state derivatives through FMI 3.0 equal FMI 2.0's at the same states
/// (bitwise), and the adjoint derivative is the transpose of the directional one:
/// v . (J w) = (J^T v) . w for the circuit's outputs and derivatives against its inputs and
/// states (to 1e-12 of the terms' magnitude: the two sums are accumulated in different orders).
#[test]
fn model_exchange_matches_fmi2_and_the_adjoint_is_the_transpose() {
    fn derivatives_agree<M: Model>() {
        let three = Inst::<M>::initialized(true, &[]);
        let messages = Box::new(common::Messages::default());
        let cb = common::callbacks(&messages);
        let g = CString::new(guid::<M>()).unwrap();
        let n = M::STATES.len();
        let (mut x, mut d3, mut d2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        unsafe {
            let c = api2::instantiate::<M>(c"i2".as_ptr(), FMI2_MODEL_EXCHANGE, g.as_ptr(), null(), &cb, 0, 0);
            assert_eq!(api2::setup_experiment::<M>(c, 0, 0.0, 0.0, 1, 1.0), OK);
            assert_eq!(api2::enter_initialization_mode::<M>(c), OK);
            assert_eq!(api2::exit_initialization_mode::<M>(c), OK);
            for inst in [three.c] {
                assert_eq!(api::enter_continuous_time_mode::<M>(inst), OK);
            }
            assert_eq!(api2::enter_continuous_time_mode::<M>(c), OK);
            assert_eq!(api::get_continuous_states::<M>(three.c, x.as_mut_ptr(), n), OK);
            // Move every state by a tenth of its nominal value, away from the rest state.
            x.iter_mut().zip(M::STATES).for_each(|(x, s)| *x += 0.1 * s.nominal);
            assert_eq!(api::set_continuous_states::<M>(three.c, x.as_ptr(), n), OK);
            assert_eq!(api2::set_continuous_states::<M>(c, x.as_ptr(), n), OK);
            assert_eq!(api::get_continuous_state_derivatives::<M>(three.c, d3.as_mut_ptr(), n), OK);
            assert_eq!(api2::get_derivatives::<M>(c, d2.as_mut_ptr(), n), OK);
            api2::free_instance::<M>(c);
        }
        assert!(d3.iter().zip(&d2).all(|(a, b)| a.to_bits() == b.to_bits()), "{}", M::INFO.identifier);
    }
    derivatives_agree::<HydraulicBoom>();
    derivatives_agree::<HydraulicCircuit>();

    type C = HydraulicCircuit;
    let i = Inst::<C>::initialized(true, &[]);
    unsafe { assert_eq!(api::enter_continuous_time_mode::<C>(i.c), OK) };
    let inputs = C::VARIABLES.iter().filter(|v| v.causality == boomsim::fmu::Causality::Input);
    let knowns: Vec<u32> = inputs
        .filter(|v| matches!(v.kind, boomsim::fmu::Kind::Real { .. }))
        .map(|v| v.vr)
        .chain(C::STATES.iter().map(|s| s.state))
        .collect();
    let outputs = C::VARIABLES.iter().filter(|v| v.causality == boomsim::fmu::Causality::Output).map(|v| v.vr);
    let unknowns: Vec<u32> = outputs.chain(C::STATES.iter().map(|s| s.derivative)).collect();
    // Seeds of mixed signs and magnitudes (deterministic).
    let w: Vec<f64> = (0..knowns.len()).map(|k| ((k * 7 + 3) % 11) as f64 - 5.0).collect();
    let v: Vec<f64> = (0..unknowns.len()).map(|k| ((k * 5 + 1) % 13) as f64 - 6.0).collect();
    let (mut jw, mut jtv) = (vec![0.0; unknowns.len()], vec![0.0; knowns.len()]);
    let (nu, nk) = (unknowns.len(), knowns.len());
    unsafe {
        let u = (unknowns.as_ptr(), nu);
        let k = (knowns.as_ptr(), nk);
        let forward = derivative(u, k, (w.as_ptr(), nk), (jw.as_mut_ptr(), nu));
        let status = api::get_directional_derivative::<C>(i.c, forward);
        assert_eq!(status, OK);
        let status = api::get_adjoint_derivative::<C>(i.c, derivative(u, k, (v.as_ptr(), nu), (jtv.as_mut_ptr(), nk)));
        assert_eq!(status, OK);
        let mut short = [0.0; 1];
        let status = api::get_adjoint_derivative::<C>(i.c, derivative(u, k, (v.as_ptr(), nu), (short.as_mut_ptr(), 1)));
        assert_eq!(status, ERR);
        assert!(i.last_error().contains("nSensitivity = 1"));
        // A message names the FMI 3.0 argument (fmi3FunctionTypes.h), not FMI 2.0's dvKnown.
        let nan = vec![f64::NAN; nk];
        let not_a_number = derivative(u, k, (nan.as_ptr(), nk), (jw.as_mut_ptr(), nu));
        let status = api::get_directional_derivative::<C>(i.c, not_a_number);
        assert_eq!(status, ERR);
        assert!(i.last_error().contains("seed of \""), "{}", i.last_error());
    }
    let a: f64 = v.iter().zip(&jw).map(|(v, x)| v * x).sum();
    let b: f64 = jtv.iter().zip(&w).map(|(x, w)| x * w).sum();
    let scale: f64 = v.iter().zip(&jw).map(|(v, x)| (v * x).abs()).sum::<f64>().max(1e-300);
    assert!(a != 0.0 && (a - b).abs() <= 1e-12 * scale, "v.(Jw) = {a}, (J^T v).w = {b}");
}

/// FMI 3.0, 2.4.8: the event indicators are the variables ModelStructure lists as
/// `<EventIndicator>`, and fmi3GetEventIndicators returns them in that order. Their values are
/// the circuit's switching functions (thesis eq. 2.44-2.45: the spool demand jumps at u_ref = 0,
/// the load-sensing pressure at x_v = +-x_db), computed here from valve.u_ref, valve.x_v and
/// valve.x_db.
#[test]
fn event_indicators_are_the_declared_variables_in_their_order() {
    fn declared(id: &str) -> Vec<u32> {
        let xml =
            std::fs::read_to_string(format!("{}/modelDescription/fmi3/{id}.xml", concat!(env!("CARGO_MANIFEST_DIR"), "/.."))).unwrap();
        xml.split("<EventIndicator valueReference=\"")
            .skip(1)
            .map(|s| s.split('"').next().unwrap().parse().unwrap())
            .collect()
    }
    fn vr_of<M: Model>(name: &str) -> u32 {
        M::VARIABLES.iter().find(|v| v.name == name).unwrap().vr
    }
    fn check<M: Model>() {
        let vrs = declared(M::INFO.identifier);
        let i = Inst::<M>::initialized(true, &[(vr_of::<M>("valve.u_ref"), -0.3)]);
        let n = M::STATES.len();
        let mut x = vec![0.0; n];
        let mut count = 0;
        unsafe {
            assert_eq!(api::get_number_of_event_indicators::<M>(i.c, &mut count), OK);
            assert_eq!(api::enter_continuous_time_mode::<M>(i.c), OK);
            assert_eq!(api::get_continuous_states::<M>(i.c, x.as_mut_ptr(), n), OK);
        }
        assert_eq!(count, vrs.len());
        // Spool positions inside, at and beyond the dead band's edges.
        let (k, x_db) = (
            M::STATES.iter().position(|s| s.state == vr_of::<M>("valve.x_v")).unwrap(),
            i.get(vr_of::<M>("valve.x_db")),
        );
        for x_v in [-2.0 * x_db, -x_db, 0.3 * x_db, 1.5 * x_db] {
            x[k] = x_v;
            let mut z = vec![f64::NAN; count];
            unsafe {
                assert_eq!(api::set_continuous_states::<M>(i.c, x.as_ptr(), n), OK);
                assert_eq!(api::get_event_indicators::<M>(i.c, z.as_mut_ptr(), count), OK);
            }
            let by_vr: Vec<f64> = vrs.iter().map(|&r| i.get(r)).collect();
            assert_eq!(z, by_vr, "{}: fmi3GetEventIndicators against fmi3GetFloat64", M::INFO.identifier);
            assert_eq!(z, [-0.3, x_v - x_db, x_v + x_db], "{}", M::INFO.identifier);
        }
        unsafe {
            let mut z = [0.0; 4];
            assert_eq!(api::get_event_indicators::<M>(i.c, z.as_mut_ptr(), count + 1), ERR);
        }
        assert!(i.last_error().contains("event indicators"), "{}", i.last_error());
    }
    check::<HydraulicBoom>();
    check::<HydraulicCircuit>();
    // The controller has no switching function: none declared, none returned.
    assert!(declared("PressureFeedbackController").is_empty());
    let i = Inst::<Pfc>::initialized(true, &[]);
    let mut count = 1;
    unsafe { assert_eq!(api::get_number_of_event_indicators::<Pfc>(i.c, &mut count), OK) };
    assert_eq!(count, 0);
}

/// FMI 3.0, 2.2.4 (fmi3Discard: "the FMU is in the same state as before the call ... the
/// computation may continue") and 4.2.1 (fmi3DoStep may return it "if the FMU is in the same
/// state as before the call"): a step of 1e12 s that the plant's integrator cannot finish (its
/// smallest step, 10 eps of the span: 2.2 ms, is too coarse for the lowering's first transient) is
/// discarded and the instance stays at its time in Step Mode, so a smaller step continues from
/// there and gives what an untouched twin gives.
#[test]
fn a_discarded_step_leaves_the_instance_as_it_was() {
    use boomsim::models::vr as plant;
    let setup = [(plant::U_REF, -0.3)];
    let open_ended = || {
        let s = Inst::<HydraulicBoom>::new(false);
        unsafe {
            assert_eq!(api::enter_initialization_mode::<HydraulicBoom>(s.c, false, 0.0, 0.0, false, 0.0), OK);
            assert_eq!(s.set(setup[0].0, setup[0].1), OK);
            assert_eq!(api::exit_initialization_mode::<HydraulicBoom>(s.c), OK);
        }
        s
    };
    let (i, twin) = (open_ended(), open_ended());
    assert_eq!(i.step(0.0, 1e12), fmi3Status::Discard);
    let said = i.messages.lock().unwrap().last().map(|m| (m.0, m.2.clone())).expect("a message");
    assert!(said.0 == fmi3Status::Discard && said.1.contains("the instance is back at t = 0"), "{said:?}");
    assert_eq!(i.get(boomsim::fmu::instance::INDEPENDENT_VR), 0.0);
    for k in 0..5 {
        let t = k as f64 * 1e-3;
        assert_eq!((i.step(t, 1e-3), twin.step(t, 1e-3)), (OK, OK), "{}", i.last_error());
        assert_eq!(i.get(plant::P3).to_bits(), twin.get(plant::P3).to_bits());
    }
}

/// FMI 3.0, 2.3.3: fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative are among
/// Initialization Mode's calls. At the rigid boom's start equilibrium (p3 A_p = F + p4 A_r, eq.
/// 2.72 at rest) dp3/d(start.p4) = A_r / A_p = 1 - (d_rod / d_piston)^2 from the FMU's own
/// bore and rod, both ways; 1e-6 relative: the central difference's error and the equilibrium
/// solve's tolerance.
#[test]
fn derivatives_in_initialization_mode() {
    use boomsim::models::vr as plant;
    let (start_p4, d_piston, d_rod): (u32, u32, u32) = (32, 120, 121);
    for me in [false, true] {
        let i = Inst::<HydraulicBoom>::new(me);
        unsafe {
            assert_eq!(api::enter_initialization_mode::<HydraulicBoom>(i.c, false, 0.0, 0.0, false, 0.0), OK);
            assert_eq!(api::set_boolean::<HydraulicBoom>(i.c, &plant::FLEXIBLE, 1, &0, 1), OK);
        }
        let ratio = 1.0 - (i.get(d_rod) / i.get(d_piston)).powi(2);
        let (mut forward, mut adjoint) = (f64::NAN, f64::NAN);
        unsafe {
            let p3 = (&plant::P3 as *const u32, 1);
            let known = (&start_p4 as *const u32, 1);
            let dd = api::get_directional_derivative::<HydraulicBoom>(
                i.c,
                derivative(p3, known, (&1.0, 1), (&mut forward, 1)),
            );
            assert_eq!(dd, OK, "{}", i.last_error());
            let ad = api::get_adjoint_derivative::<HydraulicBoom>(
                i.c,
                derivative(p3, known, (&1.0, 1), (&mut adjoint, 1)),
            );
            assert_eq!(ad, OK, "{}", i.last_error());
        }
        for d in [forward, adjoint] {
            assert!((d - ratio).abs() <= 1e-6 * ratio, "ME {me}: {d} vs A_r/A_p = {ratio}");
        }
    }
}

/// FMI 3.0, 3.2.1 (fmi3EnterInitializationMode: in Model Exchange the tolerance is the importer's
/// integrator's): a tolerance looser than the model needs is kept with fmi3Warning and a message
/// naming both, as in FMI 2.0 (tests/abi/hardening.rs); in Co-Simulation it is fmi3OK.
#[test]
fn a_model_exchange_tolerance_looser_than_the_model_needs_is_a_warning() {
    for (me, expected) in [(true, fmi3Status::Warning), (false, OK)] {
        let i = Inst::<HydraulicBoom>::new(me);
        let status = unsafe { api::enter_initialization_mode::<HydraulicBoom>(i.c, true, 1e-4, 0.0, false, 0.0) };
        let m = i.messages.lock().unwrap().iter().map(|m| m.2.clone()).collect::<Vec<_>>().join(" ");
        assert_eq!(status, expected, "{m}");
        assert_eq!(m.contains("tolerance = 0.0001 is looser than the 1e-6"), me, "{m}");
    }
}

/// FMI 3.0, 3.2.1 (fmi3SetContinuousStates: "fmi3Discard should be returned if the FMU rejects
/// any of the state values"): the plant rejects none; a trial state with p3 below absolute zero
/// (-101325 Pa gauge) is taken with OK, and its derivatives are finite and pull p3 back towards
/// vacuum (issue 49: the equations are continued there, `boomsim::hydraulics::line`).
#[test]
fn fmi3_states_below_absolute_zero_are_taken() {
    let i = Inst::<HydraulicBoom>::initialized(true, &[]);
    let n = HydraulicBoom::STATES.len();
    let (mut x, mut dx) = (vec![0.0; n], vec![0.0; n]);
    unsafe {
        assert_eq!(api::enter_continuous_time_mode::<HydraulicBoom>(i.c), OK);
        assert_eq!(api::get_continuous_states::<HydraulicBoom>(i.c, x.as_mut_ptr(), n), OK);
        let p3 = boomsim::hydraulics::circuit::P3;
        x[p3] = -2e5;
        assert_eq!(api::set_continuous_states::<HydraulicBoom>(i.c, x.as_ptr(), n), OK);
        let mut taken = vec![0.0; n];
        assert_eq!(api::get_continuous_states::<HydraulicBoom>(i.c, taken.as_mut_ptr(), n), OK);
        assert_eq!(taken, x);
        assert_eq!(api::get_continuous_state_derivatives::<HydraulicBoom>(i.c, dx.as_mut_ptr(), n), OK);
        assert!(dx.iter().all(|d| d.is_finite()) && dx[p3] > 0.0, "{dx:?}");
    }
}
