//! The stiff integrator used inside fmi2DoStep.
//!
//! Models implement [`OdeSystem`] (`dx/dt = f(t, x)`, optional analytic Jacobian); [`Radau5`]
//! advances them from one communication point exactly to the next with error control on a
//! relative tolerance and a per-component absolute tolerance. The method (Radau IIA of order 5,
//! see [`radau5`]) was chosen by `examples/solver_bench.rs`.

use nalgebra::DMatrix;
use std::fmt;

pub(crate) mod cholesky;
mod iteration;
mod lu;
pub mod radau5;
#[cfg(test)]
mod tests;

pub use iteration::SecondOrder;
pub use radau5::{plan, stage_times, tail_rhs, Dense, Radau5, Watch, NEWTON_BUDGET};

/// An ODE `dx/dt = f(t, x)` of fixed dimension.
pub trait OdeSystem {
    /// Number of states.
    fn dim(&self) -> usize;

    /// Writes `f(t, x)` into `dx` (both of length [`dim`](Self::dim)). A non-finite value in
    /// `dx` makes the integrator reject the step and retry with a smaller one.
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]);

    /// Optionally writes the Jacobian `∂f/∂x` (dim × dim, `jac[(i, j)] = ∂f_i/∂x_j`) and returns
    /// `true`. The default returns `false`: the integrator then uses forward differences.
    fn jacobian(&self, _t: f64, _x: &[f64], _jac: &mut DMatrix<f64>) -> bool {
        false
    }

    /// Optionally declares position states whose derivative is exactly a velocity state; the
    /// integrator then eliminates them from its linear systems ([`SecondOrder`]). Default: none.
    fn second_order(&self) -> Option<SecondOrder> {
        None
    }
}

/// Work counters, cumulative since construction or [`Radau5::reset_stats`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SolverStats {
    /// Accepted steps.
    pub accepted_steps: u64,
    /// Rejected steps (error test failed, Newton failed, non-finite RHS or singular matrix).
    pub rejected_steps: u64,
    /// Evaluations of [`OdeSystem::rhs`], including those for finite-difference Jacobians.
    pub rhs_evals: u64,
    /// Jacobian evaluations (analytic or finite-difference).
    pub jacobian_evals: u64,
    /// LU factorisations of the iteration matrix; one count is the real n×n plus the complex
    /// n×n factorisation of one Radau IIA iteration matrix.
    pub lu_decompositions: u64,
    /// Simplified Newton iterations (each solves both linear systems once).
    pub newton_iterations: u64,
    /// Closing steps of the real-time mode ([`Radau5::integrate_bounded`]) whose accuracy-loss
    /// indicator exceeded 1: steps the adaptive mode would have rejected.
    pub inaccurate_steps: u64,
}

/// Why a step could not be completed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FailureCause {
    /// The local error estimate stayed above the tolerance.
    ErrorTest,
    /// The simplified Newton iteration diverged or converged too slowly.
    NewtonFailure,
    /// [`OdeSystem::rhs`] returned NaN or infinity.
    NonFiniteRhs,
    /// The Jacobian contained NaN or infinity.
    NonFiniteJacobian,
    /// An iteration matrix was singular.
    SingularMatrix,
}

/// What stopped the integration.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveErrorKind {
    /// The step size fell below the minimum `10 ε max(|t|, |t_end|)` after rejections.
    StepSizeTooSmall(FailureCause),
    /// More consecutive rejections than the limit of 100.
    TooManyRejections(FailureCause),
    /// More accepted steps in one `integrate` call than the configured maximum.
    TooManySteps(u64),
    /// The Jacobian at an accepted state is not finite; smaller steps cannot help.
    NonFiniteJacobian,
    /// `rhs` is not finite at the initial state of the call.
    NonFiniteInitialRhs,
    /// The closing step of the real-time mode ([`Radau5::integrate_bounded`]) could not be
    /// completed; it has no smaller step to try.
    FixedStepFailed(FailureCause),
    /// The arguments are invalid (wrong dimension, `t_end < t0`, non-finite values).
    InvalidArgument(String),
}

/// The integrator could not reach `t_end`. The state vector holds the last accepted state,
/// which belongs to time [`t`](Self::t).
#[derive(Clone, Debug, PartialEq)]
pub struct SolveError {
    /// What went wrong.
    pub kind: SolveErrorKind,
    /// Time of the last accepted state (the state left in `x`); NaN for errors of the setters.
    pub t: f64,
    /// Step size of the last attempt.
    pub h: f64,
}

impl fmt::Display for FailureCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FailureCause::ErrorTest => "local error estimate above tolerance",
            FailureCause::NewtonFailure => "Newton iteration did not converge",
            FailureCause::NonFiniteRhs => "right-hand side returned NaN or infinity",
            FailureCause::NonFiniteJacobian => "Jacobian contains NaN or infinity",
            FailureCause::SingularMatrix => "singular iteration matrix",
        })
    }
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "integration stopped at t = {:e} s (step {:e} s): ", self.t, self.h)?;
        match &self.kind {
            SolveErrorKind::StepSizeTooSmall(c) => write!(f, "step size below minimum ({c})"),
            SolveErrorKind::TooManyRejections(c) => write!(f, "too many rejected steps ({c})"),
            SolveErrorKind::TooManySteps(n) => write!(f, "more than {n} steps in one call"),
            SolveErrorKind::NonFiniteJacobian => f.write_str("Jacobian contains NaN or infinity"),
            SolveErrorKind::NonFiniteInitialRhs => {
                f.write_str("right-hand side is NaN or infinite at the initial state")
            }
            SolveErrorKind::FixedStepFailed(c) => write!(f, "real-time step failed ({c})"),
            SolveErrorKind::InvalidArgument(m) => write!(f, "invalid argument: {m}"),
        }
    }
}

impl std::error::Error for SolveError {}
