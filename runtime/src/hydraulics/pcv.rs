//! Pressure compensator (PCV) of the PVG 32 basic module, section 2.2.1, eq. 2.49-2.50:
//! a normally open reducing restriction between the supply and the main spool that keeps
//! `p1 - p_x` close to the spring pressure.

use super::orifice;
use crate::scalar::{clamp, Scalar};

/// PCV parameters (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pcv {
    /// Spring pressure `p_pcv` (Pa), 7 bar (parameter list).
    pub p_spring: f64,
    /// Spring pressure rise from open to fully closed `p_fc,pcv` (Pa), 1 bar (assumed, 2.2.1).
    pub p_fc: f64,
    /// Flow through the fully open PCV at `dp_nom`: rated PVB flow 100 l/min (2.2.1).
    pub q_nom: f64,
    /// Pressure drop of the fully open PCV at `q_nom`: 6 bar (shorted circuit of Fig. 2.11:
    /// 20 bar supply minus 2 x 7 bar across the spool).
    pub dp_nom: f64,
}

impl Pcv {
    /// Flow coefficient `K3 = 100 l/min / sqrt(6 bar)` = 2.15e-6 m^3/(s sqrt(Pa)) (section 2.2.1).
    pub fn k3(&self) -> f64 {
        orifice::flow_coefficient(self.q_nom, self.dp_nom)
    }

    /// Opening `u_pcv = 1 - (p1 - p_x - p_pcv) / p_fc,pcv` (eq. 2.49), limited to [0, 1]
    /// (the valve cannot open beyond its stops; the thesis states the law without limits).
    /// The PCV dynamics are neglected as in the thesis.
    pub fn opening<T: Scalar>(&self, p1: T, p_x: T) -> T {
        clamp(T::from(1.0) - (p1 - p_x - self.p_spring) / self.p_fc, 0.0, 1.0)
    }

    /// Flow from the supply into line 1, `Q1 = K3 * u_pcv * sqrt(p_s - p1)` (eq. 2.50), with
    /// the regularised root of [`orifice::reg_sqrt`] (reverse flow if `p1 > p_s`; the thesis has
    /// no check function in the compensator).
    pub fn flow<T: Scalar>(&self, u_pcv: T, p_s: f64, p1: T, p_tr: f64) -> T {
        orifice::flow(self.k3(), u_pcv, T::from(p_s) - p1, p_tr)
    }
}

#[cfg(test)]
mod tests {
    use crate::hydraulics::circuit::Circuit;
    use crate::units::{bar, lpm};

    /// Fig. 2.12 / 3.10: the fully open PCV (pilot to tank) passes 100 l/min at 6 bar and
    /// follows the square-root law below (50 l/min at 1.5 bar). Tolerance: float rounding only.
    #[test]
    fn characteristic_fig_2_12() {
        let c = Circuit::default();
        let pcv = c.pcv;
        assert!((pcv.k3() - 2.15e-6).abs() < 0.005e-6, "K3 = {}", pcv.k3());
        let u = pcv.opening(0.0, 0.0);
        assert_eq!(u, 1.0);
        let q = pcv.flow(u, bar(6.0), 0.0, c.p_tr);
        assert!((q / lpm(100.0) - 1.0).abs() < 1e-12, "Q(6 bar) = {} l/min", q / lpm(1.0));
        let q = pcv.flow(u, bar(1.5), 0.0, c.p_tr);
        assert!((q / lpm(50.0) - 1.0).abs() < 1e-12);
    }

    /// Eq. 2.49: fully open up to p1 = p_x + 7 bar, closed at p_x + 8 bar, linear between.
    #[test]
    fn opening_eq_2_49() {
        let pcv = Circuit::default().pcv;
        let px = bar(50.0);
        assert_eq!(pcv.opening(px + bar(7.0), px), 1.0);
        assert_eq!(pcv.opening(px + bar(6.0), px), 1.0);
        assert!((pcv.opening(px + bar(7.25), px) - 0.75).abs() < 1e-12);
        assert_eq!(pcv.opening(px + bar(8.0), px), 0.0);
        assert_eq!(pcv.opening(px + bar(9.0), px), 0.0);
    }
}
