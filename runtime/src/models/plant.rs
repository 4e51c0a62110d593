//! What the plant models (HydraulicBoom, HydraulicCircuit, BoomMechanics) share beyond their
//! variable rows: the [`ModelInfo`] defaults (the controller's too) and the check of a start or
//! restored state. The
//! driver ([`crate::fmu::driver`]) integrates them.
//!
//! [`ModelInfo`]: crate::fmu::ModelInfo

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

/// What the models share in their [`ModelInfo`]: the thesis' 15 s experiments at 1 ms, rtol
/// 1e-6, and the log category of the integrator (the plants'; the controller has its own).
pub(crate) const MODEL_INFO: crate::fmu::ModelInfo = crate::fmu::ModelInfo {
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
    terminals: &[],
};
