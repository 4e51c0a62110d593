//! Options and entry point of `boomsim linearize` (engineering units on the command line).

use super::directional::{circuit_model, CIRCUIT_OUTPUTS};
use super::linearize::{crossovers, operating_point, LinearModel, Point, DEFAULT_OUTPUTS};
use super::modes::parameter_change;
use super::sine_test::{sine_response, AMPLITUDE, SETTLE};
use crate::arrays::{self, Array};
use boomsim::control::HighPassFeedback;
use boomsim::fmu::log::num;
use boomsim::fmu::Value;
use nalgebra::{Complex, DMatrix};
use serde_json::{json, Value as Json};
use std::path::PathBuf;

/// `boomsim linearize`: the HydraulicBoom's linear model at an operating point.
#[derive(clap::Args, Debug, Clone)]
pub struct LinearizeArgs {
    /// The model: HydraulicBoom (circuit and boom; input valve.u_ref) or HydraulicCircuit (the
    /// circuit alone with its plain port, through its own directional derivatives; inputs
    /// valve.u_ref, cylinder.x, cylinder.v; default outputs cylinder.F, p3, p4), at the
    /// HydraulicBoom's steady lowering.
    #[arg(long, default_value = "HydraulicBoom", value_parser = ["HydraulicBoom", "HydraulicCircuit"])]
    pub model: String,
    /// The boom: rigid or flexible (the lumped arm, boom.n2 + boom.n3 sections).
    #[arg(long, default_value = "flexible", value_parser = ["rigid", "flexible"])]
    pub boom: String,
    /// Spool reference of the steady lowering (< 0 lowers; experiment B: -0.05).
    #[arg(long, default_value_t = -0.05)]
    pub u_ref: f64,
    /// Stroke of the steady lowering [mm] (Table 6.1's point: 250).
    #[arg(long, default_value_t = 250.0)]
    pub stroke: f64,
    /// Instead: at rest with the boom horizontal, spool and CBV closed, no friction (`boomsim
    /// eigen`'s point).
    #[arg(long, conflicts_with_all = ["u_ref", "stroke", "at"])]
    pub rest: bool,
    /// Rod-side pressure trapped at rest [bar] (with --rest; default tank pressure).
    #[arg(long, requires = "rest")]
    pub p4: Option<f64>,
    /// Instead: the state at T seconds after the reference steps to --u-ref at rest at --start
    /// (a lowering without a steady state, such as experiment U's limit cycle).
    #[arg(long, value_name = "T", conflicts_with = "stroke")]
    pub at: Option<f64>,
    /// Start stroke of --at [mm] (chapter 7's experiments: 480).
    #[arg(long, default_value_t = 480.0, requires = "at")]
    pub start: f64,
    /// Close the loop with the high-pass pressure feedback (eq. 6.2; defaults: experiment B,
    /// K_f = 1.24e-11 m^4 s^2/kg, omega_f = 35.8 rad/s) and report its margins.
    #[arg(long)]
    pub feedback: bool,
    /// Filter gain K_f [m^4 s^2/kg] of --feedback.
    #[arg(long, requires = "feedback")]
    pub k_f: Option<f64>,
    /// Filter corner frequency omega_f [rad/s] of --feedback.
    #[arg(long, requires = "feedback")]
    pub omega_f: Option<f64>,
    /// An output by name (repeatable; default p3, p4, cylinder.x, cylinder.v,
    /// boom.tip_deflection).
    #[arg(long = "output", value_name = "NAME")]
    pub outputs: Vec<String>,
    /// A parameter of the HydraulicBoom, NAME=VALUE (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub set: Vec<String>,
    /// Add the frequency response of every output to valve.u_ref (0.1 to 100 Hz, 40 points per
    /// decade) to the JSON, and at a steady lowering that of p4 in section 2.3's reduced model
    /// (eq. 2.76, 2.81, 6.4; with --feedback 6.8's loop) at the same point with the rigid boom;
    /// with --feedback also the loop transfer function L (the margins' open loop).
    #[arg(long)]
    pub bode: bool,
    /// With --feedback at a steady lowering: p4's response to a 2 % swing of the reference at
    /// these frequencies [Hz, comma separated] measured on the nonlinear closed loop (the sine
    /// test; about 0.1 s per frequency rigid, 0.5 s flexible), added to the JSON and the table.
    #[arg(long, value_delimiter = ',', requires = "feedback", conflicts_with_all = ["rest", "at"])]
    pub sine: Vec<f64>,
    /// Print JSON: the point, names and units, A, B, C, D, eigenvalues, margins, Bode data.
    #[arg(long)]
    pub json: bool,
    /// Also write the model to FILE: .json (as --json), .npz (numpy) or .mat (MATLAB, Level 5).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// Frequencies of the margins' search (rad/s): 0.01 to 10 000.
const MARGIN_BAND: (f64, f64) = (1e-2, 1e4);

/// Runs `boomsim linearize`.
pub fn run(args: &LinearizeArgs) -> Result<(), String> {
    if let Some(path) = &args.out {
        if !["json", "npz", "mat"].iter().any(|e| path.extension().is_some_and(|x| x == *e)) {
            return Err(format!("--out {}: the extension must be .json, .npz or .mat", path.display()));
        }
    }
    let mut changes: Vec<(&str, Value)> = vec![("boom.flexible", Value::Boolean(args.boom == "flexible"))];
    for arg in &args.set {
        let (v, value) = parameter_change(arg)?;
        changes.push((v.name, value));
    }
    if !(-1.0..=1.0).contains(&args.u_ref) {
        return Err(format!("--u-ref {} is outside [-1, 1] (valve.u_ref's range)", args.u_ref));
    }
    let feedback = args.feedback.then(|| {
        let d = HighPassFeedback::default();
        HighPassFeedback { k_f: args.k_f.unwrap_or(d.k_f), omega_f: args.omega_f.unwrap_or(d.omega_f), ..d }
    });
    if let Some(f) = &feedback {
        for (k, x) in [f.k_f, f.omega_f].into_iter().enumerate() {
            let p = &boomsim::control::FEEDBACK_PARAMS[k].spec;
            if !(p.min..=p.max).contains(&x) {
                let (flag, lo, hi) = (["k-f", "omega-f"][k], num(p.min), num(p.max));
                return Err(format!("--{flag} {} is outside [{lo}, {hi}] {} ({})", num(x), p.unit, p.name));
            }
        }
    }
    let point = if args.rest {
        if let Some(p) = args.p4.filter(|p| !(0.0..=100.0).contains(p)) {
            return Err(format!("--p4 {p} bar is outside [0, 100] bar (start.p4's range)"));
        }
        Point::Rest { p4: args.p4.map(|p| p * 1e5) }
    } else if let Some(t) = args.at {
        if !(t > 0.0 && t <= 1000.0) {
            return Err(format!("--at {t} s is outside (0, 1000] s"));
        }
        Point::Time { u_ref: args.u_ref, stroke: args.start * 1e-3, t, feedback }
    } else {
        Point::Lowering { u_ref: args.u_ref, stroke: args.stroke * 1e-3 }
    };
    let circuit = args.model == "HydraulicCircuit";
    let outputs: Vec<&str> = match (args.outputs.is_empty(), circuit) {
        (true, true) => CIRCUIT_OUTPUTS.to_vec(),
        (true, false) => DEFAULT_OUTPUTS.to_vec(),
        (false, _) => args.outputs.iter().map(String::as_str).collect(),
    };
    // The HydraulicBoom's point (for the sine test), or HydraulicCircuit's model at the same.
    let (open, boom_point) = if circuit {
        let Point::Lowering { u_ref, stroke } = point else {
            return Err("--model HydraulicCircuit is linearised at a steady lowering (its port's stroke and velocity \
                        those of the HydraulicBoom there), not with --rest or --at"
                .into());
        };
        if !args.sine.is_empty() {
            return Err("--sine drives the HydraulicBoom's closed loop; not with --model HydraulicCircuit".into());
        }
        (circuit_model(&changes, u_ref, stroke, &outputs)?, None)
    } else {
        let o = operating_point(point, &changes)?;
        (super::linearize::linearize(&o.plant, &o.x, o.u_ref, &outputs)?, Some(o))
    };
    let model = match &feedback {
        Some(f) => {
            let mut closed = open.closed_loop(f)?;
            if let Some(x_f) = boom_point.as_ref().and_then(|o| o.filter) {
                *closed.x0.last_mut().expect("the filter state") = x_f;
            }
            closed
        }
        None => open.clone(),
    };
    let margins = match &feedback {
        Some(f) => Some(crossovers(|w| open.open_loop(f, w).expect("p4 is a state"), MARGIN_BAND.0, MARGIN_BAND.1)),
        None => None,
    };
    let mut report = report(args, point, &model, feedback.as_ref(), margins.as_ref());
    if let (Point::Lowering { stroke, .. }, false) = (point, circuit) {
        if args.bode {
            report["bode"]["reduced_p4"] = reduced_p4(&changes, stroke, &open, feedback.as_ref())?;
        }
    }
    if let (Some(f), true) = (&feedback, args.bode) {
        // The loop transfer function whose margins are reported: L(jw) cut at the spool reference.
        let l: Vec<Complex<f64>> = bode_frequencies()
            .iter()
            .map(|f_hz| open.open_loop(f, f_hz * std::f64::consts::TAU))
            .collect::<Result<_, _>>()?;
        report["bode"]["open_loop"] = json!({"gain": l.iter().map(|l| l.norm()).collect::<Vec<_>>(),
            "phase_deg": unwrap(l.iter().map(|l| l.arg().to_degrees()))});
    }
    if let (Some(f), Some(o)) = (&feedback, &boom_point) {
        let mut sines = Vec::new();
        for &f_hz in &args.sine {
            if !(f_hz > 0.0 && f_hz <= 100.0) {
                return Err(format!("--sine {f_hz} Hz is outside (0, 100] Hz"));
            }
            let s = sine_response(&o.plant, &o.x, o.u_ref, f, f_hz)?;
            sines.push(json!({"frequency_hz": f_hz, "output": "p4", "gain": s.response.norm(),
                "phase_deg": s.response.arg().to_degrees(), "stroke_mm": s.stroke * 1e3}));
        }
        if !sines.is_empty() {
            report["sine"] = json!({"amplitude": AMPLITUDE, "settle_s": SETTLE, "points": sines});
        }
    }
    if let Some(path) = &args.out {
        if path.extension().is_some_and(|e| e == "json") {
            std::fs::write(path, report.to_string()).map_err(|e| format!("{}: {e}", path.display()))?;
        } else {
            arrays::write(path, &named_arrays(&model))?;
        }
    }
    if args.json {
        println!("{report}");
    } else {
        print!("{}", text(&report, &model));
    }
    Ok(())
}

/// The model as named arrays for .npz and .mat.
fn named_arrays(m: &LinearModel) -> Vec<(&'static str, Array)> {
    let names = |s: &[super::linearize::Signal]| Array::Strings(s.iter().map(|s| s.name.clone()).collect());
    let units = |s: &[super::linearize::Signal]| Array::Strings(s.iter().map(|s| s.unit.clone()).collect());
    let column = |v: &[f64]| Array::Column(v.to_vec());
    vec![
        ("A", Array::Real(m.a.clone())),
        ("B", Array::Real(m.b.clone())),
        ("C", Array::Real(m.c.clone())),
        ("D", Array::Real(m.d.clone())),
        ("x0", column(&m.x0)),
        ("u0", column(&m.u0)),
        ("y0", column(&m.y0)),
        ("state_names", names(&m.states)),
        ("state_units", units(&m.states)),
        ("input_names", names(&m.inputs)),
        ("input_units", units(&m.inputs)),
        ("output_names", names(&m.outputs)),
        ("output_units", units(&m.outputs)),
        ("eigenvalues", Array::Complex(m.eigenvalues())),
    ]
}

/// The frequencies of `--bode` (Hz): 0.1 to 100, 40 per decade.
fn bode_frequencies() -> Vec<f64> {
    (0..=120).map(|k| 0.1 * 10f64.powf(k as f64 / 40.0)).collect()
}

/// p4's response to the reference in section 2.3's reduced model at the point of `open` (its p4
/// and stroke, the same parameters with the rigid boom's effective mass and load):
/// `-Q_rated G_v / (C2 s + H)` (eq. 2.76, 2.81 and the valve lag eq. 6.4, in flows per unit
/// opening; negative: opening towards lowering raises p4), with the feedback
/// `-Q_rated G_v / (C2 s + H + G_f G_v)` (Fig. 6.2, eq. 6.8's denominator).
fn reduced_p4(
    changes: &[(&str, Value)],
    stroke: f64,
    open: &LinearModel,
    f: Option<&HighPassFeedback>,
) -> Result<Json, String> {
    use super::feedback::{filter, valve};
    use super::plant::{admittance, HParams};
    let rigid = [("boom.flexible", Value::Boolean(false))];
    let values = super::modes::plant_values(changes.iter().cloned().chain(rigid))?;
    let plant = boomsim::models::hydraulic_boom::Plant::from_values(&values)?;
    let boomsim::models::hydraulic_boom::Boom::Rigid(boom) = &plant.boom else { unreachable!("built rigid") };
    let p4 = open.x0[open.state("p4")?];
    let op = super::OperatingPoint::of_circuit(&plant.circuit, boom, stroke, p4);
    let lin = op.linearise().map_err(|e| format!("the reduced model at this point: {e}"))?;
    let (y, dcv) = (admittance(lin.c2, &HParams::new(&op, &lin).h()), &plant.circuit.dcv);
    let gv = valve(dcv.omega_v);
    let h: Vec<Complex<f64>> = bode_frequencies()
        .iter()
        .map(|f_hz| {
            let w = f_hz * std::f64::consts::TAU;
            let feedback = f.map_or(Complex::new(0.0, 0.0), |f| filter(f).at(w) * gv.at(w));
            -dcv.q_rated * gv.at(w) / (y.at(w) + feedback)
        })
        .collect();
    Ok(json!({"gain": h.iter().map(|h| h.norm()).collect::<Vec<_>>(),
              "phase_deg": unwrap(h.iter().map(|h| h.arg().to_degrees()))}))
}

/// Natural frequency (Hz) and damping ratio of an eigenvalue.
fn mode(l: &Complex<f64>) -> (f64, f64) {
    (l.norm() / std::f64::consts::TAU, if l.norm() > 0.0 { -l.re / l.norm() } else { 1.0 })
}

fn report(
    args: &LinearizeArgs,
    point: Point,
    m: &LinearModel,
    feedback: Option<&HighPassFeedback>,
    margins: Option<&(Vec<super::linearize::Crossover>, Vec<super::linearize::Crossover>)>,
) -> Json {
    let rows = |a: &DMatrix<f64>| a.row_iter().map(|r| r.iter().copied().collect::<Vec<f64>>()).collect::<Vec<_>>();
    let signals =
        |s: &[super::linearize::Signal]| s.iter().map(|s| json!({"name": s.name, "unit": s.unit})).collect::<Vec<_>>();
    let point = match point {
        Point::Lowering { u_ref, stroke } => json!({"kind": "lowering", "u_ref": u_ref, "stroke_mm": stroke * 1e3}),
        Point::Rest { p4 } => json!({"kind": "rest", "p4_bar": p4.unwrap_or(0.0) / 1e5}),
        Point::Time { u_ref, stroke, t, .. } => {
            json!({"kind": "time", "u_ref": u_ref, "start_mm": stroke * 1e3, "t": t})
        }
    };
    let eig = m
        .eigenvalues()
        .iter()
        .map(|l| {
            let (f, z) = mode(l);
            json!({"re": l.re, "im": l.im, "frequency_hz": f, "damping_ratio": z})
        })
        .collect::<Vec<_>>();
    let mut out = json!({
        "point": point,
        "model": args.model,
        "boom": args.boom,
        "set": args.set,
        "feedback": feedback.map(|f| json!({"K_f": f.k_f, "omega_f": f.omega_f, "Q_rated": f.q_rated})),
        "states": signals(&m.states),
        "inputs": signals(&m.inputs),
        "outputs": signals(&m.outputs),
        "A": rows(&m.a), "B": rows(&m.b), "C": rows(&m.c), "D": rows(&m.d),
        "x0": m.x0, "u0": m.u0, "y0": m.y0,
        "eigenvalues": eig,
    });
    if let Some((gain, phase)) = margins {
        let list = |c: &[super::linearize::Crossover], key: &str| {
            c.iter()
                .map(|c| json!({"omega": c.omega, "frequency_hz": c.omega / std::f64::consts::TAU, key: c.margin}))
                .collect::<Vec<_>>()
        };
        out["margins"] = json!({"gain": list(gain, "db"), "phase": list(phase, "deg")});
    }
    if args.bode {
        let f = bode_frequencies();
        let h: Vec<DMatrix<Complex<f64>>> = f.iter().map(|f| m.frequency_response(f * std::f64::consts::TAU)).collect();
        let channels = (0..m.outputs.len())
            .map(|j| {
                let phase = unwrap(h.iter().map(|h| h[(j, 0)].arg().to_degrees()));
                json!({"output": m.outputs[j].name, "input": m.inputs[0].name,
                       "gain": h.iter().map(|h| h[(j, 0)].norm()).collect::<Vec<_>>(), "phase_deg": phase})
            })
            .collect::<Vec<_>>();
        out["bode"] = json!({"frequency_hz": f, "channels": channels});
    }
    out
}

/// Phases (deg) without jumps of 360 between neighbours.
fn unwrap(phases: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for p in phases {
        let mut q = p;
        if let Some(prev) = out.last() {
            q -= 360.0 * ((q - prev) / 360.0).round();
        }
        out.push(q);
    }
    out
}

/// The table `boomsim linearize` prints.
fn text(report: &Json, m: &LinearModel) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} ({} boom) linearised at {}",
        report["model"].as_str().unwrap_or(""),
        report["boom"].as_str().unwrap_or(""),
        report["point"]
    );
    let _ = writeln!(
        s,
        "states {}, inputs {}, outputs {}; the operating point:",
        m.states.len(),
        m.inputs.len(),
        m.outputs.len()
    );
    for (sig, y) in m.outputs.iter().zip(&m.y0) {
        let _ = writeln!(s, "  {:<22} {:>14.6e} {}", sig.name, y, sig.unit);
    }
    let _ = writeln!(s, "eigenvalues (one of each conjugate pair), slowest first:");
    for l in m.eigenvalues().iter().filter(|l| l.im >= 0.0) {
        let (f, z) = mode(l);
        let kind = if l.im == 0.0 { "real" } else { "" };
        let _ = writeln!(s, "  {:>12.4} {:+12.4}j 1/s   {:9.3} Hz  zeta {:8.4} {kind}", l.re, l.im, f, z);
    }
    for p in report["sine"]["points"].as_array().into_iter().flatten() {
        let _ = writeln!(
            s,
            "sine test at {:6.2} Hz: p4 / u_ref {:.4e} Pa at {:7.2} deg (nonlinear, mean stroke {:.1} mm)",
            p["frequency_hz"].as_f64().unwrap_or(f64::NAN),
            p["gain"].as_f64().unwrap_or(f64::NAN),
            p["phase_deg"].as_f64().unwrap_or(f64::NAN),
            p["stroke_mm"].as_f64().unwrap_or(f64::NAN)
        );
    }
    if let Some(m) = report.get("margins") {
        let _ = writeln!(s, "feedback {}: open loop cut at the spool reference", report["feedback"]);
        for g in m["gain"].as_array().into_iter().flatten() {
            let _ = writeln!(
                s,
                "  gain margin  {:8.2} dB  at {:8.3} Hz",
                g["db"].as_f64().unwrap_or(f64::NAN),
                g["frequency_hz"].as_f64().unwrap_or(f64::NAN)
            );
        }
        for p in m["phase"].as_array().into_iter().flatten() {
            let _ = writeln!(
                s,
                "  phase margin {:8.2} deg at {:8.3} Hz",
                p["deg"].as_f64().unwrap_or(f64::NAN),
                p["frequency_hz"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
    s
}
