//! The tools around the boomsim FMUs, behind the `boomsim` binary: the .fmu packer ([`pack`]:
//! platforms, modelDescription.xml from [`xml`], the documentation page with its [`figures`]),
//! the bench, the native scenario runner ([`cosim`]), the linear analysis ([`analysis`]) and the
//! static deflection study. The models and everything inside an FMU are the runtime crate,
//! [`boomsim`]; nothing here is linked into an FMU binary.

pub mod analysis;
pub mod arrays;
/// Timing through dlopen: Unix only.
#[cfg(unix)]
pub mod bench;
pub mod chart;
pub mod cosim;
pub mod deflection_study;
pub mod figures;
pub mod in_process;
pub mod jacobian_cost;
pub mod pack;
pub mod platform;
pub mod reference;
pub mod xml;
