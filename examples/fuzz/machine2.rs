//! The calls the FMI 2.0 oracle says must fail with fmi2Error (and a log message, when the
//! instance has a logger). Fewer claims than FMI 3.0's `machine3`, and the instance stays usable
//! after a refused call (FMI 2.0 has no rule that an error terminates it):
//! - counts larger than the model allows (`oversized`): value-reference lists longer than the
//!   model has variables, nx and ni other than its numbers of states and event indicators,
//!   more log categories than it declares;
//! - Model Exchange: fmi2SetTime outside Continuous-Time Mode (FMI 2.0 3.2.3's table; its note 8,
//!   Event Mode, is for FMUs without continuous states) and before the startTime.

use crate::model_description::Description;
use crate::ops::Op;
use crate::oversized::{too_many_refs, wrong_size};
use crate::view::View;

/// Why the call must fail, if it must: `view` is the instance's, `me` its interface.
pub fn forbidden(op: &Op, view: &View, me: bool, m: &Description) -> Option<String> {
    match op {
        Op::Oversized(o) => Some(o.why(m)),
        Op::GetReal { vr, .. } | Op::GetInteger { vr, .. } | Op::GetBoolean { vr, .. } | Op::GetString { vr, .. } => {
            too_many_refs(vr.len(), m)
        }
        Op::SetReal { vr, .. } | Op::SetInteger { vr, .. } | Op::SetBoolean { vr, .. } | Op::SetString { vr, .. } => {
            too_many_refs(vr.len(), m)
        }
        Op::SetRealInputDerivatives { vr, .. } | Op::GetRealOutputDerivatives { vr, .. } => too_many_refs(vr.len(), m),
        Op::GetDirectionalDerivative { unknowns, knowns, .. } => {
            too_many_refs(unknowns.len(), m).or_else(|| too_many_refs(knowns.len(), m))
        }
        Op::SetDebugLogging { categories, .. } => too_many_categories(categories.len(), m),
        Op::SetContinuousStates { x } => wrong_size(x.len(), m.states, "continuous states"),
        Op::GetDerivatives { n, .. }
        | Op::GetContinuousStates { n, .. }
        | Op::GetNominalsOfContinuousStates { n, .. } => wrong_size(*n, m.states, "continuous states"),
        Op::GetEventIndicators { n, .. } => wrong_size(*n, m.event_indicators, "event indicators"),
        Op::SetTime { t } if me => view.set_time_refusal(*t),
        _ => None,
    }
}

/// Why nCategories = `n` must be refused, if it must: more than the model declares.
pub fn too_many_categories(n: usize, m: &Description) -> Option<String> {
    (n > m.categories.len()).then(|| format!("{n} log categories; the model declares {}", m.categories.len()))
}
