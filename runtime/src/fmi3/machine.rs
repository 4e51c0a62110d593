//! The FMI 3.0 state machines of Co-Simulation (FMI 3.0, section 4.2.4) and Model Exchange
//! (section 3.2.4) as one table: per function, the interface it belongs to and the set of states
//! in which it may be called. The states are those of [`crate::fmu::machine`]: `StepComplete` is
//! FMI 3.0's Step Mode, `StepFailed` its Step Discarded; `StepCanceled` is never entered. There
//! are no structural parameters, and Event Mode in Co-Simulation only for the one model with a
//! Clock (`hasEventMode="true"`, instantiated with `eventModeUsed`, checked per instance), so
//! Configuration, Reconfiguration and Clock Activation Mode are never entered; Intermediate
//! Update Mode (`IntermediateUpdate`) only while the master's callback runs inside doStep.

pub use crate::fmu::machine::*;

/// Per function: the interface and the states in which the call is legal.
pub mod allowed {
    use super::*;
    const ANY: Mask = INST | INIT | DONE | FAIL | CANC | EVENT | CONT | TERM | ERR;
    pub const SET_DEBUG_LOGGING: Rule = both(ANY);
    /// Every state but Intermediate Update Mode, where the master's callback runs inside
    /// fmi3DoStep: 4.2.3 does not list fmi3FreeInstance among its calls, and the step would go on
    /// in freed memory.
    pub const FREE_INSTANCE: Rule = both(ANY);
    pub const ENTER_INITIALIZATION_MODE: Rule = both(INST);
    pub const EXIT_INITIALIZATION_MODE: Rule = both(INIT);
    /// Model Exchange from Continuous-Time Mode, Co-Simulation from Step Mode (with
    /// `eventModeUsed`, checked per instance).
    pub const ENTER_EVENT_MODE: Rule = both(DONE | CONT);
    pub const TERMINATE: Rule = both(DONE | FAIL | EVENT | CONT);
    pub const RESET: Rule = both(ANY);
    pub const GET: Rule = both(INIT | DONE | FAIL | EVENT | CONT | TERM | ERR);
    /// fmi3SetFloat64; in Continuous-Time Mode only continuous inputs and continuous-time states
    /// (3.2.1, as of FMI 3.0.2; checked per variable); in Intermediate Update Mode the required
    /// intermediate inputs while the callback requests them (4.2.3; checked per instance).
    pub const SET_FLOAT64: Rule = both(INST | INIT | DONE | EVENT | CONT | IU);
    /// fmi3SetInt32, fmi3SetBoolean, fmi3SetString (and the other types): not in Continuous-Time Mode.
    pub const SET_DISCRETE: Rule = both(INST | INIT | DONE | EVENT);
    pub const FMU_STATE: Rule = both(ANY);
    pub const DERIVATIVES: Rule = both(INIT | DONE | FAIL | EVENT | CONT | TERM | ERR);
    /// The functions boomsim does not provide (Configuration Mode: no structural parameters;
    /// clocks and Scheduled Execution; fmi3EvaluateDiscreteStates; per-element dependencies):
    /// every call, in any state, is an error naming why.
    pub const UNSUPPORTED: Rule = both(ANY);
    pub const UPDATE_DISCRETE_STATES: Rule = both(EVENT);
    /// fmi3SetClock and fmi3GetClock: Event Mode (2.3.5; a Clock is set there, output Clocks
    /// are read there).
    pub const SET_CLOCK: Rule = both(EVENT);
    pub const GET_CLOCK: Rule = both(EVENT);
    /// fmi3GetIntervalDecimal: Initialization and Event Mode (2.2.8.1, input Clock); the shift
    /// of a constant Clock in Initialization Mode (2.2.8.2, the table of Clock types).
    pub const GET_INTERVAL: Rule = both(INIT | EVENT);
    pub const GET_SHIFT: Rule = both(INIT);
    pub const ENTER_CONTINUOUS_TIME_MODE: Rule = me(EVENT);
    pub const COMPLETED_INTEGRATOR_STEP: Rule = me(CONT);
    /// Continuous-Time Mode only (3.2.1; Event Mode, 2.3.5, does not list it).
    pub const SET_TIME: Rule = me(CONT);
    pub const SET_CONTINUOUS_STATES: Rule = me(CONT);
    pub const GET_CONTINUOUS_STATE_DERIVATIVES: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_EVENT_INDICATORS: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_CONTINUOUS_STATES: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_NOMINALS: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_NUMBER_OF: Rule = me(ANY);
    /// From Event Mode, which a Co-Simulation instance without event mode never enters.
    pub const ENTER_STEP_MODE: Rule = cs(EVENT);
    pub const GET_OUTPUT_DERIVATIVES: Rule = cs(DONE | FAIL | TERM | ERR);
    pub const DO_STEP: Rule = cs(DONE);
}
