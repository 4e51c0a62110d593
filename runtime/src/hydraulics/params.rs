//! Every parameter of the hydraulic circuit: name, thesis default, unit, range and source, with
//! accessors into [`Circuit`]. This table is the single source of the defaults:
//! `Circuit::default()` is built from it.

use super::cbv::Cbv;
use super::circuit::Circuit;
use super::cylinder::Cylinder;
use super::dcv::Dcv;
use super::friction::{Friction, FrictionModel};
use super::line::{Fluid, Lines};
use super::pcv::Pcv;
use super::supply::Supply;
use crate::param;
use crate::units::{BAR, CM3, LPM, MM};
use std::f64::consts::FRAC_PI_4;

/// One circuit parameter: its description and how to read and write it.
pub type Param = crate::params::Param<Circuit>;

/// Why [`Circuit::set_param`] refused a value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamError {
    Unknown,
    OutOfRange { min: f64, max: f64 },
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Unknown => write!(f, "unknown parameter"),
            Self::OutOfRange { min, max } => write!(f, "value outside [{min}, {max}]"),
        }
    }
}

impl std::error::Error for ParamError {}

/// The circuit parameters (SI). Cross-parameter constraints (e.g. `valve.x_db < valve.x_max`,
/// `cylinder.d_rod < cylinder.d_piston`) are not part of the ranges.
pub const PARAMS: &[Param] = &[
    param!(
        "supply.p_s",
        supply.p_s,
        200.0 * BAR,
        "Pa",
        "bar",
        [10.0 * BAR, 400.0 * BAR],
        "Supply pressure (ideal source), gauge",
        "3.2.2 simulation model: 200 bar (parameter list: 155 bar for the rig)"
    ),
    param!("supply.p_t", supply.p_t, 0.0, "Pa", "bar", [0.0, 20.0 * BAR], "Tank pressure, gauge", "parameter list"),
    param!(
        "pcv.p_spring",
        pcv.p_spring,
        7.0 * BAR,
        "Pa",
        "bar",
        [1.0 * BAR, 30.0 * BAR],
        "Pressure compensator spring pressure p_pcv",
        "parameter list, eq. 2.49"
    ),
    param!(
        "pcv.p_fc",
        pcv.p_fc,
        1.0 * BAR,
        "Pa",
        "bar",
        [0.01 * BAR, 20.0 * BAR],
        "PCV spring pressure rise from open to fully closed p_fc,pcv",
        "2.2.1 (assumed), eq. 2.49"
    ),
    param!(
        "pcv.q_nom",
        pcv.q_nom,
        100.0 * LPM,
        "m3/s",
        "l/min",
        [1.0 * LPM, 1000.0 * LPM],
        "Flow of the fully open PCV at pcv.dp_nom (K3)",
        "2.2.1 rated PVB flow, Fig. 2.12"
    ),
    param!(
        "pcv.dp_nom",
        pcv.dp_nom,
        6.0 * BAR,
        "Pa",
        "bar",
        [0.1 * BAR, 100.0 * BAR],
        "Pressure drop of the fully open PCV at pcv.q_nom (K3)",
        "2.2.1, Fig. 2.11"
    ),
    param!(
        "valve.x_max",
        dcv.x_max,
        7.0 * MM,
        "m",
        "mm",
        [1.0 * MM, 20.0 * MM],
        "Maximum main spool travel",
        "2.2.1, eq. 2.44"
    ),
    param!("valve.x_db", dcv.x_db, 0.8 * MM, "m", "mm", [0.0, 5.0 * MM], "Main spool dead band", "2.2.1, eq. 2.44"),
    param!(
        "valve.omega_v",
        dcv.omega_v,
        4.0 / 0.120,
        "rad/s",
        "",
        [1.0, 1000.0],
        "Main spool eigenfrequency, 4 / rated reaction time",
        "eq. 2.45, 6.4; Table 4.2, 6.1"
    ),
    param!(
        "valve.q_rated",
        dcv.q_rated,
        25.0 * LPM,
        "m3/s",
        "l/min",
        [0.1 * LPM, 200.0 * LPM],
        "Rated main spool flow at full opening (K1)",
        "2.2.1"
    ),
    param!(
        "valve.dp_rated",
        dcv.dp_rated,
        7.72 * BAR,
        "Pa",
        "bar",
        [1.0 * BAR, 50.0 * BAR],
        "Main spool pressure drop at rated flow (K1)",
        "2.2.1, eq. 2.51-2.54"
    ),
    param!(
        "valve.dq_leak",
        dcv.dq_leak,
        25.0 * CM3 / 60.0 / (100.0 * BAR),
        "m3/(s.Pa)",
        "",
        [0.0, 1e-10],
        "Laminar leakage coefficient of ports P, A, B to tank",
        "eq. 2.46-2.48, data sheet Table D.1 (25 cm3/min at 100 bar)"
    ),
    param!(
        "cbv.p_cv",
        cbv.p_cv,
        2.8 * BAR,
        "Pa",
        "bar",
        [0.0, 20.0 * BAR],
        "Check valve spring pressure",
        "2.2.2, eq. 2.55"
    ),
    param!(
        "cbv.p_fo_cv",
        cbv.p_fo_cv,
        1.0 * BAR,
        "Pa",
        "bar",
        [0.01 * BAR, 50.0 * BAR],
        "Pressure rise to fully open the check valve",
        "2.2.2 (assumed), eq. 2.55"
    ),
    param!(
        "cbv.p_set",
        cbv.p_set,
        210.0 * BAR,
        "Pa",
        "bar",
        [70.0 * BAR, 280.0 * BAR],
        "Load-holding valve set pressure (defaults: 210 bar for 1:1 and 1:3, 140 bar for 1:2 and 1:5)",
        "Table 4.3, CWCA LHN 1:3 default setting"
    ),
    param!(
        "cbv.mu_p",
        cbv.mu_p,
        3.0,
        "1",
        "",
        [1.0, 10.0],
        "Pilot area ratio (available valves: 1, 2, 3, 5)",
        "Table 4.3; 3 reproduces K_f of Table 6.1"
    ),
    param!(
        "cbv.p_fo_cbv",
        cbv.p_fo_cbv,
        350.0 * BAR,
        "Pa",
        "bar",
        [1.0 * BAR, 1000.0 * BAR],
        "Pressure rise to fully open the load-holding valve",
        "2.2.2, Fig. 2.15, eq. 2.56"
    ),
    param!(
        "cbv.omega_cbv",
        cbv.omega_cbv,
        63.0,
        "rad/s",
        "",
        [1.0, 10000.0],
        "Load-holding valve eigenfrequency",
        "3.3, eq. 2.57"
    ),
    param!(
        "cbv.q_nom",
        cbv.q_nom,
        60.0 * LPM,
        "m3/s",
        "l/min",
        [1.0 * LPM, 1000.0 * LPM],
        "Flow of the fully open CBV at cbv.dp_nom (K2)",
        "2.2.2, Fig. 2.16"
    ),
    param!(
        "cbv.dp_nom",
        cbv.dp_nom,
        16.0 * BAR,
        "Pa",
        "bar",
        [0.1 * BAR, 100.0 * BAR],
        "Pressure drop of the fully open CBV at cbv.q_nom (K2)",
        "2.2.2, Fig. 2.16"
    ),
    param!(
        "cylinder.d_piston",
        cylinder.d_piston,
        65.0 * MM,
        "m",
        "mm",
        [10.0 * MM, 500.0 * MM],
        "Cylinder bore",
        "parameter list d_c"
    ),
    param!(
        "cylinder.d_rod",
        cylinder.d_rod,
        35.0 * MM,
        "m",
        "mm",
        [5.0 * MM, 400.0 * MM],
        "Rod diameter",
        "parameter list d_r"
    ),
    param!(
        "cylinder.stroke",
        cylinder.stroke,
        500.0 * MM,
        "m",
        "mm",
        [10.0 * MM, 5000.0 * MM],
        "Cylinder stroke",
        "parameter list s_c, 4.1.3"
    ),
    param!(
        "cylinder.v_dead_a",
        cylinder.v_dead_a,
        50.0 * CM3,
        "m3",
        "cm3",
        [0.1 * CM3, 1e4 * CM3],
        "Dead volume of the piston-side chamber V_CH1",
        "parameter list, 5.1.1 (assumed)"
    ),
    param!(
        "cylinder.v_dead_b",
        cylinder.v_dead_b,
        50.0 * CM3,
        "m3",
        "cm3",
        [0.1 * CM3, 1e4 * CM3],
        "Dead volume of the rod-side chamber V_CH2",
        "parameter list, 5.1.1 (assumed)"
    ),
    param!(
        "cylinder.k_stop",
        cylinder.k_stop,
        1e8,
        "N/m",
        "",
        [1e5, 1e12],
        "End-stop contact stiffness",
        "not in the thesis: 0.9 mm yield at 280 bar"
    ),
    param!(
        "cylinder.c_stop",
        cylinder.c_stop,
        2e5,
        "N.s/m",
        "",
        [0.0, 1e9],
        "End-stop contact damping",
        "not in the thesis: about critical for 100 kg"
    ),
    param!(choice "friction.model", friction.model, FrictionModel::Bak,
        "Friction law: bak (eq. 2.65), ottestad (Ottestad et al., eq. 2.63) or fitted (eq. 5.4)",
        "2.2.3, 5.1.2; Bak is the thesis' simulation model"),
    param!(
        "friction.c_p_bak",
        friction.c_p_bak,
        0.02,
        "1",
        "%",
        [0.0, 0.2],
        "Bak's force-dependent friction coefficient",
        "2.2.3, eq. 2.65 (2-3 % in [5])"
    ),
    param!(
        "friction.p_static",
        friction.p_static,
        1.0 * BAR,
        "Pa",
        "bar",
        [0.0, 20.0 * BAR],
        "Pressure to overcome static friction (Bak)",
        "2.2.3, eq. 2.66"
    ),
    param!(
        "friction.v_s",
        friction.v_s,
        0.1 * MM,
        "m/s",
        "mm/s",
        [1e-7, 1e-2],
        "tanh regularisation velocity of the Bak and Ottestad models",
        "not in the thesis: about 1 / C_tan of Table 5.3"
    ),
    param!(
        "friction.f_c",
        friction.f_c,
        273.99,
        "N",
        "",
        [0.0, 1e5],
        "Coulomb friction (Ottestad, fitted)",
        "Table 5.3"
    ),
    param!(
        "friction.f_s",
        friction.f_s,
        1155.43,
        "N",
        "",
        [0.0, 1e5],
        "Static friction (Ottestad, fitted)",
        "Table 5.3"
    ),
    param!(
        "friction.v_0",
        friction.v_0,
        14.19 * MM,
        "m/s",
        "mm/s",
        [1e-5, 1.0],
        "Stribeck velocity (Ottestad, fitted)",
        "Table 5.3"
    ),
    param!(
        "friction.c_v",
        friction.c_v,
        4.06 / MM,
        "N.s/m",
        "N.s/mm",
        [0.0, 1e6],
        "Viscous friction coefficient (Ottestad, fitted)",
        "Table 5.3"
    ),
    param!(
        "friction.c_p",
        friction.c_p,
        0.02 * FRAC_PI_4 * (65.0 * MM) * (65.0 * MM),
        "m2",
        "mm2",
        [0.0, 0.1],
        "Pressure friction coefficient of Ottestad's model",
        "not in the thesis: 2 % of the piston area (Bak-equivalent)"
    ),
    param!(
        "friction.c_tan",
        friction.c_tan,
        10.31 / MM,
        "s/m",
        "s/mm",
        [10.0, 1e7],
        "Hyperbolic tangent coefficient (fitted)",
        "Table 5.3"
    ),
    param!(
        "friction.c_l",
        friction.c_l,
        34629.0 * MM,
        "m/N",
        "mm/N",
        [1e-6, 1e9],
        "Cylinder stroke coefficient (fitted)",
        "Table 5.3"
    ),
    param!("fluid.beta", fluid.beta, 1300e6, "Pa", "MPa", [100e6, 3000e6], "Oil bulk modulus", "parameter list"),
    param!(
        "fluid.air_fraction",
        fluid.air_fraction,
        1e-3,
        "1",
        "%",
        [1e-7, 0.2],
        "Free air per oil volume at atmospheric pressure (cavitation model)",
        concat!(
            "not in the thesis (constant bulk modulus); a fifth of Simscape's 0.5 % for the same law: ",
            "docs/models.md, Cavitation"
        )
    ),
    param!(
        "line.v_l2",
        lines.v_l2,
        100.0 * CM3,
        "m3",
        "cm3",
        [0.01 * CM3, 1e4 * CM3],
        "Volume of line 2 (port A to CBV)",
        "parameter list, 5.1.1, Table 5.2"
    ),
    param!(
        "line.v_l3",
        lines.v_l3,
        150.0 * CM3,
        "m3",
        "cm3",
        [0.01 * CM3, 1e4 * CM3],
        "Volume of line 3 (CBV to piston side)",
        "parameter list, 5.1.1, Table 5.2"
    ),
    param!(
        "line.v_l4",
        lines.v_l4,
        200.0 * CM3,
        "m3",
        "cm3",
        [0.01 * CM3, 1e4 * CM3],
        "Volume of line 4 (rod side to port B)",
        "parameter list, 5.1.1, Table 5.2"
    ),
    param!(
        "line.c_hose",
        lines.c_hose,
        0.00065 / BAR,
        "1/Pa",
        "1/bar",
        [0.0, 1e-6],
        "Hose compliance per hose volume (0: rigid lines)",
        "eq. 5.2, Table 5.2"
    ),
    param!(
        "orifice.p_tr",
        p_tr,
        0.1 * BAR,
        "Pa",
        "bar",
        [1.0, 1.0 * BAR],
        "Transition pressure of the regularised orifice root",
        "not in the thesis: regularisation, exact root above it"
    ),
    param!(
        "valve.omega_loop",
        dcv.omega_loop,
        0.0,
        "rad/s",
        "",
        [0.0, 1e4],
        "Gain of the PVES spool position loop; 0 = the first-order lag of eq. 2.45 (valve.omega_v)",
        concat!(
            "4.2.1 (internal spool position control); gain not in the thesis or data sheet: ",
            "docs/models.md, Valve electronics"
        )
    ),
    param!(
        "valve.v_open",
        dcv.v_open,
        7.0 * MM / 0.120,
        "m/s",
        "mm/s",
        [1.0 * MM, 10.0],
        "Largest spool speed away from neutral, with valve.omega_loop > 0",
        "Table 4.2: 7 mm in the rated reaction time neutral -> max, 0.120 s"
    ),
    param!(
        "valve.v_close",
        dcv.v_close,
        7.0 * MM / 0.090,
        "m/s",
        "mm/s",
        [1.0 * MM, 10.0],
        "Largest spool speed toward neutral, with valve.omega_loop > 0",
        "Table 4.2: 7 mm in the rated reaction time max -> neutral, 0.090 s"
    ),
];

impl Default for Circuit {
    /// The thesis circuit: every parameter at its default of [`PARAMS`].
    fn default() -> Self {
        let mut c = Circuit {
            supply: Supply { p_s: 0.0, p_t: 0.0 },
            pcv: Pcv { p_spring: 0.0, p_fc: 0.0, q_nom: 0.0, dp_nom: 0.0 },
            dcv: Dcv {
                x_max: 0.0,
                x_db: 0.0,
                omega_v: 0.0,
                q_rated: 0.0,
                dp_rated: 0.0,
                dq_leak: 0.0,
                omega_loop: 0.0,
                v_open: 0.0,
                v_close: 0.0,
            },
            cbv: Cbv {
                p_cv: 0.0,
                p_fo_cv: 0.0,
                p_set: 0.0,
                mu_p: 0.0,
                p_fo_cbv: 0.0,
                omega_cbv: 0.0,
                q_nom: 0.0,
                dp_nom: 0.0,
            },
            cylinder: Cylinder {
                d_piston: 0.0,
                d_rod: 0.0,
                stroke: 0.0,
                v_dead_a: 0.0,
                v_dead_b: 0.0,
                k_stop: 0.0,
                c_stop: 0.0,
            },
            friction: Friction {
                model: FrictionModel::Bak,
                c_p_bak: 0.0,
                p_static: 0.0,
                v_s: 0.0,
                f_c: 0.0,
                f_s: 0.0,
                v_0: 0.0,
                c_v: 0.0,
                c_p: 0.0,
                c_tan: 0.0,
                c_l: 0.0,
            },
            fluid: Fluid { beta: 0.0, air_fraction: 0.0 },
            lines: Lines { v_l2: 0.0, v_l3: 0.0, v_l4: 0.0, c_hose: 0.0 },
            p_tr: 0.0,
        };
        for p in PARAMS {
            (p.set)(&mut c, p.spec.default);
        }
        c
    }
}

impl Circuit {
    /// Value of the parameter `name` (SI), `None` if there is no such parameter.
    pub fn param(&self, name: &str) -> Option<f64> {
        PARAMS.iter().find(|p| p.spec.name == name).map(|p| (p.get)(self))
    }

    /// Sets the parameter `name` to `value` (SI) after checking it against its range.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let p = PARAMS.iter().find(|p| p.spec.name == name).ok_or(ParamError::Unknown)?;
        let (min, max) = (p.spec.min, p.spec.max);
        if !(min..=max).contains(&value) {
            return Err(ParamError::OutOfRange { min, max });
        }
        (p.set)(self, value);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::unit;

    #[test]
    fn table_is_consistent() {
        let c = Circuit::default();
        for (i, p) in PARAMS.iter().enumerate() {
            let s = &p.spec;
            assert!(PARAMS[..i].iter().all(|q| q.spec.name != s.name), "duplicate {}", s.name);
            assert!(s.min <= s.default && s.default <= s.max, "{} default out of range", s.name);
            let u = unit(s.unit).unwrap_or_else(|| panic!("{}: unknown unit {}", s.name, s.unit));
            assert!(
                s.display_unit.is_empty() || u.display.iter().any(|d| d.name == s.display_unit),
                "{}: display unit {}",
                s.name,
                s.display_unit
            );
            assert_eq!((p.get)(&c), s.default, "{}", s.name);
        }
    }

    #[test]
    fn set_param_checks_range() {
        let mut c = Circuit::default();
        assert_eq!(c.set_param("cbv.mu_p", 5.0), Ok(()));
        assert_eq!(c.cbv.mu_p, 5.0);
        assert_eq!(c.param("cbv.mu_p"), Some(5.0));
        assert!(matches!(c.set_param("cbv.mu_p", 0.5), Err(ParamError::OutOfRange { .. })));
        assert!(matches!(c.set_param("cbv.mu_p", f64::NAN), Err(ParamError::OutOfRange { .. })));
        assert_eq!(c.set_param("cbv.nope", 1.0), Err(ParamError::Unknown));
        assert_eq!(c.set_param("friction.model", 2.0), Ok(()));
        assert_eq!(c.friction.model, FrictionModel::Fitted);
    }
}
