//! The FMI 2.0 state machines of Co-Simulation (FMI 2.0.4, section 4.2.4) and Model Exchange
//! (section 3.2.3) as one table: per function, the interface it belongs to and the set of states
//! in which it may be called (the states themselves are shared with FMI 3.0: [`crate::fmu::machine`]).

pub use crate::fmu::machine::*;

/// Per function: the interface and the states in which the call is legal.
pub mod allowed {
    use super::*;
    const ANY: Mask = INST | INIT | DONE | FAIL | CANC | EVENT | CONT | TERM | ERR;
    pub const SET_DEBUG_LOGGING: Rule = both(ANY);
    /// In every state, IntermediateUpdate too (no FMI 2.0 instance enters it, but an instance
    /// that ever did is still freed, not leaked).
    pub const FREE_INSTANCE: Rule = both(ANY | IU);
    pub const SETUP_EXPERIMENT: Rule = both(INST);
    pub const ENTER_INITIALIZATION_MODE: Rule = both(INST);
    pub const EXIT_INITIALIZATION_MODE: Rule = both(INIT);
    pub const TERMINATE: Rule = both(DONE | FAIL | CANC | EVENT | CONT);
    pub const RESET: Rule = both(ANY);
    pub const GET: Rule = both(INIT | DONE | FAIL | CANC | EVENT | CONT | TERM | ERR);
    /// fmi2SetReal; in Continuous-Time Mode only continuous inputs and continuous states
    /// (rule 5, clarified in 2.0.1; checked per variable).
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
    /// Table note 8: in Event Mode only for a pure discrete-time FMU, which these are not.
    pub const SET_TIME: Rule = me(CONT);
    pub const SET_CONTINUOUS_STATES: Rule = me(CONT);
    /// Initialization Mode since the 2.0.1 errata (3.2.3: "fmi2GetDerivatives may be called in
    /// initializationMode").
    pub const GET_DERIVATIVES: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_EVENT_INDICATORS: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_CONTINUOUS_STATES: Rule = me(INIT | EVENT | CONT | TERM | ERR);
    pub const GET_NOMINALS: Rule = me(INST | INIT | EVENT | CONT | TERM | ERR);
}
