//! Zero memory growth of the FMI 2.0 life cycle, measured with a counting global allocator.
//!
//! FMI 2.0.4, section 2.1.5: fmi2FreeInstance "disposes the given instance, unloads the loaded
//! model, and frees all the allocated memory and other resources that have been allocated by the
//! functions of the FMU interface"; section 2.1.8: fmi2FreeFMUstate frees the memory of an FMU
//! state, and a state the importer never frees is memory the instance allocated, so it goes with
//! the instance. An importer that runs thousands of instances (parameter sweeps, optimisation,
//! Monte Carlo) or rolls back with FMU states in every communication step must not see the
//! process grow. This test proves, for all four models, through the same generic functions the C
//! ABI exports (`boomsim::fmi2::api::*::<Model>`), that after a warm-up iteration
//!
//! 1. 10 000 cycles fmi2Instantiate / fmi2SetupExperiment / fmi2EnterInitializationMode /
//!    fmi2ExitInitializationMode / fmi2DoStep (1 ms) / fmi2GetReal / fmi2Terminate /
//!    fmi2FreeInstance leave exactly the live bytes and live allocations they found;
//! 2. 10 000 cycles fmi2GetFMUstate (new) / fmi2SerializedFMUstateSize / fmi2SerializeFMUstate /
//!    fmi2DeSerializeFMUstate / fmi2SetFMUstate / fmi2FreeFMUstate (both states) on one live
//!    instance per model leave the live memory unchanged;
//! 3. an instance that makes 100 FMU states (fmi2GetFMUstate with *FMUstate = NULL and
//!    fmi2DeSerializeFMUstate) and never frees them returns, in fmi2FreeInstance, to exactly the
//!    live bytes before its fmi2Instantiate;
//! 4. a state overwritten in place (fmi2GetFMUstate with *FMUstate a state of this instance,
//!    section 2.1.8) between steps does not grow memory;
//! 5. fmi2DoStep in the real-time mode (`solver.mode` = 1, the flexible boom lowering with the
//!    smallest `solver.rhs_budget`, so closing steps occur) makes no allocator call at all: a
//!    hardware-in-the-loop step must not wait for the allocator.
//!
//! The counts are global (every thread), so the checks run in the binary's own `main` on one
//! thread (no libtest harness, whose thread allocated during a measurement now and then: 900
//! bytes in 4 allocations, seen once in four runs on the loaded 2-core machine), and nothing
//! prints while a measurement is open. The logger the FMU gets writes with `libc::write`, so a message cannot
//! disturb the count either; any message fails the test (none is expected).
//!
//! Run: `cargo test --release --test leaks` (prints the measured numbers).

#[path = "../common/mod.rs"]
mod common;

use boomsim::fmu::guid::guid;
use boomsim::fmi2::types::*;
use boomsim::fmi2::api;
use boomsim::fmu::Model;
use boomsim::models::{BoomMechanics, HydraulicBoom, HydraulicCircuit, PressureFeedbackController as Pfc};
use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::{CStr, CString};
use std::os::raw::{c_char, c_int};
use std::sync::atomic::{AtomicIsize, AtomicU64, AtomicUsize, Ordering::Relaxed};
use std::time::Instant;

/// `std::alloc::System`, counting live bytes, live allocations and allocation calls.
struct Counting;

static LIVE_BYTES: AtomicIsize = AtomicIsize::new(0);
static LIVE_ALLOCS: AtomicIsize = AtomicIsize::new(0);
static CALLS: AtomicU64 = AtomicU64::new(0);

/// Counts the allocation `p` of `layout` if it succeeded, and returns it.
fn counted(p: *mut u8, layout: Layout) -> *mut u8 {
    if !p.is_null() {
        LIVE_BYTES.fetch_add(layout.size() as isize, Relaxed);
        LIVE_ALLOCS.fetch_add(1, Relaxed);
        CALLS.fetch_add(1, Relaxed);
    }
    p
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        counted(System.alloc(layout), layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        counted(System.alloc_zeroed(layout), layout)
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        System.dealloc(p, layout);
        LIVE_BYTES.fetch_sub(layout.size() as isize, Relaxed);
        LIVE_ALLOCS.fetch_sub(1, Relaxed);
    }
    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let q = System.realloc(p, layout, new_size);
        if !q.is_null() {
            LIVE_BYTES.fetch_add(new_size as isize - layout.size() as isize, Relaxed);
            CALLS.fetch_add(1, Relaxed);
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The allocator's counters at one moment.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Live {
    bytes: isize,
    allocs: isize,
    calls: u64,
}

fn live() -> Live {
    Live { bytes: LIVE_BYTES.load(Relaxed), allocs: LIVE_ALLOCS.load(Relaxed), calls: CALLS.load(Relaxed) }
}

/// Messages the FMUs logged (warnings and errors; logging is off otherwise).
static MESSAGES: AtomicUsize = AtomicUsize::new(0);

/// Counts the message and writes it to stderr without allocating.
unsafe extern "C" fn logger(
    _env: fmi2ComponentEnvironment,
    _name: fmi2String,
    status: c_int,
    _category: fmi2String,
    _format: fmi2String,
    message: *const c_char,
) {
    MESSAGES.fetch_add(1, Relaxed);
    let head: &[u8] =
        if status >= fmi2Status::Error as c_int { b"leaks: FMU error: " } else { b"leaks: FMU message: " };
    let text = CStr::from_ptr(message).to_bytes();
    for part in [head, text, b"\n"] {
        libc::write(2, part.as_ptr().cast(), part.len());
    }
}

fn callbacks() -> fmi2CallbackFunctions {
    fmi2CallbackFunctions {
        logger: common::variadic(logger),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    }
}

const OK: fmi2Status = fmi2Status::OK;
const H: f64 = 1e-3;
/// `boom.flexible` (HydraulicBoom, BoomMechanics).
const FLEXIBLE: u32 = 31;

/// What an importer keeps for one model: instance name, GUID and callbacks. Made before a
/// measurement starts and dropped after it ends.
struct Importer {
    name: CString,
    guid: CString,
    callbacks: fmi2CallbackFunctions,
}

impl Importer {
    fn of<M: Model>() -> Self {
        Importer {
            name: CString::new("leaks").unwrap(),
            guid: CString::new(guid::<M>()).unwrap(),
            callbacks: callbacks(),
        }
    }
}

/// fmi2Instantiate, fmi2SetupExperiment and the initialisation, with `boom.flexible` set in
/// initialisation mode when `flexible` is given: an instance ready to step at t = 0.
unsafe fn initialized<M: Model>(imp: &Importer, flexible: Option<bool>) -> fmi2Component {
    let c = initializing::<M>(imp);
    if let Some(f) = flexible {
        let b = if f { FMI2_TRUE } else { FMI2_FALSE };
        assert_eq!(api::set_boolean::<M>(c, &FLEXIBLE, 1, &b), OK);
    }
    assert_eq!(api::exit_initialization_mode::<M>(c), OK);
    c
}

/// fmi2Instantiate, fmi2SetupExperiment and fmi2EnterInitializationMode.
unsafe fn initializing<M: Model>(imp: &Importer) -> fmi2Component {
    let c = api::instantiate::<M>(
        imp.name.as_ptr(),
        FMI2_COSIMULATION,
        imp.guid.as_ptr(),
        std::ptr::null(),
        &imp.callbacks,
        0,
        0,
    );
    assert!(!c.is_null(), "fmi2Instantiate of {}", M::INFO.identifier);
    assert_eq!(api::setup_experiment::<M>(c, 0, 0.0, 0.0, 0, 0.0), OK);
    assert_eq!(api::enter_initialization_mode::<M>(c), OK);
    c
}

/// One whole life of an instance; returns the output read after the step.
unsafe fn life<M: Model>(imp: &Importer, flexible: Option<bool>, output: u32) -> f64 {
    let c = initialized::<M>(imp, flexible);
    assert_eq!(api::do_step::<M>(c, 0.0, H, 1), OK);
    let mut y = f64::NAN;
    assert_eq!(api::get_real::<M>(c, &output, 1, &mut y), OK);
    assert_eq!(api::terminate::<M>(c), OK);
    api::free_instance::<M>(c);
    y
}

/// One measured run: counters before and after, cycles, seconds.
#[derive(Clone, Copy)]
struct Run {
    phase: &'static str,
    case: &'static str,
    cycles: usize,
    seconds: f64,
    before: Live,
    after: Live,
}

impl Run {
    fn print(&self) {
        let calls = (self.after.calls - self.before.calls) as f64 / self.cycles.max(1) as f64;
        println!(
            "{:<9} {:<30} {:>6} cycles {:>8.3} s  live bytes {:>8} -> {:>8} (diff {:>2})  live allocations {:>5} -> {:>5}  {:>7.1} allocator calls/cycle",
            self.phase,
            self.case,
            self.cycles,
            self.seconds,
            self.before.bytes,
            self.after.bytes,
            self.after.bytes - self.before.bytes,
            self.before.allocs,
            self.after.allocs,
            calls
        );
    }

    /// Exactly zero: every allocation a cycle makes is freed in the same cycle (or, for
    /// unfreed FMU states, by fmi2FreeInstance), so the difference is 0 bytes, not "small".
    fn assert_no_growth(&self) {
        let per_cycle = (self.after.bytes - self.before.bytes) as f64 / self.cycles.max(1) as f64;
        assert_eq!(
            (self.after.bytes, self.after.allocs),
            (self.before.bytes, self.before.allocs),
            "{} {}: live memory grew by {} bytes in {} allocations over {} cycles ({per_cycle} bytes/cycle)",
            self.phase,
            self.case,
            self.after.bytes - self.before.bytes,
            self.after.allocs - self.before.allocs,
            self.cycles
        );
    }
}

/// Phase 1 for one model: `cycles` whole lives after one warm-up life.
fn lives<M: Model>(case: &'static str, flexible: Option<bool>, output: u32, cycles: usize) -> Run {
    let imp = Importer::of::<M>();
    let reference = unsafe { life::<M>(&imp, flexible, output) };
    assert!(reference.is_finite());
    let before = live();
    let t0 = Instant::now();
    for _ in 0..cycles {
        let y = unsafe { life::<M>(&imp, flexible, output) };
        assert_eq!(y.to_bits(), reference.to_bits(), "{case}: every life gives the same output");
    }
    let seconds = t0.elapsed().as_secs_f64();
    let after = live();
    Run { phase: "lives", case, cycles, seconds, before, after }
}

/// One FMU-state cycle on a live instance at time `t`: a new state, its bytes, a second state
/// from the bytes, (a step for `step`), back to the second state, both freed.
unsafe fn state_cycle<M: Model>(c: fmi2Component, t: f64, step: bool) {
    let mut s1: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(api::get_fmu_state::<M>(c, &mut s1), OK);
    let mut size = 0;
    assert_eq!(api::serialized_fmu_state_size::<M>(c, s1, &mut size), OK);
    let mut bytes = vec![0 as fmi2Byte; size];
    assert_eq!(api::serialize_fmu_state::<M>(c, s1, bytes.as_mut_ptr(), size), OK);
    if step {
        assert_eq!(api::do_step::<M>(c, t, H, 1), OK);
    }
    let mut s2: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(api::deserialize_fmu_state::<M>(c, bytes.as_ptr(), size, &mut s2), OK);
    assert_eq!(api::set_fmu_state::<M>(c, s2), OK);
    assert_eq!(api::free_fmu_state::<M>(c, &mut s1), OK);
    assert_eq!(api::free_fmu_state::<M>(c, &mut s2), OK);
    assert!(s1.is_null() && s2.is_null());
}

/// Phase 2 for one model: `cycles` state cycles on one instance that has made one step; the
/// instance is made before and freed after the measurement.
fn states<M: Model>(case: &'static str, flexible: Option<bool>, step: bool, cycles: usize) -> Run {
    let imp = Importer::of::<M>();
    unsafe {
        let c = initialized::<M>(&imp, flexible);
        assert_eq!(api::do_step::<M>(c, 0.0, H, 1), OK);
        // Every cycle returns to the state at t = H, so each step starts there.
        state_cycle::<M>(c, H, step);
        let before = live();
        let t0 = Instant::now();
        for _ in 0..cycles {
            state_cycle::<M>(c, H, step);
        }
        let seconds = t0.elapsed().as_secs_f64();
        let after = live();
        let mut t = f64::NAN;
        assert_eq!(api::get_real_status::<M>(c, FMI2_LAST_SUCCESSFUL_TIME, &mut t), OK);
        assert_eq!(t, H, "{case}: fmi2SetFMUstate went back to t = 1 ms");
        api::free_instance::<M>(c);
        Run { phase: "states", case, cycles, seconds, before, after }
    }
}

/// A state overwritten in place after every one of `cycles` steps.
fn overwrite<M: Model>(case: &'static str, flexible: Option<bool>, cycles: usize) -> Run {
    let imp = Importer::of::<M>();
    unsafe {
        let c = initialized::<M>(&imp, flexible);
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(api::get_fmu_state::<M>(c, &mut s), OK);
        let first = s;
        // Warm-up: one step and one overwrite.
        assert_eq!(api::do_step::<M>(c, 0.0, H, 1), OK);
        assert_eq!(api::get_fmu_state::<M>(c, &mut s), OK);
        let before = live();
        let t0 = Instant::now();
        for k in 1..=cycles {
            assert_eq!(api::do_step::<M>(c, k as f64 * H, H, 1), OK);
            assert_eq!(api::get_fmu_state::<M>(c, &mut s), OK);
            assert_eq!(s, first, "{case}: overwritten in place, not a new state");
        }
        let seconds = t0.elapsed().as_secs_f64();
        let after = live();
        // The state holds the last step's end: another step, back to the state, time checked.
        let end = (cycles + 1) as f64 * H;
        assert_eq!(api::do_step::<M>(c, end, H, 1), OK);
        assert_eq!(api::set_fmu_state::<M>(c, s), OK);
        let mut t = f64::NAN;
        assert_eq!(api::get_real_status::<M>(c, FMI2_LAST_SUCCESSFUL_TIME, &mut t), OK);
        assert_eq!(t, end, "{case}: the overwritten state is the latest one");
        assert_eq!(api::free_fmu_state::<M>(c, &mut s), OK);
        api::free_instance::<M>(c);
        Run { phase: "overwrite", case, cycles, seconds, before, after }
    }
}

/// Phase 5: `cycles` real-time doSteps of HydraulicBoom (flexible, u_ref = -0.1, budget 100)
/// after a warm-up step; returns the run and the closing steps above the tolerance.
fn real_time_steps(cycles: usize) -> (Run, f64) {
    use boomsim::models::hydraulic_boom::vr as hb;
    let imp = Importer::of::<HydraulicBoom>();
    unsafe {
        let c = initializing::<HydraulicBoom>(&imp);
        let (refs, ints) = ([hb::SOLVER_MODE, hb::RHS_BUDGET], [1, 100]);
        assert_eq!(api::set_integer::<HydraulicBoom>(c, refs.as_ptr(), 2, ints.as_ptr()), OK);
        assert_eq!(api::set_real::<HydraulicBoom>(c, &hb::U_REF, 1, &-0.1), OK);
        assert_eq!(api::exit_initialization_mode::<HydraulicBoom>(c), OK);
        assert_eq!(api::do_step::<HydraulicBoom>(c, 0.0, H, 1), OK);
        let before = live();
        let t0 = Instant::now();
        for k in 1..=cycles {
            assert_eq!(api::do_step::<HydraulicBoom>(c, k as f64 * H, H, 1), OK);
        }
        let seconds = t0.elapsed().as_secs_f64();
        let after = live();
        let mut inaccurate = 0.0;
        assert_eq!(api::get_real::<HydraulicBoom>(c, &hb::INACCURATE_STEPS, 1, &mut inaccurate), OK);
        api::free_instance::<HydraulicBoom>(c);
        (Run { phase: "realtime", case: "HydraulicBoom flexible doStep", cycles, seconds, before, after }, inaccurate)
    }
}

/// Orphans: an instance that makes `n` / 2 states with fmi2GetFMUstate and `n` / 2 with
/// fmi2DeSerializeFMUstate, frees none, and is freed. `before` is taken before fmi2Instantiate
/// and `after` after fmi2FreeInstance; also returns the live bytes just before the free.
fn orphans<M: Model>(case: &'static str, flexible: Option<bool>, n: usize) -> (Run, isize) {
    let imp = Importer::of::<M>();
    let mut kept = [std::ptr::null_mut(); 100];
    assert!(n <= kept.len() && n.is_multiple_of(2));
    let before = live();
    let t0 = Instant::now();
    let peak = unsafe {
        let c = initialized::<M>(&imp, flexible);
        assert_eq!(api::do_step::<M>(c, 0.0, H, 1), OK);
        for s in &mut kept[..n / 2] {
            assert_eq!(api::get_fmu_state::<M>(c, s), OK);
        }
        let mut size = 0;
        assert_eq!(api::serialized_fmu_state_size::<M>(c, kept[0], &mut size), OK);
        let mut bytes = vec![0 as fmi2Byte; size];
        assert_eq!(api::serialize_fmu_state::<M>(c, kept[0], bytes.as_mut_ptr(), size), OK);
        for s in &mut kept[n / 2..n] {
            assert_eq!(api::deserialize_fmu_state::<M>(c, bytes.as_ptr(), size, s), OK);
        }
        drop(bytes);
        assert!(kept[..n].iter().all(|s| !s.is_null()));
        let peak = live().bytes;
        api::free_instance::<M>(c);
        peak
    };
    let seconds = t0.elapsed().as_secs_f64();
    let after = live();
    (Run { phase: "orphans", case, cycles: 1, seconds, before, after }, peak)
}

fn main() {
    use boomsim::models::boom_mechanics::vr as bm;
    use boomsim::models::hydraulic_boom::vr as hb;
    use boomsim::models::hydraulic_circuit::vr as hc;
    use boomsim::models::pressure_feedback_controller::vr as pfc;

    let started = Instant::now();
    let mut runs: Vec<Run> = Vec::with_capacity(64);
    let mut peaks: Vec<(&'static str, isize, isize)> = Vec::with_capacity(16);

    // Phase 1: 10 000 lives, most of the plants' with the rigid boom (boom.flexible = false).
    let p1 = live();
    let t1 = Instant::now();
    runs.push(lives::<Pfc>("PressureFeedbackController", None, pfc::U, 2500));
    runs.push(lives::<HydraulicCircuit>("HydraulicCircuit", None, hc::P4, 2500));
    runs.push(lives::<HydraulicBoom>("HydraulicBoom rigid", Some(false), hb::P4, 2000));
    runs.push(lives::<HydraulicBoom>("HydraulicBoom flexible", None, hb::P4, 500));
    runs.push(lives::<BoomMechanics>("BoomMechanics rigid", Some(false), bm::THETA, 2000));
    runs.push(lives::<BoomMechanics>("BoomMechanics flexible", None, bm::THETA, 500));
    let (seconds, after) = (t1.elapsed().as_secs_f64(), live());
    let cycles1: usize = runs.iter().map(|r| r.cycles).sum();
    runs.push(Run { phase: "lives", case: "total", cycles: cycles1, seconds, before: p1, after });
    let first = runs.len();

    // Phase 2: 10 000 FMU-state cycles, the controller with a rolled-back step in each.
    let p2 = live();
    let t2 = Instant::now();
    runs.push(states::<Pfc>("PressureFeedbackController", None, true, 4000));
    runs.push(states::<HydraulicCircuit>("HydraulicCircuit", None, false, 2000));
    runs.push(states::<HydraulicBoom>("HydraulicBoom rigid", Some(false), false, 1800));
    runs.push(states::<HydraulicBoom>("HydraulicBoom flexible", None, false, 200));
    runs.push(states::<BoomMechanics>("BoomMechanics rigid", Some(false), false, 1800));
    runs.push(states::<BoomMechanics>("BoomMechanics flexible", None, false, 200));
    let (seconds, after) = (t2.elapsed().as_secs_f64(), live());
    let cycles2: usize = runs[first..].iter().map(|r| r.cycles).sum();
    runs.push(Run { phase: "states", case: "total", cycles: cycles2, seconds, before: p2, after });

    // A state overwritten in place between steps.
    runs.push(overwrite::<Pfc>("PressureFeedbackController", None, 2000));
    runs.push(overwrite::<HydraulicCircuit>("HydraulicCircuit", None, 200));
    runs.push(overwrite::<HydraulicBoom>("HydraulicBoom rigid", Some(false), 200));
    runs.push(overwrite::<BoomMechanics>("BoomMechanics rigid", Some(false), 200));

    // Phase 3: 100 orphaned states per instance, freed by fmi2FreeInstance. Each measured instance
    // after a warm-up instance (it has made the same calls, so the measured one finds nothing left
    // to initialise lazily).
    let cases: [(_, _, fn(&'static str, Option<bool>, usize) -> (Run, isize)); 6] = [
        ("PressureFeedbackController", None, orphans::<Pfc>),
        ("HydraulicBoom rigid", Some(false), orphans::<HydraulicBoom>),
        ("HydraulicBoom flexible", None, orphans::<HydraulicBoom>),
        ("HydraulicCircuit", None, orphans::<HydraulicCircuit>),
        ("BoomMechanics rigid", Some(false), orphans::<BoomMechanics>),
        ("BoomMechanics flexible", None, orphans::<BoomMechanics>),
    ];
    for (case, flexible, orphans) in cases {
        let _ = orphans(case, flexible, 100);
        let (run, peak) = orphans(case, flexible, 100);
        peaks.push((case, run.before.bytes, peak));
        runs.push(run);
    }
    let (real_time, inaccurate) = real_time_steps(3000);
    runs.push(real_time);
    let messages = MESSAGES.load(Relaxed);

    // Measurements done: print, then check.
    println!("leaks: counting global allocator; live bytes / live allocations before and after each run");
    runs.iter().for_each(Run::print);
    for (case, before, peak) in &peaks {
        println!("orphans   {case:<30} 100 unfreed states held {} bytes before fmi2FreeInstance", peak - before);
    }
    println!("leaks: {} s in all, {messages} FMU messages", started.elapsed().as_secs_f64());
    assert_eq!(cycles1, 10_000);
    assert_eq!(cycles2, 10_000);
    assert_eq!(messages, 0, "no FMU warned or failed (see stderr)");
    for (case, before, peak) in &peaks {
        // The orphans were really there: 100 states of at least the size of their variables.
        assert!(peak - before > 100 * 64, "{case}: the 100 states held only {} bytes", peak - before);
    }
    runs.iter().for_each(Run::assert_no_growth);
    assert!(inaccurate > 0.0, "the real-time run had closing steps beyond the tolerance");
    assert_eq!(real_time.after.calls, real_time.before.calls, "allocator calls in real-time doSteps");
}
