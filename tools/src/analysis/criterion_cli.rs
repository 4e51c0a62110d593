//! `boomsim criterion`: the instability criterion of section 2.3 with the HydraulicBoom's own
//! parameters, at three levels of detail, for lowering without pressure feedback (the analytic
//! half of python/boomsim/instability.py, whose other half simulates the FMU).
//!
//! The steady lowering at spool opening `u < 0` has the ideal compensated flow `|u| Q_rated` into
//! the rod side, so `Q3 = |u| Q_rated / mu_c` leaves the piston side through the CBV and line 2
//! through the A->T edge (eq. 2.42), whose back pressure `p2` the CBV's pressure drop `p3 - p2`
//! has (the thesis neglects it); the CBV opening follows the pilot (eq. 2.73) and the load is
//! held by eq. 2.85 (friction neglected): [`OperatingPoint::with_flow`]. The load is the holding
//! force of the HydraulicBoom at rest at the stroke (the FMU's start equilibrium). The critical
//! stroke `x_c` (stable below it):
//! - eq. 2.87: `s_c / (1 + mu_p)` (no line or dead volumes, `u_cbv p_fo << p3`);
//! - eq. 2.86 with the line and dead volumes (rigid lines, constant bulk modulus):
//!   `C2(x) / C1(x) = mu_c mu_p`, `C1 = (V_L3 + V_CH1 + A x) / beta`,
//!   `C2 = (V_L4 + V_CH2 + mu_c A (s_c - x)) / beta`;
//! - eq. 2.84 with the effective bulk modulus of the oil-air law at the steady p3 and p4
//!   ([`Fluid::bulk_modulus`]) and the factor `2 dp / (2 dp + u_cbv p_fo)`, `dp = p3 - p2`, with
//!   rigid lines, and with the hose compliance `C_w = c_hose V_L` (eq. 5.2) added to C1 and C2.
//!
//! The linear frequencies at the stroke (full capacitances): `omega_n = A / sqrt(C1 m)` of
//! eq. 2.81 (the piston side only) and with both chambers as springs,
//! `sqrt((A^2 / C1 + (mu_c A)^2 / C2) / m)`, for the thesis' `m = F / g` (eq. 2.69, the load
//! seen at the cylinder) and for the rigid boom's effective mass `m_eff` (eq. 2.68).

use super::criterion::{
    critical_stroke, describe_critical_stroke, required_ratio, required_ratio_simplified, xc_crit_simplified,
};
use super::modes::{parameter_change, plant_values};
use super::operating_point::{Linearised, OperatingPoint};
use super::plant::HParams;
use boomsim::fmu::{Model, Value};
use boomsim::hydraulics::solve::bisect;
use boomsim::hydraulics::Circuit;
use boomsim::models::hydraulic_boom::{Boom, Plant};
use boomsim::models::HydraulicBoom;
use boomsim::units::{BAR, MM};
use serde_json::{json, Value as Json};
use std::f64::consts::TAU;

/// `boomsim criterion`: the critical stroke of section 2.3 for the HydraulicBoom's parameters.
#[derive(clap::Args, Debug, Clone)]
pub struct CriterionArgs {
    /// Spool references of the steady lowering (< 0), comma separated.
    #[arg(long, value_delimiter = ',', default_values_t = [-0.05, -0.1])]
    pub u_ref: Vec<f64>,
    /// Stroke [mm] of the load (the boom at rest there), the capacitances and the frequencies.
    #[arg(long, default_value_t = 250.0)]
    pub stroke: f64,
    /// A parameter of the HydraulicBoom, NAME=VALUE (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub set: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The criterion at one steady lowering.
#[derive(Debug, Clone)]
pub struct Lowering {
    pub u_ref: f64,
    /// Line 2's back pressure (Pa).
    pub p2: f64,
    /// The steady state, at the stroke with the full capacitances (oil-air law, hoses).
    pub lin: Linearised,
    /// The rod-side pressure (Pa).
    pub p4: f64,
    /// `2 dp / (2 dp + u_cbv p_fo)`, eq. 2.84's required ratio over eq. 2.86's.
    pub factor: f64,
    /// x_c (m) of eq. 2.87, eq. 2.86 with volumes, eq. 2.84 with rigid lines, eq. 2.84 with hoses.
    pub x_287: f64,
    pub x_286: f64,
    pub x_284_rigid: f64,
    pub x_284: f64,
    /// Frequencies (Hz): eq. 2.81 and both chambers with `m = F / g`, then with `m_eff`.
    pub frequencies: [f64; 4],
}

/// The criterion at every lowering of the arguments.
#[derive(Debug, Clone)]
pub struct Study {
    /// The stroke (m) and the HydraulicBoom's holding force there (N).
    pub stroke: f64,
    pub load: f64,
    /// `F / g` and the rigid boom's effective mass at the stroke (kg).
    pub m_g: f64,
    pub m_eff: f64,
    pub circuit: Circuit,
    pub lowerings: Vec<Lowering>,
}

/// The natural frequency (rad/s) of the mass `op.mass` on both chambers as springs,
/// `sqrt((A^2 / C1 + (mu_c A)^2 / C2) / m)`; eq. 2.81's `omega_n` has the piston side only.
pub fn two_chamber_omega(op: &OperatingPoint, lin: &Linearised) -> f64 {
    let (a, b) = (op.area, op.mu_c * op.area);
    ((a * a / lin.c1 + b * b / lin.c2) / op.mass).sqrt()
}

/// The study with the HydraulicBoom's parameters changed by `changes` at `stroke` (m).
pub fn study(changes: &[(&str, Value)], stroke: f64, u_refs: &[f64]) -> Result<Study, String> {
    let values = plant_values(changes.iter().cloned())?;
    let plant = Plant::from_values(&values)?;
    let s_c = plant.circuit.cylinder.stroke;
    if !(0.0..=s_c).contains(&stroke) {
        return Err(format!("--stroke {} mm is outside the cylinder's stroke [0, {}] mm", stroke / MM, s_c / MM));
    }
    let rest = plant.boom.mechanics().equilibrium(stroke).map_err(|e| format!("no rest at {stroke} m: {e}"))?;
    let rigid =
        Plant::from_values(&plant_values(changes.iter().cloned().chain([("boom.flexible", Value::Boolean(false))]))?)?;
    let Boom::Rigid(boom) = &rigid.boom else { unreachable!("built rigid") };
    let g = HydraulicBoom::VARIABLES.iter().find(|v| v.name == "env.g").map(|v| values.real(v.vr)).expect("env.g");
    let (c, load) = (plant.circuit, rest.f_cyl);
    let (m_g, m_eff) = (load / g, boom.m_eff(stroke));
    let lowerings = u_refs.iter().map(|&u| lowering(&c, stroke, load, [m_g, m_eff], u)).collect::<Result<_, _>>()?;
    Ok(Study { stroke, load, m_g, m_eff, circuit: c, lowerings })
}

/// The criterion at the steady lowering with spool opening `u` of the circuit `c` at `stroke`
/// carrying `load`; the frequencies for the `masses` `[F / g, m_eff]`.
fn lowering(c: &Circuit, stroke: f64, load: f64, masses: [f64; 2], u: f64) -> Result<Lowering, String> {
    if !(-1.0..0.0).contains(&u) {
        return Err(format!("--u-ref {u} is outside [-1, 0) (a lowering)"));
    }
    let (beta, p_t, p_tr) = (c.fluid.beta, c.supply.p_t, c.p_tr);
    // the ideal compensated flow |u| Q_rated into the rod side, Q3 = Q4 / mu_c out of the piston side
    let q3 = u.abs() * c.dcv.q_rated / c.cylinder.mu_c();
    // line 2's pressure that passes Q3 through the A->T edge (eq. 2.42: Q2 = -Q3)
    let q2 = |p2: f64| c.dcv.flows(u, 0.0, p2, 0.0, p_t, p_tr)[0] + q3;
    if q2(c.cbv.p_set) > 0.0 {
        return Err(format!("u = {u}: the A->T edge cannot pass {q3} m^3/s below the CBV's set pressure"));
    }
    let p2 = bisect(q2, p_t, c.cbv.p_set, 1e-13 * c.cbv.p_set);
    let point =
        |betas, hoses| OperatingPoint { p2, ..OperatingPoint::of_volumes(c, stroke, masses[0], load, betas, hoses) };
    let steady = point([beta; 2], false).with_flow(q3).ok_or_else(|| {
        format!("u = {u}: the CBV cannot pass the lowering flow {q3} m^3/s at this load, even fully open")
    })?;
    let p4 = steady.p4;
    let p3 = steady.linearise().map_err(|e| format!("u = {u}: {e}"))?.p3;
    let at = |betas, hoses| -> Result<(OperatingPoint, Linearised), String> {
        let op = OperatingPoint { p4, ..point(betas, hoses) };
        Ok((op, op.linearise().map_err(|e| format!("u = {u}: {e}"))?))
    };
    let oil_air = [c.fluid.bulk_modulus(p3), c.fluid.bulk_modulus(p4)];
    let (rigid, lin) = at(oil_air, false)?;
    let r = required_ratio(&rigid, &lin);
    let (full, lin) = at(oil_air, true)?;
    let constant = point([beta; 2], false);
    let omegas = masses.map(|mass| {
        let op = OperatingPoint { mass, ..full };
        [HParams::new(&op, &lin).omega_n, two_chamber_omega(&op, &lin)]
    });
    Ok(Lowering {
        u_ref: u,
        p2,
        lin,
        p4,
        factor: r / required_ratio_simplified(&full),
        x_287: xc_crit_simplified(&full),
        x_286: critical_stroke(&constant, required_ratio_simplified(&constant)),
        x_284_rigid: critical_stroke(&rigid, r),
        x_284: critical_stroke(&full, r),
        frequencies: [omegas[0][0], omegas[0][1], omegas[1][0], omegas[1][1]].map(|w| w / TAU),
    })
}

impl Study {
    pub fn to_json(&self, set: &[String]) -> Json {
        let cyl = &self.circuit.cylinder;
        let lowerings: Vec<Json> = self
            .lowerings
            .iter()
            .map(|l| {
                let f = l.frequencies;
                json!({
                    "u_ref": l.u_ref, "p2_bar": l.p2 / BAR, "p3_bar": l.lin.p3 / BAR, "p4_bar": l.p4 / BAR,
                    "u_cbv": l.lin.u_cbv, "factor": l.factor, "C1": l.lin.c1, "C2": l.lin.c2,
                    "x_c_mm": {"2.87": l.x_287 / MM, "2.86": l.x_286 / MM, "2.84_rigid": l.x_284_rigid / MM,
                               "2.84": l.x_284 / MM},
                    "frequency_hz": {"omega_n_m_g": f[0], "both_m_g": f[1], "omega_n_m_eff": f[2], "both_m_eff": f[3]},
                })
            })
            .collect();
        json!({
            "set": set, "stroke_mm": self.stroke / MM, "A_mm2": cyl.area_a() / (MM * MM),
            "mu_c_A_mm2": cyl.area_b() / (MM * MM), "mu_c": cyl.mu_c(), "mu_p": self.circuit.cbv.mu_p,
            "s_c_mm": cyl.stroke / MM, "load_N": self.load, "m_g_kg": self.m_g, "m_eff_kg": self.m_eff,
            "lowerings": lowerings,
        })
    }

    /// The table: the circuit, then per lowering its steady state, the critical strokes and the
    /// frequencies.
    pub fn text(&self) -> String {
        let cyl = &self.circuit.cylinder;
        let x = |x: f64| describe_critical_stroke(cyl.stroke, x);
        let mut s = format!(
            "A = {:.1} mm^2, mu_c A = {:.1} mm^2, mu_c = {:.4}, mu_p = {}, s_c = {:.0} mm\n\n\
             Stability criterion of section 2.3 (stable for x <= x_c)\n",
            cyl.area_a() / (MM * MM),
            cyl.area_b() / (MM * MM),
            cyl.mu_c(),
            self.circuit.cbv.mu_p,
            cyl.stroke / MM
        );
        for l in &self.lowerings {
            let f = l.frequencies;
            s += &format!(
                "  u = {:+.2}: steady lowering p2 = {:.1}, p3 = {:.1}, p4 = {:.1} bar, u_cbv = {:.4}, factor of 2.84 = {:.4}\n\
                 \x20   x_c eq. 2.87 (no volumes)          : {}\n\
                 \x20   x_c eq. 2.86 + line/dead volumes   : {}\n\
                 \x20   x_c eq. 2.84, oil-air beta, rigid  : {}\n\
                 \x20   x_c eq. 2.84 + hose compliance 5.2 : {}\n\
                 \x20   linear frequency at {:.0} mm, m = F/g = {:.0} kg: omega_n (2.81) {:.2} Hz, both chambers \
                 {:.2} Hz; m_eff = {:.0} kg: {:.2} Hz, {:.2} Hz\n",
                l.u_ref,
                l.p2 / BAR,
                l.lin.p3 / BAR,
                l.p4 / BAR,
                l.lin.u_cbv,
                l.factor,
                x(l.x_287),
                x(l.x_286),
                x(l.x_284_rigid),
                x(l.x_284),
                self.stroke / MM,
                self.m_g,
                f[0],
                f[1],
                self.m_eff,
                f[2],
                f[3]
            );
        }
        s
    }
}

/// Runs `boomsim criterion`.
pub fn run(args: &CriterionArgs) -> Result<(), String> {
    let changes = args
        .set
        .iter()
        .map(|arg| parameter_change(arg).map(|(v, value)| (v.name, value)))
        .collect::<Result<Vec<_>, String>>()?;
    let s = study(&changes, args.stroke * MM, &args.u_ref)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&s.to_json(&args.set)).map_err(|e| e.to_string())?);
    } else {
        print!("{}", s.text());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn changes(set: &[&str]) -> Vec<(&'static str, Value)> {
        set.iter().map(|arg| parameter_change(arg).map(|(v, value)| (v.name, value)).unwrap()).collect()
    }

    /// Eq. 2.87's closed form `x_c = s_c / (1 + mu_p)`: 125 mm for the default valve (mu_p = 3,
    /// s_c = 500 mm) and 500 / 6 mm for mu_p = 5 (float rounding, 1e-12). Eq. 2.86 tends to it as
    /// the line and dead volumes vanish: with the smallest the parameter ranges allow (0.11 cm^3 a
    /// side) its root moves by `V (1 - mu_c mu_p) / ((mu_c mu_p + mu_c) A)`, 1.1e-4 (mu_p = 3) and
    /// 2.4e-4 (mu_p = 5) relative, so 3e-4. With the default volumes eq. 2.86's root is where
    /// `C2 / C1 = mu_c mu_p` with the chambers' and lines' volumes (runtime's cylinder, 1e-12).
    #[test]
    fn critical_strokes_against_eq_2_86_and_2_87() {
        for mu_p in [3.0, 5.0] {
            let mu = format!("cbv.mu_p={mu_p}");
            let small = ["line.v_l3=1e-8", "line.v_l4=1e-8", "cylinder.v_dead_a=1e-7", "cylinder.v_dead_b=1e-7", &mu];
            let l = &study(&changes(&small), 0.25, &[-0.05]).unwrap().lowerings[0];
            assert!((l.x_287 / (0.5 / (1.0 + mu_p)) - 1.0).abs() < 1e-12, "{}", l.x_287);
            assert!((l.x_286 / l.x_287 - 1.0).abs() < 3e-4, "{} vs {}", l.x_286, l.x_287);
        }
        let s = study(&[], 0.25, &[-0.05]).unwrap();
        let (c, x) = (&s.circuit, s.lowerings[0].x_286);
        let (cyl, ln) = (&c.cylinder, &c.lines);
        let ratio = (cyl.volume_b(x) + ln.v_l4) / (cyl.volume_a(x) + ln.v_l3);
        assert!((ratio / (cyl.mu_c() * c.cbv.mu_p) - 1.0).abs() < 1e-12, "{ratio}");
        assert!(x > 0.1 && x < 0.125, "{x}");
    }

    /// The steady lowering obeys the laws it was solved from, checked in their closed forms: the
    /// A->T edge passes Q3 = |u| Q_rated / mu_c at p2 = (Q3 / (K1 |u|))^2 (eq. 2.42 inverted), the
    /// CBV passes it, K2 u_cbv sqrt(p3 - p2) (eq. 2.72) with u_cbv of eq. 2.73, and the load is
    /// held, p3 A - p4 mu_c A = F (eq. 2.85); 1e-9: the bisections' tolerances. The criteria order
    /// as the model's details add compliance: the hoses soften both sides and lower x_c.
    #[test]
    fn steady_lowering_obeys_its_laws() {
        let s = study(&[], 0.25, &[-0.05, -0.1]).unwrap();
        let c = &s.circuit;
        let (a, b) = (c.cylinder.area_a(), c.cylinder.area_b());
        for l in &s.lowerings {
            let q3 = l.u_ref.abs() * c.dcv.q_rated * a / b;
            let p2 = (q3 / (c.dcv.k1() * l.u_ref.abs())).powi(2);
            assert!((l.p2 / p2 - 1.0).abs() < 1e-9, "{} vs {p2}", l.p2);
            let u_cbv = (c.cbv.mu_p * l.p4 + l.lin.p3 - c.cbv.p_set) / c.cbv.p_fo_cbv;
            assert!((l.lin.u_cbv / u_cbv - 1.0).abs() < 1e-12);
            assert!((c.cbv.k2() * u_cbv * (l.lin.p3 - l.p2).sqrt() / q3 - 1.0).abs() < 1e-9);
            assert!(((l.lin.p3 * a - l.p4 * b) / s.load - 1.0).abs() < 1e-9);
            assert!(l.x_284 < l.x_284_rigid && l.x_284 > 0.0 && l.x_286 < l.x_287);
            assert!(l.frequencies[1] > l.frequencies[0] && l.frequencies[2] < l.frequencies[0]);
        }
    }
}
