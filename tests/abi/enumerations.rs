//! Enumeration variables (the arm's damping law, the friction law, the solver mode, the port's
//! coupling) through both versions' C ABI: FMI 2.0 reads and writes them as Integers (2.2.7:
//! "fmi2Integer ... Enumeration"), FMI 3.0 only with fmi3GetInt64 and fmi3SetInt64 (2.4.7.4); a
//! value that is no item is refused naming the variable, the value and the items.

use crate::common::Slave;
use crate::fmi3_api::Inst;
use boomsim::fmi2::api as api2;
use boomsim::fmi2::types::fmi2Status;
use boomsim::fmi3::api as api3;
use boomsim::fmi3::types::fmi3Status;
use boomsim::fmu::Model;
use boomsim::models::{vr, HydraulicBoom};

/// The value reference of HydraulicBoom's variable `name`.
fn reference(name: &str) -> u32 {
    HydraulicBoom::VARIABLES.iter().find(|v| v.name == name).unwrap_or_else(|| panic!("{name}")).vr
}

/// p3 after 20 ms of lowering (u_ref = -0.3 from rest) of the flexible arm whose damping law is
/// set through FMI 2.0's fmi2SetInteger, with `law`'s value.
fn p3_fmi2(law: Option<i32>) -> f64 {
    let s = Slave::<HydraulicBoom>::new("e2");
    unsafe {
        assert_eq!(api2::setup_experiment::<HydraulicBoom>(s.c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::OK);
        assert_eq!(api2::enter_initialization_mode::<HydraulicBoom>(s.c), fmi2Status::OK);
        if let Some(law) = law {
            let r = reference("boom.damping");
            assert_eq!(api2::set_integer::<HydraulicBoom>(s.c, &r, 1, &law), fmi2Status::OK);
            let mut back = -1;
            assert_eq!(api2::get_integer::<HydraulicBoom>(s.c, &r, 1, &mut back), fmi2Status::OK);
            assert_eq!(back, law);
        }
        assert_eq!(api2::exit_initialization_mode::<HydraulicBoom>(s.c), fmi2Status::OK);
    }
    assert_eq!(s.set_real(vr::U_REF, -0.3), fmi2Status::OK);
    (0..20).for_each(|k| assert_eq!(s.step(k as f64 * 1e-3, 1e-3), fmi2Status::OK));
    s.real(vr::P3)
}

/// The same through FMI 3.0's fmi3SetInt64.
fn p3_fmi3(law: i64) -> f64 {
    let s = Inst::<HydraulicBoom>::new(false);
    let r = reference("boom.damping");
    unsafe {
        assert_eq!(api3::enter_initialization_mode::<HydraulicBoom>(s.c, false, 0.0, 0.0, true, 1.0), fmi3Status::OK);
        assert_eq!(api3::set_int64::<HydraulicBoom>(s.c, &r, 1, &law, 1), fmi3Status::OK);
        let mut back = -1i64;
        assert_eq!(api3::get_int64::<HydraulicBoom>(s.c, &r, 1, &mut back, 1), fmi3Status::OK);
        assert_eq!(back, law);
        assert_eq!(api3::exit_initialization_mode::<HydraulicBoom>(s.c), fmi3Status::OK);
    }
    assert_eq!(s.set(vr::U_REF, -0.3), fmi3Status::OK);
    (0..20).for_each(|k| assert_eq!(s.step(k as f64 * 1e-3, 1e-3), fmi3Status::OK));
    s.get(vr::P3)
}

/// The law set by its value through either version reaches the model: the same law gives the
/// same p3 bit for bit in both versions (one model, principle 7), and the thesis' law (0) gives
/// another p3 than the default (modal), so the setting is not ignored.
#[test]
fn the_damping_law_is_set_by_its_item_in_both_versions() {
    let thesis = p3_fmi2(Some(0));
    assert_eq!(thesis.to_bits(), p3_fmi3(0).to_bits());
    assert_eq!(p3_fmi2(None).to_bits(), p3_fmi3(2).to_bits(), "the default is modal (2)");
    assert_ne!(thesis.to_bits(), p3_fmi2(None).to_bits());
}

/// FMI 3.0: an Enumeration only through Int64 (2.4.7.4), Int64 only for an Enumeration, and a
/// value that is no item (or beyond Int32) refused with fmi3Error and a message naming the
/// variable, the value and the items.
#[test]
fn fmi3_reaches_enumerations_through_int64_only() {
    let (damping, n2) = (reference("boom.damping"), reference("boom.n2"));
    let wrong: [(&str, &dyn Fn(&Inst<HydraulicBoom>) -> fmi3Status, &str); 5] = [
        ("Int32 of an Enumeration", &|s| unsafe { api3::set_int32::<HydraulicBoom>(s.c, &damping, 1, &0, 1) }, "is a Enumeration, not a Int32"),
        ("Int64 of an Int32", &|s| unsafe { api3::get_int64::<HydraulicBoom>(s.c, &n2, 1, &mut 0, 1) }, "\"boom.n2\" (vr 256) is a Int32, not a Enumeration"),
        ("no item", &|s| unsafe { api3::set_int64::<HydraulicBoom>(s.c, &damping, 1, &4, 1) }, "boom.damping = 4 is no item of DampingLaw; valid: 0 (thesis), 1 (structural), 2 (modal), 3 (converged_modal)"),
        ("negative", &|s| unsafe { api3::set_int64::<HydraulicBoom>(s.c, &damping, 1, &-1, 1) }, "boom.damping = -1 is no item"),
        ("beyond Int32", &|s| unsafe { api3::set_int64::<HydraulicBoom>(s.c, &damping, 1, &(1 << 40), 1) }, "1099511627776 is no item"),
    ];
    for (what, call, says) in wrong {
        let s = Inst::<HydraulicBoom>::new(false);
        unsafe {
            assert_eq!(
                api3::enter_initialization_mode::<HydraulicBoom>(s.c, false, 0.0, 0.0, true, 1.0),
                fmi3Status::OK
            )
        };
        assert_eq!(call(&s), fmi3Status::Error, "{what}");
        assert!(s.last_error().contains(says), "{what}: {}", s.last_error());
    }
}

/// FMI 2.0: an Enumeration is an Integer to fmi2SetInteger, with the items as its values.
#[test]
fn fmi2_refuses_a_value_that_is_no_item() {
    let s = Slave::<HydraulicBoom>::new("e2");
    let r = reference("friction.model");
    unsafe {
        assert_eq!(api2::setup_experiment::<HydraulicBoom>(s.c, 0, 0.0, 0.0, 0, 0.0), fmi2Status::OK);
        assert_eq!(api2::enter_initialization_mode::<HydraulicBoom>(s.c), fmi2Status::OK);
        assert_eq!(api2::set_integer::<HydraulicBoom>(s.c, &r, 1, &3), fmi2Status::Error);
    }
    assert!(
        s.last_error()
            .contains("friction.model = 3 is no item of FrictionModel; valid: 0 (bak), 1 (ottestad), 2 (fitted)"),
        "{}",
        s.last_error()
    );
}
