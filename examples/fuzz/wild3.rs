//! FMI 3.0 calls an importer can get wrong: the value generators of `wild` (unknown value
//! references, wrong types, out-of-range values, NaN, ±Inf, NULL arrays, freed and foreign FMU
//! states, damaged serialized states, any step) through the FMI 3.0 functions, plus nValues that
//! differ from the number of value references, fmi3Boolean bytes other than 0 and 1, Int64
//! values of Enumerations that are no item (beyond the Int32 range, too), the types no variable
//! has, the functions the FMUs do not provide, any function in any state, and instantiations
//! with a wrong token, name, eventModeUsed or intermediate variables; counts far larger than the
//! arrays (`oversized`); a Clock set or read with any values and references.

use crate::model_description::{Description, Type, Variable};
use crate::ops::{Arr, Text};
use crate::ops3::{Instantiation3, Interface3, Op3, OTHER_TYPES, REFUSED};
use crate::oversized::Oversized;
use crate::rng::Rng;
use crate::session3::Session3;
use crate::wild::{
    any_vr, array, bad_guid, categories, maybe_null, variables_of, vrs, wild_count, wild_experiment, wild_integer,
    wild_real, wild_state_call, wild_states, wild_step, wild_text, wild_values, INSTANCE_NAMES, ME_SHARE,
};

/// Any of the functions with any arguments (fmi3FreeInstance through a second instance).
pub fn wild3(rng: &mut Rng, s: &Session3) -> Op3 {
    let m = s.model;
    let real = Type::Real;
    match rng.below(34) {
        32..=33 => Op3::Oversized(Oversized::draw(rng, m, true)),
        0 => Op3::GetVersion,
        1 => Op3::SetDebugLogging { logging_on: rng.chance(0.5), categories: categories(rng, m) },
        2 => Op3::Instantiate(instantiation3(rng, m)),
        3 => Op3::EnterInitializationMode(wild_experiment(rng)),
        4 => Op3::ExitInitializationMode,
        5 => Op3::EnterEventMode,
        6 => Op3::Terminate,
        7 => Op3::Reset,
        8..=11 => {
            let (ty, of) = (*rng.pick(m.types()), *rng.pick(m.types()));
            let vr = vrs(rng, m, of);
            let n_values = n_values(rng, vr.len());
            let null_values = rng.chance(0.05);
            match ty {
                Type::Real => Op3::GetFloat64 { vr, n_values, null_values },
                Type::Integer => Op3::GetInt32 { vr, n_values, null_values },
                Type::Enumeration => Op3::GetInt64 { vr, n_values, null_values },
                Type::Boolean => Op3::GetBoolean { vr, n_values, null_values },
                Type::String => Op3::GetString { vr, n_values, null_values },
            }
        }
        12..=15 => wild_set3(rng, m),
        16 => match (rng.below(OTHER_TYPES.len()), rng.chance(0.5), vrs(rng, m, real)) {
            (CLOCK, set, vr) if m.clock.is_some() => wild_clock(rng, m, set, vr),
            (ty, set, vr) => Op3::OtherType { ty, set, vr },
        },
        17 => Op3::Refused { function: rng.below(REFUSED.len()) },
        18..=20 => Op3::State(wild_state_call(rng, &s.states)),
        21 => {
            let (unknowns, knowns) = (vrs(rng, m, real), vrs(rng, m, real));
            let n_seed = n_values(rng, knowns.len());
            let seed = array(rng, n_seed, |r| wild_real(r, None));
            let n_sensitivity = n_values(rng, unknowns.len());
            let (adjoint, null_sensitivity) = (rng.chance(0.5), rng.chance(0.1));
            Op3::Derivative { adjoint, unknowns, knowns, seed, n_sensitivity, null_sensitivity }
        }
        22 => Op3::EnterStepMode,
        23 => {
            let (t, h) = wild_step(rng, &s.view, s.budget());
            Op3::DoStep { t, h, no_set_prior: rng.chance(0.5), null_outputs: rng.chance(0.05) }
        }
        24 => match rng.below(3) {
            0 => Op3::EnterContinuousTimeMode,
            1 => Op3::UpdateDiscreteStates { null_flags: rng.chance(0.3) },
            _ => Op3::CompletedIntegratorStep { no_set_prior: rng.chance(0.5), null_flags: rng.chance(0.3) },
        },
        25 => Op3::SetTime { t: wild_real(rng, None) },
        26 => Op3::SetContinuousStates { x: wild_states(rng, m, &s.x) },
        27 => match rng.below(3) {
            0 => Op3::GetContinuousStateDerivatives { n: wild_count(rng, m.states), null: rng.chance(0.1) },
            1 => Op3::GetContinuousStates { n: wild_count(rng, m.states), null: rng.chance(0.1) },
            _ => Op3::GetNominalsOfContinuousStates { n: wild_count(rng, m.states), null: rng.chance(0.1) },
        },
        28 => Op3::GetEventIndicators { n: wild_count(rng, m.event_indicators), null: rng.chance(0.1) },
        29 => Op3::GetNumberOfContinuousStates { null: rng.chance(0.2) },
        30 => Op3::GetNumberOfEventIndicators { null: rng.chance(0.2) },
        _ => Op3::Instantiate(Instantiation3 { interface: Interface3::ScheduledExecution, ..instantiation3(rng, m) }),
    }
}

/// The index of Clock in `OTHER_TYPES`.
const CLOCK: usize = OTHER_TYPES.len() - 1;

/// fmi3SetClock or (`set` false) fmi3GetClock of a model with a Clock: mostly of the Clock alone,
/// else of `vr` (Reals, unknown references), with the Clock among them now and then; set to
/// true, false or a byte that is neither.
fn wild_clock(rng: &mut Rng, m: &Description, set: bool, vr: Arr<u32>) -> Op3 {
    let clock = m.clock.as_ref().map_or(0, |c| c.vr);
    let vr = match (rng.below(4), vr) {
        (0..=1, _) => Arr::Items(vec![clock]),
        (2, Arr::Items(mut v)) => {
            v.insert(rng.below(v.len() + 1), clock);
            Arr::Items(v)
        }
        (_, vr) => vr,
    };
    match set {
        true => Op3::SetClock { values: array(rng, vr.len(), |r| *r.pick(&[1, 1, 1, 0, 2, 255])), vr },
        false => Op3::GetClock { vr, null_values: rng.chance(0.1) },
    }
}

/// nValues for `n` value references: mostly `n`, else one off, 0 or twice.
fn n_values(rng: &mut Rng, n: usize) -> usize {
    match rng.below(12) {
        0 => n + 1,
        1 => n.saturating_sub(1),
        2 => 0,
        3 => 2 * n,
        _ => n,
    }
}

/// fmi3Set<type> of any type with any value references, values and nValues.
fn wild_set3(rng: &mut Rng, m: &Description) -> Op3 {
    let ty = *rng.pick(m.types());
    let refs = (0..rng.range(0, 4)).map(|_| any_vr(rng, m, ty)).collect();
    let vr = maybe_null(rng, refs);
    let n = n_values(rng, vr.len());
    let mut vars: Vec<Option<&Variable>> = variables_of(m, &vr);
    vars.resize(n, None);
    match ty {
        Type::Real => Op3::SetFloat64 { values: wild_values(rng, &vars, wild_real), vr },
        Type::Integer => Op3::SetInt32 { values: wild_values(rng, &vars, wild_integer), vr },
        Type::Enumeration => Op3::SetInt64 { values: wild_values(rng, &vars, wild_int64), vr },
        Type::Boolean => Op3::SetBoolean { values: array(rng, n, |r| *r.pick(&[0, 1, 0, 1, 2, 255])), vr },
        Type::String => Op3::SetString { values: array(rng, n, |r| wild_text(r, m)), vr },
    }
}

/// Any Int64: those of `wild_integer`, an item (for an Enumeration) or its range's bound ± 1, an
/// item ± 2^32 or 2^31 (beyond the Int32 range; truncated, an item again), or the Int64 extremes.
fn wild_int64(rng: &mut Rng, var: Option<&Variable>) -> i64 {
    match (rng.below(6), var) {
        (0..=1, _) => i64::from(wild_integer(rng, var)),
        (2, Some(v)) => v.plausible(rng) as i64,
        (3, Some(v)) => *rng.pick(&[(v.min as i64).saturating_sub(1), (v.max as i64).saturating_add(1)]),
        (4, Some(v)) => (v.plausible(rng) as i64).wrapping_add(*rng.pick(&[1 << 32, -(1 << 32), 1 << 31])),
        _ => *rng.pick(&[i64::MAX, i64::MIN, i64::from(i32::MAX) + 1, i64::from(i32::MIN) - 1]),
    }
}

/// The main instantiation: Co-Simulation or (a third) Model Exchange, mostly valid (logMessage
/// sometimes NULL), now and then with a wrong token, an empty, NULL or non-UTF-8 name,
/// eventModeUsed or required intermediate variables.
pub fn instantiation3(rng: &mut Rng, m: &Description) -> Instantiation3 {
    let interface = if rng.chance(ME_SHARE) { Interface3::ModelExchange } else { Interface3::CoSimulation };
    let mut spec = Instantiation3 {
        interface,
        name: Text::new(rng.pick::<&str>(&INSTANCE_NAMES)),
        resources: rng.pick(&[Text::Null, Text::new("file:///tmp/"), Text::new("")]).clone(),
        visible: rng.chance(0.5),
        logging_on: rng.chance(0.2),
        early_return_allowed: rng.chance(0.3),
        logger: !rng.chance(0.1),
        ..Instantiation3::quiet(Text::new(&m.guid))
    };
    if m.clock.is_some() {
        // FMI 3.0, 2.3.1: "For FMUs that have clocks, eventModeUsed = fmi3True is required".
        spec.event_mode_used = !rng.chance(0.05);
    }
    if rng.chance(0.15) {
        match rng.below(5) {
            0 | 1 => spec.token = bad_guid(rng, &m.guid),
            2 => spec.name = rng.pick(&[Text::new(""), Text::Null, Text::bytes(b"\xff\xfe")]).clone(),
            3 => spec.event_mode_used = true,
            _ => {
                let required = m.outputs.iter().take(rng.range(1, 3)).copied().collect();
                spec.required_intermediate = maybe_null(rng, required);
            }
        }
    }
    spec
}

/// Whether the FMU must accept (`Some(true)`) or refuse (`Some(false)`) an instantiation:
/// accept with the model description's token and valid arguments, refuse with another token and
/// for Scheduled Execution, which the model description does not declare; `None`: not decided
/// by the standard's text alone (an unusual instance name, eventModeUsed, intermediate variables).
pub fn valid_instantiation(spec: &Instantiation3, m: &Description) -> Option<bool> {
    if spec.interface == Interface3::ScheduledExecution {
        return Some(false);
    }
    let token_right = matches!(&spec.token, Text::Bytes(t) if t.to_bytes() == m.guid.as_bytes());
    if !token_right {
        return Some(false);
    }
    let name_ok =
        matches!(&spec.name, Text::Bytes(n) if !n.to_bytes().is_empty() && std::str::from_utf8(n.to_bytes()).is_ok());
    // Event Mode where the model has it (hasEventMode), and with a Clock (2.3.1: required);
    // intermediate variables only with the intermediateUpdate callback, which the fuzzer never
    // passes.
    let event_mode_ok = if spec.event_mode_used { m.event_mode } else { m.clock.is_none() };
    let co_simulation_ok =
        spec.interface == Interface3::ModelExchange || (event_mode_ok && spec.required_intermediate.len() == 0);
    (name_ok && co_simulation_ok).then_some(true)
}
