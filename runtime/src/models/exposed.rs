//! The continuous states the FMU models give Model Exchange, and their `der()` variables.
//!
//! FMI 2.0 fixes the number of states in modelDescription.xml, while the boom's degrees of freedom
//! follow its parameters (rigid: one; flexible: `boom.n2` + `boom.n3` sections, up to 32). The
//! boom's states are therefore the 32 section angles `boom.section[k].phi` and their rates
//! `boom.section[k].omega`, in both configurations: the slots beyond the last section repeat the
//! last one (as the outputs always did) with its derivative, and the rigid boom is its angle
//! theta2 in every slot (its Co-Simulation solver keeps the stroke, see [`super::boom::Boom`]).

use super::vr;
use crate::fmu::{ContinuousState, Seeds, Variable};
use crate::hydraulics::circuit::N_STATES as N_CIRCUIT;
use crate::mechanics::flexible_boom::MAX_SECTIONS;
use crate::scalar::Dual64;

/// Typical magnitudes of the boom states (see [`super::boom::Boom::scale`]): 2 mrad, 0.1 rad/s.
const PHI_NOMINAL: f64 = 2e-3;
const OMEGA_NOMINAL: f64 = 0.1;

/// The value reference of `der()` of slot `k` of HydraulicBoom's layout as it was with line 1
/// integrated (p1, the circuit's other five, then the boom's 64); the same in every model that
/// has the state. Slot 0, der(p1), is retired: line 1 is quasi-static
/// ([`crate::hydraulics::Circuit::line1_pressure`]).
const fn der_vr(k: usize) -> u32 {
    vr::DERIVATIVES + k as u32
}

/// The circuit's states p2..p4, spool position, load-holding opening, with their nominals
/// ([`super::circuit::CIRCUIT_SCALE`]).
pub(crate) const CIRCUIT_STATES: [ContinuousState; N_CIRCUIT] = {
    let r = [vr::P2, vr::P3, vr::P4, vr::X_V, vr::U_CBV];
    let mut s = [ContinuousState { state: 0, derivative: 0, nominal: 0.0 }; N_CIRCUIT];
    let mut k = 0;
    while k < N_CIRCUIT {
        s[k] = ContinuousState { state: r[k], derivative: der_vr(1 + k), nominal: super::circuit::CIRCUIT_SCALE[k] };
        k += 1;
    }
    s
};

/// The boom's states: the section angles, then their rates.
pub(crate) const BOOM_STATES: [ContinuousState; 2 * MAX_SECTIONS] = {
    let mut s = [ContinuousState { state: 0, derivative: 0, nominal: 0.0 }; 2 * MAX_SECTIONS];
    let mut k = 0;
    while k < MAX_SECTIONS {
        s[k] = ContinuousState { state: vr::SECTIONS + k as u32, derivative: der_vr(6 + k), nominal: PHI_NOMINAL };
        s[MAX_SECTIONS + k] = ContinuousState {
            state: vr::SECTION_RATES + k as u32,
            derivative: der_vr(6 + MAX_SECTIONS + k),
            nominal: OMEGA_NOMINAL,
        };
        k += 1;
    }
    s
};

/// HydraulicBoom's states: the circuit's, then the boom's.
pub(crate) const PLANT_STATES: [ContinuousState; N_CIRCUIT + 2 * MAX_SECTIONS] = {
    let mut s = [CIRCUIT_STATES[0]; N_CIRCUIT + 2 * MAX_SECTIONS];
    let mut k = 0;
    while k < s.len() {
        s[k] = if k < N_CIRCUIT { CIRCUIT_STATES[k] } else { BOOM_STATES[k - N_CIRCUIT] };
        k += 1;
    }
    s
};

/// The `der()` variables of the circuit's states.
pub(crate) const CIRCUIT_DERIVATIVES: [Variable; N_CIRCUIT] = [
    der("der(p2)", 1, "Pa/s", "bar/s"),
    der("der(p3)", 2, "Pa/s", "bar/s"),
    der("der(p4)", 3, "Pa/s", "bar/s"),
    der("der(valve.x_v)", 4, "m/s", "mm/s"),
    der("der(cbv.u_cbv)", 5, "1/s", ""),
];

/// The `der()` variables of the boom's states.
pub(crate) const BOOM_DERIVATIVES: [Variable; 2 * MAX_SECTIONS] = [
    der("der(boom.section[1].phi)", 6, "rad/s", "deg/s"),
    der("der(boom.section[2].phi)", 7, "rad/s", "deg/s"),
    der("der(boom.section[3].phi)", 8, "rad/s", "deg/s"),
    der("der(boom.section[4].phi)", 9, "rad/s", "deg/s"),
    der("der(boom.section[5].phi)", 10, "rad/s", "deg/s"),
    der("der(boom.section[6].phi)", 11, "rad/s", "deg/s"),
    der("der(boom.section[7].phi)", 12, "rad/s", "deg/s"),
    der("der(boom.section[8].phi)", 13, "rad/s", "deg/s"),
    der("der(boom.section[9].phi)", 14, "rad/s", "deg/s"),
    der("der(boom.section[10].phi)", 15, "rad/s", "deg/s"),
    der("der(boom.section[11].phi)", 16, "rad/s", "deg/s"),
    der("der(boom.section[12].phi)", 17, "rad/s", "deg/s"),
    der("der(boom.section[13].phi)", 18, "rad/s", "deg/s"),
    der("der(boom.section[14].phi)", 19, "rad/s", "deg/s"),
    der("der(boom.section[15].phi)", 20, "rad/s", "deg/s"),
    der("der(boom.section[16].phi)", 21, "rad/s", "deg/s"),
    der("der(boom.section[17].phi)", 22, "rad/s", "deg/s"),
    der("der(boom.section[18].phi)", 23, "rad/s", "deg/s"),
    der("der(boom.section[19].phi)", 24, "rad/s", "deg/s"),
    der("der(boom.section[20].phi)", 25, "rad/s", "deg/s"),
    der("der(boom.section[21].phi)", 26, "rad/s", "deg/s"),
    der("der(boom.section[22].phi)", 27, "rad/s", "deg/s"),
    der("der(boom.section[23].phi)", 28, "rad/s", "deg/s"),
    der("der(boom.section[24].phi)", 29, "rad/s", "deg/s"),
    der("der(boom.section[25].phi)", 30, "rad/s", "deg/s"),
    der("der(boom.section[26].phi)", 31, "rad/s", "deg/s"),
    der("der(boom.section[27].phi)", 32, "rad/s", "deg/s"),
    der("der(boom.section[28].phi)", 33, "rad/s", "deg/s"),
    der("der(boom.section[29].phi)", 34, "rad/s", "deg/s"),
    der("der(boom.section[30].phi)", 35, "rad/s", "deg/s"),
    der("der(boom.section[31].phi)", 36, "rad/s", "deg/s"),
    der("der(boom.section[32].phi)", 37, "rad/s", "deg/s"),
    der("der(boom.section[1].omega)", 38, "rad/s2", ""),
    der("der(boom.section[2].omega)", 39, "rad/s2", ""),
    der("der(boom.section[3].omega)", 40, "rad/s2", ""),
    der("der(boom.section[4].omega)", 41, "rad/s2", ""),
    der("der(boom.section[5].omega)", 42, "rad/s2", ""),
    der("der(boom.section[6].omega)", 43, "rad/s2", ""),
    der("der(boom.section[7].omega)", 44, "rad/s2", ""),
    der("der(boom.section[8].omega)", 45, "rad/s2", ""),
    der("der(boom.section[9].omega)", 46, "rad/s2", ""),
    der("der(boom.section[10].omega)", 47, "rad/s2", ""),
    der("der(boom.section[11].omega)", 48, "rad/s2", ""),
    der("der(boom.section[12].omega)", 49, "rad/s2", ""),
    der("der(boom.section[13].omega)", 50, "rad/s2", ""),
    der("der(boom.section[14].omega)", 51, "rad/s2", ""),
    der("der(boom.section[15].omega)", 52, "rad/s2", ""),
    der("der(boom.section[16].omega)", 53, "rad/s2", ""),
    der("der(boom.section[17].omega)", 54, "rad/s2", ""),
    der("der(boom.section[18].omega)", 55, "rad/s2", ""),
    der("der(boom.section[19].omega)", 56, "rad/s2", ""),
    der("der(boom.section[20].omega)", 57, "rad/s2", ""),
    der("der(boom.section[21].omega)", 58, "rad/s2", ""),
    der("der(boom.section[22].omega)", 59, "rad/s2", ""),
    der("der(boom.section[23].omega)", 60, "rad/s2", ""),
    der("der(boom.section[24].omega)", 61, "rad/s2", ""),
    der("der(boom.section[25].omega)", 62, "rad/s2", ""),
    der("der(boom.section[26].omega)", 63, "rad/s2", ""),
    der("der(boom.section[27].omega)", 64, "rad/s2", ""),
    der("der(boom.section[28].omega)", 65, "rad/s2", ""),
    der("der(boom.section[29].omega)", 66, "rad/s2", ""),
    der("der(boom.section[30].omega)", 67, "rad/s2", ""),
    der("der(boom.section[31].omega)", 68, "rad/s2", ""),
    der("der(boom.section[32].omega)", 69, "rad/s2", ""),
];

/// The derivative variable of slot `k` ([`der_vr`]).
const fn der(name: &'static str, k: usize, unit: &'static str, display: &'static str) -> Variable {
    Variable::real_local(name, der_vr(k), unit, display, "Time derivative of the continuous state (Model Exchange)")
}

/// The dual number of the value `x` of the variable `r` seeded with the sum of the seeds the
/// importer gave `r` among `knowns` (zero if it is none of them).
pub(crate) fn seeded(knowns: &[(u32, f64)], r: u32, x: f64) -> Dual64 {
    Dual64::new(x, knowns.iter().filter(|k| k.0 == r).map(|k| k.1).sum())
}

/// The continuous states `x` of `states` as dual numbers with their seeds among `knowns`.
pub(crate) fn seeded_states<const N: usize>(
    states: &[ContinuousState; N],
    x: &[f64; N],
    knowns: &[(u32, f64)],
) -> [Dual64; N] {
    std::array::from_fn(|k| seeded(knowns, states[k].state, x[k]))
}

/// Writes the directional derivative of each of the unknowns from the differentiated `rows`.
pub(crate) fn pick_derivatives(rows: &[(u32, Dual64)], seeds: Seeds<'_>) -> Result<(), String> {
    for (o, &r) in seeds.out.iter_mut().zip(seeds.unknowns) {
        *o = rows
            .iter()
            .find(|row| row.0 == r)
            .map(|row| row.1.eps)
            .ok_or_else(|| format!("vr {r} is not differentiated"))?;
    }
    Ok(())
}
