//! The model GUID: an RFC 4122 name-based (v5) UUID of the model's identity and variable table,
//! so it changes exactly when the interface changes, and is the same in the binary and the XML.

use super::model::Model;
use uuid::Uuid;

/// boomsim's UUID namespace (a v5 UUID of "boomsim" in the OID namespace).
fn namespace() -> Uuid {
    Uuid::new_v5(&Uuid::NAMESPACE_OID, b"boomsim")
}

/// The GUID of model `M`, in braces as FMI tools write it.
pub fn guid<M: Model>() -> String {
    let i = &M::INFO;
    let mut name = format!("{}|{}|{:?}|{}", i.identifier, i.version, i.interpolated_inputs, M::VARIABLES.len());
    for v in M::VARIABLES {
        name.push_str(&format!("|{v:?}"));
    }
    format!("{{{}}}", Uuid::new_v5(&namespace(), name.as_bytes()))
}
