//! fmi2GetDirectionalDerivative against central differences: at states along a Co-Simulation
//! run, for every unknown/known pair ModelStructure declares (outputs and derivatives on states
//! and inputs), the dual-number derivative agrees with central differences (f(k + h) - f(k - h))
//! / 2h, Richardson-extrapolated, to 1e-6 relative, wherever the entry exceeds 1e-8 of its row's scale (entries times the knowns'
//! nominal values or input ranges) and moves the unknown by more than its round-off resolves. Central differences are exact to O(h^2) only where the model
//! is smooth over the stencil: a pair whose forward and backward quotients disagree by more than
//! 1e-3, or whose extrapolated quotients at h and h/4 by more than 1e-7, sits at or straddles a kink
//! (a valve opening at its limit, the dead-band edge; there the dual number gives the one-sided
//! derivative of the branch taken) and is not compared there; the test counts them and requires
//! most pairs to be compared.

use crate::common;

use boomsim::fmi2::api;
use boomsim::fmu::structure::{probe, unknowns};
use boomsim::fmi2::types::*;
use boomsim_tools::xml::fmi2::dependencies;
use boomsim::fmu::{Causality, Kind, Model, Seeds, Value, Values};
use boomsim::models::vr;
use boomsim::models::{BoomMechanics, HydraulicBoom, HydraulicCircuit};

/// The scale of a known: a state's nominal, an input's range (bounded to 1e3 of its unit).
fn scale<M: Model>(known: u32) -> f64 {
    if let Some(s) = M::STATES.iter().find(|s| s.state == known) {
        return s.nominal;
    }
    match M::VARIABLES.iter().find(|v| v.vr == known).map(|v| v.kind) {
        Some(Kind::Real { min, max, .. }) => (max - min).min(1e3),
        _ => 1.0,
    }
}

/// The unknowns of `model` with the known `k` moved by `d` (a state or an input in `values`).
fn moved<M: Model>(model: &M, values: &Values, k: u32, d: f64) -> Vec<(u32, f64)> {
    let mut m = model.clone();
    let mut v = values.clone();
    if let Some(j) = M::STATES.iter().position(|s| s.state == k) {
        let mut x = vec![0.0; M::STATES.len()];
        m.continuous_states(&mut x);
        x[j] += d;
        m.set_continuous_states(&x).unwrap();
    } else {
        v.set_real(k, v.real(k) + d);
    }
    unknowns(&m, &v)
}

/// Checks model `M` at `samples` states of a CS run with the inputs `setup`; returns (compared,
/// skipped at kinks).
fn check<M: Model>(setup: &[(u32, Value)], steps: usize, samples: usize) -> (usize, usize) {
    let deps = dependencies::<M>(&probe::<M>());
    let mut inst = common::in_initialization::<M>(setup);
    inst.exit_initialization_mode().unwrap();
    let (mut compared, mut skipped, mut worst) = (0, 0, (0.0, String::new()));
    for k in 0..steps {
        inst.do_step(k as f64 * 1e-3, 1e-3).unwrap();
        if (k + 1) % (steps / samples) != 0 {
            continue;
        }
        let (model, values) = (M::clone(inst.core.model.as_ref().unwrap()), inst.core.values.clone());
        let base = unknowns(&model, &values);
        // The unknowns of Continuous-Time Mode (FMI 3.0, 2.2.11): outputs and derivatives, not
        // the event indicators.
        for (unknown, knowns) in deps.iter().filter(|(u, _)| !M::EVENT_INDICATORS.contains(u)) {
            let row = base.iter().position(|u| u.0 == *unknown).unwrap();
            // The row: dual-number derivatives, each scaled by its known's scale.
            let dd: Vec<f64> = knowns
                .iter()
                .map(|&kn| {
                    let mut o = [0.0];
                    let seeds = Seeds { knowns: &[(kn, 1.0)], unknowns: &[*unknown], out: &mut o };
                    model.directional_derivative(&values, seeds).unwrap();
                    o[0]
                })
                .collect();
            assert!(dd.iter().all(|d| d.is_finite()), "d {} / d {knowns:?} = {dd:?}", name::<M>(*unknown));
            let row_scale = knowns.iter().zip(&dd).map(|(&kn, d)| (d * scale::<M>(kn)).abs()).fold(0.0, f64::max);
            for (&kn, &d) in knowns.iter().zip(&dd) {
                if (d * scale::<M>(kn)).abs() <= 1e-8 * row_scale {
                    continue;
                }
                let h = 1e-4 * scale::<M>(kn);
                // The smallest stencil (h / 8) must move the unknown by more than 1e-8 of its
                // value, or its round-off (2e-16 of the value) exceeds 2e-8 of the quotient.
                if (d * h / 8.0).abs() <= 1e-8 * base[row].1.abs() {
                    continue;
                }
                let f = |h: f64| moved(&model, &values, kn, h)[row].1;
                let central = |h: f64| (f(h) - f(-h)) / (2.0 * h);
                // Richardson's extrapolation of the central quotient: error O(h^4), so h can be
                // large enough (1e-4 of the scale) that round-off stays below 1e-9 of the entry.
                let richardson = |h: f64| (4.0 * central(h / 2.0) - central(h)) / 3.0;
                let (c2, c1) = (richardson(h), richardson(h / 4.0));
                let (fwd, bwd) = ((f(h / 10.0) - base[row].1) / (h / 10.0), (base[row].1 - f(-h / 10.0)) / (h / 10.0));
                let smooth = (fwd - bwd).abs() <= 1e-3 * fwd.abs().max(bwd.abs());
                if !smooth || (c1 - c2).abs() > 1e-7 * c1.abs().max(c2.abs()) {
                    skipped += 1;
                    continue;
                }
                compared += 1;
                let err = (d - c1).abs() / d.abs();
                if err > worst.0 {
                    worst = (err, format!("d {} / d {} = {d} vs {c1}", name::<M>(*unknown), name::<M>(kn)));
                }
            }
        }
    }
    assert!(worst.0 < 1e-6, "{}: relative error {:.2e} at {}", M::INFO.identifier, worst.0, worst.1);
    (compared, skipped)
}

fn name<M: Model>(r: u32) -> &'static str {
    M::VARIABLES.iter().find(|v| v.vr == r).map_or("?", |v| v.name)
}

#[test]
fn hydraulic_circuit_derivatives_are_exact() {
    let (c, s) = check::<HydraulicCircuit>(&[(vr::U_REF, Value::Real(-0.3)), (vr::V, Value::Real(-0.01))], 400, 8);
    assert!(c > 5 * s && c > 200, "compared {c} entries, {s} at kinks");
    eprintln!("compared {c} entries, {s} at kinks");
    let (c, s) = check::<HydraulicCircuit>(&[(vr::U_REF, Value::Real(0.3)), (vr::V, Value::Real(0.01))], 400, 8);
    assert!(c > 5 * s && c > 200, "compared {c} entries, {s} at kinks");
    eprintln!("compared {c} entries, {s} at kinks");
}

/// Lowering and lifting, rigid and flexible (the default 4 + 5 sections): 64 of the 70 Model
/// Exchange states carry the arm, and the boom's outputs depend on them.
#[test]
fn hydraulic_boom_derivatives_are_exact() {
    let rigid = (vr::FLEXIBLE, Value::Boolean(false));
    for (case, setup, steps) in [
        ("rigid, lowering", vec![rigid.clone(), (vr::U_REF, Value::Real(-0.4))], 400),
        ("rigid, lifting", vec![rigid, (vr::U_REF, Value::Real(0.4))], 400),
        ("flexible, lowering", vec![(vr::U_REF, Value::Real(-0.4))], 200),
    ] {
        let (c, s) = check::<HydraulicBoom>(&setup, steps, 4);
        eprintln!("HydraulicBoom {case}: compared {c} entries, {s} at kinks");
        assert!(c > 5 * s && c > 200, "compared {c} entries, {s} at kinks");
    }
}

/// The boom pushed by 90 % and 110 % of its holding force start.F (sinking and rising), rigid
/// and flexible.
#[test]
fn boom_mechanics_derivatives_are_exact() {
    for flexible in [false, true] {
        let mut inst = common::in_initialization::<BoomMechanics>(&[(vr::FLEXIBLE, Value::Boolean(flexible))]);
        inst.exit_initialization_mode().unwrap();
        let mut values = inst.core.values.clone();
        inst.core.model.as_ref().unwrap().outputs(&mut values);
        let f_start = values.real(boomsim::models::port::vr::START_F);
        assert!(f_start > 1e4, "the boom's holding force: {f_start} N");
        for load in [0.9, 1.1] {
            let setup = [(vr::FLEXIBLE, Value::Boolean(flexible)), (vr::F, Value::Real(load * f_start))];
            let (c, s) = check::<BoomMechanics>(&setup, 200, 4);
            eprintln!("BoomMechanics flexible {flexible}, {load} start.F: compared {c} entries, {s} at kinks");
            assert!(c > 5 * s && c > 100, "compared {c} entries, {s} at kinks");
        }
    }
}

/// Through the C ABI: references checked (a local is no unknown, a parameter no known), NaN
/// seeds refused, and in Co-Simulation the knowns are inputs only.
#[test]
fn directional_derivative_arguments_are_checked() {
    let s = common::Slave::<HydraulicCircuit>::initialized("dd", &[]);
    let (p3, der_p3) = (vr::P3, HydraulicCircuit::STATES[2].derivative);
    let x_v = vr::X_V;
    let mut out = [f64::NAN];
    let call = |u: u32, k: u32, dv: f64, out: &mut [f64; 1]| unsafe {
        api::get_directional_derivative::<HydraulicCircuit>(s.c, &u, 1, &k, 1, &dv, out.as_mut_ptr())
    };
    assert_eq!(call(vr::F, vr::V, 1.0, &mut out), fmi2Status::OK, "{:?}", s.take_messages());
    assert!(out[0] < 0.0, "friction opposes the velocity: {}", out[0]);
    assert_eq!(call(x_v, vr::X, 1.0, &mut out), fmi2Status::Error);
    assert!(
        s.last_error().contains("\"valve.x_v\"") && s.last_error().contains("is not an output or a derivative"),
        "{}",
        s.last_error()
    );
    assert_eq!(call(vr::F, p3, 1.0, &mut out), fmi2Status::Error, "a state is no known in Co-Simulation");
    assert!(s.last_error().contains("known \"p3\""), "{}", s.last_error());
    // FMI 2.0, 2.1.9, Step Mode: "If <ModelStructure><Derivatives> is present, also the
    // variables listed here as state derivatives" are unknowns. Against a central difference of
    // the der() variable itself (the f64 right-hand side, not the dual numbers) over the stroke
    // input; 1e-5 relative: the difference's truncation error at a 1e-7 m step.
    assert_eq!(call(der_p3, vr::X, 1.0, &mut out), fmi2Status::OK, "{}", s.last_error());
    let x = s.real(vr::X);
    let h = 1e-7;
    let der_at = |x: f64| {
        assert_eq!(s.set_real(vr::X, x), fmi2Status::OK);
        s.real(der_p3)
    };
    let central = (der_at(x + h) - der_at(x - h)) / (2.0 * h);
    assert_eq!(s.set_real(vr::X, x), fmi2Status::OK);
    assert!((out[0] - central).abs() <= 1e-5 * central.abs(), "d der(p3)/dx: {} vs {central}", out[0]);
    assert_eq!(call(vr::F, vr::X, f64::NAN, &mut out), fmi2Status::Error);
    assert!(s.last_error().contains("dvKnown of \"cylinder.x\" = NaN"), "{}", s.last_error());
    let param = HydraulicCircuit::VARIABLES.iter().find(|v| v.causality == Causality::Parameter).unwrap().vr;
    assert_eq!(call(vr::F, param, 1.0, &mut out), fmi2Status::Error);
}

/// FMI 2.0 tables (3.2.3, 4.2.4: fmi2GetDirectionalDerivative in Initialization Mode) and 2.1.9
/// (there the unknowns are the InitialUnknowns, the knowns what Initialization Mode sets: a
/// parameter too), in Co-Simulation and Model Exchange. The rigid boom starts at rest, held by
/// the closed CBV: the piston carries the load and the rod side's start.p4 (eq. 2.72 at rest),
/// p3 A_p = F + p4 A_r, so dp3/d(start.p4) = A_r / A_p = 1 - (d_rod / d_piston)^2, from the
/// FMU's own bore and rod. 1e-6 relative: the central difference's error (~1e-10) and the
/// equilibrium solve's tolerance, far below the ratio's 0.5.
#[test]
fn initialization_mode_derivatives_follow_the_start_equilibrium() {
    let (start_p4, d_piston, d_rod) = (32, 120, 121);
    for fmu_type in [FMI2_COSIMULATION, FMI2_MODEL_EXCHANGE] {
        let s = common::Slave::<HydraulicBoom>::try_new("init", &boomsim::fmu::guid::guid::<HydraulicBoom>(), fmu_type)
            .unwrap();
        unsafe {
            assert_eq!(api::setup_experiment::<HydraulicBoom>(s.c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::OK);
            assert_eq!(api::enter_initialization_mode::<HydraulicBoom>(s.c), fmi2Status::OK);
        }
        assert_eq!(s.set_boolean(vr::FLEXIBLE, false), fmi2Status::OK);
        let ratio = 1.0 - (s.real(d_rod) / s.real(d_piston)).powi(2);
        let mut out = [f64::NAN];
        let status =
            unsafe { api::get_directional_derivative::<HydraulicBoom>(s.c, &vr::P3, 1, &start_p4, 1, &1.0, out.as_mut_ptr()) };
        assert_eq!(status, fmi2Status::OK, "{}", s.last_error());
        assert!((out[0] - ratio).abs() <= 1e-6 * ratio, "type {fmu_type}: dp3/dp4 = {} vs A_r/A_p = {ratio}", out[0]);
        // A local (an event indicator's variable) is no InitialUnknown.
        let status =
            unsafe { api::get_directional_derivative::<HydraulicBoom>(s.c, &vr::EVENT_U_REF, 1, &start_p4, 1, &1.0, out.as_mut_ptr()) };
        assert_eq!(status, fmi2Status::Error);
        assert!(s.last_error().contains("is not an InitialUnknown"), "{}", s.last_error());
        // Counts past the arrays are refused before they are read.
        let status = unsafe {
            api::get_directional_derivative::<HydraulicBoom>(s.c, &vr::P3, usize::MAX, &start_p4, 1, &1.0, out.as_mut_ptr())
        };
        assert_eq!(status, fmi2Status::Error);
        assert!(s.last_error().contains("vUnknown_ref: 18446744073709551615 elements announced"), "{}", s.last_error());
    }
}
