//! The mechanical port between [`super::HydraulicCircuit`] and [`super::BoomMechanics`] (or any
//! external mechanics): the coupling modes, their parameters and the wave variables.
//!
//! Signs: stroke `x` and velocity `v` are positive extending; a force is positive when it pushes
//! the rod out (extends the cylinder).
//!
//! - **Plain** (`port.coupling = 0`): the circuit takes `cylinder.x`, `cylinder.v` and returns
//!   `cylinder.F`; the mechanics takes `cylinder.F` and returns x, v. Exact, but the force seen by
//!   the mechanics is one communication step old: stable while omega h < 2 for every mode the
//!   oil column couples to the mechanics (omega^2 ~ k_oil / m_local).
//! - **TLM** (`port.coupling = 1`): a bilateral delay line (transmission-line element) of
//!   characteristic impedance `Z_c` and delay one communication step. The circuit integrates a
//!   local rod mass `m` with the line force `F_H = c_m + Z_c v_H` and emits
//!   `c_h = F_H + Z_c v_H`; the mechanics is pushed by `F_M = c_h - Z_c v_M` and emits
//!   `c_m = F_M - Z_c v_M`. The waves are exchanged once per step and need no iteration; the
//!   line is passive, so the exchange is stable at any step. Its price is a spring `Z_c / h` in
//!   series with the oil column and a mass `Z_c h` at the pin; `Z_c = sqrt(k_oil m_eff)` makes
//!   both relative errors equal to omega h.

use crate::fmu::{StepStart, Value, Values, Variable};
use crate::params::{ParamSpec, ParamType};

/// Value references of the port (the same in both FMUs; 80-99, after the section angles 41-72).
pub mod vr {
    pub const COUPLING: u32 = 80;
    pub const Z_C: u32 = 81;
    pub const M: u32 = 82;
    pub const START_F: u32 = 83;
    /// Wave from the mechanics to the circuit.
    pub const C_M: u32 = 84;
    /// Wave from the circuit to the mechanics.
    pub const C_H: u32 = 85;
    pub const F: u32 = 86;
    pub const ALPHA: u32 = 89;
}

/// How the circuit and the mechanics exchange the port variables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Coupling {
    /// x, v to the circuit, F to the mechanics.
    Plain,
    /// Wave variables of a transmission line with impedance `z_c` [N s/m], each emitted wave
    /// low-pass filtered with `alpha` (0: none).
    Tlm { z_c: f64, alpha: f64 },
}

/// The port settings that change a split model's equations: plain and TLM.
pub(crate) fn configurations() -> Vec<Vec<(u32, Value)>> {
    vec![vec![(vr::COUPLING, Value::Integer(0))], vec![(vr::COUPLING, Value::Integer(1))]]
}

/// Directional derivatives are provided for the plain port only: the TLM port's wave is sampled at
/// communication points.
pub(crate) fn directional_derivative_check(coupling: Coupling) -> Result<(), String> {
    match coupling {
        Coupling::Plain => Ok(()),
        Coupling::Tlm { .. } => {
            Err("directional derivatives are provided for the plain port (port.coupling = 0)".into())
        }
    }
}

/// Model Exchange runs the plain port only: the TLM port is a delay line of one communication
/// step, which Model Exchange does not have; without it the two waves form an algebraic loop
/// (c_h depends on c_m and c_m on c_h).
pub(crate) fn model_exchange_check(values: &Values) -> Result<(), String> {
    match Coupling::from_values(values) {
        Coupling::Plain => Ok(()),
        Coupling::Tlm { .. } => Err(
            "port.coupling = 1 (TLM) is a Co-Simulation coupling (a delay line of one communication step); in Model Exchange use port.coupling = 0 (plain): the importer's integrator solves both sides together".into(),
        ),
    }
}

impl Coupling {
    /// The coupling selected by `port.coupling` and `port.Z_c`.
    pub fn from_values(values: &Values) -> Self {
        match values.integer(vr::COUPLING) {
            0 => Coupling::Plain,
            _ => Coupling::Tlm { z_c: values.real(vr::Z_C), alpha: values.real(vr::ALPHA) },
        }
    }
}

/// How to couple HydraulicCircuit with BoomMechanics or mechanics of one's own: the section both
/// FMUs' pages carry (docs/coupling.md has the derivations). A macro, so that `concat!` appends
/// it to each page at compile time.
macro_rules! coupling_recipe {
    () => {
        r#"<h2>Coupling recipe</h2>
<ol><li><b>Start at rest.</b> Set HydraulicCircuit's <code>start.F</code> to the mechanics' static cylinder force at
<code>start.x</code> (BoomMechanics: its <code>start.F</code> output after initialisation), and the same
<code>start.x</code> in both.</li>
<li><b>TLM (<code>port.coupling</code> = 1, recommended)</b> for flexible or light mechanics at the pin and for Jacobi
masters: the same <code>port.Z_c</code> in both, about sqrt(k m<sub>eff</sub>) with k the oil column's stiffness at the
pin and m<sub>eff</sub> the mechanics' effective mass in its lowest coupled mode (the default suits the thesis' boom at
480 mm); connect <code>port.c_h</code> to the mechanics and <code>port.c_m</code> back, in any order;
<code>port.alpha</code> = 0.1 with a Jacobi master. Mechanics of your own apply F = c<sub>h</sub> &minus;
Z<sub>c</sub>v to the pin inside their integrator and return c<sub>m</sub> = F &minus; Z<sub>c</sub>v.</li>
<li><b>Plain (<code>port.coupling</code> = 0)</b> for heavy, rigid mechanics that take a force and return motion: step
the mechanics first, pass <code>cylinder.x</code>, <code>cylinder.v</code> (with the slope of v) to the circuit and
<code>cylinder.F</code> back; keep the communication step small against the oil column's stiffest mode (2 ms or less
for the thesis' rigid boom).</li>
<li>The end stops act in the mechanics (BoomMechanics has them; mechanics of your own keep the stroke within
[0, <code>cylinder.stroke</code>]).</li></ol>
<p>The derivations, the measured largest stable communication steps and the equivalence with HydraulicBoom:
<code>docs/coupling.md</code> in boomsim's sources.</p>"#
    };
}
pub(crate) use coupling_recipe;

/// `port.coupling`: 0 plain, 1 TLM.
pub const COUPLING: Variable = Variable::int_param(
    "port.coupling",
    vr::COUPLING,
    0,
    (0, 1),
    "Mechanical port: 0 plain (inputs cylinder.x, cylinder.v / output cylinder.F), 1 TLM (wave variables port.c_h, port.c_m with impedance port.Z_c)",
);

/// Default characteristic impedance: sqrt(k_oil m_eff) at the 480 mm start stroke with the
/// thesis parameters, k_oil = A^2/C_3 + A_B^2/C_4 = 8.3e6 N/m (C = V/beta + hose compliance,
/// eq. 5.2) and the rigid boom's m_eff = 16.9 t (test `default_impedance_matches_the_oil_column`);
/// the same within 5 % with the model's own stiffness, entrained air included, at a lowering's
/// pressures (test `default_impedance_holds_with_the_models_own_stiffness_while_lowering`).
pub const Z_C: ParamSpec = ParamSpec {
    name: "port.Z_c",
    default: 3.75e5,
    unit: "N.s/m",
    display_unit: "",
    min: 1.0,
    max: 1e9,
    description: "TLM characteristic impedance: line stiffness Z_c/h and mass Z_c h per communication step h",
    source: "sqrt(k_oil m_eff) at the start stroke (boomsim: port module); equal stiffness and mass errors omega h",
    ty: ParamType::Real,
};

/// Wave damping: the emitted wave is `c_k+1 = alpha c_k + (1 - alpha) (F + Z_c v)`.
pub const ALPHA: ParamSpec = ParamSpec {
    name: "port.alpha",
    default: 0.0,
    unit: "1",
    display_unit: "",
    min: 0.0,
    max: 0.9,
    description: "TLM wave damping (low-pass factor of each emitted wave per step); > 0 damps the numerical line mode at half the communication frequency",
    source: "signal damping of TLM wave variables (Hopsan C-type components); see docs/coupling.md",
    ty: ParamType::Real,
};

impl Coupling {
    /// The wave to emit after a step: the previous one `c` filtered toward `f_line + z_c v`
    /// (`f_line`: line force pushing the rod out on the emitting side, `v` its velocity toward
    /// the line; the mechanics passes `-v`). The line force itself when plain.
    pub fn emit(&self, c: f64, f_line: f64, v: f64) -> f64 {
        match *self {
            Coupling::Plain => f_line,
            Coupling::Tlm { z_c, alpha } => alpha * c + (1.0 - alpha) * (f_line + z_c * v),
        }
    }
}

/// `port.F`: the line force on the own side.
pub const PORT_F: Variable = Variable::real_output(
    "port.F",
    vr::F,
    "N",
    "kN",
    "TLM line force pushing the rod out: c_m + Z_c v (circuit), c_h - Z_c v (mechanics); the cylinder force when plain",
);

/// A Real input over the current step: its value at `t0` and its slope (set with
/// fmi2SetRealInputDerivatives; 0 holds it); or, in FMI 3.0 intermediate update, the values the
/// master gave for the times of the integrator's attempted step after `t0` (`samples`: its stage
/// times, [`crate::solver::stage_times`]), linear in between, so that the right-hand side sees
/// the master's values exactly where the integrator evaluates it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Ramp {
    pub t0: f64,
    pub y0: f64,
    pub slope: f64,
    pub samples: Option<[(f64, f64); 3]>,
}

impl Ramp {
    /// Input `r` and its derivative at the start of a step.
    pub fn read(step: &StepStart<'_>, r: u32) -> Self {
        let slope = step.values.position(r).map_or(0.0, |i| step.input_derivatives[i]);
        Ramp::new(step.t, step.values.real(r), slope)
    }

    /// The ramp through `y0` at `t0` with `slope`.
    pub fn new(t0: f64, y0: f64, slope: f64) -> Self {
        Ramp { t0, y0, slope, samples: None }
    }

    /// The value at `t`: the master's sample where it gave one.
    pub fn at(&self, t: f64) -> f64 {
        let Some(samples) = &self.samples else {
            return self.y0 + self.slope * (t - self.t0);
        };
        let mut before = (self.t0, self.y0);
        for &(ts, ys) in samples {
            if t == ts {
                return ys;
            }
            if t < ts || ts == samples[2].0 {
                return before.1 + (ys - before.1) * (t - before.0) / (ts - before.0);
            }
            before = (ts, ys);
        }
        before.1
    }

    /// The input from its value at `t` through the master's `samples` at the times after `t` of
    /// the integrator's next attempted step (FMI 3.0 intermediate update).
    pub fn through(&self, t: f64, samples: [(f64, f64); 3]) -> Self {
        Ramp { t0: t, y0: self.at(t), slope: 0.0, samples: Some(samples) }
    }

    /// Its integral from `t0` to `t`.
    pub fn integral(&self, t: f64) -> f64 {
        let Some(samples) = &self.samples else {
            let tau = t - self.t0;
            return tau * (self.y0 + 0.5 * self.slope * tau);
        };
        // The trapezoids of the samples up to t.
        let (mut sum, mut before) = (0.0, (self.t0, self.y0));
        for &(ts, _) in samples {
            let end = ts.min(t);
            if end > before.0 {
                let y = self.at(end);
                sum += 0.5 * (before.1 + y) * (end - before.0);
                before = (end, y);
            }
        }
        if t > before.0 {
            sum += before.1 * (t - before.0);
        }
        sum
    }
}

/// Admissible port force and wave values [N]: far beyond the 93 kN the cylinder can push.
pub const FORCE_RANGE: (f64, f64) = (-1e8, 1e8);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hydraulics::circuit::Circuit;
    use crate::mechanics::params::BoomParams;
    use crate::mechanics::rigid_boom::RigidBoom;

    /// Z_C's default against sqrt(k_oil m_eff) recomputed from the circuit and boom defaults at
    /// the 480 mm start stroke, with the oil's bulk modulus (the thesis' constant beta, eq.
    /// 2.70-2.71) in both chambers. The model's entrained air is not in it: at p3 ~ 70 bar it
    /// changes the piston side little, but at p4 ~ 0 it takes most of the rod side's stiffness
    /// (docs/models.md, "Cavitation", whose numbers a test checks). 5 %: the default is rounded.
    /// The oil column's stiffness `k = A^2 / C_3 + A_B^2 / C_4` at stroke `x` (C = V / beta +
    /// hose compliance, eq. 5.2) with bulk moduli `beta3`, `beta4` in the two chambers.
    fn oil_column_stiffness(c: &Circuit, x: f64, beta3: f64, beta4: f64) -> f64 {
        let (cyl, ln) = (&c.cylinder, &c.lines);
        let c3 = (ln.v_l3 + cyl.volume_a(x)) / beta3 + ln.hose_compliance(ln.v_l3);
        let c4 = (ln.v_l4 + cyl.volume_b(x)) / beta4 + ln.hose_compliance(ln.v_l4);
        cyl.area_a().powi(2) / c3 + cyl.area_b().powi(2) / c4
    }

    #[test]
    fn default_impedance_matches_the_oil_column() {
        let c = Circuit::default();
        let x = 0.48;
        let k = oil_column_stiffness(&c, x, c.fluid.beta, c.fluid.beta);
        let m = RigidBoom::new(&BoomParams::default(), c.cylinder.stroke).unwrap().m_eff(x);
        let z = (k * m).sqrt();
        assert!((z / Z_C.default - 1.0).abs() < 0.05, "k = {k:.3e} N/m, m_eff = {m:.0} kg, sqrt(k m) = {z:.3e}");
        assert!((k / 8.3e6 - 1.0).abs() < 0.05 && (m / 16.9e3 - 1.0).abs() < 0.05, "k = {k:.3e}, m = {m:.0}");
    }

    /// Z_C's default with the model's own stiffness, entrained air included, where the TLM port
    /// works: a lowering, whose rod side sits between the CBV's cracking and full opening (eq.
    /// 2.73 with p3 = mu_c p4 + F / A of eq. 2.85, the rigid boom's static force at 480 mm),
    /// above 30 bar, where the air softens the oil by about 1 % (docs/models.md, "Cavitation").
    /// 5 %: the default is rounded.
    #[test]
    fn default_impedance_holds_with_the_models_own_stiffness_while_lowering() {
        let c = Circuit::default();
        let (cyl, fl, cbv) = (&c.cylinder, &c.fluid, &c.cbv);
        let x = 0.48;
        let boom = RigidBoom::new(&BoomParams::default(), cyl.stroke).unwrap();
        let (load, mu_c) = (boom.static_force(x) / cyl.area_a(), cyl.area_b() / cyl.area_a());
        let p4_crack = (cbv.p_set - load) / (cbv.mu_p + mu_c);
        let p4_open = (cbv.p_set + cbv.p_fo_cbv - load) / (cbv.mu_p + mu_c);
        assert!(p4_crack > 30e5 && p4_open > p4_crack, "rod side {p4_crack:.3e}-{p4_open:.3e} Pa");
        for p4 in [p4_crack, p4_open] {
            let p3 = mu_c * p4 + load;
            let k = oil_column_stiffness(&c, x, fl.bulk_modulus(p3), fl.bulk_modulus(p4));
            let z = (k * boom.m_eff(x)).sqrt();
            assert!((z / Z_C.default - 1.0).abs() < 0.05, "p4 = {p4:.3e} Pa: sqrt(k m) = {z:.3e}");
        }
    }

    #[test]
    fn ramp_value_and_integral() {
        let r = Ramp::new(1.0, 2.0, 4.0);
        assert_eq!(r.at(1.5), 4.0);
        assert_eq!(r.integral(1.5), 0.5 * (2.0 + 4.0) / 2.0);
    }

    /// FMI 3.0 intermediate update: through the master's samples at the stage times of a step
    /// from t = 1 of 0.5 s, the input is exactly the sample at each (the right-hand side sees the
    /// master's values), continuous at the step's start, and linear in between: for samples of
    /// a quadratic y = t^2 the integral is the trapezoids' sum, within rounding (1e-15) of the
    /// exact sum of the three trapezoids computed here by hand.
    #[test]
    fn ramp_through_samples() {
        let stages = crate::solver::stage_times(1.0, 0.5, 1.5);
        let samples = stages.map(|t| (t, t * t));
        let r = Ramp::new(0.0, 1.0, 0.0).through(1.0, samples);
        assert_eq!(r.at(1.0), 1.0, "its value at the start");
        for (t, y) in samples {
            assert_eq!(r.at(t), y, "the sample at {t}");
        }
        let [(t1, y1), (t2, y2), (t3, y3)] = samples;
        let mid = 0.5 * (t1 + t2);
        assert!((r.at(mid) - 0.5 * (y1 + y2)).abs() < 1e-15, "linear between samples");
        let trapezoids = 0.5 * (1.0 + y1) * (t1 - 1.0) + 0.5 * (y1 + y2) * (t2 - t1) + 0.5 * (y2 + y3) * (t3 - t2);
        assert!((r.integral(1.5) - trapezoids).abs() < 1e-15, "{} vs {trapezoids}", r.integral(1.5));
        assert!((r.integral(t1) - 0.5 * (1.0 + y1) * (t1 - 1.0)).abs() < 1e-15);
    }
}
