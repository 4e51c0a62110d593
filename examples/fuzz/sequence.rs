//! A sequence: one instantiation (mostly valid), 20 to 200 calls, mostly planned, some wild,
//! and the frees; all of it drawn from the sequence's seed, for either version (its session's
//! `Driven`), with the logger's account and the leak check.

use crate::bookkeeping::Target;
use crate::callbacks::{LogSink, LOG};
use crate::fmu_states::StateCall;
use crate::library::{Binding, Library};
use crate::ops::Slot;
use crate::planner::{Planned, Planner};
use crate::report::{Report, Subject};
use crate::rng::Rng;
use std::ffi::c_void;
use std::path::Path;
use std::ptr::null_mut;

/// Calls between the instantiation and the frees.
const CALLS: (usize, usize) = (20, 200);
/// Calls when the instantiation returned NULL (all of them on the NULL instance).
const CALLS_WITHOUT_INSTANCE: usize = 20;

/// Runs a sequence with `drive`, adding to `report`; `Err` is the oracle violation (the calls are
/// in the report). When the heap holds more after the sequence than before, it runs once more
/// (a first use may allocate for good: buffers, thread-locals): a sequence that again leaves
/// memory behind leaked it (an instance or FMU state not freed by FreeInstance).
fn run_logged(
    fmi3: bool,
    seed: u64,
    report: &mut Report,
    drive: impl Fn(&mut Report) -> Result<(), String>,
) -> Result<(), String> {
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

impl<F: Binding> Subject for Library<F> {
    fn identifier(&self) -> &str {
        &self.model.identifier
    }
    fn path(&self) -> &Path {
        &self.path
    }
    fn fmi(&self) -> u8 {
        F::FMI
    }
    fn run_sequence(&self, seed: u64, report: &mut Report) -> Result<(), String> {
        run_logged(F::FMI == 3, seed, report, |report| drive(&mut F::session(self, report), seed))
    }
}

/// A version's op, as `drive` and the sessions make them.
pub trait Call {
    /// Whether the function takes the instance as its first argument.
    fn takes_instance(&self) -> bool;
    fn free_instance(instance: *mut c_void) -> Self;
    fn state(call: StateCall) -> Self;
}

/// A version's session as `drive` runs it: its calls, planner and wild generator.
pub trait Driven {
    type Op: Planned;
    /// The main instance and the second one (NULL when there is none).
    fn instances(&self) -> (*mut c_void, *mut c_void);
    fn instantiation(&self, rng: &mut Rng) -> Self::Op;
    fn planned(&self, planner: &mut Planner<Self::Op>, rng: &mut Rng) -> Self::Op;
    fn wild(&self, rng: &mut Rng) -> Self::Op;
    /// Makes one call and checks the oracle.
    fn call(&mut self, op: Self::Op, target: Target) -> Result<(), String>;

    /// What follows an instantiation that returned `c`, as `Bookkeeping::adopt` says: an FMU
    /// state of the second instance, or the instance freed right away.
    fn adopted(&mut self, c: *mut c_void, adopt: Option<Target>) -> Result<(), String> {
        match adopt {
            Some(Target::Second) => {
                self.call(Self::Op::state(StateCall::Get { state: Slot::Holding(null_mut()) }), Target::Second)
            }
            Some(_) => self.call(Self::Op::free_instance(c), Target::Main),
            None => Ok(()),
        }
    }
}

/// Makes a version's session `$session` (its `Bookkeeping` in the field `b`, its own `call`)
/// `Driven`, with `$op` its ops and `$instantiation` and `$wild` its generators.
macro_rules! driven {
    ($session:ident, $op:ident, $instantiation:path, $wild:path) => {
        impl<'a> std::ops::Deref for $session<'a> {
            type Target = crate::bookkeeping::Bookkeeping<'a>;
            fn deref(&self) -> &Self::Target {
                &self.b
            }
        }

        impl std::ops::DerefMut for $session<'_> {
            fn deref_mut(&mut self) -> &mut Self::Target {
                &mut self.b
            }
        }

        impl crate::sequence::Driven for $session<'_> {
            type Op = $op;
            fn instances(&self) -> (*mut std::ffi::c_void, *mut std::ffi::c_void) {
                (self.c, self.second)
            }
            fn instantiation(&self, rng: &mut crate::rng::Rng) -> $op {
                $op::Instantiate($instantiation(rng, self.model))
            }
            fn planned(&self, planner: &mut crate::planner::Planner<$op>, rng: &mut crate::rng::Rng) -> $op {
                planner.next(rng, self)
            }
            fn wild(&self, rng: &mut crate::rng::Rng) -> $op {
                $wild(rng, self)
            }
            fn call(&mut self, op: $op, target: crate::bookkeeping::Target) -> Result<(), String> {
                $session::call(self, op, target)
            }
        }
    };
}
pub(crate) use driven;

/// The calls: instantiation, a mix of planned and wild calls (all wild without an instance, a
/// few on a NULL instance), the frees.
fn drive<S: Driven>(s: &mut S, seed: u64) -> Result<(), String> {
    let mut rng = Rng::new(seed);
    let instantiation = s.instantiation(&mut rng);
    s.call(instantiation, Target::Main)?;
    let wildness = *rng.pick(&[0.02, 0.02, 0.05, 0.1, 0.3, 1.0]);
    let mut calls = rng.range(CALLS.0, CALLS.1);
    if s.instances().0.is_null() {
        calls = calls.min(CALLS_WITHOUT_INSTANCE);
    }
    let mut planner = Planner::new(&mut rng);
    for _ in 0..calls {
        let op = if s.instances().0.is_null() || rng.chance(wildness) {
            s.wild(&mut rng)
        } else {
            s.planned(&mut planner, &mut rng)
        };
        let null = op.takes_instance() && (s.instances().0.is_null() || rng.chance(0.01));
        s.call(op, if null { Target::Null } else { Target::Main })?;
    }
    let (main, second) = s.instances();
    if !second.is_null() {
        s.call(S::Op::free_instance(second), Target::Main)?;
    }
    s.call(S::Op::free_instance(main), Target::Main)
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
