//! One FMU under test through one FMI version: its functions and its model description, loaded
//! and checked alike for both versions; `Binding` is what the versions differ in.

use crate::model_description::Description;
use crate::report::Report;
use crate::sequence::Driven;
use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};

/// One FMU under test: its functions and its model description.
pub struct Library<F> {
    pub path: PathBuf,
    pub fmi: F,
    pub model: Description,
}

/// A version's binding (`Fmi2`, `Fmi3`): how it is loaded and checked, and its sequences' session.
pub trait Binding: Sized {
    /// 2 or 3.
    const FMI: u8;
    /// The model description's folder below `modelDescription/`.
    const XML_FOLDER: &'static str;
    /// The model description's name for the token the FMU checks at instantiation.
    const TOKEN: &'static str;
    type Session<'a>: Driven
    where
        Self: 'a;
    /// Opens the shared library.
    unsafe fn open(path: &Path) -> Result<Self, String>;
    /// The first function of the version that the library does not export.
    fn first_missing(&self) -> Option<&'static str>;
    /// Whether a Co-Simulation instantiation named "fuzz" with `token` returns an instance (then
    /// freed); `event_mode_used` for an FMI 3.0 model with a Clock, which requires it.
    unsafe fn instantiates(&self, token: &CStr, event_mode_used: bool) -> bool;
    fn session<'a>(library: &'a Library<Self>, report: &'a mut Report) -> Self::Session<'a>;
}

impl<F: Binding> Library<F> {
    /// Opens `lib<Id>.so` (or `<Id>.so`), checks that it exports every function of the version,
    /// reads its model description and instantiates once with its token: a stale build would
    /// refuse every instantiation, and the fuzzer would test nothing but error paths.
    pub fn load(path: &Path) -> Result<Self, String> {
        let identifier = crate::identifier(path)?;
        let xml = format!("modelDescription/{}{identifier}.xml", F::XML_FOLDER);
        let model = Description::read(&crate::repository().join(&xml))?;
        if F::FMI == 3 && !model.fmi3 {
            return Err(format!("{}: not an FMI 3.0 model description", crate::repository().join(&xml).display()));
        }
        // SAFETY: an FMU library has no initialisers that could break this process; it stays loaded.
        let fmi = unsafe { F::open(path) }?;
        if let Some(function) = fmi.first_missing() {
            return Err(format!("{}: {function} is not exported", path.display()));
        }
        let token = CString::new(model.guid.as_str()).map_err(|e| e.to_string())?;
        // SAFETY: a valid string; the instance is freed once.
        if !unsafe { fmi.instantiates(&token, model.clock.is_some()) } {
            return Err(format!(
                "{} refuses the {} {} of {xml}: a stale build? (cargo build --release)",
                path.display(),
                F::TOKEN,
                model.guid
            ));
        }
        Ok(Library { path: path.to_owned(), fmi, model })
    }
}
