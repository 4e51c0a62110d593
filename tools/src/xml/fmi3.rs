//! The FMI 3.0 modelDescription.xml, generated with quick-xml from the same variable table as
//! FMI 2.0 (shared parts in [`crate::xml`]): `<Float64>`/`<Int32>`/`<Enumeration>`/`<Boolean>`/`<String>`
//! variables with the same value references, ModelStructure by value reference.
//!
//! Units are declared as `<Float64Type>`s, one per unit and display unit, which the variables
//! name in `declaredType` (the Reference FMUs' style; FMI 3.0 allows `unit` on the variable too,
//! but importers such as the `fmi` crate 0.8 read units only from type definitions).
//!
//! The 32 section angles and velocities of the boom stay 32 scalars each rather than FMI 3.0
//! arrays: the value references, names and get/set calls are then the same in both versions
//! (one table, one FMU state format, and a master can switch version without remapping), and
//! the unused sections beyond `boom.n2 + boom.n3` need no structural parameter for an array size.

use crate::xml::{
    default_experiment, document, element, enumeration_attrs, enumeration_items, flag, log_categories,
    model_structure, range_attrs, root_attrs, unit_attrs, unit_definitions, variable_attrs, Attrs, Unknowns, Xml,
};
use boomsim::fmu::guid::token;
use boomsim::fmu::instance::INDEPENDENT_VR;
use boomsim::fmu::log::num;
use boomsim::fmu::model::{clock_row, has_event_mode, Model};
use boomsim::fmu::variables::{enumerations, Kind, Variable};
use std::io;

/// The complete FMI 3.0 modelDescription.xml of model `M`.
pub fn model_description<M: Model>() -> String {
    write::<M>().expect("writing XML to memory cannot fail")
}

/// Value references, sorted, unique, space separated.
fn references(vrs: &[u32]) -> String {
    let mut v = vrs.to_vec();
    v.sort_unstable();
    v.dedup();
    v.iter().map(u32::to_string).collect::<Vec<_>>().join(" ")
}

/// The name of the `<Float64Type>` of a unit and display unit.
fn type_name(unit: &str, display_unit: &str) -> String {
    if display_unit.is_empty() {
        unit.to_owned()
    } else {
        format!("{unit} [{display_unit}]")
    }
}

/// `<TypeDefinitions>`: a `<Float64Type>` per unit and display unit of the table (first use
/// order), and the independent variable's seconds; an `<EnumerationType>` per Enumeration type.
fn type_definitions<M: Model>(w: &mut Xml) -> io::Result<()> {
    let mut pairs: Vec<(&str, &str)> = vec![("s", "")];
    for v in M::VARIABLES {
        if let Kind::Real { unit, display_unit, .. } = v.kind {
            if !pairs.contains(&(unit, display_unit)) {
                pairs.push((unit, display_unit));
            }
        }
    }
    w.create_element("TypeDefinitions").write_inner_content(|w| {
        for (unit, display_unit) in pairs {
            let a: Attrs = [vec![("name", type_name(unit, display_unit))], unit_attrs(unit, display_unit)].concat();
            element(w, "Float64Type", &a)?;
        }
        for ty in enumerations(M::VARIABLES) {
            let a: Attrs = vec![("name", ty.name.into()), ("description", ty.description.into())];
            w.create_element("EnumerationType")
                .with_attributes(a.iter().map(|(k, v)| (*k, v.as_str())))
                .write_inner_content(|w| enumeration_items(w, ty))?;
        }
        Ok(())
    })?;
    Ok(())
}

/// The element name and attributes of one variable (FMI 3.0, 2.4.7).
fn variable<M: Model>(v: &Variable) -> (&'static str, Attrs, Option<String>) {
    let mut a = variable_attrs(v);
    let start = v.has_start();
    let (name, string_start) = match v.kind {
        Kind::Real { start: s, unit, display_unit, min, max } => {
            a.push(("declaredType", type_name(unit, display_unit)));
            a.extend(range_attrs((min, max), start.then_some(s)));
            if let Some(state) = M::STATES.iter().find(|x| x.derivative == v.vr) {
                a.push(("derivative", state.state.to_string()));
            }
            // An input the master may set in intermediate update (4.2.3).
            if M::INTERMEDIATE_INPUTS.contains(&v.vr) {
                a.push(("intermediateUpdate", "true".into()));
            }
            ("Float64", None)
        }
        Kind::Integer { start: s, min, max } => {
            a.push(("min", min.to_string()));
            a.push(("max", max.to_string()));
            if start {
                a.push(("start", s.to_string()));
            }
            ("Int32", None)
        }
        Kind::Enumeration { start: s, ty } => {
            a.extend(enumeration_attrs(ty, start.then_some(s)));
            ("Enumeration", None)
        }
        Kind::Boolean { start: s } => {
            if start {
                a.push(("start", s.to_string()));
            }
            ("Boolean", None)
        }
        // FMI 3.0 writes a String's start value as a <Start> child.
        Kind::String { start: s } => ("String", start.then(|| s.to_owned())),
        // A constant periodic input Clock (2.4.7.5): no start value.
        Kind::Clock { interval, shift } => {
            a.push(("intervalVariability", "constant".into()));
            a.push(("intervalDecimal", num(interval)));
            a.push(("shiftDecimal", num(shift)));
            ("Clock", None)
        }
    };
    // A clocked variable names its Clock (`clocks`), a clocked state its previous value.
    if let (true, Some(row)) = (v.clocked, clock_row::<M>()) {
        a.push(("clocks", M::VARIABLES[row].vr.to_string()));
    }
    if let Some(previous) = v.previous {
        a.push(("previous", previous.to_string()));
    }
    (name, a, string_start)
}

fn write<M: Model>() -> io::Result<String> {
    let info = &M::INFO;
    let root = root_attrs::<M>("3.0", ("instantiationToken", token::<M>()), vec![]);
    document("fmiModelDescription", &root, |w| {
        // The capabilities both interfaces share, then each one's own.
        let interface = |own: Attrs| -> Attrs {
            let head: Attrs = vec![
                ("modelIdentifier", info.identifier.into()),
                ("needsExecutionTool", flag(false)),
                ("canBeInstantiatedOnlyOncePerProcess", flag(false)),
                ("canGetAndSetFMUState", flag(true)),
                ("canSerializeFMUState", flag(true)),
                ("providesDirectionalDerivatives", flag(M::DIRECTIONAL_DERIVATIVES)),
                ("providesAdjointDerivatives", flag(M::DIRECTIONAL_DERIVATIVES)),
                ("providesPerElementDependencies", flag(false)),
            ];
            [head, own].concat()
        };
        let me = interface(vec![
            ("needsCompletedIntegratorStep", flag(false)),
            ("providesEvaluateDiscreteStates", flag(false)),
        ]);
        element(w, "ModelExchange", &me)?;
        // A model with a Clock has Event Mode in Co-Simulation (FMI 3.0, 4.4: required then); one
        // with event indicators too, and may end a step early at their roots (4.2.3).
        let cs = interface(vec![
            ("canHandleVariableCommunicationStepSize", flag(true)),
            ("maxOutputDerivativeOrder", "0".into()),
            ("providesIntermediateUpdate", flag(!M::INTERMEDIATE_INPUTS.is_empty())),
            ("mightReturnEarlyFromDoStep", flag(!M::EVENT_INDICATORS.is_empty() || !M::INTERMEDIATE_INPUTS.is_empty())),
            ("canReturnEarlyAfterIntermediateUpdate", flag(!M::INTERMEDIATE_INPUTS.is_empty())),
            ("hasEventMode", flag(has_event_mode::<M>())),
            ("providesEvaluateDiscreteStates", flag(false)),
        ]);
        element(w, "CoSimulation", &cs)?;
        unit_definitions::<M>(w, &["s"])?;
        type_definitions::<M>(w)?;
        log_categories::<M>(w, |d| d.replace("fmi2", "fmi3"))?;
        default_experiment::<M>(w)?;
        w.create_element("ModelVariables").write_inner_content(|w| {
            let time: Attrs = vec![
                ("name", "time".into()),
                ("valueReference", INDEPENDENT_VR.to_string()),
                ("description", "Simulation time".into()),
                ("causality", "independent".into()),
                ("variability", "continuous".into()),
                ("declaredType", "s".into()),
            ];
            element(w, "Float64", &time)?;
            for v in M::VARIABLES {
                match variable::<M>(v) {
                    (name, a, None) => element(w, name, &a)?,
                    (name, a, Some(start)) => {
                        w.create_element(name)
                            .with_attributes(a.iter().map(|(k, v)| (*k, v.as_str())))
                            .write_inner_content(|w| element(w, "Start", &vec![("value", start.clone())]))?;
                    }
                }
            }
            Ok(())
        })?;
        model_structure::<M>(w, Unknowns::Fmi3, references)
    })
}
