//! Linearised stability analysis and filter tuning (thesis section 2.3 and 6.1): transfer
//! functions, the Routh-Hurwitz instability criterion, margins and settling times of the
//! pressure feedback, the `boomsim analyze` command, and the modes of the nonlinear model
//! linearised at rest (`boomsim eigen`).

pub mod cli;
pub mod criterion;
pub mod criterion_cli;
#[cfg(test)]
mod dimensions;
pub mod directional;
pub mod feedback;
pub mod linearize;
pub mod linearize_cli;
pub mod margins;
pub mod modes;
pub mod operating_point;
pub mod plant;
pub mod poly;
pub mod report;
pub mod routh;
pub mod sine_test;
pub mod step;
pub mod sweep;
pub mod tf;

pub use operating_point::OperatingPoint;
pub use report::Analysis;
