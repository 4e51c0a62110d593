//! The FMI 3.0 C ABI as the standard's headers declare it (the bindings of the `fmi` crate), and
//! the shared libraries under test through it (the same files as FMI 2.0's, other symbols).

use crate::model_description::Description;
pub use fmi::fmi3::binding::{
    fmi3Instance as Instance, fmi3Status as Status, Fmi3Binding as Fmi3,
};
use std::path::{Path, PathBuf};
use std::ptr::{null, null_mut};

/// One FMU under test through FMI 3.0: its functions and its model description.
pub struct Library {
    pub path: PathBuf,
    pub fmi: Fmi3,
    pub model: Description,
}

impl Library {
    /// Opens `lib<Id>.so` (or `<Id>.so`), checks that it exports the 75 functions of
    /// fmi3FunctionTypes.h, reads `modelDescription/fmi3/<Id>.xml` and instantiates once for
    /// Co-Simulation with its instantiation token (a stale build refuses it).
    pub fn load(path: &Path) -> Result<Self, String> {
        let identifier = crate::identifier(path)?;
        let xml = crate::repository().join(format!("modelDescription/fmi3/{identifier}.xml"));
        let model = Description::read(&xml)?;
        if !model.fmi3 {
            return Err(format!("{}: not an FMI 3.0 model description", xml.display()));
        }
        // SAFETY: an FMU library has no initialisers that could break this process; it stays loaded.
        let fmi = unsafe { Fmi3::new(path) }.map_err(|e| format!("dlopen {e}"))?;
        #[rustfmt::skip]
        let missing = first_missing!(fmi:
            fmi3GetVersion fmi3SetDebugLogging fmi3InstantiateModelExchange fmi3InstantiateCoSimulation
            fmi3InstantiateScheduledExecution fmi3FreeInstance fmi3EnterInitializationMode
            fmi3ExitInitializationMode fmi3EnterEventMode fmi3Terminate fmi3Reset fmi3GetFloat32 fmi3GetFloat64
            fmi3GetInt8 fmi3GetUInt8 fmi3GetInt16 fmi3GetUInt16 fmi3GetInt32 fmi3GetUInt32 fmi3GetInt64
            fmi3GetUInt64 fmi3GetBoolean fmi3GetString fmi3GetBinary fmi3GetClock fmi3SetFloat32 fmi3SetFloat64
            fmi3SetInt8 fmi3SetUInt8 fmi3SetInt16 fmi3SetUInt16 fmi3SetInt32 fmi3SetUInt32 fmi3SetInt64
            fmi3SetUInt64 fmi3SetBoolean fmi3SetString fmi3SetBinary fmi3SetClock
            fmi3GetNumberOfVariableDependencies fmi3GetVariableDependencies fmi3GetFMUState fmi3SetFMUState
            fmi3FreeFMUState fmi3SerializedFMUStateSize fmi3SerializeFMUState fmi3DeserializeFMUState
            fmi3GetDirectionalDerivative fmi3GetAdjointDerivative fmi3EnterConfigurationMode
            fmi3ExitConfigurationMode fmi3GetIntervalDecimal fmi3GetIntervalFraction fmi3GetShiftDecimal
            fmi3GetShiftFraction fmi3SetIntervalDecimal fmi3SetIntervalFraction fmi3SetShiftDecimal
            fmi3SetShiftFraction fmi3EvaluateDiscreteStates fmi3UpdateDiscreteStates fmi3EnterContinuousTimeMode
            fmi3CompletedIntegratorStep fmi3SetTime fmi3SetContinuousStates fmi3GetContinuousStateDerivatives
            fmi3GetEventIndicators fmi3GetContinuousStates fmi3GetNominalsOfContinuousStates
            fmi3GetNumberOfEventIndicators fmi3GetNumberOfContinuousStates fmi3EnterStepMode
            fmi3GetOutputDerivatives fmi3DoStep fmi3ActivateModelPartition);
        if let Some(function) = missing {
            return Err(format!("{}: {function} is not exported", path.display()));
        }
        let token = std::ffi::CString::new(model.guid.as_str()).map_err(|e| e.to_string())?;
        // SAFETY: valid strings, no callbacks; the instance is freed once.
        unsafe {
            let c = fmi.fmi3InstantiateCoSimulation(
                c"fuzz".as_ptr(),
                token.as_ptr(),
                null(),
                false,
                false,
                false,
                false,
                null(),
                0,
                null_mut(),
                None,
                None,
            );
            if c.is_null() {
                return Err(format!(
                    "{} refuses the instantiationToken {} of modelDescription/fmi3/{identifier}.xml: a stale build? (cargo build --release)",
                    path.display(),
                    model.guid
                ));
            }
            fmi.fmi3FreeInstance(c);
        }
        Ok(Library { path: path.to_owned(), fmi, model })
    }
}
