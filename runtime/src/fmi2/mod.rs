//! The FMI 2.0 adapter (Model Exchange and Co-Simulation): any [`crate::fmu::Model`] becomes an
//! FMU through [`export_fmu!`](crate::export_fmu). It knows nothing about the physics it
//! exposes; what it shares with FMI 3.0, the contract included, lives in [`crate::fmu`].

pub mod api;
mod export;
pub mod machine;
pub mod types;

