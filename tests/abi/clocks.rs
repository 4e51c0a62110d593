//! The FMI 3.0 Clock of ClockedPressureFeedbackController through the C ABI (`fmi3::api`): the
//! sampled filter against its closed form, and the rules of FMI 3.0 for Clocks and clocked
//! variables (2.2.8 Clocks, 2.3.5 Event Mode), each test citing its rule.

use crate::fmi3_api::Inst;
use boomsim::control::FEEDBACK_PARAMS;
use boomsim::fmi2::api as api2;
use boomsim::fmi2::types::FMI2_MODEL_EXCHANGE;
use boomsim::fmi3::api;
use boomsim::fmi3::types::*;
use boomsim::fmu::guid::token;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::ClockedPressureFeedbackController as Cpfc;
use std::ffi::CString;
use std::ptr::null;

const OK: fmi3Status = fmi3Status::OK;
const ERR: fmi3Status = fmi3Status::Error;
/// The rig's loop period (thesis 4.2.2): the Clock's interval and its first activation.
const T: f64 = 5e-3;
/// fmi3IntervalUnchanged (fmi3FunctionTypes.h: NotYetKnown 0, Unchanged 1, Changed 2).
const UNCHANGED: fmi3IntervalQualifier = 1;

/// Initialised as Model Exchange with p = `p0` and u_ref = `u_ref`, in Continuous-Time Mode, with
/// (u, u_comp) as read in Initialization Mode.
fn start(p0: f64, u_ref: f64) -> (Inst<Cpfc>, (f64, f64)) {
    let i = Inst::<Cpfc>::new(true);
    let initial = unsafe {
        assert_eq!(api::enter_initialization_mode::<Cpfc>(i.c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!((i.set(vr::P, p0), i.set(vr::U_REF, u_ref)), (OK, OK));
        let initial = (i.get(vr::U), i.get(vr::U_COMP));
        assert_eq!(api::exit_initialization_mode::<Cpfc>(i.c), OK);
        initial
    };
    assert_eq!(update(&i), OK);
    assert_eq!(unsafe { api::enter_continuous_time_mode::<Cpfc>(i.c) }, OK);
    (i, initial)
}

fn running(p0: f64, u_ref: f64) -> Inst<Cpfc> {
    start(p0, u_ref).0
}

fn update(i: &Inst<Cpfc>) -> fmi3Status {
    let mut flags = [true; 5];
    let mut next = f64::NAN;
    let [a, b, c, d, e] = flags.each_mut().map(|f| f as *mut bool);
    unsafe { api::update_discrete_states::<Cpfc>(i.c, (a, b, c, d, e), &mut next) }
}

fn set_clock(i: &Inst<Cpfc>, active: bool) -> fmi3Status {
    unsafe { api::set_clock::<Cpfc>(i.c, &vr::SAMPLE, 1, &(active as u8)) }
}

fn clock(i: &Inst<Cpfc>) -> bool {
    let mut on = false;
    assert_eq!(unsafe { api::get_clock::<Cpfc>(i.c, &vr::SAMPLE, 1, &mut on) }, OK, "{}", i.last_error());
    on
}

/// From Continuous-Time Mode: Event Mode at `t`, the Clock activated, p set, Event Mode until
/// the caller ends the instant.
fn activate(i: &Inst<Cpfc>, t: f64, p: f64) {
    unsafe {
        assert_eq!(api::set_time::<Cpfc>(i.c, t), OK);
        assert_eq!(api::enter_event_mode::<Cpfc>(i.c), OK);
    }
    assert_eq!(set_clock(i, true), OK, "{}", i.last_error());
    assert_eq!(i.set(vr::P, p), OK, "{}", i.last_error());
}

/// An activation as an importer's time event: (u, u_comp) of the sample p at t.
fn tick(i: &Inst<Cpfc>, t: f64, p: f64) -> (f64, f64) {
    activate(i, t, p);
    let read = (i.get(vr::U), i.get(vr::U_COMP));
    assert_eq!(update(i), OK);
    assert_eq!(unsafe { api::enter_continuous_time_mode::<Cpfc>(i.c) }, OK);
    read
}

/// The module's discretisation is exact for p linear between samples, so at the activations the
/// sampled controller is the continuous filter of eq. 6.2: for a ramp of slope a from t0, the
/// high pass gives u_comp = K_f a / Q_rated (1 - e^(-omega_f (t - t0))), and after the ramp ends
/// at t1 that value decays with e^(-omega_f (t - t1)). Tolerance 1e-9 of the plateau: the filter
/// state (5e6 Pa, ulp 1e-9 Pa) rounded at each of 300 activations against p - x = a / omega_f
/// = 5.6e4 Pa.
#[test]
fn the_sampled_filter_is_the_continuous_filter_at_the_activations() {
    let (k_f, omega, q_rated) =
        (FEEDBACK_PARAMS[0].spec.default, FEEDBACK_PARAMS[1].spec.default, FEEDBACK_PARAMS[2].spec.default);
    let (p0, a, t0, t1, u_ref) = (50e5, 20e5, 0.5, 1.0, -0.05);
    let plateau = k_f * a / q_rated;
    let (i, initial) = start(p0, u_ref);
    assert_eq!(initial, (u_ref, 0.0), "at rest at the start");
    for k in 1..=300 {
        let t = k as f64 * T;
        let p = p0 + a * (t.clamp(t0, t1) - t0);
        let (u, u_comp) = tick(&i, t, p);
        let expected = match t {
            t if t <= t0 => 0.0,
            t if t <= t1 => plateau * -(-omega * (t - t0)).exp_m1(),
            t => plateau * -(-omega * (t1 - t0)).exp_m1() * (-omega * (t - t1)).exp(),
        };
        assert!((u_comp - expected).abs() <= 1e-9 * plateau, "t = {t}: u_comp {u_comp}, closed form {expected}");
        assert_eq!(u, u_ref + u_comp, "t = {t}: u = u_ref + u_comp within the limits");
    }
}

/// FMI 3.0, 2.2.8.3: "Clocked variables can acquire new values and can be queried only when their
/// Clock is active, except during Initialization Mode." Refused with a message naming the
/// variable and its Clock; accepted once fmi3SetClock activated it.
#[test]
fn clocked_variables_are_set_and_read_only_while_the_clock_is_active() {
    let i = running(50e5, -0.05);
    let mut u = f64::NAN;
    assert_eq!(unsafe { api::get_float64::<Cpfc>(i.c, &vr::U, 1, &mut u, 1) }, ERR, "u in Continuous-Time Mode");
    let m = i.last_error();
    assert!(m.contains("\"u\" is clocked by \"sample\", which is not active"), "{m}");
    let i = running(50e5, -0.05);
    unsafe { assert_eq!(api::enter_event_mode::<Cpfc>(i.c), OK) };
    assert_eq!(i.set(vr::P, 51e5), ERR, "p in Event Mode before the Clock is set");
    assert!(i.last_error().contains("\"p\" is clocked by \"sample\""), "{}", i.last_error());
    let i = running(50e5, -0.05);
    activate(&i, T, 51e5);
    assert!(i.get(vr::U).is_finite(), "u while the Clock is active");
    assert_eq!(i.set(vr::U_MIN, -0.9), OK, "an unclocked tunable parameter");
}

/// FMI 3.0, 2.3.5, fmi3SetClock: input Clocks are set in Event Mode; a Clock without
/// canBeDeactivated="true" cannot be set inactive; "Any Clock active during
/// fmi3UpdateDiscreteStates must be deactivated by the FMU itself".
#[test]
fn the_clock_is_activated_in_event_mode_and_deactivated_by_update_discrete_states() {
    let i = running(50e5, -0.05);
    assert_eq!(set_clock(&i, true), ERR, "fmi3SetClock in Continuous-Time Mode");
    assert!(i.last_error().contains("illegal call in state ContinuousTimeMode"), "{}", i.last_error());
    let i = running(50e5, -0.05);
    unsafe { assert_eq!(api::enter_event_mode::<Cpfc>(i.c), OK) };
    assert!(!clock(&i), "inactive before fmi3SetClock");
    assert_eq!(set_clock(&i, false), ERR, "deactivated by the importer");
    assert!(i.last_error().contains("canBeDeactivated=\"false\""), "{}", i.last_error());
    let i = running(50e5, -0.05);
    activate(&i, T, 51e5);
    assert!(clock(&i));
    assert_eq!(update(&i), OK);
    assert!(!clock(&i), "deactivated by fmi3UpdateDiscreteStates");
    let bad = 2u8;
    assert_eq!(unsafe { api::set_clock::<Cpfc>(i.c, &vr::SAMPLE, 1, &bad) }, ERR, "2 is no fmi3Clock");
}

/// FMI 3.0, 2.2.8.2: a constant periodic Clock ticks at t_i = t_start + shift + i interval; an
/// activation at another time (here 3.1 ms, and t = 0, before the first at 5 ms) is refused with
/// the times it has. And where the standard leaves the call open (2.3.5: each instant "concludes
/// with a call to fmi3UpdateDiscreteStates"), fmi3EnterContinuousTimeMode with the Clock still
/// active is refused, naming the missing call.
#[test]
fn the_clock_is_activated_at_its_times_and_its_instant_ends_with_update_discrete_states() {
    for t in [3.1e-3, 0.0] {
        let i = running(50e5, -0.05);
        unsafe {
            if t > 0.0 {
                assert_eq!(api::set_time::<Cpfc>(i.c, t), OK);
            }
            assert_eq!(api::enter_event_mode::<Cpfc>(i.c), OK);
        }
        assert_eq!(set_clock(&i, true), ERR, "t = {t}");
        assert!(i.last_error().contains("which is none of its times 0.005 + i 0.005 s"), "{}", i.last_error());
    }
    let i = running(50e5, -0.05);
    activate(&i, T, 51e5);
    assert_eq!(unsafe { api::enter_continuous_time_mode::<Cpfc>(i.c) }, ERR);
    assert!(i.last_error().contains("end the instant with fmi3UpdateDiscreteStates"), "{}", i.last_error());
}

/// FMI 3.0, 2.2.8.2 (constant Clock: intervalDecimal and shiftDecimal in the modelDescription;
/// fmi3GetInterval in Initialization and Event Mode, fmi3GetShift in Initialization Mode) and
/// 2.2.8.4 (a constant Clock's only qualifier is fmi3IntervalUnchanged): the rig's 5 ms, first
/// activation 5 ms after the start. The fraction variants are refused (supportsFraction="false"),
/// and so is setting a constant Clock's interval.
#[test]
fn the_interval_and_shift_are_the_constant_clocks() {
    let i = Inst::<Cpfc>::new(true);
    let (mut interval, mut qualifier, mut shift) = (f64::NAN, -1, f64::NAN);
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Cpfc>(i.c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!(api::get_interval_decimal::<Cpfc>(i.c, &vr::SAMPLE, 1, &mut interval, &mut qualifier), OK);
        assert_eq!((interval, qualifier), (T, UNCHANGED));
        assert_eq!(api::get_shift_decimal::<Cpfc>(i.c, &vr::SAMPLE, 1, &mut shift), OK);
        assert_eq!(shift, T);
        assert_eq!(
            api::get_interval_decimal::<Cpfc>(i.c, &vr::P, 1, &mut interval, &mut qualifier),
            ERR,
            "p is no Clock"
        );
        assert!(i.last_error().contains("\"p\" (vr 1) is a Float64, not a Clock"), "{}", i.last_error());
    }
    let i = running(50e5, -0.05);
    unsafe {
        assert_eq!(api::enter_event_mode::<Cpfc>(i.c), OK);
        assert_eq!(api::get_interval_decimal::<Cpfc>(i.c, &vr::SAMPLE, 1, &mut interval, &mut qualifier), OK);
        assert_eq!((interval, qualifier), (T, UNCHANGED));
        assert_eq!(
            api::get_shift_decimal::<Cpfc>(i.c, &vr::SAMPLE, 1, &mut shift),
            ERR,
            "the shift after initialisation"
        );
        for (f, why) in [("fmi3GetIntervalFraction", "supportsFraction"), ("fmi3SetIntervalDecimal", "constant")] {
            let j = running(50e5, -0.05);
            assert_eq!(api::clock_unsupported::<Cpfc>(j.c, f), ERR);
            assert!(j.last_error().starts_with(f) && j.last_error().contains(why), "{}", j.last_error());
        }
    }
}

/// FMI 3.0, 2.3.5: the importer may set a Clock's inputs again in the same instant (an algebraic
/// loop); the partition then starts from the previous values each time: the same command as an
/// instant that saw only the last value, bit for bit.
#[test]
fn an_instant_recomputed_with_new_inputs_starts_from_the_previous_values() {
    let (once, twice) = (running(50e5, -0.05), running(50e5, -0.05));
    for k in 1..=20 {
        let (t, p) = (k as f64 * T, 50e5 + 1e4 * (k * k) as f64);
        activate(&twice, t, p - 3e5);
        let _ = twice.get(vr::U);
        assert_eq!(twice.set(vr::P, p), OK);
        let again = (twice.get(vr::U), twice.get(vr::U_COMP), twice.get(vr::P_LP));
        assert_eq!(update(&twice), OK);
        unsafe { assert_eq!(api::enter_continuous_time_mode::<Cpfc>(twice.c), OK) };
        activate(&once, t, p);
        assert_eq!(again, (once.get(vr::U), once.get(vr::U_COMP), once.get(vr::P_LP)), "t = {t}");
        assert_eq!(update(&once), OK);
        unsafe { assert_eq!(api::enter_continuous_time_mode::<Cpfc>(once.c), OK) };
    }
}

/// FMI 2.0 has no Clocks, and FMI 3.0 Co-Simulation needs Event Mode for one (2.3.1: "For FMUs
/// that have clocks, eventModeUsed = fmi3True is required"): fmi2Instantiate and
/// fmi3InstantiateCoSimulation without eventModeUsed are refused with a message. An FMU state
/// taken between activations resumes bit for bit.
#[test]
fn fmi2_and_co_simulation_without_event_mode_are_refused_and_states_resume() {
    let e = Inst::<Cpfc>::try_new(false, &token::<Cpfc>(), (false, false)).err().expect("Co-Simulation refused");
    assert!(e.iter().any(|m| m.contains("eventModeUsed = false, but the FMU has a Clock")), "{e:?}");
    let messages = Box::new(crate::common::Messages::default());
    let callbacks = crate::common::callbacks(&messages);
    let (name, guid) = (CString::new("i2").unwrap(), CString::new(token::<Cpfc>()).unwrap());
    let c = unsafe {
        api2::instantiate::<Cpfc>(name.as_ptr(), FMI2_MODEL_EXCHANGE, guid.as_ptr(), null(), &callbacks, 0, 0)
    };
    assert!(c.is_null(), "fmi2Instantiate refused");
    assert!(messages.lock().unwrap().iter().any(|m| m.2.contains("is an FMI 3.0 FMU")), "{messages:?}");

    let i = running(50e5, -0.05);
    let ramp = |k: usize| 50e5 + 2e4 * k as f64;
    for k in 1..=10 {
        tick(&i, k as f64 * T, ramp(k));
    }
    let mut state = std::ptr::null_mut();
    assert_eq!(unsafe { api::get_fmu_state::<Cpfc>(i.c, &mut state) }, OK);
    let first: Vec<_> = (11..=20).map(|k| tick(&i, k as f64 * T, ramp(k))).collect();
    unsafe {
        assert_eq!(api::set_fmu_state::<Cpfc>(i.c, state), OK);
        assert_eq!(api::free_fmu_state::<Cpfc>(i.c, &mut state), OK);
    }
    let again: Vec<_> = (11..=20).map(|k| tick(&i, k as f64 * T, ramp(k))).collect();
    assert_eq!(first, again);
}

/// Co-Simulation with Event Mode (FMI 3.0, 4.2: initialisation ends in Event Mode;
/// fmi3EnterStepMode, fmi3DoStep to the activation, fmi3EnterEventMode, the Clock and its
/// variables, fmi3UpdateDiscreteStates): the commands of Model Exchange bit for bit (one model).
/// A step past an activation is refused naming it (the importer activates a time-based Clock at
/// its times, 2.2.8.2), and so is fmi3EnterStepMode before the instant ended (2.3.5).
#[test]
fn co_simulation_with_event_mode_gives_the_commands_of_model_exchange() {
    let me = running(50e5, -0.05);
    let cs = Inst::<Cpfc>::try_new(false, &token::<Cpfc>(), (true, false)).expect("Co-Simulation with Event Mode");
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Cpfc>(cs.c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!((cs.set(vr::P, 50e5), cs.set(vr::U_REF, -0.05)), (OK, OK));
        assert_eq!(api::exit_initialization_mode::<Cpfc>(cs.c), OK);
        assert!(!clock(&cs), "in Event Mode after initialisation");
        assert_eq!(update(&cs), OK);
        assert_eq!(api::enter_step_mode::<Cpfc>(cs.c), OK);
    }
    for k in 1..=40 {
        let (t, p) = (k as f64 * T, 50e5 + 1e4 * (k * k) as f64);
        assert_eq!(cs.step(t - T, T), OK, "{}", cs.last_error());
        unsafe { assert_eq!(api::enter_event_mode::<Cpfc>(cs.c), OK, "{}", cs.last_error()) };
        assert_eq!(set_clock(&cs, true), OK, "{}", cs.last_error());
        assert_eq!(cs.set(vr::P, p), OK);
        let read = (cs.get(vr::U), cs.get(vr::U_COMP));
        assert_eq!(update(&cs), OK);
        unsafe { assert_eq!(api::enter_step_mode::<Cpfc>(cs.c), OK) };
        assert_eq!(read, tick(&me, t, p), "t = {t}");
    }
    assert_eq!(cs.step(40.0 * T, 1.5 * T), ERR, "past the activation at 41 T");
    assert!(cs.last_error().contains("would pass the Clock's activation at t = 0.205"), "{}", cs.last_error());
    let cs = Inst::<Cpfc>::try_new(false, &token::<Cpfc>(), (true, false)).unwrap();
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Cpfc>(cs.c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!(api::exit_initialization_mode::<Cpfc>(cs.c), OK);
        assert_eq!(update(&cs), OK);
        assert_eq!(api::enter_step_mode::<Cpfc>(cs.c), OK);
        assert_eq!(cs.step(0.0, T), OK);
        assert_eq!(api::enter_event_mode::<Cpfc>(cs.c), OK);
        assert_eq!(set_clock(&cs, true), OK);
        assert_eq!(api::enter_step_mode::<Cpfc>(cs.c), ERR, "the instant has not ended");
    }
    assert!(cs.last_error().contains("end the instant with fmi3UpdateDiscreteStates"), "{}", cs.last_error());
}

/// A Co-Simulation instance with Event Mode in Step Mode at t = 0, p = 50 bar, u_ref = -0.05.
fn stepping() -> Inst<Cpfc> {
    let cs = Inst::<Cpfc>::try_new(false, &token::<Cpfc>(), (true, false)).expect("Co-Simulation with Event Mode");
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Cpfc>(cs.c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!((cs.set(vr::P, 50e5), cs.set(vr::U_REF, -0.05)), (OK, OK));
        assert_eq!(api::exit_initialization_mode::<Cpfc>(cs.c), OK);
        assert_eq!(update(&cs), OK);
        assert_eq!(api::enter_step_mode::<Cpfc>(cs.c), OK);
    }
    cs
}

/// Issue 46, rule 4: a skipped activation is refused. FMI 3.0, 2.2.8.2: the importer activates
/// a periodic Clock at each of its times t_i = t_start + shift + i interval (here 5 ms, 10 ms,
/// ...). In Co-Simulation a doStep to 5 ms is fine, a further doStep from there without the
/// activation is fmi3Error naming it; in Model Exchange fmi3SetTime past 5 ms is; a state that
/// claims a time past an activation not made (forged) cannot activate the next one. (Before the
/// rule the next activation advanced the filter by 5 ms although 10 ms had passed: u_comp 9 %
/// off.) fmi3Error leaves the instance Terminated (2.3.1).
#[test]
fn a_skipped_activation_is_refused() {
    let cs = stepping();
    assert_eq!(cs.step(0.0, T), OK, "to the first activation");
    assert_eq!(cs.step(T, T), ERR, "on without activating the Clock");
    let e = cs.last_error();
    assert!(e.contains("skip activation 1 of Clock \"sample\" at t = 0.005") && e.contains("2.2.8.2"), "{e}");

    let me = running(50e5, -0.05);
    unsafe {
        assert_eq!(api::set_time::<Cpfc>(me.c, 0.004), OK, "before the activation");
        assert_eq!(api::set_time::<Cpfc>(me.c, T), OK, "on it");
        assert_eq!(api::set_time::<Cpfc>(me.c, 0.007), ERR, "past it");
    }
    assert!(me.last_error().contains("time = 0.007 would skip activation 1"), "{}", me.last_error());

    let me = running(50e5, -0.05);
    let mut forged = crate::fmi3_api::serialize(&me);
    let at = crate::common::time_offset(&forged);
    crate::common::forge(&mut forged, at, 2.0 * T);
    unsafe {
        let mut s = std::ptr::null_mut();
        assert_eq!(api::deserialize_fmu_state::<Cpfc>(me.c, forged.as_ptr(), forged.len(), &mut s), OK);
        assert_eq!(api::set_fmu_state::<Cpfc>(me.c, s), OK, "{}", me.last_error());
        assert_eq!(api::free_fmu_state::<Cpfc>(me.c, &mut s), OK);
    }
    unsafe { assert_eq!(api::enter_event_mode::<Cpfc>(me.c), OK) };
    assert_eq!(set_clock(&me, true), ERR, "activation 2 before activation 1");
    assert!(me.last_error().contains("skip activation 1"), "{}", me.last_error());
}

/// Issue 46, rule 5: a double activation is refused. FMI 3.0, 2.2.8.2: a periodic Clock is
/// activated once at each of its times. A second fmi3SetClock after fmi3UpdateDiscreteStates
/// ended the instant, in the same Event Mode or in a second Event Mode at the same time, would
/// advance the filter again (u_comp 0.0829 instead of 0.0896 at 10 ms): fmi3Error naming the
/// rule. Set again while still active, in the same instant, it is the same activation: the
/// command is that of one activation, bit for bit.
#[test]
fn a_double_activation_is_refused() {
    for second_event_mode in [false, true] {
        let me = running(50e5, -0.05);
        if second_event_mode {
            tick(&me, T, 50.5e5);
            unsafe { assert_eq!(api::enter_event_mode::<Cpfc>(me.c), OK) };
        } else {
            activate(&me, T, 50.5e5);
            assert_eq!(update(&me), OK);
        }
        assert_eq!(set_clock(&me, true), ERR, "a second activation at 5 ms");
        let e = me.last_error();
        assert!(e.contains("was activated at t = 0.005 already") && e.contains("2.2.8.2"), "{e}");
    }
    let (once, twice) = (running(50e5, -0.05), running(50e5, -0.05));
    activate(&once, T, 50.5e5);
    activate(&twice, T, 50.5e5);
    assert_eq!(set_clock(&twice, true), OK, "set again in the same instant");
    assert_eq!(twice.get(vr::U_COMP).to_bits(), once.get(vr::U_COMP).to_bits());
    assert_eq!((update(&once), update(&twice)), (OK, OK));
    unsafe {
        assert_eq!(api::enter_continuous_time_mode::<Cpfc>(once.c), OK);
        assert_eq!(api::enter_continuous_time_mode::<Cpfc>(twice.c), OK);
    }
    assert_eq!(tick(&twice, 2.0 * T, 51e5), tick(&once, 2.0 * T, 51e5), "the next activation alike");
}

/// Found by the fuzzer (examples/fuzz/regressions.txt): far from t = 0 the Clock's times are as
/// strict. With startTime 1e6 s (or 1e9 s) a step past the first activation at start + 5 ms was
/// accepted (the step-time tolerance, relative to the time, was 1 ms there, 1 s at 1e9); an
/// activation is now matched within 1e-6 of the interval or four ulps of its time, whichever is
/// more, and an activation at its time is accepted there too.
#[test]
fn the_clock_is_as_strict_far_from_time_zero() {
    for start in [1e6, 1e9] {
        let cs = stepping_from(start);
        assert_eq!(cs.step(start, 0.0058), ERR, "start {start}: past the activation at start + 5 ms");
        assert!(cs.last_error().contains("would pass the Clock's activation"), "{}", cs.last_error());
        let cs = stepping_from(start);
        assert_eq!(cs.step(start, T), OK, "start {start}: to the activation");
        unsafe { assert_eq!(api::enter_event_mode::<Cpfc>(cs.c), OK) };
        assert_eq!(set_clock(&cs, true), OK, "start {start}: {}", cs.last_error());
    }
}

/// [`stepping`] from `start`.
fn stepping_from(start: f64) -> Inst<Cpfc> {
    let cs = Inst::<Cpfc>::try_new(false, &token::<Cpfc>(), (true, false)).unwrap();
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Cpfc>(cs.c, false, 0.0, start, false, 0.0), OK);
        assert_eq!(api::exit_initialization_mode::<Cpfc>(cs.c), OK);
        assert_eq!(update(&cs), OK);
        assert_eq!(api::enter_step_mode::<Cpfc>(cs.c), OK);
    }
    cs
}
