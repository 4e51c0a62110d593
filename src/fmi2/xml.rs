//! modelDescription.xml, generated with quick-xml from the model's variable table.

use super::guid::guid;
use super::log::{num, GENERIC_CATEGORIES};
use super::model::Model;
use super::structure::{probe, Structure};
use super::variables::{fmi_name, Causality, Initial, Kind, Variability, Variable};
use crate::units::{self, BASE_NAMES};
use quick_xml::Writer;
use std::collections::BTreeMap;
use std::io;

type Attrs = Vec<(&'static str, String)>;

fn element(w: &mut Writer<Vec<u8>>, name: &str, attrs: &Attrs) -> io::Result<()> {
    w.create_element(name).with_attributes(attrs.iter().map(|(k, v)| (*k, v.as_str()))).write_empty()?;
    Ok(())
}

/// The units the model's Real variables use, in table order of [`units::UNITS`].
fn used_units<M: Model>() -> Vec<&'static units::Unit> {
    units::UNITS
        .iter()
        .filter(|u| M::VARIABLES.iter().any(|v| matches!(v.kind, Kind::Real { unit, .. } if unit == u.name)))
        .collect()
}

fn variable_attrs(v: &Variable) -> Attrs {
    let mut a: Attrs = vec![("name", v.name.into()), ("valueReference", v.vr.to_string())];
    if !v.description.is_empty() {
        a.push(("description", v.description.into()));
    }
    a.push(("causality", fmi_name(v.causality)));
    a.push(("variability", fmi_name(v.variability)));
    // Written only where it differs from the FMI 2.0 default for the causality/variability.
    let default_initial = match (v.causality, v.variability) {
        (Causality::Input, _) => None,
        (Causality::Parameter, _) | (_, Variability::Constant) => Some(Initial::Exact),
        _ => Some(Initial::Calculated),
    };
    if default_initial != Some(v.initial) && v.causality != Causality::Input {
        a.push(("initial", fmi_name(v.initial)));
    }
    a
}

fn type_attrs(v: &Variable) -> (&'static str, Attrs) {
    let start = v.has_start();
    match v.kind {
        Kind::Real { start: s, unit, display_unit, min, max } => {
            let mut a: Attrs = vec![("unit", unit.into())];
            if !display_unit.is_empty() {
                a.push(("displayUnit", display_unit.into()));
            }
            if min.is_finite() {
                a.push(("min", num(min)));
            }
            if max.is_finite() {
                a.push(("max", num(max)));
            }
            if start {
                a.push(("start", num(s)));
            }
            ("Real", a)
        }
        Kind::Integer { start: s, min, max } => {
            let mut a: Attrs = vec![("min", min.to_string()), ("max", max.to_string())];
            if start {
                a.push(("start", s.to_string()));
            }
            ("Integer", a)
        }
        Kind::Boolean { start: s } => ("Boolean", if start { vec![("start", s.to_string())] } else { vec![] }),
        Kind::String { start: s } => ("String", if start { vec![("start", s.into())] } else { vec![] }),
    }
}

/// 1-based ModelVariables indices of value references, space separated.
fn indices<M: Model>(vrs: &[u32]) -> String {
    let mut i: Vec<usize> = vrs.iter().filter_map(|vr| M::VARIABLES.iter().position(|v| v.vr == *vr)).collect();
    // FMI 2.0, 2.2.8: dependencies are ordered by index.
    i.sort_unstable();
    i.dedup();
    i.iter().map(|i| (i + 1).to_string()).collect::<Vec<_>>().join(" ")
}

/// The knowns an initial unknown depends on in Initialization Mode (FMI 2.0, 2.2.8: inputs and
/// variables with initial="exact"): the inputs it depends on in Initialization Mode (as after it
/// unless the table says otherwise) and every parameter, since the start state is computed from
/// them.
pub fn initial_dependencies<M: Model>(v: &Variable) -> Vec<u32> {
    let parameters = M::VARIABLES.iter().filter(|p| p.causality == Causality::Parameter).map(|p| p.vr);
    v.initial_depends_on.unwrap_or(v.depends_on).iter().copied().chain(parameters).collect()
}

/// The knowns of every unknown after initialisation, by value reference: for an output its
/// declared inputs and the states it depends on; for a `der()` variable the states and inputs
/// (both from [`probe`]).
pub fn dependencies<M: Model>(structure: &Structure) -> BTreeMap<u32, Vec<u32>> {
    let is_state = |r: &u32| M::STATES.iter().any(|s| s.state == *r);
    let probed = |vr: u32| structure.after.get(&vr).into_iter().flatten().copied();
    let outputs = M::VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| (v.vr, v.depends_on.iter().copied().chain(probed(v.vr).filter(is_state)).collect()));
    outputs.chain(M::STATES.iter().map(|s| (s.derivative, probed(s.derivative).collect()))).collect()
}

/// FMI 2.0 section 2.2.8: the initial unknowns in index order with their dependencies on the
/// knowns of Initialization Mode: outputs with initial approx/calculated, calculated parameters,
/// and the continuous states with initial approx/calculated and every `der()` variable (on the
/// inputs their probe found, and every parameter, since the start state is computed from them).
fn initial_unknowns<M: Model>(structure: &Structure) -> Vec<(u32, Vec<u32>)> {
    let parameters = || M::VARIABLES.iter().filter(|p| p.causality == Causality::Parameter).map(|p| p.vr);
    let mut rows: Vec<(usize, u32, Vec<u32>)> = M::VARIABLES
        .iter()
        .enumerate()
        .filter_map(|(i, v)| {
            let state = M::STATES.iter().any(|s| s.state == v.vr && v.initial != Initial::Exact);
            let derivative = M::STATES.iter().any(|s| s.derivative == v.vr);
            let deps = if derivative || (state && v.causality != Causality::Output) {
                structure.initial.get(&v.vr).into_iter().flatten().copied().chain(parameters()).collect()
            } else if (v.causality == Causality::Output && v.initial != Initial::Exact)
                || v.causality == Causality::CalculatedParameter
            {
                initial_dependencies::<M>(v)
            } else {
                return None;
            };
            Some((i, v.vr, deps))
        })
        .collect();
    rows.sort_by_key(|r| r.0);
    rows.into_iter().map(|(_, vr, deps)| (vr, deps)).collect()
}

/// The complete modelDescription.xml of model `M`.
pub fn model_description<M: Model>() -> String {
    write::<M>().expect("writing XML to memory cannot fail")
}

fn write<M: Model>() -> io::Result<String> {
    let info = &M::INFO;
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(quick_xml::events::Event::Decl(quick_xml::events::BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let root: Attrs = vec![
        ("fmiVersion", "2.0".into()),
        ("modelName", info.identifier.into()),
        ("guid", guid::<M>()),
        ("description", info.description.into()),
        ("author", "boomsim developers".into()),
        ("version", info.version.into()),
        ("license", "MIT OR Apache-2.0".into()),
        ("generationTool", format!("boomsim {}", env!("CARGO_PKG_VERSION"))),
        ("variableNamingConvention", "structured".into()),
        ("numberOfEventIndicators", M::EVENT_INDICATORS.to_string()),
    ];
    w.create_element("fmiModelDescription")
        .with_attributes(root.iter().map(|(k, v)| (*k, v.as_str())))
        .write_inner_content(|w| {
            let flag = |b: bool| b.to_string();
            // The capabilities both interfaces share, around each one's own (schema order).
            let interface = |own: Attrs| -> Attrs {
                let head: Attrs =
                    vec![("modelIdentifier", info.identifier.into()), ("needsExecutionTool", flag(false))];
                let tail: Attrs = vec![
                    ("canBeInstantiatedOnlyOncePerProcess", flag(false)),
                    ("canNotUseMemoryManagementFunctions", flag(true)),
                    ("canGetAndSetFMUstate", flag(true)),
                    ("canSerializeFMUstate", flag(true)),
                    ("providesDirectionalDerivative", flag(M::DIRECTIONAL_DERIVATIVES)),
                ];
                [head, own, tail].concat()
            };
            element(w, "ModelExchange", &interface(vec![("completedIntegratorStepNotNeeded", flag(true))]))?;
            let cs = interface(vec![
                ("canHandleVariableCommunicationStepSize", flag(true)),
                ("canInterpolateInputs", flag(info.can_interpolate_inputs())),
                ("maxOutputDerivativeOrder", "0".into()),
                ("canRunAsynchronuously", flag(false)),
            ]);
            element(w, "CoSimulation", &cs)?;
            w.create_element("UnitDefinitions").write_inner_content(|w| {
                for u in used_units::<M>() {
                    w.create_element("Unit").with_attribute(("name", u.name)).write_inner_content(|w| {
                        let base: Attrs = BASE_NAMES
                            .iter()
                            .zip(u.base)
                            .filter(|(_, e)| *e != 0)
                            .map(|(n, e)| (*n, e.to_string()))
                            .collect();
                        element(w, "BaseUnit", &base)?;
                        for d in u.display {
                            let mut a: Attrs = vec![("name", d.name.into()), ("factor", num(d.factor))];
                            if d.offset != 0.0 {
                                a.push(("offset", num(d.offset)));
                            }
                            element(w, "DisplayUnit", &a)?;
                        }
                        Ok(())
                    })?;
                }
                Ok(())
            })?;
            w.create_element("LogCategories").write_inner_content(|w| {
                for (name, description) in GENERIC_CATEGORIES.iter().chain(info.log_categories) {
                    element(w, "Category", &vec![("name", (*name).into()), ("description", (*description).into())])?;
                }
                Ok(())
            })?;
            let exp: Attrs = vec![
                ("startTime", num(info.start_time)),
                ("stopTime", num(info.stop_time)),
                ("tolerance", num(info.default_tolerance)),
                ("stepSize", num(info.step_size)),
            ];
            element(w, "DefaultExperiment", &exp)?;
            w.create_element("ModelVariables").write_inner_content(|w| {
                for v in M::VARIABLES {
                    let attrs = variable_attrs(v);
                    w.create_element("ScalarVariable")
                        .with_attributes(attrs.iter().map(|(k, v)| (*k, v.as_str())))
                        .write_inner_content(|w| {
                            let (ty, mut a) = type_attrs(v);
                            if let Some(s) = M::STATES.iter().find(|s| s.derivative == v.vr) {
                                a.push(("derivative", indices::<M>(&[s.state])));
                            }
                            element(w, ty, &a)
                        })?;
                }
                Ok(())
            })?;
            let structure = probe::<M>();
            let deps = dependencies::<M>(&structure);
            w.create_element("ModelStructure").write_inner_content(|w| {
                let unknown = |w: &mut Writer<Vec<u8>>, vr: u32, deps: &[u32]| {
                    element(w, "Unknown", &vec![("index", indices::<M>(&[vr])), ("dependencies", indices::<M>(deps))])
                };
                let outputs: Vec<&Variable> =
                    M::VARIABLES.iter().filter(|v| v.causality == Causality::Output).collect();
                if !outputs.is_empty() {
                    w.create_element("Outputs").write_inner_content(|w| {
                        for v in &outputs {
                            unknown(w, v.vr, &deps[&v.vr])?;
                        }
                        Ok(())
                    })?;
                }
                if !M::STATES.is_empty() {
                    // The order of the state vector (fmi2GetContinuousStates).
                    w.create_element("Derivatives").write_inner_content(|w| {
                        for s in M::STATES {
                            unknown(w, s.derivative, &deps[&s.derivative])?;
                        }
                        Ok(())
                    })?;
                }
                let initial = initial_unknowns::<M>(&structure);
                if !initial.is_empty() {
                    w.create_element("InitialUnknowns").write_inner_content(|w| {
                        for (vr, deps) in &initial {
                            unknown(w, *vr, deps)?;
                        }
                        Ok(())
                    })?;
                }
                Ok(())
            })?;
            Ok(())
        })?;
    let mut s = String::from_utf8(w.into_inner()).map_err(io::Error::other)?;
    s.push('\n');
    Ok(s)
}
