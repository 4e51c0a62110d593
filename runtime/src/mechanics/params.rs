//! Parameters of the boom, its payload and the cylinder's mechanical data (thesis nomenclature,
//! section 2.1 and chapter 3.1), each described once in [`BOOM_PARAMS`] and [`BEAM_PARAMS`].

use crate::param;
use crate::params::{build, Choice, Enumeration, Item, Param};

/// The damping law of the arm's joints (`boom.damping`, module doc of
/// [`crate::mechanics::flexible_boom`]). Only [`DampingLaw::Thesis`] is the thesis'.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DampingLaw {
    /// Per section, eq. 2.36-2.38: `c = 2 xi sqrt(k J)` of each section; its modal damping falls
    /// with the number of sections.
    Thesis,
    /// Not in the thesis: stiffness-proportional, `c = beta k` with `beta = 2 xi / omega_b`.
    Structural,
    /// Not in the thesis: the locked arm's modes below 50 Hz keep the thesis' damping, those
    /// above are damped critically (quasi-static).
    Modal,
    /// Not in the thesis: every locked mode the lumping has converged keeps the ratio `xi`, the
    /// others up to critical, smoothly in frequency.
    ConvergedModal,
}

impl Choice for DampingLaw {
    const ENUMERATION: &'static Enumeration = &Enumeration {
        name: "DampingLaw",
        description: "Damping law of the flexible arm's joints; only 'thesis' is the thesis' (eq. 2.36-2.38)",
        items: &[
            Item {
                name: "thesis",
                description: "The thesis' law, eq. 2.36-2.38: c = 2 xi sqrt(k J) per section (its modal damping falls \
                              with the number of sections)",
            },
            Item {
                name: "structural",
                description: "Not in the thesis: stiffness-proportional c = beta k, the ratio xi at the arm's first \
                              bending mode",
            },
            Item {
                name: "modal",
                description: "Not in the thesis: the locked arm's modes below 50 Hz keep the thesis' damping, those \
                              above are damped critically (quasi-static)",
            },
            Item {
                name: "converged_modal",
                description: "Not in the thesis: every locked mode within 1 % of its frequency with twice the \
                              sections gets the ratio xi, the others up to critical, smoothly in frequency",
            },
        ],
    };
    const ALL: &'static [Self] =
        &[DampingLaw::Thesis, DampingLaw::Structural, DampingLaw::Modal, DampingLaw::ConvergedModal];
}

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

const NOMENCLATURE: &str = "thesis nomenclature, list of parameters; Fig. 2.1";

/// Every boom, payload and cylinder-mechanics parameter (SI).
#[rustfmt::skip]
pub const BOOM_PARAMS: &[Param<BoomParams>] = &[
    param!("boom.b1", (b[0]), 0.050, "m", "mm", [0.0, 0.5],
        "Joint centre to inner end of the lower beam", NOMENCLATURE),
    param!("boom.b2", (b[1]), 0.076, "m", "mm", [0.0, 0.5],
        "End of the lower mounting bracket to its bolt hole", NOMENCLATURE),
    param!("boom.b3", (b[2]), 0.058, "m", "mm", [0.0, 0.5],
        "Bottom of the lower mounting bracket to its bolt hole", NOMENCLATURE),
    param!("boom.b4", (b[3]), 0.076, "m", "mm", [0.0, 0.5],
        "End of the upper mounting bracket to its bolt hole", NOMENCLATURE),
    param!("boom.b5", (b[4]), 0.058, "m", "mm", [0.0, 0.5],
        "Bottom of the upper mounting bracket to its bolt hole", NOMENCLATURE),
    param!("boom.b6", (b[5]), 0.075, "m", "mm", [0.0, 0.5],
        "Joint centre to the bottom of the upper beam (arm)", NOMENCLATURE),
    param!("boom.b7", (b[6]), 0.080, "m", "mm", [0.0, 0.5],
        "Joint centre to the inner end of the upper beam (arm)", NOMENCLATURE),
    param!("boom.b8", (b[7]), 1.115, "m", "mm", [0.1, 3.0],
        "Joint centre to the top of the lower beam", NOMENCLATURE),
    param!("boom.l1", l1, 0.600, "m", "mm", [0.0, 2.0],
        "Inner end of the arm to the inner end of the upper cylinder bracket",
        "chapter 3.1 (the nomenclature lists 548 mm, a different rig setting)"),
    param!("boom.l2", l2, 0.300, "m", "mm", [0.0, 2.0],
        "Inner end of the lower beam to the inner end of the lower cylinder bracket",
        "chapter 3.1 (the nomenclature lists 410 mm, a different rig setting)"),
    param!("boom.l_arm", l_arm, 3.680, "m", "mm", [0.5, 10.0],
        "Length of the arm (upper beam)", NOMENCLATURE),
    param!("boom.m_arm", m_arm, 81.0, "kg", "", [1.0, 1000.0],
        "Mass of the arm, uniform over its length", NOMENCLATURE),
    param!("payload.m", m_pl, 382.6, "kg", "", [0.0, 2000.0],
        "Payload mass (point mass, fixture and all plates)",
        "chapter 3.1, experiment I: 'all available weights'; the nomenclature's fixture 7.5 kg + \
         plates 4 x 76 kg + 16 kg sum to 327.5 kg only"),
    param!("payload.x_inboard", x_pl_inboard, 0.080, "m", "mm", [0.0, 3.0],
        "Payload mass centre inboard of the arm's outer end (l_pl = l_arm - x_inboard, eq. 2.8)",
        "chapter 3.1, experiment I"),
    param!("payload.h", h_pl, 0.070, "m", "mm", [-0.5, 0.5],
        "Payload mass centre above the arm's centre line (h_pl, eq. 2.8)",
        "chapter 3.1, experiment I"),
    param!("cylinder.l_retracted", l_retracted, L_RETRACTED_DEFAULT, "m", "mm", [0.3, 3.0],
        "Pin-to-pin cylinder length when fully retracted (l_cyl = l_retracted + stroke position)",
        "not in the thesis: stroke + 250 mm build length, see mechanics::params::L_RETRACTED_DEFAULT"),
    param!("cylinder.m_rod", m_rod, 5.0, "kg", "", [0.0, 100.0],
        "Mass of the cylinder rod and piston, moving with the stroke", NOMENCLATURE),
    param!("env.g", g, 9.807, "m/s2", "", [0.0, 30.0],
        "Gravitational acceleration", NOMENCLATURE),
];

/// The boom parameters as numbers (SI); names and ranges are in [`BOOM_PARAMS`].
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
    /// The parameters with `value(k)` for [`BOOM_PARAMS`]`[k]` (e.g. the FMU's parameter values,
    /// already checked against their ranges).
    pub fn from_values(value: impl Fn(usize) -> f64) -> Self {
        let unset = BoomParams {
            b: [0.0; 8],
            l1: 0.0,
            l2: 0.0,
            l_arm: 0.0,
            m_arm: 0.0,
            m_pl: 0.0,
            x_pl_inboard: 0.0,
            h_pl: 0.0,
            l_retracted: 0.0,
            m_rod: 0.0,
            g: 0.0,
        };
        build(unset, BOOM_PARAMS, value)
    }

    /// Length from the arm's inner end to the payload mass centre, l_pl of eq. (2.8).
    pub fn l_pl(&self) -> f64 {
        self.l_arm - self.x_pl_inboard
    }
}

impl Default for BoomParams {
    /// The defaults of [`BOOM_PARAMS`]: chapter 3.1 geometry (l1 = 0.6 m, l2 = 0.3 m) and payload.
    fn default() -> Self {
        Self::from_values(|k| BOOM_PARAMS[k].spec.default)
    }
}

/// Every parameter of the arm's cross-section and of the lumped flexible beam (thesis 2.1.3,
/// 2.1.4, 3.1.2), SI. Kept apart from [`BOOM_PARAMS`] so that the rigid-boom FMU's variable table does
/// not change; `boom.n2` and `boom.n3` are structural (integer) parameters.
#[rustfmt::skip]
pub const BEAM_PARAMS: &[Param<BeamParams>] = &[
    param!("boom.w_arm", w_arm, 0.100, "m", "mm", [0.02, 1.0],
        "Width of the arm's hollow rectangular section (eq. 2.26)",
        "not in the thesis: the analytic end deflection of 3.1.2 experiment I (22.29 mm, eq. 2.23-2.33) \
         needs 100.03 mm, i.e. the standard 150x100x6 rectangular hollow section"),
    param!("boom.h_arm", h_arm, 0.150, "m", "mm", [0.02, 1.0],
        "Height of the arm's hollow rectangular section (eq. 2.26)", NOMENCLATURE),
    param!("boom.t_arm", t_arm, 0.006, "m", "mm", [0.001, 0.1],
        "Wall thickness of the arm's hollow rectangular section (eq. 2.26)", NOMENCLATURE),
    param!("boom.E", e, 210e9, "Pa", "MPa", [1e9, 1e12],
        "Young's modulus of the arm", NOMENCLATURE),
    param!("boom.xi", xi, 0.02, "1", "%", [0.0, 1.0],
        "Damping ratio of the arm: of each section's torsional damper (boom.damping = thesis, eq. 2.36-2.38, and \
         modal below its band), of the arm's first bending mode (structural) or of each converged mode \
         (converged_modal)", "section 2.1.4, [3, p. 97]"),
    param!("boom.x_mount", x_mount, 0.590, "m", "mm", [0.01, 3.0],
        "Joint B to the boundary between beam parts II and III at the upper cylinder mount",
        "section 3.1.2, Table 3.1 (the pin itself is at x1 = w1 cos(phi2), eq. 2.25)"),
    param!(int "boom.n2", n2, 4.0, [0.0, 16.0],
        "Sections of beam part II, joint B to the cylinder mount (0: rigid)", "section 3.1.2, experiment III"),
    param!(int "boom.n3", n3, 5.0, [1.0, 16.0],
        "Sections of beam part III, cylinder mount to the arm's end", "section 3.1.2, experiment II"),
    param!(choice "boom.damping", damping, DampingLaw::Modal,
        "Damping law of the arm's joints: thesis (the thesis' law, c = 2 xi sqrt(k J) of each section, its \
         modal damping falls with the number of sections), structural (stiffness-proportional, c = beta k \
         with beta = 2 xi / omega_b: the damping ratio xi at the arm's first bending mode omega_b, whatever \
         the sections), modal, the default (the arm's modes with the cylinder locked below 50 Hz keep the \
         thesis' damping, those above it are damped critically: quasi-static), converged_modal (each \
         locked mode within 1 % of its frequency with twice the sections gets the damping ratio xi, the \
         others up to critical, smoothly in frequency). Only thesis is the thesis'",
        "thesis: eq. 2.36-2.38; structural: not in the thesis, Rayleigh stiffness-proportional damping \
         (Clough & Penzien, Dynamics of Structures, 3rd ed., sec. 12-5) anchored where [3, p. 97]'s 1-2 % for \
         steel structures applies; modal: not in the thesis, the damping matrix of modal damping ratios (ibid., \
         same section) with the modes above the band quasi-static as in a modal truncation with static \
         correction; converged_modal: not in the thesis, the same matrix with [3, p. 97]'s ratio on every mode \
         the lumping resolves"),
];

/// The cross-section and lumped-beam parameters as numbers (SI); names and ranges are in
/// [`BEAM_PARAMS`].
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
    /// Damping law of the joints (`boom.damping`).
    pub damping: DampingLaw,
}

impl BeamParams {
    /// The parameters with `value(k)` for [`BEAM_PARAMS`]`[k]`; `n2`, `n3` are rounded.
    pub fn from_values(value: impl Fn(usize) -> f64) -> Self {
        let unset = BeamParams {
            w_arm: 0.0,
            h_arm: 0.0,
            t_arm: 0.0,
            e: 0.0,
            xi: 0.0,
            x_mount: 0.0,
            n2: 0,
            n3: 0,
            damping: DampingLaw::Thesis,
        };
        build(unset, BEAM_PARAMS, value)
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
    /// The defaults of [`BEAM_PARAMS`].
    fn default() -> Self {
        Self::from_values(|k| BEAM_PARAMS[k].spec.default)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamType;

    /// Every field is one parameter: set parameter k to k + 0.5 (a count to k + 1, a choice to
    /// its last item, away from the first that `from_values` starts from), and each reads back
    /// what was set, and no field is left at the zero it starts from.
    #[test]
    fn every_field_is_one_parameter() {
        fn value<T>(params: &[Param<T>], k: usize) -> f64 {
            match params[k].spec.ty {
                ParamType::Real => k as f64 + 0.5,
                ParamType::Count => k as f64 + 1.0,
                ParamType::Choice(e) => (e.items.len() - 1) as f64,
            }
        }
        fn check<T: std::fmt::Debug>(params: &[Param<T>], built: T) {
            for (k, p) in params.iter().enumerate() {
                assert_eq!((p.get)(&built), value(params, k), "{}", p.spec.name);
            }
            let shown = format!("{built:?}");
            let zeros = shown.split(|c: char| !(c.is_ascii_digit() || c == '.')).filter(|t| *t == "0.0" || *t == "0");
            assert_eq!(zeros.count(), 0, "a field no parameter sets: {shown}");
        }
        check(BOOM_PARAMS, BoomParams::from_values(|k| value(BOOM_PARAMS, k)));
        check(BEAM_PARAMS, BeamParams::from_values(|k| value(BEAM_PARAMS, k)));
        assert_eq!(BeamParams::from_values(|k| value(BEAM_PARAMS, k)).damping, DampingLaw::ConvergedModal);
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
        for s in BOOM_PARAMS.iter().map(|p| &p.spec).chain(BEAM_PARAMS.iter().map(|p| &p.spec)) {
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
