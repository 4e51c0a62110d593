//! The .fmu archive of either FMI version: modelDescription.xml at the root, the shared library
//! of every platform under `binaries/<platform>/<modelIdentifier>.<so|dll>` (the version's
//! platform names, [`crate::platform`]), `documentation/index.html`, the reference results in
//! `documentation/reference/` ([`crate::reference`]) and, in FMI 3.0, the model's terminals in
//! `terminalsAndIcons/terminalsAndIcons.xml`. The same library goes into both versions' archives:
//! it exports the fmi2* and the fmi3* symbols.

use crate::chart::escape;
use crate::figures::Figures;
use crate::platform::Platform;
use crate::reference::{self, Referenced};
use boomsim::fmu::guid::{guid, token};
use boomsim::fmu::log::{num, GENERIC_CATEGORIES};
use boomsim::fmu::model::clock_row;
use boomsim::fmu::model::Model;
use boomsim::fmu::variables::{Kind, Variable};
use boomsim::fmu::version::Version;
use boomsim::models::{
    BoomMechanics, ClockedPressureFeedbackController, HydraulicBoom, HydraulicCircuit, PressureFeedbackController,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;

/// Every FMU boomsim ships, with the cdylib package that exports it.
pub fn all() -> Vec<Fmu> {
    vec![
        Fmu::of::<PressureFeedbackController>("fmu-pressure-feedback-controller"),
        Fmu::of::<ClockedPressureFeedbackController>("fmu-clocked-pressure-feedback-controller"),
        Fmu::of::<HydraulicBoom>("fmu-hydraulic-boom"),
        Fmu::of::<HydraulicCircuit>("fmu-hydraulic-circuit"),
        Fmu::of::<BoomMechanics>("fmu-boom-mechanics"),
    ]
}

/// One FMU the project ships: its model and the cdylib package that exports it.
#[derive(Clone, Copy)]
pub struct Fmu {
    pub identifier: &'static str,
    /// Cargo package of the cdylib crate under `fmu/<identifier>/`.
    pub package: &'static str,
    /// modelDescription.xml of each version.
    pub model_description: fn(Version) -> String,
    /// documentation/index.html of a version for the platforms packed.
    pub documentation: fn(Version, &[Platform]) -> String,
    /// terminalsAndIcons.xml (FMI 3.0), when the model has terminals.
    pub terminals: fn() -> Option<String>,
    /// The files of documentation/reference/: (name, content).
    pub reference: fn() -> Result<Vec<(String, String)>, String>,
    /// Whether it has an FMI 2.0 archive: not for a model with a Clock (FMI 3.0 only).
    pub fmi2: bool,
}

impl Fmu {
    /// The FMU of model `M`, built by the cdylib package `package`.
    pub fn of<M: Figures + Referenced>(package: &'static str) -> Self {
        Fmu {
            identifier: M::INFO.identifier,
            package,
            model_description: model_description::<M>,
            documentation: documentation::<M>,
            terminals: crate::xml::terminals::terminals_and_icons::<M>,
            reference: reference::files::<M>,
            fmi2: clock_row::<M>().is_none(),
        }
    }

    /// Whether the FMU has an archive of FMI `version`.
    pub fn has(&self, version: Version) -> bool {
        version == Version::Fmi3 || self.fmi2
    }

    /// Writes the .fmu of `version` from the built shared library of each platform. Entries carry
    /// a fixed timestamp, so the archive is reproducible.
    pub fn write(&self, version: Version, libraries: &[(Platform, PathBuf)], out: &Path) -> zip::result::ZipResult<()> {
        let mut zip = zip::ZipWriter::new(std::fs::File::create(out)?);
        let deflate = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("modelDescription.xml", deflate)?;
        zip.write_all((self.model_description)(version).as_bytes())?;
        for (platform, library) in libraries {
            zip.start_file(platform.entry(version, self.identifier), deflate.unix_permissions(0o755))?;
            zip.write_all(&std::fs::read(library)?)?;
        }
        zip.start_file("documentation/index.html", deflate)?;
        let platforms: Vec<Platform> = libraries.iter().map(|(p, _)| *p).collect();
        zip.write_all((self.documentation)(version, &platforms).as_bytes())?;
        for (name, content) in
            (self.reference)().map_err(|e| std::io::Error::other(format!("{}: {e}", self.identifier)))?
        {
            zip.start_file(format!("documentation/reference/{name}"), deflate)?;
            zip.write_all(content.as_bytes())?;
        }
        if let (Version::Fmi3, Some(terminals)) = (version, (self.terminals)()) {
            zip.start_file("terminalsAndIcons/terminalsAndIcons.xml", deflate)?;
            zip.write_all(terminals.as_bytes())?;
        }
        zip.finish()?;
        Ok(())
    }
}

fn row(v: &Variable) -> String {
    let (ty, start, unit, range) = match v.kind {
        Kind::Real { start, unit, display_unit, min, max } => {
            let shown = |x: f64| match in_display_unit(x, unit, display_unit) {
                Some(d) => format!("{} ({d})", num(x)),
                None => num(x),
            };
            let unit = if display_unit.is_empty() { unit.to_owned() } else { format!("{unit} ({display_unit})") };
            let range = format!("[{}, {}]", num(min), num(max));
            ("Real", shown(start), unit, range)
        }
        Kind::Integer { start, min, max } => ("Integer", start.to_string(), String::new(), format!("[{min}, {max}]")),
        Kind::Enumeration { start, ty } => {
            let name = ty.item(i64::from(start)).map_or("", |i| i.name);
            ("Enumeration", format!("{start} ({name})"), String::new(), ty.listed())
        }
        Kind::Boolean { start } => ("Boolean", start.to_string(), String::new(), String::new()),
        Kind::String { start } => ("String", start.to_owned(), String::new(), String::new()),
        Kind::Clock { interval, shift } => {
            ("Clock", String::new(), "s".into(), format!("every {} s from {} s", num(interval), num(shift)))
        }
    };
    let start = if v.has_start() { start } else { String::new() };
    format!(
        "<tr><td><code>{}</code></td><td>{}</td><td>{:?}</td><td>{:?}</td><td>{ty}</td><td>{start}</td><td>{unit}</td><td>{}</td><td>{}</td></tr>\n",
        escape(v.name),
        v.vr,
        v.causality,
        v.variability,
        escape(&range),
        escape(v.description)
    )
}

/// `x` in the display unit, as "25 l/min" (None without a display unit other than the unit).
fn in_display_unit(x: f64, unit: &str, display_unit: &str) -> Option<String> {
    let d = boomsim::units::display_unit(unit, display_unit)?;
    let y = d.factor * x + d.offset;
    // Rounded to 6 significant digits: the SI value beside it is exact.
    let y: f64 = format!("{y:.5e}").parse().unwrap_or(y);
    Some(format!("{} {display_unit}", num(y)))
}

/// modelDescription.xml of model `M` in FMI `version`.
pub fn model_description<M: Model>(version: Version) -> String {
    match version {
        Version::Fmi2 => crate::xml::fmi2::model_description::<M>(),
        Version::Fmi3 => crate::xml::fmi3::model_description::<M>(),
    }
}

/// The facts of the FMU, generated so that they cannot go stale: interface, version, GUID,
/// default experiment, interpolated inputs, log categories, platforms.
fn facts<M: Model>(version: Version, platforms: &[Platform]) -> String {
    let i = &M::INFO;
    let name = |r: &u32| M::VARIABLES.iter().find(|v| v.vr == *r).map_or("?", |v| v.name);
    let ramped = if version == Version::Fmi3 { M::INTERMEDIATE_INPUTS } else { i.interpolated_inputs };
    let interpolated: Vec<&str> = ramped.iter().map(name).collect();
    let categories: Vec<&str> = GENERIC_CATEGORIES.iter().chain(i.log_categories).map(|c| c.0).collect();
    let platforms: Vec<&str> = platforms.iter().map(|p| p.folder(version)).collect();
    let states: Vec<&str> = M::STATES.iter().map(|s| name(&s.state)).collect();
    let (fmi, identity, interpolation, after_error) = match version {
        Version::Fmi2 => (
            "FMI 2.0",
            ("GUID", guid::<M>()),
            "Inputs linear over a step (fmi2SetRealInputDerivatives)",
            "A refused call changes nothing and the instance goes on (FMI 2.0 leaves the state after fmi2Error open); \
             a model that leaves its valid range puts it in the Error state (fmi2Reset, fmi2SetFMUstate). \
             fmi2Discard of fmi2DoStep stops at the last good time (fmi2LastSuccessfulTime).",
        ),
        Version::Fmi3 => (
            "FMI 3.0",
            ("Instantiation token", token::<M>()),
            "Inputs linear over a step by intermediate update (set in the intermediateUpdate callback where it \
             requests them; held over a step without one)",
            "Terminated after any fmi3Error (FMI 3.0, 2.3.1): getters, FMU states, fmi3Reset; fmi3SetFMUState of a \
             state saved before resumes. fmi3Discard of fmi3DoStep leaves the instance as before the step (2.2.4): \
             retry with a smaller step.",
        ),
    };
    let states_label =
        format!("Continuous states (Model Exchange, in {} order)", version.function("fmi2GetContinuousStates"));
    let rows = [
        (
            "Interfaces",
            match (clock_row::<M>(), version, M::EVENT_INDICATORS.is_empty()) {
                (Some(_), ..) => format!("{fmi} Model Exchange and Co-Simulation with Event Mode (a Clock)"),
                (None, Version::Fmi3, false) => format!(
                    "{fmi} Model Exchange and Co-Simulation (with earlyReturnAllowed a step ends at an event \
                     indicator's root; Event Mode there with eventModeUsed)"
                ),
                _ => format!("{fmi} Model Exchange and Co-Simulation"),
            },
        ),
        (states_label.as_str(), format!("{}: {}", states.len(), states.join(", "))),
        ("Model identifier", i.identifier.to_owned()),
        ("Version", i.version.to_owned()),
        identity,
        ("Platforms", platforms.join(", ")),
        (
            "Default experiment",
            format!(
                "{} to {} s, communication step {} s, relative tolerance {}",
                num(i.start_time),
                num(i.stop_time),
                num(i.step_size),
                num(i.default_tolerance)
            ),
        ),
        match clock_row::<M>().map(|r| &M::VARIABLES[r]) {
            Some(Variable { name, kind: Kind::Clock { interval, shift }, .. }) => (
                "Clock (input, constant interval)",
                format!("{name}: every {} s from {} s after the start time", num(*interval), num(*shift)),
            ),
            _ => (interpolation, if interpolated.is_empty() { "none".into() } else { interpolated.join(", ") }),
        },
        ("Log categories", categories.join(", ")),
        (
            "Model Exchange tolerance",
            match M::MODEL_EXCHANGE_TOLERANCE {
                Some(t) => format!(
                    "{} or tighter with a BDF integrator such as CVode; a looser one set at initialisation is kept \
                     with a warning",
                    num(t)
                ),
                None => "any".into(),
            },
        ),
        ("After an error", after_error.to_owned()),
        ("Variables", M::VARIABLES.len().to_string()),
    ];
    let terminals: Vec<String> = i
        .terminals
        .iter()
        .map(|t| {
            let members: Vec<String> = t.members.iter().map(|(m, r)| format!("{m}: {}", name(r))).collect();
            format!("{} ({}; {})", t.name, t.kind, members.join(", "))
        })
        .collect();
    let terminals = (version == Version::Fmi3 && !terminals.is_empty())
        .then(|| ("Terminals (terminalsAndIcons.xml, matching rule plug)", terminals.join("; ")));
    let rows: String = rows
        .iter()
        .chain(terminals.iter())
        .map(|(k, v)| format!("<tr><th>{k}</th><td>{}</td></tr>\n", escape(v)))
        .collect();
    format!("<table class=\"facts\">\n{rows}</table>\n")
}

/// A small stylesheet: readable tables in any browser an importer opens the page in.
const STYLE: &str = "body{font-family:sans-serif;max-width:70em;margin:2em auto;padding:0 1em;line-height:1.4}\
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #bbb;padding:0.2em 0.5em;text-align:left;\
vertical-align:top}th{background:#eee}code{font-size:95%}table.facts th{width:18em}\
figure{margin:1.5em 0}figure svg{max-width:100%;height:auto;border:1px solid #ddd}figcaption{font-size:90%;color:#333;max-width:56em}";

/// documentation/index.html of FMI `version`: the model's facts, equations and notes, and every
/// variable.
pub fn documentation<M: Figures>(version: Version, platforms: &[Platform]) -> String {
    let i = &M::INFO;
    let rows: String = M::VARIABLES.iter().map(row).collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{id}</title><style>{STYLE}</style></head><body>\n<h1>{id} {version}</h1>\n<p>{desc}</p>\n<p>From the master's thesis <i>Stabilization of hydraulically actuated boom using pressure feedback</i> (University of Agder), exported by boomsim.</p>\n{facts}<h2>Model</h2>\n{note}{doc}\n{figures}<h2>Variables</h2>\n<p>All values are SI; the display unit is given in brackets, and start values in it too.</p>\n<table>\n<tr><th>Name</th><th>VR</th><th>Causality</th><th>Variability</th><th>Type</th><th>Start</th><th>Unit</th><th>Range</th><th>Description</th></tr>\n{rows}</table>\n</body></html>\n",
        id = i.identifier,
        version = i.version,
        desc = escape(i.description),
        facts = facts::<M>(version, platforms),
        doc = i.documentation,
        figures = M::figures(),
        note = match (version, clock_row::<M>()) {
            (Version::Fmi2, _) | (_, Some(_)) => "",
            (Version::Fmi3, None) => "<p><i>The model text names FMI 2.0's functions: in FMI 3.0, fmi3DoStep and fmi3EnterInitializationMode (with the tolerance and stop time) take the roles of fmi2DoStep and fmi2SetupExperiment, and FMI 3.0 has no input derivatives: the inputs hold their value over a step.</i></p>\n",
        },
    )
}
