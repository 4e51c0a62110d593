//! The account of a batch child (counts, failure message, the last calls), in memory shared
//! with the parent so that it survives a crash; the parent's tallies of them.

use crate::callbacks::LogSink;
use crate::fmu_states::Status;
use std::borrow::Cow;
use std::collections::BTreeSet;
use std::fmt;
use std::ptr::null_mut;
use std::time::Duration;

/// Calls of the failing sequence shown with a failure.
const TRACE_LEN: usize = 16;
/// `TraceEntry::outcome` of a call that has not returned: the crash or hang is in it.
const NO_RETURN: i64 = i64::MIN;
/// `TraceEntry::outcome` of a function without a status.
const NO_STATUS: i64 = i64::MIN + 1;

/// Text in a fixed buffer, cut at `N` bytes.
#[repr(C)]
pub struct Line<const N: usize> {
    len: usize,
    bytes: [u8; N],
}

impl<const N: usize> Line<N> {
    pub fn set(&mut self, args: fmt::Arguments) {
        self.len = 0;
        // A full line ends the formatting early; the cut text is what is kept.
        let _ = fmt::write(self, args);
    }

    pub fn text(&self) -> Cow<'_, str> {
        String::from_utf8_lossy(&self.bytes[..self.len.min(N)])
    }
}

impl<const N: usize> fmt::Write for Line<N> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let n = s.len().min(N - self.len);
        self.bytes[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        if n < s.len() {
            Err(fmt::Error)
        } else {
            Ok(())
        }
    }
}

/// One recorded call: its status, `NO_RETURN` or `NO_STATUS`, and what was called.
#[repr(C)]
pub struct TraceEntry {
    outcome: i64,
    line: Line<256>,
}

/// A batch child's account. Only integers, booleans and bytes: all zero is the empty report.
#[repr(C)]
pub struct Report {
    /// Print every call to stderr as it happens (replay).
    pub echo: bool,
    /// The sequence running is an FMI 3.0 one (status names).
    pub fmi3: bool,
    /// The sequence running has a Model Exchange instance (set at its main instantiation).
    pub me: bool,
    /// Index in the batch of the sequence running (or failed).
    pub running: u64,
    /// The child finished its batch (or ran out of time) normally.
    pub done: bool,
    /// `sequences` counts those completed.
    pub counts: Counts,
    first_internal_error_seed: u64,
    first_internal_error: Line<512>,
    /// The oracle violation; empty unless a sequence failed.
    pub violation: Line<1024>,
    /// Calls of the current sequence so far; the last `TRACE_LEN` are in `trace`.
    pub traced: u64,
    trace: [TraceEntry; TRACE_LEN],
}

impl Report {
    /// An empty report on the heap (replay).
    pub fn boxed() -> Box<Report> {
        // SAFETY: all zero is a valid Report (integers, booleans and byte arrays).
        unsafe { Box::<Report>::new_zeroed().assume_init() }
    }

    /// The entry of call `n` (from 1) of the sequence.
    fn entry(&mut self, n: u64) -> &mut TraceEntry {
        &mut self.trace[(n % TRACE_LEN as u64) as usize]
    }

    /// The recorded calls of the sequence with their numbers, oldest first.
    fn tail(&self) -> impl Iterator<Item = (u64, &TraceEntry)> {
        let first = self.traced.saturating_sub(TRACE_LEN as u64) + 1;
        (first..=self.traced).map(|n| (n, &self.trace[(n % TRACE_LEN as u64) as usize]))
    }

    /// Records a call about to be made.
    pub fn begin(&mut self, call: fmt::Arguments) {
        self.counts.calls += 1;
        self.traced += 1;
        let (n, echo) = (self.traced, self.echo);
        let entry = self.entry(n);
        entry.outcome = NO_RETURN;
        entry.line.set(call);
        if echo {
            eprintln!("#{n} {}", entry.line.text());
        }
    }

    /// Records the status of the call that returned.
    pub fn end(&mut self, status: Option<Status>) {
        let (echo, fmi3) = (self.echo, self.fmi3);
        let entry = self.entry(self.traced);
        entry.outcome = status.map_or(NO_STATUS, i64::from);
        if echo {
            eprintln!("     -> {}", outcome(entry.outcome, fmi3));
        }
    }

    /// Adds the logger's counts of the sequence `seed`.
    pub fn absorb_log(&mut self, seed: u64, sink: LogSink) {
        self.counts.messages += sink.messages;
        if let (0, Some(first)) = (self.counts.internal_errors, &sink.first_internal_error) {
            self.first_internal_error_seed = seed;
            self.first_internal_error.set(format_args!("{first}"));
        }
        self.counts.internal_errors += sink.internal_errors;
    }

    /// The sequence seed and message of the first log message that reported a caught panic.
    pub fn first_internal_error(&self) -> Option<(u64, String)> {
        let first = (self.first_internal_error_seed, self.first_internal_error.text().into_owned());
        (self.counts.internal_errors > 0).then_some(first)
    }

    /// What tells failures apart: the model, how the child ended, the function of the last call
    /// and the first two words of the violation and the first three of its reason (after the
    /// first ": ", where it has one), without digits (names and values that follow differ
    /// between failures of one kind).
    pub fn signature(&self, identifier: &str, ending: &str) -> String {
        let last = self.tail().last().map(|(_, e)| e.line.text().into_owned()).unwrap_or_default();
        let function = last.split([' ', '(', '{']).next().unwrap_or_default();
        let violation = self.violation.text();
        let words = |text: &str, n| text.split(' ').take(n).collect::<Vec<_>>().join(" ");
        let reason = violation.split_once(": ").map_or(String::new(), |(_, why)| words(why, 3));
        let message: String =
            format!("{} / {reason}", words(&violation, 2)).chars().filter(|c| !c.is_ascii_digit()).collect();
        format!("{identifier}: {ending}: {function}: {message}")
    }

    /// Prints a failure: the seed, how the child ended, the violation, the last calls, the
    /// replay command and, for a sequence drawn from a master seed (`new`), the line that adds
    /// it to the regressions. Pointers are numbered in their order of appearance, so that two
    /// runs print the same (the addresses differ with the address-space layout).
    pub fn print_failure(&self, subject: &dyn Subject, seed: u64, ending: &str, new: bool) {
        let mut pointers = Pointers::default();
        eprintln!("fuzz: FAILURE in {} (FMI {}), sequence seed {seed}: {ending}", subject.identifier(), subject.fmi());
        let violation = self.violation.text();
        if !violation.is_empty() {
            eprintln!("fuzz:   {}", pointers.name(&violation));
        }
        eprintln!("fuzz:   last calls of the sequence:");
        for (n, entry) in self.tail() {
            let call = pointers.name(&entry.line.text());
            eprintln!("fuzz:     #{n} {call} -> {}", outcome(entry.outcome, self.fmi3));
        }
        eprintln!("fuzz:   replay: bash scripts/fuzz --lib {} --seed {seed} --replay", subject.path().display());
        if new {
            let what = if violation.is_empty() { ending } else { &violation };
            let words: Vec<&str> = what.split_whitespace().take(REGRESSION_WORDS).collect();
            let what = words.join(" ").replace(['\'', '\\'], "");
            eprintln!(
                "fuzz:   add it: echo '{} {seed}  # {what}' >> {}",
                subject.identifier(),
                crate::regressions::LIST
            );
        }
    }
}

/// Words of the violation in the line that adds a failure to the regressions.
const REGRESSION_WORDS: usize = 12;

/// Names for the pointers of a failure's text (`ptr1`, `ptr2`, ... in their order of appearance;
/// NULL stays `0x0`).
#[derive(Default)]
struct Pointers(Vec<String>);

impl Pointers {
    /// `text` with every hexadecimal address replaced by its name.
    fn name(&mut self, text: &str) -> String {
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(at) = rest.find("0x") {
            out.push_str(&rest[..at]);
            let digits = rest[at + 2..].find(|c: char| !c.is_ascii_hexdigit()).unwrap_or(rest.len() - at - 2);
            let address = &rest[at..at + 2 + digits];
            if address.trim_start_matches("0x").trim_start_matches('0').is_empty() {
                out.push_str(address);
            } else {
                let k = self.0.iter().position(|a| a == address).unwrap_or_else(|| {
                    self.0.push(address.to_owned());
                    self.0.len() - 1
                });
                out.push_str(&format!("ptr{}", k + 1));
            }
            rest = &rest[at + 2 + digits..];
        }
        out.push_str(rest);
        out
    }
}

/// A call's outcome for people, with FMI 2.0's or (`fmi3`) FMI 3.0's status names.
pub fn outcome(outcome: i64, fmi3: bool) -> String {
    let v = if fmi3 { 3 } else { 2 };
    match outcome {
        NO_RETURN => "no return: the crash or hang is in this call".into(),
        NO_STATUS => "returned".into(),
        0 => format!("fmi{v}OK"),
        1 => format!("fmi{v}Warning"),
        2 => format!("fmi{v}Discard"),
        3 => format!("fmi{v}Error"),
        4 => format!("fmi{v}Fatal"),
        s => format!("{s}, not an fmi{v}Status"),
    }
}

/// What is fuzzed: one library through one FMI version.
pub trait Subject {
    fn identifier(&self) -> &str;
    fn path(&self) -> &std::path::Path;
    /// 2 or 3.
    fn fmi(&self) -> u8;
    /// Runs the sequence of `seed`, adding to `report`; `Err` is the oracle violation.
    fn run_sequence(&self, seed: u64, report: &mut Report) -> Result<(), String>;
}

/// A `Report` in an anonymous shared mapping, inherited by the forked children.
pub struct SharedReport(*mut Report);

impl SharedReport {
    pub fn new() -> Result<Self, String> {
        // SAFETY: a fresh anonymous mapping, zero-filled by the kernel: an empty Report.
        let p = unsafe {
            libc::mmap(
                null_mut(),
                size_of::<Report>(),
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_SHARED | libc::MAP_ANONYMOUS,
                -1,
                0,
            )
        };
        if p == libc::MAP_FAILED {
            return Err(format!("mmap: {}", std::io::Error::last_os_error()));
        }
        Ok(SharedReport(p.cast()))
    }

    pub fn clear(&mut self) {
        // SAFETY: the mapping holds one Report; all zero is a valid one.
        unsafe { std::ptr::write_bytes(self.0, 0, 1) }
    }

    /// The report; in the parent only while no child runs.
    pub fn get(&self) -> &Report {
        // SAFETY: the mapping holds one Report, written only by a child that has exited.
        unsafe { &*self.0 }
    }

    pub fn get_mut(&mut self) -> &mut Report {
        // SAFETY: as `get`; in the child, the only reference.
        unsafe { &mut *self.0 }
    }
}

impl Drop for SharedReport {
    fn drop(&mut self) {
        // SAFETY: the mapping made in `new`, unmapped once.
        unsafe { libc::munmap(self.0.cast(), size_of::<Report>()) };
    }
}

/// What the sequences of a batch, of a library or of the run add up to.
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub struct Counts {
    pub sequences: u64,
    pub calls: u64,
    /// Of `sequences` and `calls`, those of Model Exchange instances (the rest: Co-Simulation).
    pub me_sequences: u64,
    pub me_calls: u64,
    pub messages: u64,
    pub internal_errors: u64,
}

impl Counts {
    pub fn add(&mut self, other: Counts) {
        self.sequences += other.sequences;
        self.calls += other.calls;
        self.me_sequences += other.me_sequences;
        self.me_calls += other.me_calls;
        self.messages += other.messages;
        self.internal_errors += other.internal_errors;
    }
}

/// One library's run (or all of them).
#[derive(Default)]
pub struct Tally {
    pub elapsed: Duration,
    pub counts: Counts,
    pub failures: u64,
    /// Kinds of failure (see `Report::signature`); each is shown once. Ordered: a hash set frees
    /// in a random order, and the forked children would inherit a heap laid out differently.
    pub kinds: BTreeSet<String>,
    /// The sequence seed and message of the first log message that reported a caught panic.
    pub first_internal_error: Option<(u64, String)>,
}

impl Tally {
    /// Adds another library's tally with its elapsed time.
    pub fn add_timed(&mut self, other: &Tally) {
        self.counts.add(other.counts);
        self.failures += other.failures;
        self.kinds.extend(other.kinds.iter().cloned());
        self.elapsed += other.elapsed;
    }

    /// Adds another library's tally but its elapsed time.
    pub fn add(&mut self, other: Tally) {
        self.counts.add(other.counts);
        self.failures += other.failures;
        self.kinds.extend(other.kinds);
    }

    /// The summary line named `name`; with the elapsed time and calls per second for a run on
    /// a time budget (`timed`), else only what repeats exactly.
    pub fn line(&self, name: &str, timed: bool) -> String {
        let c = &self.counts;
        let seconds = self.elapsed.as_secs_f64();
        let (time, rate) = match timed {
            true => (format!(" {seconds:.1} s,"), format!("; {:.0} calls/s", c.calls as f64 / seconds.max(1e-9))),
            false => (String::new(), String::new()),
        };
        let kinds = match self.kinds.len() {
            _ if self.failures == 0 => String::new(),
            1 => " (1 kind, each shown once)".into(),
            n => format!(" ({n} kinds, each shown once)"),
        };
        format!(
            "{name}{time} {} sequences (CS {}, ME {}), {} calls (CS {}, ME {}{rate}), {} failures{kinds}, {} log messages, {} internal errors",
            c.sequences,
            c.sequences - c.me_sequences,
            c.me_sequences,
            c.calls,
            c.calls - c.me_calls,
            c.me_calls,
            self.failures,
            c.messages,
            c.internal_errors
        )
    }
}
