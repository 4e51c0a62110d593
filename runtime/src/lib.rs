//! boomsim: the hydraulically actuated boom of the thesis "Stabilization of hydraulically actuated
//! boom using pressure feedback" as FMUs with a C ABI: FMI 2.0 and 3.0, Model Exchange and
//! Co-Simulation in one .fmu.
//!
//! This crate is what runs inside every .fmu. Physics lives in [`hydraulics`], [`mechanics`] and
//! [`control`] and knows nothing about FMI; [`solver`] integrates it; [`models`] composes it into
//! FMU models; [`fmu`] is what both FMI versions share (the model contract, the instance and its
//! state machine, the bodies of the C calls), and [`fmi2`] and [`fmi3`] export any model through
//! their C functions. The packer, modelDescription.xml, the bench, the scenario runner and the
//! linear analysis are the tools crate (`boomsim-tools`, the `boomsim` binary).

pub mod control;
pub mod fmi2;
pub mod fmi3;
pub mod fmu;
pub mod hydraulics;
pub mod mechanics;
pub mod models;
pub mod params;
pub mod scalar;
pub mod solver;
pub mod units;
