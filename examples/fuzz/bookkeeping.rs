//! What the fuzzer keeps of one sequence's instances, alike for both versions: the main and the
//! second instance, the interface, the view of the main one's state, its FMU states, the last
//! continuous states read, the watch and the simulated time; each version's session holds it.

use crate::fmu_states::FmuStates;
use crate::model_description::Description;
use crate::report::Report;
use crate::view::View;
use crate::watch::{Seen, Watch};
use std::ffi::c_void;
use std::ptr::null_mut;

/// Simulated seconds per sequence at most (the flexible boom runs about 30 times real time).
const SIMULATION_BUDGET: f64 = 0.5;

/// The instance a call goes to: the sequence's, NULL, or a second one from a wild
/// instantiation, kept until the end of the sequence (its FMU states are foreign to the main one).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Main,
    Null,
    Second,
}

/// One sequence's instances with the fuzzer's bookkeeping.
pub struct Bookkeeping<'a> {
    pub model: &'a Description,
    pub report: &'a mut Report,
    /// The main instance (fmi2Component, fmi3Instance).
    pub c: *mut c_void,
    /// The `Target::Second` instance, or NULL.
    pub second: *mut c_void,
    /// The main instantiation has been called.
    pub opened: bool,
    /// The main instance is a Model Exchange one.
    pub me: bool,
    /// The main instance is a Co-Simulation one with eventModeUsed, and with earlyReturnAllowed
    /// (FMI 3.0).
    pub event_mode: bool,
    pub early_return: bool,
    /// The main instance has a logger.
    pub logger: bool,
    /// The continuous states the main instance last returned (Model Exchange).
    pub x: Vec<f64>,
    /// `x` was read by the last call to the main instance.
    pub x_fresh: bool,
    pub view: View,
    pub states: FmuStates,
    pub watch: Watch,
    /// Simulated time so far (an upper bound).
    pub simulated: f64,
}

impl<'a> Bookkeeping<'a> {
    pub fn new(model: &'a Description, report: &'a mut Report, states: FmuStates) -> Self {
        Bookkeeping {
            model,
            report,
            c: null_mut(),
            second: null_mut(),
            opened: false,
            me: false,
            event_mode: false,
            early_return: false,
            logger: false,
            x: Vec::new(),
            x_fresh: false,
            view: View::fresh(),
            states,
            watch: Watch::default(),
            simulated: 0.0,
        }
    }

    /// The instance a call to `target` passes, and how the trace says so.
    pub fn instance(&self, target: Target) -> (*mut c_void, &'static str) {
        match target {
            Target::Main => (self.c, ""),
            Target::Null => (null_mut(), " on a NULL instance"),
            Target::Second => (self.second, " on the second instance"),
        }
    }

    /// An instantiation returned `c`: the first is the main instance (`None`), as is a NULL one
    /// (nothing to do); else the second one (`Target::Second`: an FMU state of it is to be
    /// taken) or, with a second one already, an instance to free right away (`Target::Main`).
    pub fn adopt(&mut self, c: *mut c_void) -> Option<Target> {
        if !self.opened {
            self.opened = true;
            self.c = c;
            None
        } else if c.is_null() {
            None
        } else if self.second.is_null() {
            self.second = c;
            Some(Target::Second)
        } else {
            Some(Target::Main)
        }
    }

    /// FreeInstance of `instance`: the main or the second one is gone, with its FMU states.
    pub fn freed(&mut self, instance: *mut c_void) {
        if instance == self.c {
            self.c = null_mut();
            self.states.live.clear();
            self.states.stale.clear();
        } else if instance == self.second {
            self.second = null_mut();
            self.states.foreign.clear();
        }
    }

    /// A call to the main instance returned: the watch sees what it did (`seen`, if it
    /// succeeded), and the states read before are no longer the last call's.
    pub fn see(&mut self, seen: Seen) -> Result<(), String> {
        self.watch.see(seen, self.model)?;
        self.x_fresh = false;
        Ok(())
    }

    /// Simulated seconds left for the sequence.
    pub fn budget(&self) -> f64 {
        SIMULATION_BUDGET - self.simulated
    }
}
