//! The FMU models: each struct composes the physics and implements [`crate::fmu::Model`], the
//! contract both FMI versions export.

pub mod boom;
pub mod clocked_pressure_feedback_controller;
pub mod boom_mechanics;
pub mod circuit;
pub mod hydraulic_boom;
pub mod hydraulic_circuit;
pub mod plant;
pub mod port;
pub mod pressure_feedback_controller;
pub mod exposed;
pub mod table;
pub mod terminals;
pub mod vr;

pub use boom_mechanics::BoomMechanics;
pub use clocked_pressure_feedback_controller::ClockedPressureFeedbackController;
pub use hydraulic_boom::HydraulicBoom;
pub use hydraulic_circuit::HydraulicCircuit;
pub use pressure_feedback_controller::PressureFeedbackController;
