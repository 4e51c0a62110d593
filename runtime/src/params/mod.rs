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
    /// A count or a selection (a model index, section counts), exposed as an Integer; values
    /// are whole numbers within the range.
    pub integer: bool,
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
/// count (`usize` field, rounded).
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
                integer: true,
            },
            get: |c| c.$field as f64,
            set: |c, v| c.$field = v.round() as usize,
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
                integer: false,
            },
            get: |c| c.$($place)+,
            set: |c, v| c.$($place)+ = v,
        }
    };
    ($name:literal, $($field:ident).+, $($rest:tt)+) => {
        $crate::param!($name, ($($field).+), $($rest)+)
    };
}
