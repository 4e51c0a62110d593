//! What the fuzzer believes about an instance, from the calls that succeeded: its phase, time
//! and stop time, and so which steps it may take.

use crate::fmi2::{Status, DISCARD, OK, WARNING};

/// The FMI state of the instance as far as the fuzzer can tell from the statuses.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    Instantiated,
    Initialization,
    StepComplete,
    StepFailed,
    /// Model Exchange: Event Mode and Continuous-Time Mode.
    EventMode,
    ContinuousTime,
    Terminated,
    /// A step that might have been carried out returned fmi2Error: probe with fmi2GetRealStatus.
    Unknown,
    /// Nothing sensible is known: reset.
    Broken,
}

#[derive(Clone, Copy)]
pub struct View {
    pub phase: Phase,
    /// The instance time (NaN when unknown).
    pub time: f64,
    pub stop: Option<f64>,
    /// The startTime of the experiment (NaN before it is set up).
    pub start: f64,
    /// A parameter was set since the instantiation or reset: its values may not fit together,
    /// and what needs them (Initialization Mode's derivatives) may fail.
    pub tuned: bool,
    pub set_up: bool,
    /// FMI 3.0 with a Clock (`clock_rules`): the activations made (the next one due is this
    /// index) and whether the Clock is active; part of the FMU state, like the time.
    pub activations: u64,
    pub clock_active: bool,
    /// False for a state restored from bytes edited with the CRC recomputed.
    certain: bool,
}

impl View {
    /// Right after fmi2Instantiate or fmi2Reset.
    pub fn fresh() -> Self {
        View {
            phase: Phase::Instantiated,
            time: 0.0,
            stop: None,
            start: f64::NAN,
            tuned: false,
            set_up: false,
            activations: 0,
            clock_active: false,
            certain: true,
        }
    }

    /// A state restored from bytes edited with the CRC recomputed: nothing is known about it.
    pub fn unknown() -> Self {
        View {
            phase: Phase::Unknown,
            time: f64::NAN,
            stop: None,
            start: f64::NAN,
            tuned: true,
            set_up: true,
            activations: 0,
            clock_active: false,
            certain: false,
        }
    }

    /// Whether the phase and time are known for certain (not from edited bytes).
    pub fn certain(&self) -> bool {
        self.certain && !matches!(self.phase, Phase::Unknown | Phase::Broken)
    }

    /// Why fmi2SetTime/fmi3SetTime(t) of a Model Exchange instance must fail, if it must: it is
    /// allowed in Continuous-Time Mode only (FMI 2.0 3.2.3's table, whose note 8 on Event Mode is
    /// for FMUs without continuous states; FMI 3.0 3.2.4: Event Mode does not list it), and a
    /// time before the startTime is refused (issue 25 item 4).
    pub fn set_time_refusal(&self, t: f64) -> Option<String> {
        match self.phase {
            Phase::Unknown | Phase::Broken => None,
            Phase::ContinuousTime => (t < self.start).then(|| format!("time {t} before the startTime {}", self.start)),
            _ => Some("SetTime is allowed only in Continuous-Time Mode".into()),
        }
    }

    /// fmi2GetRealStatus(fmi2LastSuccessfulTime) returned `t`: the oracle's check of it.
    pub fn synchronised(&mut self, t: f64) -> Result<(), String> {
        match self.phase {
            Phase::Unknown => (self.phase, self.time, self.certain) = (Phase::StepComplete, t, false),
            Phase::StepFailed => self.time = t,
            Phase::StepComplete | Phase::Terminated if self.certain && self.time.is_finite() && t != self.time => {
                return Err(format!(
                    "fmi2GetRealStatus(fmi2LastSuccessfulTime) = {t}, but the last successful step ended at {}",
                    self.time
                ));
            }
            _ => {}
        }
        Ok(())
    }

    /// fmi2DoStep(t, h) returned `status`; the simulated time it may have cost.
    pub fn stepped(&mut self, t: f64, h: f64, status: Option<Status>) -> f64 {
        match status {
            Some(OK | WARNING) => {
                let cost = (t + h - self.time).max(h);
                (self.time, self.phase) = (t + h, Phase::StepComplete);
                cost
            }
            Some(DISCARD) => {
                (self.time, self.phase) = (f64::NAN, Phase::StepFailed);
                h
            }
            _ => {
                if self.may_advance(t, h) {
                    self.phase = if self.certain { Phase::Unknown } else { Phase::Broken };
                }
                0.0
            }
        }
    }

    /// Whether the FMU might carry out fmi2DoStep(t, h): false only when it must refuse it
    /// (invalid h, a time that cannot match, a step past the stop time, a state without steps).
    fn may_advance(&self, t: f64, h: f64) -> bool {
        if !(t.is_finite() && h > 0.0 && h.is_finite()) {
            return false;
        }
        if !self.certain {
            return true;
        }
        if matches!(
            self.phase,
            Phase::Instantiated
                | Phase::Initialization
                | Phase::StepFailed
                | Phase::EventMode
                | Phase::ContinuousTime
                | Phase::Terminated
        ) {
            return false;
        }
        // Twice the FMU's tolerances: what is refused here is refused there.
        let matches_time = (t - self.time).abs() <= 2e-9 * self.time.abs().max(1.0);
        let before_stop = self.stop.is_none_or(|stop| t + h <= stop + 2e-9 * stop.abs().max(1.0));
        matches_time && before_stop
    }

    /// The longest legal step left by the simulation `budget` and the stop time (0 when the
    /// time is unknown).
    pub fn room(&self, budget: f64) -> f64 {
        let room = budget.min(self.stop.map_or(f64::INFINITY, |stop| stop - self.time));
        if self.time.is_finite() && room > 0.0 {
            room
        } else {
            0.0
        }
    }

    /// A step made harmless for the simulation `budget`: one the FMU might carry out never
    /// simulates more than that (a huge h at the right time would run for hours, not hang).
    pub fn bounded_step(&self, t: f64, h: f64, budget: f64) -> (f64, f64) {
        let budget = budget.max(0.0);
        if !self.certain {
            (self.time, if h > budget { budget } else { h })
        } else if self.may_advance(t, h) && t + h - self.time > budget {
            (self.time, budget)
        } else {
            (t, h)
        }
    }
}
