//! The models' behaviour through the FMI functions: pre-charged starts, the controller's pressure extrapolation, the real-time mode, the linear analysis against the nonlinear FMU.

#[path = "../common/mod.rs"]
mod common;
mod analysis;
mod pre_charge;
mod pressure_extrapolation;
mod realtime;
