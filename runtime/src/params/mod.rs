//! Physical parameters: each with its thesis default, SI unit and source (equation or table).
//!
//! Component parameter structs live beside their component (`hydraulics`, `mechanics`,
//! `control`), each with a table of [`Param`]s built with [`param!`](crate::param); this module
//! holds the one mechanism: the description ([`ParamSpec`]), the accessors, and building a
//! struct from values.

/// Description of one physical parameter. Values are SI; `display_unit` is what users see.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Structured FMU name, e.g. `cbv.p_set`.
    pub name: &'static str,
    /// Default (SI).
    pub default: f64,
    /// SI unit, one of [`crate::units::UNITS`].
    pub unit: &'static str,
    /// Display unit ("" for none).
    pub display_unit: &'static str,
    /// Physically admissible range (SI); values outside are rejected.
    pub min: f64,
    pub max: f64,
    pub description: &'static str,
    /// Where the default comes from: thesis equation/table/section, or the reasoning if the
    /// thesis lacks it.
    pub source: &'static str,
    /// What the number is: a quantity, a count or a choice among named items.
    pub ty: ParamType,
}

/// What a parameter's number is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamType {
    /// A physical quantity (an FMI Real).
    Real,
    /// A count (section counts): a whole number within the range (an FMI Integer).
    Count,
    /// A choice among named items, the value the index of the item (an FMI Enumeration).
    Choice(&'static Enumeration),
}

/// A choice among named items: a law or a mode. The item at index k has the value k, so items
/// are only ever added at the end (value references and values stay stable).
#[derive(Debug, PartialEq)]
pub struct Enumeration {
    /// The type's name (`DampingLaw`), unique within a model.
    pub name: &'static str,
    pub description: &'static str,
    pub items: &'static [Item],
}

/// One item of an [`Enumeration`].
#[derive(Debug, PartialEq)]
pub struct Item {
    /// A short identifier (`thesis`).
    pub name: &'static str,
    pub description: &'static str,
}

impl Enumeration {
    /// The item with value `value`.
    pub fn item(&self, value: i64) -> Option<&Item> {
        usize::try_from(value).ok().and_then(|k| self.items.get(k))
    }

    /// The value of the item named `name`.
    pub fn value(&self, name: &str) -> Option<usize> {
        self.items.iter().position(|i| i.name == name)
    }

    /// The items for a message: `0 (thesis), 1 (structural), ...`.
    pub fn listed(&self) -> String {
        self.items.iter().enumerate().map(|(k, i)| format!("{k} ({})", i.name)).collect::<Vec<_>>().join(", ")
    }
}

/// A Rust enum that a parameter chooses: its items in the order of their values.
pub trait Choice: Copy + PartialEq + 'static {
    const ENUMERATION: &'static Enumeration;
    const ALL: &'static [Self];

    /// The value of the item (its index).
    fn index(self) -> usize {
        Self::ALL.iter().position(|&x| x == self).expect("every item is in ALL")
    }
}

/// One parameter of the physics struct `T`: its description and how to read and write it. Each
/// component's table of these (circuit, boom, beam, feedback filter) is the single source of its
/// parameters' names, defaults, units, ranges, sources and types; the FMU variable tables, the
/// defaults and the reading of parameter values come from it.
pub struct Param<T> {
    pub spec: ParamSpec,
    pub get: fn(&T) -> f64,
    pub set: fn(&mut T, f64),
}

impl<T> Clone for Param<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Param<T> {}

impl<T> std::fmt::Debug for Param<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.spec.fmt(f)
    }
}

/// `base` with every parameter of `params` set to `value(k)` (`k` its index in `params`).
pub fn build<T>(mut base: T, params: &[Param<T>], value: impl Fn(usize) -> f64) -> T {
    for (k, p) in params.iter().enumerate() {
        (p.set)(&mut base, value(k));
    }
    base
}

/// A [`Param`] of a field of `T` (`a.b` or, in parentheses, any place such as `(b[0])`): name,
/// field, default, unit, display unit, `[min, max]`, description, source. With `int` first, a
/// count (`usize` field, rounded); with `choice` first, a [`Choice`] field: name, field,
/// `Type::Default`, description, source.
#[macro_export]
macro_rules! param {
    (int $name:literal, $field:ident, $default:expr, [$min:expr, $max:expr], $description:expr, $source:expr) => {
        $crate::params::Param {
            spec: $crate::params::ParamSpec {
                name: $name,
                default: $default,
                unit: "1",
                display_unit: "",
                min: $min,
                max: $max,
                description: $description,
                source: $source,
                ty: $crate::params::ParamType::Count,
            },
            get: |c| c.$field as f64,
            set: |c, v| c.$field = v.round() as usize,
        }
    };
    (choice $name:literal, $($field:ident).+, $ty:ident :: $default:ident, $description:expr, $source:expr) => {
        $crate::params::Param {
            spec: $crate::params::ParamSpec {
                name: $name,
                default: $ty::$default as usize as f64,
                unit: "1",
                display_unit: "",
                min: 0.0,
                max: (<$ty as $crate::params::Choice>::ALL.len() - 1) as f64,
                description: $description,
                source: $source,
                ty: $crate::params::ParamType::Choice(<$ty as $crate::params::Choice>::ENUMERATION),
            },
            get: |c| $crate::params::Choice::index(c.$($field).+) as f64,
            set: |c, v| {
                if let Some(&x) = <$ty as $crate::params::Choice>::ALL.get(v.round() as usize) {
                    c.$($field).+ = x;
                }
            },
        }
    };
    ($name:literal, ($($place:tt)+), $default:expr, $unit:literal, $display:literal,
     [$min:expr, $max:expr], $description:expr, $source:expr) => {
        $crate::params::Param {
            spec: $crate::params::ParamSpec {
                name: $name,
                default: $default,
                unit: $unit,
                display_unit: $display,
                min: $min,
                max: $max,
                description: $description,
                source: $source,
                ty: $crate::params::ParamType::Real,
            },
            get: |c| c.$($place)+,
            set: |c, v| c.$($place)+ = v,
        }
    };
    ($name:literal, $($field:ident).+, $($rest:tt)+) => {
        $crate::param!($name, ($($field).+), $($rest)+)
    };
}
