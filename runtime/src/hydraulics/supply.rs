//! Pressure source and tank (Fig. 2.8, section 3.2.2).

/// Ideal pressure source with unlimited flow, and the tank.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Supply {
    /// Supply pressure `p_s` (Pa). Default 200 bar: the source of the simulation model of
    /// section 3.2.2, which the FMUs reproduce, and the LS relief setting of the PVB (Table
    /// 4.1). The parameter list gives 155 bar for the rig; any value well above the load
    /// pressure plus ~8 bar gives the same compensated flow (within 0.6 %, see the DCV tests).
    pub p_s: f64,
    /// Tank pressure `p_T` (Pa), 0 bar (parameter list).
    pub p_t: f64,
}
