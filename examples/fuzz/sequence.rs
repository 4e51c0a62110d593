//! A sequence: one fmi2Instantiate (mostly valid), 20 to 200 calls, mostly planned, some wild,
//! and fmi2FreeInstance; all of it drawn from the sequence's seed.

use crate::callbacks::{LogSink, LOG};
use crate::fmi2::Library;
use crate::ops::Op;
use crate::planner::Planner;
use crate::report::Report;
use crate::rng::Rng;
use crate::session::{Session, Target};
use crate::wild::{instantiation, wild};

/// Calls between fmi2Instantiate and fmi2FreeInstance.
const CALLS: (usize, usize) = (20, 200);
/// Calls when fmi2Instantiate returned NULL (all of them on the NULL instance).
const CALLS_WITHOUT_INSTANCE: usize = 20;

/// Runs the sequence of `seed`, adding to `report`; `Err` is the oracle violation (the calls
/// are in the report).
pub fn run_sequence(library: &Library, seed: u64, report: &mut Report) -> Result<(), String> {
    LOG.with(|sink| *sink.borrow_mut() = LogSink { echo: report.echo, ..LogSink::default() });
    report.traced = 0;
    let result = drive(&mut Session::new(library, report), seed);
    report.absorb_log(seed, LOG.with(|sink| sink.take()));
    result
}

/// The calls: instantiation, a mix of planned and wild calls (all wild without an instance, a
/// few on a NULL instance), the frees.
fn drive(s: &mut Session, seed: u64) -> Result<(), String> {
    let mut rng = Rng::new(seed);
    s.call(Op::Instantiate(instantiation(&mut rng, s.model)), Target::Main)?;
    let wildness = *rng.pick(&[0.02, 0.02, 0.05, 0.1, 0.3, 1.0]);
    let mut calls = rng.range(CALLS.0, CALLS.1);
    if s.c.is_null() {
        calls = calls.min(CALLS_WITHOUT_INSTANCE);
    }
    let mut planner = Planner::new(&mut rng);
    for _ in 0..calls {
        let op = if s.c.is_null() || rng.chance(wildness) { wild(&mut rng, s) } else { planner.next(&mut rng, s) };
        let null = op.takes_component() && (s.c.is_null() || rng.chance(0.01));
        s.call(op, if null { Target::Null } else { Target::Main })?;
    }
    let (second, main) = (s.second, s.c);
    if !second.is_null() {
        s.call(Op::FreeInstance { instance: second }, Target::Main)?;
    }
    s.call(Op::FreeInstance { instance: main }, Target::Main)
}

/// Runs one sequence in this process, printing every call and log message; the exit status.
pub fn replay(library: &Library, seed: u64) -> i32 {
    println!("fuzz: replaying sequence seed {seed} on {}", library.model.identifier);
    let mut report = Report::boxed();
    report.echo = true;
    match run_sequence(library, seed, &mut report) {
        Ok(()) => {
            println!("fuzz: {} calls, no failure", report.counts.calls);
            0
        }
        Err(violation) => {
            eprintln!("fuzz: FAILURE: {violation}");
            1
        }
    }
}
