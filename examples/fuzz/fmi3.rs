//! The FMI 3.0 C ABI as the standard's headers declare it (the bindings of the `fmi` crate), and
//! the shared libraries under test through it (the same files as FMI 2.0's, other symbols).

use crate::library::Binding;
use crate::ops::Text;
use crate::ops3::Instantiation3;
use crate::report::Report;
use crate::session3::{instantiate, Session3};
pub use fmi::fmi3::binding::{fmi3Instance as Instance, fmi3Status as Status, Fmi3Binding as Fmi3};
use std::ffi::CStr;
use std::path::Path;

/// One FMU under test through FMI 3.0 (the same files as FMI 2.0's, other symbols).
pub type Library = crate::library::Library<Fmi3>;

impl Binding for Fmi3 {
    const FMI: u8 = 3;
    const XML_FOLDER: &'static str = "fmi3/";
    const TOKEN: &'static str = "instantiationToken";
    type Session<'a> = Session3<'a>;

    unsafe fn open(path: &Path) -> Result<Self, String> {
        Fmi3::new(path).map_err(|e| format!("dlopen {e}"))
    }

    /// Of the 75 functions of fmi3FunctionTypes.h.
    #[rustfmt::skip]
    fn first_missing(&self) -> Option<&'static str> {
    first_missing!(self:
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
        fmi3GetOutputDerivatives fmi3DoStep fmi3ActivateModelPartition)
    }

    /// Co-Simulation, without a logger.
    unsafe fn instantiates(&self, token: &CStr, event_mode_used: bool) -> bool {
        let quiet = Instantiation3::quiet(Text::Bytes(token.to_owned()));
        let c = instantiate(self, &Instantiation3 { event_mode_used, ..quiet });
        if !c.is_null() {
            self.fmi3FreeInstance(c);
        }
        !c.is_null()
    }

    fn session<'a>(library: &'a Library, report: &'a mut Report) -> Session3<'a> {
        Session3::new(library, report)
    }
}
