//! Co-Simulation steps that pass the communication points (`Model::LOOKAHEAD`, the HydraulicBoom)
//! as a master sees them: fewer integrator steps than doSteps where the tolerance allows long
//! steps, a changed input acting from the communication point where it was set, and FMU states
//! saved while a step is ahead continuing bit for bit.

use crate::common::{serialized, Slave};
use boomsim::fmi2::api;
use boomsim::fmi2::types::*;
use boomsim::models::vr;
use boomsim::models::HydraulicBoom as Hb;

const OK: fmi2Status = fmi2Status::OK;
const H: f64 = 1e-3;

/// The plant at rest (the load held by the closed CBV, `u_ref` = 0), rigid or flexible boom.
fn at_rest(flexible: bool) -> Slave<Hb> {
    let s = Slave::<Hb>::new("lookahead");
    unsafe {
        assert_eq!(api::setup_experiment::<Hb>(s.c, 1, 1e-6, 0.0, 0, 0.0), OK);
        assert_eq!(api::enter_initialization_mode::<Hb>(s.c), OK);
        assert_eq!(s.set_boolean(vr::FLEXIBLE, flexible), OK);
        assert_eq!(api::exit_initialization_mode::<Hb>(s.c), OK);
    }
    s
}

/// `n` doSteps of 1 ms from doStep `k0`.
fn steps(s: &Slave<Hb>, k0: usize, n: usize) {
    for k in k0..k0 + n {
        assert_eq!(s.step(k as f64 * H, H), OK, "{}", s.last_error());
    }
}

/// At rest nothing changes: the error estimate is ~0 and the controller grows each step by its
/// largest factor, so 2 s of 1 ms doSteps take fewer than one integrator step per 10 doSteps
/// (measured: 9 steps in 10 s). The state stays the equilibrium (stroke 480 mm to 1 nm, p3 its
/// start value to 1 Pa, as `real_time_holds_the_load_at_rest` asks of the real-time mode).
#[test]
fn at_rest_the_integrator_steps_past_the_communication_points() {
    for flexible in [false, true] {
        let s = at_rest(flexible);
        let p3 = s.real(vr::P3);
        steps(&s, 0, 2000);
        assert!(s.real(vr::SOLVER_STEPS) < 200.0, "flexible {flexible}: {} steps", s.real(vr::SOLVER_STEPS));
        assert!((s.real(vr::X) - 0.48).abs() < 1e-9, "flexible {flexible}: stroke {}", s.real(vr::X));
        assert!((s.real(vr::P3) - p3).abs() < 1.0, "flexible {flexible}: p3 {p3} -> {} Pa", s.real(vr::P3));
    }
}

/// A command set at a communication point acts from there, although the integrator's last step
/// at rest reached seconds beyond it: 1 s at rest, then `u_ref` = -0.3 for 1 ms and for 100 ms,
/// against a plant commanded at t = 0. The plant has no explicit time, so both integrate the
/// same equations from the same equilibrium: the spool position after 1 ms and the stroke
/// after 100 ms agree to 1e-4 of their change (both integrations within the tolerance 1e-6 of
/// the solution: a few tolerance units of the state). A step kept from before the command would
/// leave the spool closed (x_v = 0) after the first doStep.
#[test]
fn a_changed_command_acts_from_its_communication_point() {
    let (late, early) = (at_rest(false), at_rest(false));
    let x0 = late.real(vr::X);
    steps(&late, 0, 1000);
    for (s, k0) in [(&late, 1000), (&early, 0)] {
        assert_eq!(s.set_real(vr::U_REF, -0.3), OK);
        steps(s, k0, 1);
    }
    let (xv_late, xv_early) = (late.real(vr::X_V), early.real(vr::X_V));
    assert!(xv_early.abs() > 0.0, "the spool moves within 1 ms");
    assert!((xv_late - xv_early).abs() <= 1e-4 * xv_early.abs(), "x_v {xv_late} against {xv_early}");
    steps(&late, 1001, 99);
    steps(&early, 1, 99);
    let (x_late, x_early) = (late.real(vr::X), early.real(vr::X));
    assert!((x_late - x_early).abs() <= 1e-4 * (x_early - x0).abs(), "stroke {x_late} against {x_early}");
}

/// Lowering with u_ref = -0.1 (case U) and the rigid boom: an FMU state serialised after 300 ms,
/// restored into another instance, continues bit for bit as the original over the next 300 ms
/// (FMI 2.0, 2.1.8), the integrator's step that passed the last communication point included;
/// over the run the integrator took fewer steps than doSteps.
#[test]
fn a_state_saved_while_a_step_is_ahead_continues_bit_for_bit() {
    let s = at_rest(false);
    assert_eq!(s.set_real(vr::U_REF, -0.1), OK);
    steps(&s, 0, 300);
    let bytes = serialized(&s);
    let other = Slave::<Hb>::new("restored");
    let mut st: fmi2FMUstate = std::ptr::null_mut();
    unsafe {
        let p = bytes.as_ptr() as *const fmi2Byte;
        assert_eq!(api::deserialize_fmu_state::<Hb>(other.c, p, bytes.len(), &mut st), OK);
        assert_eq!(api::set_fmu_state::<Hb>(other.c, st), OK);
        assert_eq!(api::free_fmu_state::<Hb>(other.c, &mut st), OK);
    }
    let run = |s: &Slave<Hb>| {
        (300..600)
            .map(|k| {
                assert_eq!(s.step(k as f64 * H, H), OK);
                [vr::P3, vr::X, vr::SOLVER_STEPS].map(|r| s.real(r).to_bits())
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(&other), run(&s));
    assert!(s.real(vr::SOLVER_STEPS) < 600.0, "{} steps in 600 doSteps", s.real(vr::SOLVER_STEPS));
}
