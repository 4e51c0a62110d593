//! What FMI 2.0 and FMI 3.0 share: the model contract, the variable table and its value checks,
//! the instance (values, model, time, state), the states of the state machines, logging, FMU
//! state bytes, the ModelStructure probe, the GUID and the bodies of the C functions both
//! versions have. The adapters
//! [`crate::fmi2`] and [`crate::fmi3`] add only what their version names or types differently.

pub mod calls;
pub mod driver;
mod export;
mod forward;
pub mod snapshot;
pub mod guid;
pub mod instance;
pub mod log;
pub mod model;
pub mod machine;
pub mod structure;
pub mod variables;
pub mod version;

pub use log::Status;
pub use model::{ContinuousState, Log, Model, ModelInfo, Seeds, StepError, StepStart, Terminal};
pub use variables::{Causality, Initial, Kind, Value, Values, Variability, Variable};
pub use version::Version;
