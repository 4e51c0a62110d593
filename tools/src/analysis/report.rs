//! One analysis at one operating point: the coefficients of Table 6.1, the critical strokes
//! and the filters of Table 6.3, as a struct and as the JSON of `boomsim analyze --json`.

use super::criterion;
use super::feedback::{self, FilterResult};
use super::margins::Margins;
use super::operating_point::{Linearised, OperatingPoint, SteadyStateError};
use super::plant::{self, HParams};
use super::routh;
use boomsim::hydraulics::Circuit;
use boomsim::units::{BAR, MM};
use serde_json::{json, Value};

/// The default filters: `n_K` = 1..5 with `n_omega` = 2 (Table 6.3 and the filter of
/// eq. 6.3), and `n_K` = 1 with `n_omega` = 0.5 (the proposal of [1], Fig. 6.3).
pub const DEFAULT_FILTERS: [(f64, f64); 6] = [(1.0, 2.0), (2.0, 2.0), (3.0, 2.0), (4.0, 2.0), (5.0, 2.0), (1.0, 0.5)];

/// Everything `boomsim analyze` computes at one operating point.
#[derive(Debug, Clone)]
pub struct Analysis {
    pub op: OperatingPoint,
    pub lin: Linearised,
    pub h: HParams,
    /// Valve bandwidth `omega_v` of eq. 6.4 (rad/s).
    pub omega_v: f64,
    /// The uncompensated closed loop (eq. 2.82) is stable.
    pub stable_uncompensated: bool,
    /// Critical stroke by eq. 2.84 (m).
    pub xc_crit_exact: f64,
    /// Critical stroke by eq. 2.87 (m).
    pub xc_crit_simplified: f64,
    pub filters: Vec<FilterResult>,
}

/// Valve bandwidth of the circuit: `4 / T_s` with the rated reaction time 0.120 s (Table 4.2,
/// eq. 6.4): 33.3 rad/s as in Table 6.1.
pub fn default_omega_v() -> f64 {
    Circuit::default().dcv.omega_v
}

impl Analysis {
    /// Analyses `op` with valve bandwidth `omega_v` for the filters `(n_K, n_omega)` and any
    /// explicit filters `(K_f, omega_f)`.
    pub fn new(
        op: OperatingPoint,
        omega_v: f64,
        tuned: &[(f64, f64)],
        explicit: &[(f64, f64)],
    ) -> Result<Self, SteadyStateError> {
        let lin = op.linearise()?;
        let h = HParams::new(&op, &lin);
        let htf = h.h();
        let k_f1 = lin.c1 * op.mu_c * op.mu_p;
        let factors = explicit.iter().map(|&(k_f, omega_f)| (k_f / k_f1, omega_f / h.omega_n));
        let filters = tuned
            .iter()
            .copied()
            .chain(factors)
            .map(|(n_k, n_w)| feedback::evaluate(&op, &lin, &htf, h.omega_n, omega_v, n_k, n_w))
            .collect();
        Ok(Analysis {
            op,
            lin,
            h,
            omega_v,
            stable_uncompensated: plant::closed_loop(lin.c2, &htf).is_stable(),
            xc_crit_exact: criterion::xc_crit_exact(&op, &lin),
            xc_crit_simplified: criterion::xc_crit_simplified(&op),
            filters,
        })
    }

    /// The JSON report; the keys of the issue plus the operating point, the steady state and
    /// every crossover.
    pub fn to_json(&self) -> Value {
        let (op, lin, h) = (&self.op, &self.lin, &self.h);
        json!({
            "operating_point": {
                "x_c_mm": op.x_c / MM, "p4_bar": op.p4 / BAR, "mu_p": op.mu_p, "p_set_bar": op.p_set / BAR,
                "mass_kg": op.mass, "load_N": op.load, "beta1_MPa": op.beta1 / 1e6, "beta2_MPa": op.beta2 / 1e6,
                "C1_extra": op.c1_extra, "C2_extra": op.c2_extra, "omega_v": self.omega_v,
            },
            "p3_bar": lin.p3 / BAR,
            "u_cbv": lin.u_cbv,
            "C1": lin.c1, "C2": lin.c2, "K_qu": lin.k_qu, "K_qp": lin.k_qp,
            "kappa": h.kappa, "tau": h.tau, "omega_n": h.omega_n, "zeta": h.zeta,
            "C2_over_C1": lin.c2 / lin.c1,
            "required_ratio_exact": criterion::required_ratio(op, lin),
            "required_ratio_simplified": criterion::required_ratio_simplified(op),
            "stable_uncompensated": self.stable_uncompensated,
            "routh_rhp_poles_uncompensated":
                routh::rhp_roots(&plant::closed_loop(lin.c2, &h.h()).den),
            "xc_crit_exact_mm": self.xc_crit_exact / MM,
            "xc_crit_simplified_mm": self.xc_crit_simplified / MM,
            "filters": self.filters.iter().map(filter_json).collect::<Vec<_>>(),
        })
    }
}

fn filter_json(f: &FilterResult) -> Value {
    let m: &Margins = &f.margins;
    json!({
        "n_K": f.n_k, "n_omega": f.n_omega, "K_f": f.filter.k_f, "omega_f": f.filter.omega_f,
        "gain_margin_db": m.relevant_gain.map(|g| g.db),
        "gain_margin_omega": m.relevant_gain.map(|g| g.omega),
        "phase_margin_deg": m.relevant_phase.map(|p| p.deg),
        "phase_margin_omega": m.relevant_phase.map(|p| p.omega),
        "settling_time_s": f.settling_time,
        "stable": f.stable,
        "phase_crossovers": m.gain.iter().map(|g| json!({
            "omega": g.omega, "gain_margin_db": g.db, "changes_stability": g.changes_stability,
        })).collect::<Vec<_>>(),
        "gain_crossovers": m.phase.iter().map(|p| json!({
            "omega": p.omega, "phase_margin_deg": p.deg,
        })).collect::<Vec<_>>(),
    })
}

/// A short human-readable report.
pub fn text(a: &Analysis) -> String {
    let mut s = format!(
        "{}\nC1 = {:.4e} m^3/Pa, C2 = {:.4e} m^3/Pa, p3 = {:.2} bar, u_cbv = {:.4}\n\
         K_qu = {:.4e} m^3/s, K_qp = {:.4e} m^3/(s Pa)\n\
         H(s): kappa = {:.4e} m^4 s/kg, tau = {:.4e} s, omega_n = {:.2} rad/s, zeta = {:.4}\n\
         uncompensated: {}; x_c,crit = {} (exact, eq. 2.84), {} (simplified, eq. 2.87)\n\
         {:>4} {:>7} {:>11} {:>9} {:>9} {:>9} {:>8} {}\n",
        super::operating_point::describe(&a.op),
        a.lin.c1,
        a.lin.c2,
        a.lin.p3 / BAR,
        a.lin.u_cbv,
        a.lin.k_qu,
        a.lin.k_qp,
        a.h.kappa,
        a.h.tau,
        a.h.omega_n,
        a.h.zeta,
        if a.stable_uncompensated { "stable" } else { "unstable" },
        super::criterion::describe_critical_stroke(a.op.stroke, a.xc_crit_exact),
        super::criterion::describe_critical_stroke(a.op.stroke, a.xc_crit_simplified),
        "n_K",
        "n_omega",
        "K_f",
        "omega_f",
        "GM [dB]",
        "PM [deg]",
        "T_s [s]",
        "closed loop"
    );
    let opt = |x: Option<f64>, p: usize| x.map_or("-".into(), |v| format!("{v:.p$}"));
    for f in &a.filters {
        s += &format!(
            "{:>4} {:>7} {:>11.4e} {:>9.2} {:>9} {:>9} {:>8} {}\n",
            f.n_k,
            f.n_omega,
            f.filter.k_f,
            f.filter.omega_f,
            opt(f.margins.relevant_gain.map(|g| g.db), 2),
            opt(f.margins.relevant_phase.map(|p| p.deg), 1),
            opt(f.settling_time, 3),
            if f.stable { "stable" } else { "unstable" }
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn default_analysis() -> Analysis {
        Analysis::new(OperatingPoint::default(), default_omega_v(), &DEFAULT_FILTERS, &[]).unwrap()
    }

    /// The JSON carries every key of the issue, and the filters in the default order.
    #[test]
    fn json_has_the_required_keys() {
        let j = default_analysis().to_json();
        for k in
            ["C1", "C2", "K_qu", "K_qp", "kappa", "tau", "omega_n", "zeta", "xc_crit_exact_mm", "xc_crit_simplified_mm"]
        {
            assert!(j[k].is_number(), "{k}");
        }
        let filters = j["filters"].as_array().unwrap();
        assert_eq!(filters.len(), DEFAULT_FILTERS.len());
        for (f, (n_k, n_w)) in filters.iter().zip(DEFAULT_FILTERS) {
            assert_eq!((f["n_K"].as_f64(), f["n_omega"].as_f64()), (Some(n_k), Some(n_w)));
            for k in ["K_f", "omega_f", "gain_margin_db", "phase_margin_deg", "settling_time_s", "stable"] {
                assert!(f.get(k).is_some(), "{k}");
            }
        }
    }

    /// The thesis' own statements about the default operating point (section 2.3, 6.1), an
    /// independent source for the chain identification -> H(s) -> loop -> margins:
    /// - Table 6.1: omega_f = 0.5 omega_n = 41.91 rad/s, omega_v = 33.3 rad/s (4 digits given);
    /// - eq. 2.87: for mu_p = 3 unstable above s_c / 4 = 125 mm, so 250 mm is unstable;
    /// - Fig. 6.3: the filter of [1] (n_K = 1, n_omega = 0.5) with valve dynamics is unstable,
    ///   its loop gain never reaches 0 dB (no gain crossover);
    /// - Table 6.3 / guideline: n_K = 2..5 with n_omega = 2 give a stable loop with gain
    ///   margins in -6..-20 dB and phase margins "around 35 deg" (we accept 25-45 deg), filter a
    ///   (n_K = 2) settles fastest and the settling time grows with n_K (filter b "small
    ///   increase");
    /// - the final filter: K_f = 4.08e-12, omega_f = 168 rad/s (3 digits given).
    #[test]
    fn thesis_statements_hold() {
        let a = default_analysis();
        assert!((0.5 * a.h.omega_n - 41.91).abs() < 0.005 && (a.omega_v - 33.3).abs() < 0.05);
        assert!(!a.stable_uncompensated && a.xc_crit_simplified == 0.125);
        let fig_6_3 = &a.filters[5];
        assert!(!fig_6_3.stable && fig_6_3.margins.phase.is_empty());
        let table_6_3 = &a.filters[1..5];
        for f in table_6_3 {
            let gm = f.margins.relevant_gain.unwrap().db;
            let pm = f.margins.relevant_phase.unwrap().deg;
            assert!(f.stable && (-20.0..=-6.0).contains(&gm) && (25.0..=45.0).contains(&pm), "{f:?}");
        }
        let ts: Vec<f64> = table_6_3.iter().map(|f| f.settling_time.unwrap()).collect();
        assert!(ts.windows(2).all(|w| w[0] < w[1]), "{ts:?}");
        let b = &a.filters[2].filter;
        assert!((b.k_f / 4.08e-12 - 1.0).abs() < 0.005 && (b.omega_f - 168.0).abs() < 0.5);
    }
}
