//! The FMI 3.0 call catalogue: one `Op3` per fmi3 function (or family), with its arguments.
//! C arrays, strings and FMU state arguments are those of `ops` and `fmu_states`.

use crate::fmu_states::StateCall;
use crate::model_description::Type;
use crate::ops::{Arr, Text};
use crate::planner::Experiment;
use crate::sequence::Call;
use std::os::raw::c_void;

/// The instantiation functions' arguments; `logger` false passes a NULL logMessage.
#[derive(Debug)]
pub struct Instantiation3 {
    pub interface: Interface3,
    pub name: Text,
    pub token: Text,
    pub resources: Text,
    pub visible: bool,
    pub logging_on: bool,
    /// Co-Simulation: eventModeUsed, earlyReturnAllowed and the required intermediate variables.
    pub event_mode_used: bool,
    pub early_return_allowed: bool,
    pub required_intermediate: Arr<u32>,
    pub logger: bool,
}

impl Instantiation3 {
    /// Co-Simulation named "fuzz" with `token`: no resources, logger or options.
    pub fn quiet(token: Text) -> Self {
        Instantiation3 {
            interface: Interface3::CoSimulation,
            name: Text::new("fuzz"),
            token,
            resources: Text::Null,
            visible: false,
            logging_on: false,
            event_mode_used: false,
            early_return_allowed: false,
            required_intermediate: Arr::Items(Vec::new()),
            logger: false,
        }
    }
}

/// Which fmi3Instantiate* function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interface3 {
    CoSimulation,
    ModelExchange,
    ScheduledExecution,
}

/// The get and set functions of the types no variable of these FMUs has: the function, whether
/// it sets, and its value references (values are scratch buffers of the call). Int64 is not
/// among them: fmi3GetInt64 and fmi3SetInt64 read and write the Enumerations.
pub const OTHER_TYPES: [&str; 9] =
    ["Float32", "Int8", "UInt8", "Int16", "UInt16", "UInt32", "UInt64", "Binary", "Clock"];

/// Functions these FMUs do not provide (modelDescription: no clocks, no structural parameters,
/// no Scheduled Execution, no per-element dependencies, no evaluateDiscreteStates, output
/// derivatives of order 0): every call is an error, with a message.
pub const REFUSED: [&str; 15] = [
    "GetNumberOfVariableDependencies",
    "GetVariableDependencies",
    "EnterConfigurationMode",
    "ExitConfigurationMode",
    "GetIntervalDecimal",
    "GetIntervalFraction",
    "GetShiftDecimal",
    "GetShiftFraction",
    "SetIntervalDecimal",
    "SetIntervalFraction",
    "SetShiftDecimal",
    "SetShiftFraction",
    "ActivateModelPartition",
    "EvaluateDiscreteStates",
    "GetOutputDerivatives",
];

/// One call, named after the FMI 3.0 function without `fmi3`. `n_values` is the nValues
/// argument (right: the number of value references); the buffers have `n_values` elements. A
/// `null_*` flag passes NULL for that output pointer.
#[derive(Debug)]
pub enum Op3 {
    GetVersion,
    SetDebugLogging { logging_on: bool, categories: Arr<Text> },
    Instantiate(Instantiation3),
    FreeInstance { instance: *mut c_void },
    EnterInitializationMode(Experiment),
    ExitInitializationMode,
    EnterEventMode,
    Terminate,
    Reset,
    GetFloat64 { vr: Arr<u32>, n_values: usize, null_values: bool },
    GetInt32 { vr: Arr<u32>, n_values: usize, null_values: bool },
    /// Of the Enumerations (FMI 3.0 2.4.7.4), as of any other variable.
    GetInt64 { vr: Arr<u32>, n_values: usize, null_values: bool },
    GetBoolean { vr: Arr<u32>, n_values: usize, null_values: bool },
    GetString { vr: Arr<u32>, n_values: usize, null_values: bool },
    SetFloat64 { vr: Arr<u32>, values: Arr<f64> },
    SetInt32 { vr: Arr<u32>, values: Arr<i32> },
    SetInt64 { vr: Arr<u32>, values: Arr<i64> },
    /// Bytes, so that values other than 0 and 1 can be passed.
    SetBoolean { vr: Arr<u32>, values: Arr<u8> },
    SetString { vr: Arr<u32>, values: Arr<Text> },
    /// fmi3Get<OTHER_TYPES[ty]> or fmi3Set<...>.
    OtherType { ty: usize, set: bool, vr: Arr<u32> },
    /// fmi3<REFUSED[function]>.
    Refused { function: usize },
    /// fmi3SetClock and fmi3GetClock (`clock_rules`; the FMUs without a Clock get
    /// `OtherType`): fmi3Clock values as bytes, so that values other than 0 and 1 can be passed.
    SetClock { vr: Arr<u32>, values: Arr<u8> },
    GetClock { vr: Arr<u32>, null_values: bool },
    State(StateCall),
    /// fmi3GetDirectionalDerivative or (`adjoint`) fmi3GetAdjointDerivative: `n_sensitivity`
    /// elements are written.
    Derivative { adjoint: bool, unknowns: Arr<u32>, knowns: Arr<u32>, seed: Arr<f64>, n_sensitivity: usize, null_sensitivity: bool },
    EnterStepMode,
    DoStep { t: f64, h: f64, no_set_prior: bool, null_outputs: bool },
    UpdateDiscreteStates { null_flags: bool },
    EnterContinuousTimeMode,
    CompletedIntegratorStep { no_set_prior: bool, null_flags: bool },
    SetTime { t: f64 },
    SetContinuousStates { x: Arr<f64> },
    /// fmi3GetContinuousStateDerivatives, fmi3GetEventIndicators, fmi3GetContinuousStates,
    /// fmi3GetNominalsOfContinuousStates: `n` announced, NULL for `null`.
    GetContinuousStateDerivatives { n: usize, null: bool },
    GetEventIndicators { n: usize, null: bool },
    GetContinuousStates { n: usize, null: bool },
    GetNominalsOfContinuousStates { n: usize, null: bool },
    GetNumberOfContinuousStates { null: bool },
    GetNumberOfEventIndicators { null: bool },
    /// A function with a count larger than the model allows (`oversized`).
    Oversized(crate::oversized::Oversized),
}

impl Call for Op3 {
    fn takes_instance(&self) -> bool {
        !matches!(self, Op3::GetVersion | Op3::Instantiate(_) | Op3::FreeInstance { .. })
    }
    fn free_instance(instance: *mut c_void) -> Op3 {
        Op3::FreeInstance { instance }
    }
    fn state(call: StateCall) -> Op3 {
        Op3::State(call)
    }
}

/// A get or set of variable values: its value references, nValues, the base type of the
/// function (`Type::Enumeration`: Int64) and whether it sets.
pub struct Access<'a> {
    pub vr: &'a Arr<u32>,
    pub n_values: usize,
    pub ty: Type,
    pub set: bool,
}

impl Op3 {
    /// The fmi3Get<type> and fmi3Set<type> of the types variables have, as an `Access`.
    pub fn access(&self) -> Option<Access<'_>> {
        let (vr, n_values, ty, set) = match self {
            Op3::GetFloat64 { vr, n_values, .. } => (vr, *n_values, Type::Real, false),
            Op3::GetInt32 { vr, n_values, .. } => (vr, *n_values, Type::Integer, false),
            Op3::GetInt64 { vr, n_values, .. } => (vr, *n_values, Type::Enumeration, false),
            Op3::GetBoolean { vr, n_values, .. } => (vr, *n_values, Type::Boolean, false),
            Op3::GetString { vr, n_values, .. } => (vr, *n_values, Type::String, false),
            Op3::SetFloat64 { vr, values } => (vr, values.len(), Type::Real, true),
            Op3::SetInt32 { vr, values } => (vr, values.len(), Type::Integer, true),
            Op3::SetInt64 { vr, values } => (vr, values.len(), Type::Enumeration, true),
            Op3::SetBoolean { vr, values } => (vr, values.len(), Type::Boolean, true),
            Op3::SetString { vr, values } => (vr, values.len(), Type::String, true),
            _ => return None,
        };
        Some(Access { vr, n_values, ty, set })
    }

    /// The call for the trace: the FMI 3.0 name and the arguments.
    pub fn describe(&self) -> String {
        match self {
            Op3::State(call) => call.describe(true),
            Op3::OtherType { ty, set, vr } => {
                format!("fmi3{}{} {{ vr: {vr:?} }}", if *set { "Set" } else { "Get" }, OTHER_TYPES[*ty])
            }
            Op3::Refused { function } => format!("fmi3{}", REFUSED[*function]),
            Op3::Oversized(o) => o.describe(true),
            Op3::Instantiate(i) => format!("fmi3Instantiate{:?}({i:?})", i.interface),
            Op3::Derivative { adjoint: true, .. } => format!("fmi3GetAdjointDerivative{}", arguments(self)),
            Op3::Derivative { .. } => format!("fmi3GetDirectionalDerivative{}", arguments(self)),
            op => format!("fmi3{op:?}"),
        }
    }
}

/// The derived Debug of a variant without its name.
fn arguments(op: &Op3) -> String {
    let all = format!("{op:?}");
    all.find(' ').map_or(String::new(), |i| all[i..].to_owned())
}
