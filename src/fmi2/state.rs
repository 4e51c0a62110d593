//! The FMI 2.0 state machines of Co-Simulation (FMI 2.0.4, section 4.2.4) and Model Exchange
//! (section 3.2.3) as one table: the states of both and, per function, the interface it belongs
//! to and the set of states in which it may be called.

/// The instance's state. An instance of one interface never enters the states of the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    Instantiated,
    InitializationMode,
    /// Co-Simulation: after a step that succeeded (or initialisation).
    StepComplete,
    StepFailed,
    StepCanceled,
    /// Model Exchange: discrete-time equations active (after initialisation, fmi2EnterEventMode).
    EventMode,
    /// Model Exchange: the importer's integrator sets time and states and reads derivatives.
    ContinuousTimeMode,
    Terminated,
    Error,
}

impl State {
    /// The state's bit in a [`Mask`].
    pub const fn bit(self) -> Mask {
        1 << self as u16
    }

    /// The interface whose state this is; `None` for the states both share.
    pub const fn interface(self) -> Option<Interface> {
        match self {
            State::StepComplete | State::StepFailed | State::StepCanceled => Some(Interface::CoSimulation),
            State::EventMode | State::ContinuousTimeMode => Some(Interface::ModelExchange),
            _ => None,
        }
    }

    /// Every state, for messages and the FMU state bytes.
    pub const ALL: [State; 9] = [
        State::Instantiated,
        State::InitializationMode,
        State::StepComplete,
        State::StepFailed,
        State::StepCanceled,
        State::EventMode,
        State::ContinuousTimeMode,
        State::Terminated,
        State::Error,
    ];
}

/// The interface an instance was instantiated as (fmi2Instantiate's fmuType).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interface {
    ModelExchange,
    CoSimulation,
}

/// A set of states.
pub type Mask = u16;

/// Where a function may be called: the interface (`None`: both) and the states.
#[derive(Debug, Clone, Copy)]
pub struct Rule {
    pub interface: Option<Interface>,
    pub states: Mask,
}

const INST: Mask = State::Instantiated.bit();
const INIT: Mask = State::InitializationMode.bit();
const DONE: Mask = State::StepComplete.bit();
const FAIL: Mask = State::StepFailed.bit();
const CANC: Mask = State::StepCanceled.bit();
const EVENT: Mask = State::EventMode.bit();
const CONT: Mask = State::ContinuousTimeMode.bit();
const TERM: Mask = State::Terminated.bit();
const ERR: Mask = State::Error.bit();

const fn both(states: Mask) -> Rule {
    Rule { interface: None, states }
}
const fn cs(states: Mask) -> Rule {
    Rule { interface: Some(Interface::CoSimulation), states }
}
const fn me(states: Mask) -> Rule {
    Rule { interface: Some(Interface::ModelExchange), states }
}

/// Per function: the interface and the states in which the call is legal.
pub mod allowed {
    use super::*;
    const ANY: Mask = INST | INIT | DONE | FAIL | CANC | EVENT | CONT | TERM | ERR;
    pub const SET_DEBUG_LOGGING: Rule = both(ANY);
    pub const FREE_INSTANCE: Rule = both(ANY);
    pub const SETUP_EXPERIMENT: Rule = both(INST);
    pub const ENTER_INITIALIZATION_MODE: Rule = both(INST);
    pub const EXIT_INITIALIZATION_MODE: Rule = both(INIT);
    pub const TERMINATE: Rule = both(DONE | FAIL | CANC | EVENT | CONT);
    pub const RESET: Rule = both(ANY);
    pub const GET: Rule = both(INIT | DONE | FAIL | CANC | EVENT | CONT | TERM | ERR);
    /// fmi2SetReal; in Continuous-Time Mode only continuous inputs (checked per variable).
    pub const SET_REAL: Rule = both(INST | INIT | DONE | EVENT | CONT);
    /// fmi2SetInteger, fmi2SetBoolean, fmi2SetString: discrete, so not in Continuous-Time Mode.
    pub const SET_DISCRETE: Rule = both(INST | INIT | DONE | EVENT);
    pub const FMU_STATE: Rule = both(ANY);
    pub const DIRECTIONAL_DERIVATIVE: Rule = both(INIT | DONE | FAIL | CANC | EVENT | CONT | TERM | ERR);
    pub const SET_INPUT_DERIVATIVES: Rule = cs(INST | INIT | DONE);
    pub const GET_OUTPUT_DERIVATIVES: Rule = cs(DONE | FAIL | CANC | TERM | ERR);
    pub const DO_STEP: Rule = cs(DONE);
    /// No asynchronous doStep: a step is never in progress, so cancelling is never legal.
    pub const CANCEL_STEP: Rule = cs(0);
    pub const GET_STATUS: Rule = cs(DONE | FAIL | CANC | TERM);
    pub const ENTER_EVENT_MODE: Rule = me(EVENT | CONT);
    pub const NEW_DISCRETE_STATES: Rule = me(EVENT);
    pub const ENTER_CONTINUOUS_TIME_MODE: Rule = me(EVENT);
    pub const COMPLETED_INTEGRATOR_STEP: Rule = me(CONT);
    pub const SET_TIME: Rule = me(EVENT | CONT);
    pub const SET_CONTINUOUS_STATES: Rule = me(CONT);
    pub const GET_DERIVATIVES: Rule = me(EVENT | CONT | TERM | ERR);
    pub const GET_EVENT_INDICATORS: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_CONTINUOUS_STATES: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_NOMINALS: Rule = me(INST | EVENT | CONT | TERM | ERR);
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
