//! Unit helpers. Everything inside boomsim is SI; these convert the engineering units of the
//! thesis (bar, mm, l/min, cm^3, deg) and describe the units written to modelDescription.xml.

/// 1 bar in Pa.
pub const BAR: f64 = 1e5;
/// 1 mm in m.
pub const MM: f64 = 1e-3;
/// 1 l/min in m^3/s.
pub const LPM: f64 = 1e-3 / 60.0;
/// 1 cm^3 in m^3.
pub const CM3: f64 = 1e-6;
/// 1 degree in rad.
pub const DEG: f64 = std::f64::consts::PI / 180.0;
/// Standard atmospheric pressure in Pa: absolute zero is `-P_ATM` in the gauge pressures used
/// throughout boomsim.
pub const P_ATM: f64 = 101_325.0;

/// Pressure in bar to Pa.
pub fn bar(p: f64) -> f64 {
    p * BAR
}
/// Length in mm to m.
pub fn mm(x: f64) -> f64 {
    x * MM
}
/// Flow in l/min to m^3/s.
pub fn lpm(q: f64) -> f64 {
    q * LPM
}

/// A display unit: `display = factor * value + offset` (FMI 2.0, section 2.2.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayUnit {
    pub name: &'static str,
    pub factor: f64,
    pub offset: f64,
}

/// An SI unit: its name and exponents of the SI base units (kg, m, s, A, K, mol, cd, rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    pub name: &'static str,
    /// Exponents of kg, m, s, A, K, mol, cd, rad.
    pub base: [i32; 8],
    pub display: &'static [DisplayUnit],
}

/// Base-unit symbols in the order of [`Unit::base`], as FMI 2.0 names the BaseUnit attributes.
pub const BASE_NAMES: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

const fn u(name: &'static str, base: [i32; 8], display: &'static [DisplayUnit]) -> Unit {
    Unit { name, base, display }
}
const fn d(name: &'static str, factor: f64) -> DisplayUnit {
    DisplayUnit { name, factor, offset: 0.0 }
}

/// Every unit a boomsim model may declare. A model variable's unit must be one of these names
/// (checked by a test), and its display unit one of the unit's display units.
pub const UNITS: &[Unit] = &[
    u("1", [0, 0, 0, 0, 0, 0, 0, 0], &[d("%", 100.0)]),
    u("s", [0, 0, 1, 0, 0, 0, 0, 0], &[d("ms", 1e3)]),
    u("1/s", [0, 0, -1, 0, 0, 0, 0, 0], &[]),
    u("m", [0, 1, 0, 0, 0, 0, 0, 0], &[d("mm", 1e3)]),
    u("m/s", [0, 1, -1, 0, 0, 0, 0, 0], &[d("mm/s", 1e3)]),
    u("m/s2", [0, 1, -2, 0, 0, 0, 0, 0], &[]),
    u("s/m", [0, -1, 1, 0, 0, 0, 0, 0], &[d("s/mm", 1e-3)]),
    u("m/N", [-1, 0, 2, 0, 0, 0, 0, 0], &[d("mm/N", 1e3)]),
    u("m2", [0, 2, 0, 0, 0, 0, 0, 0], &[d("mm2", 1e6)]),
    u("m3", [0, 3, 0, 0, 0, 0, 0, 0], &[d("cm3", 1e6), d("l", 1e3)]),
    u("m3/s", [0, 3, -1, 0, 0, 0, 0, 0], &[d("l/min", 6e4)]),
    u("m3/(s.Pa)", [-1, 4, 1, 0, 0, 0, 0, 0], &[]),
    u("m4.s2/kg", [-1, 4, 2, 0, 0, 0, 0, 0], &[]),
    u("kg", [1, 0, 0, 0, 0, 0, 0, 0], &[]),
    u("kg.m2", [1, 2, 0, 0, 0, 0, 0, 0], &[]),
    u("N", [1, 1, -2, 0, 0, 0, 0, 0], &[d("kN", 1e-3)]),
    u("N.s/m", [1, 0, -1, 0, 0, 0, 0, 0], &[d("N.s/mm", 1e-3)]),
    u("N.m", [1, 2, -2, 0, 0, 0, 0, 0], &[]),
    u("N.m/rad", [1, 2, -2, 0, 0, 0, 0, -1], &[]),
    u("N.m.s/rad", [1, 2, -1, 0, 0, 0, 0, -1], &[]),
    u("N/m", [1, 0, -2, 0, 0, 0, 0, 0], &[]),
    u("Pa", [1, -1, -2, 0, 0, 0, 0, 0], &[d("bar", 1e-5), d("MPa", 1e-6)]),
    u("Pa/s", [1, -1, -3, 0, 0, 0, 0, 0], &[d("bar/s", 1e-5)]),
    u("1/Pa", [-1, 1, 2, 0, 0, 0, 0, 0], &[d("1/bar", 1e5)]),
    u("rad", [0, 0, 0, 0, 0, 0, 0, 1], &[d("deg", 180.0 / std::f64::consts::PI)]),
    u("rad/s", [0, 0, -1, 0, 0, 0, 0, 1], &[d("deg/s", 180.0 / std::f64::consts::PI)]),
    u("rad/s2", [0, 0, -2, 0, 0, 0, 0, 1], &[]),
];

/// Looks up a unit by name.
pub fn unit(name: &str) -> Option<&'static Unit> {
    UNITS.iter().find(|u| u.name == name)
}

/// The display unit `display` of SI unit `unit`, if it is one other than the unit itself.
pub fn display_unit(unit: &str, display: &str) -> Option<&'static DisplayUnit> {
    self::unit(unit)?.display.iter().find(|d| d.name == display && d.name != unit)
}
