//! The FMI 2.0 adapter (Model Exchange and Co-Simulation): any [`Model`] becomes an FMU through
//! [`export_fmu!`](crate::export_fmu). It knows nothing about the physics it exposes; what it
//! shares with FMI 3.0 lives in [`crate::fmu`] (re-exported here under its old paths).

pub mod api;
mod export;
pub mod machine;
pub mod types;
pub mod xml;

pub use crate::fmu::{guid, instance, log, model, pack, snapshot, structure, variables};
pub use crate::fmu::{Causality, ContinuousState, Fmu, Initial, Kind, Log, Model, ModelInfo, StepError, Value};
pub use crate::fmu::{Values, Variability, Variable};
