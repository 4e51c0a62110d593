//! The model GUID (FMI 2.0) and instantiation token (FMI 3.0): RFC 4122 name-based (v5) UUIDs of
//! the model's identity and variable table, so they change exactly when the interface changes,
//! and are the same in the binary and the XML. The two differ, so that an FMI 2.0 modelDescription
//! (or serialised FMU state) is never taken for the FMI 3.0 one of the same binary.

use super::model::Model;
use uuid::Uuid;

/// boomsim's UUID namespace (a v5 UUID of "boomsim" in the OID namespace).
fn namespace() -> Uuid {
    Uuid::new_v5(&Uuid::NAMESPACE_OID, b"boomsim")
}

/// The GUID of model `M`, in braces as FMI tools write it.
pub fn guid<M: Model>() -> String {
    uuid_of::<M>("")
}

/// The FMI 3.0 instantiationToken of model `M`.
pub fn token<M: Model>() -> String {
    uuid_of::<M>("|fmi3")
}

fn uuid_of<M: Model>(suffix: &str) -> String {
    let i = &M::INFO;
    let mut name = format!("{}|{}|{:?}|{}", i.identifier, i.version, i.interpolated_inputs, M::VARIABLES.len());
    for v in M::VARIABLES {
        name.push_str(&format!("|{v:?}"));
    }
    name.push_str(suffix);
    format!("{{{}}}", Uuid::new_v5(&namespace(), name.as_bytes()))
}
