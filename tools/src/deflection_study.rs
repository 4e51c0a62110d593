//! The static deflection study of thesis 3.1.2 (`boomsim deflection`): experiment I conditions
//! (l1 = 0.6 m, l2 = 0.3 m, l_cyl = 0.93 m, 382.6 kg payload 80 mm inboard of the end and 70 mm
//! above the centre line, the defaults of [`BoomParams`]); the analytic end deflection (2.23-2.33),
//! the arm width it implies, and the lumped beam's end deflection for the section counts of
//! experiments I-III. Deflections are reported positive downwards, in mm.

use std::fmt;

use serde_json::json;

use boomsim::mechanics::deflection::AnalyticDeflection;
use boomsim::mechanics::flexible_boom::FlexibleBoom;
use boomsim::mechanics::params::{BeamParams, BoomParams};
use boomsim::mechanics::{Mechanics, MechanicsError};
use boomsim::units::DEG;

/// Cylinder length of experiment I (m).
pub const L_CYL: f64 = 0.93;
/// The thesis' analytic end deflection in experiment I (mm).
pub const THESIS_ANALYTIC_MM: f64 = 22.29;
/// Stroke range used to build the booms (the cylinder's 500 mm).
const STROKE: f64 = 0.5;

/// One lumped beam: n2 = 0 is a rigid part II.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedCase {
    pub n2: usize,
    pub n3: usize,
    pub tip_deflection_mm: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct DeflectionStudy {
    /// Boom angle theta2 at l_cyl = 0.93 m (deg).
    pub theta2_deg: f64,
    /// Arm width for which (2.23-2.33) give the thesis' 22.29 mm (mm).
    pub w_arm_mm: f64,
    /// Analytic end deflection with the default width (mm).
    pub analytic_mm: f64,
    /// Analytic end deflection of part III as a cantilever clamped at the mount (mm).
    pub cantilever_mm: f64,
    /// (15, 15), (rigid, 1..15), (1..10, 5).
    pub lumped: Vec<LumpedCase>,
}

/// The section counts of experiments I (15 + 15), II (rigid part II, 1..15) and III (1..10 + 5).
fn cases() -> impl Iterator<Item = (usize, usize)> {
    std::iter::once((15, 15)).chain((1..=15).map(|n3| (0, n3))).chain((1..=10).map(|n2| (n2, 5)))
}

/// Runs the study with the default parameters.
pub fn run() -> Result<DeflectionStudy, MechanicsError> {
    let p = BoomParams::default();
    let beam = BeamParams::default();
    let analytic = AnalyticDeflection::new(&p, &beam, L_CYL)?;
    let analytic_mm = -analytic.tip() * 1e3;
    let lumped = cases()
        .map(|(n2, n3)| {
            let boom = FlexibleBoom::new(&p, &BeamParams { n2, n3, ..beam }, STROKE)?;
            let q = boom.equilibrium(L_CYL - p.l_retracted)?.q;
            Ok(LumpedCase { n2, n3, tip_deflection_mm: -boom.tip_deflection(&q) * 1e3 })
        })
        .collect::<Result<_, MechanicsError>>()?;
    Ok(DeflectionStudy {
        theta2_deg: analytic.theta2 / DEG,
        w_arm_mm: beam.width_for(beam.i_z() * analytic_mm / THESIS_ANALYTIC_MM) * 1e3,
        analytic_mm,
        cantilever_mm: -analytic.cantilever_tip(beam.x_mount) * 1e3,
        lumped,
    })
}

impl DeflectionStudy {
    pub fn to_json(&self) -> serde_json::Value {
        json!({
            "theta2_deg": self.theta2_deg,
            "w_arm_mm": self.w_arm_mm,
            "analytic_mm": self.analytic_mm,
            "cantilever_mm": self.cantilever_mm,
            "lumped": self.lumped.iter().map(|c| json!({
                "n2": c.n2, "n3": c.n3, "tip_deflection_mm": c.tip_deflection_mm,
            })).collect::<Vec<_>>(),
        })
    }
}

impl fmt::Display for DeflectionStudy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "theta2 at l_cyl = {L_CYL} m: {:.3} deg", self.theta2_deg)?;
        writeln!(f, "arm width for {THESIS_ANALYTIC_MM} mm analytic: {:.2} mm", self.w_arm_mm)?;
        writeln!(f, "analytic end deflection (2.23-2.33): {:.4} mm", self.analytic_mm)?;
        writeln!(f, "analytic part III cantilever: {:.4} mm", self.cantilever_mm)?;
        writeln!(f, "  n2  n3  end deflection (mm)")?;
        for c in &self.lumped {
            let n2 = if c.n2 == 0 { "rigid".to_string() } else { c.n2.to_string() };
            writeln!(f, "{n2:>5} {:>3}  {:.4}", c.n3, c.tip_deflection_mm)?;
        }
        Ok(())
    }
}
