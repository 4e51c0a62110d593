//! The generic FMI 2.0 layer (Model Exchange and Co-Simulation): any [`Model`] becomes an FMU through
//! [`export_fmu!`](crate::export_fmu). It knows nothing about the physics it exposes.

pub mod api;
mod export;
pub mod fmu_state;
pub mod guid;
pub mod instance;
pub mod log;
pub mod model;
pub mod pack;
pub mod state;
pub mod structure;
pub mod types;
pub mod variables;
pub mod xml;

pub use model::{ContinuousState, Log, Model, ModelInfo, StepError};
pub use pack::Fmu;
pub use variables::{Causality, Initial, Kind, Value, Values, Variability, Variable};
