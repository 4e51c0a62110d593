//! Runs one FMU through the `fmi` crate (an independent Rust FMI importer) for the
//! compatibility matrix of scripts/compat.py:
//!
//!     cargo run --release --example fmi_import -- <file.fmu> <stop> <step> [name=value ...]
//!
//! The FMU's fmiVersion chooses the crate's FMI 2.0 or FMI 3.0 (feature `fmi3`) import; both
//! run the same steps (Co-Simulation, start values set in initialisation mode, fixed steps k h).
//! Prints one JSON object: `loads` (unzipped, modelDescription parsed, instantiated),
//! `validates` (an FMI 2.0 / 3.0 co-simulation description with unique value references and
//! names, the GUID / instantiationToken accepted by the instantiate function), `simulates`
//! (initialised with the start values, stepped to `stop`), `outputs` (every Real / Float64 output
//! at `stop`), `fmi_version` and `error`.

// The crate's FMI 2.0 and FMI 3.0 traits have the same names.
use fmi::fmi2::instance::{CoSimulation as Cs2, Common as Common2};
use fmi::fmi3::{CoSimulation as Cs3, Common as Common3, GetSet};
use fmi::traits::FmiImport;
use serde_json::{json, Map, Value};
use std::collections::HashSet;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = |why: &str| -> ! {
        eprintln!("fmi_import: {why}; usage: fmi_import <file.fmu> <stop> <step> [name=value ...]");
        std::process::exit(2)
    };
    let (path, stop, step) = match &args[..] {
        [p, s, h, ..] => match (s.parse::<f64>(), h.parse::<f64>()) {
            (Ok(s), Ok(h)) if s > 0.0 && h > 0.0 => (p.clone(), s, h),
            _ => usage(&format!("stop {s:?} and step {h:?} must be positive numbers")),
        },
        _ => usage("too few arguments"),
    };
    let mut report = Map::new();
    for key in ["loads", "validates", "simulates"] {
        report.insert(key.into(), json!(false));
    }
    if let Err(e) = run(&path, stop, step, &args[3..], &mut report) {
        report.insert("error".into(), json!(e));
    }
    println!("{}", Value::Object(report));
}

/// The type of a variable, as far as this importer sets or reads it.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
    Other,
}

/// A variable of either version's model description.
struct Var {
    name: String,
    vr: u32,
    kind: Kind,
    output: bool,
}

/// The calls of a Co-Simulation run, implemented by each version's instance.
trait Slave {
    fn enter_initialization_mode(&mut self, stop: f64) -> Result<(), String>;
    fn exit_initialization_mode(&mut self) -> Result<(), String>;
    fn set_real(&mut self, vr: u32, x: f64) -> Result<(), String>;
    fn set_integer(&mut self, vr: u32, x: i32) -> Result<(), String>;
    fn set_boolean(&mut self, vr: u32, x: bool) -> Result<(), String>;
    /// Sets `value` (text) as a start value of the variable's type.
    fn set(&mut self, vr: u32, kind: Kind, value: &str) -> Result<(), String> {
        match kind {
            Kind::Real => self.set_real(vr, value.parse().map_err(|_| format!("{value}: not a number"))?),
            Kind::Integer => self.set_integer(vr, value.parse().map_err(|_| format!("{value}: not an integer"))?),
            Kind::Boolean => match value {
                "true" | "1" => self.set_boolean(vr, true),
                "false" | "0" => self.set_boolean(vr, false),
                _ => Err(format!("{value}: not a Boolean (true, false, 1 or 0)")),
            },
            Kind::Other => Err("unsupported type".into()),
        }
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String>;
    fn get_real(&mut self, vr: u32) -> Result<f64, String>;
    fn terminate(&mut self) -> Result<(), String>;
}

fn run(path: &str, stop: f64, step: f64, starts: &[String], report: &mut Map<String, Value>) -> Result<(), String> {
    let version = fmi::import::peek_descr_path(path).map_err(|e| format!("import {path}: {e}"))?.fmi_version;
    report.insert("fmi_version".into(), json!(version));
    match version.as_str() {
        "2.0" => run2(path, stop, step, starts, report),
        "3.0" => run3(path, stop, step, starts, report),
        v => Err(format!("fmiVersion {v:?}: this importer runs 2.0 and 3.0")),
    }
}

fn run2(path: &str, stop: f64, step: f64, starts: &[String], report: &mut Map<String, Value>) -> Result<(), String> {
    use fmi::schema::fmi2::{Causality, ScalarVariableElement};

    let import: fmi::fmi2::import::Fmi2Import = fmi::import::from_path(path).map_err(|e| format!("import: {e}"))?;
    let md = import.model_description();
    let vars: Vec<Var> = md
        .model_variables
        .variables
        .iter()
        .map(|v| Var {
            name: v.name.clone(),
            vr: v.value_reference,
            kind: match v.elem {
                ScalarVariableElement::Real(_) => Kind::Real,
                ScalarVariableElement::Integer(_) => Kind::Integer,
                ScalarVariableElement::Boolean(_) => Kind::Boolean,
                _ => Kind::Other,
            },
            output: v.causality == Causality::Output,
        })
        .collect();
    let mut s = import.instantiate_cs("compat", false, false).map_err(|e| format!("instantiate: {e}"))?;
    simulate(&mut s, md.fmi_version == "2.0" && md.co_simulation.is_some(), &vars, (stop, step), starts, report)
}

fn run3(path: &str, stop: f64, step: f64, starts: &[String], report: &mut Map<String, Value>) -> Result<(), String> {
    use fmi::fmi3::Fmi3Model;
    use fmi::schema::fmi3::{Causality, VariableType};

    let import: fmi::fmi3::import::Fmi3Import = fmi::import::from_path(path).map_err(|e| format!("import: {e}"))?;
    let md = import.model_description();
    let vars: Vec<Var> = md
        .model_variables
        .iter_abstract()
        .map(|v| Var {
            name: v.name().into(),
            vr: v.value_reference(),
            kind: match v.data_type() {
                VariableType::FmiFloat64 => Kind::Real,
                VariableType::FmiInt32 => Kind::Integer,
                VariableType::FmiBoolean => Kind::Boolean,
                _ => Kind::Other,
            },
            output: v.causality() == Causality::Output,
        })
        .collect();
    let mut s =
        import.instantiate_cs("compat", false, false, false, false, &[]).map_err(|e| format!("instantiate: {e}"))?;
    simulate(&mut s, md.fmi_version == "3.0" && md.co_simulation.is_some(), &vars, (stop, step), starts, report)
}

impl Slave for fmi::fmi2::instance::InstanceCS {
    fn enter_initialization_mode(&mut self, stop: f64) -> Result<(), String> {
        Common2::setup_experiment(self, None, 0.0, Some(stop)).map_err(|e| format!("setupExperiment: {e}"))?;
        Common2::enter_initialization_mode(self).map_err(|e| format!("enterInitializationMode: {e}"))?;
        Ok(())
    }
    fn exit_initialization_mode(&mut self) -> Result<(), String> {
        Common2::exit_initialization_mode(self).map(drop).map_err(|e| format!("exitInitializationMode: {e}"))
    }
    fn set_real(&mut self, vr: u32, x: f64) -> Result<(), String> {
        Common2::set_real(self, &[vr], &[x]).map(drop).map_err(|e| e.to_string())
    }
    fn set_integer(&mut self, vr: u32, x: i32) -> Result<(), String> {
        Common2::set_integer(self, &[vr], &[x]).map(drop).map_err(|e| e.to_string())
    }
    fn set_boolean(&mut self, vr: u32, x: bool) -> Result<(), String> {
        Common2::set_boolean(self, &[vr], &[i32::from(x)]).map(drop).map_err(|e| e.to_string())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        Cs2::do_step(self, t, h, true).map(drop).map_err(|e| e.to_string())
    }
    fn get_real(&mut self, vr: u32) -> Result<f64, String> {
        let mut x = [0.0];
        Common2::get_real(self, &[vr], &mut x).map_err(|e| e.to_string())?;
        Ok(x[0])
    }
    fn terminate(&mut self) -> Result<(), String> {
        Common2::terminate(self).map(drop).map_err(|e| format!("terminate: {e}"))
    }
}

impl Slave for fmi::fmi3::instance::InstanceCS {
    fn enter_initialization_mode(&mut self, stop: f64) -> Result<(), String> {
        Common3::enter_initialization_mode(self, None, 0.0, Some(stop))
            .map(drop)
            .map_err(|e| format!("enterInitializationMode: {e}"))
    }
    fn exit_initialization_mode(&mut self) -> Result<(), String> {
        Common3::exit_initialization_mode(self).map(drop).map_err(|e| format!("exitInitializationMode: {e}"))
    }
    fn set_real(&mut self, vr: u32, x: f64) -> Result<(), String> {
        GetSet::set_float64(self, &[vr], &[x]).map(drop).map_err(|e| e.to_string())
    }
    fn set_integer(&mut self, vr: u32, x: i32) -> Result<(), String> {
        GetSet::set_int32(self, &[vr], &[x]).map(drop).map_err(|e| e.to_string())
    }
    fn set_boolean(&mut self, vr: u32, x: bool) -> Result<(), String> {
        GetSet::set_boolean(self, &[vr], &[x]).map(drop).map_err(|e| e.to_string())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
        Cs3::do_step(self, t, h, true, &mut event, &mut terminate, &mut early, &mut last).map_err(|e| e.to_string())?;
        // FMI 3.0, 4.2.1: without early return the step reaches t + h
        if event || terminate || early || last != t + h {
            return Err(format!(
                "event {event}, terminate {terminate}, early return {early}, reached {last} instead of {}",
                t + h
            ));
        }
        Ok(())
    }
    fn get_real(&mut self, vr: u32) -> Result<f64, String> {
        let mut x = [0.0];
        GetSet::get_float64(self, &[vr], &mut x).map_err(|e| e.to_string())?;
        Ok(x[0])
    }
    fn terminate(&mut self) -> Result<(), String> {
        Common3::terminate(self).map(drop).map_err(|e| format!("terminate: {e}"))
    }
}

/// The run both versions share: validity, start values, k steps of h, the Real outputs at `stop`.
fn simulate(
    s: &mut dyn Slave,
    description_valid: bool,
    vars: &[Var],
    (stop, step): (f64, f64),
    starts: &[String],
    report: &mut Map<String, Value>,
) -> Result<(), String> {
    report.insert("loads".into(), json!(true));
    let names: HashSet<&str> = vars.iter().map(|v| v.name.as_str()).collect();
    let vrs: HashSet<u32> = vars.iter().map(|v| v.vr).collect();
    let valid = description_valid && names.len() == vars.len() && vrs.len() == vars.len();
    report.insert("validates".into(), json!(valid));

    s.enter_initialization_mode(stop)?;
    for kv in starts {
        let (name, value) = kv.split_once('=').ok_or(format!("start value {kv}: expected name=value"))?;
        let v = vars.iter().find(|v| v.name == name).ok_or(format!("no variable {name}"))?;
        s.set(v.vr, v.kind, value).map_err(|e| format!("set {name}={value}: {e}"))?;
    }
    s.exit_initialization_mode()?;
    let n = (stop / step).round() as usize;
    for k in 0..n {
        let t = k as f64 * step;
        s.do_step(t, step).map_err(|e| format!("doStep at {t}: {e}"))?;
    }
    let mut outputs = Map::new();
    for v in vars.iter().filter(|v| v.output && v.kind == Kind::Real) {
        outputs.insert(v.name.clone(), json!(s.get_real(v.vr).map_err(|e| format!("get {}: {e}", v.name))?));
    }
    s.terminate()?;
    report.insert("simulates".into(), json!(true));
    report.insert("outputs".into(), Value::Object(outputs));
    Ok(())
}
