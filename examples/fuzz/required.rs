//! Calls the standard allows in the instance's state with arguments that are right, which these
//! FMUs must carry out (fmi2OK/fmi3OK or a warning; issue 25 items 2, 3, 4 and 8). Both versions:
//! - a directional (FMI 3.0 also adjoint) derivative with seeds of at most 1000 in magnitude in
//!   Initialization Mode, of Real InitialUnknowns on Real inputs and variables with
//!   initial="exact" (FMI 2.0 3.2.3 and 4.2.4 tables, FMI 3.0 2.3.3), and in Co-Simulation Step
//!   Mode of outputs and the `der(...)` derivatives of ModelStructure on Real inputs (FMI 2.0
//!   2.1.9); where the model description provides them and the parameters keep their start
//!   values (others may not fit together, or choose a variant without derivatives);
//! - Model Exchange: setting continuous states by value reference to finite values in
//!   Continuous-Time Mode (FMI 2.0 rule 5 of 3.2.3 as clarified in 2.0.1; FMI 3.0.2 3.2.4);
//!   FMI 2.0 only: fmi2GetDerivatives and fmi2GetNominalsOfContinuousStates with the right nx
//!   in Initialization Mode (FMI 2.0 3.2.3's table), the parameters at their start values;
//! - the FMU state round trip (FMI 2.0 2.1.8, FMI 3.0 2.2.6.4): the serialized size of a live
//!   state, its serialization with that size, and deserializing intact bytes this instance
//!   serialized, in any state (also after a step that clamped an input at its bound and after
//!   fmi2SetTime backwards, which the planners lead to).

use crate::fmu_states::{FmuStates, StateCall};
use crate::model_description::Description;
use crate::ops::Arr;
use crate::view::{Phase, View};

/// A derivative call: its value references, seeds (per known; adjoint: per unknown) and whether
/// the other counts and output pointers are right.
pub struct Derivative<'a> {
    pub unknowns: &'a Arr<u32>,
    pub knowns: &'a Arr<u32>,
    pub seeds: &'a Arr<f64>,
    pub adjoint: bool,
    pub outputs_right: bool,
}

/// Why the derivative must succeed, if it must.
pub fn derivative(d: &Derivative, view: &View, me: bool, m: &Description) -> Option<&'static str> {
    let (Arr::Items(unknowns), Arr::Items(knowns), Arr::Items(seeds)) = (d.unknowns, d.knowns, d.seeds) else {
        return None;
    };
    let seeded = if d.adjoint { unknowns.len() } else { knowns.len() };
    let right = d.outputs_right && !unknowns.is_empty() && !knowns.is_empty() && seeds.len() == seeded;
    let provided = if d.adjoint { m.adjoint } else { m.directional };
    if !(provided && right && view.certain() && !view.tuned && seeds.iter().all(|s| s.abs() <= 1e3)) {
        return None;
    }
    let within = |list: &[u32], pool: &[u32]| list.iter().all(|r| pool.contains(r));
    match view.phase {
        Phase::Initialization if within(unknowns, &m.initial_unknowns) && within(knowns, &m.initial_knowns) => {
            Some("a derivative of InitialUnknowns on inputs and initial=\"exact\" variables in Initialization Mode")
        }
        Phase::StepComplete if !me && unknowns.iter().all(|r| m.outputs.contains(r) || m.derivatives.contains(r)) => {
            let inputs: Vec<u32> = m.real_inputs.iter().map(|&i| m.variables[i].vr).collect();
            within(knowns, &inputs).then_some("a derivative of outputs and der(...) on Real inputs in Step Mode")
        }
        _ => None,
    }
}

/// Why setting Reals must not be refused as unsettable, if it must not: continuous states of a
/// Model Exchange instance in Continuous-Time Mode, finite values (the model may still refuse a
/// state outside its domain, as fmi2SetContinuousStates does, naming it; not "cannot set").
pub fn state_set(vr: &Arr<u32>, values: &Arr<f64>, view: &View, me: bool, m: &Description) -> Option<&'static str> {
    if !crate::callbacks::last_error_says("cannot set") {
        return None;
    }
    let (Arr::Items(vr), Arr::Items(values)) = (vr, values) else { return None };
    let states = !vr.is_empty() && vr.len() == values.len() && vr.iter().all(|r| m.state_vrs.contains(r));
    let now = me && view.phase == Phase::ContinuousTime && view.certain();
    (states && now && values.iter().all(|x| x.is_finite()))
        .then_some("continuous states set by value reference in Continuous-Time Mode")
}

/// Why fmi2GetDerivatives or fmi2GetNominalsOfContinuousStates with `n` must succeed, if it
/// must: a Model Exchange instance in Initialization Mode, nx right, a buffer.
pub fn initialization_getter(n: usize, null: bool, view: &View, me: bool, m: &Description) -> Option<&'static str> {
    let now = me && view.phase == Phase::Initialization && view.certain() && !view.tuned;
    (now && n == m.states && !null).then_some("allowed in Initialization Mode (FMI 2.0 3.2.3)")
}

/// Whether setting these variables tunes a parameter (see `View::tuned`) other than
/// `boom.flexible`, which picks the model rather than a value.
pub fn tunes(vr: &Arr<u32>, m: &Description) -> bool {
    let Arr::Items(vr) = vr else { return false };
    let tuned = |&r: &u32| Some(r) != m.flexible && m.variable(r).is_some_and(|v| v.causality.ends_with("arameter"));
    vr.iter().any(tuned)
}

/// Why an FMU state call must succeed, if it must: the round trip's size, serialization and
/// deserialization.
pub fn state_call(call: &StateCall, states: &FmuStates) -> Option<&'static str> {
    let live = |p| states.live.iter().find(|l| l.ptr == p);
    match call {
        StateCall::Size { state, null_size: false } if live(*state).is_some() => {
            Some("the serialized size of a live FMU state")
        }
        StateCall::Serialize { state, size, null_buffer: false }
            if live(*state).is_some_and(|l| l.size == Some(*size)) =>
        {
            Some("serializing a live FMU state with its size")
        }
        StateCall::Deserialize { bytes, null_state: false } if !bytes.damaged && bytes.view.is_some() => {
            Some("deserializing intact bytes this instance serialized")
        }
        _ => None,
    }
}
