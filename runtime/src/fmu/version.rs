//! What the shared layer's messages call differently in FMI 2.0 and FMI 3.0: function and type
//! names. Each instance knows its version, so a message names the function the importer calls.

use super::variables::BaseType;
use std::borrow::Cow;

/// The FMI version an instance was created through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Version {
    Fmi2,
    Fmi3,
}

impl Version {
    /// The function of this version that does what the FMI 2.0 function `fmi2` does.
    pub fn function(self, fmi2: &'static str) -> Cow<'static, str> {
        if self == Version::Fmi2 {
            return Cow::Borrowed(fmi2);
        }
        let renamed = match fmi2 {
            "fmi2SetupExperiment" => "fmi3EnterInitializationMode",
            "fmi2DeSerializeFMUstate" => "fmi3DeserializeFMUState",
            "fmi2GetDerivatives" => "fmi3GetContinuousStateDerivatives",
            "fmi2NewDiscreteStates" => "fmi3UpdateDiscreteStates",
            _ => return Cow::Owned(fmi2.replacen("fmi2", "fmi3", 1).replace("FMUstate", "FMUState")),
        };
        Cow::Borrowed(renamed)
    }

    /// The name in this version of the FMI 2.0 argument `fmi2` of fmi2GetDirectionalDerivative
    /// (FMI 3.0: unknowns, knowns, seed, sensitivity).
    pub fn argument(self, fmi2: &'static str) -> &'static str {
        match (self, fmi2) {
            (Version::Fmi3, "vUnknown_ref") => "unknowns",
            (Version::Fmi3, "vKnown_ref") => "knowns",
            (Version::Fmi3, "dvKnown") => "seed",
            (Version::Fmi3, "dvUnknown") => "sensitivity",
            _ => fmi2,
        }
    }

    /// The type of the get and set functions that access a variable of type `t`: FMI 2.0 reads
    /// and writes an Enumeration with fmi2GetInteger and fmi2SetInteger (2.2.7, "fmi2Integer ...
    /// Enumeration"); FMI 3.0 has fmi3GetInt64 and fmi3SetInt64 for it (2.4.7.4).
    pub fn accessed_as(self, t: BaseType) -> BaseType {
        match (self, t) {
            (Version::Fmi2, BaseType::Enumeration) => BaseType::Integer,
            _ => t,
        }
    }

    /// The name of a base type in this version (FMI 3.0: Float64, Int32).
    pub fn type_name(self, t: BaseType) -> &'static str {
        match (self, t) {
            (Version::Fmi2, BaseType::Real) => "Real",
            (Version::Fmi2, BaseType::Integer) => "Integer",
            (Version::Fmi3, BaseType::Real) => "Float64",
            (Version::Fmi3, BaseType::Integer) => "Int32",
            (_, BaseType::Enumeration) => "Enumeration",
            (_, BaseType::Boolean) => "Boolean",
            (_, BaseType::String) => "String",
            (_, BaseType::Clock) => "Clock",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FMI 3.0 names from fmi3FunctionTypes.h.
    #[test]
    fn fmi3_names() {
        let v = Version::Fmi3;
        assert_eq!(v.function("fmi2SetupExperiment"), "fmi3EnterInitializationMode");
        assert_eq!(v.function("fmi2SetFMUstate"), "fmi3SetFMUState");
        assert_eq!(v.function("fmi2Reset"), "fmi3Reset");
        assert_eq!(Version::Fmi2.function("fmi2SetFMUstate"), "fmi2SetFMUstate");
        assert_eq!(v.type_name(BaseType::Real), "Float64");
        assert_eq!(v.argument("dvKnown"), "seed");
        assert_eq!(Version::Fmi2.argument("dvKnown"), "dvKnown");
    }
}
