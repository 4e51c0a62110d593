//! The dependencies of ModelStructure (FMI 2.0, 2.2.8) on the continuous states, found from the
//! model itself: which outputs and derivatives change when a state or an input moves.
//!
//! The model is probed in each of its [`Model::configurations`] at a few states around its start
//! state (deterministic pseudo-random offsets of 0.5 to 1000 nominal values: pressures up to
//! 1000 bar, where the valves open) with random inputs around their start values inside their
//! ranges. A known is a dependency where moving it by a small step changes the unknown at any
//! sample (by more than round-off, see [`record`]). A dependency that shows only outside the
//! sampled states would be missed; `tests/dependencies.rs` probes other states, along runs.

use super::instance::start_values;
use super::model::Model;
use super::variables::{Causality, Kind, Values};
use std::collections::{BTreeMap, BTreeSet};

/// The probed dependencies, by value reference.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Structure {
    /// Per output, `der()` variable and event indicator: the states and inputs it depends on
    /// after initialisation.
    pub after: BTreeMap<u32, BTreeSet<u32>>,
    /// Per state and per `der()` variable: the inputs it depends on in Initialization Mode.
    pub initial: BTreeMap<u32, BTreeSet<u32>>,
}

/// Offsets of the samples from the start state, in nominal values, and samples per offset.
const SPREAD: [f64; 6] = [0.0, 0.5, 3.0, 30.0, 300.0, 1000.0];
const SAMPLES: usize = 8;

/// A small deterministic generator (SplitMix64) for the sample points, in [-1, 1].
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// The Real inputs of `M`: value reference, range.
fn inputs<M: Model>() -> Vec<(u32, f64, f64)> {
    M::VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .filter_map(|v| match v.kind {
            Kind::Real { min, max, .. } => Some((v.vr, min, max)),
            _ => None,
        })
        .collect()
}

/// A step for an input at `x` with range [min, max] that stays inside it.
fn input_step(x: f64, min: f64, max: f64) -> f64 {
    let dx = if (max - min).is_finite() { 1e-6 * (max - min) } else { 1e-3 * x.abs().max(1.0) };
    if x + dx <= max {
        x + dx
    } else {
        x - dx
    }
}

/// The unknowns after initialisation, by value reference: every output, the `der()` variables
/// and the event indicators.
pub fn unknowns<M: Model>(model: &M, values: &Values) -> Vec<(u32, f64)> {
    let mut v = values.clone();
    model.outputs(&mut v);
    let mut dx = vec![0.0; M::STATES.len()];
    model.derivatives(values, &mut dx);
    let mut z = vec![0.0; M::EVENT_INDICATORS.len()];
    model.event_indicators(values, &mut z);
    let outputs = M::VARIABLES.iter().filter(|x| x.causality == Causality::Output).map(|x| (x.vr, v.real(x.vr)));
    let derivatives = M::STATES.iter().zip(dx).map(|(s, d)| (s.derivative, d));
    outputs.chain(derivatives).chain(M::EVENT_INDICATORS.iter().copied().zip(z)).collect()
}

/// The initial unknowns a model built from `values` gives: its states and their derivatives.
fn initial_unknowns<M: Model>(values: &Values) -> Option<Vec<(u32, f64)>> {
    let v = start_values::<M>(values).ok()?;
    let states = M::STATES.iter().map(|s| (s.state, v.real(s.state)));
    Some(states.chain(M::STATES.iter().map(|s| (s.derivative, v.real(s.derivative)))).collect())
}

/// Records `known` for every unknown that differs between `a` and `b` by more than 1e-12
/// relative: far above the round-off of a state that passes through a change of coordinates (the
/// rigid boom's angle and stroke), far below what a step of 1e-3 nominal moves a dependency.
fn record(deps: &mut BTreeMap<u32, BTreeSet<u32>>, known: u32, a: &[(u32, f64)], b: &[(u32, f64)]) {
    for ((r, x), (_, y)) in a.iter().zip(b) {
        if (x - y).abs() > 1e-12 * x.abs().max(y.abs()).max(1e-300) {
            deps.entry(*r).or_default().insert(known);
        }
    }
}

/// Probes model `M` (see the module documentation).
pub fn probe<M: Model>() -> Structure {
    let mut out = Structure::default();
    let mut noise = Noise(0x5eed);
    let ins = inputs::<M>();
    for config in M::configurations() {
        let mut values = Values::new(M::VARIABLES);
        for (r, value) in &config {
            let i = values.position(*r).expect("configuration variable");
            values.put(i, value.clone());
        }
        // Initialization Mode: the inputs at their start values.
        if let Some(base) = initial_unknowns::<M>(&values) {
            for &(r, min, max) in &ins {
                let mut v = values.clone();
                v.set_real(r, input_step(v.real(r), min, max));
                if let Some(moved) = initial_unknowns::<M>(&v) {
                    record(&mut out.initial, r, &base, &moved);
                }
            }
        }
        let Ok(mut model) = M::initialize(&values) else { continue };
        let mut x0 = vec![0.0; M::STATES.len()];
        model.continuous_states(&mut x0);
        for spread in SPREAD.into_iter().flat_map(|s| std::iter::repeat_n(s, if s == 0.0 { 1 } else { SAMPLES })) {
            let x: Vec<f64> = x0.iter().zip(M::STATES).map(|(x, s)| x + spread * s.nominal * noise.next()).collect();
            let mut v = values.clone();
            // Inputs around their start values, as far as the states move (a third of the range
            // at 100 nominal values and beyond), inside their ranges.
            for &(r, min, max) in &ins {
                if (max - min).is_finite() {
                    let x = v.real(r) + (max - min) * (spread / 300.0).min(1.0) * noise.next();
                    v.set_real(r, x.clamp(min, max));
                }
            }
            if model.set_continuous_states(&x).is_err() {
                continue;
            }
            let base = unknowns(&model, &v);
            for (k, s) in M::STATES.iter().enumerate() {
                let mut moved = x.clone();
                moved[k] += 1e-3 * s.nominal;
                if model.set_continuous_states(&moved).is_ok() {
                    record(&mut out.after, s.state, &base, &unknowns(&model, &v));
                }
            }
            model.set_continuous_states(&x).expect("the sample state was accepted before");
            for &(r, min, max) in &ins {
                let mut moved = v.clone();
                moved.set_real(r, input_step(v.real(r), min, max));
                record(&mut out.after, r, &base, &unknowns(&model, &moved));
            }
        }
    }
    out
}
