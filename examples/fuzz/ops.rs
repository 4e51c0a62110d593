//! The call catalogue: one `Op` per FMI function, with the arguments it is called with.

use crate::callbacks::Callbacks;
use crate::fmi2::Component;
use crate::fmu_states::{FmuState, StateCall};
use crate::sequence::Call;
use crate::view::View;
use std::ffi::CString;
use std::fmt::{self, Debug};
use std::os::raw::{c_char, c_int};
use std::ptr::null;

/// A C array argument: the elements, or NULL announcing `n` of them (legal only for n = 0).
#[derive(Clone)]
pub enum Arr<T> {
    Items(Vec<T>),
    Null(usize),
}

impl<T> Arr<T> {
    pub fn len(&self) -> usize {
        match self {
            Arr::Items(v) => v.len(),
            Arr::Null(n) => *n,
        }
    }

    /// The elements (none for NULL).
    pub fn items(&self) -> &[T] {
        match self {
            Arr::Items(v) => v,
            Arr::Null(_) => &[],
        }
    }

    pub fn ptr(&self) -> *const T {
        match self {
            Arr::Items(v) => v.as_ptr(),
            Arr::Null(_) => null(),
        }
    }

    pub fn map<U>(&self, f: impl FnMut(&T) -> U) -> Arr<U> {
        match self {
            Arr::Items(v) => Arr::Items(v.iter().map(f).collect()),
            Arr::Null(n) => Arr::Null(*n),
        }
    }
}

impl<T: Debug> Debug for Arr<T> {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Arr::Items(v) => v.fmt(f),
            Arr::Null(n) => write!(f, "NULL[{n}]"),
        }
    }
}

/// A C string argument: NULL, or bytes that need not be UTF-8.
#[derive(Clone)]
pub enum Text {
    Null,
    Bytes(CString),
}

impl Text {
    pub fn new(s: &str) -> Self {
        Self::bytes(s.as_bytes())
    }

    /// Text from bytes without NUL.
    pub fn bytes(b: &[u8]) -> Self {
        Text::Bytes(CString::new(b).expect("the fuzzer's strings have no NUL"))
    }

    pub fn ptr(&self) -> *const c_char {
        match self {
            Text::Null => null(),
            Text::Bytes(s) => s.as_ptr(),
        }
    }
}

impl Debug for Text {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Text::Null => f.write_str("NULL"),
            Text::Bytes(s) => s.fmt(f),
        }
    }
}

/// The FMUstate* argument of fmi2GetFMUstate and fmi2FreeFMUstate (FMI 3.0 alike): NULL, or a variable
/// holding the given state pointer.
#[derive(Debug, Clone, Copy)]
pub enum Slot {
    Null,
    Holding(FmuState),
}

/// Bytes for fmi2DeSerializeFMUstate (fmi3DeserializeFMUState) and how they were made.
pub struct Blob {
    pub bytes: Arr<u8>,
    pub how: String,
    /// Bytes the FMU must refuse: damaged without a recomputed CRC, garbage, or NULL.
    pub damaged: bool,
    /// What the state holds, when it is an intact copy.
    pub view: Option<View>,
}

impl Debug for Blob {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match &self.bytes {
            Arr::Null(n) => write!(f, "{{NULL with {n} bytes announced}}"),
            Arr::Items(b) => write!(f, "{{{} bytes, {}}}", b.len(), self.how),
        }
    }
}

/// The arguments of fmi2Instantiate; `callbacks` `None` is a NULL functions pointer.
#[derive(Debug)]
pub struct Instantiation {
    pub name: Text,
    pub fmu_type: c_int,
    pub guid: Text,
    pub resources: Text,
    pub callbacks: Option<Callbacks>,
    pub visible: c_int,
    pub logging_on: c_int,
}

/// One call: the variants are the FMI functions without the `fmi2` prefix, with their arguments
/// (the instance is the session's, or NULL). A `null_*` flag passes NULL for that output pointer.
/// After the main fmi2Instantiate, a second instance is kept until the end of the sequence and a
/// third freed right away.
#[derive(Debug)]
pub enum Op {
    GetTypesPlatform,
    GetVersion,
    SetDebugLogging {
        logging_on: c_int,
        categories: Arr<Text>,
    },
    Instantiate(Instantiation),
    FreeInstance {
        instance: Component,
    },
    SetupExperiment {
        tolerance_defined: c_int,
        tolerance: f64,
        start: f64,
        stop_defined: c_int,
        stop: f64,
    },
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal {
        vr: Arr<u32>,
        null_values: bool,
    },
    GetInteger {
        vr: Arr<u32>,
        null_values: bool,
    },
    GetBoolean {
        vr: Arr<u32>,
        null_values: bool,
    },
    GetString {
        vr: Arr<u32>,
        null_values: bool,
    },
    SetReal {
        vr: Arr<u32>,
        values: Arr<f64>,
    },
    SetInteger {
        vr: Arr<u32>,
        values: Arr<c_int>,
    },
    SetBoolean {
        vr: Arr<u32>,
        values: Arr<c_int>,
    },
    SetString {
        vr: Arr<u32>,
        values: Arr<Text>,
    },
    /// The FMU state functions.
    State(StateCall),
    GetDirectionalDerivative {
        unknowns: Arr<u32>,
        knowns: Arr<u32>,
        dv_known: Arr<f64>,
        null_dv_unknown: bool,
    },
    SetRealInputDerivatives {
        vr: Arr<u32>,
        orders: Arr<c_int>,
        values: Arr<f64>,
    },
    GetRealOutputDerivatives {
        vr: Arr<u32>,
        orders: Arr<c_int>,
        null_values: bool,
    },
    DoStep {
        t: f64,
        h: f64,
        no_set_prior: c_int,
    },
    CancelStep,
    GetStatus {
        kind: c_int,
        null_value: bool,
    },
    GetRealStatus {
        kind: c_int,
        null_value: bool,
    },
    GetIntegerStatus {
        kind: c_int,
        null_value: bool,
    },
    GetBooleanStatus {
        kind: c_int,
        null_value: bool,
    },
    GetStringStatus {
        kind: c_int,
        null_value: bool,
    },
    EnterEventMode,
    NewDiscreteStates {
        null_info: bool,
    },
    EnterContinuousTimeMode,
    CompletedIntegratorStep {
        no_set_prior: c_int,
        null_flags: bool,
    },
    SetTime {
        t: f64,
    },
    SetContinuousStates {
        x: Arr<f64>,
    },
    /// fmi2GetDerivatives, fmi2GetEventIndicators, fmi2GetContinuousStates and
    /// fmi2GetNominalsOfContinuousStates: `n` announced, NULL for `null`.
    GetDerivatives {
        n: usize,
        null: bool,
    },
    GetEventIndicators {
        n: usize,
        null: bool,
    },
    GetContinuousStates {
        n: usize,
        null: bool,
    },
    GetNominalsOfContinuousStates {
        n: usize,
        null: bool,
    },
    /// A function with a count larger than the model allows (`oversized`).
    Oversized(crate::oversized::Oversized),
}

impl Call for Op {
    fn takes_instance(&self) -> bool {
        !matches!(self, Op::GetTypesPlatform | Op::GetVersion | Op::Instantiate(_) | Op::FreeInstance { .. })
    }
    fn free_instance(instance: Component) -> Op {
        Op::FreeInstance { instance }
    }
    fn state(call: StateCall) -> Op {
        Op::State(call)
    }
}
