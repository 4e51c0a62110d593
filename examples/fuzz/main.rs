//! Seeded API-sequence fuzzer of the FMI 2.0 and FMI 3.0 C ABIs (Co-Simulation and Model
//! Exchange) of the boomsim FMUs: the 44 fmi2* and the 75 fmi3* functions of each library (the
//! clocked controller, which refuses fmi2Instantiate, through FMI 3.0 only).
//!
//! ```sh
//! bash scripts/fuzz [--seconds S] [--seed N] [--fmi 2|3|both] [--lib PATH ...]   # default: 60 s, both
//! bash scripts/fuzz --seed N --sequences K --regressions examples/fuzz/regressions.txt   # scripts/test
//! bash scripts/fuzz --lib target/release/libHydraulicBoom.so --seed N --replay
//! ```
//!
//! The time is split evenly over the libraries and the versions (`--fmi both`, the default: half
//! each); `--sequences K` runs K sequences per library and version instead, and then nothing
//! depends on the clock but the hang timeout: with `--seed N` the run and its output are the same
//! every time (the summary has no times then, and a failure's pointers are numbered, not
//! printed). A sequence is one instantiation (FMI 2.0: fmi2Instantiate; FMI 3.0:
//! fmi3InstantiateCoSimulation or fmi3InstantiateModelExchange; in both versions a third of them
//! for Model Exchange, with the GUID or instantiation token of the model description or now and
//! then a wrong one), 20 to 200 calls and the frees, all drawn from its seed. Most calls are what
//! a well-behaved importer does (`planner`, `planner3`: the state machines' paths, steps, an
//! integrator's calls, derivatives in Initialization Mode, and the probe paths of `probes`; for
//! the clocked FMU a clock master's, `clock_master`: steps or times up to each activation, the
//! Clock set in Event Mode, its inputs and outputs, the instant ended), so that the models
//! really simulate (at most 0.5 s per sequence); the others are any function
//! with arguments an importer can get wrong, also on a NULL instance (`wild`, `wild3`: NULL
//! pointers, nValues other than the number of value references, unknown value references, counts
//! far larger than the arrays (`oversized`), wrong states, NaN and ±Inf, out-of-range values,
//! damaged serialized states, clocks, Scheduled Execution and the other functions these FMUs do
//! not provide). The oracle (`session`, `session3`) is checked after every call: what the
//! standard forbids must return Error (FMI 2.0: `machine2`, counts and Model Exchange times;
//! FMI 3.0: `machine3`, the state machines, with Terminated after any fmi3Error, and
//! `clock_rules`, a Clock's activations skipped, repeated or at other times and its clocked
//! variables while it is inactive), what it allows with right arguments must succeed
//! (`required`: derivatives in Initialization Mode and of `der(...)` in Step Mode, states set by
//! value reference, FMU state round trips; the active Clock set again), the probes'
//! expectations must hold (`watch`: event locals against the event indicators and current after
//! steps, states set by reference as SetContinuousStates sets them), every doStep that answers
//! OK or Warning is followed by a read of all Real outputs and locals that must succeed with
//! finite values (`step_outputs`), and an Error or Discard comes with a log message (FMI 2.0: for
//! the refusals of `machine2`). A crash (a signal), a hang
//! (a sequence still running after 120 s; legal extreme parameters can make one slow) or a leak
//! (the heap larger after the sequence than before, twice; glibc's tcache is turned off for this)
//! fails the sequence too. Log messages
//! that report a panic the FMU caught ("internal error") are counted and the first is shown with
//! its seed, but they are not failures.
//!
//! A failure prints the sequence's seed, the message, the last calls and the line that adds it to
//! `regressions.txt`; `--seed N --replay` with that seed and its `--lib` runs exactly this
//! sequence in-process, without fork, printing every call and log message (the seed's top bit
//! tells the version: set for FMI 3.0). `--regressions FILE` first replays every sequence listed
//! there (`regressions`: every failure found so far) in forked children, with a summary line of
//! its own. Without `--seed` the master seed comes from the clock; it is printed, and `--seed N`
//! repeats the run (with a time budget, as far as the same number of sequences fit in it). The
//! summary has a line for the regressions, one per library and version, one per version and the
//! total (the regressions' included), each with its sequences and calls on Co-Simulation (CS)
//! and Model Exchange (ME) instances. Exit status: 0 when nothing failed, 1 on a failure, 2 on a
//! usage or setup error. A 60 s run against the issue 25 runtime (main at
//! 136f7a4; both versions, 7.5 s per library and version; 60.2 s in all) made 5.47 M calls:
//! 3.06 M in 31 026 FMI 2.0 sequences (ME: 9 904 sequences, 1.01 M calls) and 2.41 M in 24 225
//! FMI 3.0 ones (ME: 7 747, 0.80 M); its failures were the runtime's (FMI 2.0 value-reference
//! lists one longer than the variables accepted; FMU states that serialize but do not
//! deserialize: FMI 3.0 Terminated before initialisation, FMI 2.0 after a step that failed).
//! With the clocked controller and the reads after steps (issue 46, main at 8315122), a 60 s run
//! made 15.0 M calls in 133 463 sequences (251 000 calls/s); the test command's run
//! (`--seed 20261205 --sequences 7500` after the regressions) 7.88 M calls in 67 505 sequences,
//! about 62 s on 2 cores.
//!
//! - `fmi2`, `fmi3`: the C ABIs; `library`: the libraries under test; `model_description`: their XML;
//! - `sequence`: one sequence, of calls (`ops`, `ops3`) from the planners (with `probes` and
//!   `clock_master`) and the wild generators (with `oversized`), drawn with `rng`; `refused`: the
//!   FMI 3.0 functions the FMUs must refuse;
//! - `session`, `session3`: make the calls and check the oracle, with `machine2`, `machine3`,
//!   `clock_rules`, `required`, `watch` and `step_outputs`, `view` (the instance's phase, time
//!   and activations), `fmu_states` (the FMU state functions, shared by both versions) and
//!   `callbacks` (the loggers);
//! - `batch`: the forked children, heartbeat and timeout; `report`: their account in shared
//!   memory, the tallies and the output; `regressions`: the list of failing sequences.

/// The libraries' loaders (`fmi2`, `fmi3`): the first of the functions named that `fmi` does not export.
macro_rules! first_missing {
    ($fmi:ident: $($function:ident)*) => {
        [$((stringify!($function), $fmi.$function.is_ok())),*].into_iter().find(|(_, ok)| !ok).map(|(f, _)| f)
    };
}

mod batch;
mod bookkeeping;
mod callbacks;
mod clock_master;
mod clock_rules;
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
mod regressions;
mod report;
mod required;
mod rng;
mod sequence;
mod session;
mod session3;
mod step_outputs;
mod view;
mod watch;
mod wild;
mod wild3;

use report::{Subject, Tally};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// The FMUs of this repository, fuzzed when no `--lib` is given (each through the versions it
/// has a model description for: ClockedPressureFeedbackController FMI 3.0 only).
const MODELS: [&str; 5] = [
    "PressureFeedbackController",
    "HydraulicBoom",
    "HydraulicCircuit",
    "BoomMechanics",
    "ClockedPressureFeedbackController",
];

const USAGE: &str = "usage: fuzz [--seconds S | --sequences N] [--seed N] [--fmi 2|3|both] [--regressions FILE] [--lib PATH ...] [--replay]
  --seconds S       time budget, split evenly over the libraries and versions (default 60)
  --sequences N     N sequences per library and version instead: with --seed, the same run
                    every time (the summary then has no times)
  --seed N          master seed (default: from the clock, printed); with --replay, a sequence's
                    seed (its top bit set: an FMI 3.0 sequence)
  --fmi V           the interface fuzzed: FMI 2.0, FMI 3.0 or both (default both)
  --regressions F   first replay the sequences listed in F (examples/fuzz/regressions.txt: one
                    `<ModelIdentifier> <sequence seed>  # what it found` a line) on their libraries
  --lib PATH        FMU shared libraries (default: target/release/lib<Id>.so of the five FMUs);
                    the model descriptions are modelDescription/<Id>.xml (FMI 2.0; a library
                    without one is fuzzed through FMI 3.0 only) and modelDescription/fmi3/<Id>.xml
  --replay          run the sequence --seed N on the one --lib in-process, printing every call";

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

/// Replays the regressions, then fuzzes every library through every version asked for (its
/// share of the time, or its number of sequences), or replays one sequence; the exit status.
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
        if options.versions.contains(&2) && has_fmi2(path)? {
            subjects.push(Box::new(fmi2::Library::load(path)?));
        }
        if options.versions.contains(&3) {
            subjects.push(Box::new(fmi3::Library::load(path)?));
        }
    }
    if subjects.is_empty() {
        return Err("no library has a model description of the FMI version asked for".into());
    }
    let seed = options.seed.unwrap_or_else(clock_seed);
    let (sequences, timed) = match options.sequences {
        Some(count) => {
            println!("fuzz: seed {seed} (repeat with --seed {seed} --sequences {count}), {count} sequences per library and version");
            (batch::Sequences::Counted { master: seed, count }, false)
        }
        None => {
            let budget = Duration::from_secs_f64(options.seconds.unwrap_or(60.0) / subjects.len() as f64);
            let seconds = budget.as_secs_f64();
            println!("fuzz: seed {seed} (repeat with --seed {seed}), {seconds:.1} s per library and version");
            (batch::Sequences::Timed { master: seed, budget }, true)
        }
    };
    let started = Instant::now();
    let (mut total, mut per_version) = (Tally::default(), [Tally::default(), Tally::default()]);
    if let Some(path) = &options.regressions {
        let (tally, skipped) = regressions::replay(path, &subjects)?;
        let skipped = match skipped {
            0 => String::new(),
            n => format!(" ({n} listed for libraries or versions not in this run)"),
        };
        println!("fuzz: {}{skipped}", tally.line(&format!("regressions of {}", path.display()), timed));
        print_internal_error(&tally);
        total.add(tally);
    }
    for subject in &subjects {
        let tally = batch::fuzz_library(subject.as_ref(), &sequences)?;
        println!("fuzz: {}", tally.line(&format!("{} FMI {}", subject.identifier(), subject.fmi()), timed));
        print_internal_error(&tally);
        per_version[usize::from(subject.fmi() == 3)].add_timed(&tally);
        total.add(tally);
    }
    for (version, tally) in options.versions.iter().map(|&v| (v, &per_version[usize::from(v == 3)])) {
        let libraries = subjects.iter().filter(|s| s.fmi() == version).count();
        println!("fuzz: FMI {version}.0 {}", tally.line(&format!("{libraries} libraries"), timed));
    }
    total.elapsed = started.elapsed();
    println!("fuzz: total {} (seed {seed})", total.line(&format!("{} libraries", options.libs.len()), timed));
    Ok(if total.failures > 0 { 1 } else { 0 })
}

/// Prints the first log message of a tally that reported a caught panic, with its sequence.
fn print_internal_error(tally: &Tally) {
    if let Some((seed, message)) = &tally.first_internal_error {
        println!("fuzz:   first internal error (sequence seed {seed}): {message}");
    }
}

/// Whether the library at `path` has an FMI 2.0 model description in this repository.
fn has_fmi2(path: &Path) -> Result<bool, String> {
    Ok(repository().join(format!("modelDescription/{}.xml", identifier(path)?)).exists())
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
    /// The time budget (`None`: 60 s, unless `sequences` is given).
    seconds: Option<f64>,
    /// Sequences per library and version instead of a time budget.
    sequences: Option<u64>,
    /// 2, 3 or both.
    versions: Vec<u8>,
    seed: Option<u64>,
    regressions: Option<PathBuf>,
    libs: Vec<PathBuf>,
    replay: bool,
}

/// Parses the arguments; `None` for `--help`.
fn parse_args(args: impl Iterator<Item = String>) -> Result<Option<Options>, String> {
    let mut o = Options {
        seconds: None,
        sequences: None,
        versions: vec![2, 3],
        seed: None,
        regressions: None,
        libs: Vec::new(),
        replay: false,
    };
    let mut args = args.peekable();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--seconds" => o.seconds = Some(parse_value(args.next(), &arg)?),
            "--sequences" => o.sequences = Some(parse_value(args.next(), &arg)?),
            "--seed" => o.seed = Some(parse_value(args.next(), &arg)?),
            "--regressions" => o.regressions = Some(args.next().ok_or("--regressions needs a file")?.into()),
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
    if o.seconds.is_some() && o.sequences.is_some() {
        return Err("--seconds and --sequences exclude each other".into());
    }
    if o.seconds.is_some_and(|s| !(s > 0.0 && s.is_finite())) {
        return Err("--seconds must be a positive number".into());
    }
    if o.sequences == Some(0) {
        return Err("--sequences must be at least 1".into());
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
