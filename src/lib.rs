//! boomsim: the hydraulically actuated boom of the thesis "Stabilization of hydraulically actuated
//! boom using pressure feedback" as FMUs with a C ABI: FMI 2.0 and 3.0, Model Exchange and
//! Co-Simulation in one .fmu.
//!
//! Physics lives in [`hydraulics`], [`mechanics`] and [`control`] and knows nothing about FMI;
//! [`models`] composes it into FMU models; [`fmu`] is what both FMI versions share (the model
//! contract, the instance and its state machine, the bodies of the C calls), and [`fmi2`] and
//! [`fmi3`] export any model through their C functions. Beside the runtime: the packer and
//! documentation ([`fmu::pack`]), the bench, the native scenario runner ([`cosim`]) and the
//! linear analysis ([`analysis`]) of the `boomsim` binary.

pub mod analysis;
/// Timing through dlopen: Unix only (the library itself builds for every platform).
#[cfg(unix)]
pub mod bench;
pub mod control;
pub mod cosim;
pub mod fmi2;
pub mod fmi3;
pub mod fmu;
pub mod hydraulics;
pub mod mechanics;
pub mod models;
pub mod params;
pub mod platform;
pub mod scalar;
pub mod solver;
pub mod units;
