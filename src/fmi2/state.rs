//! The FMI 2.0 Co-Simulation state machine (FMI 2.0.4, section 4.2.4): the states and, per
//! function, the set of states in which it may be called.

/// The slave's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
}

impl State {
    /// The state's bit in a [`Mask`].
    pub const fn bit(self) -> Mask {
        1 << self as u16
    }

    /// Every state, for messages.
    pub const ALL: [State; 7] = [
        State::Instantiated,
        State::InitializationMode,
        State::StepComplete,
        State::StepFailed,
        State::StepCanceled,
        State::Terminated,
        State::Error,
    ];
}

/// A set of states.
pub type Mask = u16;

const INST: Mask = State::Instantiated.bit();
const INIT: Mask = State::InitializationMode.bit();
const DONE: Mask = State::StepComplete.bit();
const FAIL: Mask = State::StepFailed.bit();
const CANC: Mask = State::StepCanceled.bit();
const TERM: Mask = State::Terminated.bit();
const ERR: Mask = State::Error.bit();

/// Per function: the states in which the call is legal.
pub mod allowed {
    use super::*;
    pub const SET_DEBUG_LOGGING: Mask = INST | INIT | DONE | FAIL | CANC | TERM | ERR;
    pub const FREE_INSTANCE: Mask = INST | INIT | DONE | FAIL | CANC | TERM | ERR;
    pub const SETUP_EXPERIMENT: Mask = INST;
    pub const ENTER_INITIALIZATION_MODE: Mask = INST;
    pub const EXIT_INITIALIZATION_MODE: Mask = INIT;
    pub const TERMINATE: Mask = DONE | FAIL | CANC;
    pub const RESET: Mask = INST | INIT | DONE | FAIL | CANC | TERM | ERR;
    pub const GET: Mask = INIT | DONE | FAIL | CANC | TERM | ERR;
    pub const SET: Mask = INST | INIT | DONE;
    pub const FMU_STATE: Mask = INST | INIT | DONE | FAIL | CANC | TERM | ERR;
    pub const DIRECTIONAL_DERIVATIVE: Mask = INIT | DONE | FAIL | CANC | TERM | ERR;
    pub const SET_INPUT_DERIVATIVES: Mask = INST | INIT | DONE;
    pub const GET_OUTPUT_DERIVATIVES: Mask = DONE | FAIL | CANC | TERM | ERR;
    pub const DO_STEP: Mask = DONE;
    /// No asynchronous doStep: a step is never in progress, so cancelling is never legal.
    pub const CANCEL_STEP: Mask = 0;
    pub const GET_STATUS: Mask = DONE | FAIL | CANC | TERM;
}

/// The names of the states in a mask, for error messages.
pub fn describe(mask: Mask) -> String {
    let names: Vec<String> = State::ALL.iter().filter(|s| mask & s.bit() != 0).map(|s| format!("{s:?}")).collect();
    if names.is_empty() {
        "no state".to_owned()
    } else {
        names.join(", ")
    }
}
