//! The states of an instance, shared by the FMI 2.0 and FMI 3.0 state machines (each adapter's
//! `state.rs` holds its table of allowed states per function), and the building blocks of those
//! tables.

/// The instance's state. An instance of one interface never enters the states of the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
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
    /// FMI 3.0 Co-Simulation: inside doStep, while the master's intermediateUpdate callback runs
    /// (4.2.3); the master may set the intermediate inputs there and call nothing else.
    IntermediateUpdate,
}

impl Mode {
    /// The state's bit in a [`Mask`].
    pub const fn bit(self) -> Mask {
        1 << self as u16
    }

    /// The interface whose state this is; `None` for the states both share (Event Mode: Model
    /// Exchange, and FMI 3.0 Co-Simulation with eventModeUsed).
    pub const fn interface(self) -> Option<Interface> {
        match self {
            Mode::StepComplete | Mode::StepFailed | Mode::StepCanceled | Mode::IntermediateUpdate => {
                Some(Interface::CoSimulation)
            }
            Mode::ContinuousTimeMode => Some(Interface::ModelExchange),
            _ => None,
        }
    }

    /// Every state, for messages and the FMU state bytes.
    pub const ALL: [Mode; 10] = [
        Mode::Instantiated,
        Mode::InitializationMode,
        Mode::StepComplete,
        Mode::StepFailed,
        Mode::StepCanceled,
        Mode::EventMode,
        Mode::ContinuousTimeMode,
        Mode::Terminated,
        Mode::Error,
        Mode::IntermediateUpdate,
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

pub const INST: Mask = Mode::Instantiated.bit();
pub const INIT: Mask = Mode::InitializationMode.bit();
pub const DONE: Mask = Mode::StepComplete.bit();
pub const FAIL: Mask = Mode::StepFailed.bit();
pub const CANC: Mask = Mode::StepCanceled.bit();
pub const EVENT: Mask = Mode::EventMode.bit();
pub const CONT: Mask = Mode::ContinuousTimeMode.bit();
pub const TERM: Mask = Mode::Terminated.bit();
pub const ERR: Mask = Mode::Error.bit();
pub const IU: Mask = Mode::IntermediateUpdate.bit();

pub const fn both(states: Mask) -> Rule {
    Rule { interface: None, states }
}
pub const fn cs(states: Mask) -> Rule {
    Rule { interface: Some(Interface::CoSimulation), states }
}
pub const fn me(states: Mask) -> Rule {
    Rule { interface: Some(Interface::ModelExchange), states }
}

/// The names of the states in a mask, for error messages.
pub fn describe(mask: Mask) -> String {
    let names: Vec<String> = Mode::ALL.iter().filter(|s| mask & s.bit() != 0).map(|s| format!("{s:?}")).collect();
    if names.is_empty() {
        "no state".to_owned()
    } else {
        names.join(", ")
    }
}
