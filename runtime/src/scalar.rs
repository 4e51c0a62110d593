//! The number type the right-hand sides are generic over: `f64` for simulation, a dual number
//! ([`num_dual::Dual64`]) for exact directional derivatives by forward-mode differentiation.
//! The `f64` instances compute exactly what the code computed before it was generic: constants
//! on the left of an operator become `T::from(c)`, and no operation is regrouped.

pub use num_dual::{Dual64, DualSVec64};

/// A real number of the right-hand sides.
pub trait Scalar: num_dual::DualNum<Primitive = f64> + Copy {}

impl<T: num_dual::DualNum<Primitive = f64> + Copy> Scalar for T {}

/// `x` limited to [lo, hi], as `f64::clamp`.
pub fn clamp<T: Scalar>(x: T, lo: f64, hi: f64) -> T {
    if x < lo {
        T::from(lo)
    } else if x > hi {
        T::from(hi)
    } else {
        x
    }
}

/// The smaller of `x` and `hi` (`f64::min` for numbers).
pub fn min<T: Scalar>(x: T, hi: f64) -> T {
    if x > hi {
        T::from(hi)
    } else {
        x
    }
}

/// The larger of `x` and `lo` (`f64::max` for numbers).
pub fn max<T: Scalar>(x: T, lo: f64) -> T {
    if x < lo {
        T::from(lo)
    } else {
        x
    }
}

/// tanh(x) with the derivative (1 - tanh^2) x'. num-dual's `tanh` divides sinh by cosh, whose
/// square overflows beyond |x| ~ 355 and turns the derivative into NaN (the friction's
/// tanh(v / v_s) reaches 400 at 40 mm/s). For `f64` this is `f64::tanh` (except that tanh(-0)
/// gives +0).
pub fn tanh<T: Scalar>(x: T) -> T {
    let t = x.re().tanh();
    (x - x.re()) * (1.0 - t * t) + t
}
