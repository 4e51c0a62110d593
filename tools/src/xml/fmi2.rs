//! The FMI 2.0 modelDescription.xml, generated with quick-xml from the model's variable table
//! (the parts FMI 3.0 writes alike are in [`crate::xml`]).

use crate::xml::{
    default_experiment, document, element, enumeration_attrs, enumeration_items, flag, log_categories,
    model_structure, real_attrs, root_attrs, unit_definitions, variable_attrs, Attrs, Unknowns, Xml,
};
use boomsim::fmu::guid::guid;
use boomsim::fmu::model::Model;
use boomsim::fmu::variables::{enumerations, Kind, Variable};
use std::io;

pub use crate::xml::{dependencies, initial_dependencies};

fn type_attrs(v: &Variable) -> (&'static str, Attrs) {
    let start = v.has_start();
    match v.kind {
        Kind::Real { start: s, unit, display_unit, min, max } => {
            ("Real", real_attrs(unit, display_unit, (min, max), start.then_some(s)))
        }
        Kind::Integer { start: s, min, max } => {
            let mut a: Attrs = vec![("min", min.to_string()), ("max", max.to_string())];
            if start {
                a.push(("start", s.to_string()));
            }
            ("Integer", a)
        }
        Kind::Enumeration { start: s, ty } => ("Enumeration", enumeration_attrs(ty, start.then_some(s))),
        Kind::Boolean { start: s } => ("Boolean", if start { vec![("start", s.to_string())] } else { vec![] }),
        Kind::String { start: s } => ("String", if start { vec![("start", s.into())] } else { vec![] }),
        Kind::Clock { .. } => unreachable!("FMI 2.0 has no Clocks: a model with one is packed as FMI 3.0 only"),
    }
}

/// `<TypeDefinitions>`: a `<SimpleType>` per Enumeration type (2.2.3), none without one.
fn type_definitions<M: Model>(w: &mut Xml) -> io::Result<()> {
    let types = enumerations(M::VARIABLES);
    if types.is_empty() {
        return Ok(());
    }
    w.create_element("TypeDefinitions").write_inner_content(|w| {
        for ty in types {
            let a: Attrs = vec![("name", ty.name.into()), ("description", ty.description.into())];
            w.create_element("SimpleType")
                .with_attributes(a.iter().map(|(k, v)| (*k, v.as_str())))
                .write_inner_content(|w| {
                    w.create_element("Enumeration").write_inner_content(|w| enumeration_items(w, ty))?;
                    Ok(())
                })?;
        }
        Ok(())
    })?;
    Ok(())
}

/// 1-based ModelVariables indices of value references, space separated.
fn indices<M: Model>(vrs: &[u32]) -> String {
    let mut i: Vec<usize> = vrs.iter().filter_map(|vr| M::VARIABLES.iter().position(|v| v.vr == *vr)).collect();
    // FMI 2.0, 2.2.8: dependencies are ordered by index.
    i.sort_unstable();
    i.dedup();
    i.iter().map(|i| (i + 1).to_string()).collect::<Vec<_>>().join(" ")
}

/// The complete modelDescription.xml of model `M`.
pub fn model_description<M: Model>() -> String {
    write::<M>().expect("writing XML to memory cannot fail")
}

fn write<M: Model>() -> io::Result<String> {
    let info = &M::INFO;
    let root = root_attrs::<M>(
        "2.0",
        ("guid", guid::<M>()),
        vec![("numberOfEventIndicators", M::EVENT_INDICATORS.len().to_string())],
    );
    document("fmiModelDescription", &root, |w| {
        // The capabilities both interfaces share, around each one's own (schema order).
        let interface = |own: Attrs| -> Attrs {
            let head: Attrs = vec![("modelIdentifier", info.identifier.into()), ("needsExecutionTool", flag(false))];
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
        unit_definitions::<M>(w, &[])?;
        type_definitions::<M>(w)?;
        log_categories::<M>(w, str::to_owned)?;
        default_experiment::<M>(w)?;
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
        model_structure::<M>(w, Unknowns::Fmi2, indices::<M>)
    })
}
