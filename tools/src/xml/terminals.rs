//! terminalsAndIcons/terminalsAndIcons.xml of the FMI 3.0 .fmu (FMI 3.0, section 2.4.9, schema
//! fmi3TerminalsAndIcons.xsd): the model's terminals ([`boomsim::models::terminals`]), each member
//! named by its variable's name from the variable table. `fmiVersion` is the modelDescription's
//! ("3.0"); no graphical representation.

use super::{document, element, Attrs};
use boomsim::fmu::model::Model;
use std::io;

/// The file of model `M`, or None when it has no terminal.
pub fn terminals_and_icons<M: Model>() -> Option<String> {
    let terminals = M::INFO.terminals;
    if terminals.is_empty() {
        return None;
    }
    let root: Attrs = vec![("fmiVersion", "3.0".into())];
    let xml = document("fmiTerminalsAndIcons", &root, |w| {
        w.create_element("Terminals").write_inner_content(|w| {
            for t in terminals {
                let attrs: Attrs = vec![
                    ("name", t.name.into()),
                    ("matchingRule", t.matching_rule.into()),
                    ("terminalKind", t.kind.into()),
                    ("description", t.description.into()),
                ];
                w.create_element("Terminal")
                    .with_attributes(attrs.iter().map(|(k, v)| (*k, v.as_str())))
                    .write_inner_content(|w| {
                        for &(member, vr) in t.members {
                            let variable = M::VARIABLES
                                .iter()
                                .find(|v| v.vr == vr)
                                .ok_or_else(|| io::Error::other(format!("terminal {}: no variable {vr}", t.name)))?;
                            let member: Attrs = vec![
                                ("variableName", variable.name.into()),
                                ("memberName", member.into()),
                                ("variableKind", "signal".into()),
                            ];
                            element(w, "TerminalMemberVariable", &member)?;
                        }
                        Ok(())
                    })?;
            }
            Ok(())
        })?;
        Ok(())
    });
    Some(xml.expect("writing to memory cannot fail; every member is in the table (tested)"))
}
