//! The rules of an FMI 3.0 input Clock with a constant interval (ClockedPressureFeedbackController's
//! `sample`: active at t_k = startTime + shift + k interval, k = 0, 1, ...), written from FMI 3.0
//! 2.2.8 and 2.3.5, and the oracle's account of it: the activations made (the next one due is
//! t_k with k = `View::activations`) and whether the Clock is active, kept in the `View` with
//! the time, so that an FMU state restores them (`fmu_states`) and fmi3Reset clears them.
//! Each of these must return fmi3Error (and the instance is then Terminated, 2.3.1):
//! - a skipped activation: fmi3DoStep that starts at t_k (within `ON` intervals) or ends past it
//!   (by more than `PAST`), fmi3SetTime past t_k (Model Exchange), fmi3SetClock at a later
//!   activation time;
//! - a double activation: fmi3SetClock at an activation time whose activation was made (ended by
//!   fmi3UpdateDiscreteStates; in the same instant, the Clock still active, it is the same
//!   activation, which must succeed);
//! - fmi3SetClock at a time that is no activation time (farther than `OFF` from every t_k);
//! - a clocked variable set or read while its Clock is inactive, outside Instantiated and
//!   Initialization Mode (2.2.8.3);
//! - fmi3SetClock and fmi3GetClock of a variable that is no Clock.
//!
//! The FMU counts a time within 1e-6 intervals of t_k (or a few ulps, where more) as on it;
//! between `ON` and `OFF` (and within `PAST`), widened by the rounding of t_k, the oracle claims
//! nothing, nor where the view is not certain.

use crate::model_description::{Clock, Description};
use crate::ops::Arr;
use crate::ops3::Op3;
use crate::view::{Phase, View};

/// A time this close to t_k (in intervals) is on it for the oracle, ...
const ON: f64 = 0.5e-6;
/// ... one farther than this (and the rounding of t_k) from every t_k is on none.
const OFF: f64 = 2e-6;
/// A step ending this far past t_k (in intervals, plus the rounding of t_k) passes it.
const PAST: f64 = 2e-6;

/// Where a time lies among the activations.
#[derive(Debug, PartialEq, Eq)]
pub enum Place {
    On(u64),
    Off,
    Unsure,
}

impl Clock {
    /// The activation time t_k of an experiment starting at `start`, computed as the FMU does.
    pub fn time(&self, start: f64, k: u64) -> f64 {
        (start + self.shift) + k as f64 * self.interval
    }

    /// Where `t` lies among the activations of an experiment starting at `start`: on t_k, or off
    /// every one by more than `OFF` and the rounding of t_k (at large times a time resolves
    /// coarser than the FMU's tolerance, which it widens to a few ulps there).
    pub fn place(&self, start: f64, t: f64) -> Place {
        let k = ((t - (start + self.shift)) / self.interval).round().max(0.0) as u64;
        let off = (t - self.time(start, k)).abs();
        if off <= ON * self.interval {
            Place::On(k)
        } else if off > OFF * self.interval + rounding(self.time(start, k)) {
            Place::Off
        } else {
            Place::Unsure
        }
    }

    /// The activation due in `view` and its time.
    fn due(&self, view: &View) -> (u64, f64) {
        (view.activations, self.time(view.start, view.activations))
    }
}

/// The Clock of the model, where `view` is certain enough for a claim.
fn clock<'m>(m: &'m Description, view: &View) -> Option<&'m Clock> {
    m.clock.as_ref().filter(|_| view.certain() && view.start.is_finite())
}

/// Why the call must fail under the clock rules, if it must (the state machines aside).
pub fn forbidden(op: &Op3, view: &View, m: &Description) -> Option<String> {
    match op {
        Op3::SetClock { vr, values } => not_clocks(vr, m).or_else(|| set_clock(vr, values, view, m)),
        Op3::GetClock { vr, .. } => not_clocks(vr, m),
        Op3::DoStep { t, h, .. } => do_step(*t, *h, view, m),
        Op3::SetTime { t } => set_time(*t, view, m),
        _ => op.access().and_then(|a| inactive(a.vr, view, m)),
    }
}

/// Why fmi3SetClock must succeed, if it must: the Clock set again in the instant it is active.
pub fn required(op: &Op3, view: &View, m: &Description) -> Option<&'static str> {
    let Op3::SetClock { vr, values } = op else { return None };
    let c = clock(m, view)?;
    let again = view.phase == Phase::EventMode && view.clock_active && activates(vr, values, c);
    (again && c.place(view.start, view.time) == Place::On(view.activations))
        .then_some("the active Clock set again in its instant: the same activation (FMI 3.0, 2.3.5)")
}

/// The bookkeeping of a call to the main instance that returned OK or Warning.
pub fn observe(op: &Op3, view: &mut View, m: &Description) {
    let Some(c) = &m.clock else { return };
    match op {
        Op3::SetClock { vr, .. } if vr.items().contains(&c.vr) => view.clock_active = true,
        Op3::UpdateDiscreteStates { .. } if view.clock_active => {
            view.activations = match c.place(view.start, view.time) {
                Place::On(k) => k + 1,
                _ => view.activations + 1,
            };
            view.clock_active = false;
        }
        _ => {}
    }
}

/// Whether the arguments activate exactly the Clock `c`.
fn activates(vr: &Arr<u32>, values: &Arr<u8>, c: &Clock) -> bool {
    vr.items() == [c.vr] && values.items() == [1]
}

/// fmi3SetClock or fmi3GetClock of a variable of another type, or of no variable.
fn not_clocks(vr: &Arr<u32>, m: &Description) -> Option<String> {
    let clock = m.clock.as_ref().map(|c| c.vr);
    vr.items().iter().find(|&&r| Some(r) != clock).map(|r| match m.variable(*r) {
        Some(v) => format!("{} is no Clock", v.name),
        None => format!("vr {r} is no variable"),
    })
}

/// fmi3SetClock(true) in Event Mode: at no activation time, at a later one than due, at one made.
fn set_clock(vr: &Arr<u32>, values: &Arr<u8>, view: &View, m: &Description) -> Option<String> {
    let c = clock(m, view).filter(|c| view.phase == Phase::EventMode && activates(vr, values, c))?;
    let (due, t_due) = c.due(view);
    let t = view.time;
    match c.place(view.start, t) {
        Place::Off => Some(format!("no activation time: t = {t} is none of the Clock's times (FMI 3.0, 2.2.8.2)")),
        Place::On(k) if k > due => Some(format!(
            "skipped activation: set for activation {k} at t = {t}, but activation {due} at t = {t_due} was \
             not made (FMI 3.0, 2.2.8.2)"
        )),
        Place::On(k) if k < due => Some(format!(
            "double activation: activation {k} at t = {t} was made (ended by fmi3UpdateDiscreteStates) (FMI 3.0, \
             2.3.5)"
        )),
        _ => None,
    }
}

/// fmi3DoStep(t, h) in Step Mode: starting at the activation due or ending past it skips it.
fn do_step(t: f64, h: f64, view: &View, m: &Description) -> Option<String> {
    let c = clock(m, view).filter(|_| view.phase == Phase::StepComplete)?;
    let (due, t_due) = c.due(view);
    if ((view.time - t_due) / c.interval).abs() <= ON {
        return Some(format!(
            "skipped activation: starts at activation {due} (t = {t_due}), not made; activate the Clock in Event \
             Mode first (FMI 3.0, 2.2.8.2)"
        ));
    }
    (t + h > t_due + slack(c, t_due)).then(|| {
        let end = t + h;
        format!(
            "skipped activation: passes activation {due} at t = {t_due}, not made, with a step to t = {end} \
             (FMI 3.0, 2.2.8.2)"
        )
    })
}

/// fmi3SetTime(t) in Continuous-Time Mode: past the activation due skips it.
fn set_time(t: f64, view: &View, m: &Description) -> Option<String> {
    let c = clock(m, view).filter(|_| view.phase == Phase::ContinuousTime)?;
    let (due, t_due) = c.due(view);
    (t > t_due + slack(c, t_due)).then(|| {
        format!("skipped activation: t = {t} is past activation {due} at t = {t_due}, not made (FMI 3.0, 2.2.8.2)")
    })
}

/// How far past t_k a time may be and not claimed to pass it: `PAST` intervals and the rounding
/// of t_k.
fn slack(c: &Clock, t_k: f64) -> f64 {
    PAST * c.interval + rounding(t_k)
}

/// Eight ulps of a time: more than the FMU's and the oracle's sums may differ by.
fn rounding(t: f64) -> f64 {
    8.0 * f64::EPSILON * t.abs()
}

/// A clocked variable set or read while its Clock is inactive (Step, Event or Continuous-Time
/// Mode; FMI 3.0, 2.2.8.3).
fn inactive(vr: &Arr<u32>, view: &View, m: &Description) -> Option<String> {
    let c = clock(m, view)?;
    let now = matches!(view.phase, Phase::StepComplete | Phase::StepFailed | Phase::EventMode | Phase::ContinuousTime);
    let v = vr.items().iter().filter_map(|&r| m.variable(r)).find(|v| v.clocked)?;
    (now && !view.clock_active)
        .then(|| format!("inactive Clock: {} is clocked by {}, which is not active (FMI 3.0, 2.2.8.3)", v.name, c.name))
}
