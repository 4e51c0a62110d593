//! The stiff integrator used inside fmi2DoStep.
