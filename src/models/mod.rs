//! The FMU models: each struct composes the physics and implements [`crate::fmi2::Model`].
