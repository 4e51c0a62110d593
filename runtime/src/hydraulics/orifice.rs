//! Turbulent orifice `Q = K * u * sqrt(dp)` (form of eq. 2.40-2.43, 2.50, 2.58, 2.59) with a
//! regularised square root near `dp = 0`.

use crate::scalar::Scalar;

/// Flow coefficient `K = Q_nom / sqrt(dp_nom)` of an orifice that passes `q_nom` (m^3/s) at the
/// pressure drop `dp_nom` (Pa) when fully open. This is how the thesis computes K1, K2 and K3
/// (section 2.2.1, 2.2.2); the coefficient lumps discharge coefficient, area and density.
pub fn flow_coefficient(q_nom: f64, dp_nom: f64) -> f64 {
    q_nom / dp_nom.sqrt()
}

/// Regularised signed square root: `sign(dp) * sqrt(|dp|)` for `|dp| >= p_tr`, and inside
/// `|dp| < p_tr` the odd cubic `sqrt(p_tr) * (5 xi - xi^3) / 4` with `xi = dp / p_tr`.
///
/// Deviation from the thesis (which uses the plain root of a turbulent orifice): the plain root
/// has an infinite slope at `dp = 0`, so its Jacobian is singular for an implicit solver. The
/// cubic matches value and slope at `|dp| = p_tr` (C1), is odd and strictly monotone (its slope
/// `(5 - 3 xi^2) / (4 sqrt(p_tr))` is positive on `|xi| <= 1`), and has the finite slope
/// `5 / (4 sqrt(p_tr))` at zero, a laminar-like region. Outside the band the result is the exact
/// root, so the flow at 7 bar is unchanged as long as `p_tr < 7 bar`. Reverse flow through an
/// open orifice (`dp < 0`) follows the same law with negative sign.
pub fn reg_sqrt<T: Scalar>(dp: T, p_tr: f64) -> T {
    let a = dp.abs();
    if a >= p_tr {
        dp.signum() * a.sqrt()
    } else {
        let xi = dp / p_tr;
        xi * p_tr.sqrt() * (T::from(5.0) - xi * xi) * 0.25
    }
}

/// Orifice flow `Q = K * u * reg_sqrt(dp)` (m^3/s) for flow coefficient `k`, opening `u`
/// and pressure drop `dp` (Pa), positive in the direction of the pressure drop.
pub fn flow<T: Scalar>(k: f64, u: T, dp: T, p_tr: f64) -> T {
    u * k * reg_sqrt(dp, p_tr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::bar;

    const P_TR: f64 = 1e4;

    #[test]
    fn exact_root_outside_band() {
        // The regularisation must not change the flow at 7 bar by more than 0.1 %;
        // by construction it is exact there, bit for bit.
        let exact = bar(7.0).sqrt();
        assert_eq!(reg_sqrt(bar(7.0), P_TR), exact);
        assert_eq!(reg_sqrt(-bar(7.0), P_TR), -exact);
    }

    #[test]
    fn odd_monotone_and_c1() {
        let n = 2001;
        let mut prev = f64::NEG_INFINITY;
        for i in 0..n {
            let dp = -3.0 * P_TR + 6.0 * P_TR * i as f64 / (n - 1) as f64;
            let q = reg_sqrt(dp, P_TR);
            assert_eq!(q, -reg_sqrt(-dp, P_TR), "odd at {dp}");
            assert!(q > prev, "strictly monotone at {dp}");
            prev = q;
        }
        // Value and slope continuity at the junction: one-sided difference quotients with step
        // h agree to O(h) (the second derivative jumps); h = 1e-4 p_tr gives ~1e-4 relative.
        let h = 1e-4 * P_TR;
        let f = |x| reg_sqrt(x, P_TR);
        assert!((f(P_TR - 1e-9) - f(P_TR + 1e-9)).abs() < 1e-9);
        let left = (f(P_TR) - f(P_TR - h)) / h;
        let right = (f(P_TR + h) - f(P_TR)) / h;
        let slope = 0.5 / P_TR.sqrt();
        assert!((left / slope - 1.0).abs() < 1e-3 && (right / slope - 1.0).abs() < 1e-3);
        // finite slope at zero: 5 / (4 sqrt(p_tr))
        let s0 = (f(h) - f(-h)) / (2.0 * h);
        assert!((s0 / (1.25 / P_TR.sqrt()) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn coefficient_reproduces_nominal_point() {
        let k = flow_coefficient(1e-3, bar(16.0));
        assert!((flow(k, 1.0, bar(16.0), P_TR) - 1e-3).abs() < 1e-15);
        assert!((flow(k, 0.5, bar(4.0), P_TR) - 0.25e-3).abs() < 1e-15);
    }
}
