//! What the plant models share to step and to save themselves: their [`ModelInfo`] defaults, one
//! integrator step with logging, the solver's counters as outputs, and the saved-state layout
//! (head, state, integrator).
//!
//! [`ModelInfo`]: crate::fmu::ModelInfo

use super::vr;
use crate::fmu::{Log, StepError, Values};
use crate::solver::{OdeSystem, Radau5, SolverStats};

/// `solver.mode` of the real-time mode (0, the default, is the adaptive integrator).
pub const REALTIME: i32 = 1;

/// Writes the integrator's counters and accuracy indicator.
pub(crate) fn solver_outputs(solver: &Radau5, values: &mut Values) {
    let stats = solver.stats();
    values.set_real(vr::SOLVER_STEPS, stats.accepted_steps as f64);
    values.set_real(vr::SOLVER_REJECTED, stats.rejected_steps as f64);
    values.set_real(vr::SOLVER_RHS, stats.rhs_evals as f64);
    values.set_real(vr::SOLVER_JACOBIANS, stats.jacobian_evals as f64);
    values.set_real(vr::ACCURACY_LOSS, solver.accuracy_loss());
    values.set_real(vr::INACCURATE_STEPS, stats.inaccurate_steps as f64);
}

/// `state` if given and `dim` finite numbers, else `start()`.
pub(crate) fn checked_state(
    dim: usize,
    state: Option<&[f64]>,
    start: impl FnOnce() -> Result<Vec<f64>, String>,
) -> Result<Vec<f64>, String> {
    match state {
        None => start(),
        Some(s) if s.len() == dim && s.iter().all(|x| x.is_finite()) => Ok(s.to_vec()),
        Some(s) => Err(format!("expected {dim} finite states, got {}", s.len())),
    }
}

/// Advances `state` of `sys` from `t` to `t + h` with relative tolerance `rtol` and absolute
/// tolerances `rtol * scale` (evaluated only when `rtol` changes), logging the integrator
/// statistics of the step. `solver.mode` of `values` picks the integration: adaptive
/// ([`Radau5::integrate`]: error control, steps rejected and repeated as needed) or real-time
/// ([`Radau5::integrate_bounded`]: the same within `solver.rhs_budget` RHS evaluations, the
/// accuracy of its closing step reported instead of enforced). Neither allocates.
pub(crate) fn advance<S: OdeSystem>(
    solver: &mut Radau5,
    sys: &S,
    state: &mut [f64],
    (t, h, rtol): (f64, f64, f64),
    scale: impl FnOnce() -> Vec<f64>,
    values: &Values,
    log: &mut dyn Log,
) -> Result<(), StepError> {
    let fail = |time, message: String| StepError { time, message };
    solver.set_tolerance(rtol, scale).map_err(|e| fail(t, e.to_string()))?;
    let before = *solver.stats();
    let result = match values.integer(vr::SOLVER_MODE) {
        REALTIME => solver.integrate_bounded(sys, t, state, t + h, values.integer(vr::RHS_BUDGET) as u64),
        _ => solver.integrate(sys, t, state, t + h),
    };
    result.map_err(|e| fail(e.t, e.to_string()))?;
    log_step(log, t + h, &before, solver.stats());
    Ok(())
}

/// What the plant models (HydraulicBoom, HydraulicCircuit, BoomMechanics) share in their
/// [`ModelInfo`]: the thesis' 15 s experiments at 1 ms, rtol 1e-6, the solver log category.
pub(crate) const PLANT_INFO: crate::fmu::ModelInfo = crate::fmu::ModelInfo {
    identifier: "",
    description: "",
    version: env!("CARGO_PKG_VERSION"),
    start_time: 0.0,
    stop_time: 15.0,
    step_size: 1e-3,
    default_tolerance: 1e-6,
    log_categories: &[("logSolver", "Integrator statistics per communication step")],
    interpolated_inputs: &[],
    documentation: "",
};

/// A saved model: `head` (time, port values), the state, the integrator's state.
pub(crate) fn save(head: &[f64], state: &[f64], solver: &Radau5) -> Vec<f64> {
    [head, state, &solver.save_state()].concat()
}

/// A saved model's parts: head, state, integrator state.
type Saved<'a> = (&'a [f64], &'a [f64], &'a [f64]);

/// The parts of a model saved by [`save`] with `n_head` leading numbers: the state dimension n is
/// the one for which head + n + the integrator's saved length add up to the total.
pub(crate) fn split_saved(saved: &[f64], n_head: usize) -> Result<Saved<'_>, String> {
    let rest = saved.len().checked_sub(n_head).ok_or("the saved model state is too short")?;
    let n = (0..=rest)
        .find(|&n| n + Radau5::saved_len(n) >= rest)
        .filter(|&n| n + Radau5::saved_len(n) == rest)
        .ok_or_else(|| format!("{} numbers are no saved model state", saved.len()))?;
    let (head, rest) = saved.split_at(n_head);
    let (state, solver) = rest.split_at(n);
    Ok((head, state, solver))
}

/// Logs the integrator statistics of the step that ended at `t` (category `logSolver`).
fn log_step(log: &mut dyn Log, t: f64, before: &SolverStats, after: &SolverStats) {
    if !log.enabled("logSolver") {
        return;
    }
    log.info(
        "logSolver",
        &format!(
            "t = {t}: {} steps ({} rejected), {} RHS, {} Jacobians",
            after.accepted_steps - before.accepted_steps,
            after.rejected_steps - before.rejected_steps,
            after.rhs_evals - before.rhs_evals,
            after.jacobian_evals - before.jacobian_evals
        ),
    );
}
