//! boomsim: the hydraulically actuated boom of the thesis "Stabilization of hydraulically actuated
//! boom using pressure feedback" as FMI 2.0 Co-Simulation FMUs.
//!
//! Physics lives in [`hydraulics`], [`mechanics`] and [`control`] and knows nothing about FMI;
//! [`models`] composes it into FMU models; [`fmi2`] exposes any model through the C ABI.

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
