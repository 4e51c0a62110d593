//! Calls an importer can get wrong: any function with unknown value references and wrong types,
//! values outside the range, NaN, ±Inf, ±DBL_MAX, denormals, NULL arrays (also with n = 0, which
//! is legal), calls in the wrong state, zero, negative, tiny and huge step sizes, communication
//! points that do not match, input derivatives of any order and size, freed FMU states and states
//! of a second instance, serialized states with a flipped bit, truncated, extended, random, or
//! edited with the CRC recomputed, unknown log categories, NULL and non-UTF-8 strings; Model
//! Exchange calls with NULL or wrongly sized arrays, special states and times; counts far larger
//! than the arrays (`oversized`).

use crate::callbacks::Callbacks;
use crate::fmi2::{CO_SIMULATION, MODEL_EXCHANGE};
use crate::fmu_states::{FmuState, FmuStates, StateCall};
use crate::view::View;
use crate::model_description::{Description, Type, Variable};
use crate::ops::{Arr, Blob, Instantiation, Op, Slot, Text};
use crate::oversized::Oversized;
use crate::planner::Experiment;
use crate::rng::Rng;
use crate::session::Session;
use std::os::raw::c_int;
use std::ptr::null_mut;

pub const SPECIAL_REALS: [f64; 14] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MAX,
    f64::MIN,
    1e-300,
    -1e-300,
    5e-324,
    f64::MIN_POSITIVE,
    0.0,
    -0.0,
    1.0,
    -1.0,
    1e300,
];
pub const SPECIAL_INTEGERS: [c_int; 8] = [0, 1, -1, 2, c_int::MIN, c_int::MAX, 1000, -1000];
const SPECIAL_BOOLEANS: [c_int; 6] = [0, 1, 2, -1, 255, c_int::MIN];
const STATUS_KINDS: [c_int; 7] = [0, 1, 2, 3, 4, -1, 99];
/// The share of sequences on a Model Exchange instance (both versions).
pub const ME_SHARE: f64 = 1.0 / 3.0;
/// Valid instance names, some unusual.
pub const INSTANCE_NAMES: [&str; 6] = ["fuzz", "fuzz", "fuzz", "B\u{f6}\u{f6}m", "%s%n%s", "a.b[1]"];

/// Any of the functions with any arguments (fmi2FreeInstance through a second instance).
pub fn wild(rng: &mut Rng, s: &Session) -> Op {
    let m = s.model;
    let real = Type::Real;
    match rng.below(40) {
        38..=39 => Op::Oversized(Oversized::draw(rng, m, false)),
        0 => Op::GetTypesPlatform,
        1 => Op::GetVersion,
        2 => Op::SetDebugLogging { logging_on: wild_boolean(rng), categories: categories(rng, m) },
        3 => Op::Instantiate(instantiation(rng, m)),
        4 => wild_setup(rng),
        5 => Op::EnterInitializationMode,
        6 => Op::ExitInitializationMode,
        7 => Op::Terminate,
        8 => Op::Reset,
        9 => Op::GetReal { vr: vrs(rng, m, real), null_values: rng.chance(0.05) },
        10 => Op::GetInteger { vr: vrs(rng, m, Type::Integer), null_values: rng.chance(0.05) },
        11 => Op::GetBoolean { vr: vrs(rng, m, Type::Boolean), null_values: rng.chance(0.05) },
        12 => Op::GetString { vr: vrs(rng, m, Type::String), null_values: rng.chance(0.05) },
        13..=16 => {
            let ty = *rng.pick(m.types());
            wild_set(rng, m, ty)
        }
        17..=22 => Op::State(wild_state_call(rng, &s.states)),
        23 => {
            let (unknowns, knowns) = (vrs(rng, m, real), vrs(rng, m, real));
            let dv_known = array(rng, knowns.len(), |r| wild_real(r, None));
            Op::GetDirectionalDerivative { unknowns, knowns, dv_known, null_dv_unknown: rng.chance(0.1) }
        }
        24 => {
            let vr = vrs(rng, m, real);
            let orders = array(rng, vr.len(), |r| *r.pick(&[1, 1, 1, 0, 2, -1, c_int::MAX]));
            Op::SetRealInputDerivatives { values: wild_values(rng, &variables_of(m, &vr), wild_real), orders, vr }
        }
        25 => {
            let vr = vrs(rng, m, real);
            let orders = array(rng, vr.len(), |r| *r.pick(&[1, 0, 2, -1]));
            Op::GetRealOutputDerivatives { vr, orders, null_values: rng.chance(0.1) }
        }
        26 => {
            let (t, h) = wild_step(rng, &s.view, s.budget());
            Op::DoStep { t, h, no_set_prior: *rng.pick(&[0, 1, 2]) }
        }
        27 => Op::CancelStep,
        28 => Op::GetStatus { kind: *rng.pick(&STATUS_KINDS), null_value: rng.chance(0.1) },
        29 => Op::GetRealStatus { kind: *rng.pick(&STATUS_KINDS), null_value: rng.chance(0.1) },
        30 => Op::GetIntegerStatus { kind: *rng.pick(&STATUS_KINDS), null_value: rng.chance(0.1) },
        31 => Op::GetBooleanStatus { kind: *rng.pick(&STATUS_KINDS), null_value: rng.chance(0.1) },
        32 => Op::GetStringStatus { kind: *rng.pick(&STATUS_KINDS), null_value: rng.chance(0.1) },
        33 => match rng.below(4) {
            0 => Op::EnterEventMode,
            1 => Op::EnterContinuousTimeMode,
            2 => Op::NewDiscreteStates { null_info: rng.chance(0.3) },
            _ => Op::CompletedIntegratorStep { no_set_prior: wild_boolean(rng), null_flags: rng.chance(0.3) },
        },
        34 => Op::SetTime { t: wild_real(rng, None) },
        35 => Op::SetContinuousStates { x: wild_states(rng, m, &s.x) },
        36 => match rng.below(3) {
            0 => Op::GetDerivatives { n: wild_count(rng, m.states), null: rng.chance(0.1) },
            1 => Op::GetContinuousStates { n: wild_count(rng, m.states), null: rng.chance(0.1) },
            _ => Op::GetNominalsOfContinuousStates { n: wild_count(rng, m.states), null: rng.chance(0.1) },
        },
        _ => Op::GetEventIndicators { n: wild_count(rng, m.event_indicators), null: rng.chance(0.1) },
    }
}

/// Continuous states to set: a wild count of them, mostly the last ones read (`x`), else wild
/// numbers; now and then NULL.
pub fn wild_states(rng: &mut Rng, m: &Description, x: &[f64]) -> Arr<f64> {
    let n = wild_count(rng, m.states);
    let x: Vec<f64> =
        (0..n).map(|k| if rng.chance(0.7) { x.get(k).copied().unwrap_or(0.0) } else { wild_real(rng, None) }).collect();
    maybe_null(rng, x)
}

/// A count announced for an array of `n`: mostly `n`, else 0, one off, or far off.
pub fn wild_count(rng: &mut Rng, n: usize) -> usize {
    match rng.below(10) {
        0..=5 => n,
        6 => 0,
        7 => n + 1,
        8 => n.saturating_sub(1),
        _ => rng.range(0, 200),
    }
}

/// The main fmi2Instantiate: mostly valid (logger and memory callbacks sometimes NULL), now and
/// then with a wrong GUID, an empty, NULL or non-UTF-8 name, another fmuType or NULL functions;
/// a third of them for Model Exchange.
pub fn instantiation(rng: &mut Rng, m: &Description) -> Instantiation {
    let mut spec = Instantiation {
        name: Text::new(rng.pick::<&str>(&INSTANCE_NAMES)),
        fmu_type: if rng.chance(ME_SHARE) { MODEL_EXCHANGE } else { CO_SIMULATION },
        guid: Text::new(&m.guid),
        resources: rng.pick(&[Text::Null, Text::new("file:///tmp/"), Text::new("")]).clone(),
        callbacks: Some(Callbacks { logger: !rng.chance(0.1), memory: !rng.chance(0.2) }),
        visible: c_int::from(rng.chance(0.5)),
        logging_on: c_int::from(rng.chance(0.2)),
    };
    if rng.chance(0.15) {
        match rng.below(5) {
            0 => spec.guid = bad_guid(rng, &m.guid),
            1 => spec.name = rng.pick(&[Text::new(""), Text::Null]).clone(),
            2 => spec.fmu_type = *rng.pick(&[2, -1, c_int::MAX]),
            3 => spec.callbacks = None,
            _ => spec.name = Text::bytes(b"\xff\xfe"),
        }
    }
    spec
}

/// A GUID that is not this model's.
pub fn bad_guid(rng: &mut Rng, guid: &str) -> Text {
    match rng.below(5) {
        0 => Text::Null,
        1 => Text::new(""),
        2 => {
            let mut b = guid.as_bytes().to_vec();
            let i = rng.below(b.len());
            b[i] = if b[i] == b'0' { b'1' } else { b'0' };
            Text::bytes(&b)
        }
        3 => Text::new(guid.trim_matches(|c| c == '{' || c == '}')),
        _ => Text::new(&format!("{guid} ")),
    }
}

/// Any Real: special values, the variable's bounds and just beyond, or any magnitude.
pub fn wild_real(rng: &mut Rng, var: Option<&Variable>) -> f64 {
    match (rng.below(8), var) {
        (0..=2, _) => *rng.pick(&SPECIAL_REALS),
        (3..=4, Some(v)) => v.edge(rng),
        (5, Some(v)) => v.plausible(rng),
        _ => {
            let x = 10f64.powf(rng.uniform(-320.0, 308.0));
            x.copysign(if rng.chance(0.5) { -1.0 } else { 1.0 })
        }
    }
}

pub fn wild_integer(rng: &mut Rng, var: Option<&Variable>) -> c_int {
    match (rng.below(4), var) {
        (0..=1, _) => *rng.pick(&SPECIAL_INTEGERS),
        (2, Some(v)) => v.edge(rng) as c_int,
        (3, Some(v)) => v.plausible(rng) as c_int,
        _ => rng.next() as c_int,
    }
}

pub fn wild_boolean(rng: &mut Rng) -> c_int {
    if rng.chance(0.7) {
        rng.below(2) as c_int
    } else {
        *rng.pick(&SPECIAL_BOOLEANS)
    }
}

/// Any string: NULL, empty, a log category, not UTF-8, printf directives, very long.
pub fn wild_text(rng: &mut Rng, m: &Description) -> Text {
    match rng.below(8) {
        0 => Text::Null,
        1 => Text::new(""),
        2 => Text::new(rng.choose(&m.categories).map_or("logAll", |c| c.as_str())),
        3 => Text::new("logNoSuchCategory"),
        4 => Text::bytes(b"\xff\xfe not UTF-8"),
        5 => Text::new("%s%n%s%n"),
        6 => Text::new(&"x".repeat(4096)),
        _ => Text::new("fuzz"),
    }
}

/// Items, or NULL announcing as many now and then.
pub fn maybe_null<T>(rng: &mut Rng, items: Vec<T>) -> Arr<T> {
    if rng.chance(0.05) {
        Arr::Null(items.len())
    } else {
        Arr::Items(items)
    }
}

/// `n` generated elements, or NULL for them now and then.
pub fn array<T>(rng: &mut Rng, n: usize, mut item: impl FnMut(&mut Rng) -> T) -> Arr<T> {
    let items = (0..n).map(|_| item(rng)).collect();
    maybe_null(rng, items)
}

/// Values for `vars`, each drawn by `value` (which knows its variable, if any), or NULL for them
/// now and then.
pub fn wild_values<T>(
    rng: &mut Rng,
    vars: &[Option<&Variable>],
    value: fn(&mut Rng, Option<&Variable>) -> T,
) -> Arr<T> {
    let items = vars.iter().map(|&v| value(rng, v)).collect();
    maybe_null(rng, items)
}

/// A value reference for a function on type `ty`: mostly of that type, else of another type,
/// one past the largest, or any number.
pub fn any_vr(rng: &mut Rng, m: &Description, ty: Type) -> u32 {
    let any = rng.next() as u32;
    match rng.below(10) {
        0..=5 if !m.of_type(ty).is_empty() => *rng.pick(m.of_type(ty)),
        0..=7 => rng.pick(&m.variables).vr,
        8 => m.max_vr.saturating_add(1 + rng.below(100) as u32),
        _ => *rng.pick(&[u32::MAX, 0x8000_0000, any]),
    }
}

/// Value references for a function on type `ty`: none, a few, many, or all of the type.
pub fn vrs(rng: &mut Rng, m: &Description, ty: Type) -> Arr<u32> {
    let list = match rng.below(20) {
        0 => Vec::new(),
        1..=2 if !m.of_type(ty).is_empty() => m.of_type(ty).to_vec(),
        3 => (0..rng.range(5, 40)).map(|_| any_vr(rng, m, ty)).collect(),
        _ => (0..rng.range(1, 4)).map(|_| any_vr(rng, m, ty)).collect(),
    };
    maybe_null(rng, list)
}

/// The variables behind value references (`None` for unknown ones and NULL arrays).
pub fn variables_of<'m>(m: &'m Description, vr: &Arr<u32>) -> Vec<Option<&'m Variable>> {
    match vr {
        Arr::Items(v) => v.iter().map(|&r| m.variable(r)).collect(),
        Arr::Null(n) => vec![None; *n],
    }
}

/// fmi2Set<ty> with any value references and values.
fn wild_set(rng: &mut Rng, m: &Description, ty: Type) -> Op {
    let vr = vrs(rng, m, ty);
    let vars = variables_of(m, &vr);
    match ty {
        Type::Real => Op::SetReal { values: wild_values(rng, &vars, wild_real), vr },
        // FMI 2.0's Enumerations are Integers (`model_description`): no Enumeration here.
        Type::Integer | Type::Enumeration => Op::SetInteger { values: wild_values(rng, &vars, wild_integer), vr },
        Type::Boolean => Op::SetBoolean { values: array(rng, vars.len(), wild_boolean), vr },
        Type::String => Op::SetString { values: array(rng, vars.len(), |r| wild_text(r, m)), vr },
    }
}

/// fmi2SetupExperiment with any tolerance, start and stop.
fn wild_setup(rng: &mut Rng) -> Op {
    let e = wild_experiment(rng);
    let (tolerance_defined, stop_defined) = (wild_boolean(rng), wild_boolean(rng));
    Op::SetupExperiment { tolerance_defined, tolerance: e.tolerance, start: e.start, stop_defined, stop: e.stop }
}

/// An experiment with any tolerance, start and stop.
pub fn wild_experiment(rng: &mut Rng) -> Experiment {
    let start = *rng.pick(&[0.0, 0.0, 1.0, -1.0, 1e9, f64::NAN, f64::INFINITY, -1e300, f64::MAX, 5e-324]);
    Experiment {
        tolerance_defined: rng.chance(0.5),
        tolerance: *rng.pick(&[1e-6, 1e-20, 0.0, -1e-6, f64::NAN, f64::INFINITY, 1e-300, 0.5, 1e-12, 1e-2]),
        start,
        stop_defined: rng.chance(0.5),
        stop: start + *rng.pick(&[0.1, 0.0, -1.0, f64::NAN, f64::INFINITY, f64::MAX, 1e-12, 1e3]),
    }
}

/// A communication point and step size for a doStep: any, bounded by the time budget.
pub fn wild_step(rng: &mut Rng, view: &View, budget: f64) -> (f64, f64) {
    let time = view.time;
    let tolerance = 1e-9 * time.abs().max(1.0);
    let t = match rng.below(10) {
        0..=5 => time,
        6 => time + tolerance * rng.uniform(-0.9, 0.9),
        7 => time + *rng.pick(&[1e-6, -1e-6, 1.0, -1.0, 1e3]),
        8 => *rng.pick(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]),
        _ => wild_real(rng, None),
    };
    let h = match rng.below(10) {
        0..=3 => rng.log_uniform(1e-4, 1e-2),
        4 => *rng.pick(&[0.0, -0.0]),
        5 => -rng.log_uniform(1e-6, 1.0),
        6 => *rng.pick(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]),
        7 => *rng.pick(&[1e-300, 5e-324, 1e-15, f64::MIN_POSITIVE]),
        8 => *rng.pick(&[1e3, 1e300, f64::MAX]),
        _ => wild_real(rng, None),
    };
    view.bounded_step(t, h, budget)
}

/// fmi2SetDebugLogging categories: mostly the model's own, sometimes anything.
pub fn categories(rng: &mut Rng, m: &Description) -> Arr<Text> {
    let n = rng.below(4);
    array(rng, n, |r| match r.choose(&m.categories) {
        Some(c) if r.chance(0.7) => Text::new(c),
        _ => wild_text(r, m),
    })
}

/// Any FMU state call: any state, slot, size and bytes.
pub fn wild_state_call(rng: &mut Rng, states: &FmuStates) -> StateCall {
    match rng.below(6) {
        0 => StateCall::Get { state: any_slot(rng, states) },
        1 => StateCall::Set { state: any_state(rng, states) },
        2 => StateCall::Free { state: any_slot(rng, states) },
        3 => StateCall::Size { state: any_state(rng, states), null_size: rng.chance(0.1) },
        4 => wild_serialize(rng, states),
        _ => StateCall::Deserialize { bytes: blob(rng, states), null_state: rng.chance(0.05) },
    }
}

/// An FMUstate argument: mostly a live state, sometimes a freed one, one of the second
/// instance, or NULL.
fn any_state(rng: &mut Rng, states: &FmuStates) -> FmuState {
    match rng.below(10) {
        0..=5 if !states.live.is_empty() => rng.pick(&states.live).ptr,
        0..=7 if !states.stale.is_empty() => *rng.pick(&states.stale),
        0..=8 if !states.foreign.is_empty() => *rng.pick(&states.foreign),
        _ => null_mut(),
    }
}

/// An FMUstate* argument: NULL, a variable holding NULL (a new state), or any state.
fn any_slot(rng: &mut Rng, states: &FmuStates) -> Slot {
    match rng.below(10) {
        0 => Slot::Null,
        1..=4 => Slot::Holding(null_mut()),
        _ => Slot::Holding(any_state(rng, states)),
    }
}

/// A serialize call with the right size, one off, or any.
fn wild_serialize(rng: &mut Rng, states: &FmuStates) -> StateCall {
    let state = any_state(rng, states);
    let known = states.live.iter().find(|l| l.ptr == state).and_then(|l| l.size);
    let size = match (rng.below(6), known) {
        (0..=2, Some(n)) => n,
        (3, Some(n)) => n + 1,
        (4, Some(n)) => n.saturating_sub(1),
        _ => *rng.pick(&[0, 1, 64, 100_000]),
    };
    StateCall::Serialize { state, size, null_buffer: rng.chance(0.1) }
}

/// Bytes for deserialization: a state this instance serialized, intact, damaged, or edited with
/// the CRC recomputed; or garbage.
pub fn blob(rng: &mut Rng, states: &FmuStates) -> Blob {
    let Some(saved) = rng.choose(&states.saved) else { return garbage(rng) };
    let mut bytes = saved.bytes.clone();
    let len = bytes.len();
    let (how, damaged) = match rng.below(20) {
        0..=7 => return saved.intact(),
        8..=10 => {
            let bit = rng.below(len * 8);
            bytes[bit / 8] ^= 1 << (bit % 8);
            (format!("bit {bit} flipped"), true)
        }
        11..=12 => {
            let n = rng.below(len);
            bytes.truncate(n);
            (format!("truncated to {n} bytes"), true)
        }
        13 => {
            let n = rng.range(1, 16);
            bytes.extend((0..n).map(|_| rng.next() as u8));
            (format!("{n} bytes appended"), true)
        }
        14..=17 if len > 4 => (format!("edited at byte {}, CRC recomputed", edit(rng, &mut bytes)), false),
        _ => return garbage(rng),
    };
    let bytes = maybe_null(rng, bytes);
    let damaged = damaged || matches!(bytes, Arr::Null(_));
    Blob { bytes, how, damaged, view: None }
}

/// Overwrites one or eight bytes before the CRC-32 trailer (the last four bytes) and recomputes
/// it: the FMU's checks of the content must catch what is wrong. The offset edited.
fn edit(rng: &mut Rng, bytes: &mut [u8]) -> usize {
    let body = bytes.len() - 4;
    let at = rng.below(body);
    if at + 8 <= body && rng.chance(0.5) {
        bytes[at..at + 8].copy_from_slice(&rng.pick(&SPECIAL_REALS).to_le_bytes());
    } else {
        bytes[at] = rng.next() as u8;
    }
    let crc = crc32fast::hash(&bytes[..body]);
    bytes[body..].copy_from_slice(&crc.to_le_bytes());
    at
}

/// Random bytes, some after the format's magic.
fn garbage(rng: &mut Rng) -> Blob {
    let mut bytes = if rng.chance(0.5) { b"BOOMSIM\0".to_vec() } else { Vec::new() };
    bytes.extend((0..rng.below(64)).map(|_| rng.next() as u8));
    Blob { bytes: maybe_null(rng, bytes), how: "random bytes".into(), damaged: true, view: None }
}
