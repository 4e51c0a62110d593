//! The packed FMI 3.0 .fmu files loaded by an independent importer, the `fmi` crate (0.8, feature
//! `fmi3`): the controller's analytic step response in Co-Simulation, and the plant in
//! Co-Simulation and Model Exchange against the FMI 2.0 .fmu of the same binary through the same
//! importer. Needs `boomsim pack` first (scripts/test runs it).

use crate::fmi_crate::{assert_step_response, DP, H, P0, U_REF};
use crate::fmu;
use boomsim::fmu::guid::token;
use boomsim::fmu::Model;
use boomsim::models::pressure_feedback_controller::vr;
use boomsim::models::{HydraulicBoom, PressureFeedbackController};
use fmi::fmi2::import::Fmi2Import;
use fmi::fmi3::import::Fmi3Import;
use fmi::fmi3::{CoSimulation, Common, Fmi3Model, GetSet, ModelExchange};
use fmi::traits::FmiImport;

/// Step of the fed-back pressure by dp after initialisation: u_comp(t) = K_f omega_f dp
/// e^(-omega_f t) / Q_rated (eq. 6.2), as in the FMI 2.0 test of tests/fmi_crate.rs.
#[test]
fn controller_runs_in_the_fmi_crate_as_fmi3_and_matches_the_analytic_step_response() {
    let import = fmu::<Fmi3Import>("PressureFeedbackController");
    assert_eq!(import.model_description().instantiation_token, token::<PressureFeedbackController>());
    let mut s = import.instantiate_cs("pfc3", false, true, false, false, &[]).expect("instantiates");
    assert_eq!(s.get_version(), "3.0");
    s.enter_initialization_mode(Some(1e-6), 0.0, Some(1.0)).unwrap();
    s.set_float64(&[vr::P, vr::U_REF], &[P0, U_REF]).unwrap();
    s.exit_initialization_mode().unwrap();
    s.set_float64(&[vr::P], &[P0 + DP]).unwrap();
    let mut out = [0.0; 2];
    for k in 0..200 {
        let t = k as f64 * H;
        s.get_float64(&[vr::U, vr::U_COMP], &mut out).unwrap();
        assert_step_response(t, out[1]);
        let (mut event, mut terminate, mut early, mut last) = (true, true, true, 0.0);
        s.do_step(t, H, true, &mut event, &mut terminate, &mut early, &mut last).unwrap();
        assert!(!event && !terminate && !early && last == t + H);
    }
    let (mut e, mut te, mut ea, mut l) = (false, false, false, 0.0);
    assert!(s.do_step(0.2, -H, true, &mut e, &mut te, &mut ea, &mut l).is_err(), "negative step refused");
    assert!(s.terminate().is_err(), "FMI 3.0, 2.3.1: the error left the instance Terminated");
}

/// fmi2SetupExperiment and fmi2EnterInitializationMode, or fmi3EnterInitializationMode, at t = 0
/// with the defaults, and the exit from Initialization Mode.
fn initialized(i: &mut impl fmi::traits::FmiInstance) {
    i.enter_initialization_mode(None, 0.0, None).unwrap();
    i.exit_initialization_mode().unwrap();
}

/// A Model Exchange instance of HydraulicBoom, initialised and in Continuous-Time Mode: its
/// states, then at t = 0.01 and the states moved by 5 % of their nominals, the derivatives and
/// the event indicators.
fn model_exchange_sample(m: &mut impl fmi::traits::FmiModelExchange) -> [Vec<f64>; 3] {
    initialized(m);
    m.update_discrete_states(&mut fmi::EventFlags::default()).unwrap();
    m.enter_continuous_time_mode().unwrap();
    let (n, nz) = (HydraulicBoom::STATES.len(), HydraulicBoom::EVENT_INDICATORS.len());
    let (mut x, mut d, mut z) = (vec![0.0; n], vec![0.0; n], vec![f64::NAN; nz]);
    m.get_continuous_states(&mut x).unwrap();
    let moved: Vec<f64> = x.iter().zip(HydraulicBoom::STATES).map(|(x, s)| x + 0.05 * s.nominal).collect();
    m.set_time(0.01).unwrap();
    m.set_continuous_states(&moved).unwrap();
    m.get_continuous_state_derivatives(&mut d).unwrap();
    m.get_event_indicators(&mut z).unwrap();
    [x, d, z]
}

/// The bit patterns of `v`, to compare to the last bit.
fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The plant lowering the load (valve.u_ref = -0.3 for 0.3 s, flexible boom) in Co-Simulation:
/// bit-identical through the FMI 3.0 and the FMI 2.0 .fmu in the same importer.
#[test]
fn plant_co_simulation_in_the_fmi_crate_equals_fmi2() {
    use fmi::fmi2::instance::{CoSimulation as Cs2, Common as Common2};
    let (i3, i2) = (fmu::<Fmi3Import>("HydraulicBoom"), fmu::<Fmi2Import>("HydraulicBoom"));
    let mut s3 = i3.instantiate_cs("plant3", false, true, false, false, &[]).unwrap();
    let mut s2 = i2.instantiate_cs("plant2", false, true).unwrap();
    initialized(&mut s3);
    initialized(&mut s2);
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
    let (i3, i2) = (fmu::<Fmi3Import>("HydraulicBoom"), fmu::<Fmi2Import>("HydraulicBoom"));
    let mut m3 = i3.instantiate_me("me3", false, true).unwrap();
    let mut m2 = i2.instantiate_me("me2", false, true).unwrap();
    let [x3, d3, z3] = model_exchange_sample(&mut m3);
    let [x2, d2, z2] = model_exchange_sample(&mut m2);
    assert_eq!(m3.get_number_of_continuous_states().unwrap(), HydraulicBoom::STATES.len());
    // The same three event indicators, declared as variables in FMI 3.0 (ModelStructure).
    assert_eq!(m3.get_number_of_event_indicators().unwrap(), HydraulicBoom::EVENT_INDICATORS.len());
    assert_eq!(x3, x2);
    assert!(d3.iter().any(|d| *d != 0.0) && d3.iter().all(|d| d.is_finite()));
    assert_eq!(bits(&d3), bits(&d2));
    assert!(z3.iter().all(|z| z.is_finite()), "{z3:?}");
    assert_eq!(bits(&z3), bits(&z2));
}

/// The terminals of each FMI 3.0 .fmu (terminalsAndIcons/terminalsAndIcons.xml), read by the `fmi`
/// crate's schema: every terminal satisfies its matching rule (`plug`: a unique memberName per
/// member, FMI 3.0 section 2.4.9) and every member variable resolves in the model description.
/// Then each pair of FMUs the project connects, through the terminals of the same name: the same
/// terminalKind and member names, and per member an output on one side and an input on the other,
/// or a parameter on both (a `signal` member, section 2.4.9, "Terminal Member Variable").
#[test]
fn the_terminals_connect_the_fmus_member_by_member() {
    use fmi::schema::fmi3::{resolve_terminals, Causality, Fmi3TerminalsAndIcons};
    use std::collections::BTreeMap;

    /// name -> (kind, member name -> causality)
    type Ports = BTreeMap<String, (Option<String>, BTreeMap<String, Causality>)>;
    let ports = |id: &str| -> Ports {
        let import = fmu::<Fmi3Import>(id);
        let path = import.archive_path().join("terminalsAndIcons/terminalsAndIcons.xml");
        let xml = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{id}: {}: {e}", path.display()));
        let terminals: Fmi3TerminalsAndIcons = fmi::schema::deserialize(&xml).expect("the schema reads it");
        assert_eq!(terminals.fmi_version, "3.0");
        let resolved = resolve_terminals(&terminals, import.model_description()).expect("every member resolves");
        resolved
            .terminals
            .iter()
            .map(|t| {
                t.terminal.validate_matching_rule().expect("plug: unique member names");
                assert_eq!(t.terminal.matching_rule, "plug");
                let members =
                    t.members.iter().map(|m| (m.member.member_name.clone().unwrap(), m.variable.causality())).collect();
                (t.terminal.name.clone(), (t.terminal.terminal_kind.clone(), members))
            })
            .collect()
    };
    let (circuit, mechanics) = (ports("HydraulicCircuit"), ports("BoomMechanics"));
    let (boom, controller) = (ports("HydraulicBoom"), ports("PressureFeedbackController"));
    let pairs = [
        (&circuit, &mechanics, "rod"),
        (&circuit, &mechanics, "rod_tlm"),
        (&circuit, &controller, "valve"),
        (&circuit, &controller, "pressure"),
        (&boom, &controller, "valve"),
        (&boom, &controller, "pressure"),
    ];
    for (a, b, name) in pairs {
        let ((kind_a, members_a), (kind_b, members_b)) = (&a[name], &b[name]);
        assert!(kind_a.as_deref().is_some_and(|k| k.starts_with("_boomsim_")) && kind_a == kind_b, "{name}");
        assert_eq!(members_a.keys().collect::<Vec<_>>(), members_b.keys().collect::<Vec<_>>(), "{name}");
        for (member, ca) in members_a {
            let cb = &members_b[member];
            let complementary = matches!(
                (ca, cb),
                (Causality::Output, Causality::Input)
                    | (Causality::Input, Causality::Output)
                    | (Causality::Parameter, Causality::Parameter)
            );
            assert!(complementary, "{name}.{member}: {ca:?} against {cb:?}");
        }
    }
    assert_eq!(circuit.len(), 4);
    assert_eq!((mechanics.len(), boom.len(), controller.len()), (2, 2, 2));
}

/// ClockedPressureFeedbackController through the `fmi` crate's FMI 3.0 Model Exchange and Clock
/// calls (fmi3SetClock, fmi3GetClock, fmi3UpdateDiscreteStates), the crate reading the Clock from
/// the modelDescription: p steps by dp at the first activation, which the sampled filter takes as
/// a ramp of slope dp / T over the first interval, so u_comp(T) = K_f (dp / T) (1 - e^(-omega_f
/// T)) / Q_rated (eq. 6.2's high pass of a ramp), decaying with e^(-omega_f (t - T)) while p
/// stays. 1e-12: rounding, the filter state 5e6 Pa against p - x of 3e4 Pa.
#[test]
fn clocked_controller_runs_in_the_fmi_crate_with_its_clock() {
    use boomsim::control::FEEDBACK_PARAMS;
    use boomsim::models::ClockedPressureFeedbackController as Cpfc;
    use fmi::schema::fmi3::{AbstractVariableTrait, Variable};
    let import = fmu::<Fmi3Import>("ClockedPressureFeedbackController");
    let md = import.model_description();
    assert_eq!(md.instantiation_token, token::<Cpfc>());
    let clock = md.model_variables.variables.iter().find_map(|v| match v {
        Variable::Clock(c) if c.name() == "sample" => Some(c.value_reference()),
        _ => None,
    });
    assert_eq!(clock, Some(vr::SAMPLE), "the crate reads the Clock");
    let (k_f, omega, q_rated) =
        (FEEDBACK_PARAMS[0].spec.default, FEEDBACK_PARAMS[1].spec.default, FEEDBACK_PARAMS[2].spec.default);
    let t_s = boomsim::models::clocked_pressure_feedback_controller::INTERVAL;
    let mut m = import.instantiate_me("cpfc", false, true).expect("instantiates");
    m.enter_initialization_mode(None, 0.0, Some(1.0)).unwrap();
    m.set_float64(&[vr::P, vr::U_REF], &[P0, U_REF]).unwrap();
    m.exit_initialization_mode().unwrap();
    m.update_discrete_states(&mut fmi::EventFlags::default()).unwrap();
    m.enter_continuous_time_mode().unwrap();
    let peak = k_f * (DP / t_s) * -(-omega * t_s).exp_m1() / q_rated;
    let mut out = [0.0; 2];
    for k in 1..=100 {
        let t = k as f64 * t_s;
        m.set_time(t).unwrap();
        m.enter_event_mode().unwrap();
        m.set_clock(&[vr::SAMPLE], &[true]).unwrap();
        let mut on = [false];
        m.get_clock(&[vr::SAMPLE], &mut on).unwrap();
        assert!(on[0], "t = {t}: active after fmi3SetClock");
        m.set_float64(&[vr::P], &[P0 + DP]).unwrap();
        m.get_float64(&[vr::U, vr::U_COMP], &mut out).unwrap();
        let expected = peak * (-omega * (t - t_s)).exp();
        assert!(
            (out[1] - expected).abs() <= 1e-12 * peak.abs(),
            "t = {t}: u_comp {}, ramp response {expected}",
            out[1]
        );
        assert_eq!(out[0], U_REF + out[1]);
        m.update_discrete_states(&mut fmi::EventFlags::default()).unwrap();
        m.enter_continuous_time_mode().unwrap();
    }
    assert!(m.get_float64(&[vr::U], &mut out[..1]).is_err(), "u is clocked: not readable between activations");
}
