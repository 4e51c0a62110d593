//! Options and entry point of `boomsim analyze` (engineering units on the command line).

use super::operating_point::{p_set_for, OperatingPoint};
use super::report::{self, Analysis, DEFAULT_FILTERS};
use super::sweep;
use boomsim::mechanics::params::BoomParams;
use boomsim::mechanics::rigid_boom::RigidBoom;
use boomsim::units::{bar, mm, BAR, LPM};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `boomsim analyze`: linear stability and filter tuning at one operating point.
#[derive(clap::Args, Debug, Clone)]
pub struct AnalyzeArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also write the stroke/flow stability boundaries and the margin maps (CSV + PNG).
    #[arg(long)]
    pub sweep: bool,
    /// Output directory of --sweep.
    #[arg(long, default_value = "out/analysis")]
    pub out: PathBuf,
    /// Stroke x_c [mm] (Table 6.1: 250).
    #[arg(long, default_value_t = 250.0)]
    pub xc: f64,
    /// Steady rod-side pressure p4 [bar] (Table 6.1: 45).
    #[arg(long, default_value_t = 45.0)]
    pub p4: f64,
    /// Steady lowering flow into the rod side Q4 [l/min]: p4 is the pressure that passes it
    /// through the CBV (eq. 2.72, 2.73), replacing --p4.
    #[arg(long)]
    pub q4: Option<f64>,
    /// CBV pilot ratio mu_p [-] (default: 3, identified from Table 6.1).
    #[arg(long)]
    pub mu_p: Option<f64>,
    /// CBV set pressure [bar] (default: Table 4.3 setting of the valve with this mu_p).
    #[arg(long)]
    pub p_set: Option<f64>,
    /// Equivalent mass at the cylinder [kg] (default: 2456, identified from Table 6.1).
    #[arg(long)]
    pub mass: Option<f64>,
    /// Load force on the rod [N] (default: mass * g, eq. 2.69).
    #[arg(long)]
    pub load: Option<f64>,
    /// Payload [kg] of the rigid boom (chapter 2 geometry): the mass is its effective mass at
    /// the cylinder at --xc (eq. 2.68) and the load its static cylinder force (eq. 2.19),
    /// replacing --mass and --load.
    #[arg(long, conflicts_with_all = ["mass", "load"])]
    pub payload: Option<f64>,
    /// Bulk modulus [MPa] (parameter list: 1300).
    #[arg(long)]
    pub beta: Option<f64>,
    /// Extra capacitance on the piston side [cm^3/bar] (line 3, dead volume, hose).
    #[arg(long, default_value_t = 0.0)]
    pub c1_extra: f64,
    /// Extra capacitance on the rod side [cm^3/bar] (line 4, dead volume, hose).
    #[arg(long, default_value_t = 0.0)]
    pub c2_extra: f64,
    /// Valve bandwidth omega_v [rad/s] (default 33.3: 4 / 0.120 s, eq. 6.4).
    #[arg(long)]
    pub omega_v: Option<f64>,
    /// Filter gain factors n_K (eq. 6.6), comma separated; combined with every --n-omega.
    #[arg(long, value_delimiter = ',')]
    pub n_k: Vec<f64>,
    /// Filter frequency factors n_omega (eq. 6.7), comma separated.
    #[arg(long, value_delimiter = ',')]
    pub n_omega: Vec<f64>,
    /// Explicit filter gain K_f [m^4 s^2/kg] (with --omega-f; replaces the default filters).
    #[arg(long, requires = "omega_f")]
    pub k_f: Option<f64>,
    /// Explicit filter frequency omega_f [rad/s].
    #[arg(long, requires = "k_f")]
    pub omega_f: Option<f64>,
}

impl AnalyzeArgs {
    /// The operating point: Table 6.1 defaults overridden by the options.
    pub fn operating_point(&self) -> Result<OperatingPoint, String> {
        let d = OperatingPoint::default();
        let mu_p = self.mu_p.unwrap_or(d.mu_p);
        let x_c = mm(self.xc);
        let (mass, load) = match self.payload {
            Some(m_pl) => rigid_boom_load(m_pl, x_c, d.stroke)?,
            None => {
                let mass = self.mass.unwrap_or(d.mass);
                (mass, self.load.unwrap_or(d.load / d.mass * mass))
            }
        };
        let op = OperatingPoint {
            x_c,
            p4: bar(self.p4),
            mu_p,
            p_set: self.p_set.map_or_else(|| p_set_for(mu_p), bar),
            mass,
            load,
            beta1: self.beta.map_or(d.beta1, |b| b * 1e6),
            beta2: self.beta.map_or(d.beta2, |b| b * 1e6),
            c1_extra: self.c1_extra * 1e-6 / BAR,
            c2_extra: self.c2_extra * 1e-6 / BAR,
            ..d
        };
        let Some(q4) = self.q4 else { return Ok(op) };
        if !(q4 > 0.0) {
            return Err(format!("--q4 {q4} l/min must be > 0"));
        }
        op.with_flow(q4 * LPM / op.mu_c)
            .ok_or_else(|| format!("the CBV cannot pass --q4 {q4} l/min at this operating point, even fully open"))
    }

    /// `(n_K, n_omega)` pairs: the cross product of the options, or the defaults.
    fn tuned_filters(&self) -> Vec<(f64, f64)> {
        if self.n_k.is_empty() && self.n_omega.is_empty() {
            return if self.k_f.is_some() { Vec::new() } else { DEFAULT_FILTERS.to_vec() };
        }
        let n_k = if self.n_k.is_empty() { vec![1.0] } else { self.n_k.clone() };
        let n_w = if self.n_omega.is_empty() { vec![2.0] } else { self.n_omega.clone() };
        n_k.iter().flat_map(|&k| n_w.iter().map(move |&w| (k, w))).collect()
    }
}

/// `(m, F)`: the effective mass at the cylinder (eq. 2.68) and the static cylinder force
/// (eq. 2.19) of the rigid boom with the chapter 2 geometry and a payload of `m_pl` kg at stroke
/// `x_c` of a cylinder with `stroke`.
fn rigid_boom_load(m_pl: f64, x_c: f64, stroke: f64) -> Result<(f64, f64), String> {
    if !(0.0..=2000.0).contains(&m_pl) {
        return Err(format!("--payload {m_pl} kg is outside [0, 2000] kg (payload.m)"));
    }
    let boom = RigidBoom::new(&BoomParams { m_pl, ..BoomParams::default() }, stroke).map_err(|e| e.to_string())?;
    Ok((boom.m_eff(x_c), boom.static_force(x_c)))
}

/// Runs `boomsim analyze`; `root` is the workspace root (for the plot script and a relative
/// `--out`).
pub fn run(args: &AnalyzeArgs, root: &Path) -> Result<(), String> {
    let op = args.operating_point()?;
    let omega_v = args.omega_v.unwrap_or_else(report::default_omega_v);
    let explicit: Vec<(f64, f64)> = args.k_f.zip(args.omega_f).into_iter().collect();
    let a = Analysis::new(op, omega_v, &args.tuned_filters(), &explicit).map_err(|e| e.to_string())?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&a.to_json()).map_err(|e| e.to_string())?);
    } else {
        print!("{}", report::text(&a));
    }
    if args.sweep {
        let out = if args.out.is_absolute() { args.out.clone() } else { root.join(&args.out) };
        for p in sweep::write_all(&op, omega_v, &out)? {
            eprintln!("{}", p.display());
        }
        plot(root, &out)?;
    }
    Ok(())
}

/// Runs the Python package's `boomsim.plot_analysis` with the project's venv (or `python3`) to draw the PNGs.
fn plot(root: &Path, dir: &Path) -> Result<(), String> {
    let venv = root.join(".venv/bin/python");
    let python = if venv.exists() { venv } else { PathBuf::from("python3") };
    let status = Command::new(&python)
        .args(["-m", "boomsim.plot_analysis"])
        .arg(dir)
        .status()
        .map_err(|e| format!("cannot run {}: {e} (the CSV files are written)", python.display()))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("boomsim.plot_analysis failed ({status}); the CSV files are written"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use boomsim::units::LPM;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: AnalyzeArgs,
    }

    fn op(args: &str) -> Result<OperatingPoint, String> {
        Cli::try_parse_from(format!("analyze {args}").split_whitespace())
            .map_err(|e| e.to_string())?
            .args
            .operating_point()
    }

    /// `--payload`: at Table 6.1's stroke the rigid boom's static force over g is the 2456 kg the
    /// table implies (1 %: section "Table 6.1's hidden inputs"), and the effective mass is larger
    /// (the payload and arm swing about the joint, the cylinder's lever is short). `--q4`: the
    /// steady state carries that flow, Q3 = Q4 / mu_c (continuity, eq. 2.70, 2.71 at rest;
    /// 1e-9: the bisection's tolerance). Bad values are refused with the option's name.
    #[test]
    fn payload_and_flow_give_the_operating_point() {
        let g = BoomParams::default().g;
        let p = op("--xc 250 --payload 382.6").unwrap();
        assert!((p.load / g / 2456.0 - 1.0).abs() < 0.01, "{}", p.load / g);
        assert!(p.mass > p.load / g);
        let p = op("--xc 480 --payload 382.6 --q4 1.25").unwrap();
        assert!((p.flow().unwrap() * p.mu_c / (1.25 * LPM) - 1.0).abs() < 1e-9);
        assert!(op("--payload 2500").unwrap_err().contains("--payload 2500 kg is outside [0, 2000] kg"));
        assert!(op("--q4 0").unwrap_err().contains("--q4 0 l/min must be > 0"));
        assert!(op("--payload 300 --mass 2000").is_err());
    }
}
