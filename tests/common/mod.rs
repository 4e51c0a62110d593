//! In-process harness: drives a model through the generic FMI 2.0 functions with a logger that
//! records every message, as an importer would see them.
#![allow(dead_code)]

use boomsim::fmi2::api;
use boomsim::fmu::guid::guid;
use boomsim::fmi2::types::*;
use boomsim::fmu::Model;
use std::ffi::{CStr, CString};
use std::marker::PhantomData;
use std::os::raw::{c_char, c_int, c_void};
use std::sync::Mutex;

/// Messages received by the logger: (status, category, text).
pub type Messages = Mutex<Vec<(i32, String, String)>>;

unsafe extern "C" fn record(
    env: fmi2ComponentEnvironment,
    _name: fmi2String,
    status: c_int,
    category: fmi2String,
    format: fmi2String,
    message: *const c_char,
) {
    let messages = &*(env as *const Messages);
    assert_eq!(CStr::from_ptr(format).to_str().unwrap(), "%s", "the logger must get a \"%s\" format");
    let text = CStr::from_ptr(message).to_string_lossy().into_owned();
    messages.lock().unwrap().push((status, CStr::from_ptr(category).to_string_lossy().into_owned(), text));
}

unsafe extern "C" fn alloc(n: usize, size: usize) -> *mut c_void {
    libc::calloc(n, size)
}
unsafe extern "C" fn free(p: *mut c_void) {
    libc::free(p)
}

/// A logger with the one argument the FMU passes after the "%s" format.
pub type TextLogger =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, c_int, fmi2String, fmi2String, *const c_char);

/// `logger` as the C-variadic fmi2CallbackLogger. A C-variadic function cannot be defined in
/// stable Rust; calling `logger` through the variadic pointer type is ABI-compatible on the
/// x86_64 System V ABI that the tests run on.
pub fn variadic(logger: TextLogger) -> fmi2CallbackLogger {
    Some(unsafe {
        std::mem::transmute::<
            TextLogger,
            unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, c_int, fmi2String, fmi2String, ...),
        >(logger)
    })
}

/// Callback functions whose logger records into `messages`.
pub fn callbacks(messages: &Messages) -> fmi2CallbackFunctions {
    fmi2CallbackFunctions {
        logger: variadic(record),
        allocateMemory: Some(alloc),
        freeMemory: Some(free),
        stepFinished: None,
        componentEnvironment: messages as *const Messages as *mut c_void,
    }
}

/// One instance of model `M` with its recorded messages.
pub struct Slave<M: Model> {
    pub c: fmi2Component,
    pub messages: Box<Messages>,
    _callbacks: Box<fmi2CallbackFunctions>,
    _m: PhantomData<M>,
}

impl<M: Model> Slave<M> {
    /// Instantiates with the right GUID.
    pub fn new(name: &str) -> Self {
        Self::try_new(name, &guid::<M>(), FMI2_COSIMULATION).expect("instantiation succeeds")
    }

    /// Instantiates with the given GUID and type; `Err` carries the logged messages.
    pub fn try_new(name: &str, guid: &str, fmu_type: c_int) -> Result<Self, Vec<String>> {
        let messages = Box::new(Messages::default());
        let callbacks = Box::new(callbacks(&messages));
        let (n, g) = (CString::new(name).unwrap(), CString::new(guid).unwrap());
        let c = unsafe { api::instantiate::<M>(n.as_ptr(), fmu_type, g.as_ptr(), std::ptr::null(), &*callbacks, 0, 0) };
        if c.is_null() {
            return Err(messages.lock().unwrap().iter().map(|m| m.2.clone()).collect());
        }
        Ok(Slave { c, messages, _callbacks: callbacks, _m: PhantomData })
    }

    /// Setup, initialisation with the given Real start values, and exit: ready to step.
    pub fn initialized(name: &str, reals: &[(u32, f64)]) -> Self {
        let s = Self::new(name);
        assert_eq!(unsafe { api::setup_experiment::<M>(s.c, 0, 0.0, 0.0, 0, 0.0) }, fmi2Status::OK);
        assert_eq!(unsafe { api::enter_initialization_mode::<M>(s.c) }, fmi2Status::OK);
        for &(vr, x) in reals {
            assert_eq!(s.set_real(vr, x), fmi2Status::OK);
        }
        assert_eq!(unsafe { api::exit_initialization_mode::<M>(s.c) }, fmi2Status::OK);
        s
    }

    pub fn set_real(&self, vr: u32, x: f64) -> fmi2Status {
        unsafe { api::set_real::<M>(self.c, &vr, 1, &x) }
    }

    pub fn set_boolean(&self, vr: u32, x: bool) -> fmi2Status {
        let x = if x { FMI2_TRUE } else { FMI2_FALSE };
        unsafe { api::set_boolean::<M>(self.c, &vr, 1, &x) }
    }

    /// fmi2SetRealInputDerivatives, first order.
    pub fn set_slope(&self, vr: u32, d: f64) -> fmi2Status {
        unsafe { api::set_real_input_derivatives::<M>(self.c, &vr, 1, &1, &d) }
    }

    pub fn real(&self, vr: u32) -> f64 {
        let mut x = f64::NAN;
        assert_eq!(unsafe { api::get_real::<M>(self.c, &vr, 1, &mut x) }, fmi2Status::OK);
        x
    }

    pub fn step(&self, t: f64, h: f64) -> fmi2Status {
        unsafe { api::do_step::<M>(self.c, t, h, 1) }
    }

    /// The texts logged so far, and clears them.
    pub fn take_messages(&self) -> Vec<(i32, String, String)> {
        std::mem::take(&mut *self.messages.lock().unwrap())
    }

    /// The last message with status fmi2Error.
    pub fn last_error(&self) -> String {
        let m = self.messages.lock().unwrap();
        m.iter().rev().find(|m| m.0 == fmi2Status::Error as i32).map(|m| m.2.clone()).unwrap_or_default()
    }
}

impl<M: Model> Drop for Slave<M> {
    fn drop(&mut self) {
        unsafe { api::free_instance::<M>(self.c) }
    }
}

/// Overwrites the f64 at byte `at` of a serialised FMU state and recomputes its trailing CRC-32:
/// a forged state that passes every integrity check.
pub fn forge(b: &mut [u8], at: usize, x: f64) {
    forge_bytes(b, at, &x.to_le_bytes());
}

/// Overwrites the bytes at `at` of a serialised FMU state and recomputes its trailing CRC-32.
pub fn forge_bytes(b: &mut [u8], at: usize, bytes: &[u8]) {
    b[at..at + bytes.len()].copy_from_slice(bytes);
    let n = b.len() - 4;
    let crc = crc32(&b[..n]);
    b[n..].copy_from_slice(&crc.to_le_bytes());
}

/// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320), bit by bit: a second implementation,
/// so that forged states are not made with the code under test.
fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
        }
    }
    !c
}

/// Byte offset of the payload of a serialised FMU state (the layout of src/fmu/snapshot.rs,
/// read independently: magic 8, format version 4, GUID length 4 + GUID, payload length 8).
pub fn payload_offset(b: &[u8]) -> usize {
    let n = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    16 + n + 8
}

/// The payload's first three bytes: the codes of the FMI version (0: 2.0, 1: 3.0), the interface
/// (0: Model Exchange, 1: Co-Simulation) and the state machine state (its position in `Mode::ALL`).
pub const CODES: usize = 3;

/// Byte offset of the instance time in a serialised FMU state, after the codes.
pub fn time_offset(b: &[u8]) -> usize {
    payload_offset(b) + CODES
}

/// Byte offset of the value of the variable at table index `i` in a serialised state of `M`:
/// after the payload's codes 3, three times 24, the Clock's activations 8, two optional times 2 x 9, outputs flag 1 and
/// the value count 8, each value is a type tag (0 Real: 8 bytes, 1 Integer: 4, 2 Boolean: 1,
/// 3 String: length 8 + bytes).
pub fn value_offset<M: Model>(b: &[u8], i: usize) -> usize {
    let mut at = time_offset(b) + 24 + 8 + 18 + 1 + 8;
    for _ in 0..i {
        at += 1 + match b[at] {
            0 => 8,
            1 => 4,
            2 => 1,
            _ => 8 + u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap()) as usize,
        };
    }
    assert!(i < M::VARIABLES.len());
    at + 1
}

/// A forged state: the value of the variable at table index `i` replaced by `x`.
pub fn forge_value<M: Model>(b: &mut [u8], i: usize, x: f64) {
    let at = value_offset::<M>(b, i);
    forge(b, at, x);
}

/// The instance's current state, serialised (fmi2GetFMUstate, size, serialise, free).
pub fn serialized<M: Model>(s: &Slave<M>) -> Vec<u8> {
    let mut st: fmi2FMUstate = std::ptr::null_mut();
    let mut size = 0;
    unsafe {
        assert_eq!(api::get_fmu_state::<M>(s.c, &mut st), fmi2Status::OK);
        assert_eq!(api::serialized_fmu_state_size::<M>(s.c, st, &mut size), fmi2Status::OK);
        let mut b = vec![0u8; size];
        assert_eq!(api::serialize_fmu_state::<M>(s.c, st, b.as_mut_ptr() as *mut fmi2Byte, size), fmi2Status::OK);
        assert_eq!(api::free_fmu_state::<M>(s.c, &mut st), fmi2Status::OK);
        b
    }
}

/// A silent in-process Co-Simulation instance of `M` in Initialization Mode with the values of
/// `setup` set (the safe Rust API under the C ABI).
pub fn in_initialization<M: Model>(setup: &[(u32, boomsim::fmu::Value)]) -> boomsim::fmu::instance::Instance<M> {
    use boomsim::fmu::{instance::Instance, log::Logger, machine::Interface};
    let log = Logger::new(None, "test", &[], false);
    let mut i = Instance::<M>::new(log, guid::<M>(), boomsim::fmu::Version::Fmi2, Interface::CoSimulation);
    i.setup_experiment(None, 0.0, None).unwrap();
    i.enter_initialization_mode();
    for (r, x) in setup {
        i.set(&[*r], x.base_type(), vec![x.clone()]).unwrap();
    }
    i
}
