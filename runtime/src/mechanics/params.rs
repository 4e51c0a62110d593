//! Parameters of the boom, its payload and the cylinder's mechanical data (thesis nomenclature,
//! section 2.1 and chapter 3.1), each described once in [`SPECS`].

use crate::params::ParamSpec;

/// The retracted pin-to-pin cylinder length, which the thesis does not give.
///
/// Chosen as stroke (500 mm) + 250 mm build length:
/// - a 65/35 mm double-acting cylinder with eye or clevis mounts needs 200-300 mm beyond its stroke
///   (rear cap and eye, piston, gland and guide, rod eye), so 0.7..0.8 m is what a 500 mm stroke
///   cylinder measures retracted; putting the near-horizontal l_cyl = 0.93 m at the 480 mm start
///   of the experiments would need 0.45 m, shorter than the stroke;
/// - with l1 = 0.6 m, l2 = 0.3 m it puts the horizontal boom (theta2 = 0, l_cyl = 0.963 m) at
///   213 mm stroke, close to the mid-stroke operating point of the stability analysis
///   (x_c = 250 mm, Table 6.1), and the l_cyl = 0.93 m of experiment I ("approximately
///   horizontal", theta2 = -3.07 deg) at 180 mm stroke; the full stroke sweeps the boom from
///   -20.2 deg to +28.3 deg, and the 480 mm start of chapters 6 and 7 is at +26.2 deg (with the
///   nomenclature's l1 = 548 mm, l2 = 410 mm, for which l_cyl = 0.93 m is horizontal to 0.03 deg,
///   the range is -19.6 deg .. +33.5 deg and horizontal at 180 mm stroke);
/// - cross-check: the mass m = A_c beta / (x_c omega_n^2) = 2456 kg implied by omega_n = 83.82 rad/s
///   at x_c = 250 mm (Table 6.1, eq. 2.81, C_1 = A_c x_c / beta) equals the static cylinder force
///   over g; this length gives 24.07 kN at 250 mm against m g = 24.09 kN (0.05 %). The static force
///   is flat in the stroke, so this confirms masses and geometry rather than the length itself.
pub const L_RETRACTED_DEFAULT: f64 = 0.75;

/// Positional constructor of a [`ParamSpec`], to keep [`SPECS`] one entry per parameter.
#[allow(clippy::too_many_arguments)]
const fn spec(
    name: &'static str,
    default: f64,
    unit: &'static str,
    display_unit: &'static str,
    min: f64,
    max: f64,
    description: &'static str,
    source: &'static str,
) -> ParamSpec {
    ParamSpec { name, default, unit, display_unit, min, max, description, source }
}

const NOMENCLATURE: &str = "thesis nomenclature, list of parameters; Fig. 2.1";

/// Every boom, payload and cylinder-mechanics parameter (SI).
#[rustfmt::skip]
pub const SPECS: &[ParamSpec] = &[
    spec("boom.b1", 0.050, "m", "mm", 0.0, 0.5,
        "Joint centre to inner end of the lower beam", NOMENCLATURE),
    spec("boom.b2", 0.076, "m", "mm", 0.0, 0.5,
        "End of the lower mounting bracket to its bolt hole", NOMENCLATURE),
    spec("boom.b3", 0.058, "m", "mm", 0.0, 0.5,
        "Bottom of the lower mounting bracket to its bolt hole", NOMENCLATURE),
    spec("boom.b4", 0.076, "m", "mm", 0.0, 0.5,
        "End of the upper mounting bracket to its bolt hole", NOMENCLATURE),
    spec("boom.b5", 0.058, "m", "mm", 0.0, 0.5,
        "Bottom of the upper mounting bracket to its bolt hole", NOMENCLATURE),
    spec("boom.b6", 0.075, "m", "mm", 0.0, 0.5,
        "Joint centre to the bottom of the upper beam (arm)", NOMENCLATURE),
    spec("boom.b7", 0.080, "m", "mm", 0.0, 0.5,
        "Joint centre to the inner end of the upper beam (arm)", NOMENCLATURE),
    spec("boom.b8", 1.115, "m", "mm", 0.1, 3.0,
        "Joint centre to the top of the lower beam", NOMENCLATURE),
    spec("boom.l1", 0.600, "m", "mm", 0.0, 2.0,
        "Inner end of the arm to the inner end of the upper cylinder bracket",
        "chapter 3.1 (the nomenclature lists 548 mm, a different rig setting)"),
    spec("boom.l2", 0.300, "m", "mm", 0.0, 2.0,
        "Inner end of the lower beam to the inner end of the lower cylinder bracket",
        "chapter 3.1 (the nomenclature lists 410 mm, a different rig setting)"),
    spec("boom.l_arm", 3.680, "m", "mm", 0.5, 10.0,
        "Length of the arm (upper beam)", NOMENCLATURE),
    spec("boom.m_arm", 81.0, "kg", "", 1.0, 1000.0,
        "Mass of the arm, uniform over its length", NOMENCLATURE),
    spec("payload.m", 382.6, "kg", "", 0.0, 2000.0,
        "Payload mass (point mass, fixture and all plates)",
        "chapter 3.1, experiment I: 'all available weights'; the nomenclature's fixture 7.5 kg + \
         plates 4 x 76 kg + 16 kg sum to 327.5 kg only"),
    spec("payload.x_inboard", 0.080, "m", "mm", 0.0, 3.0,
        "Payload mass centre inboard of the arm's outer end (l_pl = l_arm - x_inboard, eq. 2.8)",
        "chapter 3.1, experiment I"),
    spec("payload.h", 0.070, "m", "mm", -0.5, 0.5,
        "Payload mass centre above the arm's centre line (h_pl, eq. 2.8)",
        "chapter 3.1, experiment I"),
    spec("cylinder.l_retracted", L_RETRACTED_DEFAULT, "m", "mm", 0.3, 3.0,
        "Pin-to-pin cylinder length when fully retracted (l_cyl = l_retracted + stroke position)",
        "not in the thesis: stroke + 250 mm build length, see mechanics::params::L_RETRACTED_DEFAULT"),
    spec("cylinder.m_rod", 5.0, "kg", "", 0.0, 100.0,
        "Mass of the cylinder rod and piston, moving with the stroke", NOMENCLATURE),
    spec("env.g", 9.807, "m/s2", "", 0.0, 30.0,
        "Gravitational acceleration", NOMENCLATURE),
];

/// The boom parameters as numbers (SI); names and ranges are in [`SPECS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoomParams {
    /// Bracket and joint dimensions b_1..b_8 (index 0 is b_1), Fig. 2.1.
    pub b: [f64; 8],
    pub l1: f64,
    pub l2: f64,
    pub l_arm: f64,
    pub m_arm: f64,
    pub m_pl: f64,
    pub x_pl_inboard: f64,
    pub h_pl: f64,
    pub l_retracted: f64,
    pub m_rod: f64,
    pub g: f64,
}

impl BoomParams {
    /// Reads every parameter by its structured name from `value` (e.g. the FMU's parameter
    /// values, already checked against the [`SPECS`] ranges).
    pub fn from_lookup(value: impl Fn(&str) -> f64) -> Self {
        Self {
            b: [
                value("boom.b1"),
                value("boom.b2"),
                value("boom.b3"),
                value("boom.b4"),
                value("boom.b5"),
                value("boom.b6"),
                value("boom.b7"),
                value("boom.b8"),
            ],
            l1: value("boom.l1"),
            l2: value("boom.l2"),
            l_arm: value("boom.l_arm"),
            m_arm: value("boom.m_arm"),
            m_pl: value("payload.m"),
            x_pl_inboard: value("payload.x_inboard"),
            h_pl: value("payload.h"),
            l_retracted: value("cylinder.l_retracted"),
            m_rod: value("cylinder.m_rod"),
            g: value("env.g"),
        }
    }

    /// Length from the arm's inner end to the payload mass centre, l_pl of eq. (2.8).
    pub fn l_pl(&self) -> f64 {
        self.l_arm - self.x_pl_inboard
    }
}

impl Default for BoomParams {
    /// The defaults of [`SPECS`]: chapter 3.1 geometry (l1 = 0.6 m, l2 = 0.3 m) and payload.
    fn default() -> Self {
        Self::from_lookup(|name| default_of(SPECS, name))
    }
}

/// Every parameter of the arm's cross-section and of the lumped flexible beam (thesis 2.1.3,
/// 2.1.4, 3.1.2), SI. Kept apart from [`SPECS`] so that the rigid-boom FMU's variable table does
/// not change; `boom.n2` and `boom.n3` are structural (integer) parameters.
#[rustfmt::skip]
pub const BEAM_SPECS: &[ParamSpec] = &[
    spec("boom.w_arm", 0.100, "m", "mm", 0.02, 1.0,
        "Width of the arm's hollow rectangular section (eq. 2.26)",
        "not in the thesis: the analytic end deflection of 3.1.2 experiment I (22.29 mm, eq. 2.23-2.33) \
         needs 100.03 mm, i.e. the standard 150x100x6 rectangular hollow section"),
    spec("boom.h_arm", 0.150, "m", "mm", 0.02, 1.0,
        "Height of the arm's hollow rectangular section (eq. 2.26)", NOMENCLATURE),
    spec("boom.t_arm", 0.006, "m", "mm", 0.001, 0.1,
        "Wall thickness of the arm's hollow rectangular section (eq. 2.26)", NOMENCLATURE),
    spec("boom.E", 210e9, "Pa", "MPa", 1e9, 1e12,
        "Young's modulus of the arm", NOMENCLATURE),
    spec("boom.xi", 0.02, "1", "%", 0.0, 1.0,
        "Damping ratio of the lumped beam's torsional dampers (eq. 2.36-2.38)", "section 2.1.4, [3, p. 97]"),
    spec("boom.x_mount", 0.590, "m", "mm", 0.01, 3.0,
        "Joint B to the boundary between beam parts II and III at the upper cylinder mount",
        "section 3.1.2, Table 3.1 (the pin itself is at x1 = w1 cos(phi2), eq. 2.25)"),
    spec("boom.n2", 4.0, "1", "", 0.0, 16.0,
        "Sections of beam part II, joint B to the cylinder mount (0: rigid)", "section 3.1.2, experiment III"),
    spec("boom.n3", 5.0, "1", "", 1.0, 16.0,
        "Sections of beam part III, cylinder mount to the arm's end", "section 3.1.2, experiment II"),
];

/// The cross-section and lumped-beam parameters as numbers (SI); names and ranges are in
/// [`BEAM_SPECS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamParams {
    pub w_arm: f64,
    pub h_arm: f64,
    pub t_arm: f64,
    pub e: f64,
    pub xi: f64,
    pub x_mount: f64,
    /// Sections of part II; 0 makes part II one rigid body.
    pub n2: usize,
    pub n3: usize,
}

impl BeamParams {
    /// Reads every parameter of [`BEAM_SPECS`] by name; `n2`, `n3` are rounded.
    pub fn from_lookup(value: impl Fn(&str) -> f64) -> Self {
        Self {
            w_arm: value("boom.w_arm"),
            h_arm: value("boom.h_arm"),
            t_arm: value("boom.t_arm"),
            e: value("boom.E"),
            xi: value("boom.xi"),
            x_mount: value("boom.x_mount"),
            n2: value("boom.n2").round() as usize,
            n3: value("boom.n3").round() as usize,
        }
    }

    /// Second area moment of the hollow rectangle, eq. (2.26).
    pub fn i_z(&self) -> f64 {
        let (w, h, t) = (self.w_arm, self.h_arm, self.t_arm);
        (w * h.powi(3) - (w - 2.0 * t) * (h - 2.0 * t).powi(3)) / 12.0
    }

    /// Bending stiffness E I_z (eq. 2.21).
    pub fn ei(&self) -> f64 {
        self.e * self.i_z()
    }

    /// The width w_arm for which (2.26) gives `i_z` at this height and thickness ((2.26) is
    /// linear in w_arm).
    pub fn width_for(&self, i_z: f64) -> f64 {
        let (h, t) = (self.h_arm, self.t_arm);
        let inner = (h - 2.0 * t).powi(3);
        (12.0 * i_z - 2.0 * t * inner) / (h.powi(3) - inner)
    }
}

impl Default for BeamParams {
    /// The defaults of [`BEAM_SPECS`].
    fn default() -> Self {
        Self::from_lookup(|name| default_of(BEAM_SPECS, name))
    }
}

fn default_of(specs: &[ParamSpec], name: &str) -> f64 {
    specs.iter().find(|s| s.name == name).unwrap_or_else(|| panic!("no ParamSpec named {name}")).default
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    #[test]
    fn specs_and_struct_name_the_same_parameters() {
        let used = RefCell::new(Vec::new());
        let record = |n: &str| {
            used.borrow_mut().push(n.to_string());
            1.0
        };
        BoomParams::from_lookup(record);
        BeamParams::from_lookup(record);
        let mut used = used.into_inner();
        let mut named: Vec<String> = SPECS.iter().chain(BEAM_SPECS).map(|s| s.name.to_string()).collect();
        used.sort();
        named.sort();
        assert_eq!(used, named);
    }

    /// (2.26) for the 150x100x6 section by hand: (0.1 * 0.15^3 - 0.088 * 0.138^3) / 12
    /// = 8.85247e-6 m^4 (sharp corners); `width_for` inverts it. 1e-6: the hand value has six digits; the inverse is exact to rounding.
    #[test]
    fn hollow_section_moment() {
        let b = BeamParams::default();
        assert!((b.i_z() / 8.85247e-6 - 1.0).abs() < 1e-6, "{}", b.i_z());
        assert!((b.width_for(b.i_z()) - b.w_arm).abs() < 1e-12);
    }

    #[test]
    fn specs_are_well_formed() {
        for s in SPECS.iter().chain(BEAM_SPECS) {
            let unit = crate::units::unit(s.unit).unwrap_or_else(|| panic!("{}: unit", s.name));
            assert!(
                s.display_unit.is_empty() || unit.display.iter().any(|d| d.name == s.display_unit),
                "{}: display unit",
                s.name
            );
            assert!(s.min <= s.default && s.default <= s.max, "{}: default in range", s.name);
        }
    }
}
