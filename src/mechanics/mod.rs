//! Boom kinematics, kinetics and deflection (thesis section 2.1).
//!
//! - [`params`]: the boom, payload and cylinder-mechanics parameters with their descriptions;
//! - [`kinematics`]: the vector triangle (2.1-2.7), mass centre (2.8) and the position, velocity
//!   and acceleration constraints (2.11-2.15);
//! - [`rigid_boom`]: the kinetics (2.16-2.19) and the equation of motion in the cylinder stroke.

pub mod kinematics;
pub mod params;
pub mod rigid_boom;

use std::fmt;

/// Why a boom geometry or configuration cannot be evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MechanicsError {
    /// The triangle joint-B / lower pin A / upper pin C does not close for every cylinder length
    /// in `[l_min, l_max]`: it needs `|w1 - w2| < l_cyl < w1 + w2` (eq. 2.3).
    TriangleOpen { l_min: f64, l_max: f64, w1: f64, w2: f64 },
    /// Newton-Raphson on the position constraints (2.11) did not converge.
    NoConvergence { l_cyl: f64 },
    /// The constraint Jacobian of (2.13) is singular (cylinder axis through the joint).
    SingularJacobian { l_cyl: f64 },
}

impl fmt::Display for MechanicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TriangleOpen { l_min, l_max, w1, w2 } => write!(
                f,
                "cylinder lengths {l_min} m..{l_max} m do not close the triangle with w1 = {w1} m \
                 and w2 = {w2} m (need {} m < l_cyl < {} m)",
                (w1 - w2).abs(),
                w1 + w2
            ),
            Self::NoConvergence { l_cyl } => {
                write!(f, "position constraints (2.11) did not converge at l_cyl = {l_cyl} m")
            }
            Self::SingularJacobian { l_cyl } => {
                write!(f, "singular constraint Jacobian (2.13) at l_cyl = {l_cyl} m")
            }
        }
    }
}

impl std::error::Error for MechanicsError {}
