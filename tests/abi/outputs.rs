//! Outputs computed when the master reads them (issue 27): a read of outputs that the model holds
//! as states does not compute the others, and gives what the full computation gives.

use crate::common::Slave;
use boomsim::fmi2::api;
use boomsim::fmi2::types::*;
use boomsim::models::vr;
use boomsim::models::HydraulicBoom as Hb;

/// Lowering from rest (u_ref = -0.3, rigid boom, 100 doSteps of 1 ms, a limit cycle through the
/// CBV's opening): after each step the circuit's states p2, p3, p4, the spool and the CBV opening
/// read alone (`Model::held_output`, no outputs computed) equal bit for bit the same variables
/// read with q1, which makes the FMU compute every output (the second path, `Model::outputs`).
#[test]
fn held_outputs_equal_the_computed_ones() {
    let s = Slave::<Hb>::new("held");
    unsafe {
        assert_eq!(api::setup_experiment::<Hb>(s.c, 1, 1e-6, 0.0, 0, 0.0), fmi2Status::OK);
        assert_eq!(api::enter_initialization_mode::<Hb>(s.c), fmi2Status::OK);
        assert_eq!(s.set_boolean(vr::FLEXIBLE, false), fmi2Status::OK);
        assert_eq!(s.set_real(vr::U_REF, -0.3), fmi2Status::OK);
        assert_eq!(api::exit_initialization_mode::<Hb>(s.c), fmi2Status::OK);
    }
    let held = [vr::P2, vr::P3, vr::P4, vr::X_V, vr::U_CBV];
    let with_q1 = [vr::P2, vr::P3, vr::P4, vr::X_V, vr::U_CBV, vr::Q1];
    let (mut alone, mut computed) = ([0.0; 5], [0.0; 6]);
    for k in 0..100 {
        assert_eq!(s.step(k as f64 * 1e-3, 1e-3), fmi2Status::OK);
        unsafe {
            assert_eq!(api::get_real::<Hb>(s.c, held.as_ptr(), 5, alone.as_mut_ptr()), fmi2Status::OK);
            assert_eq!(api::get_real::<Hb>(s.c, with_q1.as_ptr(), 6, computed.as_mut_ptr()), fmi2Status::OK);
        }
        assert_eq!(alone.map(f64::to_bits), computed[..5].iter().map(|x| x.to_bits()).collect::<Vec<_>>()[..]);
    }
    assert!(computed[2] > 0.0 && computed[5] != 0.0, "{computed:?}");
}
