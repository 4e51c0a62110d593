//! The boomsim command line: build and pack the FMUs, keep modelDescription files current,
//! analyse the linearised stability.

use boomsim::fmu::Version;
use boomsim::models;
use boomsim_tools::pack;
use boomsim_tools::platform::Platform;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "boomsim",
    version,
    about = "FMI 2.0 and 3.0 FMUs of a hydraulic boom with counterbalance valve and pressure feedback"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Build every FMU crate in release mode and write target/fmu/<ModelIdentifier>.fmu (FMI 2.0)
    /// and target/fmu/fmi3/<ModelIdentifier>.fmu (FMI 3.0, the same binaries).
    Pack {
        /// Output directory.
        #[arg(long, default_value = "target/fmu")]
        out: PathBuf,
        /// Binary platforms, comma-separated: linux64 (the host), win64, aarch64-linux, or all.
        /// The cross builds need scripts/setup-cross; the first one builds the standard library
        /// for its target (about a minute each on 2 cores).
        #[arg(long, default_value = "linux64")]
        platforms: String,
    },
    /// Time the lowering scenarios U and B and the load at rest (R: the cost floor of a doStep) in-process and through the C ABI (1 ms steps, rtol 1e-6).
    Bench {
        /// Print a JSON list of {case, boom, via, simulated_s, wall_s, rtf, steps, rhs_evals, jac_evals, do_step_us}.
        #[arg(long)]
        json: bool,
        /// Simulated time per case [s], > 0.
        #[arg(long, default_value_t = 10.0, value_parser = positive)]
        duration: f64,
        /// Then Model Exchange (fmpy + CVode) against Co-Simulation on the same cases, with RHS
        /// counts and the error against an rtol 1e-9 reference (scripts/bench_interfaces.py
        /// --only interfaces, under a minute; needs the venv of scripts/setup and `boomsim pack`).
        #[arg(long)]
        model_exchange: bool,
        /// Instead: the distribution of one doStep's wall time, thread CPU time and RHS
        /// evaluations (median, p99, p99.9, max) in cases U and B, rigid and flexible, and with
        /// the spool reference switched at random every 0.5 s (flexible), adaptive and real-time
        /// (`solver.mode`), over `--repeats` runs of `--duration` s (in-process).
        #[arg(long)]
        realtime: bool,
        /// Instead: the time of one Jacobian of the flexible plant at U's start in RHS
        /// evaluations, finite differences against the exact one in dual numbers and the
        /// structured one the integrator uses, under the thesis' damping law and the default
        /// (in-process, a few seconds).
        #[arg(long)]
        jacobian: bool,
        /// Runs per case of `--realtime`, > 0.
        #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
        repeats: u32,
        /// A parameter of the HydraulicBoom, NAME=VALUE (repeatable): every case runs with the
        /// defaults and then with these, and the table adds their ratios (same run, so load
        /// cancels), e.g. --set boom.damping=structural.
        #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true)]
        set: Vec<String>,
    },
    /// Modes of the HydraulicBoom linearised at rest with the boom horizontal (full payload,
    /// spool closed): the flexible boom (default n2 = 4, n3 = 5) and, for comparison, the rigid one.
    Eigen {
        /// Print JSON: {stroke_mm, modes: [{frequency_hz, damping_ratio}], rigid_modes: [...]}.
        #[arg(long)]
        json: bool,
        /// How many of the lowest modes to print.
        #[arg(long, default_value_t = 6)]
        count: usize,
        /// Rod-side pressure trapped at rest [bar, gauge] for the listed modes (default: tank
        /// pressure); the `rig` entry always uses the thesis' 1 bar.
        #[arg(long, allow_negative_numbers = true)]
        p4: Option<f64>,
        /// A parameter of the HydraulicBoom for the listed modes, NAME=VALUE (repeatable), e.g.
        /// boom.n2=2 or boom.xi=0.05; the `rig` entry keeps the defaults.
        #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true)]
        set: Vec<String>,
    },
    /// Write modelDescription/<ModelIdentifier>.xml (FMI 2.0),
    /// modelDescription/fmi3/<ModelIdentifier>.xml (FMI 3.0) from the variable tables, and the
    /// FMI 3.0 terminals, modelDescription/fmi3/<ModelIdentifier>.terminalsAndIcons.xml.
    Xml {
        /// Compare instead of writing; fail if a committed file differs from the generator.
        #[arg(long)]
        check: bool,
    },
    /// Static deflection study of thesis 3.1.2: analytic and lumped end deflections.
    Deflection {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Co-simulate HydraulicBoom with the PressureFeedbackController in-process, as
    /// python/boomsim/cosim.py's `run` does through fmpy (the sweeps' native runner): a JSON request on
    /// stdin, a JSON header line and the rows as little-endian f64 on stdout.
    Cosim,
    /// Linear stability analysis and pressure-feedback tuning (thesis sections 2.3, 6.1).
    #[command(allow_negative_numbers = true)]
    Analyze(Box<boomsim_tools::analysis::cli::AnalyzeArgs>),
    /// The critical stroke of section 2.3's instability criterion for the HydraulicBoom's
    /// parameters (eq. 2.87; 2.86 with line and dead volumes; 2.84 with the oil-air law, the A->T
    /// edge's back pressure, rigid lines and hoses), at steady lowerings without pressure
    /// feedback, and the linear frequencies (eq. 2.81) at a stroke.
    #[command(allow_negative_numbers = true)]
    Criterion(boomsim_tools::analysis::criterion_cli::CriterionArgs),
    /// The HydraulicBoom's linear model dx = A x + B u, y = C x + D u at an operating point (a
    /// steady lowering, rest, or a time of a run), open or closed with the pressure feedback,
    /// from exact derivatives: eigenvalues, margins, Bode data, .json/.npz/.mat files.
    #[command(allow_negative_numbers = true)]
    Linearize(Box<boomsim_tools::analysis::linearize_cli::LinearizeArgs>),
}

/// A finite number > 0 (clap value parser).
fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not a positive number of seconds")),
        Err(e) => Err(format!("{s:?} is not a number: {e}")),
    }
}

/// The workspace root (the parent of this package's manifest directory).
fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root().join("target"))
}

/// Builds every FMU crate in release mode for `platform`.
fn build_fmus(platform: &Platform) -> Result<(), String> {
    let packages: Vec<&str> = pack::all().iter().map(|f| f.package).collect();
    let mut build = platform.build_command(root(), &target_dir(), &packages)?;
    let status = build.status().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build for {} failed ({status})", platform.name));
    }
    Ok(())
}

fn pack(out: &Path, platforms: &str) -> Result<(), String> {
    let platforms = Platform::parse_list(platforms)?;
    for (k, p) in platforms.iter().enumerate() {
        let start = std::time::Instant::now();
        eprintln!("pack: building the FMU libraries for {} ({} of {})", p.name, k + 1, platforms.len());
        build_fmus(p)?;
        eprintln!("pack: {} built in {:.0} s", p.name, start.elapsed().as_secs_f64());
    }
    let out = if out.is_absolute() { out.to_path_buf() } else { root().join(out) };
    for (version, dir) in [(Version::Fmi2, out.clone()), (Version::Fmi3, out.join("fmi3"))] {
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for f in pack::all().iter().filter(|f| f.has(version)) {
            let libs: Vec<_> = platforms.iter().map(|p| (*p, p.library(&target_dir(), f.identifier))).collect();
            let fmu = dir.join(format!("{}.fmu", f.identifier));
            f.write(version, &libs, &fmu).map_err(|e| format!("{}: {e}", fmu.display()))?;
            println!("{}", fmu.display());
        }
    }
    Ok(())
}

/// The Model Exchange rows of the benchmark: fmpy's CVode against the FMUs' Co-Simulation.
fn bench_interfaces() -> Result<(), String> {
    let python = root().join(".venv/bin/python");
    let status = std::process::Command::new(&python)
        .arg(root().join("scripts/bench_interfaces.py"))
        .args(["--only", "interfaces"])
        .status()
        .map_err(|e| format!("{}: {e} (run scripts/setup first)", python.display()))?;
    status.success().then_some(()).ok_or_else(|| format!("scripts/bench_interfaces.py: {status}"))
}

fn bench(json: bool, duration: f64, set: &[String]) -> Result<(), String> {
    use boomsim_tools::analysis::modes::parameter_change;
    let changes = set
        .iter()
        .map(|arg| parameter_change(arg).map(|(v, value)| (v.vr, value)))
        .collect::<Result<Vec<_>, String>>()?;
    if json && !changes.is_empty() {
        return Err("--set prints a comparison table; it does not go with --json".into());
    }
    build_fmus(&boomsim_tools::platform::PLATFORMS[0])?;
    let libs = target_dir().join("release");
    if !changes.is_empty() {
        return bench_changes(&libs, duration, &changes, set);
    }
    let results = boomsim_tools::bench::run_all(&libs, duration, &[])?;
    let cycle_in = boomsim_tools::bench::controller_cycle(
        &mut boomsim_tools::bench::InProcess::<models::PressureFeedbackController>::new(1e-6, &[])?,
        200_000,
    )?;
    let cycle_c = boomsim_tools::bench::controller_cycle(
        &mut boomsim_tools::bench::CAbi::new::<models::PressureFeedbackController>(
            &libs.join("libPressureFeedbackController.so"),
            1e-6,
            &[],
        )?,
        200_000,
    )?;
    if json {
        let list: Vec<_> = results.iter().map(|r| r.to_json()).collect();
        println!("{}", serde_json::to_string_pretty(&list).map_err(|e| e.to_string())?);
        return Ok(());
    }
    println!(
        "{:<5} {:<8} {:<11} {:>8} {:>8} {:>8} {:>9} {:>8} {:>10} {:>8}",
        "case", "boom", "via", "sim s", "wall s", "rtf", "us/doStep", "steps", "rhs", "jac"
    );
    for r in &results {
        println!(
            "{:<5} {:<8} {:<11} {:>8.1} {:>8.4} {:>8.0} {:>9.2} {:>8} {:>10} {:>8}",
            r.case,
            r.boom,
            r.via,
            r.simulated_s,
            r.wall_s,
            r.rtf(),
            r.per_do_step() * 1e6,
            r.steps,
            r.rhs_evals,
            r.jac_evals
        );
    }
    println!("R: the load held at rest, nothing happens: the cost floor of one doStep");
    println!(
        "controller setReal+doStep+getReal: {:.0} ns in-process, {:.0} ns through the C ABI",
        cycle_in * 1e9,
        cycle_c * 1e9
    );
    Ok(())
}

/// `boomsim bench --set`: every case with the default parameters, then with `changes`, and the
/// ratios (default over changed: above 1, the change is faster or needs fewer evaluations).
fn bench_changes(
    libs: &Path,
    duration: f64,
    changes: &[(u32, boomsim::fmu::Value)],
    set: &[String],
) -> Result<(), String> {
    let reference = boomsim_tools::bench::run_all(libs, duration, &[])?;
    let changed = boomsim_tools::bench::run_all(libs, duration, changes)?;
    println!("{duration} s per case, 1 ms steps, rtol 1e-6; default against {}", set.join(", "));
    println!(
        "{:<5} {:<8} {:<11} {:>8} {:>8} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9}",
        "case", "boom", "via", "rtf", "rtf set", "rhs", "rhs set", "jac", "jac set", "speed-up", "rhs ratio"
    );
    for (a, b) in reference.iter().zip(&changed) {
        println!(
            "{:<5} {:<8} {:<11} {:>8.0} {:>8.0} {:>10} {:>10} {:>8} {:>8} {:>9.2} {:>9.2}",
            a.case,
            a.boom,
            a.via,
            a.rtf(),
            b.rtf(),
            a.rhs_evals,
            b.rhs_evals,
            a.jac_evals,
            b.jac_evals,
            a.wall_s / b.wall_s,
            a.rhs_evals as f64 / b.rhs_evals as f64
        );
    }
    Ok(())
}

/// `boomsim bench --jacobian`: one Jacobian of the flexible plant in RHS evaluations.
fn bench_jacobian() -> Result<(), String> {
    println!(
        "| boom.damping | states | RHS [us] | finite differences: RHS | time / RHS | dual numbers: time / RHS | difference \
         | structured: time / RHS | difference |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for c in boomsim_tools::jacobian_cost::measure(&["thesis", "modal"])? {
        println!(
            "| {} | {} | {:.2} | {} | {:.1} | {:.1} | {:.1e} | {:.2} | {:.1e} |",
            c.law,
            c.states,
            c.rhs_s * 1e6,
            c.fd_rhs,
            c.fd_equivalents,
            c.dual_equivalents,
            c.difference,
            c.structured_equivalents,
            c.structured_difference
        );
    }
    Ok(())
}

fn bench_realtime(repeats: usize, duration: f64) -> Result<(), String> {
    println!(
        "doStep distributions: {repeats} x {duration} s per row, 1 ms steps, rtol 1e-6, in-process; \
         wall and thread CPU time [us] and RHS evaluations per doStep (median / p99 / p99.9 / max)"
    );
    println!(
        "{:<6} {:<8} {:<8} {:>7}  {:>27}  {:>27}  {:>19}  {:>7}  {:>10}",
        "case", "boom", "mode", "doSteps", "wall us", "CPU us", "RHS", "p99.9 %", "inaccurate"
    );
    let row = |q: [f64; 4], p: usize| q.map(|x| format!("{x:.p$}")).join(" / ");
    for d in boomsim_tools::bench::step_distributions(repeats, duration)? {
        println!(
            "{:<6} {:<8} {:<8} {:>7}  {:>27}  {:>27}  {:>19}  {:>7.1}  {:>10}",
            d.case,
            d.boom,
            d.mode,
            d.do_steps,
            row(d.wall.map(|x| x * 1e6), 1),
            row(d.cpu.map(|x| x * 1e6), 1),
            row(d.rhs, 0),
            d.cpu[2] / boomsim_tools::bench::STEP * 100.0,
            d.inaccurate
        );
    }
    println!("p99.9 %: the 99.9th percentile of the CPU time as a share of the 1 ms communication step");
    println!("inaccurate: closing steps of the real-time mode above the tolerance (solver.inaccurate_steps)");
    Ok(())
}

fn eigen(json: bool, count: usize, p4_bar: Option<f64>, set: &[String]) -> Result<(), String> {
    use boomsim_tools::analysis::modes::{hydraulic_boom_modes, parameter_change, rig, Mode};
    if let Some(p) = p4_bar {
        if !(0.0..=100.0).contains(&p) {
            return Err(format!("--p4 {p} bar is outside [0, 100] bar (start.p4's range)"));
        }
    }
    let p4 = p4_bar.map(|p| p * 1e5);
    let changes = set
        .iter()
        .map(|arg| parameter_change(arg).map(|(v, value)| (v.name, value)))
        .collect::<Result<Vec<_>, String>>()?;
    let (x0, flexible) = hydraulic_boom_modes(true, p4, &changes)?;
    let (_, rigid) = hydraulic_boom_modes(false, p4, &changes)?;
    let rig = rig()?;
    let list = |m: &[Mode]| -> Vec<serde_json::Value> {
        m.iter()
            .take(count)
            .map(|m| serde_json::json!({"frequency_hz": m.frequency_hz, "damping_ratio": m.damping_ratio}))
            .collect()
    };
    if json {
        let out = serde_json::json!({
            "stroke_mm": x0 * 1e3,
            "p4_bar": p4_bar.unwrap_or(0.0),
            "set": set,
            "modes": list(&flexible),
            "rigid_modes": list(&rigid),
            "rig": {
                "conditions": rig.conditions,
                "p4_bar": rig.p4 / 1e5,
                "frequency_hz": rig.flexible.frequency_hz,
                "damping_ratio": rig.flexible.damping_ratio,
                "rigid_frequency_hz": rig.rigid.frequency_hz,
                "measured_hz": rig.measured_hz,
                "sensitivity": rig.sensitivity.iter().map(|(what, m)| serde_json::json!({
                    "change": what, "frequency_hz": m.frequency_hz, "damping_ratio": m.damping_ratio,
                })).collect::<Vec<_>>(),
            },
        });
        println!("{out}");
        return Ok(());
    }
    println!(
        "HydraulicBoom at rest, boom horizontal at stroke {:.1} mm, spool closed, rod side at {} bar, no friction{}",
        x0 * 1e3,
        p4_bar.unwrap_or(0.0),
        if set.is_empty() { String::new() } else { format!(", {}", set.join(", ")) }
    );
    let beam = boomsim::mechanics::params::BeamParams::default();
    let sections = |name: &str, default: usize| {
        changes.iter().rev().find(|(n, _)| *n == name).map_or(default, |(_, v)| match v {
            boomsim::fmu::Value::Integer(k) => *k as usize,
            _ => default,
        })
    };
    let flexible_name = format!("flexible ({} + {})", sections("boom.n2", beam.n2), sections("boom.n3", beam.n3));
    for (name, modes) in [(flexible_name.as_str(), &flexible), ("rigid", &rigid)] {
        println!("{name}:");
        for m in modes.iter().take(count) {
            println!("  {:10.3} Hz  zeta {:.4}", m.frequency_hz, m.damping_ratio);
        }
    }
    println!(
        "rig (thesis 5.1.3: {}):\n  flexible {:.3} Hz, rigid {:.3} Hz; measured {} Hz ({:+.1} % flexible)",
        rig.conditions,
        rig.flexible.frequency_hz,
        rig.rigid.frequency_hz,
        rig.measured_hz,
        100.0 * (rig.flexible.frequency_hz / rig.measured_hz - 1.0)
    );
    for (what, m) in &rig.sensitivity {
        println!("  with {what}: flexible {:.3} Hz", m.frequency_hz);
    }
    Ok(())
}

fn xml(check: bool) -> Result<(), String> {
    let mut stale = Vec::new();
    let dir = root().join("modelDescription");
    for (version, dir) in [(Version::Fmi2, dir.clone()), (Version::Fmi3, dir.join("fmi3"))] {
        std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
        for f in pack::all().into_iter().filter(|f| f.has(version)) {
            let terminals = (version == Version::Fmi3).then(|| (f.terminals)()).flatten();
            let files = [
                (format!("{}.xml", f.identifier), Some((f.model_description)(version))),
                (format!("{}.terminalsAndIcons.xml", f.identifier), terminals),
            ];
            for (name, xml) in files.into_iter().filter_map(|(n, x)| Some((n, x?))) {
                let path = dir.join(name);
                if check {
                    if std::fs::read_to_string(&path).ok().as_deref() != Some(xml.as_str()) {
                        stale.push(path.display().to_string());
                    }
                } else {
                    std::fs::write(&path, xml).map_err(|e| format!("{}: {e}", path.display()))?;
                    println!("{}", path.display());
                }
            }
        }
    }
    if stale.is_empty() {
        Ok(())
    } else {
        Err(format!("out of date (run `boomsim xml`): {}", stale.join(", ")))
    }
}

fn deflection(json: bool) -> Result<(), String> {
    let study = boomsim_tools::deflection_study::run().map_err(|e| e.to_string())?;
    if json {
        println!("{}", study.to_json());
    } else {
        print!("{study}");
    }
    Ok(())
}

fn main() -> ExitCode {
    // A closed pipe (`boomsim eigen --json | head`) ends the program quietly, as it does other
    // command-line tools, instead of a panic in println!.
    // SAFETY: restoring the default disposition of SIGPIPE before any thread or output exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let result = match Cli::parse().command {
        Cmd::Pack { out, platforms } => pack(&out, &platforms),
        Cmd::Bench { realtime: true, set, .. } if !set.is_empty() => Err("--set compares the cases U, B and R; \
             it does not go with --realtime"
            .into()),
        Cmd::Bench { realtime: true, duration, repeats, .. } => bench_realtime(repeats as usize, duration),
        Cmd::Bench { jacobian: true, .. } => bench_jacobian(),
        Cmd::Bench { json, duration, model_exchange, set, .. } => {
            bench(json, duration, &set).and_then(|()| if model_exchange { bench_interfaces() } else { Ok(()) })
        }
        Cmd::Eigen { json, count, p4, set } => eigen(json, count, p4, &set),
        Cmd::Xml { check } => xml(check),
        Cmd::Deflection { json } => deflection(json),
        Cmd::Cosim => boomsim_tools::cosim::main(),
        Cmd::Analyze(args) => boomsim_tools::analysis::cli::run(&args, root()),
        Cmd::Criterion(args) => boomsim_tools::analysis::criterion_cli::run(&args),
        Cmd::Linearize(args) => boomsim_tools::analysis::linearize_cli::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("boomsim: {e}");
            ExitCode::FAILURE
        }
    }
}
