//! The packed FMI 3.0 .fmu files loaded by an independent importer, the `fmi` crate (0.8, feature
//! `fmi3`): the controller's analytic step response in Co-Simulation, and the plant in
//! Co-Simulation and Model Exchange against the FMI 2.0 .fmu of the same binary through the same
//! importer. Needs `boomsim pack` first (scripts/test runs it).

use boomsim::fmu::guid::token;
use boomsim::fmu::Model;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::{HydraulicBoom, PressureFeedbackController};
use fmi::fmi3::import::Fmi3Import;
use fmi::fmi3::{CoSimulation, Common, Fmi3Model, GetSet, ModelExchange};
use fmi::traits::FmiImport;
use std::path::Path;

fn fmu3(id: &str) -> Fmi3Import {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join(format!("target/fmu/fmi3/{id}.fmu"));
    assert!(path.exists(), "{} is missing: run `target/release/boomsim pack` first", path.display());
    fmi::import::from_path(&path).expect("the fmi crate loads the FMI 3.0 FMU")
}

fn fmu2(id: &str) -> fmi::fmi2::import::Fmi2Import {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join(format!("target/fmu/{id}.fmu"));
    fmi::import::from_path(&path).expect("the fmi crate loads the FMI 2.0 FMU")
}

/// Step of the fed-back pressure by dp after initialisation: u_comp(t) = K_f omega_f dp
/// e^(-omega_f t) / Q_rated (eq. 6.2), as in the FMI 2.0 test of tests/fmi_crate.rs.
#[test]
fn controller_runs_in_the_fmi_crate_as_fmi3_and_matches_the_analytic_step_response() {
    let import = fmu3("PressureFeedbackController");
    let md = import.model_description();
    assert_eq!(md.fmi_version, "3.0");
    assert_eq!(md.instantiation_token, token::<PressureFeedbackController>());
    let mut s = import.instantiate_cs("pfc3", false, true, false, false, &[]).expect("instantiates");
    assert_eq!(s.get_version(), "3.0");
    s.enter_initialization_mode(Some(1e-6), 0.0, Some(1.0)).unwrap();
    let (p0, dp, u_ref) = (45e5, -2e5, -0.05);
    s.set_float64(&[vr::P, vr::U_REF], &[p0, u_ref]).unwrap();
    s.exit_initialization_mode().unwrap();
    s.set_float64(&[vr::P], &[p0 + dp]).unwrap();
    let (k_f, w, q, h) = (1.24e-11, 35.8, 25.0 / 60_000.0, 1e-3);
    let mut out = [0.0; 2];
    for k in 0..200 {
        let t = k as f64 * h;
        s.get_float64(&[vr::U, vr::U_COMP], &mut out).unwrap();
        let expected = k_f * w * dp * (-w * t).exp() / q;
        // Exact discretisation: only rounding of the 1e7 Pa state remains.
        assert!((out[1] - expected).abs() <= 1e-9 * (k_f * w * dp / q).abs(), "t = {t}: {} vs {expected}", out[1]);
        let (mut event, mut terminate, mut early, mut last) = (true, true, true, 0.0);
        s.do_step(t, h, true, &mut event, &mut terminate, &mut early, &mut last).unwrap();
        assert!(!event && !terminate && !early && last == t + h);
    }
    let (mut e, mut te, mut ea, mut l) = (false, false, false, 0.0);
    assert!(s.do_step(0.2, -h, true, &mut e, &mut te, &mut ea, &mut l).is_err(), "negative step refused");
    assert!(s.terminate().is_err(), "FMI 3.0, 2.3.1: the error left the instance Terminated");
}

/// The plant lowering the load (valve.u_ref = -0.3 for 0.3 s, flexible boom) in Co-Simulation:
/// bit-identical through the FMI 3.0 and the FMI 2.0 .fmu in the same importer.
#[test]
fn plant_co_simulation_in_the_fmi_crate_equals_fmi2() {
    use fmi::fmi2::instance::{CoSimulation as Cs2, Common as Common2};
    let (i3, i2) = (fmu3("HydraulicBoom"), fmu2("HydraulicBoom"));
    let mut s3 = i3.instantiate_cs("plant3", false, true, false, false, &[]).unwrap();
    let mut s2 = i2.instantiate_cs("plant2", false, true).unwrap();
    s3.enter_initialization_mode(None, 0.0, None).unwrap();
    s2.setup_experiment(None, 0.0, None).unwrap();
    s2.enter_initialization_mode().unwrap();
    s3.exit_initialization_mode().unwrap();
    s2.exit_initialization_mode().unwrap();
    let outs = [boomsim::models::vr::P3, boomsim::models::vr::P4, boomsim::models::vr::X, boomsim::models::vr::V];
    let (mut y3, mut y2) = ([0.0; 4], [0.0; 4]);
    let h = 1e-3;
    for k in 0..300 {
        let t = k as f64 * h;
        s3.set_float64(&[boomsim::models::vr::U_REF], &[-0.3]).unwrap();
        s2.set_real(&[boomsim::models::vr::U_REF], &[-0.3]).unwrap();
        let (mut e, mut te, mut ea, mut l) = (false, false, false, 0.0);
        s3.do_step(t, h, true, &mut e, &mut te, &mut ea, &mut l).unwrap();
        s2.do_step(t, h, true).unwrap();
        s3.get_float64(&outs, &mut y3).unwrap();
        s2.get_real(&outs, &mut y2).unwrap();
        assert_eq!(y3.map(f64::to_bits), y2.map(f64::to_bits), "t = {}", t + h);
    }
    assert!(y3[2].is_finite() && y3[1] > 1e5, "the load is held or lowered: p4 = {} Pa", y3[1]);
}

/// Model Exchange in the fmi crate: the number of states and event indicators, the states, their
/// derivatives and the event indicators at moved states, equal (bitwise) through FMI 3.0 and
/// FMI 2.0.
#[test]
fn plant_model_exchange_in_the_fmi_crate_equals_fmi2() {
    use fmi::fmi2::instance::{Common as Common2, ModelExchange as Me2};
    let (i3, i2) = (fmu3("HydraulicBoom"), fmu2("HydraulicBoom"));
    let mut m3 = i3.instantiate_me("me3", false, true).unwrap();
    let mut m2 = i2.instantiate_me("me2", false, true).unwrap();
    m3.enter_initialization_mode(None, 0.0, None).unwrap();
    m2.setup_experiment(None, 0.0, None).unwrap();
    m2.enter_initialization_mode().unwrap();
    m3.exit_initialization_mode().unwrap();
    m2.exit_initialization_mode().unwrap();
    m3.update_discrete_states(&mut fmi::EventFlags::default()).unwrap();
    m2.new_discrete_states(&mut fmi::EventFlags::default()).unwrap();
    m3.enter_continuous_time_mode().unwrap();
    m2.enter_continuous_time_mode().unwrap();
    let n = HydraulicBoom::STATES.len();
    assert_eq!(m3.get_number_of_continuous_states().unwrap(), n);
    // The same three event indicators, declared as variables in FMI 3.0 (ModelStructure).
    let nz = HydraulicBoom::EVENT_INDICATORS.len();
    assert_eq!(m3.get_number_of_event_indicators().unwrap(), nz);
    let (mut x3, mut x2) = (vec![0.0; n], vec![0.0; n]);
    m3.get_continuous_states(&mut x3).unwrap();
    m2.get_continuous_states(&mut x2).unwrap();
    assert_eq!(x3, x2);
    let x: Vec<f64> = x3.iter().zip(HydraulicBoom::STATES).map(|(x, s)| x + 0.05 * s.nominal).collect();
    m3.set_time(0.01).unwrap();
    m2.set_time(0.01).unwrap();
    m3.set_continuous_states(&x).unwrap();
    m2.set_continuous_states(&x).unwrap();
    let (mut d3, mut d2) = (vec![0.0; n], vec![0.0; n]);
    m3.get_continuous_state_derivatives(&mut d3).unwrap();
    m2.get_derivatives(&mut d2).unwrap();
    assert!(d3.iter().any(|d| *d != 0.0) && d3.iter().all(|d| d.is_finite()));
    assert_eq!(d3.iter().map(|d| d.to_bits()).collect::<Vec<_>>(), d2.iter().map(|d| d.to_bits()).collect::<Vec<_>>());
    let (mut z3, mut z2) = (vec![f64::NAN; nz], vec![f64::NAN; nz]);
    m3.get_event_indicators(&mut z3).unwrap();
    m2.get_event_indicators(&mut z2).unwrap();
    assert!(z3.iter().all(|z| z.is_finite()), "{z3:?}");
    assert_eq!(z3.iter().map(|z| z.to_bits()).collect::<Vec<_>>(), z2.iter().map(|z| z.to_bits()).collect::<Vec<_>>());
}
