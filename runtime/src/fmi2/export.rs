//! `export_fmu!`: emits the 44 FMI 2.0 symbols (Model Exchange and Co-Simulation) for one model,
//! and the FMI 3.0 ones ([`crate::export_fmi3`]). A cdylib crate under `fmu/<ModelIdentifier>/`
//! consists of this one invocation.

/// Exports the FMI 2.0 C ABI (25 common + 9 Co-Simulation + 10 Model Exchange functions) and the
/// FMI 3.0 C ABI for a [`Model`](crate::fmu::Model).
#[macro_export]
macro_rules! export_fmu {
    ($model:ty) => {
        $crate::export_fmi3!($model);
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
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: fmi2Component,
                on: fmi2Boolean,
                n: usize,
                cats: *const fmi2String,
            ) -> fmi2Status {
                api::set_debug_logging::<M>(c, on, n, cats)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Instantiate(
                name: fmi2String,
                fmu_type: c_int,
                guid: fmi2String,
                resources: fmi2String,
                functions: *const fmi2CallbackFunctions,
                visible: fmi2Boolean,
                logging_on: fmi2Boolean,
            ) -> fmi2Component {
                api::instantiate::<M>(name, fmu_type, guid, resources, functions, visible, logging_on)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
                api::free_instance::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetupExperiment(
                c: fmi2Component,
                tol_defined: fmi2Boolean,
                tol: f64,
                start: f64,
                stop_defined: fmi2Boolean,
                stop: f64,
            ) -> fmi2Status {
                api::setup_experiment::<M>(c, tol_defined, tol, start, stop_defined, stop)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
                api::enter_initialization_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
                api::exit_initialization_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
                api::terminate::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
                api::reset::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetReal(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut f64,
            ) -> fmi2Status {
                api::get_real::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut c_int,
            ) -> fmi2Status {
                api::get_integer::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut c_int,
            ) -> fmi2Status {
                api::get_boolean::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetString(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *mut fmi2String,
            ) -> fmi2Status {
                api::get_string::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetReal(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const f64,
            ) -> fmi2Status {
                api::set_real::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const c_int,
            ) -> fmi2Status {
                api::set_integer::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const c_int,
            ) -> fmi2Status {
                api::set_boolean::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetString(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                v: *const fmi2String,
            ) -> fmi2Status {
                api::set_string::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status {
                api::get_fmu_state::<M>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, s: fmi2FMUstate) -> fmi2Status {
                api::set_fmu_state::<M>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeFMUstate(c: fmi2Component, s: *mut fmi2FMUstate) -> fmi2Status {
                api::free_fmu_state::<M>(c, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: fmi2Component,
                s: fmi2FMUstate,
                size: *mut usize,
            ) -> fmi2Status {
                api::serialized_fmu_state_size::<M>(c, s, size)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: fmi2Component,
                s: fmi2FMUstate,
                b: *mut fmi2Byte,
                size: usize,
            ) -> fmi2Status {
                api::serialize_fmu_state::<M>(c, s, b, size)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: fmi2Component,
                b: *const fmi2Byte,
                size: usize,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                api::deserialize_fmu_state::<M>(c, b, size, s)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: fmi2Component,
                unknown: *const u32,
                n_unknown: usize,
                known: *const u32,
                n_known: usize,
                dv_known: *const f64,
                dv_unknown: *mut f64,
            ) -> fmi2Status {
                api::get_directional_derivative::<M>(c, unknown, n_unknown, known, n_known, dv_known, dv_unknown)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: fmi2Component,
                vr: *const u32,
                n: usize,
                order: *const c_int,
                v: *const f64,
            ) -> fmi2Status {
                api::set_real_input_derivatives::<M>(c, vr, n, order, v)
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
            pub unsafe extern "C" fn fmi2DoStep(c: fmi2Component, t: f64, h: f64, no_prior: fmi2Boolean) -> fmi2Status {
                api::do_step::<M>(c, t, h, no_prior)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
                api::cancel_step::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(c: fmi2Component, _kind: c_int, _v: *mut fmi2Status) -> fmi2Status {
                api::get_status::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealStatus(c: fmi2Component, kind: c_int, v: *mut f64) -> fmi2Status {
                api::get_real_status::<M>(c, kind, v)
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
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: fmi2Component,
                kind: c_int,
                v: *mut fmi2Boolean,
            ) -> fmi2Status {
                api::get_boolean_status::<M>(c, kind, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: fmi2Component,
                _kind: c_int,
                _v: *mut fmi2String,
            ) -> fmi2Status {
                api::get_string_status::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
                api::enter_event_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2NewDiscreteStates(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status {
                api::new_discrete_states::<M>(c, info)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
                api::enter_continuous_time_mode::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
                c: fmi2Component,
                no_prior: fmi2Boolean,
                enter_event_mode: *mut fmi2Boolean,
                terminate: *mut fmi2Boolean,
            ) -> fmi2Status {
                api::completed_integrator_step::<M>(c, no_prior, enter_event_mode, terminate)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: f64) -> fmi2Status {
                api::set_time::<M>(c, time)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetContinuousStates(c: fmi2Component, x: *const f64, nx: usize) -> fmi2Status {
                api::set_continuous_states::<M>(c, x, nx)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDerivatives(c: fmi2Component, dx: *mut f64, nx: usize) -> fmi2Status {
                api::get_derivatives::<M>(c, dx, nx)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetEventIndicators(c: fmi2Component, z: *mut f64, ni: usize) -> fmi2Status {
                api::get_event_indicators::<M>(c, z, ni)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetContinuousStates(c: fmi2Component, x: *mut f64, nx: usize) -> fmi2Status {
                api::get_continuous_states::<M>(c, x, nx)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
                c: fmi2Component,
                x: *mut f64,
                nx: usize,
            ) -> fmi2Status {
                api::get_nominals_of_continuous_states::<M>(c, x, nx)
            }
        }
    };
}
