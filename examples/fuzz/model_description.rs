//! What the fuzzer reads from `modelDescription/<Id>.xml` (FMI 2.0) or
//! `modelDescription/fmi3/<Id>.xml` (FMI 3.0): the GUID or instantiation token, the log
//! categories, every variable, the continuous states and event indicators, with the lists the call
//! generators draw from.

use crate::rng::Rng;
use quick_xml::events::{BytesStart, Event};
use quick_xml::XmlVersion;
use std::collections::{BTreeMap, HashMap};
use std::os::raw::c_int;
use std::path::Path;

/// A variable's base type (FMI 3.0: Float64, Int32, Boolean, String, Enumeration; FMI 2.0 reads
/// and writes its Enumerations as Integers, 2.2.7, and so has no Enumeration here).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Type {
    Real,
    Integer,
    Boolean,
    String,
    /// FMI 3.0: read and written with fmi3GetInt64 and fmi3SetInt64 only (2.4.7.4).
    Enumeration,
}

/// Every base type, in the order of `Description::by_type`; FMI 2.0 has the first four.
pub const TYPES: [Type; 5] = [Type::Real, Type::Integer, Type::Boolean, Type::String, Type::Enumeration];

/// One ScalarVariable. The range is ±Inf (Real) or the C int range (Integer, Enumeration) when
/// not declared (these model descriptions declare every Enumeration's).
pub struct Variable {
    pub name: String,
    pub vr: u32,
    pub ty: Type,
    pub causality: String,
    pub variability: String,
    pub initial: Option<String>,
    /// The `derivative` attribute: the state's index (FMI 2.0, from 1) or value reference (FMI 3.0).
    derivative: Option<u32>,
    pub min: f64,
    pub max: f64,
    start: Option<f64>,
    /// FMI 3.0: the variable has a `clocks` attribute (set and read only while its Clock is
    /// active or in Initialization Mode).
    pub clocked: bool,
}

/// An FMI 3.0 input Clock with a constant interval: active at start + shift + k interval.
#[derive(Debug, Clone)]
pub struct Clock {
    pub name: String,
    pub vr: u32,
    pub interval: f64,
    pub shift: f64,
}

/// An element's attributes. Not a HashMap: its random order of drops would make the heap's
/// layout, and so the FMU state pointers an allocator reuses, differ from run to run.
type Attributes = BTreeMap<String, String>;

impl Variable {
    /// From the attributes of a ScalarVariable and of its type element (`Real`, `Integer`, ...);
    /// in FMI 3.0 both are those of the variable's element (`Float64`, `Int32`, ...).
    fn new(scalar: &Attributes, tag: &str, typed: &Attributes) -> Result<Self, String> {
        let name = scalar.get("name").cloned().ok_or("a ScalarVariable without name")?;
        let vr = scalar
            .get("valueReference")
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| format!("{name}: no valid valueReference"))?;
        let (ty, lo, hi) = match tag {
            "Real" | "Float64" => (Type::Real, f64::NEG_INFINITY, f64::INFINITY),
            "Integer" | "Int32" => (Type::Integer, c_int::MIN as f64, c_int::MAX as f64),
            "Enumeration" => (Type::Enumeration, c_int::MIN as f64, c_int::MAX as f64),
            "Boolean" => (Type::Boolean, 0.0, 1.0),
            _ => (Type::String, 0.0, 1.0),
        };
        let number = |key: &str| typed.get(key).and_then(|s| s.parse::<f64>().ok());
        let start = match ty {
            Type::Boolean => typed.get("start").map(|s| f64::from(u8::from(s == "true" || s == "1"))),
            Type::String => None,
            _ => number("start"),
        };
        let text = |key: &str, default: &str| scalar.get(key).cloned().unwrap_or_else(|| default.into());
        Ok(Variable {
            causality: text("causality", "local"),
            variability: text("variability", "continuous"),
            initial: scalar.get("initial").cloned(),
            derivative: typed.get("derivative").and_then(|s| s.parse().ok()),
            min: number("min").unwrap_or(lo),
            max: number("max").unwrap_or(hi),
            clocked: scalar.contains_key("clocks"),
            name,
            vr,
            ty,
            start,
        })
    }

    /// Whether `initial` is, explicitly or by default, "exact" (FMI 2.0 2.2.7, FMI 3.0 2.4.7.4:
    /// parameters and constants default to exact, outputs and locals to calculated).
    pub fn exact(&self) -> bool {
        match self.initial.as_deref() {
            Some(initial) => initial == "exact",
            None => self.causality == "parameter" || self.variability == "constant",
        }
    }

    /// Whether `x` is inside the range (for an Enumeration: one of its items).
    pub fn holds(&self, x: f64) -> bool {
        self.min <= x && x <= self.max
    }

    /// A finite interval to draw values from: the range, or around the start where unbounded.
    pub fn span(&self) -> (f64, f64) {
        let start = self.start.unwrap_or(0.0);
        let lo = if self.min.is_finite() { self.min } else { start - 1.0 - start.abs() };
        let hi = if self.max.is_finite() { self.max } else { start + 1.0 + start.abs() };
        if lo <= hi && (hi - lo).is_finite() {
            (lo, hi)
        } else {
            (start, start)
        }
    }

    /// A value inside the range: mostly the start value or near it, sometimes anywhere in the
    /// range or at a bound (Integer and Enumeration rounded, Boolean 0 or 1).
    pub fn plausible(&self, rng: &mut Rng) -> f64 {
        if self.ty == Type::Boolean {
            return if rng.chance(0.6) { self.start.unwrap_or(0.0) } else { rng.below(2) as f64 };
        }
        let (lo, hi) = self.span();
        let start = self.start.unwrap_or(0.0).clamp(lo, hi);
        let x = match rng.below(10) {
            0..=3 => start,
            4..=6 => start + (hi - lo) * rng.uniform(-0.05, 0.05),
            7..=8 => rng.uniform(lo, hi),
            _ if rng.chance(0.5) => lo,
            _ => hi,
        }
        .clamp(lo, hi);
        if matches!(self.ty, Type::Integer | Type::Enumeration) {
            x.round()
        } else {
            x
        }
    }

    /// A value at a bound of the range, or just across it.
    pub fn edge(&self, rng: &mut Rng) -> f64 {
        let bound = if rng.chance(0.5) { self.min } else { self.max };
        match rng.below(4) {
            0 => bound,
            1 => bound.next_up(),
            2 => bound.next_down(),
            _ => bound + *rng.pick(&[-1e-6, 1e-6]) * bound.abs().max(1.0),
        }
    }
}

impl Clock {
    /// From the attributes of a `Clock` element with `intervalDecimal` (and `shiftDecimal`, else 0).
    fn new(a: &Attributes) -> Result<Self, String> {
        let number = |key: &str| a.get(key).map(|s| s.parse::<f64>().map_err(|e| format!("Clock {key}: {e}")));
        Ok(Clock {
            name: a.get("name").cloned().ok_or("a Clock without name")?,
            vr: a.get("valueReference").and_then(|s| s.parse().ok()).ok_or("a Clock without valueReference")?,
            interval: number("intervalDecimal")
                .ok_or("a Clock without intervalDecimal: the fuzzer knows constant ones")??,
            shift: number("shiftDecimal").unwrap_or(Ok(0.0))?,
        })
    }
}

/// The model description, with the lists the generators draw from.
pub struct Description {
    pub identifier: String,
    /// The GUID (FMI 2.0) or instantiationToken (FMI 3.0).
    pub guid: String,
    /// `fmiVersion` is 3.0.
    pub fmi3: bool,
    /// `providesAdjointDerivatives` of the CoSimulation element (FMI 3.0).
    pub adjoint: bool,
    /// `hasEventMode` of the CoSimulation element (FMI 3.0): eventModeUsed is accepted.
    pub event_mode: bool,
    /// The input Clock (FMI 3.0; one at most), not among `variables`.
    pub clock: Option<Clock>,
    /// `providesDirectionalDerivative` (FMI 3.0: `providesDirectionalDerivatives`) of the
    /// CoSimulation element.
    pub directional: bool,
    pub categories: Vec<String>,
    pub variables: Vec<Variable>,
    /// Value references per type, in the order of `TYPES`.
    by_type: [Vec<u32>; 5],
    /// Value references of the Real outputs.
    pub outputs: Vec<u32>,
    /// Value references of the Reals read after every step that succeeded (`step_outputs`):
    /// the outputs and locals that are not clocked.
    pub after_step: Vec<u32>,
    /// Indices of the variables that may be set before initialisation ends (FMI 2.0, 2.2.7:
    /// inputs and non-calculated parameters), but `boom.flexible`, which the planner sets itself.
    pub init_settable: Vec<usize>,
    /// Indices of the variables that may be set between steps: inputs that are not clocked and
    /// tunable parameters.
    pub step_settable: Vec<usize>,
    /// Indices of the Real inputs that are not clocked (for input derivatives).
    pub real_inputs: Vec<usize>,
    /// `boom.flexible`, when the model has it.
    pub flexible: Option<u32>,
    /// Continuous states (Real variables with `derivative`) and event indicators
    /// (`numberOfEventIndicators`; FMI 3.0: the `EventIndicator` elements), for Model Exchange.
    pub states: usize,
    pub event_indicators: usize,
    /// Value references of the continuous states, in the order of their derivatives.
    pub state_vrs: Vec<u32>,
    /// Value references of the derivatives of ModelStructure (`der(...)`; FMI 2.0 `Derivatives`,
    /// FMI 3.0 `ContinuousStateDerivative`).
    pub derivatives: Vec<u32>,
    /// Value references of the Real InitialUnknowns of ModelStructure.
    pub initial_unknowns: Vec<u32>,
    /// Value references of the knowns of a derivative in Initialization Mode: Real inputs and
    /// Real variables with initial="exact" but constants (FMI 2.0 3.2.1 table, FMI 3.0 2.3.3).
    pub initial_knowns: Vec<u32>,
    /// Value references of the event-indicator locals (`event.*`), in the order of the event
    /// indicators (FMI 3.0: the `EventIndicator` elements; FMI 2.0, which does not name them:
    /// the order of the variables, the same as FMI 3.0's).
    pub event_locals: Vec<u32>,
    /// The spool reference input (`valve.u_ref`), in the models with event locals.
    pub spool_reference: Option<u32>,
    pub max_vr: u32,
    index: HashMap<u32, usize>,
}

impl Description {
    pub fn read(path: &Path) -> Result<Self, String> {
        let xml = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::parse(&xml).map_err(|e| format!("{}: {e}", path.display()))
    }

    fn parse(xml: &str) -> Result<Self, String> {
        let mut reader = quick_xml::Reader::from_str(xml);
        let (mut identifier, mut guid, mut categories, mut variables) = (None, None, Vec::new(), Vec::new());
        let (mut states, mut event_indicators, mut fmi3, mut adjoint, mut directional) = (0, 0, false, false, false);
        let (mut event_mode, mut clock) = (false, None);
        let mut scalar: Option<Attributes> = None;
        // ModelStructure: (the section, the index or value reference) of every Unknown element.
        let (mut section, mut structure) = (String::new(), Vec::<(String, u32)>::new());
        let mut event_vrs = Vec::new();
        loop {
            match reader.read_event().map_err(|e| e.to_string())? {
                Event::Start(e) | Event::Empty(e) => {
                    let a = attributes(&e)?;
                    match e.name().0 {
                        "fmiModelDescription" => {
                            fmi3 = a.get("fmiVersion").is_some_and(|v| v.starts_with("3."));
                            guid = a.get(if fmi3 { "instantiationToken" } else { "guid" }).cloned();
                            event_indicators = a
                                .get("numberOfEventIndicators")
                                .map_or(Ok(0), |n| n.parse())
                                .map_err(|e| format!("numberOfEventIndicators: {e}"))?;
                        }
                        "CoSimulation" => {
                            identifier = a.get("modelIdentifier").cloned();
                            adjoint = a.get("providesAdjointDerivatives").is_some_and(|v| v == "true");
                            event_mode = a.get("hasEventMode").is_some_and(|v| v == "true");
                            let key = if fmi3 { "providesDirectionalDerivatives" } else { "providesDirectionalDerivative" };
                            directional = a.get(key).is_some_and(|v| v == "true");
                        }
                        "Category" => categories.extend(a.get("name").cloned()),
                        "ScalarVariable" => scalar = Some(a),
                        "EventIndicator" if fmi3 => {
                            event_indicators += 1;
                            event_vrs.extend(a.get("valueReference").and_then(|s| s.parse::<u32>().ok()));
                        }
                        tag @ ("Outputs" | "Derivatives" | "InitialUnknowns") => section = tag.to_owned(),
                        "Unknown" => structure.extend(a.get("index").and_then(|s| s.parse().ok()).map(|i| (section.clone(), i))),
                        tag @ ("ContinuousStateDerivative" | "InitialUnknown") if fmi3 => {
                            let section = if tag == "InitialUnknown" { "InitialUnknowns" } else { "Derivatives" };
                            structure.extend(a.get("valueReference").and_then(|s| s.parse().ok()).map(|r| (section.into(), r)));
                        }
                        tag @ ("Float64" | "Int32" | "Boolean" | "String" | "Enumeration") if fmi3 => {
                            states += usize::from(tag == "Float64" && a.contains_key("derivative"));
                            variables.push(Variable::new(&a, tag, &a)?);
                        }
                        "Clock" if fmi3 && clock.is_none() => clock = Some(Clock::new(&a)?),
                        tag @ ("Float32" | "Int8" | "UInt8" | "Int16" | "UInt16" | "UInt32" | "Int64" | "UInt64"
                        | "Binary" | "Clock")
                            if fmi3 =>
                        {
                            let known = "Float64, Int32, Boolean, String, Enumeration, a Clock";
                            return Err(format!("a {tag} variable: the fuzzer knows {known}"));
                        }
                        tag @ ("Real" | "Integer" | "Boolean" | "String" | "Enumeration") => {
                            states += usize::from(tag == "Real" && a.contains_key("derivative"));
                            // FMI 2.0 reads and writes Enumerations as Integers (2.2.7), in their range.
                            let tag = if tag == "Enumeration" { "Integer" } else { tag };
                            if let Some(s) = scalar.take() {
                                variables.push(Variable::new(&s, tag, &a)?);
                            }
                        }
                        _ => {}
                    }
                }
                Event::Eof => break,
                _ => {}
            }
        }
        if variables.is_empty() {
            return Err("no ScalarVariable".into());
        }
        let indices = |keep: &dyn Fn(&Variable) -> bool| -> Vec<usize> {
            variables.iter().enumerate().filter(|(_, v)| keep(v)).map(|(i, _)| i).collect()
        };
        let input = |v: &Variable| v.causality == "input" && !v.clocked;
        let parameter = |v: &Variable| v.causality == "parameter";
        // FMI 2.0 refers to variables by their index (from 1), FMI 3.0 by value reference.
        let vr_of = |reference: u32| match fmi3 {
            true => Some(reference),
            false => variables.get((reference as usize).wrapping_sub(1)).map(|v| v.vr),
        };
        let real = |vr: &u32| variables.iter().any(|v| v.vr == *vr && v.ty == Type::Real);
        let listed = |name: &str| -> Vec<u32> {
            structure.iter().filter(|(s, _)| s == name).filter_map(|&(_, r)| vr_of(r)).filter(real).collect()
        };
        let derivatives = listed("Derivatives");
        let state_vrs = derivatives
            .iter()
            .filter_map(|d| variables.iter().find(|v| v.vr == *d)?.derivative.and_then(vr_of))
            .collect();
        if !fmi3 {
            event_vrs = variables.iter().filter(|v| v.name.starts_with("event.")).map(|v| v.vr).collect();
        }
        let flexible = variables.iter().find(|v| v.name == "boom.flexible" && v.ty == Type::Boolean).map(|v| v.vr);
        Ok(Description {
            by_type: TYPES.map(|t| variables.iter().filter(|v| v.ty == t).map(|v| v.vr).collect()),
            outputs: variables.iter().filter(|v| v.ty == Type::Real && v.causality == "output").map(|v| v.vr).collect(),
            after_step: variables
                .iter()
                .filter(|v| v.ty == Type::Real && !v.clocked && matches!(v.causality.as_str(), "output" | "local"))
                .map(|v| v.vr)
                .collect(),
            init_settable: indices(&|v| {
                v.variability != "constant"
                    && (v.causality == "input" || (parameter(v) && v.initial.as_deref() != Some("calculated")))
                    && Some(v.vr) != flexible
            }),
            step_settable: indices(&|v| input(v) || (parameter(v) && v.variability == "tunable")),
            real_inputs: indices(&|v| input(v) && v.ty == Type::Real),
            initial_unknowns: listed("InitialUnknowns"),
            initial_knowns: variables
                .iter()
                .filter(|v| v.ty == Type::Real && v.variability != "constant" && (v.causality == "input" || v.exact()))
                .map(|v| v.vr)
                .collect(),
            state_vrs,
            derivatives,
            spool_reference: variables.iter().find(|v| v.name == "valve.u_ref" && v.ty == Type::Real).map(|v| v.vr),
            event_locals: event_vrs,
            max_vr: variables.iter().map(|v| v.vr).max().unwrap_or(0),
            index: variables.iter().enumerate().map(|(i, v)| (v.vr, i)).collect(),
            identifier: identifier.ok_or("no CoSimulation modelIdentifier")?,
            guid: guid.ok_or("no guid or instantiationToken")?,
            fmi3,
            adjoint,
            event_mode,
            clock,
            directional,
            flexible,
            states,
            event_indicators,
            categories,
            variables,
        })
    }

    pub fn variable(&self, vr: u32) -> Option<&Variable> {
        self.index.get(&vr).map(|&i| &self.variables[i])
    }

    pub fn of_type(&self, ty: Type) -> &[u32] {
        &self.by_type[ty as usize]
    }

    /// The base types of the version's get and set functions (FMI 2.0: no Enumeration).
    pub fn types(&self) -> &'static [Type] {
        &TYPES[..if self.fmi3 { 5 } else { 4 }]
    }
}

/// An element's attributes, unescaped.
fn attributes(e: &BytesStart) -> Result<Attributes, String> {
    e.attributes()
        .map(|a| {
            let a = a.map_err(|e| e.to_string())?;
            let value = a.normalized_value(XmlVersion::Implicit1_0).map_err(|e| e.to_string())?;
            Ok((a.key.0.to_owned(), value.into_owned()))
        })
        .collect()
}
