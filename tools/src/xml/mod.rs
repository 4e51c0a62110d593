//! modelDescription.xml, generated with quick-xml from a model's variable table: [`fmi2`] and
//! [`fmi3`] write each version's schema; this module what they share: the document frame,
//! units, log categories, default experiment, and ModelStructure ([`model_structure`]: which
//! unknowns depend on which knowns; FMI 2.0 writes them as indices in groups, FMI 3.0 as value
//! references).

pub mod fmi2;
pub mod fmi3;
pub mod terminals;

use boomsim::fmu::log::{num, GENERIC_CATEGORIES};
use boomsim::fmu::model::{initial_unknown, Model};
use boomsim::fmu::structure::{probe, Structure};
use boomsim::fmu::variables::{fmi_name, Causality, Initial, Kind, Variability, Variable};
use boomsim::params::Enumeration;
use boomsim::units::{self, BASE_NAMES};
use quick_xml::Writer;
use std::collections::BTreeMap;
use std::io;

/// Attributes of an element, in the order written.
pub type Attrs = Vec<(&'static str, String)>;

/// The writer both versions use.
pub type Xml = Writer<Vec<u8>>;

/// An empty element.
pub fn element(w: &mut Xml, name: &str, attrs: &Attrs) -> io::Result<()> {
    w.create_element(name).with_attributes(attrs.iter().map(|(k, v)| (*k, v.as_str()))).write_empty()?;
    Ok(())
}

/// "true"/"false".
pub fn flag(b: bool) -> String {
    b.to_string()
}

/// The document: declaration, the root element `name` with `root` attributes and `body` inside.
pub fn document(name: &str, root: &Attrs, body: impl FnOnce(&mut Xml) -> io::Result<()>) -> io::Result<String> {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(quick_xml::events::Event::Decl(quick_xml::events::BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    w.create_element(name).with_attributes(root.iter().map(|(k, v)| (*k, v.as_str()))).write_inner_content(body)?;
    let mut s = String::from_utf8(w.into_inner()).map_err(io::Error::other)?;
    s.push('\n');
    Ok(s)
}

/// The root attributes both versions write around the version's own (`fmiVersion`, then the
/// model name, `identity` (guid or instantiationToken), and the rest).
pub fn root_attrs<M: Model>(fmi_version: &str, identity: (&'static str, String), tail: Attrs) -> Attrs {
    let info = &M::INFO;
    let head: Attrs = vec![
        ("fmiVersion", fmi_version.into()),
        ("modelName", info.identifier.into()),
        identity,
        ("description", info.description.into()),
        ("author", "boomsim developers".into()),
        ("version", info.version.into()),
        ("license", "MIT OR Apache-2.0".into()),
        ("generationTool", format!("boomsim {}", env!("CARGO_PKG_VERSION"))),
        ("variableNamingConvention", "structured".into()),
    ];
    [head, tail].concat()
}

/// The units the model's Real variables use, and `extra`, in table order of [`units::UNITS`].
fn used_units<M: Model>(extra: &[&str]) -> Vec<&'static units::Unit> {
    let used = |name: &str| {
        extra.contains(&name) || M::VARIABLES.iter().any(|v| matches!(v.kind, Kind::Real { unit, .. } if unit == name))
    };
    units::UNITS.iter().filter(|u| used(u.name)).collect()
}

/// `<UnitDefinitions>`: every unit used (by the table, or the `extra` ones), with its SI base
/// and its display units.
pub fn unit_definitions<M: Model>(w: &mut Xml, extra: &[&str]) -> io::Result<()> {
    w.create_element("UnitDefinitions").write_inner_content(|w| {
        for u in used_units::<M>(extra) {
            w.create_element("Unit").with_attribute(("name", u.name)).write_inner_content(|w| {
                let base: Attrs =
                    BASE_NAMES.iter().zip(u.base).filter(|(_, e)| *e != 0).map(|(n, e)| (*n, e.to_string())).collect();
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
    Ok(())
}

/// The `<Item>`s of an Enumeration type (FMI 2.0, 2.2.3; FMI 3.0, 2.4.6): value k for the k-th.
pub fn enumeration_items(w: &mut Xml, ty: &Enumeration) -> io::Result<()> {
    for (k, item) in ty.items.iter().enumerate() {
        let a: Attrs =
            vec![("name", item.name.into()), ("value", k.to_string()), ("description", item.description.into())];
        element(w, "Item", &a)?;
    }
    Ok(())
}

/// The attributes of an Enumeration variable: its type, its items' range and its start value.
pub fn enumeration_attrs(ty: &Enumeration, start: Option<i32>) -> Attrs {
    let mut a: Attrs =
        vec![("declaredType", ty.name.into()), ("min", "0".into()), ("max", (ty.items.len() - 1).to_string())];
    if let Some(s) = start {
        a.push(("start", s.to_string()));
    }
    a
}

/// `<LogCategories>`; `describe` adapts a description to the version (status names).
pub fn log_categories<M: Model>(w: &mut Xml, describe: impl Fn(&str) -> String) -> io::Result<()> {
    w.create_element("LogCategories").write_inner_content(|w| {
        for (name, description) in GENERIC_CATEGORIES.iter().chain(M::INFO.log_categories) {
            element(w, "Category", &vec![("name", (*name).into()), ("description", describe(description))])?;
        }
        Ok(())
    })?;
    Ok(())
}

/// `<DefaultExperiment>`.
pub fn default_experiment<M: Model>(w: &mut Xml) -> io::Result<()> {
    let info = &M::INFO;
    let exp: Attrs = vec![
        ("startTime", num(info.start_time)),
        ("stopTime", num(info.stop_time)),
        ("tolerance", num(info.default_tolerance)),
        ("stepSize", num(info.step_size)),
    ];
    element(w, "DefaultExperiment", &exp)
}

/// The attributes every variable has in both versions: name, value reference, description,
/// causality, variability and (where it is not the default) initial.
pub fn variable_attrs(v: &Variable) -> Attrs {
    let mut a: Attrs = vec![("name", v.name.into()), ("valueReference", v.vr.to_string())];
    if !v.description.is_empty() {
        a.push(("description", v.description.into()));
    }
    a.push(("causality", fmi_name(v.causality)));
    a.push(("variability", fmi_name(v.variability)));
    if let Some(initial) = initial_attr(v) {
        a.push(("initial", initial));
    }
    a
}

/// The attributes of a Real (FMI 3.0: Float64) with a start value if it has one.
pub fn real_attrs(unit: &str, display_unit: &str, range: (f64, f64), start: Option<f64>) -> Attrs {
    [unit_attrs(unit, display_unit), range_attrs(range, start)].concat()
}

/// `unit` and, if there is one, `displayUnit`.
pub fn unit_attrs(unit: &str, display_unit: &str) -> Attrs {
    let mut a: Attrs = vec![("unit", unit.into())];
    if !display_unit.is_empty() {
        a.push(("displayUnit", display_unit.into()));
    }
    a
}

/// The finite bounds and the start value, if any.
pub fn range_attrs((min, max): (f64, f64), start: Option<f64>) -> Attrs {
    let mut a = Attrs::new();
    if min.is_finite() {
        a.push(("min", num(min)));
    }
    if max.is_finite() {
        a.push(("max", num(max)));
    }
    if let Some(s) = start {
        a.push(("start", num(s)));
    }
    a
}

/// The `initial` attribute where it differs from the default for the causality/variability
/// (the same table in FMI 2.0, 2.2.7, and FMI 3.0, 2.4.7.5).
fn initial_attr(v: &Variable) -> Option<String> {
    let default_initial = match (v.causality, v.variability) {
        (Causality::Input, _) => None,
        (Causality::Parameter, _) | (_, Variability::Constant) => Some(Initial::Exact),
        _ => Some(Initial::Calculated),
    };
    (default_initial != Some(v.initial) && v.causality != Causality::Input).then(|| fmi_name(v.initial))
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
/// declared inputs and the states it depends on; for a `der()` variable and an event indicator
/// the states and inputs (both from [`boomsim::fmu::structure::probe`]).
pub fn dependencies<M: Model>(structure: &Structure) -> BTreeMap<u32, Vec<u32>> {
    let is_state = |r: &u32| M::STATES.iter().any(|s| s.state == *r);
    let probed = |vr: u32| structure.after.get(&vr).into_iter().flatten().copied();
    let outputs = M::VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| (v.vr, v.depends_on.iter().copied().chain(probed(v.vr).filter(is_state)).collect()));
    let derived = M::STATES.iter().map(|s| s.derivative).chain(M::EVENT_INDICATORS.iter().copied());
    outputs.chain(derived.map(|r| (r, probed(r).collect()))).collect()
}

/// FMI 2.0 section 2.2.8 (FMI 3.0, 2.4.8 alike): the initial unknowns in table order with their
/// dependencies on the knowns of Initialization Mode: outputs with initial approx/calculated,
/// calculated parameters, and the continuous states with initial approx/calculated and every
/// `der()` variable (on the inputs their probe found, and every parameter, since the start state
/// is computed from them).
pub fn initial_unknowns<M: Model>(structure: &Structure) -> Vec<(u32, Vec<u32>)> {
    let parameters = || M::VARIABLES.iter().filter(|p| p.causality == Causality::Parameter).map(|p| p.vr);
    M::VARIABLES
        .iter()
        .filter_map(|v| {
            if !initial_unknown::<M>(v) {
                return None;
            }
            let state = M::STATES.iter().any(|s| s.state == v.vr && v.initial != Initial::Exact);
            let derivative = M::STATES.iter().any(|s| s.derivative == v.vr);
            let deps = if derivative || (state && v.causality != Causality::Output) {
                structure.initial.get(&v.vr).into_iter().flatten().copied().chain(parameters()).collect()
            } else {
                initial_dependencies::<M>(v)
            };
            Some((v.vr, deps))
        })
        .collect()
}

/// How a version writes ModelStructure's unknowns: FMI 2.0 groups `<Unknown index=...>` under
/// `<Outputs>`, `<Derivatives>`, `<InitialUnknowns>` and has no clocked states or event
/// indicators there; FMI 3.0 writes one element per unknown, named by its kind, with
/// `valueReference`.
pub enum Unknowns {
    Fmi2,
    Fmi3,
}

/// ModelStructure of model `M` (FMI 2.0, 2.2.8; FMI 3.0, 2.4.8), the one writer of both
/// versions: outputs, derivatives (in the order of the state vector), clocked states (on every
/// known: no `dependencies`), initial unknowns, event indicators (in the order of
/// fmi3GetEventIndicators), each with its knowns, written by `refs` (indices or value references).
pub fn model_structure<M: Model>(w: &mut Xml, version: Unknowns, refs: impl Fn(&[u32]) -> String) -> io::Result<()> {
    let structure = probe::<M>();
    let deps = dependencies::<M>(&structure);
    let with = |vr: u32| (vr, Some(deps[&vr].clone()));
    let outputs = M::VARIABLES.iter().filter(|v| v.causality == Causality::Output).map(|v| with(v.vr)).collect();
    let derivatives = M::STATES.iter().map(|s| with(s.derivative)).collect();
    let clocked = M::VARIABLES.iter().filter(|v| v.previous.is_some()).map(|v| (v.vr, None)).collect();
    let initial = initial_unknowns::<M>(&structure).into_iter().map(|(vr, d)| (vr, Some(d))).collect();
    let indicators = M::EVENT_INDICATORS.iter().map(|&vr| with(vr)).collect();
    // (FMI 2.0 group, FMI 3.0 element, its unknowns)
    let lists: [(&str, &str, Vec<(u32, Option<Vec<u32>>)>); 5] = [
        ("Outputs", "Output", outputs),
        ("Derivatives", "ContinuousStateDerivative", derivatives),
        ("", "ClockedState", clocked),
        ("InitialUnknowns", "InitialUnknown", initial),
        ("", "EventIndicator", indicators),
    ];
    w.create_element("ModelStructure").write_inner_content(|w| {
        for (group, name, unknowns) in &lists {
            let write = |w: &mut Xml, name: &str, reference: &'static str| {
                unknowns.iter().try_for_each(|(vr, deps)| {
                    let mut attrs = vec![(reference, refs(&[*vr]))];
                    attrs.extend(deps.as_deref().map(|d| ("dependencies", refs(d))));
                    element(w, name, &attrs)
                })
            };
            match version {
                Unknowns::Fmi3 => write(w, name, "valueReference")?,
                Unknowns::Fmi2 if group.is_empty() || unknowns.is_empty() => {}
                Unknowns::Fmi2 => {
                    w.create_element(*group).write_inner_content(|w| write(w, "Unknown", "index"))?;
                }
            }
        }
        Ok(())
    })?;
    Ok(())
}
