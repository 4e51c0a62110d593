//! The FMI 2.0 C ABI as the standard's headers declare it (the bindings of the `fmi` crate),
//! and the shared libraries under test.

use crate::callbacks::Callbacks;
use crate::library::Binding;
use crate::report::Report;
use crate::session::Session;
use fmi::fmi2::binding;
pub use fmi::fmi2::binding::{
    fmi2CallbackFunctions as CallbackFunctions, fmi2CallbackLogger as Logger, fmi2Component as Component,
    fmi2Status as Status, fmi2Status_fmi2Discard as DISCARD, fmi2Status_fmi2Error as ERROR, fmi2Status_fmi2OK as OK,
    fmi2Status_fmi2Warning as WARNING, Fmi2Binding as Fmi2,
};
use std::ffi::CStr;
use std::os::raw::c_int;
use std::path::Path;
use std::ptr::null;

// fmi2Type and fmi2StatusKind values as the `c_int` the fuzzer passes (which may be invalid ones).
pub const CO_SIMULATION: c_int = binding::fmi2Type_fmi2CoSimulation as c_int;
pub const MODEL_EXCHANGE: c_int = binding::fmi2Type_fmi2ModelExchange as c_int;
pub use fmi::fmi2::binding::fmi2EventInfo as EventInfo;
pub const LAST_SUCCESSFUL_TIME: c_int = binding::fmi2StatusKind_fmi2LastSuccessfulTime as c_int;
pub const TERMINATED: c_int = binding::fmi2StatusKind_fmi2Terminated as c_int;

/// One FMU under test through FMI 2.0.
pub type Library = crate::library::Library<Fmi2>;

impl Binding for Fmi2 {
    const FMI: u8 = 2;
    const XML_FOLDER: &'static str = "";
    const TOKEN: &'static str = "GUID";
    type Session<'a> = Session<'a>;

    unsafe fn open(path: &Path) -> Result<Self, String> {
        Fmi2::new(path).map_err(|e| format!("dlopen {e}"))
    }

    /// Of the 25 common, 9 co-simulation and 10 model-exchange functions of FMI 2.0.
    #[rustfmt::skip]
    fn first_missing(&self) -> Option<&'static str> {
        first_missing!(self:
            fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
            fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset
            fmi2GetReal fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean
            fmi2SetString fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize
            fmi2SerializeFMUstate fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative
            fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives fmi2DoStep fmi2CancelStep fmi2GetStatus
            fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus fmi2GetStringStatus
            fmi2EnterEventMode fmi2NewDiscreteStates fmi2EnterContinuousTimeMode fmi2CompletedIntegratorStep
            fmi2SetTime fmi2SetContinuousStates fmi2GetDerivatives fmi2GetEventIndicators fmi2GetContinuousStates
            fmi2GetNominalsOfContinuousStates)
    }

    /// Co-Simulation, with logger and memory callbacks (FMI 2.0 has no Event Mode to ask for).
    unsafe fn instantiates(&self, guid: &CStr, _: bool) -> bool {
        let callbacks = Callbacks { logger: true, memory: true }.functions();
        let c = self.fmi2Instantiate(
            c"fuzz".as_ptr(),
            binding::fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &callbacks,
            0,
            0,
        );
        if !c.is_null() {
            self.fmi2FreeInstance(c);
        }
        !c.is_null()
    }

    fn session<'a>(library: &'a Library, report: &'a mut Report) -> Session<'a> {
        Session::new(library, report)
    }
}
