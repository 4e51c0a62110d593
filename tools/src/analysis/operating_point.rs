//! Steady lowering state of the simplified circuit of Fig. 2.18 and its linearisation
//! (eq. 2.69-2.80, 2.85).
//!
//! Sign convention of section 2.3 (different from section 2.2 and the rest of boomsim):
//! positive `v_c` *retracts* the cylinder (lowers the load, eq. 2.69 has `+ m g`), `Q3` is the
//! flow *out of* the piston side through the CBV (eq. 2.70) and `Q4` the flow *into* the rod
//! side (eq. 2.71). In boomsim's convention these are `-v`, `-Q3`, `-Q4`. Every transfer
//! function below is a ratio of two of them, so the signs cancel.
//!
//! Deviation (resolved inconsistency): the `where` block under eq. 2.80 gives
//! `p3 = m g / A_c + mu_p p4`, eq. 2.85 gives `p3 = mu_c p4 + m g / A_c`. The force balance
//! eq. 2.69 at rest (`0 = p4 mu_c A_c - p3 A_c + m g`) yields eq. 2.85: `mu_p` does not act on
//! the piston (it is the CBV's pilot area ratio). We use eq. 2.85.

use boomsim::hydraulics::solve::bisect;
use boomsim::hydraulics::Circuit;
use boomsim::mechanics::params::BoomParams;
use boomsim::mechanics::rigid_boom::RigidBoom;
use boomsim::units::{bar, mm};

/// Stroke of the Table 6.1 operating point (m).
pub const TABLE_6_1_XC: f64 = 0.250;
/// Steady rod-side pressure of the Table 6.1 operating point (Pa).
pub const TABLE_6_1_P4: f64 = 45e5;
/// `omega_n` of Table 6.1 (rad/s), used to identify the equivalent mass.
pub const TABLE_6_1_OMEGA_N: f64 = 83.82;
/// `K_f = C1 mu_c mu_p` of Table 6.1 (m^3/Pa), used to identify the pilot ratio.
pub const TABLE_6_1_K_F: f64 = 1.3593e-12;
/// Pilot ratios of the available CBVs with their default set pressures (Table 4.3).
pub const CBV_TABLE_4_3: [(f64, f64); 4] = [(1.0, 210e5), (2.0, 140e5), (3.0, 210e5), (5.0, 140e5)];

/// Default set pressure of the Table 4.3 valve with pilot ratio `mu_p` (the nearest listed).
pub fn p_set_for(mu_p: f64) -> f64 {
    CBV_TABLE_4_3.iter().min_by(|a, b| (a.0 - mu_p).abs().total_cmp(&(b.0 - mu_p).abs())).expect("non-empty").1
}

/// An operating point of the simplified system (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OperatingPoint {
    /// Stroke `x_c` (m), 0 fully retracted.
    pub x_c: f64,
    /// Steady rod-side (pilot) pressure `p4^(ss)` (Pa).
    pub p4: f64,
    /// CBV pilot area ratio `mu_p` (-).
    pub mu_p: f64,
    /// CBV set pressure `p_set` (Pa).
    pub p_set: f64,
    /// Equivalent mass at the cylinder `m` (kg), eq. 2.69.
    pub mass: f64,
    /// Load force on the rod (N); eq. 2.69 has `m g`. A separate value lets the rigid boom's
    /// static force and its effective mass differ (the nonlinear cross-check).
    pub load: f64,
    /// Bulk modulus `beta` of the piston side, in `C1` (Pa).
    pub beta1: f64,
    /// Bulk modulus `beta` of the rod side, in `C2` (Pa). Section 2.3 has one constant `beta`;
    /// two let the oil-air law's effective bulk modulus at each side's steady pressure in
    /// (`boomsim criterion`).
    pub beta2: f64,
    /// Capacitance added to `C1 = V3 / beta` (m^3/Pa): line 3, dead volume, hoses.
    pub c1_extra: f64,
    /// Capacitance added to `C2 = V4 / beta` (m^3/Pa): line 4, dead volume, hoses.
    pub c2_extra: f64,
    /// Piston area `A_c` (m^2).
    pub area: f64,
    /// Annulus / piston area ratio `mu_c` (-).
    pub mu_c: f64,
    /// Stroke length `s_c` (m).
    pub stroke: f64,
    /// CBV flow coefficient `K2` (m^3/(s sqrt(Pa))), section 2.2.2.
    pub k2: f64,
    /// Pressure rise to fully open the load-holding valve `p_fo,cbv` (Pa).
    pub p_fo: f64,
    /// Steady pressure downstream of the CBV, in line 2 (Pa). Section 2.3 takes the CBV's
    /// pressure drop as `p3` (line 2 at tank pressure, 0); a positive `p2` (the back pressure of
    /// the valve's A->T edge) makes it `p3 - p2` in eq. 2.72, 2.79, 2.80 and 2.84.
    pub p2: f64,
}

/// The pilot ratio and equivalent mass behind Table 6.1, identified from its `K_f` and
/// `omega_n` (see [`identify_table_6_1`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Table61Identification {
    /// `K_f / (C1 mu_c)` before rounding to an available valve.
    pub mu_p_exact: f64,
    /// The nearest pilot ratio of Table 4.3.
    pub mu_p: f64,
    /// `m = A_c^2 / (C1 omega_n^2)` (kg).
    pub mass: f64,
}

/// Identifies what Table 6.1 does not state. With `C1 = A_c x_c / beta` (x_c = 250 mm,
/// beta = 1300 MPa from the parameter list), eq. 6.3 `K_f = C1 mu_c mu_p` gives `mu_p` and
/// `omega_n = A_c / sqrt(C1 m)` (eq. 2.81) gives `m`. Uses boomsim's cylinder and fluid.
pub fn identify_table_6_1() -> Table61Identification {
    let c = Circuit::default();
    let area = c.cylinder.area_a();
    let c1 = area * TABLE_6_1_XC / c.fluid.beta;
    let mu_p_exact = TABLE_6_1_K_F / (c1 * c.cylinder.mu_c());
    let mu_p = CBV_TABLE_4_3
        .iter()
        .map(|v| v.0)
        .min_by(|a, b| (a - mu_p_exact).abs().total_cmp(&(b - mu_p_exact).abs()))
        .expect("non-empty");
    Table61Identification { mu_p_exact, mu_p, mass: area * area / (c1 * TABLE_6_1_OMEGA_N.powi(2)) }
}

impl OperatingPoint {
    /// The point of section 2.3 for boomsim's circuit `c` driving the rigid boom `boom` at stroke
    /// `x_c` with the rod side at `p4`: the boom's effective mass at the cylinder (eq. 2.68) and
    /// static load (eq. 2.19), the line and dead volumes and hose compliance (eq. 5.2) as extra
    /// capacitance, the CBV's and cylinder's parameters.
    pub fn of_circuit(c: &Circuit, boom: &RigidBoom, x_c: f64, p4: f64) -> Self {
        let beta = c.fluid.beta;
        let op = Self::of_volumes(c, x_c, boom.m_eff(x_c), boom.static_force(x_c), [beta, beta], true);
        OperatingPoint { p4, ..op }
    }

    /// The point of section 2.3 for boomsim's circuit `c` at stroke `x_c` with the mass `mass`
    /// and load `load` at the cylinder, the rod side at tank pressure (0; see
    /// [`OperatingPoint::with_flow`]): the line and dead volumes as extra capacitance at the bulk
    /// moduli `[beta1, beta2]` of the piston and rod side, plus the hose compliance (eq. 5.2) if
    /// `hoses`, the CBV's and cylinder's parameters.
    pub fn of_volumes(c: &Circuit, x_c: f64, mass: f64, load: f64, [beta1, beta2]: [f64; 2], hoses: bool) -> Self {
        let (cyl, ln) = (&c.cylinder, &c.lines);
        let hose = |v: f64| if hoses { ln.hose_compliance(v) } else { 0.0 };
        OperatingPoint {
            x_c,
            p4: 0.0,
            mu_p: c.cbv.mu_p,
            p_set: c.cbv.p_set,
            mass,
            load,
            beta1,
            beta2,
            c1_extra: (cyl.v_dead_a + ln.v_l3) / beta1 + hose(ln.v_l3),
            c2_extra: (cyl.v_dead_b + ln.v_l4) / beta2 + hose(ln.v_l4),
            area: cyl.area_a(),
            mu_c: cyl.mu_c(),
            stroke: cyl.stroke,
            k2: c.cbv.k2(),
            p_fo: c.cbv.p_fo_cbv,
            p2: 0.0,
        }
    }
}

impl Default for OperatingPoint {
    /// The operating point of Table 6.1: x_c = 250 mm, p4 = 45 bar, the identified pilot ratio
    /// (3, CWCA LHN, p_set 210 bar) and mass, load `m g`, no extra capacitance (section 2.3
    /// neglects line and dead volumes).
    fn default() -> Self {
        let c = Circuit::default();
        let id = identify_table_6_1();
        OperatingPoint {
            x_c: TABLE_6_1_XC,
            p4: TABLE_6_1_P4,
            mu_p: id.mu_p,
            p_set: p_set_for(id.mu_p),
            mass: id.mass,
            load: id.mass * BoomParams::default().g,
            beta1: c.fluid.beta,
            beta2: c.fluid.beta,
            c1_extra: 0.0,
            c2_extra: 0.0,
            area: c.cylinder.area_a(),
            mu_c: c.cylinder.mu_c(),
            stroke: c.cylinder.stroke,
            k2: c.cbv.k2(),
            p_fo: c.cbv.p_fo_cbv,
            p2: 0.0,
        }
    }
}

/// The linearised coefficients at an operating point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linearised {
    /// `C1 = A_c x_c / beta1 + extra` (m^3/Pa), piston side (eq. 2.70).
    pub c1: f64,
    /// `C2 = mu_c A_c (s_c - x_c) / beta2 + extra` (m^3/Pa), rod side (eq. 2.71).
    pub c2: f64,
    /// `p3^(ss) = mu_c p4 + F / A_c` (Pa), eq. 2.85.
    pub p3: f64,
    /// `u_cbv^(ss) = (mu_p p4 + p3 - p_set) / p_fo,cbv` (-), eq. 2.73.
    pub u_cbv: f64,
    /// `K_qu = K2 sqrt(p3 - p2)` (m^3/s), eq. 2.79.
    pub k_qu: f64,
    /// `K_qp = K2 u_cbv / (2 sqrt(p3 - p2))` (m^3/(s Pa)), eq. 2.80.
    pub k_qp: f64,
}

/// Why an operating point has no steady lowering state.
#[derive(Debug, Clone, PartialEq)]
pub enum SteadyStateError {
    /// `mu_p p4 + p3 <= p_set`: the load-holding valve is closed, nothing flows.
    CbvClosed { u_cbv: f64 },
    /// `u_cbv > 1`: the valve would have to open beyond fully open.
    CbvSaturated { u_cbv: f64 },
    /// Stroke outside `[0, s_c]` or non-positive capacitance, mass or pressure (which, with
    /// its value and the valid range).
    Invalid(String),
}

impl std::fmt::Display for SteadyStateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::CbvClosed { u_cbv } => write!(f, "the CBV is closed at this operating point (u_cbv = {u_cbv:.4})"),
            Self::CbvSaturated { u_cbv } => write!(f, "the CBV would open beyond fully open (u_cbv = {u_cbv:.4})"),
            Self::Invalid(why) => write!(f, "invalid operating point: {why}"),
        }
    }
}

impl std::error::Error for SteadyStateError {}

impl OperatingPoint {
    /// `C1` at stroke `x` (m^3/Pa).
    pub fn c1_at(&self, x: f64) -> f64 {
        self.area * x / self.beta1 + self.c1_extra
    }

    /// `C2` at stroke `x` (m^3/Pa).
    pub fn c2_at(&self, x: f64) -> f64 {
        self.mu_c * self.area * (self.stroke - x) / self.beta2 + self.c2_extra
    }

    /// Steady state and linearised coefficients (eq. 2.73, 2.79, 2.80, 2.85).
    pub fn linearise(&self) -> Result<Linearised, SteadyStateError> {
        let invalid = |s: String| Err(SteadyStateError::Invalid(s));
        if !(0.0..=self.stroke).contains(&self.x_c) {
            return invalid(format!("x_c = {} mm is outside the stroke [0, {}] mm", self.x_c * 1e3, self.stroke * 1e3));
        }
        for (name, x, unit, scale) in [("mass", self.mass, "kg", 1.0), ("beta1", self.beta1, "MPa", 1e-6), ("beta2", self.beta2, "MPa", 1e-6)] {
            if !(x > 0.0) {
                return invalid(format!("{name} = {} {unit} must be > 0", x * scale));
            }
        }
        for (name, x, unit, scale) in
            [("p4", self.p4, "bar", 1e-5), ("c1_extra", self.c1_extra, "cm^3/bar", 1e11), ("c2_extra", self.c2_extra, "cm^3/bar", 1e11)]
        {
            if !(x >= 0.0) {
                return invalid(format!("{name} = {} {unit} must be >= 0", x * scale));
            }
        }
        let (c1, c2) = (self.c1_at(self.x_c), self.c2_at(self.x_c));
        if !(c1 > 0.0 && c2 > 0.0) {
            return invalid(format!("C1 = {c1:e} and C2 = {c2:e} m^3/Pa must be > 0 (add capacitance at the stroke ends)"));
        }
        let p3 = self.mu_c * self.p4 + self.load / self.area;
        let u_cbv = (self.mu_p * self.p4 + p3 - self.p_set) / self.p_fo;
        if u_cbv <= 0.0 {
            return Err(SteadyStateError::CbvClosed { u_cbv });
        }
        if u_cbv > 1.0 {
            return Err(SteadyStateError::CbvSaturated { u_cbv });
        }
        let dp = p3 - self.p2;
        if !(dp > 0.0) {
            return invalid(format!("p3 = {} bar must exceed p2 = {} bar (the CBV's pressure drop)", p3 * 1e-5, self.p2 * 1e-5));
        }
        let k_qu = self.k2 * dp.sqrt();
        let k_qp = self.k2 * u_cbv / (2.0 * dp.sqrt());
        Ok(Linearised { c1, c2, p3, u_cbv, k_qu, k_qp })
    }

    /// Steady CBV flow `Q3 = K2 u_cbv sqrt(p3 - p2)` (m^3/s), eq. 2.72; the rod-side inflow is
    /// `mu_c Q3` (eq. 2.70, 2.71 at rest).
    pub fn flow(&self) -> Result<f64, SteadyStateError> {
        self.linearise().map(|l| self.k2 * l.u_cbv * (l.p3 - self.p2).sqrt())
    }

    /// The operating point with the rod-side pressure that carries the steady CBV flow `q3`
    /// (m^3/s) with this point's load, valve and stroke (bisection on the monotonic
    /// `Q3(p4)`); `None` if even `u_cbv = 1` cannot pass it.
    pub fn with_flow(&self, q3: f64) -> Option<OperatingPoint> {
        let q = |p4: f64| OperatingPoint { p4, ..*self }.flow();
        // p4 where the valve is fully open: (mu_p + mu_c) p4 = p_set + p_fo - F / A
        let p4_open = (self.p_set + self.p_fo - self.load / self.area) / (self.mu_p + self.mu_c);
        let p4_crack = ((self.p_set - self.load / self.area) / (self.mu_p + self.mu_c)).max(0.0);
        let hi = p4_open * (1.0 - 1e-12);
        if hi <= p4_crack || q(hi).map_or(true, |q_max| q_max < q3) {
            return None;
        }
        let p4 = bisect(|p4| q(p4).map_or(-q3, |q| q - q3), p4_crack, hi, 1e-13 * p4_open);
        Some(OperatingPoint { p4, ..*self })
    }
}

/// Readable summary of the operating point in engineering units.
pub fn describe(op: &OperatingPoint) -> String {
    format!(
        "x_c = {:.1} mm, p4 = {:.2} bar, mu_p = {}, p_set = {:.0} bar, m = {:.1} kg",
        op.x_c / mm(1.0),
        op.p4 / bar(1.0),
        op.mu_p,
        op.p_set / bar(1.0),
        op.mass
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use boomsim::mechanics::rigid_boom::RigidBoom;

    /// Table 6.1: K_f = 1.3593e-12 with beta = 1300 MPa, x_c = 250 mm gives mu_p = 3.000 to
    /// the 5 digits of K_f (the other valves, 1, 2, 5, are far off); omega_n = 83.82 rad/s
    /// gives m = 2456 kg. Independent check of the mass: the rigid boom's static cylinder
    /// force at 250 mm (geometry and masses of chapter 2, not Table 6.1) divided by g agrees
    /// to 1 % (the boom's retracted length was chosen for that, mechanics::params).
    #[test]
    fn table_6_1_identification() {
        let id = identify_table_6_1();
        assert_eq!(id.mu_p, 3.0);
        assert!((id.mu_p_exact - 3.0).abs() < 3.0 * 1e-4, "{id:?}");
        assert!((id.mass - 2456.0).abs() < 1.0, "{id:?}");
        let boom = RigidBoom::new(&BoomParams::default(), Circuit::default().cylinder.stroke).unwrap();
        assert!((boom.static_force(TABLE_6_1_XC) / BoomParams::default().g / id.mass - 1.0).abs() < 0.01);
    }

    /// The steady state obeys eq. 2.69 (force balance) and 2.70/2.71 at rest; `with_flow`
    /// inverts `flow` (bisection to 1e-9 relative).
    #[test]
    fn steady_state_balances() {
        let op = OperatingPoint::default();
        let l = op.linearise().unwrap();
        assert!((op.p4 * op.mu_c * op.area - l.p3 * op.area + op.load).abs() < 1e-9 * op.load);
        assert!(l.u_cbv > 0.0 && l.u_cbv < 1.0);
        let q = op.flow().unwrap();
        let back = OperatingPoint { p4: 0.0, ..op }.with_flow(q).unwrap();
        assert!((back.p4 / op.p4 - 1.0).abs() < 1e-9);
        let closed = OperatingPoint { p4: 0.0, ..op };
        assert!(matches!(closed.linearise(), Err(SteadyStateError::CbvClosed { .. })));
        assert_eq!(p_set_for(2.0), 140e5);
    }
}
