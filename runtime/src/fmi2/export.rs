//! `export_fmi2!`: emits the 44 FMI 2.0 symbols (Model Exchange and Co-Simulation) for one model;
//! [`crate::export_fmu`] invokes it beside [`crate::export_fmi3`].

/// Exports the FMI 2.0 C ABI (25 common + 9 Co-Simulation + 10 Model Exchange functions) for a
/// [`Model`](crate::fmu::Model).
#[macro_export]
macro_rules! export_fmi2 {
    ($model:ty) => {
        mod fmi2_exports {
            use super::*;
            use std::os::raw::{c_char, c_int};
            use $crate::fmi2::api;
            use $crate::fmi2::types::*;
            type M = $model;

            #[no_mangle]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                api::get_types_platform()
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                api::get_version()
            }
            $crate::__forward! {
                fmi2SetDebugLogging(c: fmi2Component, on: fmi2Boolean, n: usize,
                    cats: *const fmi2String) -> fmi2Status => set_debug_logging;
                fmi2Instantiate(name: fmi2String, fmu_type: c_int, guid: fmi2String, resources: fmi2String,
                    functions: *const fmi2CallbackFunctions, visible: fmi2Boolean,
                    logging_on: fmi2Boolean) -> fmi2Component => instantiate;
                fmi2SetupExperiment(c: fmi2Component, tol_defined: fmi2Boolean, tol: f64, start: f64,
                    stop_defined: fmi2Boolean, stop: f64) -> fmi2Status => setup_experiment;
                fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status => enter_initialization_mode;
                fmi2GetReal(c: fmi2Component, vr: *const u32, n: usize, v: *mut f64) -> fmi2Status => get_real;
                fmi2GetInteger(c: fmi2Component, vr: *const u32, n: usize, v: *mut c_int) -> fmi2Status => get_integer;
                fmi2GetBoolean(c: fmi2Component, vr: *const u32, n: usize, v: *mut c_int) -> fmi2Status => get_boolean;
                fmi2GetString(c: fmi2Component, vr: *const u32, n: usize,
                    v: *mut fmi2String) -> fmi2Status => get_string;
                fmi2SetReal(c: fmi2Component, vr: *const u32, n: usize, v: *const f64) -> fmi2Status => set_real;
                fmi2SetInteger(c: fmi2Component, vr: *const u32, n: usize,
                    v: *const c_int) -> fmi2Status => set_integer;
                fmi2SetBoolean(c: fmi2Component, vr: *const u32, n: usize,
                    v: *const c_int) -> fmi2Status => set_boolean;
                fmi2SetString(c: fmi2Component, vr: *const u32, n: usize,
                    v: *const fmi2String) -> fmi2Status => set_string;
                fmi2GetDirectionalDerivative(c: fmi2Component, unknown: *const u32, n_unknown: usize, known: *const u32,
                    n_known: usize, dv_known: *const f64,
                    dv_unknown: *mut f64) -> fmi2Status => get_directional_derivative;
                fmi2SetRealInputDerivatives(c: fmi2Component, vr: *const u32, n: usize, order: *const c_int,
                    v: *const f64) -> fmi2Status => set_real_input_derivatives;
                fmi2DoStep(c: fmi2Component, t: f64, h: f64, no_prior: fmi2Boolean) -> fmi2Status => do_step;
                fmi2CancelStep(c: fmi2Component) -> fmi2Status => cancel_step;
                fmi2GetRealStatus(c: fmi2Component, kind: c_int, v: *mut f64) -> fmi2Status => get_real_status;
                fmi2GetBooleanStatus(c: fmi2Component, kind: c_int,
                    v: *mut fmi2Boolean) -> fmi2Status => get_boolean_status;
                fmi2NewDiscreteStates(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status => new_discrete_states;
                fmi2CompletedIntegratorStep(c: fmi2Component, no_prior: fmi2Boolean, enter_event_mode: *mut fmi2Boolean,
                    terminate: *mut fmi2Boolean) -> fmi2Status => completed_integrator_step;
            }
            $crate::__common_functions! {
                fmi2Component, fmi2FMUstate, fmi2Byte;
                fmi2FreeInstance, fmi2ExitInitializationMode, fmi2Terminate, fmi2Reset;
                fmi2EnterEventMode, fmi2EnterContinuousTimeMode, fmi2SetTime, fmi2SetContinuousStates,
                fmi2GetContinuousStates, fmi2GetDerivatives => get_derivatives, fmi2GetEventIndicators,
                fmi2GetNominalsOfContinuousStates;
                fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate, fmi2SerializedFMUstateSize, fmi2SerializeFMUstate,
                fmi2DeSerializeFMUstate;
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: fmi2Component,
                _vr: *const u32,
                _n: usize,
                _order: *const c_int,
                _v: *mut f64,
            ) -> fmi2Status {
                api::get_real_output_derivatives::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(c: fmi2Component, _kind: c_int, _v: *mut fmi2Status) -> fmi2Status {
                api::get_status::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(
                c: fmi2Component,
                _kind: c_int,
                _v: *mut c_int,
            ) -> fmi2Status {
                api::get_integer_status::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: fmi2Component,
                _kind: c_int,
                _v: *mut fmi2String,
            ) -> fmi2Status {
                api::get_string_status::<M>(c)
            }
        }
    };
}
