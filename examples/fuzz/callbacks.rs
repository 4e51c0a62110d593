//! The callbacks fmi2Instantiate gets, and FMI 3.0's logMessage; the loggers check every call they
//! receive.

use crate::fmi2::{CallbackFunctions, Logger, Status};
use crate::fmi3;
use crate::report::outcome;
use std::cell::RefCell;
use std::ffi::CStr;
use std::os::raw::{c_char, c_int, c_void};

/// What the logger saw during the current sequence.
#[derive(Default)]
pub struct LogSink {
    /// Print every message to stderr (replay).
    pub echo: bool,
    /// The sequence is an FMI 3.0 one (status names).
    pub fmi3: bool,
    pub messages: u64,
    /// Messages with status Discard and with Error or Fatal (the oracle's check that an error
    /// or discard comes with a message compares them before and after a call).
    pub discards: u64,
    pub errors: u64,
    /// The last Error or Fatal message (the oracle tells a refusal the standard allows, such as
    /// a state outside the model's domain, from one it forbids, such as an illegal call).
    pub last_error: String,
    pub internal_errors: u64,
    pub first_internal_error: Option<String>,
    /// The first oracle violation in a logger call.
    pub violation: Option<String>,
}

thread_local! {
    pub static LOG: RefCell<LogSink> = RefCell::new(LogSink::default());
}

/// The componentEnvironment given to fmi2Instantiate (FMI 3.0: instanceEnvironment): the logger
/// checks that it comes back.
static ENVIRONMENT: u8 = 0;

/// Whether the last Error or Fatal message contains `text`.
pub fn last_error_says(text: &str) -> bool {
    LOG.with(|l| l.borrow().last_error.contains(text))
}

pub fn environment() -> *mut c_void {
    &ENVIRONMENT as *const u8 as *mut c_void
}

/// `logger`'s type: the FMI logger with the one string boomsim passes after "%s".
type Logged = unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, *const c_char);

/// The logger, with the one argument boomsim passes after the "%s" format: checks the call,
/// counts the message (and the caught panics it reports) and, on replay, prints it.
unsafe extern "C" fn logger(
    env: *mut c_void,
    instance: *const c_char,
    status: Status,
    category: *const c_char,
    format: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the strings the FMU passes are NUL-terminated; each is read once found non-NULL.
    let violation = if env != environment() {
        Some(format!("the logger got componentEnvironment {env:p}, not the one given to fmi2Instantiate"))
    } else if instance.is_null() || category.is_null() || format.is_null() {
        Some("the logger got a NULL instanceName, category or message".into())
    } else if !(0..=4).contains(&status) {
        Some(format!("the logger got status {}, which is not an fmi2Status", status as c_int))
    } else if CStr::from_ptr(format).to_bytes() != b"%s" {
        let format = CStr::from_ptr(format);
        Some(format!("the logger got the format {format:?}; boomsim passes \"%s\" and one string"))
    } else if message.is_null() {
        Some("the logger got \"%s\" with a NULL string".into())
    } else {
        None
    };
    record(violation, status as c_int, category, message);
}

/// Counts a message, or keeps the violation found in the logger's arguments; on replay, prints it.
///
/// # Safety
/// Without a violation, `category` and `message` are NUL-terminated strings.
unsafe fn record(violation: Option<String>, status: c_int, category: *const c_char, message: *const c_char) {
    LOG.with(|sink| {
        let sink = &mut *sink.borrow_mut();
        sink.messages += 1;
        if let Some(violation) = violation {
            sink.violation.get_or_insert(violation);
            return;
        }
        let message = CStr::from_ptr(message);
        match status {
            2 => sink.discards += 1,
            3..=4 => {
                sink.errors += 1;
                sink.last_error = message.to_string_lossy().into_owned();
            }
            _ => {}
        }
        if message.to_bytes().windows(15).any(|w| w == b"internal error:") {
            sink.internal_errors += 1;
            sink.first_internal_error.get_or_insert_with(|| message.to_string_lossy().into_owned());
        }
        if sink.echo {
            let category = CStr::from_ptr(category).to_string_lossy();
            eprintln!("     log {} {category}: {}", outcome(i64::from(status), sink.fmi3), message.to_string_lossy());
        }
    });
}

/// FMI 3.0's fmi3LogMessageCallback (not variadic, no instance name): checks the call, counts the
/// message and, on replay, prints it.
pub unsafe extern "C" fn log_message(env: *mut c_void, status: fmi3::Status, category: *const c_char, message: *const c_char) {
    let violation = if env != environment() {
        Some(format!("logMessage got instanceEnvironment {env:p}, not the one given at instantiation"))
    } else if category.is_null() || message.is_null() {
        Some("logMessage got a NULL category or message".into())
    } else if status > 4 {
        Some(format!("logMessage got status {status}, which is not an fmi3Status"))
    } else {
        None
    };
    record(violation, status as c_int, category, message);
}

unsafe extern "C" fn allocate(n: usize, size: usize) -> *mut c_void {
    libc::calloc(n, size)
}

unsafe extern "C" fn free(p: *mut c_void) {
    libc::free(p)
}

/// Which callbacks fmi2Instantiate gets.
#[derive(Debug, Clone, Copy)]
pub struct Callbacks {
    pub logger: bool,
    pub memory: bool,
}

impl Callbacks {
    pub fn functions(self) -> CallbackFunctions {
        // SAFETY: a C-variadic function cannot be defined in stable Rust. `logger` takes the one
        // string boomsim passes after "%s" (it checks the format before reading it); calling it
        // through the variadic pointer type is ABI-compatible on x86_64 System V and aarch64 Linux.
        let logger = unsafe { std::mem::transmute::<Option<Logged>, Logger>(Some(logger)) };
        CallbackFunctions {
            logger: if self.logger { logger } else { None },
            allocateMemory: self.memory.then_some(allocate as unsafe extern "C" fn(usize, usize) -> *mut c_void),
            freeMemory: self.memory.then_some(free as unsafe extern "C" fn(*mut c_void)),
            stepFinished: None,
            componentEnvironment: environment(),
        }
    }
}
