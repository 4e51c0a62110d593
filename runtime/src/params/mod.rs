//! Physical parameters: each with its thesis default, SI unit and source (equation or table).
//!
//! Component parameter structs live beside their component (`hydraulics`, `mechanics`,
//! `control`); this module holds the shared description type used to expose them as FMU
//! parameters and to document them.

/// Description of one physical parameter. Values are SI; `display_unit` is what users see.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Structured FMU name, e.g. `cbv.p_set`.
    pub name: &'static str,
    /// Default (SI).
    pub default: f64,
    /// SI unit, one of [`crate::units::UNITS`].
    pub unit: &'static str,
    /// Display unit ("" for none).
    pub display_unit: &'static str,
    /// Physically admissible range (SI); values outside are rejected.
    pub min: f64,
    pub max: f64,
    pub description: &'static str,
    /// Where the default comes from: thesis equation/table/section, or the reasoning if the
    /// thesis lacks it.
    pub source: &'static str,
}
