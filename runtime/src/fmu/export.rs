//! `export_fmu!`: the whole C ABI of one model, both versions' symbols ([`crate::export_fmi2`],
//! [`crate::export_fmi3`]; the names differ, fmi2* and fmi3*), so one cdylib serves both
//! versions' .fmu files. A cdylib crate under `fmu/<ModelIdentifier>/` consists of this one
//! invocation.

/// Exports the FMI 2.0 and the FMI 3.0 C ABI for a [`Model`](crate::fmu::Model).
#[macro_export]
macro_rules! export_fmu {
    ($model:ty) => {
        $crate::export_fmi2!($model);
        $crate::export_fmi3!($model);
    };
}
