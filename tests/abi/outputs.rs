//! The outputs of the state a step reached (issue 46): every doStep writes them and checks that
//! each is a finite number, so a step that leaves the model's valid range is the one that fails,
//! not the master's next read (or none, for a master that reads nothing).

use crate::common::Slave;
use boomsim::fmi2::api;
use boomsim::fmi2::types::*;

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

/// The end of the cylinder's strokes (Cylinder::stroke_domain), computed here from the data sheet
/// values of section 4.1.3 and 5.1.1: bore 65 mm, rod 35 mm, stroke 500 mm, dead volumes 50 cm^3.
/// Past the bottom stop by V_CH1 / A (15.07 mm) the piston-side chamber is gone.
fn strokes_where_a_chamber_is_gone() -> (f64, f64) {
    let a = std::f64::consts::PI / 4.0 * 0.065f64.powi(2);
    let a_rod_side = std::f64::consts::PI / 4.0 * (0.065f64.powi(2) - 0.035f64.powi(2));
    (-50e-6 / a, 0.5 + 50e-6 / a_rod_side)
}

/// The random-seed fuzzer's finding (sequence 1781628347514925975): BoomMechanics in FMI 2.0,
/// rigid boom, pushed in by cylinder.F = -4.9e7 N (inside the input's range of +-1e8 N, 500 times
/// the end stop's 1e8 N/m at 0.9 mm). The stop yields 0.49 m at that force; on its way the piston
/// passes the end of the cylinder (and then the triangle's dead centre, where the equations end,
/// and der() was NaN after an OK step). The step that carries the stroke past
/// the chamber's end is the one that fails: fmi2Error (FMI 2.0, 4.2.3: the slave cannot continue)
/// naming cylinder.x, its value and the valid range. Every step before it ends inside that range.
#[test]
fn a_force_past_the_stops_strength_fails_the_step_in_fmi2() {
    use boomsim::models::boom_mechanics::vr as bm;
    use boomsim::models::BoomMechanics as Bm;
    let (lo, hi) = strokes_where_a_chamber_is_gone();
    let s = Slave::<Bm>::initialized("bm2", &[]);
    assert_eq!(s.set_real(bm::F, -4.9e7), fmi2Status::OK);
    let h = 1e-3;
    let mut k = 0;
    while s.step(k as f64 * h, h) == fmi2Status::OK {
        let x = s.real(bm::X);
        assert!((lo..=hi).contains(&x), "an OK step ended at cylinder.x = {x} m");
        k += 1;
        assert!(k < 1000, "1 s at -4.9e7 N and the piston is still inside the cylinder");
    }
    let e = s.last_error();
    let range = e.split("valid: [").nth(1).and_then(|r| r.split(']').next()).unwrap_or_default();
    let bounds: Vec<f64> = range.split(", ").filter_map(|b| b.trim_end_matches(" m").parse().ok()).collect();
    // The message's bounds are the data sheet's to round-off (areas from pi d^2 / 4 either way).
    assert!(bounds.len() == 2 && (bounds[0] / lo - 1.0).abs() < 1e-12 && (bounds[1] / hi - 1.0).abs() < 1e-12, "{e}");
    assert!(e.contains("cylinder.x = -0.0"), "{e}");
    assert!(e.contains("Error state"), "{e}");
}

/// The same force in FMI 3.0: the step is fmi3Discard and the instance is as before the call
/// (FMI 3.0, 2.2.4): its stroke inside the range, and a step with a force the stop can hold goes on.
#[test]
fn a_force_past_the_stops_strength_is_discarded_in_fmi3() {
    use crate::fmi3_api::Inst;
    use boomsim::fmi3::types::fmi3Status;
    use boomsim::models::boom_mechanics::vr as bm;
    use boomsim::models::BoomMechanics as Bm;
    let (lo, hi) = strokes_where_a_chamber_is_gone();
    let i = Inst::<Bm>::initialized(false, &[]);
    assert_eq!(i.set(bm::F, -4.9e7), fmi3Status::OK);
    let (h, mut t) = (1e-3, 0.0);
    let status = loop {
        match i.step(t, h) {
            fmi3Status::OK => t += h,
            s => break s,
        }
        assert!(t < 1.0, "1 s at -4.9e7 N and the piston is still inside the cylinder");
    };
    assert_eq!(status, fmi3Status::Discard, "{}", i.last_error());
    let x = i.get(bm::X);
    assert!((lo..=hi).contains(&x), "after the Discard cylinder.x = {x} m");
    assert_eq!(i.set(bm::F, 0.0), fmi3Status::OK);
    assert_eq!(i.step(t, h), fmi3Status::OK, "{}", i.last_error());
}
