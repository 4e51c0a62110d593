//! The .fmu archive: modelDescription.xml at the root, the shared library of every platform
//! under `binaries/<platform>/<modelIdentifier>.<so|dll>` ([`crate::platform`]), and
//! `documentation/index.html`.

use super::model::Model;
use super::variables::{Kind, Variable};
use super::log::num;
use super::xml::model_description;
use crate::platform::Platform;
use std::io::Write;
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;

/// One FMU the project ships: its model and the cdylib package that exports it.
#[derive(Clone, Copy)]
pub struct Fmu {
    pub identifier: &'static str,
    /// Cargo package of the cdylib crate under `fmu/<identifier>/`.
    pub package: &'static str,
    pub model_description: fn() -> String,
    pub documentation: fn() -> String,
}

impl Fmu {
    /// The FMU of model `M`, built by the cdylib package `package`.
    pub fn of<M: Model>(package: &'static str) -> Self {
        Fmu {
            identifier: M::INFO.identifier,
            package,
            model_description: model_description::<M>,
            documentation: documentation::<M>,
        }
    }

    /// Writes the .fmu from the built shared library of each platform. Entries carry a fixed
    /// timestamp, so the archive is reproducible.
    pub fn write(&self, libraries: &[(Platform, PathBuf)], out: &Path) -> zip::result::ZipResult<()> {
        let mut zip = zip::ZipWriter::new(std::fs::File::create(out)?);
        let deflate = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("modelDescription.xml", deflate)?;
        zip.write_all((self.model_description)().as_bytes())?;
        for (platform, library) in libraries {
            zip.start_file(platform.entry(self.identifier), deflate.unix_permissions(0o755))?;
            zip.write_all(&std::fs::read(library)?)?;
        }
        zip.start_file("documentation/index.html", deflate)?;
        zip.write_all((self.documentation)().as_bytes())?;
        zip.finish()?;
        Ok(())
    }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

fn row(v: &Variable) -> String {
    let (ty, start, unit, range) = match v.kind {
        Kind::Real { start, unit, display_unit, min, max } => {
            let unit = if display_unit.is_empty() { unit.to_owned() } else { format!("{unit} ({display_unit})") };
            let range = format!("[{}, {}]", num(min), num(max));
            ("Real", num(start), unit, range)
        }
        Kind::Integer { start, min, max } => ("Integer", start.to_string(), String::new(), format!("[{min}, {max}]")),
        Kind::Boolean { start } => ("Boolean", start.to_string(), String::new(), String::new()),
        Kind::String { start } => ("String", start.to_owned(), String::new(), String::new()),
    };
    let start = if v.has_start() { start } else { String::new() };
    format!(
        "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{:?}</td><td>{ty}</td><td>{start}</td><td>{unit}</td><td>{}</td><td>{}</td></tr>\n",
        html_escape(v.name),
        v.vr,
        v.causality,
        v.variability,
        html_escape(&range),
        html_escape(v.description)
    )
}

/// documentation/index.html: the model's equations and notes, and every variable.
pub fn documentation<M: Model>() -> String {
    let i = &M::INFO;
    let rows: String = M::VARIABLES.iter().map(row).collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{id}</title></head><body>\n<h1>{id} {version}</h1>\n<p>{desc}</p>\n<h2>Model</h2>\n{doc}\n<h2>Variables</h2>\n<p>All values are SI; the display unit is given in brackets.</p>\n<table border=\"1\">\n<tr><th>Name</th><th>VR</th><th>Causality</th><th>Variability</th><th>Type</th><th>Start</th><th>Unit</th><th>Range</th><th>Description</th></tr>\n{rows}</table>\n</body></html>\n",
        id = i.identifier,
        version = i.version,
        desc = html_escape(i.description),
        doc = i.documentation,
    )
}
