//! Value references shared by every model that has the variable (stable: append, never renumber).

/// The driver's: the integrator's mode and counters (23-26, 33-36).
pub use crate::fmu::driver::vr::*;

pub const U_REF: u32 = 0;
pub const P1: u32 = 1;
pub const P2: u32 = 2;
pub const P3: u32 = 3;
pub const P4: u32 = 4;
pub const U: u32 = 5;
pub const U_CV: u32 = 6;
pub const U_CBV: u32 = 7;
pub const Q1: u32 = 8;
pub const Q2: u32 = 9;
pub const Q3: u32 = 10;
pub const Q4: u32 = 11;
pub const X: u32 = 12;
pub const V: u32 = 13;
pub const F: u32 = 14;
pub const F_FR: u32 = 15;
pub const THETA: u32 = 16;
pub const OMEGA: u32 = 17;
pub const PAYLOAD_X: u32 = 18;
pub const PAYLOAD_Y: u32 = 19;
pub const X_V: u32 = 20;
pub const U_PCV: u32 = 21;
pub const P_X: u32 = 22;
/// The circuit's event indicators ([`crate::models::circuit::event_indicators`]).
pub const EVENT_U_REF: u32 = 27;
pub const EVENT_DEAD_BAND_UPPER: u32 = 28;
pub const EVENT_DEAD_BAND_LOWER: u32 = 29;
pub const X0: u32 = 30;
pub const FLEXIBLE: u32 = 31;
pub const START_P4: u32 = 32;
pub const TIP_DEFLECTION: u32 = 40;
/// Section angles: `SECTIONS + i` is `boom.section[i + 1].phi`.
pub const SECTIONS: u32 = 41;
/// Section rates: `SECTION_RATES + i` is `boom.section[i + 1].omega`.
pub const SECTION_RATES: u32 = 300;
/// Derivatives of the continuous states: `DERIVATIVES + k` is der() of state k of
/// HydraulicBoom's layout ([`crate::models::states`]).
pub const DERIVATIVES: u32 = 400;
/// Hydraulic parameters: [`hydraulic`] of their index in [`crate::hydraulics::params::PARAMS`].
pub const HYDRAULICS: u32 = 100;
/// `HYDRAULICS + 39` was `line.v_l1`, the volume of line 1, retired when line 1 became
/// quasi-static ([`crate::hydraulics::Circuit::line1_pressure`]); the parameters after it keep
/// their references.
const RETIRED_V_L1: usize = 39;

/// The value reference of the hydraulic parameter `PARAMS[k]`.
pub const fn hydraulic(k: usize) -> u32 {
    HYDRAULICS + k as u32 + (k >= RETIRED_V_L1) as u32
}
/// Boom parameters: `BOOM + index` in [`crate::mechanics::params::BOOM_PARAMS`].
pub const BOOM: u32 = 200;
/// Flexible-beam parameters: `BEAM + index` in [`crate::mechanics::params::BEAM_PARAMS`].
pub const BEAM: u32 = 250;
