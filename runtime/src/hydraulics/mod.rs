//! Hydraulic components of the circuit of thesis Fig. 2.8, one file per component, and the
//! circuit ODE with a mechanical port ([`circuit::Circuit`]). Pure physics in SI units;
//! pressures are gauge (absolute zero is `-units::P_ATM`).

pub mod cbv;
pub mod circuit;
pub mod cylinder;
pub mod dcv;
pub mod friction;
pub mod line;
pub mod orifice;
pub mod params;
pub mod pcv;
pub mod solve;
pub mod supply;

pub use circuit::{Circuit, Eval, State};
