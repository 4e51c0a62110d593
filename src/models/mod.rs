//! The FMU models: each struct composes the physics and implements [`crate::fmu::Model`], the
//! contract both FMI versions export.

pub mod boom;
pub mod boom_mechanics;
pub mod circuit;
pub(crate) mod figures;
pub mod hydraulic_boom;
pub mod hydraulic_circuit;
pub mod port;
pub mod pressure_feedback_controller;
pub mod exposed;
pub mod stepping;
pub mod table;
pub mod vr;

pub use boom_mechanics::BoomMechanics;
pub use hydraulic_boom::HydraulicBoom;
pub use hydraulic_circuit::HydraulicCircuit;
pub use pressure_feedback_controller::PressureFeedbackController;

use crate::fmu::Fmu;

/// Every FMU boomsim ships, with the cdylib package that exports it.
pub fn all() -> Vec<Fmu> {
    vec![
        Fmu::of::<PressureFeedbackController>("fmu-pressure-feedback-controller"),
        Fmu::of::<HydraulicBoom>("fmu-hydraulic-boom"),
        Fmu::of::<HydraulicCircuit>("fmu-hydraulic-circuit"),
        Fmu::of::<BoomMechanics>("fmu-boom-mechanics"),
    ]
}
