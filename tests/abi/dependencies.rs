//! The declared dependencies of ModelStructure against the models themselves (FMI 2.0, 2.2.8):
//! perturbing an input changes exactly the outputs that declare it, after initialisation
//! (`<Outputs>`) and in Initialization Mode (`<InitialUnknowns>`). A dependency the XML omits
//! lets an importer order the calls wrongly; one it adds makes it see algebraic loops that are not
//! there (OMSimulator reported loops of size 2/4 and 4/10 without any). Each model is probed in
//! every configuration that changes its equations (port coupling, rigid/flexible), and a
//! dependency must show in at least one of them.

use crate::common;

use boomsim::fmu::instance::Instance;
use boomsim::fmu::variables::BaseType;
use boomsim_tools::xml::fmi2::initial_dependencies;
use boomsim::fmu::{Causality, Initial, Kind, Model, Value};
use boomsim::models::vr;
use boomsim::models::{BoomMechanics, HydraulicBoom, HydraulicCircuit, PressureFeedbackController};
use std::collections::{BTreeMap, BTreeSet};

type Deps = BTreeMap<&'static str, BTreeSet<&'static str>>;

fn instance<M: Model>(setup: &[(u32, Value)]) -> Instance<M> {
    common::in_initialization::<M>(setup)
}

/// Every Real the importer reads as an unknown (outputs; in Initialization Mode the initial
/// unknowns, the same rows here), by name.
fn unknowns<M: Model>(i: &mut Instance<M>) -> Vec<(&'static str, f64)> {
    M::VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output && v.initial != Initial::Exact)
        .map(|v| {
            let mut x = [f64::NAN];
            i.get(&[v.vr], &mut x, BaseType::Real, |v| if let Value::Real(x) = v { *x } else { f64::NAN }).unwrap();
            (v.name, x[0])
        })
        .collect()
}

/// An input moved by a small step inside its range (5 % of its magnitude, at least 1e-3).
fn perturbed(kind: Kind, x: f64) -> f64 {
    let Kind::Real { min, max, .. } = kind else { unreachable!("Real inputs only") };
    let dx = (0.05 * x.abs()).max(1e-3);
    if x + dx <= max {
        x + dx
    } else {
        (x - dx).max(min)
    }
}

/// The outputs that change when each input moves, after `steps` steps of 1 ms (none: in
/// Initialization Mode). Relative change above 1e-12: far above round-off of a recomputation
/// with identical inputs (which is bit-exact: the models are deterministic).
fn probe<M: Model>(setup: &[(u32, Value)], steps: usize, deps: &mut Deps) {
    let inputs: Vec<_> = M::VARIABLES.iter().filter(|v| v.causality == Causality::Input).collect();
    for input in inputs {
        let mut i = instance::<M>(setup);
        if steps > 0 {
            i.exit_initialization_mode().unwrap();
            for k in 0..steps {
                i.do_step(k as f64 * 1e-3, 1e-3).unwrap();
            }
        }
        let before = unknowns(&mut i);
        let Value::Real(x) = *i.core.values.at(i.core.values.position(input.vr).unwrap()) else { unreachable!() };
        i.set(&[input.vr], BaseType::Real, vec![Value::Real(perturbed(input.kind, x))]).unwrap();
        for ((name, a), (_, b)) in before.iter().zip(unknowns(&mut i)) {
            if (a - b).abs() > 1e-12 * a.abs().max(b.abs()).max(1e-300) {
                deps.entry(name).or_default().insert(input.name);
            }
        }
    }
}

/// The input dependencies a table declares (`<Outputs>`), or those among the initial
/// dependencies (`<InitialUnknowns>`; the rest are parameters).
fn declared<M: Model>(initial: bool) -> Deps {
    let name = |r: u32| M::VARIABLES.iter().find(|v| v.vr == r).unwrap();
    M::VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| {
            let d = if initial { initial_dependencies::<M>(v) } else { v.depends_on.to_vec() };
            let inputs = d.into_iter().map(name).filter(|k| k.causality == Causality::Input).map(|k| k.name).collect();
            (v.name, inputs)
        })
        .filter(|(_, d): &(_, BTreeSet<_>)| !d.is_empty())
        .collect()
}

fn check<M: Model>(configurations: &[&[(u32, Value)]]) {
    for (initial, steps) in [(false, 20), (true, 0)] {
        let mut found = Deps::new();
        for setup in configurations {
            probe::<M>(setup, steps, &mut found);
        }
        let what = if initial { "InitialUnknowns" } else { "Outputs" };
        assert_eq!(
            found,
            declared::<M>(initial),
            "{}: {what} dependencies on inputs (found, declared)",
            M::INFO.identifier
        );
    }
}

const LOWER: (u32, Value) = (vr::U_REF, Value::Real(-0.05));
const RIGID: (u32, Value) = (vr::FLEXIBLE, Value::Boolean(false));
const TLM: (u32, Value) = (boomsim::models::port::vr::COUPLING, Value::Integer(1));

#[test]
fn controller_dependencies_are_exact() {
    use boomsim::models::pressure_feedback_controller::vr as c;
    check::<PressureFeedbackController>(&[&[(c::P, Value::Real(40e5)), (c::U_REF, Value::Real(-0.05))]]);
}

#[test]
fn hydraulic_boom_dependencies_are_exact() {
    check::<HydraulicBoom>(&[&[LOWER, RIGID]]);
}

#[test]
fn hydraulic_circuit_dependencies_are_exact() {
    let moving = [LOWER, (vr::V, Value::Real(-0.01))];
    // The fitted friction law (eq. 5.4) is the one with a stroke term.
    let friction = HydraulicCircuit::VARIABLES.iter().find(|v| v.name == "friction.model").unwrap().vr;
    let fitted = [LOWER, (vr::V, Value::Real(-0.01)), (friction, Value::Integer(2))];
    check::<HydraulicCircuit>(&[&moving, &fitted, &[LOWER], &[LOWER, TLM]]);
}

#[test]
fn boom_mechanics_dependencies_are_exact() {
    check::<BoomMechanics>(&[&[RIGID, (vr::F, Value::Real(23e3))], &[RIGID, TLM]]);
}

/// The states' part of ModelStructure against the model along Co-Simulation runs (states the
/// generator's probe never sampled): every state or input that moves an output or a derivative
/// at any of these states is among its declared dependencies (`<Outputs>`, `<Derivatives>`).
/// Moves of 1e-3 and 1e-6 nominal, both signs, at 10 times per run; a change above 1e-12
/// relative counts (round-off of a recomputation is below 1e-15).
fn check_states<M: Model>(configurations: &[&[(u32, Value)]], steps: usize) {
    let declared = boomsim_tools::xml::fmi2::dependencies::<M>(&boomsim::fmu::structure::probe::<M>());
    let name = |r: u32| M::VARIABLES.iter().find(|v| v.vr == r).map_or("?", |v| v.name);
    let mut missing = BTreeSet::new();
    for setup in configurations {
        let mut i = instance::<M>(setup);
        i.exit_initialization_mode().unwrap();
        for k in 0..steps {
            i.do_step(k as f64 * 1e-3, 1e-3).unwrap();
            if (k + 1) % (steps / 10) != 0 {
                continue;
            }
            let values = i.core.values.clone();
            let mut model = M::clone(i.core.model.as_ref().unwrap());
            let mut x = vec![0.0; M::STATES.len()];
            model.continuous_states(&mut x);
            let base = boomsim::fmu::structure::unknowns(&model, &values);
            let moved = |known: u32, unknowns: Vec<(u32, f64)>, missing: &mut BTreeSet<_>| {
                for ((r, a), (_, b)) in base.iter().zip(unknowns) {
                    if (a - b).abs() > 1e-12 * a.abs().max(b.abs()).max(1e-300) && !declared[r].contains(&known) {
                        missing.insert((name(*r), name(known)));
                    }
                }
            };
            for (j, s) in M::STATES.iter().enumerate() {
                for d in [1e-3, -1e-3, 1e-6, -1e-6] {
                    let mut y = x.clone();
                    y[j] += d * s.nominal;
                    if model.set_continuous_states(&y).is_ok() {
                        moved(s.state, boomsim::fmu::structure::unknowns(&model, &values), &mut missing);
                    }
                }
            }
            model.set_continuous_states(&x).unwrap();
            for input in M::VARIABLES.iter().filter(|v| v.causality == Causality::Input) {
                let mut v = values.clone();
                v.set_real(input.vr, perturbed(input.kind, values.real(input.vr)));
                moved(input.vr, boomsim::fmu::structure::unknowns(&model, &v), &mut missing);
            }
        }
    }
    assert!(missing.is_empty(), "{}: undeclared (unknown, known): {missing:?}", M::INFO.identifier);
}

#[test]
fn model_exchange_dependencies_hold_along_runs() {
    use boomsim::models::pressure_feedback_controller::vr as c;
    let opening = (vr::U_REF, Value::Real(-0.3));
    check_states::<HydraulicBoom>(&[&[opening.clone(), RIGID], &[opening.clone()]], 500);
    check_states::<HydraulicCircuit>(&[&[opening.clone(), (vr::V, Value::Real(-0.01))]], 500);
    check_states::<BoomMechanics>(&[&[RIGID, (vr::F, Value::Real(23e3))], &[(vr::F, Value::Real(23e3))]], 500);
    check_states::<PressureFeedbackController>(&[&[(c::P, Value::Real(40e5))]], 100);
}
