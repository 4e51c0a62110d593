//! Early return and Event Mode of the plants in FMI 3.0 Co-Simulation through the C ABI: a step
//! ends at the first root of an event indicator (4.2.3: `earlyReturn`, `lastSuccessfulTime`,
//! `eventHandlingNeeded`) and the importer handles the event in Event Mode (4.2.2), each test
//! citing its rule.

use crate::fmi3_api::Inst;
use boomsim::fmi3::api;
use boomsim::fmi3::types::*;
use boomsim::fmu::guid::token;
use boomsim::hydraulics::circuit::Circuit;
use boomsim::models::vr;
use boomsim::models::{BoomMechanics, HydraulicBoom as Hb, PressureFeedbackController as Pfc};

const OK: fmi3Status = fmi3Status::OK;
/// The communication step of the runs below, and the fine one that brackets events.
const H: f64 = 0.01;
const FINE: f64 = 1e-4;
/// The lowering command: the spool leaves the closed dead band once, through x_v = -x_db.
const U_REF: f64 = -0.3;

/// The event indicators (u_ref, x_v - x_db, x_v + x_db), as locals.
fn indicators(i: &Inst<Hb>) -> [f64; 3] {
    [vr::EVENT_U_REF, vr::EVENT_DEAD_BAND_UPPER, vr::EVENT_DEAD_BAND_LOWER].map(|r| i.get(r))
}

/// HydraulicBoom instantiated for Co-Simulation with (eventModeUsed, earlyReturnAllowed),
/// initialised (stop time 1 s), in Step Mode with u_ref set.
fn lowering(modes: (bool, bool)) -> Inst<Hb> {
    let i = Inst::<Hb>::try_new(false, &token::<Hb>(), modes).expect("instantiated");
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Hb>(i.c, false, 0.0, 0.0, true, 1.0), OK);
        assert_eq!(api::exit_initialization_mode::<Hb>(i.c), OK);
        if modes.0 {
            // 4.2.2: with eventModeUsed, initialisation ends in Event Mode.
            assert_eq!(update(&i), [false; 5]);
            assert_eq!(api::enter_step_mode::<Hb>(i.c), OK, "{}", i.last_error());
        }
    }
    assert_eq!(i.set(vr::U_REF, U_REF), OK);
    i
}

/// fmi3UpdateDiscreteStates' flags (discreteStatesNeedUpdate, terminateSimulation, nominals and
/// values of the continuous states changed, nextEventTimeDefined).
fn update(i: &Inst<Hb>) -> [bool; 5] {
    let mut flags = [true; 5];
    let mut next = f64::NAN;
    let [a, b, c, d, e] = flags.each_mut().map(|f| f as *mut bool);
    assert_eq!(unsafe { api::update_discrete_states::<Hb>(i.c, (a, b, c, d, e), &mut next) }, OK);
    flags
}

/// fmi3DoStep's status and out-arguments (eventHandlingNeeded, earlyReturn, lastSuccessfulTime).
fn step(i: &Inst<Hb>, t: f64, h: f64) -> (fmi3Status, bool, bool, f64) {
    let (mut event, mut term, mut early, mut last) = (true, true, true, f64::NAN);
    let status = unsafe { api::do_step::<Hb>(i.c, t, h, true, (&mut event, &mut term, &mut early), &mut last) };
    assert!(!term, "terminateSimulation");
    (status, event, early, last)
}

/// Runs to `stop` by `H` with the given modes; returns the times of the early returns and p3 at
/// the end. Each early return is checked as it happens (4.2.3): it ends before t + h and after
/// t, `eventHandlingNeeded` is set exactly when the importer uses Event Mode, the indicator that
/// changed sign is 0 there (the root: within 1e-9 of the dead band, far below its 0.8 mm), the
/// next step starts at lastSuccessfulTime, and Event Mode's
/// fmi3UpdateDiscreteStates has nothing to update (the plant has no discrete states).
fn run(modes: (bool, bool), stop: f64) -> (Vec<f64>, f64) {
    let i = lowering(modes);
    let x_db = Circuit::default().dcv.x_db;
    // The communication points k H, and the early returns between them (as fmusim steps).
    let (mut t, mut k, mut events) = (0.0, 0, Vec::new());
    while k < (stop / H).round() as usize {
        let before = indicators(&i);
        let next = (k + 1) as f64 * H;
        let (status, event, early, last) = step(&i, t, next - t);
        assert_eq!(status, OK, "{}", i.last_error());
        assert_eq!(event, early && modes.0, "eventHandlingNeeded at t = {t}");
        if !early {
            assert_eq!(last, next);
            (t, k) = (next, k + 1);
            continue;
        }
        assert!(modes.1, "earlyReturn without earlyReturnAllowed");
        assert!(last > t && last < next, "lastSuccessfulTime {last} within ({t}, {next})");
        let after = indicators(&i);
        let changed: Vec<usize> = (0..3).filter(|&k| before[k] * after[k] <= 0.0 && before[k] != 0.0).collect();
        assert_eq!(changed.len(), 1, "one indicator changed sign: {before:?} -> {after:?}");
        assert!(after[changed[0]].abs() < 1e-9 * x_db, "at its root: {after:?}");
        if modes.0 {
            unsafe { assert_eq!(api::enter_event_mode::<Hb>(i.c), OK, "{}", i.last_error()) };
            assert_eq!(update(&i), [false; 5], "nothing to update, no next event time");
            unsafe { assert_eq!(api::enter_step_mode::<Hb>(i.c), OK, "{}", i.last_error()) };
        }
        events.push(last);
        t = last;
    }
    (events, i.get(vr::P3))
}

/// 4.2.3: with earlyReturnAllowed and eventModeUsed, the lowering command's run returns early
/// once, where the spool leaves the closed dead band (x_v + x_db = 0); the time lies in the
/// 0.1 ms interval where a run without early return, stepped by 0.1 ms, sees that indicator
/// change sign (a second run that only samples the indicator).
#[test]
fn a_step_ends_where_the_spool_leaves_the_dead_band() {
    let (events, _) = run((true, true), 0.2);
    assert_eq!(events.len(), 1, "{events:?}");
    let fine = Inst::<Hb>::initialized(false, &[(vr::U_REF, U_REF)]);
    let mut t = 0.0;
    let mut before = indicators(&fine);
    let bracket = loop {
        assert_eq!(fine.step(t, FINE), OK);
        let after = indicators(&fine);
        if before[2] * after[2] <= 0.0 {
            break (t, t + FINE);
        }
        (t, before) = (t + FINE, after);
        assert!(t < 0.2, "no sign change");
    };
    assert!(bracket.0 <= events[0] && events[0] <= bracket.1, "{events:?} outside {bracket:?}");
}

/// 4.2.3: earlyReturn only with earlyReturnAllowed, eventHandlingNeeded only with eventModeUsed
/// (an early return without it is the FMU's request for a communication point); the same event
/// time either way. Ending a step at the event does not change the physics: p3 after 0.2 s equals
/// that of a run without early return within 1e-6 relative (both runs solve the same equations
/// at rtol 1e-6, with step sequences that differ from the event on; measured 1.3e-9).
#[test]
fn early_return_needs_its_flag_and_event_handling_needs_event_mode() {
    let (with_event_mode, p3) = run((true, true), 0.2);
    let (without_event_mode, _) = run((false, true), 0.2);
    assert_eq!(with_event_mode, without_event_mode);
    for modes in [(false, false), (true, false)] {
        let (events, p3_plain) = run(modes, 0.2);
        assert!(events.is_empty(), "{modes:?}: {events:?}");
        assert!((p3 - p3_plain).abs() < 1e-6 * p3.abs(), "p3 {p3} vs {p3_plain}");
    }
}

/// 4.4 (hasEventMode="false"): the models without event indicators or Clock refuse eventModeUsed.
#[test]
fn models_without_events_refuse_event_mode() {
    let e = Inst::<BoomMechanics>::try_new(false, &token::<BoomMechanics>(), (true, true)).err().expect("refused");
    assert!(e.iter().any(|m| m.contains("eventModeUsed") && m.contains("hasEventMode")), "{e:?}");
    assert!(Inst::<Pfc>::try_new(false, &token::<Pfc>(), (false, true)).is_ok(), "earlyReturnAllowed is accepted");
}

/// The bytes of an FMU state of `i` taken now (fmi3GetFMUState, fmi3SerializeFMUState).
fn serialized(i: &Inst<Hb>) -> Vec<u8> {
    let mut state = std::ptr::null_mut();
    let mut size = 0;
    unsafe {
        assert_eq!(api::get_fmu_state::<Hb>(i.c, &mut state), OK);
        assert_eq!(api::serialized_fmu_state_size::<Hb>(i.c, state, &mut size), OK);
        let mut bytes = vec![0u8; size];
        assert_eq!(api::serialize_fmu_state::<Hb>(i.c, state, bytes.as_mut_ptr(), size), OK);
        assert_eq!(api::free_fmu_state::<Hb>(i.c, &mut state), OK);
        bytes
    }
}

/// fmi3DeserializeFMUState of a state fmi3SerializeFMUState gave (FMI 3.0, 2.2.4): a Co-Simulation
/// instance with Event Mode restores one saved in Event Mode (found by the fuzzer: it was refused
/// as a Model Exchange state), and one without Event Mode refuses it, naming why.
#[test]
fn fmu_states_saved_in_event_mode_restore_with_event_mode_only() {
    let with = Inst::<Hb>::try_new(false, &token::<Hb>(), (true, true)).expect("instantiated");
    unsafe {
        assert_eq!(api::enter_initialization_mode::<Hb>(with.c, false, 0.0, 0.0, false, 0.0), OK);
        assert_eq!(api::exit_initialization_mode::<Hb>(with.c), OK);
    }
    let bytes = serialized(&with);
    let mut state = std::ptr::null_mut();
    unsafe {
        assert_eq!(api::deserialize_fmu_state::<Hb>(with.c, bytes.as_ptr(), bytes.len(), &mut state), OK);
        assert_eq!(api::set_fmu_state::<Hb>(with.c, state), OK);
        assert_eq!(api::free_fmu_state::<Hb>(with.c, &mut state), OK);
        assert_eq!(update(&with), [false; 5], "restored in Event Mode");
    }
    let without = Inst::<Hb>::try_new(false, &token::<Hb>(), (false, false)).expect("instantiated");
    let status = unsafe { api::deserialize_fmu_state::<Hb>(without.c, bytes.as_ptr(), bytes.len(), &mut state) };
    assert_eq!(status, fmi3Status::Error);
    assert!(without.last_error().contains("no Event Mode (eventModeUsed = false)"), "{}", without.last_error());
}
