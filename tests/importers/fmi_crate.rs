//! The packed .fmu loaded by an independent importer, the `fmi` crate (0.8): model description,
//! instantiation, stepping, and the controller's analytic step response.
//! Needs `boomsim pack` first (scripts/test runs it).

use crate::fmu;
use boomsim::fmu::guid::guid;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::PressureFeedbackController;
use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::traits::FmiImport;

/// The controller's step response: initial pressure P0, valve reference U_REF, then a step of the
/// fed-back pressure by DP after initialisation, sampled every H.
pub const P0: f64 = 45e5;
pub const DP: f64 = -2e5;
pub const U_REF: f64 = -0.05;
pub const H: f64 = 1e-3;

/// The compensation u_comp at time t after the pressure step is the analytic step response of the
/// test below (also the FMI 3.0 test's, tests/importers/fmi3_crate.rs).
pub fn assert_step_response(t: f64, u_comp: f64) {
    let (k_f, w, q) = (1.24e-11, 35.8, 25.0 / 60_000.0);
    let expected = k_f * w * DP * (-w * t).exp() / q;
    // Exact discretisation: only rounding of the 1e7 Pa state remains.
    assert!((u_comp - expected).abs() <= 1e-9 * (k_f * w * DP / q).abs(), "t = {t}: {u_comp} vs {expected}");
}

/// Step of the fed-back pressure by dp after initialisation: u_comp(t) = K_f omega_f dp
/// e^(-omega_f t) / Q_rated, the impulse-free step response of eq. 6.2 in spool units.
#[test]
fn controller_runs_in_the_fmi_crate_and_matches_the_analytic_step_response() {
    let import = fmu::<Fmi2Import>("PressureFeedbackController");
    assert_eq!(import.model_description().guid, guid::<PressureFeedbackController>());
    let mut s = import.instantiate_cs("pfc", false, true).expect("instantiates");
    assert_eq!(s.get_version(), "2.0");
    assert_eq!(s.get_types_platform(), "default");
    s.setup_experiment(Some(1e-6), 0.0, Some(1.0)).unwrap();
    s.enter_initialization_mode().unwrap();
    s.set_real(&[vr::P, vr::U_REF], &[P0, U_REF]).unwrap();
    s.exit_initialization_mode().unwrap();
    let mut out = [0.0; 2];
    s.get_real(&[vr::U, vr::U_COMP], &mut out).unwrap();
    assert_eq!(out, [U_REF, 0.0], "the filter starts at rest: no kick at t = 0");
    s.set_real(&[vr::P], &[P0 + DP]).unwrap();
    for k in 0..200 {
        let t = k as f64 * H;
        s.get_real(&[vr::U, vr::U_COMP], &mut out).unwrap();
        assert_step_response(t, out[1]);
        assert!((out[0] - (U_REF + out[1])).abs() < 1e-15);
        s.do_step(t, H, true).unwrap();
    }
    assert!(s.do_step(0.2, -H, true).is_err(), "negative step refused");
    s.terminate().unwrap();
}

/// The Model Exchange interface of the same .fmu in the fmi crate: the filter state relaxes to a
/// pressure step as x(t) = p + (x0 - p) e^(-omega_f t) (eq. 6.2's low pass), integrated here by
/// classical Runge-Kutta from fmi2GetDerivatives: local error (omega_f h)^5 / 120 = 5e-10 of the
/// pressure step per step, at most 1e-7 of it over 200 steps.
#[test]
fn controller_runs_as_model_exchange_in_the_fmi_crate() {
    use fmi::fmi2::instance::ModelExchange;
    use fmi::EventFlags;
    let import = fmu::<Fmi2Import>("PressureFeedbackController");
    let mut m = import.instantiate_me("pfc-me", false, true).expect("instantiates as ME");
    m.setup_experiment(Some(1e-6), 0.0, None).unwrap();
    m.enter_initialization_mode().unwrap();
    let (p0, p) = (45e5, 43e5);
    m.set_real(&[vr::P], &[p0]).unwrap();
    m.exit_initialization_mode().unwrap();
    m.new_discrete_states(&mut EventFlags::default()).unwrap();
    m.enter_continuous_time_mode().unwrap();
    m.set_real(&[vr::P], &[p]).unwrap();
    let mut x = [0.0];
    m.get_continuous_states(&mut x).unwrap();
    assert_eq!(x[0], p0, "the filter starts at rest at the initial pressure");
    let mut f = |t: f64, x: f64| {
        m.set_time(t).unwrap();
        m.set_continuous_states(&[x]).unwrap();
        let mut dx = [0.0];
        m.get_derivatives(&mut dx).unwrap();
        dx[0]
    };
    let (h, w) = (1e-3, 35.8);
    let mut y = p0;
    for k in 0..200 {
        let t = k as f64 * h;
        let k1 = f(t, y);
        let k2 = f(t + h / 2.0, y + h / 2.0 * k1);
        let k3 = f(t + h / 2.0, y + h / 2.0 * k2);
        let k4 = f(t + h, y + h * k3);
        y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        let exact = p + (p0 - p) * (-w * (t + h)).exp();
        assert!((y - exact).abs() <= 1e-7 * (p0 - p).abs(), "t = {}: {y} vs {exact}", t + h);
    }
}
