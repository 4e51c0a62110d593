//! Runs one FMU through the `fmi` crate (an independent Rust FMI importer) for the
//! compatibility matrix of scripts/compat.py:
//!
//!     cargo run --release --example fmi_import -- <file.fmu> <stop> <step> [name=value ...]
//!
//! Prints one JSON object: `loads` (unzipped, modelDescription parsed, instantiated),
//! `validates` (FMI 2.0 co-simulation description with unique value references and names, the
//! GUID accepted by fmi2Instantiate), `simulates` (initialised with the start values, stepped to
//! `stop`), `outputs` (every Real output at `stop`) and `error`.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::schema::fmi2::{Causality, ScalarVariableElement};
use fmi::traits::FmiImport;
use serde_json::{json, Map, Value};
use std::collections::HashSet;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (path, stop, step) = match &args[..] {
        [p, s, h, ..] => (p.clone(), s.parse::<f64>().expect("stop time"), h.parse::<f64>().expect("step")),
        _ => panic!("usage: fmi_import <file.fmu> <stop> <step> [name=value ...]"),
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

fn run(path: &str, stop: f64, step: f64, starts: &[String], report: &mut Map<String, Value>) -> Result<(), String> {
    let import: Fmi2Import = fmi::import::from_path(path).map_err(|e| format!("import: {e}"))?;
    let md = import.model_description();
    let vars = &md.model_variables.variables;
    let names: HashSet<&str> = vars.iter().map(|v| v.name.as_str()).collect();
    let vrs: HashSet<u32> = vars.iter().map(|v| v.value_reference).collect();
    let mut s = import.instantiate_cs("compat", false, false).map_err(|e| format!("instantiate: {e}"))?;
    report.insert("loads".into(), json!(true));
    let valid =
        md.fmi_version == "2.0" && md.co_simulation.is_some() && names.len() == vars.len() && vrs.len() == vars.len();
    report.insert("validates".into(), json!(valid));

    s.setup_experiment(None, 0.0, Some(stop)).map_err(|e| format!("setupExperiment: {e}"))?;
    s.enter_initialization_mode().map_err(|e| format!("enterInitializationMode: {e}"))?;
    for kv in starts {
        let (name, value) = kv.split_once('=').ok_or(format!("start value {kv}: expected name=value"))?;
        let v = vars.iter().find(|v| v.name == name).ok_or(format!("no variable {name}"))?;
        let r = [v.value_reference];
        let res = match v.elem {
            ScalarVariableElement::Real(_) => {
                s.set_real(&r, &[value.parse().map_err(|_| format!("{kv}: not a number"))?])
            }
            ScalarVariableElement::Integer(_) => {
                s.set_integer(&r, &[value.parse().map_err(|_| format!("{kv}: not an integer"))?])
            }
            ScalarVariableElement::Boolean(_) => s.set_boolean(&r, &[i32::from(value == "true" || value == "1")]),
            _ => return Err(format!("{name}: unsupported type")),
        };
        res.map_err(|e| format!("set {name}: {e}"))?;
    }
    s.exit_initialization_mode().map_err(|e| format!("exitInitializationMode: {e}"))?;
    let n = (stop / step).round() as usize;
    for k in 0..n {
        s.do_step(k as f64 * step, step, true).map_err(|e| format!("doStep at {}: {e}", k as f64 * step))?;
    }
    let mut outputs = Map::new();
    for v in vars.iter().filter(|v| v.causality == Causality::Output) {
        if let ScalarVariableElement::Real(_) = v.elem {
            let mut x = [0.0];
            s.get_real(&[v.value_reference], &mut x).map_err(|e| format!("get {}: {e}", v.name))?;
            outputs.insert(v.name.clone(), json!(x[0]));
        }
    }
    s.terminate().map_err(|e| format!("terminate: {e}"))?;
    report.insert("simulates".into(), json!(true));
    report.insert("outputs".into(), Value::Object(outputs));
    Ok(())
}
