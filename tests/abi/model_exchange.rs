//! FMI 2.0 Model Exchange: the state machine of section 3.2.3 (every ME function in every
//! state), the interfaces kept apart, the derivatives against the laws they implement and
//! against the Co-Simulation trajectory, and the fixed state layout of the boom.

use crate::common;

use boomsim::fmi2::api;
use boomsim::fmi2::types::*;
use boomsim::fmu::Model;
use boomsim::hydraulics::circuit::{N_STATES as C, P4, X_V};
use boomsim::models::pressure_feedback_controller::vr as pfc;
use boomsim::models::{vr, BoomMechanics, HydraulicBoom, HydraulicCircuit, PressureFeedbackController as Pfc};
use crate::common::Slave;
use std::os::raw::c_int;

const OK: fmi2Status = fmi2Status::OK;
const ERR: fmi2Status = fmi2Status::Error;

/// A Model Exchange instance of `M`.
fn model<M: Model>(name: &str) -> Slave<M> {
    Slave::<M>::try_new(name, &boomsim::fmu::guid::guid::<M>(), FMI2_MODEL_EXCHANGE).expect("instantiates")
}

/// A HydraulicBoom ME instance set up at t = 0, in Initialization Mode.
unsafe fn plant_initializing(name: &str) -> Slave<HydraulicBoom> {
    let s = model::<HydraulicBoom>(name);
    assert_eq!(api::setup_experiment::<HydraulicBoom>(s.c, 0, 0.0, 0.0, 0, 0.0), OK);
    assert_eq!(api::enter_initialization_mode::<HydraulicBoom>(s.c), OK);
    s
}

/// The states an ME instance reaches, in order, with the calls that lead there from the previous.
#[derive(Debug, Clone, Copy, PartialEq)]
enum St {
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
}
const STATES: [St; 5] =
    [St::Instantiated, St::InitializationMode, St::EventMode, St::ContinuousTimeMode, St::Terminated];

/// A controller ME instance driven to `st` (Terminated: from Event Mode).
fn at(st: St) -> Slave<Pfc> {
    let s = model::<Pfc>("me");
    let c = s.c;
    unsafe {
        if st == St::Instantiated {
            return s;
        }
        assert_eq!(api::setup_experiment::<Pfc>(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(api::enter_initialization_mode::<Pfc>(c), OK);
        if st == St::InitializationMode {
            return s;
        }
        assert_eq!(api::exit_initialization_mode::<Pfc>(c), OK);
        match st {
            St::ContinuousTimeMode => assert_eq!(api::enter_continuous_time_mode::<Pfc>(c), OK),
            St::Terminated => assert_eq!(api::terminate::<Pfc>(c), OK),
            _ => {}
        }
    }
    s
}

type Call = fn(fmi2Component) -> fmi2Status;

/// The ten ME functions and the states the standard's table (FMI 2.0.5, section 3.2.3, with
/// the 2.0.1 to 2.0.3 errata) allows them in, written from the standard independently of
/// `src/fmi2/machine.rs`: fmi2SetTime in Event Mode only for a pure discrete-time FMU (note 8);
/// fmi2GetDerivatives and fmi2GetNominalsOfContinuousStates in Initialization Mode too.
#[rustfmt::skip]
fn me_functions() -> Vec<(&'static str, Call, &'static [St])> {
    use St::*;
    vec![
        ("fmi2EnterEventMode", |c| unsafe { api::enter_event_mode::<Pfc>(c) }, &[EventMode, ContinuousTimeMode]),
        ("fmi2NewDiscreteStates", |c| unsafe { api::new_discrete_states::<Pfc>(c, &mut fmi2EventInfo::default()) }, &[EventMode]),
        ("fmi2EnterContinuousTimeMode", |c| unsafe { api::enter_continuous_time_mode::<Pfc>(c) }, &[EventMode]),
        ("fmi2CompletedIntegratorStep", |c| unsafe {
            let (mut e, mut t) = (0 as c_int, 0 as c_int);
            api::completed_integrator_step::<Pfc>(c, 1, &mut e, &mut t)
        }, &[ContinuousTimeMode]),
        ("fmi2SetTime", |c| unsafe { api::set_time::<Pfc>(c, 0.5) }, &[ContinuousTimeMode]),
        ("fmi2SetContinuousStates", |c| unsafe { api::set_continuous_states::<Pfc>(c, &1e5, 1) }, &[ContinuousTimeMode]),
        ("fmi2GetDerivatives", |c| unsafe { api::get_derivatives::<Pfc>(c, &mut 0.0, 1) },
            &[InitializationMode, EventMode, ContinuousTimeMode, Terminated]),
        ("fmi2GetEventIndicators", |c| unsafe { api::get_event_indicators::<Pfc>(c, std::ptr::null_mut(), 0) },
            &[InitializationMode, EventMode, ContinuousTimeMode, Terminated]),
        ("fmi2GetContinuousStates", |c| unsafe { api::get_continuous_states::<Pfc>(c, &mut 0.0, 1) },
            &[InitializationMode, EventMode, ContinuousTimeMode, Terminated]),
        ("fmi2GetNominalsOfContinuousStates", |c| unsafe { api::get_nominals_of_continuous_states::<Pfc>(c, &mut 0.0, 1) },
            &[Instantiated, InitializationMode, EventMode, ContinuousTimeMode, Terminated]),
    ]
}

/// Every ME function in every state: legal calls succeed, illegal ones return fmi2Error with a
/// message naming the state and where the call is allowed.
#[test]
fn the_state_machine_refuses_every_illegal_call_with_a_reason() {
    for (name, call, legal) in me_functions() {
        for st in STATES {
            let s = at(st);
            let status = call(s.c);
            if legal.contains(&st) {
                assert_eq!(status, OK, "{name} in {st:?}: {:?}", s.take_messages());
            } else {
                assert_eq!(status, ERR, "{name} in {st:?} must be refused");
                let e = s.last_error();
                assert!(e.contains(name) && e.contains(&format!("illegal call in state {st:?}")), "{name}: {e}");
            }
        }
    }
}

/// An instance is one interface: Co-Simulation functions on an ME instance and ME functions on a
/// CS instance are refused, naming both.
#[test]
fn the_interfaces_are_kept_apart() {
    let me = at(St::EventMode);
    assert_eq!(me.step(0.0, 1e-3), ERR);
    assert!(me.last_error().contains("a CoSimulation function") && me.last_error().contains("ModelExchange"));
    assert_eq!(me.set_slope(pfc::P, 1.0), ERR, "fmi2SetRealInputDerivatives is Co-Simulation only");
    let cs = Slave::<Pfc>::initialized("cs", &[]);
    assert_eq!(unsafe { api::get_derivatives::<Pfc>(cs.c, &mut 0.0, 1) }, ERR);
    assert!(cs.last_error().contains("a ModelExchange function"), "{}", cs.last_error());
    assert_eq!(unsafe { api::set_time::<Pfc>(cs.c, 0.0) }, ERR);
}

/// Wrong counts, NULL arrays and non-finite states and times are refused with a reason, without
/// touching the instance.
#[test]
fn wrong_state_vectors_are_refused() {
    let s = at(St::ContinuousTimeMode);
    let x = [1.0, 2.0];
    assert_eq!(unsafe { api::set_continuous_states::<Pfc>(s.c, x.as_ptr(), 2) }, ERR);
    assert!(s.last_error().contains("nx = 2") && s.last_error().contains("has 1"), "{}", s.last_error());
    assert_eq!(unsafe { api::set_continuous_states::<Pfc>(s.c, &f64::NAN, 1) }, ERR);
    assert!(s.last_error().contains("filter.p_lp = NaN"), "{}", s.last_error());
    assert_eq!(unsafe { api::get_event_indicators::<Pfc>(s.c, &mut 0.0, 1) }, ERR, "no event indicators");
    assert!(s.last_error().contains("ni = 1, but PressureFeedbackController has 0 event indicators"));
    let null = std::ptr::null_mut();
    unsafe {
        assert_eq!(api::get_derivatives::<Pfc>(s.c, null, 1), ERR);
        assert!(s.last_error().contains("derivatives is NULL"), "{}", s.last_error());
        assert_eq!(api::get_continuous_states::<Pfc>(s.c, null, 1), ERR);
        assert_eq!(api::set_continuous_states::<Pfc>(s.c, null, 1), ERR);
        assert_eq!(api::get_nominals_of_continuous_states::<Pfc>(s.c, null, 1), ERR);
        assert_eq!(api::completed_integrator_step::<Pfc>(s.c, 1, std::ptr::null_mut(), std::ptr::null_mut()), ERR);
        assert_eq!(api::set_time::<Pfc>(s.c, f64::NAN), ERR);
        assert!(s.last_error().contains("time = NaN is outside its valid range [0, inf)"), "{}", s.last_error());
        // FMI 3.0, 3.2.1 (fmi3SetTime): not before the start time; FMI 2.0 alike (no state exists there).
        assert_eq!(api::set_time::<Pfc>(s.c, -1e-3), ERR);
        assert!(s.last_error().contains("time = -0.001 is outside its valid range [0, inf)"), "{}", s.last_error());
        assert_eq!(api::enter_event_mode::<Pfc>(s.c), OK);
        assert_eq!(api::new_discrete_states::<Pfc>(s.c, std::ptr::null_mut()), ERR);
        assert_eq!(api::enter_continuous_time_mode::<Pfc>(s.c), OK, "still usable");
    }
    assert_eq!(s.real(pfc::P_LP), 0.0, "the filter state is the start value's rest state");
}

/// The controller's derivative is the filter law x' = omega_f (p - x) of eq. 6.2 (omega_f from
/// the FMU's own parameter), and u follows u_ref + K_f omega_f (p - x) / Q_rated.
#[test]
fn controller_derivative_is_the_filter_law() {
    let s = model::<Pfc>("filter");
    let c = s.c;
    unsafe {
        assert_eq!(api::setup_experiment::<Pfc>(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(api::enter_initialization_mode::<Pfc>(c), OK);
        assert_eq!(s.set_real(pfc::P, 50e5), OK);
        assert_eq!(api::exit_initialization_mode::<Pfc>(c), OK);
        assert_eq!(api::enter_continuous_time_mode::<Pfc>(c), OK);
        let mut x = 0.0;
        assert_eq!(api::get_continuous_states::<Pfc>(c, &mut x, 1), OK);
        assert_eq!(x, 50e5, "the filter starts at rest at p");
        assert_eq!(api::set_continuous_states::<Pfc>(c, &40e5, 1), OK);
        let mut dx = 0.0;
        assert_eq!(api::get_derivatives::<Pfc>(c, &mut dx, 1), OK);
        let (omega_f, k_f, q_rated) = (s.real(pfc::OMEGA_F), s.real(pfc::K_F), s.real(pfc::Q_RATED));
        assert!((dx - omega_f * 10e5).abs() <= 1e-12 * dx.abs(), "{dx}");
        assert_eq!(s.real(pfc::DER_P_LP), dx, "der(filter.p_lp) reads the derivative");
        let u_comp = k_f * omega_f * 10e5 / q_rated;
        assert!((s.real(pfc::U_COMP) - u_comp).abs() <= 1e-12 * u_comp.abs());
    }
}

/// A Co-Simulation run of model `M` (rtol 1e-12) with the input `u` from rest; at a few times
/// the `der()` variables written after a step are checked against a second-order forward
/// difference of their states over two further steps of 1 us. The CS solver integrates the
/// model's own coordinates (for the rigid boom the stroke), so this checks the ME derivatives and
/// the change of coordinates against a second integration. Bound: truncation (1 us / tau)^2 for
/// the fastest time constant tau ~ 0.1 ms of the compensator gives 1e-4 of the derivative; the
/// solver's error at rtol 1e-12 and round-off over 1 us give 1e-6 x nominal per second.
fn check_derivatives_along_cs_run<M: Model>(flexible: Option<bool>, u: (u32, f64)) {
    let s = Slave::<M>::new("cs");
    unsafe {
        assert_eq!(api::setup_experiment::<M>(s.c, 1, 1e-12, 0.0, 0, 0.0), OK);
        assert_eq!(api::enter_initialization_mode::<M>(s.c), OK);
        if let Some(f) = flexible {
            assert_eq!(s.set_boolean(vr::FLEXIBLE, f), OK);
        }
        assert_eq!(api::exit_initialization_mode::<M>(s.c), OK);
    }
    assert_eq!(s.set_real(u.0, u.1), OK);
    let read = |s: &Slave<M>| -> Vec<(f64, f64)> {
        M::STATES.iter().map(|st| (s.real(st.state), s.real(st.derivative))).collect()
    };
    let (mut t, h, d) = (0.0, 1e-3, 1e-6);
    let mut worst = (0.0, "", 0.0);
    for checkpoint in [0.05, 0.15, 0.25, 0.35] {
        while t < checkpoint - 1e-9 {
            assert_eq!(s.step(t, h), OK);
            t += h;
        }
        let r0 = read(&s);
        let mut rows = vec![r0];
        for _ in 0..2 {
            assert_eq!(s.step(t, d), OK);
            t += d;
            rows.push(read(&s));
        }
        for (i, st) in M::STATES.iter().enumerate() {
            let fd = (-3.0 * rows[0][i].0 + 4.0 * rows[1][i].0 - rows[2][i].0) / (2.0 * d);
            let der = rows[0][i].1;
            let err = (fd - der).abs() / (1e-4 * der.abs() + 1e-6 * st.nominal);
            if err > worst.0 {
                worst = (err, M::VARIABLES.iter().find(|v| v.vr == st.state).map_or("?", |v| v.name), checkpoint);
            }
        }
    }
    assert!(worst.0 <= 1.0, "{}: {} of the bound at {} s, {}", M::INFO.identifier, worst.0, worst.2, worst.1);
}

/// Lowering from rest: within the 0.4 s the pilot pressure builds up, the CBV opens and the
/// boom moves.
#[test]
fn rigid_boom_derivatives_follow_the_co_simulation_trajectory() {
    check_derivatives_along_cs_run::<HydraulicBoom>(Some(false), (vr::U_REF, -0.3));
}

#[test]
fn flexible_boom_derivatives_follow_the_co_simulation_trajectory() {
    check_derivatives_along_cs_run::<HydraulicBoom>(Some(true), (vr::U_REF, -0.3));
}

/// The circuit alone with the rod held (cylinder.v = 0: the plain port's stroke stays at its
/// input), and the boom alone pushed by a force 3 % below the holding force.
#[test]
fn split_models_derivatives_follow_the_co_simulation_trajectory() {
    check_derivatives_along_cs_run::<HydraulicCircuit>(None, (vr::U_REF, -0.3));
    for flexible in [false, true] {
        check_derivatives_along_cs_run::<BoomMechanics>(Some(flexible), (vr::F, 23_000.0));
    }
}

/// The flexible 4 + 5 boom fills slots 10..32 with section 9's angle and rate, and their
/// derivatives with section 9's: the importer's solver keeps them equal.
#[test]
fn slots_beyond_the_last_section_repeat_it() {
    unsafe {
        let s = plant_initializing("slots");
        assert_eq!(api::exit_initialization_mode::<HydraulicBoom>(s.c), OK);
        assert_eq!(s.set_real(vr::U_REF, -0.2), OK);
        let n = HydraulicBoom::STATES.len();
        let (mut x, mut dx) = (vec![0.0; n], vec![0.0; n]);
        assert_eq!(api::get_continuous_states::<HydraulicBoom>(s.c, x.as_mut_ptr(), n), OK);
        assert_eq!(api::enter_continuous_time_mode::<HydraulicBoom>(s.c), OK);
        x[C + 3] += 1e-3; // bend the arm: section 4 turns
        assert_eq!(api::set_continuous_states::<HydraulicBoom>(s.c, x.as_ptr(), n), OK);
        assert_eq!(api::get_derivatives::<HydraulicBoom>(s.c, dx.as_mut_ptr(), n), OK);
        for k in 9..32 {
            for (a, b) in [(C + 8, C + k), (C + 32 + 8, C + 32 + k)] {
                assert_eq!((x[a], dx[a]), (x[b], dx[b]), "slot {}", k + 1);
            }
        }
        assert!(dx[C + 32 + 3] != 0.0, "the bent section accelerates");
    }
}

/// A rigid boom's rate state the boom cannot hold (the fuzzer's case: omega = f64::MAX with the
/// boom horizontal, where omega / dtheta2/dl_cyl * dtheta2/dl_cyl rounds to inf) is refused with
/// its name, and the instance keeps the states it had: fmi2GetContinuousStates once returned inf.
#[test]
fn a_rate_state_beyond_the_largest_number_is_refused() {
    unsafe {
        let s = plant_initializing("overflow");
        assert_eq!(s.set_boolean(vr::FLEXIBLE, false), OK);
        assert_eq!(api::exit_initialization_mode::<HydraulicBoom>(s.c), OK);
        assert_eq!(api::enter_continuous_time_mode::<HydraulicBoom>(s.c), OK);
        let n = HydraulicBoom::STATES.len();
        let (mut x, mut after) = (vec![0.0; n], vec![0.0; n]);
        assert_eq!(api::get_continuous_states::<HydraulicBoom>(s.c, x.as_mut_ptr(), n), OK);
        let mut bad = vec![0.0; n];
        bad[C..C + 32].fill(0.0); // theta2 = 0: horizontal
        bad[C + 32..].fill(f64::MAX);
        bad[0] = 7e6;
        assert_eq!(api::set_continuous_states::<HydraulicBoom>(s.c, bad.as_ptr(), n), ERR);
        assert!(s.last_error().contains("boom.section[1].omega = 1.7976931348623157e308 rad/s"), "{}", s.last_error());
        assert_eq!(api::get_continuous_states::<HydraulicBoom>(s.c, after.as_mut_ptr(), n), OK);
        assert_eq!(after, x);
    }
}

/// Model Exchange runs the plain port only; the TLM port is refused at the end of
/// initialisation with the reason.
#[test]
fn tlm_port_is_refused_in_model_exchange() {
    fn check<M: Model>() {
        let s = model::<M>("tlm");
        unsafe {
            assert_eq!(api::setup_experiment::<M>(s.c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(api::enter_initialization_mode::<M>(s.c), OK);
            let one = 1;
            assert_eq!(api::set_integer::<M>(s.c, &boomsim::models::port::vr::COUPLING, 1, &one), OK);
            assert_eq!(api::exit_initialization_mode::<M>(s.c), ERR);
        }
        assert!(s.last_error().contains("port.coupling = 1 (TLM) is a Co-Simulation coupling"), "{}", s.last_error());
    }
    check::<HydraulicCircuit>();
    check::<BoomMechanics>();
}

/// HydraulicBoom's event indicators change sign where its right-hand side jumps: u_ref through
/// 0 (the spool demand jumps across the dead band) and x_v through -x_db and +x_db (the
/// load-sensing switch), with x_db the FMU's own `valve.x_db`.
#[test]
fn event_indicators_mark_the_dead_band() {
    let x_db_vr = HydraulicBoom::VARIABLES.iter().find(|v| v.name == "valve.x_db").unwrap().vr;
    unsafe {
        let s = plant_initializing("events");
        assert_eq!(api::exit_initialization_mode::<HydraulicBoom>(s.c), OK);
        let x_db = s.real(x_db_vr);
        assert_eq!(s.set_real(vr::U_REF, -0.2), OK);
        assert_eq!(api::enter_continuous_time_mode::<HydraulicBoom>(s.c), OK);
        let n = HydraulicBoom::STATES.len();
        let mut x = vec![0.0; n];
        assert_eq!(api::get_continuous_states::<HydraulicBoom>(s.c, x.as_mut_ptr(), n), OK);
        let mut z = [0.0; 3];
        for (x_v, signs) in
            [(0.0, [-1.0, -1.0, 1.0]), (2.0 * x_db, [-1.0, 1.0, 1.0]), (-2.0 * x_db, [-1.0, -1.0, -1.0])]
        {
            x[X_V] = x_v;
            assert_eq!(api::set_continuous_states::<HydraulicBoom>(s.c, x.as_ptr(), n), OK);
            assert_eq!(api::get_event_indicators::<HydraulicBoom>(s.c, z.as_mut_ptr(), 3), OK);
            let got: Vec<f64> = z.iter().map(|z| z.signum()).collect();
            assert_eq!(got, signs, "x_v = {x_v}: {z:?}");
        }
        assert_eq!(z, [-0.2, -3.0 * x_db, -x_db]);
        assert_eq!(api::get_event_indicators::<HydraulicBoom>(s.c, z.as_mut_ptr(), 2), ERR);
        assert!(s.last_error().contains("ni = 2, but HydraulicBoom has 3 event indicators"), "{}", s.last_error());
    }
}

/// FMI 2.0, 3.2.3 rule 5 (clarified in 2.0.1): in Continuous-Time Mode fmi2SetReal may set a
/// continuous-time state by its value reference; it is the state then, as fmi2SetContinuousStates
/// would set it. And a state the FMU wrote always reads back: fmi2SetTime back before the last
/// completed integrator step (3.2.1 allows going back) still serialises into bytes that
/// fmi2DeSerializeFMUstate takes.
#[test]
fn a_state_set_by_its_reference_is_the_state_and_serialises() {
    let s = at(St::ContinuousTimeMode);
    assert_eq!(s.set_real(pfc::P_LP, 7e5), OK, "{}", s.last_error());
    let mut x = [0.0];
    assert_eq!(unsafe { api::get_continuous_states::<Pfc>(s.c, x.as_mut_ptr(), 1) }, OK);
    assert_eq!(x[0], 7e5);
    assert_eq!(s.real(pfc::P_LP), 7e5);
    assert_eq!(s.set_real(pfc::P_LP, f64::NAN), ERR, "refused as fmi2SetContinuousStates refuses it");
    assert_eq!(unsafe { api::set_time::<Pfc>(s.c, 0.5) }, OK);
    let (mut enter, mut terminate) = (0 as c_int, 0 as c_int);
    assert_eq!(unsafe { api::completed_integrator_step::<Pfc>(s.c, 1, &mut enter, &mut terminate) }, OK);
    assert_eq!(unsafe { api::set_time::<Pfc>(s.c, 0.25) }, OK);
    let bytes = common::serialized(&s);
    let mut st = std::ptr::null_mut();
    let status = unsafe { api::deserialize_fmu_state::<Pfc>(s.c, bytes.as_ptr() as *const fmi2Byte, bytes.len(), &mut st) };
    assert_eq!(status, OK, "{}", s.last_error());
    assert_eq!(unsafe { api::free_fmu_state::<Pfc>(s.c, &mut st) }, OK);
}

/// Trial states below absolute zero (-101325 Pa gauge), which an integrator tries and the physics
/// never reaches, are taken: FMI 2.0, 2.1.3 lists fmi2Discard for Model Exchange where "a
/// function is outside of its domain", and the plants' equations have none (issue 49: they are
/// continued below vacuum, `boomsim::hydraulics::line`). fmi2SetContinuousStates answers OK, the
/// derivatives are finite and pull the pressure back towards vacuum (der(p4) > 0), and the same
/// state set by its value reference (FMI 2.0, 3.2.3 rule 5) is taken the same way. Both plants.
#[test]
fn states_below_absolute_zero_are_taken_and_pulled_back() {
    fn check<M: Model>() {
        let s = model::<M>("vacuum");
        let n = M::STATES.len();
        let (mut x, mut dx) = (vec![0.0; n], vec![0.0; n]);
        unsafe {
            assert_eq!(api::setup_experiment::<M>(s.c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(api::enter_initialization_mode::<M>(s.c), OK);
            assert_eq!(api::exit_initialization_mode::<M>(s.c), OK);
            assert_eq!(api::enter_continuous_time_mode::<M>(s.c), OK);
            assert_eq!(api::get_continuous_states::<M>(s.c, x.as_mut_ptr(), n), OK);
            for depth in [500.0, 5e5] {
                let mut trial = x.clone();
                trial[P4] = -101325.0 - depth;
                let status = api::set_continuous_states::<M>(s.c, trial.as_ptr(), n);
                assert_eq!(status, OK, "{}: {}", M::INFO.identifier, s.last_error());
                let mut taken = vec![0.0; n];
                assert_eq!(api::get_continuous_states::<M>(s.c, taken.as_mut_ptr(), n), OK);
                assert_eq!(taken, trial, "{}", M::INFO.identifier);
                assert_eq!(api::get_derivatives::<M>(s.c, dx.as_mut_ptr(), n), OK);
                assert!(dx.iter().all(|d| d.is_finite()) && dx[P4] > 0.0, "{}: {dx:?}", M::INFO.identifier);
            }
            let p4 = (M::STATES[P4].state, -101325.0 - 500.0);
            assert_eq!(api::set_real::<M>(s.c, &p4.0, 1, &p4.1), OK, "{}: {}", M::INFO.identifier, s.last_error());
            let mut taken = vec![0.0; n];
            assert_eq!(api::get_continuous_states::<M>(s.c, taken.as_mut_ptr(), n), OK);
            assert_eq!(taken[P4], p4.1, "{}", M::INFO.identifier);
        }
    }
    check::<HydraulicBoom>();
    check::<HydraulicCircuit>();
}
