//! A sequence: one instantiation (mostly valid), 20 to 200 calls, mostly planned, some wild,
//! and the frees; all of it drawn from the sequence's seed. This file runs either version's
//! sequences (with the logger's account and the leak check) and holds FMI 2.0's;
//! `sequence3` holds FMI 3.0's.

use crate::callbacks::{LogSink, LOG};
use crate::fmi2::Library;
use crate::ops::Op;
use crate::planner::Planner;
use crate::report::{Report, Subject};
use crate::rng::Rng;
use crate::session::{Session, Target};
use crate::wild::{instantiation, wild};
use std::path::Path;

/// Calls between the instantiation and the frees.
pub const CALLS: (usize, usize) = (20, 200);
/// Calls when the instantiation returned NULL (all of them on the NULL instance).
pub const CALLS_WITHOUT_INSTANCE: usize = 20;

/// Runs a sequence with `drive`, adding to `report`; `Err` is the oracle violation (the calls are
/// in the report). When the heap holds more after the sequence than before, it runs once more
/// (a first use may allocate for good: buffers, thread-locals): a sequence that again leaves
/// memory behind leaked it (an instance or FMU state not freed by FreeInstance).
pub fn run_logged(fmi3: bool, seed: u64, report: &mut Report, drive: impl Fn(&mut Report) -> Result<(), String>) -> Result<(), String> {
    report.fmi3 = fmi3;
    let mut leaked = 0;
    for _ in 0..2 {
        crate::batch::beat();
        LOG.with(|sink| *sink.borrow_mut() = LogSink { echo: report.echo, fmi3, ..LogSink::default() });
        report.traced = 0;
        let before = heap_in_use();
        let result = drive(report);
        report.absorb_log(seed, LOG.with(|sink| sink.take()));
        result?;
        leaked = heap_in_use().saturating_sub(before);
        if leaked == 0 {
            return Ok(());
        }
    }
    Err(format!("memory leak: {leaked} bytes more on the heap after the sequence, twice (FreeInstance frees the instance and its FMU states)"))
}

/// Bytes allocated with malloc and not freed (small chunks and mmapped ones).
fn heap_in_use() -> usize {
    // SAFETY: mallinfo2 only reads the allocator's statistics.
    let info = unsafe { libc::mallinfo2() };
    info.uordblks + info.hblkhd
}

impl Subject for Library {
    fn identifier(&self) -> &str {
        &self.model.identifier
    }
    fn path(&self) -> &Path {
        &self.path
    }
    fn fmi(&self) -> u8 {
        2
    }
    fn run_sequence(&self, seed: u64, report: &mut Report) -> Result<(), String> {
        run_logged(false, seed, report, |report| drive(&mut Session::new(self, report), seed))
    }
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
pub fn replay(subject: &dyn Subject, seed: u64) -> i32 {
    println!("fuzz: replaying sequence seed {seed} on {} through FMI {}", subject.identifier(), subject.fmi());
    let mut report = Report::boxed();
    report.echo = true;
    match subject.run_sequence(seed, &mut report) {
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
