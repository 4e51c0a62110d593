//! The variable table: the one source of truth for get/set, range checks, the GUID and
//! modelDescription.xml (ARCHITECTURE.md, principle 2).

use crate::params::{Enumeration, ParamSpec};

/// FMI 2.0 causality (section 2.2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
}

/// FMI 2.0 variability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

/// FMI 2.0 `initial` attribute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initial {
    Exact,
    Approx,
    Calculated,
}

/// Type, start value and type-specific attributes of a variable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    Real {
        start: f64,
        unit: &'static str,
        display_unit: &'static str,
        min: f64,
        max: f64,
    },
    Integer {
        start: i32,
        min: i32,
        max: i32,
    },
    /// One of the items of `ty`, its value the item's index (FMI 2.0, 2.2.3 and 2.2.7: accessed
    /// with fmi2Get/SetInteger; FMI 3.0, 2.4.7.4: with fmi3Get/SetInt64).
    Enumeration {
        start: i32,
        ty: &'static Enumeration,
    },
    Boolean {
        start: bool,
    },
    String {
        start: &'static str,
    },
    /// An FMI 3.0 input Clock with a constant interval (`intervalVariability="constant"`,
    /// FMI 3.0, 2.2.8.2): the importer activates it every `interval` seconds from the start time
    /// plus `shift`. Its value is whether it is active.
    Clock {
        interval: f64,
        shift: f64,
    },
}

/// The FMI base types, for messages and type checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseType {
    Real,
    Integer,
    Enumeration,
    Boolean,
    String,
    Clock,
}

/// The FMI spelling of an enum value: `CalculatedParameter` -> `calculatedParameter`.
pub fn fmi_name<T: std::fmt::Debug>(x: T) -> String {
    let s = format!("{x:?}");
    let mut c = s.chars();
    c.next().map(|f| f.to_lowercase().chain(c).collect()).unwrap_or_default()
}

/// One row of a model's variable table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variable {
    pub name: &'static str,
    /// Value reference: stable across releases, never renumbered.
    pub vr: u32,
    pub description: &'static str,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Initial,
    pub kind: Kind,
    /// For outputs: the value references of the inputs it depends on directly (ModelStructure).
    pub depends_on: &'static [u32],
    /// For outputs whose initial equation differs: the inputs it depends on in Initialization
    /// Mode (`None`: those of `depends_on`).
    pub initial_depends_on: Option<&'static [u32]>,
    /// Whether the variable belongs to the model partition of the model's Clock (FMI 3.0,
    /// 2.2.8.3, attribute `clocks`): set and read only while the Clock is active, or in
    /// Initialization Mode.
    pub clocked: bool,
    /// For a clocked state (FMI 3.0 `<ClockedState>`): the value reference of the variable with
    /// its previous value (attribute `previous`).
    pub previous: Option<u32>,
}

const NO_MIN: f64 = f64::NEG_INFINITY;
const NO_MAX: f64 = f64::INFINITY;

impl Variable {
    const fn new(
        name: &'static str,
        vr: u32,
        causality: Causality,
        variability: Variability,
        initial: Initial,
        kind: Kind,
        description: &'static str,
    ) -> Self {
        Variable {
            name,
            vr,
            description,
            causality,
            variability,
            initial,
            kind,
            depends_on: &[],
            initial_depends_on: None,
            clocked: false,
            previous: None,
        }
    }

    /// A tunable Real parameter from its physical description.
    pub const fn param(vr: u32, p: ParamSpec) -> Self {
        let kind = Kind::Real { start: p.default, unit: p.unit, display_unit: p.display_unit, min: p.min, max: p.max };
        Self::new(p.name, vr, Causality::Parameter, Variability::Tunable, Initial::Exact, kind, p.description)
    }

    /// A continuous Real input with start value and admissible range.
    pub const fn real_input(
        name: &'static str,
        vr: u32,
        start: f64,
        unit: &'static str,
        display_unit: &'static str,
        (min, max): (f64, f64),
        description: &'static str,
    ) -> Self {
        let kind = Kind::Real { start, unit, display_unit, min, max };
        Self::new(name, vr, Causality::Input, Variability::Continuous, Initial::Exact, kind, description)
    }

    /// A continuous Real output computed by the model (initial = calculated, no start value).
    pub const fn real_output(
        name: &'static str,
        vr: u32,
        unit: &'static str,
        display_unit: &'static str,
        description: &'static str,
    ) -> Self {
        Self::calculated(Causality::Output, name, vr, unit, display_unit, description)
    }

    /// A continuous Real local (internal state or diagnostic), initial = calculated.
    pub const fn real_local(
        name: &'static str,
        vr: u32,
        unit: &'static str,
        display_unit: &'static str,
        description: &'static str,
    ) -> Self {
        Self::calculated(Causality::Local, name, vr, unit, display_unit, description)
    }

    const fn calculated(
        causality: Causality,
        name: &'static str,
        vr: u32,
        unit: &'static str,
        display_unit: &'static str,
        description: &'static str,
    ) -> Self {
        let kind = Kind::Real { start: 0.0, unit, display_unit, min: NO_MIN, max: NO_MAX };
        Self::new(name, vr, causality, Variability::Continuous, Initial::Calculated, kind, description)
    }

    /// A tunable Boolean parameter.
    pub const fn bool_param(name: &'static str, vr: u32, start: bool, description: &'static str) -> Self {
        let kind = Kind::Boolean { start };
        Self::new(name, vr, Causality::Parameter, Variability::Tunable, Initial::Exact, kind, description)
    }

    /// A fixed Integer parameter (FMI 2.0 has no structural parameters: fixed ones play that role).
    pub const fn int_param(
        name: &'static str,
        vr: u32,
        start: i32,
        (min, max): (i32, i32),
        description: &'static str,
    ) -> Self {
        let kind = Kind::Integer { start, min, max };
        Self::new(name, vr, Causality::Parameter, Variability::Fixed, Initial::Exact, kind, description)
    }

    /// A fixed Enumeration parameter: a choice among the items of `ty`.
    pub const fn enum_param(
        name: &'static str,
        vr: u32,
        start: i32,
        ty: &'static Enumeration,
        description: &'static str,
    ) -> Self {
        let kind = Kind::Enumeration { start, ty };
        Self::new(name, vr, Causality::Parameter, Variability::Fixed, Initial::Exact, kind, description)
    }

    /// An input Clock with a constant interval and shift [s] (FMI 3.0 `<Clock causality="input"
    /// variability="discrete" intervalVariability="constant">`); inactive at the start.
    pub const fn clock(name: &'static str, vr: u32, (interval, shift): (f64, f64), description: &'static str) -> Self {
        let kind = Kind::Clock { interval, shift };
        Self::new(name, vr, Causality::Input, Variability::Discrete, Initial::Exact, kind, description)
    }

    /// The same variable in the model partition of the model's Clock: discrete-time, changed only
    /// at the Clock's activations.
    pub const fn clocked(mut self) -> Self {
        self.variability = Variability::Discrete;
        self.clocked = true;
        self
    }

    /// The same clocked variable as a clocked state whose previous value is variable `vr`.
    pub const fn previous(mut self, vr: u32) -> Self {
        self.previous = Some(vr);
        self
    }

    /// The same calculated variable as a parameter computed from the others in Initialization
    /// Mode and fixed after it (`causality="calculatedParameter" variability="fixed"`).
    pub const fn calculated_parameter(mut self) -> Self {
        self.causality = Causality::CalculatedParameter;
        self.fixed()
    }

    /// The same variable, but fixed (settable only before initialisation ends).
    pub const fn fixed(mut self) -> Self {
        self.variability = Variability::Fixed;
        self
    }

    /// The same output, declaring the inputs it depends on directly.
    pub const fn depends(mut self, inputs: &'static [u32]) -> Self {
        self.depends_on = inputs;
        self
    }

    /// The same output, declaring other inputs for Initialization Mode than after it.
    pub const fn initial_depends(mut self, inputs: &'static [u32]) -> Self {
        self.initial_depends_on = Some(inputs);
        self
    }

    /// The variable's base type.
    pub const fn base_type(&self) -> BaseType {
        match self.kind {
            Kind::Real { .. } => BaseType::Real,
            Kind::Integer { .. } => BaseType::Integer,
            Kind::Enumeration { .. } => BaseType::Enumeration,
            Kind::Boolean { .. } => BaseType::Boolean,
            Kind::String { .. } => BaseType::String,
            Kind::Clock { .. } => BaseType::Clock,
        }
    }

    /// Whether the XML carries a start value (FMI 2.0: initial exact/approx, or an input).
    pub fn has_start(&self) -> bool {
        self.initial != Initial::Calculated || self.causality == Causality::Input
    }

    /// For an Enumeration: the value of the item named `text`, or `text` read as the value of an
    /// item (so a command line takes `thesis` or `0`); otherwise why not, naming the items.
    pub fn item_value(&self, text: &str) -> Result<i32, String> {
        let Kind::Enumeration { ty, .. } = self.kind else { return Err(format!("{} is not an Enumeration", self.name)) };
        let value = ty.value(text).map(|k| k as i64).or_else(|| text.parse().ok());
        match value.and_then(|x| ty.item(x).map(|_| x as i32)) {
            Some(x) => Ok(x),
            None => Err(format!("{} = {text} is no item of {}; valid: {}", self.name, ty.name, ty.listed())),
        }
    }

    /// The start value as a [`Value`].
    pub fn start_value(&self) -> Value {
        match self.kind {
            Kind::Real { start, .. } => Value::Real(start),
            Kind::Integer { start, .. } | Kind::Enumeration { start, .. } => Value::Integer(start),
            Kind::Boolean { start } => Value::Boolean(start),
            Kind::String { start } => Value::String(start.to_owned()),
            Kind::Clock { .. } => Value::Clock(false),
        }
    }
}

/// A variable's current value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
    /// A Clock: whether it is active.
    Clock(bool),
}

impl Value {
    /// The type of the FMI 2.0 setter that writes the value (an Enumeration's is Integer).
    pub fn base_type(&self) -> BaseType {
        match self {
            Value::Real(_) => BaseType::Real,
            Value::Integer(_) => BaseType::Integer,
            Value::Boolean(_) => BaseType::Boolean,
            Value::String(_) => BaseType::String,
            Value::Clock(_) => BaseType::Clock,
        }
    }
}

/// The Enumeration types of a table's variables, each once, in table order (the
/// TypeDefinitions of modelDescription.xml).
pub fn enumerations(table: &[Variable]) -> Vec<&'static Enumeration> {
    let mut types: Vec<&'static Enumeration> = Vec::new();
    for v in table {
        if let Kind::Enumeration { ty, .. } = v.kind {
            if !types.iter().any(|t| t.name == ty.name) {
                types.push(ty);
            }
        }
    }
    types
}

/// The current values of all variables of one instance, in table order.
#[derive(Debug, Clone, PartialEq)]
pub struct Values {
    table: &'static [Variable],
    values: Vec<Value>,
    /// Table index by value reference ([`NONE`](Self::NONE) where there is no variable): the
    /// references are small and dense, so a direct table makes every get and set O(1).
    slot: Vec<u32>,
    /// The first variable the model set to a non-finite number, if any (so that the FMI layer
    /// finds one without scanning the table after every step).
    non_finite: Option<usize>,
}

impl Values {
    const NONE: u32 = u32::MAX;

    /// All variables at their start values.
    pub fn new(table: &'static [Variable]) -> Self {
        let mut slot = vec![Self::NONE; table.iter().map(|v| v.vr as usize + 1).max().unwrap_or(0)];
        for (i, v) in table.iter().enumerate() {
            slot[v.vr as usize] = i as u32;
        }
        Values { table, values: table.iter().map(Variable::start_value).collect(), slot, non_finite: None }
    }

    /// The variable table.
    pub fn table(&self) -> &'static [Variable] {
        self.table
    }

    /// Table index of a value reference.
    pub fn position(&self, vr: u32) -> Option<usize> {
        self.slot.get(vr as usize).filter(|&&i| i != Self::NONE).map(|&i| i as usize)
    }

    /// The value at a table index.
    pub fn at(&self, i: usize) -> &Value {
        &self.values[i]
    }

    /// Replaces the value at a table index (the caller checked type and range).
    pub fn put(&mut self, i: usize, v: Value) {
        self.values[i] = v;
    }

    /// All values in table order.
    pub fn all(&self) -> &[Value] {
        &self.values
    }

    fn expect(&self, vr: u32) -> &Value {
        let i = self.position(vr).unwrap_or_else(|| panic!("no variable with value reference {vr}"));
        &self.values[i]
    }

    /// The Real with value reference `vr` (panics on a wrong vr: a bug in the model, caught at the ABI).
    pub fn real(&self, vr: u32) -> f64 {
        match self.expect(vr) {
            Value::Real(x) => *x,
            v => panic!("variable {vr} is not a Real: {v:?}"),
        }
    }

    /// The Integer with value reference `vr`.
    pub fn integer(&self, vr: u32) -> i32 {
        match self.expect(vr) {
            Value::Integer(x) => *x,
            v => panic!("variable {vr} is not an Integer: {v:?}"),
        }
    }

    /// The Boolean with value reference `vr`.
    pub fn boolean(&self, vr: u32) -> bool {
        match self.expect(vr) {
            Value::Boolean(x) => *x,
            v => panic!("variable {vr} is not a Boolean: {v:?}"),
        }
    }

    /// Sets a Real computed by the model (outputs, locals).
    pub fn set_real(&mut self, vr: u32, x: f64) {
        let i = self.position(vr).unwrap_or_else(|| panic!("no variable with value reference {vr}"));
        if !x.is_finite() && self.non_finite.is_none() {
            self.non_finite = Some(i);
        }
        self.values[i] = Value::Real(x);
    }

    /// The table index of the first non-finite number the model set since the last call, if any.
    pub fn take_non_finite(&mut self) -> Option<usize> {
        self.non_finite.take()
    }
}
