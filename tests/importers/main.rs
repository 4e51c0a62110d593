//! The packed .fmu files loaded by an independent importer, the `fmi` crate. Needs `boomsim pack` first (scripts/test runs it).

mod fmi3_crate;
mod fmi_crate;
