//! The planners' probe paths (issue 25 items 2, 4, 7 and 8), as calls of either version that
//! each planner turns into its own ops; `watch` and `required` check what they lead to:
//! - Co-Simulation: read the event locals with the spool reference, set it to another value,
//!   step, read the locals again (they must have changed);
//! - Model Exchange, Continuous-Time Mode: read the event locals, then the event indicators
//!   (equal); set a continuous state by its value reference, then read the states (set);
//!   fmi2SetTime/fmi3SetTime backwards, not before the startTime, then an FMU state round trip;
//! - the round trip: fmi*GetFMUState, its serialized size, serialization and deserialization of
//!   the bytes (all must succeed), also after a step that clamped an interpolated input.

use crate::fmu_states::{FmuStates, StateCall};
use crate::model_description::Description;
use crate::ops::Slot;
use crate::rng::Rng;
use crate::view::View;
use std::ptr::null_mut;

/// A call of a probe, for either version.
pub enum Probe {
    /// fmi2GetReal/fmi3GetFloat64 of these value references.
    Read(Vec<u32>),
    /// fmi2SetReal/fmi3SetFloat64.
    Set(Vec<u32>, Vec<f64>),
    DoStep {
        t: f64,
        h: f64,
    },
    GetContinuousStates,
    SetContinuousStates(Vec<f64>),
    GetEventIndicators,
    SetTime(f64),
}

/// Co-Simulation: the event locals change with the spool reference and a step of `h` (empty
/// for models without them).
pub fn spool(rng: &mut Rng, m: &Description, view: &View, h: f64) -> Vec<Probe> {
    let Some(u_ref) = m.spool_reference.filter(|_| !m.event_locals.is_empty()) else { return Vec::new() };
    let (lo, hi) = m.variable(u_ref).map_or((-1.0, 1.0), |v| v.span());
    let mut read = m.event_locals.clone();
    read.push(u_ref);
    vec![
        Probe::Read(read),
        Probe::Set(vec![u_ref], vec![rng.uniform(lo, hi)]),
        Probe::DoStep { t: view.time, h },
        Probe::Read(m.event_locals.clone()),
    ]
}

/// Model Exchange: the event locals equal the event indicators.
pub fn event_locals(m: &Description) -> Vec<Probe> {
    if m.event_locals.is_empty() {
        return Vec::new();
    }
    vec![Probe::Read(m.event_locals.clone()), Probe::GetEventIndicators]
}

/// Model Exchange, Continuous-Time Mode: a state near `x` (the states, just read) set by its
/// value reference, the states read, the same states set with SetContinuousStates, read again.
pub fn state_by_reference(rng: &mut Rng, m: &Description, x: &[f64]) -> Vec<Probe> {
    if x.len() != m.state_vrs.len() || x.is_empty() {
        return Vec::new();
    }
    let i = rng.below(x.len());
    let mut whole = x.to_vec();
    whole[i] = x[i] + (1e-6 + 1e-4 * x[i].abs()) * rng.uniform(-1.0, 1.0);
    vec![
        Probe::Set(vec![m.state_vrs[i]], vec![whole[i]]),
        Probe::GetContinuousStates,
        Probe::SetContinuousStates(whole),
        Probe::GetContinuousStates,
    ]
}

/// The probes of one step of an integrator in Continuous-Time Mode (both versions): now and
/// then the event locals, a state set by its value reference (the states read first where the
/// last ones are stale; `by_reference` remembers the wish), or the time set back with an FMU
/// state round trip after it.
pub fn integrating(
    rng: &mut Rng,
    m: &Description,
    (x, x_fresh): (&[f64], bool),
    (view, h): (&View, f64),
    by_reference: &mut bool,
    round_trip: &mut RoundTrip,
) -> Vec<Probe> {
    let pending = std::mem::take(by_reference) && x_fresh;
    match rng.below(100) {
        _ if pending => state_by_reference(rng, m, x),
        0..=2 => event_locals(m),
        3..=5 if x_fresh => state_by_reference(rng, m, x),
        3..=5 => {
            // The states first: the probe starts from them.
            *by_reference = true;
            vec![Probe::GetContinuousStates]
        }
        6..=7 => {
            round_trip.start();
            time_back(rng, view, h)
        }
        _ => Vec::new(),
    }
}

/// Model Exchange: the time set back by up to `h`, not before the startTime (the round trip
/// follows).
pub fn time_back(rng: &mut Rng, view: &View, h: f64) -> Vec<Probe> {
    if !(view.start.is_finite() && view.time.is_finite()) {
        return Vec::new();
    }
    vec![Probe::SetTime((view.time - h * rng.uniform(0.0, 1.0)).max(view.start))]
}

/// Where an FMU state round trip is: 0 none, else the next of its four calls.
#[derive(Default)]
pub struct RoundTrip(u8);

impl RoundTrip {
    pub fn start(&mut self) {
        self.0 = 1;
    }

    /// The next call of the round trip, if one is under way: a new state, its size, its
    /// serialization with that size, the bytes deserialized.
    pub fn next(&mut self, states: &FmuStates) -> Option<StateCall> {
        let last = states.live.last();
        let call = match (self.0, last) {
            (1, _) => StateCall::Get { state: Slot::Holding(null_mut()) },
            (2, Some(l)) => StateCall::Size { state: l.ptr, null_size: false },
            (3, Some(l)) if l.size.is_some() => {
                StateCall::Serialize { state: l.ptr, size: l.size.unwrap_or(0), null_buffer: false }
            }
            (4, _) if !states.saved.is_empty() => {
                let bytes = states.saved.last().map(|s| s.intact())?;
                StateCall::Deserialize { bytes, null_state: false }
            }
            _ => {
                self.0 = 0;
                return None;
            }
        };
        self.0 = (self.0 + 1) % 5;
        Some(call)
    }
}
