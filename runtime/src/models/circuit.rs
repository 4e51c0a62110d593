//! The circuit of an FMU model ([`crate::hydraulics::circuit`]) from its parameter values, its
//! outputs and the tolerance scales of its states.

use super::table::param_value;
use super::vr;
use crate::fmu::Values;
use crate::hydraulics::circuit::{self, Circuit, Eval, N_STATES as N_CIRCUIT};
use crate::scalar::Scalar;

/// The circuit from the parameter values at [`vr::hydraulic`]; refuses inconsistent combinations.
pub(crate) fn circuit_from_values(values: &Values) -> Result<Circuit, String> {
    let mut circuit = Circuit::default();
    for (k, p) in crate::hydraulics::params::PARAMS.iter().enumerate() {
        (p.set)(&mut circuit, param_value(values, vr::hydraulic(k), &p.spec));
    }
    let cyl = &circuit.cylinder;
    if cyl.d_rod >= cyl.d_piston {
        return Err(format!("cylinder.d_rod = {} must be less than cylinder.d_piston = {}", cyl.d_rod, cyl.d_piston));
    }
    if circuit.dcv.x_db >= circuit.dcv.x_max {
        return Err(format!("valve.x_db = {} must be less than valve.x_max = {}", circuit.dcv.x_db, circuit.dcv.x_max));
    }
    Ok(circuit)
}

/// The loosest relative tolerance a BDF integrator needs for the circuit in Model Exchange
/// ([`crate::fmu::Model::MODEL_EXCHANGE_TOLERANCE`]): HydraulicBoom, rigid, u_ref -0.3 from rest,
/// 1 s under fmpy's CVode (`scripts/bench_interfaces.py --only tolerance`, docs/interfaces.md)
/// keeps p3 within 0.05 bar of the rtol 1e-9 reference at 1e-6, 0.3 bar at 1e-5, 1.4 bar at
/// 1e-4 and 6 bar at 1e-3; with the controller, scenario U rigid at 1e-4 lowers 3.3 % slow
/// (docs/interfaces.md). 1e-6 is also the DefaultExperiment's tolerance.
pub(crate) const ME_TOLERANCE: f64 = 1e-6;

/// Scales of the circuit states for the absolute tolerance `atol_i = rtol * scale_i`: 1 bar,
/// 1 mm of spool travel, full valve opening.
pub(crate) const CIRCUIT_SCALE: [f64; N_CIRCUIT] = [1e5, 1e5, 1e5, 1e-3, 1.0];

/// The outputs and locals that are circuit states: (value reference, index in the state).
const STATE_ROWS: [(u32, usize); N_CIRCUIT] = [
    (vr::P2, circuit::P2),
    (vr::P3, circuit::P3),
    (vr::P4, circuit::P4),
    (vr::X_V, circuit::X_V),
    (vr::U_CBV, circuit::U_CBV),
];

/// The circuit's outputs and locals (p1..Q4, cylinder.F, cylinder.F_fr, spool, compensator,
/// load-sensing pressure) for state `c` and its evaluation `e`, as (value reference, value).
pub(crate) fn circuit_rows<T: Scalar>(c: &[T; N_CIRCUIT], e: &Eval<T>) -> [(u32, T); 16] {
    let [s0, s1, s2, s3, s4] = STATE_ROWS.map(|(r, i)| (r, c[i]));
    [
        (vr::P1, e.p1),
        s0,
        s1,
        s2,
        (vr::U, e.u),
        (vr::U_CV, e.u_cv),
        s4,
        (vr::Q1, e.q[0]),
        (vr::Q2, e.q[1]),
        (vr::Q3, e.q[2]),
        (vr::Q4, e.q[3]),
        (vr::F, e.force),
        (vr::F_FR, e.f_friction),
        s3,
        (vr::U_PCV, e.u_pcv),
        (vr::P_X, e.p_x),
    ]
}

/// Writes [`circuit_rows`] into `values`.
pub(crate) fn circuit_outputs(c: &circuit::State, e: &Eval, values: &mut Values) {
    for (r, x) in circuit_rows(c, e) {
        values.set_real(r, x);
    }
}

/// The log categories of the models with the circuit: the integrator's, and the events where an
/// FMI 3.0 Co-Simulation step returned early.
pub(crate) const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logSolver", "Integrator statistics per communication step"),
    ("logEvents", "FMI 3.0 Co-Simulation with earlyReturnAllowed: steps that ended early at an event indicator's root"),
];

/// The circuit's event indicator variables, in the order of [`event_indicators`].
pub(crate) const EVENT_INDICATORS: &[u32] = &[vr::EVENT_U_REF, vr::EVENT_DEAD_BAND_UPPER, vr::EVENT_DEAD_BAND_LOWER];

/// The circuit's event indicators at spool position `x_v` and reference `u_ref`: the places
/// where its right-hand side jumps. `u_ref`: the spool demand jumps between -x_db and +x_db
/// through 0 ([`crate::hydraulics::dcv::Dcv::spool_reference`]); `x_v - x_db`, `x_v + x_db`: the
/// load-sensing pressure switches between p2 or p4 and tank at the edges of the closed dead band
/// ([`crate::hydraulics::dcv::Dcv::ls_pressure`]), and with it the compensator's demand. Elsewhere
/// the circuit is continuous: the orifices' roots are regularised and the valve openings only
/// saturate (kinks, no jumps).
pub(crate) fn event_indicators(circuit: &Circuit, x_v: f64, u_ref: f64, z: &mut [f64]) {
    let x_db = circuit.dcv.x_db;
    z.copy_from_slice(&[u_ref, x_v - x_db, x_v + x_db]);
}
