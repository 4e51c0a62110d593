//! The terminals of the FMUs (terminalsAndIcons.xml, FMI 3.0 section 2.4.9): the ports a user
//! connects as a whole instead of variable by variable. Two FMUs' terminals of the same name and
//! kind connect member by member (`matchingRule="plug"`: every member present on both sides, an
//! output to the input of the same `memberName`, a parameter set equal):
//!
//! - `rod` (kind `_boomsim_RodPlain`): the plain mechanical port, HydraulicCircuit's inputs x, v
//!   and output F against BoomMechanics' outputs x, v and input F (`port.coupling = 0`);
//! - `rod_tlm` (`_boomsim_RodTLM`): the TLM port, the waves c_h (circuit to mechanics) and c_m
//!   (back) and the line impedance Z_c, a parameter both sides must share (`port.coupling = 1`);
//! - `valve` (`_boomsim_ValveCommand`): the spool reference, the plants' input `valve.u_ref`
//!   against the controller's output `u`;
//! - `pressure` (`_boomsim_RodSidePressure`): the fed-back rod-side pressure, the plants'
//!   output `p4` against the controller's input `p` (thesis Fig. 6.1).

use super::port::vr as port;
use super::pressure_feedback_controller::vr as controller;
use super::vr;
use crate::fmu::Terminal;

const PLUG: &str = "plug";
const ROD_KIND: &str = "_boomsim_RodPlain";
const ROD_TLM_KIND: &str = "_boomsim_RodTLM";
const VALVE_KIND: &str = "_boomsim_ValveCommand";
const PRESSURE_KIND: &str = "_boomsim_RodSidePressure";

/// The plain mechanical port of HydraulicCircuit and BoomMechanics (the same value references).
pub const ROD: Terminal = Terminal {
    name: "rod",
    kind: ROD_KIND,
    matching_rule: PLUG,
    description: concat!(
        "Plain mechanical port at the rod (port.coupling = 0): stroke x and velocity v to the circuit, ",
        "force F to the mechanics"
    ),
    members: &[("x", vr::X), ("v", vr::V), ("F", vr::F)],
};

/// The TLM port of HydraulicCircuit and BoomMechanics.
pub const ROD_TLM: Terminal = Terminal {
    name: "rod_tlm",
    kind: ROD_TLM_KIND,
    matching_rule: PLUG,
    description: concat!(
        "TLM port at the rod (port.coupling = 1): waves c_h to the mechanics and c_m to the circuit, ",
        "the line impedance Z_c equal on both sides"
    ),
    members: &[("c_h", port::C_H), ("c_m", port::C_M), ("Z_c", port::Z_C)],
};

/// The plants' spool reference.
pub const VALVE: Terminal = Terminal {
    name: "valve",
    kind: VALVE_KIND,
    matching_rule: PLUG,
    description: "Spool reference of the valve (input), from the controller's command",
    members: &[("command", vr::U_REF)],
};

/// The plants' rod-side pressure.
pub const PRESSURE: Terminal = Terminal {
    name: "pressure",
    kind: PRESSURE_KIND,
    matching_rule: PLUG,
    description: "Rod-side pressure p4 (output), fed back to the controller",
    members: &[("p", vr::P4)],
};

/// The controller's command to the valve.
pub const CONTROLLER_VALVE: Terminal = Terminal {
    description: "Compensated spool command u (output), to the valve's reference",
    members: &[("command", controller::U)],
    ..VALVE
};

/// The controller's measured pressure.
pub const CONTROLLER_PRESSURE: Terminal = Terminal {
    description: "Measured rod-side pressure p (input), from the plant's p4",
    members: &[("p", controller::P)],
    ..PRESSURE
};
