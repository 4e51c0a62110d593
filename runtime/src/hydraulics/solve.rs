//! Scalar root finding: the static operating points of the circuit, and line 1's quasi-static
//! pressure ([`super::Circuit::line1_pressure`]) at every evaluation.

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

/// Steps of [`falling_root`] at most: bisection alone narrows a bracket of a few hundred bar to
/// round-off in about 60.
const FALLING_ROOT_STEPS: usize = 100;

/// Root of a function falling through the bracket `[lo, hi]` (`f(lo) >= 0 >= f(hi)`) from `x`;
/// `f` returns its value and derivative. Newton's step where it stays inside the bracket and the
/// last one at least halved |f| (Newton cycles about a square-root root), else bisection. Stops
/// when Newton's next step would be below `step_tol`, or the bracket is narrower than
/// `bracket_tol`. Returns the last point with f and f' there, so that the caller can take that
/// last step (with the derivatives it wants).
pub fn falling_root(
    mut f: impl FnMut(f64) -> (f64, f64),
    mut lo: f64,
    mut hi: f64,
    mut x: f64,
    step_tol: f64,
    bracket_tol: f64,
) -> (f64, f64, f64) {
    let (mut g, mut dg) = f(x);
    let mut g_before = f64::INFINITY;
    for _ in 0..FALLING_ROOT_STEPS {
        if g > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        if g == 0.0 || (dg < 0.0 && g.abs() <= step_tol * -dg) || hi - lo <= bracket_tol {
            break;
        }
        let newton = x - g / dg;
        let fast = dg < 0.0 && newton > lo && newton < hi && g.abs() <= 0.5 * g_before.abs();
        (x, g_before) = (if fast { newton } else { 0.5 * (lo + hi) }, g);
        (g, dg) = f(x);
    }
    (x, g, dg)
}

#[cfg(test)]
mod tests {
    /// A smooth falling function (2 - x^2, root sqrt 2) and one whose root is a square root's,
    /// -sign(x) sqrt|x| (root 0), where plain Newton from x jumps to -x and back forever: both
    /// to the step tolerance (the returned point is within one Newton step, |f / f'|, of it).
    #[test]
    fn falling_root_converges_where_newton_cycles() {
        let (x, g, dg) = super::falling_root(|x| (2.0 - x * x, -2.0 * x), 0.0, 2.0, 0.5, 1e-12, 1e-15);
        assert!((x - g / dg - 2f64.sqrt()).abs() < 1e-12, "{x}");
        let root = |x: f64| (-x.signum() * x.abs().sqrt(), -0.5 / x.abs().sqrt().max(1e-300));
        let (x, _, _) = super::falling_root(root, -1.0, 1.0, 0.25, 1e-12, 1e-15);
        assert!(x.abs() < 1e-12, "{x}");
    }

    #[test]
    fn finds_root() {
        let r = super::bisect(|x| x * x - 2.0, 0.0, 2.0, 1e-12);
        assert!((r - 2f64.sqrt()).abs() < 1e-12);
        let r = super::bisect(|x| 2.0 - x * x, 0.0, 2.0, 1e-12);
        assert!((r - 2f64.sqrt()).abs() < 1e-12);
    }
}
