//! The boomsim command line: build and pack the FMUs, keep modelDescription files current,
//! analyse the linearised stability.

use boomsim::models;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

#[derive(Parser)]
#[command(
    name = "boomsim",
    version,
    about = "FMI 2.0 FMUs of a hydraulic boom with counterbalance valve and pressure feedback"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Build every FMU crate in release mode and write target/fmu/<ModelIdentifier>.fmu.
    Pack {
        /// Output directory.
        #[arg(long, default_value = "target/fmu")]
        out: PathBuf,
    },
    /// Write modelDescription/<ModelIdentifier>.xml from the variable tables.
    Xml {
        /// Compare instead of writing; fail if a committed file differs from the generator.
        #[arg(long)]
        check: bool,
    },
    /// Linear stability analysis and pressure-feedback tuning (thesis sections 2.3, 6.1).
    Analyze(Box<boomsim::analysis::cli::AnalyzeArgs>),
}

/// The workspace root (this package's manifest directory).
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root().join("target"))
}

fn pack(out: &Path) -> Result<(), String> {
    let fmus = models::all();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut build = Command::new(cargo);
    build.current_dir(root()).args(["build", "--release", "--quiet"]);
    for f in &fmus {
        build.args(["-p", f.package]);
    }
    let status = build.status().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("cargo build failed ({status})"));
    }
    let out = if out.is_absolute() { out.to_path_buf() } else { root().join(out) };
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    for f in &fmus {
        let lib = target_dir().join("release").join(format!("lib{}.so", f.identifier));
        let fmu = out.join(format!("{}.fmu", f.identifier));
        f.write(&lib, &fmu).map_err(|e| format!("{}: {e}", fmu.display()))?;
        println!("{}", fmu.display());
    }
    Ok(())
}

fn xml(check: bool) -> Result<(), String> {
    let dir = root().join("modelDescription");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let mut stale = Vec::new();
    for f in models::all() {
        let path = dir.join(format!("{}.xml", f.identifier));
        let xml = (f.model_description)();
        if check {
            if std::fs::read_to_string(&path).ok().as_deref() != Some(xml.as_str()) {
                stale.push(path.display().to_string());
            }
        } else {
            std::fs::write(&path, xml).map_err(|e| format!("{}: {e}", path.display()))?;
            println!("{}", path.display());
        }
    }
    if stale.is_empty() {
        Ok(())
    } else {
        Err(format!("out of date (run `boomsim xml`): {}", stale.join(", ")))
    }
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Cmd::Pack { out } => pack(&out),
        Cmd::Xml { check } => xml(check),
        Cmd::Analyze(args) => boomsim::analysis::cli::run(&args, root()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("boomsim: {e}");
            ExitCode::FAILURE
        }
    }
}
