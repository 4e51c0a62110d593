//! The FMI 3.0 adapter (Model Exchange and Co-Simulation): the same models and variable tables
//! as [`crate::fmi2`], through the FMI 3.0 C ABI ([`export_fmi3!`](crate::export_fmi3), invoked
//! by `export_fmu!`). What both versions share lives in
//! [`crate::fmu`]; this module holds only FMI 3.0's names, types, state table.

pub mod api;
mod export;
pub mod machine;
pub mod types;
