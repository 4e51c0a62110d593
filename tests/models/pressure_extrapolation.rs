//! PressureFeedbackController's `p.extrapolation` through the FMI functions, against closed-form
//! solutions of the filter x' = omega_f (p - x), u_comp = K_f omega_f (p - x) / Q_rated (eq. 6.2).
//!
//! A Jacobi master sets p_k at t_k, steps, and reads u at t_k+1 before it sets p_k+1. With the
//! extrapolation the controller continues p through its last two samples, so a pressure ramp
//! p0 + a t is reproduced exactly from the second step on (the first step holds p0: there is only
//! one sample): for t >= h, x(t) = p(t) - a/w + (x(h) - p(h) + a/w) e^(-w (t - h)), x(h) = p0.


use boomsim::fmi2::api;
use boomsim::fmi2::types::*;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::PressureFeedbackController as Pfc;
use crate::common::Slave;

const OK: fmi2Status = fmi2Status::OK;
const H: f64 = 1e-3;
const P0: f64 = 20e5;
/// 15 bar/s, the rod-side build-up of experiment B.
const A: f64 = 15e5;
/// Defaults of the FMU (Table 7.2, 25 l/min).
const K_F: f64 = 1.24e-11;
const W: f64 = 35.8;
const Q_RATED: f64 = 25.0 / 60_000.0;

/// An initialised controller at rest at p0, with `p.extrapolation` as given.
fn controller(extrapolation: bool) -> Slave<Pfc> {
    let s = Slave::<Pfc>::new("pfc");
    assert_eq!(unsafe { api::setup_experiment::<Pfc>(s.c, 0, 0.0, 0.0, 0, 0.0) }, OK);
    assert_eq!(unsafe { api::enter_initialization_mode::<Pfc>(s.c) }, OK);
    assert_eq!(s.set_boolean(vr::EXTRAPOLATION, extrapolation), OK);
    assert_eq!(s.set_real(vr::P, P0), OK);
    assert_eq!(unsafe { api::exit_initialization_mode::<Pfc>(s.c) }, OK);
    s
}

fn gain() -> f64 {
    K_F * W / Q_RATED
}

/// u_comp at t >= h for the ramp held over the first step (closed form above).
fn ramp_response(t: f64) -> f64 {
    let c = A / W;
    gain() * (c - (c - A * H) * (-W * (t - H)).exp())
}

/// Within rounding of the 2e6 Pa pressures over 1000 steps: 1e-9 of the ramp's u_comp.
fn close(got: f64, want: f64) -> bool {
    (got - want).abs() <= 1e-9 * gain() * A / W
}

#[test]
fn a_ramp_is_reproduced_exactly_by_a_jacobi_master() {
    let s = controller(true);
    for k in 0..1000 {
        let t = k as f64 * H;
        if k > 0 {
            assert_eq!(s.set_real(vr::P, P0 + A * t), OK);
        }
        assert_eq!(s.step(t, H), OK);
        let (got, want) = (s.real(vr::U_COMP), if k == 0 { 0.0 } else { ramp_response(t + H) });
        assert!(close(got, want), "t = {}: u_comp {got} vs {want}", t + H);
    }
}

#[test]
fn without_a_new_sample_the_ramp_continues() {
    let s = controller(true);
    for k in 0..200 {
        let t = k as f64 * H;
        // the master passes p only at the first two points and every tenth after
        if k == 1 || k % 10 == 0 {
            assert_eq!(s.set_real(vr::P, P0 + A * t), OK);
        }
        assert_eq!(s.step(t, H), OK);
        if k > 0 {
            let (got, want) = (s.real(vr::U_COMP), ramp_response(t + H));
            assert!(close(got, want), "t = {}: u_comp {got} vs {want}", t + H);
        }
    }
}

/// The default holds p over the step: x_k+1 = p_k + (x_k - p_k) e^(-w h), and u at t_k+1 (read
/// before the next sample) is K_f w (p_k - x_k+1) / Q_rated.
#[test]
fn by_default_p_is_held() {
    let s = controller(false);
    let mut x = P0;
    for k in 0..500 {
        let t = k as f64 * H;
        let p = P0 + A * t;
        assert_eq!(s.set_real(vr::P, p), OK);
        assert_eq!(s.step(t, H), OK);
        x = p + (x - p) * (-W * H).exp();
        let (got, want) = (s.real(vr::U_COMP), gain() * (p - x));
        assert!(close(got, want), "t = {}: u_comp {got} vs {want}", t + H);
    }
}

/// A slope passed with fmi2SetRealInputDerivatives is used as given (here twice the ramp's):
/// the extrapolation only fills in for a master that passes none. Closed form of one step from
/// x_k with p_k + b tau: x_k+1 = p_k + b h - b/w + (x_k - p_k + b/w) e^(-w h).
#[test]
fn a_slope_from_the_master_takes_precedence() {
    let s = controller(true);
    let b = 2.0 * A;
    let mut x = P0;
    for k in 0..500 {
        let t = k as f64 * H;
        let p = P0 + A * t;
        assert_eq!(s.set_real(vr::P, p), OK);
        assert_eq!(s.set_slope(vr::P, b), OK);
        assert_eq!(s.step(t, H), OK);
        x = p + b * H - b / W + (x - p + b / W) * (-W * H).exp();
        let (got, want) = (s.real(vr::U_COMP), gain() * (p + b * H - x));
        assert!(close(got, want), "t = {}: u_comp {got} vs {want}", t + H);
    }
}

#[test]
fn extrapolation_is_fixed_after_initialisation() {
    let s = controller(false);
    assert_eq!(s.set_boolean(vr::EXTRAPOLATION, true), fmi2Status::Error);
    assert!(s.last_error().contains("p.extrapolation"), "{}", s.last_error());
}

/// An FMU state taken between a step and the next sample (the outputs extrapolated) continues
/// bit-exactly.
#[test]
fn fmu_state_keeps_the_extrapolation() {
    let s = controller(true);
    for k in 0..3 {
        s.set_real(vr::P, P0 + A * k as f64 * H);
        s.step(k as f64 * H, H);
    }
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(unsafe { api::get_fmu_state::<Pfc>(s.c, &mut state) }, OK);
    let run = |s: &Slave<Pfc>| {
        (3..50)
            .map(|k| {
                let u = s.real(vr::U_COMP);
                s.set_real(vr::P, P0 + A * k as f64 * H - 1e3 * (k * k) as f64);
                s.step(k as f64 * H, H);
                u
            })
            .collect::<Vec<f64>>()
    };
    let reference = run(&s);
    assert_eq!(unsafe { api::set_fmu_state::<Pfc>(s.c, state) }, OK);
    assert_eq!(run(&s), reference);
    assert_eq!(unsafe { api::free_fmu_state::<Pfc>(s.c, &mut state) }, OK);
}

/// Robustness (issue 25 item 10): a denormal step (5e-324 s, the smallest f64) puts two samples
/// of p closer in time than a division resolves; the extrapolated slope through them would be
/// infinite. It is held instead, so the next steps stay finite with fmi2OK and u_comp keeps the
/// high-pass law: a pressure held at P0 since the start gives u_comp = 0.
#[test]
fn a_denormal_step_leaves_the_extrapolation_finite() {
    let s = controller(true);
    let tiny = f64::from_bits(1);
    assert_eq!(s.step(0.0, tiny), OK);
    assert_eq!(s.set_real(vr::P, P0 + 1e5), OK);
    assert_eq!(s.step(tiny, H), OK, "{}", s.last_error());
    assert!(s.real(vr::U_COMP).is_finite() && s.real(vr::U).is_finite());
    assert_eq!(s.set_real(vr::P, P0), OK);
    assert_eq!(s.step(tiny + H, H), OK, "{}", s.last_error());
    assert!(s.real(vr::U_COMP).is_finite());
}
