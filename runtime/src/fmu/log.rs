//! Logging through the importer's callback (either FMI version's, behind [`Sink`]), with the
//! log categories every boomsim FMU declares.

use std::ffi::{CStr, CString};

/// Status and fmi3Status: the same values 0 to 4 in both versions (FMI 2.0's fmi2Pending is
/// never returned: doStep is synchronous). Incoming statuses are read as `c_int`, never transmuted.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    OK = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
}

/// The importer's logging callback of one FMI version.
pub trait Sink: Send {
    /// Delivers one message of `instance` (its name) with `status` in `category`.
    fn emit(&self, instance: &CStr, status: Status, category: &CStr, message: &CStr);
}

/// Categories every boomsim FMU declares, in this order, before the model's own.
pub const GENERIC_CATEGORIES: &[(&str, &str)] = &[
    ("logStatusWarning", "Messages with status fmi2Warning"),
    ("logStatusDiscard", "Messages with status fmi2Discard"),
    ("logStatusError", "Messages with status fmi2Error (always delivered)"),
    ("logStatusFatal", "Messages with status fmi2Fatal (always delivered)"),
    ("logAll", "Every message of every category"),
    ("logFmiCalls", "Each FMI function call by name"),
];
const LOG_ALL: usize = 4;
/// Index of the `logFmiCalls` category.
pub const LOG_FMI_CALLS: usize = 5;

/// The instance's connection to the importer's logger.
pub struct Logger {
    sink: Option<Box<dyn Sink>>,
    instance_name: CString,
    categories: Vec<(&'static str, &'static str)>,
    enabled: Vec<bool>,
}

impl Logger {
    /// A logger for one instance (silent without a sink). With `logging_on`, every category is
    /// enabled; otherwise only warnings, discards and errors are.
    pub fn new(
        sink: Option<Box<dyn Sink>>,
        instance_name: &str,
        model_categories: &'static [(&'static str, &'static str)],
        logging_on: bool,
    ) -> Self {
        let categories: Vec<_> = GENERIC_CATEGORIES.iter().chain(model_categories).copied().collect();
        let enabled = (0..categories.len()).map(|i| logging_on || i < LOG_ALL).collect();
        Logger { sink, instance_name: c_string(instance_name), categories, enabled }
    }

    /// The instance name given at instantiation.
    pub fn instance_name(&self) -> &str {
        self.instance_name.to_str().unwrap_or("?")
    }

    /// fmi2SetDebugLogging / fmi3SetDebugLogging: no categories = all of them; an unknown name is an error naming it.
    pub fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Result<(), String> {
        if names.is_empty() {
            self.enabled.iter_mut().for_each(|e| *e = on);
            return Ok(());
        }
        let mut idx = Vec::with_capacity(names.len());
        for n in names {
            match self.categories.iter().position(|(c, _)| c == n) {
                Some(i) => idx.push(i),
                None => {
                    let known: Vec<&str> = self.categories.iter().map(|(c, _)| *c).collect();
                    return Err(format!("unknown log category \"{n}\"; the categories are {}", known.join(", ")));
                }
            }
        }
        idx.into_iter().for_each(|i| self.enabled[i] = on);
        Ok(())
    }

    /// Whether a category (by index) is currently delivered.
    pub fn is_enabled(&self, category: usize) -> bool {
        self.enabled.get(category).copied().unwrap_or(false) || self.enabled[LOG_ALL]
    }

    /// Logs `message` with `status`; the category follows from the status.
    pub fn status(&self, status: Status, message: &str) {
        let category = match status {
            Status::Warning => 0,
            Status::Discard => 1,
            Status::Error => 2,
            Status::Fatal => 3,
            _ => LOG_FMI_CALLS,
        };
        let always = matches!(status, Status::Error | Status::Fatal);
        if always || self.is_enabled(category) {
            self.emit(status, self.categories[category].0, message);
        }
    }

    /// Whether a category, given by name, is delivered.
    pub fn category_enabled(&self, category: &str) -> bool {
        self.categories.iter().position(|(c, _)| *c == category).is_some_and(|i| self.is_enabled(i))
    }

    /// Logs an OK message in a category given by name (the model's own or `logFmiCalls`).
    pub fn info(&self, category: &str, message: &str) {
        if self.category_enabled(category) {
            self.emit(Status::OK, category, message);
        }
    }

    fn emit(&self, status: Status, category: &str, message: &str) {
        if let Some(sink) = &self.sink {
            sink.emit(&self.instance_name, status, &c_string(category), &c_string(message));
        }
    }
}

/// A C string from any text; interior NULs become spaces.
fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// A number as a reader wants it, in messages, modelDescription.xml and the documentation: the
/// shortest text that reads back to the same f64, in exponent form when very small or large
/// (`1e-20`, not 20 zeros; `1e8`).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::num;

    /// Round trip (Rust's shortest representation) and the exponent form outside [1e-4, 1e7).
    #[test]
    fn numbers_read_as_written() {
        assert_eq!(num(1e-20), "1e-20");
        assert_eq!(num(0.001), "0.001");
        assert_eq!(num(-2.5e300), "-2.5e300");
        assert_eq!(num(f64::NAN), "NaN");
        assert_eq!(num(0.0), "0");
        for x in [1e-20, 0.1 + 0.2, 123456.789, 7e-5, f64::MAX, f64::MIN_POSITIVE] {
            assert_eq!(num(x).parse::<f64>().unwrap(), x);
        }
    }
}
