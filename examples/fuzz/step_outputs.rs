//! The outputs after a step (issue defect 3), the same for both versions: an fmi2DoStep or
//! fmi3DoStep that answers OK or Warning ends in a state whose outputs are finite numbers (one
//! that would not answers Discard or Error), so that the next read cannot fail with "the model
//! left its valid range". After every such step the session reads every Real output and local
//! the getters allow in Step Mode (`Description::after_step`: not the clocked ones, whose Clock is
//! inactive between steps) in one call, counted as a call: it must return OK (or Warning) and
//! every value must be finite. And the finite values of any Real read, named by their variable.

use crate::callbacks::LOG;
use crate::fmu_states::Status;
use crate::model_description::Description;
use crate::report::{outcome, Report};

/// The first value of a Real read that is not a finite number, as `name (vr N) = value`.
/// `vr` are the value references passed (none for a NULL array).
pub fn non_finite(m: &Description, vr: &[u32], values: &[f64]) -> Option<String> {
    let i = values.iter().position(|x| !x.is_finite())?;
    let name = match vr.get(i) {
        Some(&r) => m.variable(r).map_or(format!("vr {r}"), |var| format!("{} (vr {r})", var.name)),
        None => format!("value {i} (no value reference)"),
    };
    Some(format!("{name} = {}", values[i]))
}

/// Reads `Description::after_step` with `get` (the version's getter of these value references
/// into a buffer of as many values), recorded as a call in `report`, and checks the answer: the
/// read after a step of FMI 2.0 or (`fmi3`) FMI 3.0 that succeeded.
pub fn read(
    fmi3: bool,
    report: &mut Report,
    m: &Description,
    get: impl FnOnce(&[u32], *mut f64) -> Status,
) -> Result<(), String> {
    if m.after_step.is_empty() {
        return Ok(());
    }
    let (v, n) = (if fmi3 { 3 } else { 2 }, m.after_step.len());
    let getter = if fmi3 { "fmi3GetFloat64" } else { "fmi2GetReal" };
    report.begin(format_args!("{getter} of the {n} Real outputs and locals after the step"));
    let mut values = vec![f64::NAN; n];
    let errors = LOG.with(|sink| sink.borrow().errors);
    let status = get(&m.after_step, values.as_mut_ptr());
    report.end(Some(status));
    let step = format!("fmi{v}DoStep returned fmi{v}OK or fmi{v}Warning");
    match status {
        0 | 1 => match non_finite(m, &m.after_step, &values) {
            Some(what) => Err(format!("{step}, but the outputs and locals read after it have {what}")),
            None => Ok(()),
        },
        s => {
            // The FMU's message, if this call logged one.
            let said = LOG.with(|sink| {
                let sink = sink.borrow();
                if sink.errors > errors {
                    format!(": {}", sink.last_error)
                } else {
                    String::new()
                }
            });
            Err(format!(
                "{step}, but reading its outputs and locals then returned {}{said}",
                outcome(i64::from(s), fmi3)
            ))
        }
    }
}
