//! The FMI 2.0 C ABI as the standard's headers declare it (the bindings of the `fmi` crate),
//! and the shared libraries under test.

use crate::callbacks::Callbacks;
use crate::model_description::Description;
use fmi::fmi2::binding;
pub use fmi::fmi2::binding::{
    fmi2CallbackFunctions as CallbackFunctions, fmi2CallbackLogger as Logger, fmi2Component as Component,
    fmi2Status as Status, fmi2Status_fmi2Discard as DISCARD, fmi2Status_fmi2Error as ERROR, fmi2Status_fmi2OK as OK,
    fmi2Status_fmi2Warning as WARNING, Fmi2Binding as Fmi2,
};
use std::ffi::CString;
use std::os::raw::c_int;
use std::path::{Path, PathBuf};
use std::ptr::null;

// fmi2Type and fmi2StatusKind values as the `c_int` the fuzzer passes (which may be invalid ones).
pub const CO_SIMULATION: c_int = binding::fmi2Type_fmi2CoSimulation as c_int;
pub const MODEL_EXCHANGE: c_int = binding::fmi2Type_fmi2ModelExchange as c_int;
pub use fmi::fmi2::binding::fmi2EventInfo as EventInfo;
pub const LAST_SUCCESSFUL_TIME: c_int = binding::fmi2StatusKind_fmi2LastSuccessfulTime as c_int;
pub const TERMINATED: c_int = binding::fmi2StatusKind_fmi2Terminated as c_int;

/// One FMU under test: its functions and its model description.
pub struct Library {
    pub path: PathBuf,
    pub fmi: Fmi2,
    pub model: Description,
}

impl Library {
    /// Opens `lib<Id>.so` (or `<Id>.so`), checks that it exports the 25 common, 9
    /// co-simulation and 10 model-exchange functions of FMI 2.0, reads `modelDescription/<Id>.xml` and instantiates
    /// once with its GUID: a stale build would refuse every instantiation, and the fuzzer would
    /// test nothing but error paths.
    pub fn load(path: &Path) -> Result<Self, String> {
        let identifier = crate::identifier(path)?;
        let model = Description::read(&crate::repository().join(format!("modelDescription/{identifier}.xml")))?;
        // SAFETY: an FMU library has no initialisers that could break this process; it stays loaded.
        let fmi = unsafe { Fmi2::new(path) }.map_err(|e| format!("dlopen {e}"))?;
        #[rustfmt::skip]
        let missing = first_missing!(fmi:
            fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
            fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset
            fmi2GetReal fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean
            fmi2SetString fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize
            fmi2SerializeFMUstate fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative
            fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives fmi2DoStep fmi2CancelStep fmi2GetStatus
            fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus fmi2GetStringStatus
            fmi2EnterEventMode fmi2NewDiscreteStates fmi2EnterContinuousTimeMode fmi2CompletedIntegratorStep
            fmi2SetTime fmi2SetContinuousStates fmi2GetDerivatives fmi2GetEventIndicators fmi2GetContinuousStates
            fmi2GetNominalsOfContinuousStates);
        if let Some(function) = missing {
            return Err(format!("{}: {function} is not exported", path.display()));
        }
        let guid = CString::new(model.guid.as_str()).map_err(|e| e.to_string())?;
        let callbacks = Callbacks { logger: true, memory: true }.functions();
        // SAFETY: valid strings and callbacks that outlive the instance, freed once.
        unsafe {
            let c = fmi.fmi2Instantiate(
                c"fuzz".as_ptr(),
                binding::fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                null(),
                &callbacks,
                0,
                0,
            );
            if c.is_null() {
                return Err(format!(
                    "{} refuses the GUID {} of modelDescription/{identifier}.xml: a stale build? (cargo build --release)",
                    path.display(),
                    model.guid
                ));
            }
            fmi.fmi2FreeInstance(c);
        }
        Ok(Library { path: path.to_owned(), fmi, model })
    }
}
