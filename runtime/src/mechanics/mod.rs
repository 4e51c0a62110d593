//! Boom kinematics, kinetics and deflection (thesis section 2.1).
//!
//! - [`params`]: the boom, payload and cylinder-mechanics parameters with their descriptions;
//! - [`kinematics`]: the vector triangle (2.1-2.7), mass centre (2.8) and the position, velocity
//!   and acceleration constraints (2.11-2.15);
//! - [`rigid_boom`]: the kinetics (2.16-2.19) and the equation of motion in the cylinder stroke;
//! - [`deflection`]: the analytic static deflection (2.20-2.33);
//! - [`flexible_boom`]: the lumped flexible beam (2.34-2.39, 3.1.2);
//!
//! [`Mechanics`] and [`Kinetics`] are what a hydraulic model needs from either boom.

pub mod deflection;
pub mod flexible_boom;
pub mod kinematics;
pub mod params;
pub mod rigid_boom;

use std::fmt;

use nalgebra::Vector2;

use crate::scalar::Scalar;

/// The kinetics of a boom driven by the cylinder, in the number type `T` ([`Scalar`]: `f64`, or
/// dual numbers for exact derivatives): generalised coordinates q (velocities q_dot) from which
/// the cylinder stroke follows, and the accelerations under a cylinder force. The cylinder force
/// `f_cyl` is the net force on the rod (pressure forces minus friction); the boom adds the rod
/// mass and weight itself.
pub trait Kinetics<T: Scalar> {
    /// Cylinder stroke x = l_cyl(q) - l_retracted.
    fn stroke(&self, q: &[T]) -> T;
    /// Stroke rate dx/dt = (dl_cyl/dq) q_dot.
    fn stroke_rate(&self, q: &[T], qd: &[T]) -> T;
    /// Writes q_ddot into `out` (length [`Mechanics::dof`]) under the cylinder force
    /// `f_cyl(x, x_dot)`, called once with the stroke and stroke rate at (q, q_dot) (a hydraulic
    /// model evaluates its circuit there, so the geometry is computed once); allocation-free.
    fn accelerations(&self, q: &[T], qd: &[T], f_cyl: &mut dyn FnMut(T, T) -> T, out: &mut [T]);
    /// Payload mass centre in the global frame (origin: lower cylinder pin A).
    fn payload(&self, q: &[T]) -> Vector2<T>;
}

/// A boom driven by the cylinder: its kinetics in `f64`, its size, rest and energy.
pub trait Mechanics: Kinetics<f64> {
    /// Number of generalised coordinates.
    fn dof(&self) -> usize;
    /// Rest configuration at stroke `x` and the cylinder force that holds it.
    fn equilibrium(&self, x: f64) -> Result<Equilibrium, MechanicsError>;
    /// Kinetic and potential energy (J), see the implementations for what they include.
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy;
}

/// A static equilibrium: coordinates and the holding cylinder force on the rod (N).
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    pub q: Vec<f64>,
    pub f_cyl: f64,
}

/// Mechanical energy (J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    pub kinetic: f64,
    pub potential: f64,
}

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
    /// The lumped beam's layout is impossible (section counts, mount position).
    InvalidBeam(&'static str),
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
            Self::InvalidBeam(why) => write!(f, "lumped beam: {why}"),
        }
    }
}

impl std::error::Error for MechanicsError {}
