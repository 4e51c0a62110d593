//! `__forward!`: the exported C functions that only hand their arguments to the adapter's
//! function of the same job (inside [`export_fmu!`](crate::export_fmu) and
//! [`export_fmi3!`](crate::export_fmi3), where `api` and the model type `M` are in scope).
//! Functions that drop, regroup or add arguments are written out beside it.

/// Each entry `fmiXName(arg: Type, ...) -> Ret => api_function;` becomes
/// `#[no_mangle] pub unsafe extern "C" fn fmiXName(arg: Type, ...) -> Ret { api::api_function::<M>(arg, ...) }`.
#[doc(hidden)]
#[macro_export]
macro_rules! __forward {
    ($($name:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)? => $target:ident;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name($($arg: $ty),*) $(-> $ret)? {
            api::$target::<M>($($arg),*)
        }
    )*};
}

/// The functions both versions have with the same arguments, but for their names and C types
/// (inside the export macros, where `api` and `M` are in scope): `Instance, FMUState, Byte;`
/// the lifecycle, Model Exchange's (its derivatives' function named with its `api` function)
/// and the six FMU-state functions.
#[doc(hidden)]
#[macro_export]
macro_rules! __common_functions {
    ($instance:ty, $state:ty, $byte:ty;
     $free:ident, $exit_initialization:ident, $terminate:ident, $reset:ident;
     $enter_event:ident, $enter_continuous:ident, $set_time:ident, $set_states:ident, $get_states:ident,
     $get_derivatives:ident => $derivatives:ident, $indicators:ident, $nominals:ident;
     $get:ident, $set:ident, $free_state:ident, $size:ident, $serialize:ident, $deserialize:ident;) => {
        $crate::__forward! {
            $free(c: $instance) => free_instance;
            $exit_initialization(c: $instance) -> $crate::fmu::Status => exit_initialization_mode;
            $terminate(c: $instance) -> $crate::fmu::Status => terminate;
            $reset(c: $instance) -> $crate::fmu::Status => reset;
            $enter_event(c: $instance) -> $crate::fmu::Status => enter_event_mode;
            $enter_continuous(c: $instance) -> $crate::fmu::Status => enter_continuous_time_mode;
            $set_time(c: $instance, time: f64) -> $crate::fmu::Status => set_time;
            $set_states(c: $instance, x: *const f64, nx: usize) -> $crate::fmu::Status => set_continuous_states;
            $get_states(c: $instance, x: *mut f64, nx: usize) -> $crate::fmu::Status => get_continuous_states;
            $get_derivatives(c: $instance, dx: *mut f64, nx: usize) -> $crate::fmu::Status => $derivatives;
            $indicators(c: $instance, z: *mut f64, ni: usize) -> $crate::fmu::Status => get_event_indicators;
            $nominals(c: $instance, x: *mut f64, nx: usize)
                -> $crate::fmu::Status => get_nominals_of_continuous_states;
            $get(c: $instance, s: *mut $state) -> $crate::fmu::Status => get_fmu_state;
            $set(c: $instance, s: $state) -> $crate::fmu::Status => set_fmu_state;
            $free_state(c: $instance, s: *mut $state) -> $crate::fmu::Status => free_fmu_state;
            $size(c: $instance, s: $state, size: *mut usize) -> $crate::fmu::Status => serialized_fmu_state_size;
            $serialize(c: $instance, s: $state, b: *mut $byte, size: usize)
                -> $crate::fmu::Status => serialize_fmu_state;
            $deserialize(c: $instance, b: *const $byte, size: usize, s: *mut $state)
                -> $crate::fmu::Status => deserialize_fmu_state;
        }
    };
}
