//! The generic FMI 2.0 Co-Simulation layer.
