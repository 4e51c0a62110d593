//! Seeded API-sequence fuzzer of the FMI 2.0 and FMI 3.0 C ABIs (Co-Simulation and Model
//! Exchange) of the boomsim FMUs: the 44 fmi2* and the 75 fmi3* functions of each library.
//!
//! ```sh
//! bash scripts/fuzz [--seconds S] [--seed N] [--fmi 2|3|both] [--lib PATH ...]   # default: 60 s, both
//! bash scripts/fuzz --lib target/release/libHydraulicBoom.so --seed N --replay
//! ```
//!
//! The time is split evenly over the libraries and the versions (`--fmi both`, the default: half
//! each). A sequence is one instantiation (FMI 2.0: fmi2Instantiate; FMI 3.0:
//! fmi3InstantiateCoSimulation or fmi3InstantiateModelExchange; in both versions a third of them
//! for Model Exchange, with the GUID or instantiation token of the model description or now and
//! then a wrong one), 20 to 200 calls and the frees, all drawn from its seed. Most calls are what
//! a well-behaved importer does (`planner`, `planner3`: the state machines' paths, steps, an
//! integrator's calls, derivatives in Initialization Mode, and the probe paths of `probes`), so
//! that the models really simulate (at most 0.5 s per sequence); the others are any function
//! with arguments an importer can get wrong, also on a NULL instance (`wild`, `wild3`: NULL
//! pointers, nValues other than the number of value references, unknown value references, counts
//! far larger than the arrays (`oversized`), wrong states, NaN and ±Inf, out-of-range values,
//! damaged serialized states, clocks, Scheduled Execution and the other functions these FMUs do
//! not provide). The oracle (`session`, `session3`) is checked after every call: what the
//! standard forbids must return Error (FMI 2.0: `machine2`, counts and Model Exchange times;
//! FMI 3.0: `machine3`, the state machines, with Terminated after any fmi3Error), what it allows
//! with right arguments must succeed (`required`: derivatives in Initialization Mode and of
//! `der(...)` in Step Mode, states set by value reference, FMU state round trips), the probes'
//! expectations must hold (`watch`: event locals against the event indicators and current after
//! steps, states set by reference as SetContinuousStates sets them), and an Error or Discard
//! comes with a log message (FMI 2.0: for the refusals of `machine2`). A crash (a signal), a hang
//! (a sequence still running after 120 s; legal extreme parameters can make one slow) or a leak
//! (the heap larger after the sequence than before, twice; glibc's tcache is turned off for this)
//! fails the sequence too. Log messages
//! that report a panic the FMU caught ("internal error") are counted and the first is shown with
//! its seed, but they are not failures.
//!
//! A failure prints the sequence's seed, the message and the last calls; `--seed N --replay` with
//! that seed and its `--lib` runs exactly this sequence in-process, without fork, printing every
//! call and log message (the seed's top bit tells the version: set for FMI 3.0). Without
//! `--seed` the master seed comes from the clock; it is printed, and `--seed N` repeats the run
//! (as far as the same number of sequences fit in the time budget). The summary has a line per
//! library and version, one per version and the total, each with its sequences and calls on
//! Co-Simulation (CS) and Model Exchange (ME) instances. Exit status: 0 when nothing failed, 1
//! on a failure, 2 on a usage or setup error. A 60 s run against the issue 25 runtime (main at
//! 136f7a4; both versions, 7.5 s per library and version; 60.2 s in all) made 5.47 M calls:
//! 3.06 M in 31 026 FMI 2.0 sequences (ME: 9 904 sequences, 1.01 M calls) and 2.41 M in 24 225
//! FMI 3.0 ones (ME: 7 747, 0.80 M); its failures were the runtime's (FMI 2.0 value-reference
//! lists one longer than the variables accepted; FMU states that serialize but do not
//! deserialize: FMI 3.0 Terminated before initialisation, FMI 2.0 after a step that failed).
//!
//! - `fmi2`, `fmi3`: the C ABIs; `library`: the libraries under test; `model_description`: their XML;
//! - `sequence`: one sequence, of calls (`ops`, `ops3`) from the planners (with
//!   `probes`) and the wild generators (with `oversized`), drawn with `rng`; `refused`: the FMI
//!   3.0 functions the FMUs must refuse;
//! - `session`, `session3`: make the calls and check the oracle, with `machine2`, `machine3`,
//!   `required` and `watch`, `view` (the instance's phase and time), `fmu_states` (the FMU state
//!   functions, shared by both versions) and `callbacks` (the loggers);
//! - `batch`: the forked children, heartbeat and timeout; `report`: their account in shared
//!   memory, the tallies and the output.

/// The libraries' loaders (`fmi2`, `fmi3`): the first of the functions named that `fmi` does not export.
macro_rules! first_missing {
    ($fmi:ident: $($function:ident)*) => {
        [$((stringify!($function), $fmi.$function.is_ok())),*].into_iter().find(|(_, ok)| !ok).map(|(f, _)| f)
    };
}

mod batch;
mod bookkeeping;
mod callbacks;
mod fmi2;
mod fmi3;
mod fmu_states;
mod library;
mod machine2;
mod machine3;
mod model_description;
mod ops;
mod ops3;
mod oversized;
mod planner;
mod planner2;
mod planner3;
mod probes;
mod refused;
mod report;
mod required;
mod rng;
mod sequence;
mod session;
mod session3;
mod view;
mod watch;
mod wild;
mod wild3;

use report::{Subject, Tally};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// The FMUs of this repository, fuzzed when no `--lib` is given.
const MODELS: [&str; 4] = ["PressureFeedbackController", "HydraulicBoom", "HydraulicCircuit", "BoomMechanics"];

const USAGE: &str = "usage: fuzz [--seconds S] [--seed N] [--fmi 2|3|both] [--lib PATH ...] [--replay]
  --seconds S   time budget, split evenly over the libraries and versions (default 60)
  --seed N      master seed (default: from the clock, printed); with --replay, a sequence's seed
                (its top bit set: an FMI 3.0 sequence)
  --fmi V       the interface fuzzed: FMI 2.0, FMI 3.0 or both (default both, half the time each)
  --lib PATH    FMU shared libraries (default: target/release/lib<Id>.so of the four FMUs);
                the model descriptions are modelDescription/<Id>.xml and
                modelDescription/fmi3/<Id>.xml of this repository
  --replay      run the sequence --seed N on the one --lib in-process, printing every call";

fn main() {
    untcached();
    let code = match parse_args(std::env::args().skip(1)) {
        Ok(Some(options)) => run(&options).unwrap_or_else(|e| {
            eprintln!("fuzz: {e}");
            2
        }),
        Ok(None) => {
            println!("{USAGE}");
            0
        }
        Err(e) => {
            eprintln!("fuzz: {e}\n{USAGE}");
            2
        }
    };
    std::process::exit(code)
}

/// Fuzzes every library through every version asked for its share of the time, or replays one
/// sequence; the exit status.
fn run(options: &Options) -> Result<i32, String> {
    if options.replay {
        let [path] = &options.libs[..] else {
            return Err("--replay runs one sequence on one library: give exactly one --lib".into());
        };
        let seed = options.seed.ok_or("--replay needs the --seed of the sequence")?;
        return Ok(match rng::seed_version(seed) {
            3 => sequence::replay(&fmi3::Library::load(path)?, seed),
            _ => sequence::replay(&fmi2::Library::load(path)?, seed),
        });
    }
    let mut subjects: Vec<Box<dyn Subject>> = Vec::new();
    for path in &options.libs {
        if options.versions.contains(&2) {
            subjects.push(Box::new(fmi2::Library::load(path)?));
        }
        if options.versions.contains(&3) {
            subjects.push(Box::new(fmi3::Library::load(path)?));
        }
    }
    let seed = options.seed.unwrap_or_else(clock_seed);
    let budget = Duration::from_secs_f64(options.seconds / subjects.len() as f64);
    println!("fuzz: seed {seed} (repeat with --seed {seed}), {:.1} s per library and version", budget.as_secs_f64());
    let started = Instant::now();
    let (mut total, mut per_version) = (Tally::default(), [Tally::default(), Tally::default()]);
    for subject in &subjects {
        let tally = batch::fuzz_library(subject.as_ref(), seed, budget)?;
        println!("fuzz: {}", tally.line(&format!("{} FMI {}", subject.identifier(), subject.fmi())));
        if let Some((seed, message)) = &tally.first_internal_error {
            println!("fuzz:   first internal error (sequence seed {seed}): {message}");
        }
        per_version[usize::from(subject.fmi() == 3)].add_timed(&tally);
        total.add(tally);
    }
    for (version, tally) in options.versions.iter().map(|&v| (v, &per_version[usize::from(v == 3)])) {
        println!("fuzz: FMI {version}.0 {}", tally.line(&format!("{} libraries", options.libs.len())));
    }
    total.elapsed = started.elapsed();
    println!("fuzz: total {} (seed {seed})", total.line(&format!("{} libraries", options.libs.len())));
    Ok(if total.failures > 0 { 1 } else { 0 })
}

/// The tunable that turns off glibc's per-thread cache of freed chunks, which mallinfo2 counts as
/// in use: without it the leak check of `sequence` would see memory the FMU freed.
const NO_TCACHE: &str = "glibc.malloc.tcache_count=0";

/// Runs this program again with `NO_TCACHE` in GLIBC_TUNABLES (read only at process start),
/// unless it is there.
fn untcached() {
    use std::os::unix::process::CommandExt;
    let tunables = std::env::var("GLIBC_TUNABLES").unwrap_or_default();
    if tunables.split(':').any(|t| t == NO_TCACHE) {
        return;
    }
    let tunables = if tunables.is_empty() { NO_TCACHE.to_owned() } else { format!("{tunables}:{NO_TCACHE}") };
    let error = std::process::Command::new("/proc/self/exe")
        .args(std::env::args_os().skip(1))
        .env("GLIBC_TUNABLES", tunables)
        .exec();
    eprintln!("fuzz: cannot run again with GLIBC_TUNABLES={NO_TCACHE}: {error}");
    std::process::exit(2)
}

/// Command-line options.
struct Options {
    seconds: f64,
    /// 2, 3 or both.
    versions: Vec<u8>,
    seed: Option<u64>,
    libs: Vec<PathBuf>,
    replay: bool,
}

/// Parses the arguments; `None` for `--help`.
fn parse_args(args: impl Iterator<Item = String>) -> Result<Option<Options>, String> {
    let mut o = Options { seconds: 60.0, versions: vec![2, 3], seed: None, libs: Vec::new(), replay: false };
    let mut args = args.peekable();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--seconds" => o.seconds = parse_value(args.next(), &arg)?,
            "--seed" => o.seed = Some(parse_value(args.next(), &arg)?),
            "--replay" => o.replay = true,
            "--fmi" => {
                o.versions = match args.next().as_deref() {
                    Some("2") => vec![2],
                    Some("3") => vec![3],
                    Some("both") => vec![2, 3],
                    _ => return Err("--fmi needs 2, 3 or both".into()),
                }
            }
            "--lib" => {
                o.libs.push(args.next().ok_or("--lib needs a path")?.into());
                while let Some(path) = args.next_if(|a| !a.starts_with("--")) {
                    o.libs.push(path.into());
                }
            }
            "-h" | "--help" => return Ok(None),
            _ => return Err(format!("unknown argument {arg:?}")),
        }
    }
    if !(o.seconds > 0.0 && o.seconds.is_finite()) {
        return Err("--seconds must be a positive number".into());
    }
    if o.libs.is_empty() {
        o.libs = MODELS.iter().map(|id| repository().join(format!("target/release/lib{id}.so"))).collect();
    }
    Ok(Some(o))
}

fn parse_value<T: std::str::FromStr>(value: Option<String>, flag: &str) -> Result<T, String> {
    value.as_deref().and_then(|v| v.parse().ok()).ok_or_else(|| format!("{flag} needs a number"))
}

/// The model identifier of `lib<Id>.so` (or `<Id>.so`).
fn identifier(path: &Path) -> Result<&str, String> {
    let stem = path.file_stem().and_then(|s| s.to_str()).ok_or_else(|| format!("{}: no file name", path.display()))?;
    Ok(stem.strip_prefix("lib").unwrap_or(stem))
}

/// The repository root, with `modelDescription/` and `target/`.
fn repository() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// A master seed from the clock.
fn clock_seed() -> u64 {
    let mut nanos = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64);
    rng::splitmix64(&mut nanos)
}
