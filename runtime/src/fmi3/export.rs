//! `export_fmi3!`: emits the FMI 3.0 symbols for one model: every function of
//! fmi3FunctionTypes.h (common, Model Exchange, Co-Simulation, and Scheduled Execution and
//! clocks, which are refused); [`crate::export_fmu`] invokes it beside [`crate::export_fmi2`].

/// Exports the FMI 3.0 C ABI for a [`Model`](crate::fmu::Model).
#[macro_export]
macro_rules! export_fmi3 {
    ($model:ty) => {
        mod fmi3_exports {
            use super::*;
            use std::os::raw::c_char;
            use $crate::fmi3::api;
            use $crate::fmi3::types::*;
            type M = $model;

            $crate::__fmi3_other_types! {
                fmi3GetFloat32, fmi3SetFloat32, f32, "Float32";
                fmi3GetInt8, fmi3SetInt8, i8, "Int8";
                fmi3GetUInt8, fmi3SetUInt8, u8, "UInt8";
                fmi3GetInt16, fmi3SetInt16, i16, "Int16";
                fmi3GetUInt16, fmi3SetUInt16, u16, "UInt16";
                fmi3GetUInt32, fmi3SetUInt32, u32, "UInt32";
                fmi3GetUInt64, fmi3SetUInt64, u64, "UInt64";
            }

            #[no_mangle]
            pub extern "C" fn fmi3GetVersion() -> *const c_char {
                api::get_version()
            }
            $crate::__fmi3_values! {
                fmi3GetFloat64 => get_float64, fmi3SetFloat64 => set_float64: f64, f64;
                fmi3GetInt32 => get_int32, fmi3SetInt32 => set_int32: i32, i32;
                fmi3GetInt64 => get_int64, fmi3SetInt64 => set_int64: i64, i64;
                fmi3GetBoolean => get_boolean, fmi3SetBoolean => set_boolean: bool, u8;
                fmi3GetString => get_string, fmi3SetString => set_string: fmi3String, fmi3String;
            }
            $crate::__forward! {
                fmi3SetDebugLogging(c: fmi3Instance, on: bool, n: usize,
                    cats: *const fmi3String) -> fmi3Status => set_debug_logging;
                fmi3InstantiateModelExchange(name: fmi3String, token: fmi3String, resources: fmi3String, visible: bool,
                    logging_on: bool, env: fmi3InstanceEnvironment,
                    log: fmi3LogMessageCallback) -> fmi3Instance => instantiate_model_exchange;
                fmi3InstantiateCoSimulation(name: fmi3String, token: fmi3String, resources: fmi3String, visible: bool,
                    logging_on: bool, event_mode_used: bool, early_return_allowed: bool, required: *const u32,
                    n_required: usize, env: fmi3InstanceEnvironment, log: fmi3LogMessageCallback,
                    intermediate: fmi3IntermediateUpdateCallback) -> fmi3Instance => instantiate_co_simulation;
                fmi3EnterInitializationMode(c: fmi3Instance, tol_defined: bool, tol: f64, start: f64,
                    stop_defined: bool, stop: f64) -> fmi3Status => enter_initialization_mode;
                fmi3GetNumberOfEventIndicators(c: fmi3Instance,
                    n: *mut usize) -> fmi3Status => get_number_of_event_indicators;
                fmi3GetNumberOfContinuousStates(c: fmi3Instance,
                    n: *mut usize) -> fmi3Status => get_number_of_continuous_states;
                fmi3EnterStepMode(c: fmi3Instance) -> fmi3Status => enter_step_mode;
            }
            $crate::__common_functions! {
                fmi3Instance, fmi3FMUState, u8;
                fmi3FreeInstance, fmi3ExitInitializationMode, fmi3Terminate, fmi3Reset;
                fmi3EnterEventMode, fmi3EnterContinuousTimeMode, fmi3SetTime, fmi3SetContinuousStates,
                fmi3GetContinuousStates, fmi3GetContinuousStateDerivatives => get_continuous_state_derivatives,
                fmi3GetEventIndicators, fmi3GetNominalsOfContinuousStates;
                fmi3GetFMUState, fmi3SetFMUState, fmi3FreeFMUState, fmi3SerializedFMUStateSize, fmi3SerializeFMUState,
                fmi3DeserializeFMUState;
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
                name: fmi3String,
                _token: fmi3String,
                _resources: fmi3String,
                _visible: bool,
                logging_on: bool,
                env: fmi3InstanceEnvironment,
                log: fmi3LogMessageCallback,
                _clock_update: fmi3ClockUpdateCallback,
                _lock: fmi3PreemptionCallback,
                _unlock: fmi3PreemptionCallback,
            ) -> fmi3Instance {
                api::instantiate_scheduled_execution::<M>(name, logging_on, env, log)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetBinary(
                c: fmi3Instance,
                vr: *const u32,
                n: usize,
                _sizes: *mut usize,
                _v: *mut fmi3Binary,
                _nv: usize,
            ) -> fmi3Status {
                api::other_type::<M>(c, "fmi3GetBinary", false, vr, n, "Binary")
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetClock(
                c: fmi3Instance,
                vr: *const u32,
                n: usize,
                v: *mut fmi3Clock,
            ) -> fmi3Status {
                api::get_clock::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetBinary(
                c: fmi3Instance,
                vr: *const u32,
                n: usize,
                _sizes: *const usize,
                _v: *const fmi3Binary,
                _nv: usize,
            ) -> fmi3Status {
                api::other_type::<M>(c, "fmi3SetBinary", true, vr, n, "Binary")
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetClock(
                c: fmi3Instance,
                vr: *const u32,
                n: usize,
                v: *const u8,
            ) -> fmi3Status {
                api::set_clock::<M>(c, vr, n, v)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
                c: fmi3Instance,
                _vr: u32,
                _n: *mut usize,
            ) -> fmi3Status {
                api::unsupported::<M>(
                    c,
                    "fmi3GetNumberOfVariableDependencies",
                    "providesPerElementDependencies=\"false\"",
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetVariableDependencies(
                c: fmi3Instance,
                _dependent: u32,
                _element_of_dependent: *mut usize,
                _independents: *mut u32,
                _element_of_independents: *mut usize,
                _kinds: *mut fmi3DependencyKind,
                _n: usize,
            ) -> fmi3Status {
                api::unsupported::<M>(c, "fmi3GetVariableDependencies", "providesPerElementDependencies=\"false\"")
            }
            $crate::__fmi3_derivatives! {
                fmi3GetDirectionalDerivative => get_directional_derivative;
                fmi3GetAdjointDerivative => get_adjoint_derivative;
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterConfigurationMode(c: fmi3Instance) -> fmi3Status {
                api::unsupported::<M>(c, "fmi3EnterConfigurationMode", "the FMU has no structural parameters")
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ExitConfigurationMode(c: fmi3Instance) -> fmi3Status {
                api::unsupported::<M>(c, "fmi3ExitConfigurationMode", "the FMU has no structural parameters")
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetIntervalDecimal(
                c: fmi3Instance,
                vr: *const u32,
                n: usize,
                intervals: *mut f64,
                qualifiers: *mut fmi3IntervalQualifier,
            ) -> fmi3Status {
                api::get_interval_decimal::<M>(c, vr, n, intervals, qualifiers)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetShiftDecimal(
                c: fmi3Instance,
                vr: *const u32,
                n: usize,
                shifts: *mut f64,
            ) -> fmi3Status {
                api::get_shift_decimal::<M>(c, vr, n, shifts)
            }
            $crate::__fmi3_clock_functions! {
                fmi3GetIntervalFraction(*const u32, usize, *mut u64, *mut u64, *mut fmi3IntervalQualifier);
                fmi3GetShiftFraction(*const u32, usize, *mut u64, *mut u64);
                fmi3SetIntervalDecimal(*const u32, usize, *const f64);
                fmi3SetIntervalFraction(*const u32, usize, *const u64, *const u64);
                fmi3SetShiftDecimal(*const u32, usize, *const f64);
                fmi3SetShiftFraction(*const u32, usize, *const u64, *const u64);
                fmi3ActivateModelPartition(u32, f64);
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(c: fmi3Instance) -> fmi3Status {
                api::unsupported::<M>(c, "fmi3EvaluateDiscreteStates", "providesEvaluateDiscreteStates=\"false\"")
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
                c: fmi3Instance,
                need_update: *mut bool,
                terminate: *mut bool,
                nominals_changed: *mut bool,
                values_changed: *mut bool,
                time_defined: *mut bool,
                next_time: *mut f64,
            ) -> fmi3Status {
                api::update_discrete_states::<M>(
                    c,
                    (need_update, terminate, nominals_changed, values_changed, time_defined),
                    next_time,
                )
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
                c: fmi3Instance,
                _no_prior: bool,
                enter_event_mode: *mut bool,
                terminate: *mut bool,
            ) -> fmi3Status {
                api::completed_integrator_step::<M>(c, enter_event_mode, terminate)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetOutputDerivatives(
                c: fmi3Instance,
                _vr: *const u32,
                _n: usize,
                _orders: *const i32,
                _v: *mut f64,
                _nv: usize,
            ) -> fmi3Status {
                api::get_output_derivatives::<M>(c)
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3DoStep(
                c: fmi3Instance,
                t: f64,
                h: f64,
                no_prior: bool,
                event_handling_needed: *mut bool,
                terminate: *mut bool,
                early_return: *mut bool,
                last_successful_time: *mut f64,
            ) -> fmi3Status {
                api::do_step::<M>(
                    c,
                    t,
                    h,
                    no_prior,
                    (event_handling_needed, terminate, early_return),
                    last_successful_time,
                )
            }
        }
    };
}

/// The get and set functions of the types the variables have (inside [`export_fmi3!`]): each
/// entry `get => api_get, set => api_set: GetType, SetType;` (a Boolean is set as bytes).
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi3_values {
    ($($get:ident => $api_get:ident, $set:ident => $api_set:ident: $gt:ty, $st:ty;)*) => {$(
        $crate::__forward! {
            $get(c: fmi3Instance, vr: *const u32, n: usize, v: *mut $gt, nv: usize) -> fmi3Status => $api_get;
            $set(c: fmi3Instance, vr: *const u32, n: usize, v: *const $st, nv: usize) -> fmi3Status => $api_set;
        }
    )*};
}

/// The get and set functions of types no variable has (inside [`export_fmi3!`], where `api` and
/// `M` are in scope): an error naming the variable and its type.
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi3_other_types {
    ($($get:ident, $set:ident, $t:ty, $name:literal;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $get(c: fmi3Instance, vr: *const u32, n: usize, _v: *mut $t, _nv: usize) -> fmi3Status {
            api::other_type::<M>(c, stringify!($get), false, vr, n, $name)
        }
        #[no_mangle]
        pub unsafe extern "C" fn $set(c: fmi3Instance, vr: *const u32, n: usize, _v: *const $t, _nv: usize) -> fmi3Status {
            api::other_type::<M>(c, stringify!($set), true, vr, n, $name)
        }
    )*};
}

/// The clock functions boomsim does not provide (inside [`export_fmi3!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi3_clock_functions {
    ($($name:ident($($arg:ty),*);)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(c: fmi3Instance, $(_: $arg),*) -> fmi3Status {
            api::clock_unsupported::<M>(c, stringify!($name))
        }
    )*};
}

/// fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative (inside [`export_fmi3!`]): the
/// same arguments, gathered in an [`api::Derivative`](crate::fmi3::api::Derivative).
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi3_derivatives {
    ($($name:ident => $target:ident;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            c: fmi3Instance,
            unknowns: *const u32,
            n_unknowns: usize,
            knowns: *const u32,
            n_knowns: usize,
            seed: *const f64,
            n_seed: usize,
            sensitivity: *mut f64,
            n_sensitivity: usize,
        ) -> fmi3Status {
            let (unknown, known) = ((unknowns, n_unknowns), (knowns, n_knowns));
            let (seed, sensitivity) = ((seed, n_seed), (sensitivity, n_sensitivity));
            api::$target::<M>(c, api::Derivative { unknown, known, seed, sensitivity })
        }
    )*};
}
