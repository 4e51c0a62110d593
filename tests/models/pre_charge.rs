//! Pre-charged starts (`start.p4`): the rod side trapped above tank at the start. The piston side
//! carries the load on top of it (eq. 2.85: p3 = p4 mu_c + F / A), and with the spool closed the
//! load stays at rest while the spool's leakage (eq. 2.47) bleeds the rod side to tank. The
//! cylinder's friction holds the small force the bleeding frees, so p3 stays between its start
//! value and the balance at the current p4 (no start-up transient).


use boomsim::fmi2::api;
use boomsim::fmi2::types::fmi2Status;
use boomsim::hydraulics::circuit::Circuit;
use boomsim::models::hydraulic_boom::vr;
use boomsim::models::HydraulicBoom;
use crate::common::Slave;

fn rigid(p4: f64) -> Slave<HydraulicBoom> {
    let s = Slave::<HydraulicBoom>::new("pre");
    unsafe {
        assert_eq!(api::setup_experiment::<HydraulicBoom>(s.c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::OK);
        assert_eq!(api::enter_initialization_mode::<HydraulicBoom>(s.c), fmi2Status::OK);
    }
    assert_eq!(s.set_boolean(vr::FLEXIBLE, false), fmi2Status::OK);
    assert_eq!(s.set_real(vr::START_P4, p4), fmi2Status::OK);
    assert_eq!(unsafe { api::exit_initialization_mode::<HydraulicBoom>(s.c) }, fmi2Status::OK);
    s
}

#[test]
fn a_pre_charged_rod_side_holds_the_load_and_bleeds_to_tank() {
    let cyl = Circuit::default().cylinder;
    let mu_c = cyl.area_b() / cyl.area_a();
    // The load's share of p3: the start at tank pressure (p4 = 0).
    let load = rigid(0.0).real(vr::P3);
    let p4_0 = 10e5;
    let s = rigid(p4_0);
    assert_eq!(s.real(vr::P4), p4_0);
    // Eq. 2.85 at the start, to round-off of the 60-bar p3.
    assert!((s.real(vr::P3) - (load + mu_c * p4_0)).abs() < 1e-9 * load);
    let (h, p3_0) = (1e-3, s.real(vr::P3));
    let mut p4 = p4_0;
    for k in 0..1000 {
        assert_eq!(s.step(k as f64 * h, h), fmi2Status::OK);
        let (p3, p4_now, v) = (s.real(vr::P3), s.real(vr::P4), s.real(vr::V));
        assert!(p4_now < p4 && p4_now > 0.0, "the rod side bleeds towards tank: {p4_now} Pa at step {k}");
        p4 = p4_now;
        // At rest: the only motion is the creep of the piston as the balance shifts (far below
        // 0.1 mm/s); p3 between the balance of eq. 2.85 and its start (0.01 bar of slack for
        // the piston's creep compressing the oil).
        assert!(v.abs() < 1e-4, "v = {v} m/s at step {k}");
        let balance = load + mu_c * p4;
        assert!(p3 > balance - 1e3 && p3 < p3_0 + 1e3, "p3 = {p3} Pa outside [{balance}, {p3_0}] at step {k}");
    }
    // About a minute's time constant (docs/models.md, "Pre-charged starts"): 1 s takes 0.5-5 % of it.
    let drop = (p4_0 - p4) / p4_0;
    assert!((0.005..0.05).contains(&drop), "{drop}");
}
