//! The FMI 3.0 functions these FMUs must refuse, called with scratch buffers of the sizes
//! announced: the get and set functions of the types no variable has (`ops3::OTHER_TYPES`) and
//! the functions the model description does not provide (`ops3::REFUSED`).

use crate::fmi3::{Fmi3, Instance, Status};
use crate::ops::Arr;

/// fmi3Get<type> or fmi3Set<type> of `OTHER_TYPES[ty]` with `vr` (and as many values).
pub unsafe fn other_type(f: &Fmi3, c: Instance, ty: usize, set: bool, vr: &Arr<u32>) -> Status {
    let (p, n) = (vr.ptr(), vr.len());
    // Eight bytes per value hold any of the types; Binary has a size per value, too.
    let mut values = vec![0u64; n.max(1)];
    let mut sizes = vec![0usize; n.max(1)];
    let (v, s) = (values.as_mut_ptr(), sizes.as_mut_ptr());
    match (crate::ops3::OTHER_TYPES[ty], set) {
        ("Float32", false) => f.fmi3GetFloat32(c, p, n, v.cast(), n),
        ("Float32", true) => f.fmi3SetFloat32(c, p, n, v.cast(), n),
        ("Int8", false) => f.fmi3GetInt8(c, p, n, v.cast(), n),
        ("Int8", true) => f.fmi3SetInt8(c, p, n, v.cast(), n),
        ("UInt8", false) => f.fmi3GetUInt8(c, p, n, v.cast(), n),
        ("UInt8", true) => f.fmi3SetUInt8(c, p, n, v.cast(), n),
        ("Int16", false) => f.fmi3GetInt16(c, p, n, v.cast(), n),
        ("Int16", true) => f.fmi3SetInt16(c, p, n, v.cast(), n),
        ("UInt16", false) => f.fmi3GetUInt16(c, p, n, v.cast(), n),
        ("UInt16", true) => f.fmi3SetUInt16(c, p, n, v.cast(), n),
        ("UInt32", false) => f.fmi3GetUInt32(c, p, n, v.cast(), n),
        ("UInt32", true) => f.fmi3SetUInt32(c, p, n, v.cast(), n),
        ("UInt64", false) => f.fmi3GetUInt64(c, p, n, v.cast(), n),
        ("UInt64", true) => f.fmi3SetUInt64(c, p, n, v.cast(), n),
        ("Binary", false) => f.fmi3GetBinary(c, p, n, s, v.cast(), n),
        ("Binary", true) => f.fmi3SetBinary(c, p, n, s, v.cast(), n),
        (_, false) => f.fmi3GetClock(c, p, n, v.cast()),
        (_, true) => f.fmi3SetClock(c, p, n, v.cast()),
    }
}

/// fmi3<REFUSED[function]> with one value reference (0) and room for one value.
pub unsafe fn call(f: &Fmi3, c: Instance, function: usize) -> Status {
    let vr = [0u32];
    let (p, n) = (vr.as_ptr(), vr.len());
    let (mut a, mut b, mut q) = ([0u64; 1], [0u64; 1], [0u32; 1]);
    let mut x = [0.0f64; 1];
    let (a, b, q, x) = (a.as_mut_ptr(), b.as_mut_ptr(), q.as_mut_ptr(), x.as_mut_ptr());
    match function {
        0 => f.fmi3GetNumberOfVariableDependencies(c, 0, a.cast()),
        1 => f.fmi3GetVariableDependencies(c, 0, a.cast(), q, b.cast(), q, 1),
        2 => f.fmi3EnterConfigurationMode(c),
        3 => f.fmi3ExitConfigurationMode(c),
        4 => f.fmi3GetIntervalDecimal(c, p, n, x, q),
        5 => f.fmi3GetIntervalFraction(c, p, n, a, b, q),
        6 => f.fmi3GetShiftDecimal(c, p, n, x),
        7 => f.fmi3GetShiftFraction(c, p, n, a, b),
        8 => f.fmi3SetIntervalDecimal(c, p, n, x),
        9 => f.fmi3SetIntervalFraction(c, p, n, a, b),
        10 => f.fmi3SetShiftDecimal(c, p, n, x),
        11 => f.fmi3SetShiftFraction(c, p, n, a, b),
        12 => f.fmi3ActivateModelPartition(c, 0, 0.0),
        13 => f.fmi3EvaluateDiscreteStates(c),
        _ => f.fmi3GetOutputDerivatives(c, p, n, [1i32].as_ptr(), x, 1),
    }
}
