//! Sequences run in forked children, `BATCH` per child, so that a crash or hang ends one child
//! and the rest go on. The child writes a byte to a pipe as each sequence starts, and the parent
//! kills it when one runs longer than `SEQUENCE_TIMEOUT`. The child's account is in a `SharedReport`.

use crate::report::{Report, SharedReport, Subject, Tally};
use crate::rng::sequence_seed;
use std::ffi::CStr;
use std::os::raw::c_int;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::{Duration, Instant};

thread_local! {
    /// The child's end of the heartbeat pipe (-1: none, as on replay).
    static HEARTBEAT: std::cell::Cell<c_int> = const { std::cell::Cell::new(-1) };
}

/// Tells the parent that the child is alive and starts (or repeats) a sequence.
pub fn beat() {
    let fd = HEARTBEAT.with(|h| h.get());
    if fd >= 0 {
        // SAFETY: one byte from a live buffer to the pipe; a parent that is gone does not matter.
        unsafe { libc::write(fd, [1u8].as_ptr().cast(), 1) };
    }
}

/// Sequences per forked child.
const BATCH: u64 = 20;
/// A sequence still running after this long is a hang. Not 10 s: legal but extreme parameters
/// make the plant's integrator slow, not stuck (HydraulicBoom FMI 3.0, seed 14862978723300872466:
/// line.v_l1 = 2 ml, when line 1 was integrated, cylinder.v_dead_a = 0.16 l, a 6-section arm;
/// 33 291 steps for 20 us of one step, 34.6 s for the sequence on the quiet machine; the
/// numerics issue's stiction and fast modes), and a loaded machine stretches that further.
const SEQUENCE_TIMEOUT: Duration = Duration::from_secs(120);
/// Exit status of a child whose sequence violated the oracle (the message is in the report).
const EXIT_VIOLATION: c_int = 1;
/// Exit status of a child in which the fuzzer itself panicked.
const EXIT_FUZZER_PANIC: c_int = 3;

/// Which sequences a library runs: those of a master seed (`rng::sequence_seed`) for a time
/// budget or a fixed number of them, or the seeds listed (the regressions).
pub enum Sequences<'a> {
    Timed { master: u64, budget: Duration },
    Counted { master: u64, count: u64 },
    Listed(&'a [u64]),
}

impl Sequences<'_> {
    /// The seed of sequence `k` of `library`, if it runs that many.
    fn seed(&self, library: &dyn Subject, k: u64) -> Option<u64> {
        let seed = |master| sequence_seed(master, library.identifier(), library.fmi(), k);
        match *self {
            Sequences::Timed { master, .. } => Some(seed(master)),
            Sequences::Counted { master, count } => (k < count).then(|| seed(master)),
            Sequences::Listed(seeds) => seeds.get(k as usize).copied(),
        }
    }

    /// Whether sequences drawn from a master seed run (not listed ones): a failure is new.
    pub fn drawn(&self) -> bool {
        !matches!(self, Sequences::Listed(_))
    }
}

/// Fuzzes one library through one FMI version with `sequences`, batch after batch, printing
/// the first failure of each kind. Only a time budget makes the run depend on the clock.
pub fn fuzz_library(library: &dyn Subject, sequences: &Sequences) -> Result<Tally, String> {
    let mut report = SharedReport::new()?;
    let started = Instant::now();
    let deadline = match sequences {
        Sequences::Timed { budget, .. } => Some(started + *budget),
        _ => None,
    };
    let mut tally = Tally::default();
    let mut next = 0;
    while deadline.is_none_or(|d| Instant::now() < d) {
        let seeds: Vec<u64> = (next..next + BATCH).map_while(|k| sequences.seed(library, k)).collect();
        if seeds.is_empty() {
            break;
        }
        report.clear();
        let ending = run_batch(library, &seeds, &mut report, deadline)?;
        let r = report.get();
        tally.counts.add(r.counts);
        if tally.first_internal_error.is_none() {
            tally.first_internal_error = r.first_internal_error();
        }
        next += r.counts.sequences;
        if let Some(ending) = ending {
            let name = format!("{} (FMI {})", library.identifier(), library.fmi());
            if tally.kinds.insert(r.signature(&name, &ending)) {
                r.print_failure(library, seeds[r.running as usize], &ending, sequences.drawn());
            }
            tally.failures += 1;
            tally.counts.sequences += 1;
            next += 1;
        }
    }
    tally.elapsed = started.elapsed();
    Ok(tally)
}

/// Runs `seeds` in a forked child and waits for it; `None` when every sequence passed, else how
/// the child ended. The child's account is in `report`.
fn run_batch(
    library: &dyn Subject,
    seeds: &[u64],
    report: &mut SharedReport,
    deadline: Option<Instant>,
) -> Result<Option<String>, String> {
    let mut fds = [0; 2];
    // SAFETY: pipe fills two descriptors.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return Err(format!("pipe: {}", std::io::Error::last_os_error()));
    }
    let [heartbeat_in, heartbeat_out] = fds;
    // SAFETY: this process has one thread, so the child may run anything; it leaves with _exit.
    match unsafe { libc::fork() } {
        -1 => Err(format!("fork: {}", std::io::Error::last_os_error())),
        0 => {
            // SAFETY: the child's copy of the read end, closed once.
            unsafe { libc::close(heartbeat_in) };
            let batch = AssertUnwindSafe(|| run_child(library, seeds, report.get_mut(), heartbeat_out, deadline));
            let code = catch_unwind(batch).unwrap_or(EXIT_FUZZER_PANIC);
            // SAFETY: ends the child without running the parent's exit handlers or flushing its buffers.
            unsafe { libc::_exit(code) }
        }
        pid => {
            // SAFETY: the parent's copy of the write end, closed once: EOF comes when the child is gone.
            unsafe { libc::close(heartbeat_out) };
            let status = supervise(pid, heartbeat_in);
            // SAFETY: the read end, closed once.
            unsafe { libc::close(heartbeat_in) };
            Ok(ending(status, report.get()))
        }
    }
}

/// The child: runs the sequences, a heartbeat byte before each; the exit status.
fn run_child(
    library: &dyn Subject,
    seeds: &[u64],
    report: &mut Report,
    heartbeat: c_int,
    deadline: Option<Instant>,
) -> c_int {
    for (i, &seed) in seeds.iter().enumerate() {
        if i > 0 && deadline.is_some_and(|d| Instant::now() >= d) {
            break;
        }
        report.running = i as u64;
        HEARTBEAT.with(|h| h.set(heartbeat));
        beat();
        let calls = report.counts.calls;
        report.me = false;
        if let Err(violation) = library.run_sequence(seed, report) {
            report.violation.set(format_args!("{violation}"));
            return EXIT_VIOLATION;
        }
        report.counts.sequences += 1;
        if report.me {
            report.counts.me_sequences += 1;
            report.counts.me_calls += report.counts.calls - calls;
        }
    }
    report.done = true;
    0
}

/// Waits for the child, killing it when a sequence runs longer than `SEQUENCE_TIMEOUT`: its wait
/// status, or `None` for a hang.
fn supervise(pid: libc::pid_t, heartbeat: c_int) -> Option<c_int> {
    let mut last_beat = Instant::now();
    loop {
        let left = SEQUENCE_TIMEOUT.saturating_sub(last_beat.elapsed());
        if left.is_zero() {
            // SAFETY: our own child, not yet reaped.
            unsafe { libc::kill(pid, libc::SIGKILL) };
            reap(pid);
            return None;
        }
        let mut fd = libc::pollfd { fd: heartbeat, events: libc::POLLIN, revents: 0 };
        // SAFETY: one pollfd.
        if unsafe { libc::poll(&mut fd, 1, left.as_millis() as c_int + 1) } <= 0 {
            continue; // timeout (checked above) or EINTR
        }
        let mut buffer = [0u8; 64];
        // SAFETY: reads into a live buffer of its length.
        match unsafe { libc::read(heartbeat, buffer.as_mut_ptr().cast(), buffer.len()) } {
            0 => break, // EOF: the child has exited
            n if n > 0 => last_beat = Instant::now(),
            _ => {} // EINTR
        }
    }
    Some(reap(pid))
}

/// Waits for the child to end; its wait status.
fn reap(pid: libc::pid_t) -> c_int {
    let mut status = 0;
    // SAFETY: waits for our own child, retried when a signal interrupts.
    while unsafe { libc::waitpid(pid, &mut status, 0) } < 0 {
        if std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted {
            break;
        }
    }
    status
}

/// How a child with the wait status `status` (`None`: killed as hanging) ended, unless it
/// finished its batch.
fn ending(status: Option<c_int>, report: &Report) -> Option<String> {
    let Some(status) = status else {
        return Some(format!("hang: still running after {} s, killed", SEQUENCE_TIMEOUT.as_secs()));
    };
    if libc::WIFSIGNALED(status) {
        let s = libc::WTERMSIG(status);
        // SAFETY: strsignal returns a NUL-terminated description (or NULL).
        let p = unsafe { libc::strsignal(s) };
        let name = if p.is_null() { "?".into() } else { unsafe { CStr::from_ptr(p) }.to_string_lossy() };
        return Some(format!("crash: killed by signal {s} ({name})"));
    }
    match libc::WEXITSTATUS(status) {
        0 if report.done => None,
        EXIT_VIOLATION => Some("oracle violation".into()),
        EXIT_FUZZER_PANIC => Some("the fuzzer itself panicked (message above)".into()),
        code => Some(format!("the process exited with status {code} in the middle of its batch")),
    }
}
