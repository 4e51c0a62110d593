//! Scalar root finding for the static operating points of the circuit.

/// Root of a continuous `f` on `[lo, hi]` by bisection, given `f(lo)` and `f(hi)` of opposite
/// sign (or zero); returns the midpoint once the bracket is narrower than `tol`. Robust against
/// the kinks of the clamped valve openings, where Newton's method can cycle.
pub fn bisect(mut f: impl FnMut(f64) -> f64, mut lo: f64, mut hi: f64, tol: f64) -> f64 {
    let f_lo = f(lo);
    debug_assert!(f_lo * f(hi) <= 0.0, "bisect: root not bracketed in [{lo}, {hi}]");
    let lo_negative = f_lo < 0.0;
    while (hi - lo).abs() > tol {
        let mid = 0.5 * (lo + hi);
        if (f(mid) < 0.0) == lo_negative {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    #[test]
    fn finds_root() {
        let r = super::bisect(|x| x * x - 2.0, 0.0, 2.0, 1e-12);
        assert!((r - 2f64.sqrt()).abs() < 1e-12);
        let r = super::bisect(|x| 2.0 - x * x, 0.0, 2.0, 1e-12);
        assert!((r - 2f64.sqrt()).abs() < 1e-12);
    }
}
