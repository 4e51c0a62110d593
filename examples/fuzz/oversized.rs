//! Counts larger than the arrays passed (issue 25 item 1), through either version: a
//! value-reference list longer than the model's number of variables (FMI 3.0: plus one for
//! `time`), nx or ni other than the model's numbers of continuous states and event indicators,
//! more log categories than the model declares. The rule: the FMU returns Error (fmi2Error,
//! fmi3Error) with a log message and reads none of the arrays, whose lengths it cannot know
//! otherwise (FMI 2.0 2.1.7 and FMI 3.0 2.2.3: an array argument has the elements announced).
//! The arrays passed hold one element when the count is huge (SIZE_MAX, 2^61, 2^40, 2^32),
//! else as many as announced (a count just too large), of the model's own value references.

use crate::fmi2::Fmi2;
use crate::fmi3::Fmi3;
use crate::model_description::{Description, Type};
use crate::rng::Rng;
use std::ffi::c_void;
use std::os::raw::c_char;

/// The count that is too large: which function and argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Counted {
    /// fmi2Get<type>/fmi3Get<type>, nValueReferences (and FMI 3.0's nValues alike).
    Get(Type),
    Set(Type),
    /// fmi2/fmi3GetDirectionalDerivative and (`adjoint`) fmi3GetAdjointDerivative: nUnknowns
    /// or (`known`) nKnowns; FMI 3.0's nSeed and nSensitivity follow.
    Derivative {
        adjoint: bool,
        known: bool,
    },
    /// fmi2SetRealInputDerivatives, fmi2GetRealOutputDerivatives: nvr.
    InputDerivatives,
    OutputDerivatives,
    /// fmi2/fmi3SetDebugLogging: nCategories.
    Categories,
    /// The Model Exchange functions on nx and ni.
    SetContinuousStates,
    GetContinuousStates,
    GetDerivatives,
    GetNominals,
    GetEventIndicators,
}

/// One call with a count larger than the model allows: `n` announced.
#[derive(Debug, Clone, Copy)]
pub struct Oversized {
    pub counted: Counted,
    pub n: usize,
}

/// Counts from which the arrays hold a single element.
const HUGE: usize = 1 << 20;

impl Oversized {
    /// Any such call of FMI 2.0 or (`fmi3`) FMI 3.0.
    pub fn draw(rng: &mut Rng, m: &Description, fmi3: bool) -> Self {
        use Counted::*;
        let ty = *rng.pick(m.types());
        let counted = match rng.below(if fmi3 { 10 } else { 12 }) {
            0..=1 => Get(ty),
            2..=3 => Set(ty),
            4 => Derivative { adjoint: fmi3 && rng.chance(0.5), known: rng.chance(0.5) },
            5 => Categories,
            6 => *rng.pick(&[SetContinuousStates, GetContinuousStates]),
            7 => *rng.pick(&[GetDerivatives, GetNominals]),
            8..=9 => GetEventIndicators,
            10 => InputDerivatives,
            _ => OutputDerivatives,
        };
        let limit = limit(counted, m);
        let n = *rng.pick(&[limit + 1, 2 * limit + 3, 1 << 32, 1 << 40, usize::MAX / 8 + 1, usize::MAX]);
        Oversized { counted, n }
    }

    /// The function called, in FMI 2.0 or (`fmi3`) FMI 3.0.
    pub fn function(&self, fmi3: bool) -> String {
        use Counted::*;
        let ty = |t: Type| match (t, fmi3) {
            (Type::Real, false) => "Real",
            (Type::Real, true) => "Float64",
            (Type::Integer | Type::Enumeration, false) => "Integer",
            (Type::Integer, true) => "Int32",
            (Type::Enumeration, true) => "Int64",
            (Type::Boolean, _) => "Boolean",
            (Type::String, _) => "String",
        };
        let name = match self.counted {
            Get(t) => format!("Get{}", ty(t)),
            Set(t) => format!("Set{}", ty(t)),
            Derivative { adjoint: true, .. } => "GetAdjointDerivative".into(),
            Derivative { .. } => "GetDirectionalDerivative".into(),
            InputDerivatives => "SetRealInputDerivatives".into(),
            OutputDerivatives => "GetRealOutputDerivatives".into(),
            Categories => "SetDebugLogging".into(),
            SetContinuousStates => "SetContinuousStates".into(),
            GetContinuousStates => "GetContinuousStates".into(),
            GetDerivatives if fmi3 => "GetContinuousStateDerivatives".into(),
            GetDerivatives => "GetDerivatives".into(),
            GetNominals => "GetNominalsOfContinuousStates".into(),
            GetEventIndicators => "GetEventIndicators".into(),
        };
        format!("fmi{}{name}", if fmi3 { 3 } else { 2 })
    }

    /// The call for the trace.
    pub fn describe(&self, fmi3: bool) -> String {
        let count = match self.counted {
            Counted::Derivative { known: true, .. } => "nKnowns",
            Counted::Derivative { known: false, .. } => "nUnknowns",
            Counted::Categories => "nCategories",
            Counted::GetEventIndicators => "ni",
            Counted::SetContinuousStates
            | Counted::GetContinuousStates
            | Counted::GetDerivatives
            | Counted::GetNominals => "nx",
            _ => "nValueReferences",
        };
        format!("{} with {count} = {} (arrays of {})", self.function(fmi3), self.n, self.len())
    }

    /// Why the FMU must refuse it (always).
    pub fn why(&self, m: &Description) -> String {
        let what = match self.counted {
            Counted::Categories => "log categories",
            Counted::SetContinuousStates
            | Counted::GetContinuousStates
            | Counted::GetDerivatives
            | Counted::GetNominals => "continuous states",
            Counted::GetEventIndicators => "event indicators",
            _ => "value references (variables)",
        };
        format!("a count of {} for {} {what}", self.n, limit(self.counted, m))
    }

    /// Elements in the arrays passed.
    fn len(&self) -> usize {
        if self.n >= HUGE {
            1
        } else {
            self.n
        }
    }

    /// Value references of the model, of type `ty` where it has any.
    fn refs(&self, m: &Description, ty: Type) -> Vec<u32> {
        let pool = if m.of_type(ty).is_empty() { m.of_type(Type::Real) } else { m.of_type(ty) };
        (0..self.len()).map(|i| pool.get(i % pool.len().max(1)).copied().unwrap_or(0)).collect()
    }

    /// Log categories of the model (or "logAll"), as C strings alive for the call.
    fn categories(&self, m: &Description) -> Vec<std::ffi::CString> {
        let name = |i: usize| m.categories.get(i % m.categories.len().max(1)).map_or("logAll", |s| s.as_str());
        (0..self.len()).map(|i| std::ffi::CString::new(name(i)).expect("no NUL")).collect()
    }

    /// The call through FMI 2.0 on `c`.
    ///
    /// # Safety
    /// `c` is NULL or an instance of `f`'s library; the arrays hold `len()` elements.
    pub unsafe fn invoke2(&self, f: &Fmi2, c: *mut c_void, m: &Description) -> u32 {
        use Counted::*;
        let (n, len) = (self.n, self.len());
        let (mut x, mut ints, ty) = (vec![0.0f64; len], vec![0i32; len], self.ty());
        let vr = self.refs(m, ty);
        let text = std::ffi::CString::new("fuzz").expect("no NUL");
        let mut strings: Vec<*const c_char> = vec![text.as_ptr(); len];
        let (v, xp, ip, sp) = (vr.as_ptr(), x.as_mut_ptr(), ints.as_mut_ptr(), strings.as_mut_ptr());
        match self.counted {
            Get(Type::Real) => f.fmi2GetReal(c, v, n, xp),
            // FMI 2.0's Enumerations are Integers (`model_description`): no Enumeration here.
            Get(Type::Integer | Type::Enumeration) => f.fmi2GetInteger(c, v, n, ip),
            Get(Type::Boolean) => f.fmi2GetBoolean(c, v, n, ip),
            Get(Type::String) => f.fmi2GetString(c, v, n, sp),
            Set(Type::Real) => f.fmi2SetReal(c, v, n, xp),
            Set(Type::Integer | Type::Enumeration) => f.fmi2SetInteger(c, v, n, ip),
            Set(Type::Boolean) => f.fmi2SetBoolean(c, v, n, ip),
            Set(Type::String) => f.fmi2SetString(c, v, n, sp),
            Derivative { known: false, .. } => f.fmi2GetDirectionalDerivative(c, v, n, v, 1, xp, xp),
            Derivative { known: true, .. } => f.fmi2GetDirectionalDerivative(c, v, 1, v, n, xp, xp),
            InputDerivatives => f.fmi2SetRealInputDerivatives(c, v, n, ip, xp),
            OutputDerivatives => f.fmi2GetRealOutputDerivatives(c, v, n, ip, xp),
            Categories => {
                let names = self.categories(m);
                let p: Vec<*const c_char> = names.iter().map(|s| s.as_ptr()).collect();
                f.fmi2SetDebugLogging(c, 1, n, p.as_ptr())
            }
            SetContinuousStates => f.fmi2SetContinuousStates(c, xp, n),
            GetContinuousStates => f.fmi2GetContinuousStates(c, xp, n),
            GetDerivatives => f.fmi2GetDerivatives(c, xp, n),
            GetNominals => f.fmi2GetNominalsOfContinuousStates(c, xp, n),
            GetEventIndicators => f.fmi2GetEventIndicators(c, xp, n),
        }
    }

    /// The call through FMI 3.0 on `c` (nValues, nSeed and nSensitivity as large as the count).
    ///
    /// # Safety
    /// As `invoke2`.
    pub unsafe fn invoke3(&self, f: &Fmi3, c: *mut c_void, m: &Description) -> u32 {
        use Counted::*;
        let (n, len) = (self.n, self.len());
        let (mut x, mut ints, mut flags, ty) = (vec![0.0f64; len], vec![0i32; len], vec![0u8; len], self.ty());
        let mut longs = vec![0i64; len];
        let vr = self.refs(m, ty);
        let text = std::ffi::CString::new("fuzz").expect("no NUL");
        let mut strings: Vec<*const c_char> = vec![text.as_ptr(); len];
        let (v, xp, ip, bp, sp) =
            (vr.as_ptr(), x.as_mut_ptr(), ints.as_mut_ptr(), flags.as_mut_ptr(), strings.as_mut_ptr());
        match self.counted {
            Get(Type::Real) => f.fmi3GetFloat64(c, v, n, xp, n),
            Get(Type::Integer) => f.fmi3GetInt32(c, v, n, ip, n),
            Get(Type::Enumeration) => f.fmi3GetInt64(c, v, n, longs.as_mut_ptr(), n),
            Get(Type::Boolean) => f.fmi3GetBoolean(c, v, n, bp.cast(), n),
            Get(Type::String) => f.fmi3GetString(c, v, n, sp, n),
            Set(Type::Real) => f.fmi3SetFloat64(c, v, n, xp, n),
            Set(Type::Integer) => f.fmi3SetInt32(c, v, n, ip, n),
            Set(Type::Enumeration) => f.fmi3SetInt64(c, v, n, longs.as_ptr(), n),
            Set(Type::Boolean) => f.fmi3SetBoolean(c, v, n, bp.cast(), n),
            Set(Type::String) => f.fmi3SetString(c, v, n, sp, n),
            Derivative { adjoint, known } => {
                let (nu, nk) = if known { (1, n) } else { (n, 1) };
                match adjoint {
                    false => f.fmi3GetDirectionalDerivative(c, v, nu, v, nk, xp, nk, xp, nu),
                    true => f.fmi3GetAdjointDerivative(c, v, nu, v, nk, xp, nu, xp, nk),
                }
            }
            // FMI 3.0 has neither: drawn only for FMI 2.0.
            InputDerivatives | OutputDerivatives => unreachable!("FMI 2.0 functions"),
            Categories => {
                let names = self.categories(m);
                let p: Vec<*const c_char> = names.iter().map(|s| s.as_ptr()).collect();
                f.fmi3SetDebugLogging(c, true, n, p.as_ptr())
            }
            SetContinuousStates => f.fmi3SetContinuousStates(c, xp, n),
            GetContinuousStates => f.fmi3GetContinuousStates(c, xp, n),
            GetDerivatives => f.fmi3GetContinuousStateDerivatives(c, xp, n),
            GetNominals => f.fmi3GetNominalsOfContinuousStates(c, xp, n),
            GetEventIndicators => f.fmi3GetEventIndicators(c, xp, n),
        }
    }

    /// The type of the value references passed.
    fn ty(&self) -> Type {
        match self.counted {
            Counted::Get(ty) | Counted::Set(ty) => ty,
            _ => Type::Real,
        }
    }
}

/// The largest count the model allows for `counted` (the right one for nx and ni).
fn limit(counted: Counted, m: &Description) -> usize {
    match counted {
        Counted::Categories => m.categories.len(),
        Counted::SetContinuousStates
        | Counted::GetContinuousStates
        | Counted::GetDerivatives
        | Counted::GetNominals => m.states,
        Counted::GetEventIndicators => m.event_indicators,
        _ => max_refs(m),
    }
}

/// The most value references a call may pass: the model's variables (FMI 3.0: with `time`, which
/// modelDescription/fmi3 lists as the independent variable, and the Clock).
pub fn max_refs(m: &Description) -> usize {
    m.variables.len() + usize::from(m.clock.is_some())
}

/// Why a list of `n` value references must be refused, if it must (issue 25: longer than the
/// model has variables).
pub fn too_many_refs(n: usize, m: &Description) -> Option<String> {
    (n > max_refs(m)).then(|| format!("{n} value references for {} variables", max_refs(m)))
}

/// Why nx or ni = `n` must be refused, if it must: other than the model's `expected`.
pub fn wrong_size(n: usize, expected: usize, what: &str) -> Option<String> {
    (n != expected).then(|| format!("{n} {what} announced; the model has {expected}"))
}
