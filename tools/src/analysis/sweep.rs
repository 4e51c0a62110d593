//! `boomsim analyze --sweep`: the stability boundary along the stroke for every valve of
//! Table 4.3 and the margin maps of Fig. 6.4, as CSV tables (plotted by
//! `python -m boomsim.plot_analysis`).
//!
//! The valves are compared at the *same load and lowering flow* as the base operating point
//! (same spool opening, pressure compensated): each valve's `p4` follows from its `mu_p` and
//! `p_set` (eq. 2.72, 2.73, 2.85), since a fixed `p4` would leave the 1:1 valve closed.

use super::criterion;
use super::feedback;
use super::operating_point::{p_set_for, OperatingPoint, CBV_TABLE_4_3};
use super::plant::{closed_loop, HParams};
use boomsim::units::{BAR, LPM, MM};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Filter gain factors of Table 6.2 (Fig. 6.4).
pub const TABLE_6_2_N_K: [f64; 6] = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0];

/// The operating point with valve `mu_p` (Table 4.3 set pressure) carrying the flow `q3`.
fn with_valve(base: &OperatingPoint, mu_p: f64, q3: f64) -> Option<OperatingPoint> {
    OperatingPoint { mu_p, p_set: p_set_for(mu_p), ..*base }.with_flow(q3)
}

/// Closed-loop stability (eq. 2.82) along the stroke, 5 mm steps, per valve.
pub fn boundary_along_stroke(base: &OperatingPoint) -> Result<String, String> {
    let q3 = base.flow().map_err(|e| e.to_string())?;
    let mut csv =
        String::from("mu_p,p_set_bar,p4_bar,x_c_mm,C2_over_C1,required_exact,required_simplified,max_pole_re,stable\n");
    for (mu_p, _) in CBV_TABLE_4_3 {
        let Some(op) = with_valve(base, mu_p, q3) else { continue };
        for i in 0..=100 {
            let op = OperatingPoint { x_c: op.stroke * i as f64 / 100.0, ..op };
            let Ok(lin) = op.linearise() else { continue };
            let g = closed_loop(lin.c2, &HParams::new(&op, &lin).h());
            let re = g.max_pole_re();
            writeln!(
                csv,
                "{},{},{:.4},{:.1},{:.6},{:.6},{:.6},{:.6},{}",
                mu_p,
                op.p_set / BAR,
                op.p4 / BAR,
                op.x_c / MM,
                lin.c2 / lin.c1,
                criterion::required_ratio(&op, &lin),
                criterion::required_ratio_simplified(&op),
                re,
                re < 0.0
            )
            .expect("write to String");
        }
    }
    Ok(csv)
}

/// Critical stroke against the lowering flow into the rod side `Q4 = mu_c Q3`, 0.25..25 l/min,
/// per valve: low flows are the unstable ones (section 2.3).
pub fn boundary_over_flow(base: &OperatingPoint) -> String {
    let mut csv = String::from("mu_p,p_set_bar,q4_lpm,p4_bar,u_cbv,xc_crit_exact_mm,xc_crit_simplified_mm\n");
    for (mu_p, _) in CBV_TABLE_4_3 {
        for i in 1..=100 {
            let q4 = 0.25 * i as f64 * LPM;
            let Some(op) = with_valve(base, mu_p, q4 / base.mu_c) else { continue };
            let Ok(lin) = op.linearise() else { continue };
            writeln!(
                csv,
                "{},{},{:.2},{:.4},{:.6},{:.3},{:.3}",
                mu_p,
                op.p_set / BAR,
                q4 / LPM,
                op.p4 / BAR,
                lin.u_cbv,
                criterion::xc_crit_exact(&op, &lin) / MM,
                criterion::xc_crit_simplified(&op) / MM
            )
            .expect("write to String");
        }
    }
    csv
}

/// Margin maps of Fig. 6.4: stability-relevant GM and PM over `n_omega` (0.1..10, log) for
/// every `n_K` of Table 6.2, with closed-loop stability and settling time.
pub fn margin_maps(base: &OperatingPoint, omega_v: f64) -> Result<String, String> {
    let lin = base.linearise().map_err(|e| e.to_string())?;
    let hp = HParams::new(base, &lin);
    let h = hp.h();
    let mut csv = String::from("n_K,n_omega,K_f,omega_f,gain_margin_db,gain_margin_omega,phase_margin_deg,phase_margin_omega,n_phase_crossovers,n_gain_crossovers,stable,settling_time_s\n");
    let opt = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:.6}"));
    for n_k in TABLE_6_2_N_K {
        for i in 0..=80 {
            let n_w = 10f64.powf(-1.0 + 2.0 * i as f64 / 80.0);
            let r = feedback::evaluate(base, &lin, &h, hp.omega_n, omega_v, n_k, n_w);
            let (g, p) = (r.margins.relevant_gain, r.margins.relevant_phase);
            writeln!(
                csv,
                "{},{:.6},{:.6e},{:.4},{},{},{},{},{},{},{},{}",
                n_k,
                n_w,
                r.filter.k_f,
                r.filter.omega_f,
                opt(g.map(|g| g.db)),
                opt(g.map(|g| g.omega)),
                opt(p.map(|p| p.deg)),
                opt(p.map(|p| p.omega)),
                r.margins.gain.len(),
                r.margins.phase.len(),
                r.stable,
                opt(r.settling_time)
            )
            .expect("write to String");
        }
    }
    Ok(csv)
}

/// Writes the three tables into `dir`; returns their paths.
pub fn write_all(base: &OperatingPoint, omega_v: f64, dir: &Path) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let tables = [
        ("boundary_stroke.csv", boundary_along_stroke(base)?),
        ("boundary_flow.csv", boundary_over_flow(base)),
        ("margins.csv", margin_maps(base, omega_v)?),
    ];
    tables
        .into_iter()
        .map(|(name, csv)| {
            let path = dir.join(name);
            std::fs::write(&path, csv).map_err(|e| format!("{}: {e}", path.display()))?;
            Ok(path)
        })
        .collect()
}
