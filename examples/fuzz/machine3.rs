//! What the FMI 3.0 standard forbids, written from its text (not from the FMU's table): the
//! state machines of Co-Simulation (section 4.2.4) and Model Exchange (3.2.4), the variables
//! fmi3Set* may set in each state (2.3.3 and the `initial`/`causality`/`variability` rules of
//! 2.4.7), and the calls whose arguments cannot be right (unknown value references, a variable
//! of another type, nValues other than the number of scalars, NULL with elements announced, an
//! Enumeration set to a value that is no item, 2.4.7.4). Enumerations are read and written with
//! fmi3GetInt64 and fmi3SetInt64 only: fmi3GetInt32 on one is a call on another type, and so is
//! fmi3GetInt64 on an Int32.
//! A call forbidden here must return fmi3Error. Where the text leaves room, nothing is claimed.
//! Issue 25 adds: counts larger than the model allows (`oversized`, in any state), fmi3SetTime
//! in Continuous-Time Mode only and not before the startTime (`View::set_time_refusal`), and
//! continuous-time states settable in Continuous-Time Mode (FMI 3.0.2, 3.2.4). The rules of a
//! Clock are `clock_rules`'.

use crate::model_description::{Description, Type};
use crate::ops::Arr;
use crate::ops3::{Access, Op3, OTHER_TYPES};
use crate::oversized::{too_many_refs, wrong_size};
use crate::view::{Phase, View};

/// Why the call must fail, if it must: `view` is the instance's, `me` its interface.
/// `event_mode`: a Co-Simulation instance with eventModeUsed.
pub fn forbidden(op: &Op3, view: &View, (me, event_mode): (bool, bool), m: &Description) -> Option<String> {
    count_error(op, me, m)
        .or_else(|| state_error(op, view, (me, event_mode), m))
        .or_else(|| crate::clock_rules::forbidden(op, view, m))
}

/// Counts larger than the model allows, in any state (issue 25 item 1): value-reference lists
/// longer than the model has variables, more log categories than it declares, nx and ni other
/// than its numbers of states and event indicators.
fn count_error(op: &Op3, me: bool, m: &Description) -> Option<String> {
    let states = |n: usize| if me { wrong_size(n, m.states, "continuous states") } else { None };
    match op {
        Op3::Oversized(o) => Some(o.why(m)),
        Op3::Derivative { unknowns, knowns, .. } => too_many_refs(unknowns.len(), m).or_else(|| too_many_refs(knowns.len(), m)),
        Op3::SetDebugLogging { categories, .. } => crate::machine2::too_many_categories(categories.len(), m),
        Op3::SetContinuousStates { x } => states(x.len()),
        Op3::GetContinuousStateDerivatives { n, .. }
        | Op3::GetContinuousStates { n, .. }
        | Op3::GetNominalsOfContinuousStates { n, .. } => states(*n),
        Op3::GetEventIndicators { n, .. } if me => wrong_size(*n, m.event_indicators, "event indicators"),
        _ => op.access().and_then(|a| too_many_refs(a.vr.len(), m)),
    }
}

/// What the state machines forbid in the instance's state (certain, else nothing).
fn state_error(op: &Op3, view: &View, (me, event_mode): (bool, bool), m: &Description) -> Option<String> {
    use Phase::*;
    let phase = view.phase;
    let phase_name = match phase {
        StepComplete | StepFailed => "Step Mode",
        Instantiated => "Instantiated",
        Initialization => "Initialization Mode",
        EventMode => "Event Mode",
        ContinuousTime => "Continuous-Time Mode",
        Terminated => "Terminated",
        Unknown | Broken => return None,
    };
    let step = matches!(phase, StepComplete | StepFailed);
    let state = |allowed: bool| (!allowed).then(|| format!("not allowed in {phase_name}"));
    let me_only = |allowed: bool| if me { state(allowed) } else { Some("a Model Exchange function on a Co-Simulation instance".into()) };
    let cs_only = |allowed: bool| if me { Some("a Co-Simulation function on a Model Exchange instance".into()) } else { state(allowed) };
    if let Some(a) = op.access() {
        let allowed = if a.set { phase != Terminated } else { phase != Instantiated };
        let values = || argument_error(&a, m).or_else(|| setter_error(&a, phase, m)).or_else(|| item_error(op, m));
        return state(allowed).or_else(values);
    }
    match op {
        Op3::EnterInitializationMode(_) => state(phase == Instantiated),
        Op3::ExitInitializationMode => state(phase == Initialization),
        // Co-Simulation enters Event Mode from Step Mode only with eventModeUsed (4.2.2).
        Op3::EnterEventMode if !me && !event_mode => Some("fmi3EnterEventMode without eventModeUsed".into()),
        Op3::EnterEventMode if !me => state(phase == StepComplete),
        Op3::EnterEventMode => state(!matches!(phase, Instantiated | Initialization | Terminated)),
        Op3::Terminate => state(matches!(phase, EventMode | ContinuousTime) || step),
        Op3::OtherType { ty, vr, .. } => {
            let known = vr.len() > 0 && !matches!(OTHER_TYPES[*ty], "Binary" | "Clock");
            known.then(|| format!("no variable is a {}", OTHER_TYPES[*ty]))
        }
        Op3::Refused { .. } => Some("not provided by this FMU (modelDescription.xml)".into()),
        Op3::SetClock { .. } => state(phase != Terminated),
        Op3::Derivative { adjoint: true, .. } if !m.adjoint => Some("providesAdjointDerivatives=\"false\"".into()),
        Op3::Derivative { .. } => state(phase != Instantiated),
        Op3::EnterStepMode => cs_only(event_mode && phase == EventMode),
        Op3::DoStep { .. } => cs_only(step),
        Op3::UpdateDiscreteStates { .. } if event_mode => state(phase == EventMode),
        Op3::UpdateDiscreteStates { .. } | Op3::EnterContinuousTimeMode => me_only(phase == EventMode),
        Op3::CompletedIntegratorStep { .. } => me_only(phase == ContinuousTime),
        Op3::SetTime { t } => me_only(true).or_else(|| view.set_time_refusal(*t)),
        Op3::SetContinuousStates { .. } => {
            me_only(!matches!(phase, Instantiated | Initialization | Terminated))
        }
        Op3::GetContinuousStateDerivatives { .. }
        | Op3::GetEventIndicators { .. }
        | Op3::GetContinuousStates { .. }
        | Op3::GetNominalsOfContinuousStates { .. } => me_only(phase != Instantiated),
        _ => None,
    }
}

/// Get and set arguments that cannot be right in any state.
fn argument_error(&Access { vr, n_values, ty, .. }: &Access, m: &Description) -> Option<String> {
    if n_values != vr.len() {
        return Some(format!("nValues = {n_values} for {} scalar variables", vr.len()));
    }
    let Arr::Items(refs) = vr else {
        return (vr.len() > 0).then(|| "valueReferences is NULL".into());
    };
    refs.iter().find_map(|&r| match m.variable(r) {
        None => Some(format!("vr {r} is no variable")),
        Some(v) if v.ty != ty => Some(format!("{} is of another type", v.name)),
        _ => None,
    })
}

/// Variables fmi3Set* may not set in `phase`: the independent variable, calculated values and
/// constants always, but continuous-time states in Continuous-Time Mode (FMI 3.0.2, 3.2.4);
/// after initialisation fixed parameters; in Continuous-Time Mode all but continuous inputs and
/// continuous-time states.
fn setter_error(a: &Access, phase: Phase, m: &Description) -> Option<String> {
    let (Arr::Items(refs), true) = (a.vr, a.set) else { return None };
    let initialised = !matches!(phase, Phase::Instantiated | Phase::Initialization);
    refs.iter().filter_map(|&r| m.variable(r)).find_map(|v| {
        let calculated = v.initial.as_deref().map_or(matches!(v.causality.as_str(), "output" | "local" | "calculatedParameter"), |i| i == "calculated");
        let state = phase == Phase::ContinuousTime && m.state_vrs.contains(&v.vr);
        let never = v.causality == "independent" || v.variability == "constant" || (calculated && !state);
        let fixed = initialised && v.causality == "parameter" && v.variability != "tunable";
        let continuous_input = v.causality == "input" && v.variability == "continuous";
        let not_now = phase == Phase::ContinuousTime && !continuous_input && !state;
        (never || fixed || not_now).then(|| format!("{} cannot be set in this state", v.name))
    })
}

/// An Enumeration set to a value that is no item of its type: outside its [min, max] (FMI 3.0
/// 2.4.7.4), such as one beyond the Int32 range or one that only truncates to an item.
fn item_error(op: &Op3, m: &Description) -> Option<String> {
    let Op3::SetInt64 { vr: Arr::Items(refs), values: Arr::Items(values) } = op else { return None };
    refs.iter().zip(values).find_map(|(&r, &x)| {
        let v = m.variable(r).filter(|v| v.ty == Type::Enumeration && !v.holds(x as f64))?;
        Some(format!("{} = {x} is no item (outside [{}, {}])", v.name, v.min, v.max))
    })
}
