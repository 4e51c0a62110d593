//! The C types of the FMI 3.0 API (fmi3PlatformTypes.h, fmi3FunctionTypes.h).
#![allow(non_camel_case_types)]

use std::os::raw::{c_char, c_void};

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3Float64 = f64;
/// C99 `bool` (fmi3PlatformTypes.h).
pub type fmi3Boolean = bool;
pub type fmi3String = *const c_char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const fmi3Byte;
/// C99 `bool`.
pub type fmi3Clock = bool;
/// An enum passed as `int` (read as a number, never transmuted).
pub type fmi3IntervalQualifier = std::os::raw::c_int;
pub type fmi3DependencyKind = std::os::raw::c_int;

/// fmi3Status: the status both versions share.
pub type fmi3Status = crate::fmu::Status;

/// fmi3LogMessageCallback: not variadic (unlike FMI 2.0's logger), no instance name.
pub type fmi3LogMessageCallback =
    Option<unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String)>;
/// fmi3IntermediateUpdateCallback: called inside fmi3DoStep where the master required intermediate
/// inputs or allowed an early return (`crate::fmu::calls::do_step_with_master`).
pub type fmi3IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        fmi3InstanceEnvironment,
        fmi3Float64,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        *mut fmi3Boolean,
        *mut fmi3Float64,
    ),
>;
/// fmi3ClockUpdateCallback (Scheduled Execution, not supported).
pub type fmi3ClockUpdateCallback = Option<unsafe extern "C" fn(fmi3InstanceEnvironment)>;
/// fmi3LockPreemptionCallback / fmi3UnlockPreemptionCallback (Scheduled Execution).
pub type fmi3PreemptionCallback = Option<unsafe extern "C" fn()>;
