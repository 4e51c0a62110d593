//! The instability criterion of section 2.3: Routh-Hurwitz on the cubic denominator of
//! eq. 2.82, exact (eq. 2.83, 2.84) and simplified (eq. 2.86, 2.87), and the critical stroke.
//!
//! The cubic `a3 s^3 + a2 s^2 + a1 s + a0` with positive coefficients is stable iff
//! `a1 a2 > a3 a0`, which reduces to `C2 / C1 > r` with the required ratio
//! `r = mu_c mu_p K_qu / (K_qu + K_qp p_fo)` (eq. 2.83) `= mu_c mu_p 2 p3 / (2 p3 + u_cbv p_fo)`
//! (eq. 2.84). The thesis writes `>=`; equality is the marginal case (a pole pair on the
//! imaginary axis), so stability needs the strict inequality.

use super::operating_point::{Linearised, OperatingPoint};

/// Required `C2 / C1` of eq. 2.83.
pub fn required_ratio(op: &OperatingPoint, lin: &Linearised) -> f64 {
    op.mu_c * op.mu_p * lin.k_qu / (lin.k_qu + lin.k_qp * op.p_fo)
}

/// Required `C2 / C1` of eq. 2.84 (eq. 2.83 with eq. 2.79, 2.80 inserted; equal by algebra), with
/// the CBV's pressure drop `p3 - p2` for the thesis' `p3` (see [`OperatingPoint::p2`]).
pub fn required_ratio_steady_state(op: &OperatingPoint, lin: &Linearised) -> f64 {
    let dp = lin.p3 - op.p2;
    op.mu_c * op.mu_p * 2.0 * dp / (2.0 * dp + lin.u_cbv * op.p_fo)
}

/// Simplified required `C2 / C1 = mu_c mu_p` (eq. 2.86: `u_cbv p_fo << p3`).
pub fn required_ratio_simplified(op: &OperatingPoint) -> f64 {
    op.mu_c * op.mu_p
}

/// Exact criterion: `C2 / C1 > r` (eq. 2.83).
pub fn is_stable_exact(op: &OperatingPoint, lin: &Linearised) -> bool {
    lin.c2 / lin.c1 > required_ratio(op, lin)
}

/// Critical stroke (m) for a required ratio `r`: `C2(x) / C1(x) = r` solved for `x`, stable
/// below it. `p3` and `u_cbv` do not depend on the stroke (eq. 2.85), so `r` is constant and
/// the equation is linear in `x`:
/// `x = (mu_c A s_c / beta2 + C2_extra - r C1_extra) / (r A / beta1 + mu_c A / beta2)`.
/// May lie outside `[0, s_c]` (stable or unstable along the whole stroke).
pub fn critical_stroke(op: &OperatingPoint, r: f64) -> f64 {
    let (a1, a2) = (op.area / op.beta1, op.area / op.beta2);
    (op.mu_c * a2 * op.stroke + op.c2_extra - r * op.c1_extra) / (r * a1 + op.mu_c * a2)
}

/// Exact critical stroke (m), eq. 2.84 solved for `x_c`.
pub fn xc_crit_exact(op: &OperatingPoint, lin: &Linearised) -> f64 {
    critical_stroke(op, required_ratio(op, lin))
}

/// Where along the stroke `[0, s_c]` of a cylinder with `stroke` a critical stroke `x` (stable
/// below it) leaves the system stable, as the report says it: "123.4 mm", or that no stroke in
/// the range is critical.
pub fn describe_critical_stroke(stroke: f64, x: f64) -> String {
    let range = format!("[0, {:.1}] mm", stroke / boomsim::units::MM);
    if x.is_nan() {
        "undefined".into()
    } else if x <= 0.0 {
        format!("none: unstable at every stroke in {range} (the root of eq. 2.84 is {:.1} mm)", x / boomsim::units::MM)
    } else if x >= stroke {
        format!("none: stable at every stroke in {range} (the root of eq. 2.84 is {:.1} mm)", x / boomsim::units::MM)
    } else {
        format!("{:.1} mm", x / boomsim::units::MM)
    }
}

/// Simplified critical stroke `s_c / (1 + mu_p)` (m), eq. 2.87 (no line or dead volumes).
pub fn xc_crit_simplified(op: &OperatingPoint) -> f64 {
    op.stroke / (1.0 + op.mu_p)
}

#[cfg(test)]
mod tests {
    use super::super::plant::{closed_loop, HParams};
    use super::super::routh;
    use super::*;

    /// Eq. 2.83 and 2.84 agree (algebra, 1e-12); 2.87 equals 2.86 solved with C1 = A x / beta,
    /// C2 = mu_c A (s - x) / beta (1e-12).
    #[test]
    fn forms_agree() {
        let op = OperatingPoint::default();
        let lin = op.linearise().unwrap();
        assert!((required_ratio(&op, &lin) / required_ratio_steady_state(&op, &lin) - 1.0).abs() < 1e-12);
        let x = critical_stroke(&op, required_ratio_simplified(&op));
        assert!((x / xc_crit_simplified(&op) - 1.0).abs() < 1e-12);
    }

    /// The criterion against the closed-loop poles of eq. 2.82 and the Routh array of its
    /// denominator, along the stroke for every valve of Table 4.3, with and without extra
    /// capacitance: all three must agree except within 1e-6 of the boundary.
    #[test]
    fn criterion_matches_poles() {
        let mut checked = 0;
        for mu_p in [1.0, 2.0, 3.0, 5.0] {
            for extra in [0.0, 0.15e-11] {
                let base = OperatingPoint {
                    mu_p,
                    p_set: super::super::operating_point::p_set_for(mu_p),
                    c1_extra: extra,
                    c2_extra: extra,
                    ..OperatingPoint::default()
                };
                // same flow as Table 6.1 so the CBV is open for every valve
                let Some(base) = base.with_flow(OperatingPoint::default().flow().unwrap()) else { continue };
                for i in 1..50 {
                    let op = OperatingPoint { x_c: base.stroke * i as f64 / 50.0, ..base };
                    let lin = op.linearise().unwrap();
                    let g = closed_loop(lin.c2, &HParams::new(&op, &lin).h());
                    let margin = lin.c2 / lin.c1 / required_ratio(&op, &lin) - 1.0;
                    if margin.abs() < 1e-6 {
                        continue;
                    }
                    assert_eq!(is_stable_exact(&op, &lin), g.is_stable(), "mu_p {mu_p}, x {}", op.x_c);
                    assert_eq!(routh::rhp_roots(&g.den) == 0, g.is_stable());
                    assert_eq!(op.x_c < xc_crit_exact(&op, &lin), g.is_stable());
                    checked += 1;
                }
            }
        }
        assert!(checked > 300, "{checked}");
    }

    /// With enough extra rod-side capacitance (C1_extra = 0.13 cm^3/bar, the case) the
    /// root of eq. 2.84 is a negative stroke: the report says that no stroke is stable, and the
    /// closed-loop poles of eq. 2.82 agree at every stroke.
    #[test]
    fn a_root_outside_the_stroke_is_reported_as_such() {
        let base = OperatingPoint { c1_extra: 0.13e-6 / boomsim::units::BAR, ..OperatingPoint::default() };
        let lin = base.linearise().unwrap();
        let x = xc_crit_exact(&base, &lin);
        assert!(x < 0.0, "{x}");
        assert!(describe_critical_stroke(base.stroke, x).starts_with("none: unstable at every stroke"));
        // Every stroke short of the full one (there C2 = 0: the piston side has no volume).
        for i in 0..20 {
            let op = OperatingPoint { x_c: base.stroke * i as f64 / 20.0, ..base };
            let lin = op.linearise().unwrap();
            assert!(!closed_loop(lin.c2, &HParams::new(&op, &lin).h()).is_stable(), "x = {}", op.x_c);
        }
        assert!(describe_critical_stroke(base.stroke, 2.0 * base.stroke).starts_with("none: stable at every stroke"));
        assert_eq!(describe_critical_stroke(base.stroke, 0.1234), "123.4 mm");
    }
}
