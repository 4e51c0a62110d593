//! Counterbalance valve (Sun Hydraulics CWC* cartridge, vented), section 2.2.2: a spring
//! loaded check valve (free flow line 2 -> line 3, eq. 2.55) in parallel with a pilot-assisted
//! load-holding relief valve (line 3 -> line 2, eq. 2.56) with first-order dynamics (2.57);
//! flows eq. 2.58-2.59. `Q3` is positive from line 2 to line 3.

use super::orifice;
use crate::scalar::{clamp, Scalar};

/// CBV parameters (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cbv {
    /// Check valve spring (cracking) pressure `p_cv` (Pa), 2.8 bar (2.2.2).
    pub p_cv: f64,
    /// Pressure rise to fully open the check valve `p_fo,cv` (Pa), 1 bar (assumed, 2.2.2).
    pub p_fo_cv: f64,
    /// Load-holding valve set pressure `p_set` (Pa). Table 4.3 defaults: 210 bar (1:1, 1:3),
    /// 140 bar (1:2, 1:5); our default 210 bar belongs to the 1:3 valve (CWCA LHN).
    pub p_set: f64,
    /// Pilot area ratio `mu_p` (-), one of 1, 2, 3, 5 (Table 4.3). Default 3: the value behind
    /// `K_f = C1 mu_c mu_p = 1.3593e-12` of Table 6.1 (C1 = A * 250 mm / beta, mu_c = 0.710).
    pub mu_p: f64,
    /// Pressure rise to fully open the load-holding valve `p_fo,cbv` (Pa), 350 bar (2.2.2,
    /// Fig. 2.15; called `p_fc,cbv` "fully closed" in the parameter list).
    pub p_fo_cbv: f64,
    /// Eigenfrequency of the load-holding valve `omega_cbv` (rad/s), 63 rad/s (3.3).
    pub omega_cbv: f64,
    /// Flow through the fully open valve at `dp_nom`: 60 l/min (2.2.2).
    pub q_nom: f64,
    /// Pressure drop at `q_nom`: 16 bar (2.2.2, Fig. 2.16).
    pub dp_nom: f64,
}

impl Cbv {
    /// Flow coefficient `K2 = 60 l/min / sqrt(16 bar)` = 7.91e-7 m^3/(s sqrt(Pa)) (2.2.2).
    pub fn k2(&self) -> f64 {
        orifice::flow_coefficient(self.q_nom, self.dp_nom)
    }

    /// Check valve opening `u_cv = (p2 - p3 - p_cv) / p_fo,cv` (eq. 2.55), limited to
    /// [0, 1]. Its dynamics are neglected as in the thesis.
    pub fn check_opening<T: Scalar>(&self, p2: T, p3: T) -> T {
        clamp((p2 - p3 - self.p_cv) / self.p_fo_cv, 0.0, 1.0)
    }

    /// Static opening of the load-holding valve
    /// `u_cbv = (mu_p p4 + p3 - p_set - (1 + mu_p) p_T) / p_fo,cbv` (eq. 2.56), limited to
    /// [0, 1]; the input of the lag of eq. 2.57.
    pub fn holding_opening<T: Scalar>(&self, p3: T, p4: T, p_t: f64) -> T {
        clamp((p4 * self.mu_p + p3 - self.p_set - (1.0 + self.mu_p) * p_t) / self.p_fo_cbv, 0.0, 1.0)
    }

    /// Rate of the load-holding valve opening, first-order lag
    /// `G_cbv(s) = 1 / (s / omega_cbv + 1)` (eq. 2.57) from the static opening `u_static` of
    /// [`Cbv::holding_opening`]: `du_cbv/dt = omega_cbv (u_static - u_cbv)`. Starting in
    /// [0, 1] the opening stays there.
    pub fn holding_rate<T: Scalar>(&self, u_cbv: T, u_static: T) -> T {
        (u_static - u_cbv) * self.omega_cbv
    }

    /// Flow `Q3` from line 2 to line 3 (m^3/s): `K2 u_cv sqrt(p2 - p3)` for `p2 >= p3`
    /// (eq. 2.58, check valve) and `-K2 u_cbv sqrt(p3 - p2)` for `p2 < p3` (eq. 2.59,
    /// load-holding valve), with the regularised root. Both branches vanish at `p2 = p3`, so
    /// the flow is continuous. `u_cbv` is clamped to [0, 1] against solver overshoot.
    pub fn flow<T: Scalar>(&self, u_cv: T, u_cbv: T, p2: T, p3: T, p_tr: f64) -> T {
        let u = if p2 >= p3 { u_cv } else { clamp(u_cbv, 0.0, 1.0) };
        orifice::flow(self.k2(), u, p2 - p3, p_tr)
    }
}

#[cfg(test)]
mod tests {
    use crate::hydraulics::circuit::Circuit;
    use crate::units::{bar, lpm};

    /// Fig. 2.16 / 3.15: free flow and piloted-open characteristics pass 60 l/min at 16 bar;
    /// the free flow needs the 2.8 bar check-valve pressure before any flow, and is fully open
    /// 1 bar above it. Tolerances: float rounding only (the laws are evaluated exactly).
    #[test]
    fn characteristic_fig_2_16() {
        let c = Circuit::default();
        let (cbv, p_tr) = (c.cbv, c.p_tr);
        assert!((cbv.k2() - 7.91e-7).abs() < 0.005e-7, "K2 = {}", cbv.k2());
        let p3 = bar(100.0);
        // free flow through the check valve
        let p2 = p3 + bar(16.0);
        let q = cbv.flow(cbv.check_opening(p2, p3), 0.0, p2, p3, p_tr);
        assert!((q / lpm(60.0) - 1.0).abs() < 1e-12, "free flow at 16 bar: {q}");
        for dp in [0.0, 1.0, 2.0, 2.8] {
            let p2 = p3 + bar(dp);
            assert_eq!(cbv.flow(cbv.check_opening(p2, p3), 0.0, p2, p3, p_tr), 0.0);
        }
        let p2 = p3 + bar(3.3);
        assert!((cbv.check_opening(p2, p3) - 0.5).abs() < 1e-12);
        assert_eq!(cbv.check_opening(p3 + bar(3.8), p3), 1.0);
        // piloted open load-holding valve (u_cbv = 1), reverse direction
        let p2 = p3 - bar(16.0);
        let q = cbv.flow(0.0, 1.0, p2, p3, p_tr);
        assert!((q / -lpm(60.0) - 1.0).abs() < 1e-12, "piloted flow at 16 bar: {q}");
        // the closed load-holding valve holds the load
        assert_eq!(cbv.flow(0.0, 0.0, p2, p3, p_tr), 0.0);
    }

    /// Eq. 2.56: the valve starts to open when mu_p p4 + p3 reaches p_set and is fully open
    /// p_fo,cbv above it.
    #[test]
    fn holding_opening_eq_2_56() {
        let cbv = Circuit::default().cbv;
        let p4 = bar(20.0);
        let p3_crack = cbv.p_set - cbv.mu_p * p4;
        assert_eq!(cbv.holding_opening(p3_crack - bar(1.0), p4, 0.0), 0.0);
        let half = cbv.holding_opening(p3_crack + 0.5 * cbv.p_fo_cbv, p4, 0.0);
        assert!((half - 0.5).abs() < 1e-12);
        assert_eq!(cbv.holding_opening(p3_crack + 2.0 * cbv.p_fo_cbv, p4, 0.0), 1.0);
        // eq. 2.57: initial rate omega_cbv * 0.5 = 31.5 1/s
        assert!((cbv.holding_rate(0.0, half) - 31.5).abs() < 1e-9);
    }
}
