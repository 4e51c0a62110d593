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

/// Issue 46, defect 3 (found by an independent host's fuzzer): BoomMechanics in FMI 2.0 with
/// cylinder.F's derivative at -DBL_MAX. The step bounds the ramp to the input's range
/// (fmi2Warning "stops at the bound") and reaches a state with a non-finite output; that step
/// is the one that fails (fmi2Error naming the variable, the Error state: FMI 2.0, 4.3.1),
/// not the next read. A read of a variable that is finite is not refused because of another
/// (here the Integer solver.mode, which the fuzzer read).
#[test]
fn a_step_to_a_non_finite_output_fails_in_fmi2() {
    use boomsim::models::boom_mechanics::vr as bm;
    use boomsim::models::BoomMechanics as Bm;
    let s = Slave::<Bm>::initialized("bm2", &[]);
    assert_eq!(s.set_slope(bm::F, -f64::MAX), fmi2Status::OK);
    assert_eq!(s.step(0.0, 0.01), fmi2Status::Error);
    let e = s.last_error();
    assert!(e.contains("fmi2DoStep") && e.contains("the model left its valid range") && e.contains("Error state"), "{e}");
    let mut mode = -1;
    assert_eq!(unsafe { api::get_integer::<Bm>(s.c, &bm::SOLVER_MODE, 1, &mut mode) }, fmi2Status::OK, "{}", s.last_error());
    assert_eq!(mode, 0);
}

/// Issue 46, defect 2 (fuzzer sequence 14679269399127648895): BoomMechanics in FMI 3.0 pushed by
/// the largest rod forces its input allows (FORCE_RANGE, +-1e8 N, alternating every step of
/// 7.8 ms). A step whose state has a non-finite output is fmi3Discard, and the instance is as
/// before the call (FMI 3.0, 2.2.4); after every step that answers OK every output is finite and
/// the directional derivative is given (4.2.1: a step that returns fmi3OK completed it).
#[test]
fn a_step_to_a_non_finite_output_is_discarded_in_fmi3() {
    use crate::fmi3_api::Inst;
    use boomsim::fmi3::types::fmi3Status;
    use boomsim::models::boom_mechanics::vr as bm;
    use boomsim::models::BoomMechanics as Bm;
    let i = Inst::<Bm>::initialized(false, &[]);
    let outputs = [bm::X, bm::V, bm::THETA, bm::OMEGA, bm::PAYLOAD_X, bm::PAYLOAD_Y];
    let (h, mut t, mut discarded) = (0.0078, 0.0, 0);
    for k in 0..12 {
        assert_eq!(i.set(bm::F, if k % 2 == 0 { -1e8 } else { 1e8 }), fmi3Status::OK);
        match i.step(t, h) {
            fmi3Status::OK => {
                t += h;
                for r in outputs {
                    assert!(i.get(r).is_finite(), "vr {r} at t = {t}");
                }
                let (mut dx, seed) = (f64::NAN, 1.0);
                let status = unsafe {
                    boomsim::fmi3::api::get_directional_derivative::<Bm>(
                        i.c,
                        boomsim::fmi3::api::Derivative {
                            unknown: (&bm::V, 1),
                            known: (&bm::F, 1),
                            seed: (&seed, 1),
                            sensitivity: (&mut dx, 1),
                        },
                    )
                };
                assert_eq!(status, fmi3Status::OK, "after an OK step at t = {t}: {}", i.last_error());
            }
            fmi3Status::Discard => {
                discarded += 1;
                // The same step again from the same time: the instance is where it was.
                assert_eq!(i.set(bm::F, 0.0), fmi3Status::OK);
                assert_eq!(i.step(t, h), fmi3Status::OK, "{}", i.last_error());
                t += h;
            }
            s => panic!("step {k}: {s:?} {}", i.last_error()),
        }
    }
    assert!(discarded > 0, "the forces of the fuzzer's sequence drove the boom out of its valid range");
}
