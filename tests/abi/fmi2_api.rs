//! The generic FMI 2.0 layer, driven in-process through the same functions the C ABI exports.
//! Expected behaviour comes from the FMI 2.0.4 standard (sections cited per test).

use crate::common;

use boomsim::fmi2::api;
use boomsim::fmu::driver::Step;
use boomsim::fmu::guid::guid;
use boomsim::fmi2::types::*;
use boomsim::fmu::{ContinuousState, Log, Model, ModelInfo, StepError, StepStart, Values, Variable};
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::PressureFeedbackController as Pfc;
use crate::common::Slave;
use std::ffi::CString;

const ERR: fmi2Status = fmi2Status::Error;
const OK: fmi2Status = fmi2Status::OK;

/// FMI 2.0 4.2.4: fmi2DoStep is only allowed in stepComplete; the call is refused with a message
/// naming the function and the state, and the instance stays usable.
#[test]
fn illegal_calls_are_refused_and_the_instance_stays_usable() {
    let s = Slave::<Pfc>::new("sm");
    assert_eq!(s.step(0.0, 1e-3), ERR);
    let e = s.last_error();
    assert!(e.contains("fmi2DoStep") && e.contains("Instantiated"), "{e}");
    assert_eq!(unsafe { api::exit_initialization_mode::<Pfc>(s.c) }, ERR);
    assert!(s.last_error().contains("fmi2ExitInitializationMode"));
    let mut x = 0.0;
    assert_eq!(unsafe { api::get_real::<Pfc>(s.c, &vr::U, 1, &mut x) }, ERR, "no get before initialisation");
    // The normal sequence still works.
    assert_eq!(unsafe { api::enter_initialization_mode::<Pfc>(s.c) }, OK);
    assert_eq!(unsafe { api::exit_initialization_mode::<Pfc>(s.c) }, OK);
    assert_eq!(s.step(0.0, 1e-3), OK);
    assert_eq!(unsafe { api::cancel_step::<Pfc>(s.c) }, ERR, "no asynchronous step to cancel");
}

/// FMI 2.0 2.1.5: fmi2Instantiate returns NULL when it cannot create the instance.
#[test]
fn instantiate_refuses_bad_arguments_with_a_reason() {
    let e = Slave::<Pfc>::try_new("x", "{00000000-0000-0000-0000-000000000000}", FMI2_COSIMULATION).err().unwrap();
    assert!(e[0].contains("GUID"), "{e:?}");
    let e = Slave::<Pfc>::try_new("x", &guid::<Pfc>(), 2).err().unwrap();
    assert!(e[0].contains("fmuType = 2"), "{e:?}");
    assert!(Slave::<Pfc>::try_new("x", &guid::<Pfc>(), FMI2_MODEL_EXCHANGE).is_ok(), "both interfaces");
    let e = Slave::<Pfc>::try_new("", &guid::<Pfc>(), FMI2_COSIMULATION).err().unwrap();
    assert!(e[0].contains("instanceName"), "{e:?}");
    let (n, g) = (CString::new("x").unwrap(), CString::new(guid::<Pfc>()).unwrap());
    let null = unsafe { api::instantiate::<Pfc>(n.as_ptr(), 1, g.as_ptr(), std::ptr::null(), std::ptr::null(), 0, 0) };
    assert!(null.is_null());
}

/// FMI 2.0, 2.1.5 and 4.3.1: with canNotUseMemoryManagementFunctions="true" the importer may pass
/// NULL allocateMemory/freeMemory; boomsim also runs with a NULL logger, silently.
#[test]
fn instantiate_accepts_null_memory_callbacks_and_a_null_logger() {
    let (n, g) = (CString::new("x").unwrap(), CString::new(guid::<Pfc>()).unwrap());
    let messages = common::Messages::default();
    for (logger, memory) in [(true, false), (false, false), (false, true)] {
        let mut cb = common::callbacks(&messages);
        if !memory {
            (cb.allocateMemory, cb.freeMemory) = (None, None);
        }
        if !logger {
            cb.logger = None;
        }
        let c = unsafe { api::instantiate::<Pfc>(n.as_ptr(), 1, g.as_ptr(), std::ptr::null(), &cb, 0, 1) };
        assert!(!c.is_null(), "logger {logger}, memory callbacks {memory}");
        unsafe {
            assert_eq!(api::enter_initialization_mode::<Pfc>(c), OK);
            assert_eq!(api::exit_initialization_mode::<Pfc>(c), OK);
            assert_eq!(api::do_step::<Pfc>(c, 0.0, 1e-3, 1), OK);
            // An error without a logger is still an error status.
            assert_eq!(api::do_step::<Pfc>(c, 5.0, 1e-3, 1), ERR);
            api::free_instance::<Pfc>(c);
        }
    }
    assert!(messages.lock().unwrap().iter().all(|m| !m.2.contains("NULL")), "no complaint about NULL callbacks");
}

/// Section 2.2.7 (setting rules) and the declared min/max: refused with name, value and range.
#[test]
fn bad_values_are_refused_with_name_value_and_range() {
    let s = Slave::<Pfc>::initialized("set", &[]);
    assert_eq!(s.set_real(vr::U_REF, f64::NAN), ERR);
    let e = s.last_error();
    assert!(e.contains("u_ref") && e.contains("NaN") && e.contains("[-1, 1]"), "{e}");
    assert_eq!(s.set_real(vr::U_REF, 1.5), ERR);
    // The dimensionless unit "1" is not written after the range.
    assert!(s.last_error().ends_with("u_ref = 1.5 is outside its valid range [-1, 1]"), "{}", s.last_error());
    assert_eq!(s.set_real(vr::K_F, -1e-12), ERR, "below min = 0");
    assert_eq!(s.set_real(999, 1.0), ERR);
    assert!(s.last_error().contains("999"));
    assert_eq!(s.set_real(vr::Q_RATED, 1e-3), ERR, "fixed parameter after initialisation");
    let e = s.last_error();
    assert!(e.contains("Q_rated") && e.contains("fixed"), "{e}");
    assert_eq!(s.set_real(vr::U, 0.1), ERR, "outputs are never set");
    let mut i = 0;
    assert_eq!(unsafe { api::get_integer::<Pfc>(s.c, &vr::U, 1, &mut i) }, ERR, "type mismatch");
    assert_eq!(unsafe { api::set_boolean::<Pfc>(s.c, &vr::ENABLE, 1, &7) }, ERR, "7 is no fmi2Boolean");
    assert_eq!(unsafe { api::get_real::<Pfc>(s.c, &vr::U, 1, std::ptr::null_mut()) }, ERR);
    assert!(s.last_error().contains("NULL"));
    // All or nothing: a batch with one bad value changes nothing.
    let (vrs, xs) = ([vr::U_REF, vr::K_F], [0.2, -1.0]);
    assert_eq!(unsafe { api::set_real::<Pfc>(s.c, vrs.as_ptr(), 2, xs.as_ptr()) }, ERR);
    assert_eq!(s.real(vr::U_REF), 0.0);
    // Still usable.
    assert_eq!(s.set_real(vr::U_REF, -0.1), OK);
    assert_eq!(s.step(0.0, 1e-3), OK);
    assert_eq!(s.real(vr::U), -0.1);
}

/// Section 4.2.2: doStep refuses h <= 0, a communication point that is not the instance time,
/// and a step past the stop time of fmi2SetupExperiment.
#[test]
fn do_step_checks_time() {
    let s = Slave::<Pfc>::new("time");
    assert_eq!(unsafe { api::setup_experiment::<Pfc>(s.c, 1, 1e-6, 0.0, 1, 0.01) }, OK);
    assert_eq!(unsafe { api::enter_initialization_mode::<Pfc>(s.c) }, OK);
    assert_eq!(unsafe { api::exit_initialization_mode::<Pfc>(s.c) }, OK);
    assert_eq!(s.step(0.0, -1e-3), ERR);
    assert_eq!(s.step(0.0, 0.0), ERR);
    assert_eq!(s.step(0.5, 1e-3), ERR);
    assert!(s.last_error().contains("currentCommunicationPoint"));
    assert_eq!(s.step(0.0, 0.005), OK);
    assert_eq!(s.step(0.005 + 1e-13, 0.005), OK, "rounding-level mismatch is accepted");
    assert_eq!(s.step(0.01, 0.001), ERR);
    assert!(s.last_error().contains("stop time"));
    let mut t = 0.0;
    assert_eq!(unsafe { api::get_real_status::<Pfc>(s.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) }, OK);
    assert!((t - 0.01).abs() < 1e-12, "{t}");
    let mut b = 1;
    assert_eq!(unsafe { api::get_boolean_status::<Pfc>(s.c, FMI2_TERMINATED, &mut b) }, OK);
    assert_eq!(b, FMI2_FALSE);
}

/// Section 2.1.8: an FMU state and its serialisation continue bit-exactly; corrupted bytes are
/// refused, never undefined behaviour.
#[test]
fn fmu_state_round_trips_and_corruption_is_refused() {
    let s = Slave::<Pfc>::initialized("state", &[(vr::P, 40e5), (vr::U_REF, -0.1)]);
    s.set_real(vr::P, 45e5);
    s.step(0.0, 1e-3);
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(unsafe { api::get_fmu_state::<Pfc>(s.c, &mut state) }, OK);
    let mut size = 0;
    assert_eq!(unsafe { api::serialized_fmu_state_size::<Pfc>(s.c, state, &mut size) }, OK);
    let mut bytes = vec![0 as fmi2Byte; size];
    assert_eq!(unsafe { api::serialize_fmu_state::<Pfc>(s.c, state, bytes.as_mut_ptr(), size) }, OK);
    let run = |s: &Slave<Pfc>| {
        (1..50)
            .map(|k| {
                s.set_real(vr::P, 45e5 - 1e4 * k as f64);
                s.step(k as f64 * 1e-3, 1e-3);
                s.real(vr::U)
            })
            .collect::<Vec<f64>>()
    };
    let reference = run(&s);
    assert_eq!(unsafe { api::set_fmu_state::<Pfc>(s.c, state) }, OK);
    assert_eq!(run(&s), reference, "get/set FMU state");
    let other = Slave::<Pfc>::new("restored");
    let mut restored: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(unsafe { api::deserialize_fmu_state::<Pfc>(other.c, bytes.as_ptr(), size, &mut restored) }, OK);
    assert_eq!(unsafe { api::set_fmu_state::<Pfc>(other.c, restored) }, OK);
    assert_eq!(run(&other), reference, "serialised state in another instance");
    // Every single flipped byte and every truncation is detected.
    let mut bad: fmi2FMUstate = std::ptr::null_mut();
    for i in 0..size {
        let mut b = bytes.clone();
        b[i] ^= 0x5a;
        assert_eq!(unsafe { api::deserialize_fmu_state::<Pfc>(s.c, b.as_ptr(), size, &mut bad) }, ERR, "byte {i}");
    }
    for n in [0, 1, 12, size / 2, size - 1] {
        assert_eq!(unsafe { api::deserialize_fmu_state::<Pfc>(s.c, bytes.as_ptr(), n, &mut bad) }, ERR, "length {n}");
    }
    assert!(bad.is_null());
    // A foreign pointer is not taken for a state.
    let junk = [0u64; 64];
    assert_eq!(unsafe { api::set_fmu_state::<Pfc>(s.c, junk.as_ptr() as fmi2FMUstate) }, ERR);
    for (c, mut st) in [(s.c, state), (other.c, restored)] {
        assert_eq!(unsafe { api::free_fmu_state::<Pfc>(c, &mut st) }, OK);
        assert!(st.is_null());
    }
}

/// Section 2.1.5: fmi2Reset returns to the instantiated state with start values.
#[test]
fn reset_restores_start_values() {
    let s = Slave::<Pfc>::initialized("reset", &[(vr::K_F, 3e-11)]);
    assert_eq!(s.real(vr::K_F), 3e-11);
    assert_eq!(unsafe { api::reset::<Pfc>(s.c) }, OK);
    assert_eq!(s.step(0.0, 1e-3), ERR, "back in Instantiated");
    assert_eq!(unsafe { api::enter_initialization_mode::<Pfc>(s.c) }, OK);
    assert_eq!(s.real(vr::K_F), 1.24e-11, "start value of Table 7.2");
}

/// Section 2.1.5: no categories = all; an unknown category is an error.
#[test]
fn debug_logging_categories() {
    let s = Slave::<Pfc>::initialized("log", &[]);
    let names = [CString::new("logFmiCalls").unwrap()];
    let ptrs: Vec<fmi2String> = names.iter().map(|n| n.as_ptr()).collect();
    assert_eq!(unsafe { api::set_debug_logging::<Pfc>(s.c, 1, 1, ptrs.as_ptr()) }, OK);
    s.take_messages();
    s.step(0.0, 1e-3);
    let m = s.take_messages();
    assert!(m.iter().any(|m| m.1 == "logFmiCalls" && m.2 == "fmi2DoStep"), "{m:?}");
    assert_eq!(unsafe { api::set_debug_logging::<Pfc>(s.c, 0, 0, std::ptr::null()) }, OK);
    s.take_messages();
    s.step(1e-3, 1e-3);
    assert!(s.take_messages().is_empty());
    let bad = [CString::new("logNothing").unwrap()];
    let ptrs: Vec<fmi2String> = bad.iter().map(|n| n.as_ptr()).collect();
    assert_eq!(unsafe { api::set_debug_logging::<Pfc>(s.c, 1, 1, ptrs.as_ptr()) }, ERR);
    assert!(s.last_error().contains("logNothing"), "errors are delivered even with logging off");
}

/// Principle 5: instances share nothing; two threads give the results of sequential runs.
#[test]
fn instances_in_threads_are_independent_and_deterministic() {
    let run = |k_f: f64| {
        let s = Slave::<Pfc>::initialized("thread", &[(vr::K_F, k_f), (vr::P, 50e5)]);
        (0..2000)
            .map(|k| {
                let t = k as f64 * 1e-3;
                s.set_real(vr::P, 50e5 + 5e5 * (20.0 * t).sin());
                s.step(t, 1e-3);
                s.real(vr::U_COMP)
            })
            .collect::<Vec<f64>>()
    };
    let (a, b) = (run(1e-11), run(4e-11));
    let threads = [1e-11, 4e-11].map(|k| std::thread::spawn(move || run(k)));
    let [ta, tb] = threads.map(|t| t.join().unwrap());
    assert_eq!((ta, tb), (a.clone(), b.clone()));
    // The compensation is linear in K_f: a second, independent check that nothing is shared.
    a.iter().zip(&b).for_each(|(x, y)| assert!((4.0 * x - y).abs() <= 1e-12 * y.abs().max(1e-12)));
}

/// A model that fails: panics at t >= 1 when `mode` = 1, gives up at t = 0.5 when `mode` = 2,
/// reports a NaN output after t = 0.5 when `mode` = 3 (a model evaluated outside its range).
#[derive(Clone)]
struct Faulty {
    mode: f64,
    t: f64,
}

impl Model for Faulty {
    const INFO: ModelInfo = ModelInfo { identifier: "Faulty", ..Pfc::INFO };
    const VARIABLES: &'static [Variable] = &[
        Variable::real_input("mode", 0, 0.0, "1", "", (0.0, 3.0), "failure mode"),
        Variable::real_output("y", 1, "1", "", ""),
    ];
    const STATES: &'static [ContinuousState] = &[];
    fn initialize(values: &Values) -> Result<Self, String> {
        Ok(Faulty { mode: values.real(0), t: 0.0 })
    }
    fn outputs(&self, values: &mut Values) {
        values.set_real(1, if self.mode == 3.0 && self.t > 0.5 { f64::NAN } else { self.mode })
    }
    type Ode = ();
    fn begin_step(&mut self, step: &StepStart<'_>, _: &mut dyn Log) -> Result<Step<'_, ()>, StepError> {
        let (t, h) = (step.t, step.h);
        self.t = t + h;
        match step.values.real(0) as i32 {
            1 if t + h >= 1.0 => panic!("model bug"),
            2 if t + h > 0.5 => Err(StepError { time: 0.5, message: "solver gave up".into() }),
            _ => Ok(Step::Done),
        }
    }
    fn scale(_: &()) -> Vec<f64> {
        Vec::new()
    }
    fn state(&self) -> &[f64] {
        &[]
    }
    fn restore(values: &Values, _: &[f64], _: &[f64]) -> Result<Self, String> {
        Self::initialize(values)
    }
    fn continuous_states(&self, _: &mut [f64]) {}
    fn set_continuous_states(&mut self, _: &[f64]) -> Result<(), String> {
        Ok(())
    }
    fn derivatives(&self, _: &Values, _: &mut [f64]) {}
}

/// A Faulty instance in failure `mode` whose first step, from 0 to `h`, returns fmi2OK and whose
/// second, from `h` to 2 `h`, returns `status`.
fn failed(name: &str, mode: f64, h: f64, status: fmi2Status) -> Slave<Faulty> {
    let s = Slave::<Faulty>::initialized(name, &[(0, mode)]);
    assert_eq!(s.step(0.0, h), OK);
    assert_eq!(s.step(h, h), status);
    s
}

/// After a failed step to t = 1: the Error state allows no step; fmi2Reset recovers.
fn reset_from_error(s: &Slave<Faulty>) {
    assert_eq!(s.step(1.0, 0.5), ERR, "the Error state allows no step");
    assert_eq!(unsafe { api::reset::<Faulty>(s.c) }, OK);
}

/// Principle 4: a panic becomes fmi2Error with a message and the Error state; fmi2Reset recovers.
#[test]
fn a_panic_is_caught_at_the_boundary() {
    let s = failed("panic", 1.0, 0.5, ERR);
    assert!(s.last_error().contains("model bug"), "{}", s.last_error());
    reset_from_error(&s);
}

/// Section 4.2.3: a step that cannot be completed returns fmi2Discard; fmi2LastSuccessfulTime
/// tells how far it got and fmi2Terminated that the slave wants to stop.
#[test]
fn a_failed_step_is_discarded_at_the_last_good_time() {
    let s = failed("discard", 2.0, 0.4, fmi2Status::Discard);
    let (mut t, mut b) = (0.0, 0);
    assert_eq!(unsafe { api::get_real_status::<Faulty>(s.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) }, OK);
    assert_eq!(t, 0.5);
    assert_eq!(unsafe { api::get_boolean_status::<Faulty>(s.c, FMI2_TERMINATED, &mut b) }, OK);
    assert_eq!(b, FMI2_TRUE);
    assert_eq!(s.step(0.5, 0.1), ERR, "stepFailed allows no further step");
    assert_eq!(unsafe { api::terminate::<Faulty>(s.c) }, OK);
}

/// Never a non-finite value after fmi2OK (issue 46): the step whose state has a non-finite
/// output returns fmi2Error naming the variable, its value and the time, whether or not the
/// master reads it, and leaves the instance in the Error state (FMI 2.0, 4.3.1: after fmi2Error
/// only fmi2Reset, fmi2FreeInstance and the getters are allowed); a get of the variable is
/// fmi2Error too, never the NaN with fmi2OK.
#[test]
fn a_step_to_a_non_finite_output_is_an_error_naming_it() {
    let s = failed("nan", 3.0, 0.5, ERR);
    let e = s.last_error();
    let named = e.contains("fmi2DoStep") && e.contains("y = NaN") && e.contains("t = 1");
    assert!(named && e.contains("Error state"), "{e}");
    let mut y = 0.0;
    assert_eq!(unsafe { api::get_real::<Faulty>(s.c, &1, 1, &mut y) }, ERR);
    assert!(s.last_error().contains("y = NaN"), "{}", s.last_error());
    reset_from_error(&s);
}
