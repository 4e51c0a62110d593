//! The packed .fmu files loaded by an independent importer, the `fmi` crate. Needs `boomsim pack` first (scripts/test runs it).

mod fmi3_crate;
mod fmi_crate;

use fmi::schema::traits::FmiModelDescription;
use fmi::schema::MajorVersion;
use fmi::traits::FmiImport;
use std::path::Path;

/// The packed .fmu of model `id` in the FMI version of `I` (target/fmu/ for 2.0, target/fmu/fmi3/
/// for 3.0), loaded by the fmi crate; its model description declares that fmiVersion.
fn fmu<I: FmiImport>(id: &str) -> I {
    let (dir, version) = match I::MAJOR_VERSION {
        MajorVersion::FMI2 => ("", "2.0"),
        MajorVersion::FMI3 => ("fmi3/", "3.0"),
        MajorVersion::FMI1 => unreachable!("boomsim packs no FMI 1.0 .fmu"),
    };
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join(format!("target/fmu/{dir}{id}.fmu"));
    assert!(path.exists(), "{} is missing: run `target/release/boomsim pack` first", path.display());
    let import: I = fmi::import::from_path(&path).expect("the fmi crate loads the FMU");
    assert_eq!(import.model_description().version_string(), version);
    import
}
