//! Expectations the planners' probe paths set up and the next calls check (issue 25 items 4 and
//! 7), the same for both versions; each call that succeeded is `see`n, and any other call ends
//! the watch:
//! - the event-indicator locals (`event.*`) read by value reference equal the event indicators
//!   read right after (Model Exchange: fmi2GetEventIndicators, fmi3GetEventIndicators);
//! - in Co-Simulation, the locals change when the spool reference (`valve.u_ref`) is set to
//!   another value and a step is made: they are current after doSteps, not the values of
//!   initialisation;
//! - a continuous state set by its value reference (Model Exchange, Continuous-Time Mode) gives
//!   the states fmi2GetContinuousStates/fmi3GetContinuousStates returns right after; setting
//!   those states with the same value through fmi2SetContinuousStates/fmi3SetContinuousStates
//!   gives the same states again (the model may project states, e.g. the rigid boom's sections).

use crate::model_description::Description;

/// A call that succeeded, as far as the watch is concerned.
pub enum Seen<'a> {
    /// Reals read by value reference.
    Read(&'a [u32], &'a [f64]),
    /// Reals set by value reference.
    Set(&'a [u32], &'a [f64]),
    /// A step (fmi2DoStep, fmi3DoStep) with OK.
    Stepped,
    EventIndicators(&'a [f64]),
    ContinuousStates(&'a [f64]),
    /// fmi2SetContinuousStates, fmi3SetContinuousStates.
    SetStates(&'a [f64]),
    Other,
}

/// What is expected of the next calls.
#[derive(Default)]
pub enum Watch {
    #[default]
    Nothing,
    /// The event locals were read (and with them the spool reference, last).
    Locals { values: Vec<f64>, spool: Option<f64> },
    /// The spool reference was set to another value after the locals were read; `stepped`: a step followed.
    Spool { before: Vec<f64>, stepped: bool },
    /// The continuous state `index` was set to `value` by its value reference, and then the
    /// states read (`after`).
    State { index: usize, value: f64, after: Option<Vec<f64>> },
    /// Then the states were set with that value: the next read must give `after` again.
    Whole { index: usize, after: Vec<f64> },
}

/// Relative agreement of two numbers that should be computed alike.
fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-12)
}

impl Watch {
    /// Checks a call that succeeded against the watch and moves it on.
    pub fn see(&mut self, seen: Seen, m: &Description) -> Result<(), String> {
        let locals = &m.event_locals;
        let next = match (std::mem::take(self), seen) {
            (Watch::Spool { before, stepped: true }, Seen::Read(vr, now))
                if vr == &locals[..] && !locals.is_empty() =>
            {
                if before == now {
                    return Err(format!(
                        "the event locals {} read {now:?} after the spool reference changed and a step, as before it: not current",
                        names(m)
                    ));
                }
                Watch::Locals { values: now.to_vec(), spool: None }
            }
            (_, Seen::Read(vr, values)) if !locals.is_empty() && vr.starts_with(locals) => {
                let spool = match vr[locals.len()..] {
                    [r] if Some(r) == m.spool_reference => Some(values[locals.len()]),
                    [] => None,
                    _ => return Ok(()),
                };
                Watch::Locals { values: values[..locals.len()].to_vec(), spool }
            }
            (Watch::Locals { values, spool: Some(old) }, Seen::Set([r], [u]))
                if Some(*r) == m.spool_reference && *u != old =>
            {
                Watch::Spool { before: values, stepped: false }
            }
            (Watch::Spool { before, .. }, Seen::Stepped) => Watch::Spool { before, stepped: true },
            (Watch::Locals { values, .. }, Seen::EventIndicators(z)) => {
                if values.len() == z.len() && values.iter().zip(z).any(|(a, b)| !near(*a, *b)) {
                    return Err(format!(
                        "the event locals {} read {values:?}, but the event indicators are {z:?}",
                        names(m)
                    ));
                }
                Watch::Nothing
            }
            (_, Seen::Set([r], [x])) => match m.state_vrs.iter().position(|s| s == r) {
                Some(index) => Watch::State { index, value: *x, after: None },
                None => Watch::Nothing,
            },
            (Watch::State { index, value, after: None }, Seen::ContinuousStates(x)) => {
                Watch::State { index, value, after: Some(x.to_vec()) }
            }
            // The comparison: SetContinuousStates of the states the set by reference gave (the
            // other states as they were then), not any later set that happens to share the value.
            (Watch::State { index, value, after: Some(after) }, Seen::SetStates(x))
                if x.get(index) == Some(&value)
                    && x.len() == after.len()
                    && x.iter().zip(&after).enumerate().all(|(k, (a, b))| k == index || a == b) =>
            {
                Watch::Whole { index, after }
            }
            (Watch::Whole { index, after }, Seen::ContinuousStates(x)) => {
                if after.len() == x.len() && after.iter().zip(x).any(|(a, b)| !near(*a, *b)) {
                    let name = m.variable(m.state_vrs[index]).map_or("?", |v| v.name.as_str());
                    return Err(format!(
                        "setting the continuous state {name} by its value reference gave the states {after:?}, setting the same value with SetContinuousStates {x:?}"
                    ));
                }
                Watch::Nothing
            }
            _ => Watch::Nothing,
        };
        *self = next;
        Ok(())
    }
}

/// The event locals' names, for messages.
fn names(m: &Description) -> String {
    let names: Vec<&str> = m.event_locals.iter().filter_map(|&r| m.variable(r)).map(|v| v.name.as_str()).collect();
    names.join(", ")
}
