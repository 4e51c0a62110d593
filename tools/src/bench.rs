//! `boomsim bench`: the thesis' lowering scenarios timed in-process and through the C ABI, with
//! the integrator's work counters. Speed is reported, never asserted.
//!
//! Both paths drive the same FMI 2.0 functions: in-process through [`Instance`] (what the
//! exported symbols call), through the C ABI by loading the built shared libraries with `dlopen`
//! as an importer would.

use boomsim::fmi2::types::*;
use boomsim::fmu::{guid::guid, Model, Value};
pub use crate::in_process::{InProcess, Slave};
use boomsim::models::hydraulic_boom::vr as hb;
use boomsim::models::pressure_feedback_controller::vr as pfc;
use boomsim::models::{HydraulicBoom, PressureFeedbackController};
use std::ffi::{c_void, CStr, CString};
use std::os::raw::c_int;
use std::path::Path;
use std::time::Instant;

type Instantiate = unsafe extern "C" fn(
    fmi2String,
    c_int,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    c_int,
    c_int,
) -> fmi2Component;
type Component = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
type Setup = unsafe extern "C" fn(fmi2Component, c_int, f64, f64, c_int, f64) -> fmi2Status;
type RealIo = unsafe extern "C" fn(fmi2Component, *const u32, usize, *mut f64) -> fmi2Status;
type DoStep = unsafe extern "C" fn(fmi2Component, f64, f64, c_int) -> fmi2Status;
type SetBoolean = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const c_int) -> fmi2Status;
/// fmi2SetInteger has the same signature (fmi2Integer is a C int).
type SetInteger = SetBoolean;
type Free = unsafe extern "C" fn(fmi2Component);

/// A slave loaded from its shared library and called through the exported C functions.
pub struct CAbi {
    lib: *mut c_void,
    c: fmi2Component,
    get_real: RealIo,
    set_real: RealIo,
    do_step: DoStep,
    free: Free,
    _callbacks: Box<fmi2CallbackFunctions>,
}

/// The benchmark's logger: messages are not needed here, only a valid callback. Defined with the
/// fixed arguments only (C-variadic definitions are not stable Rust); calling it through the
/// variadic pointer type is ABI-compatible on x86_64 System V, the platform boomsim ships for.
unsafe extern "C" fn quiet(_: fmi2ComponentEnvironment, _: fmi2String, _: c_int, _: fmi2String, _: fmi2String) {}
unsafe extern "C" fn calloc(n: usize, size: usize) -> *mut c_void {
    libc::calloc(n, size)
}
unsafe extern "C" fn free(p: *mut c_void) {
    libc::free(p)
}

impl CAbi {
    /// Loads `library`, instantiates model `M` and initialises it like [`InProcess::new`].
    pub fn new<M: Model>(library: &Path, rtol: f64, start: &[(u32, Value)]) -> Result<Self, String> {
        let path = CString::new(library.to_string_lossy().as_bytes()).map_err(|e| e.to_string())?;
        // SAFETY: dlopen/dlsym with NUL-terminated names; each symbol is cast to the signature
        // the FMI 2.0 headers give it.
        unsafe {
            let lib = libc::dlopen(path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL);
            if lib.is_null() {
                return Err(format!(
                    "dlopen {}: {}",
                    library.display(),
                    CStr::from_ptr(libc::dlerror()).to_string_lossy()
                ));
            }
            let sym = |name: &CStr| {
                let p = libc::dlsym(lib, name.as_ptr());
                if p.is_null() {
                    Err(format!("{} does not export {}", library.display(), name.to_string_lossy()))
                } else {
                    Ok(p)
                }
            };
            let logger = std::mem::transmute::<
                unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, c_int, fmi2String, fmi2String),
                unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, c_int, fmi2String, fmi2String, ...),
            >(quiet);
            let callbacks = Box::new(fmi2CallbackFunctions {
                logger: Some(logger),
                allocateMemory: Some(calloc),
                freeMemory: Some(free),
                stepFinished: None,
                componentEnvironment: std::ptr::null_mut(),
            });
            let instantiate: Instantiate = std::mem::transmute(sym(c"fmi2Instantiate")?);
            let setup: Setup = std::mem::transmute(sym(c"fmi2SetupExperiment")?);
            let enter: Component = std::mem::transmute(sym(c"fmi2EnterInitializationMode")?);
            let exit: Component = std::mem::transmute(sym(c"fmi2ExitInitializationMode")?);
            let set_boolean: SetBoolean = std::mem::transmute(sym(c"fmi2SetBoolean")?);
            let set_integer: SetInteger = std::mem::transmute(sym(c"fmi2SetInteger")?);
            let (name, id) = (c"bench", CString::new(guid::<M>()).map_err(|e| e.to_string())?);
            let c = instantiate(name.as_ptr(), FMI2_COSIMULATION, id.as_ptr(), std::ptr::null(), &*callbacks, 0, 0);
            if c.is_null() {
                return Err(format!("fmi2Instantiate of {} failed", library.display()));
            }
            let mut s = CAbi {
                lib,
                c,
                get_real: std::mem::transmute(sym(c"fmi2GetReal")?),
                set_real: std::mem::transmute(sym(c"fmi2SetReal")?),
                do_step: std::mem::transmute(sym(c"fmi2DoStep")?),
                free: std::mem::transmute(sym(c"fmi2FreeInstance")?),
                _callbacks: callbacks,
            };
            check(setup(c, 1, rtol, 0.0, 0, 0.0), "fmi2SetupExperiment")?;
            check(enter(c), "fmi2EnterInitializationMode")?;
            for (r, x) in start {
                match x {
                    Value::Real(x) => s.set(*r, *x)?,
                    Value::Boolean(b) => check(set_boolean(c, r, 1, &(*b as c_int)), "fmi2SetBoolean")?,
                    Value::Integer(i) => check(set_integer(c, r, 1, i), "fmi2SetInteger")?,
                    v => return Err(format!("start value {v:?} is not a Real, Integer or Boolean")),
                }
            }
            check(exit(c), "fmi2ExitInitializationMode")?;
            Ok(s)
        }
    }
}

fn check(status: fmi2Status, function: &str) -> Result<(), String> {
    match status {
        fmi2Status::OK | fmi2Status::Warning => Ok(()),
        s => Err(format!("{function} returned {s:?}")),
    }
}

impl Slave for CAbi {
    fn set(&mut self, vr: u32, x: f64) -> Result<(), String> {
        // SAFETY: a live component, one value reference and one value.
        check(unsafe { (self.set_real)(self.c, &vr, 1, &x as *const f64 as *mut f64) }, "fmi2SetReal")
    }
    fn get(&mut self, vr: u32) -> Result<f64, String> {
        let mut x = 0.0;
        check(unsafe { (self.get_real)(self.c, &vr, 1, &mut x) }, "fmi2GetReal")?;
        Ok(x)
    }
    fn step(&mut self, t: f64, h: f64) -> Result<(), String> {
        check(unsafe { (self.do_step)(self.c, t, h, 1) }, "fmi2DoStep")
    }
}

impl Drop for CAbi {
    fn drop(&mut self) {
        // SAFETY: the component and library were created in `new` and are released once.
        unsafe {
            (self.free)(self.c);
            libc::dlclose(self.lib);
        }
    }
}

/// One benchmark result (the `--json` record).
#[derive(Debug, Clone)]
pub struct BenchResult {
    pub case: &'static str,
    pub boom: &'static str,
    pub via: &'static str,
    pub simulated_s: f64,
    pub wall_s: f64,
    pub steps: u64,
    pub rhs_evals: u64,
    pub jac_evals: u64,
}

impl BenchResult {
    /// Real-time factor: simulated time over wall time.
    pub fn rtf(&self) -> f64 {
        self.simulated_s / self.wall_s
    }

    /// Wall time per communication step (s).
    pub fn per_do_step(&self) -> f64 {
        self.wall_s / (self.simulated_s / STEP).round()
    }

    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "case": self.case, "boom": self.boom, "via": self.via, "simulated_s": self.simulated_s,
            "wall_s": self.wall_s, "rtf": self.rtf(), "steps": self.steps, "rhs_evals": self.rhs_evals,
            "jac_evals": self.jac_evals, "do_step_us": self.per_do_step() * 1e6,
        })
    }
}

/// Communication step of every case (the thesis' logging rate and the runner's default).
pub const STEP: f64 = 1e-3;
/// Relative tolerance of every case.
pub const RTOL: f64 = 1e-6;

/// Case U (section 7.1): lowering from 480 mm with u = -0.1, no compensation, `duration` s.
pub fn case_u(plant: &mut dyn Slave, duration: f64) -> Result<(), String> {
    plant.set(hb::U_REF, -0.1)?;
    steps(plant, None, 0.0, duration, None)
}

/// Case R, the cost floor of a communication step: the load held at rest (spool closed, every
/// value at its start), `duration` s of 1 ms doSteps in which nothing happens.
pub fn case_rest(plant: &mut dyn Slave, duration: f64) -> Result<(), String> {
    steps(plant, None, 0.0, duration, None)
}

/// Case B (Table 7.2): lowering with u_ref = -0.05 through the controller with the experiment-B
/// filter; Gauss-Seidel coupling p4 -> controller -> valve.u_ref (the plant has no direct
/// feedthrough, so there is no algebraic loop).
pub fn case_b(plant: &mut dyn Slave, controller: &mut dyn Slave, duration: f64) -> Result<(), String> {
    controller.set(pfc::U_REF, -0.05)?;
    steps(plant, Some(controller), 0.0, duration, None)
}

/// `duration` s of 1 ms communication steps of `plant` from `t0`, coupled to `controller` if
/// given (case B); with `record`, each plant doStep's wall and thread CPU time [s] and RHS
/// evaluations.
fn steps(
    plant: &mut dyn Slave,
    mut controller: Option<&mut dyn Slave>,
    t0: f64,
    duration: f64,
    mut record: Option<&mut Vec<[f64; 3]>>,
) -> Result<(), String> {
    let n = (duration / STEP).round() as usize;
    let mut rhs = if record.is_some() { plant.get(hb::SOLVER_RHS)? } else { 0.0 };
    for k in 0..n {
        let t = t0 + k as f64 * STEP;
        if let Some(c) = controller.as_deref_mut() {
            c.set(pfc::P, plant.get(hb::P4)?)?;
            plant.set(hb::U_REF, c.get(pfc::U)?)?;
        }
        match record.as_deref_mut() {
            None => plant.step(t, STEP)?,
            Some(r) => {
                let (wall, cpu) = (Instant::now(), thread_cpu_time());
                plant.step(t, STEP)?;
                let (cpu, wall) = (thread_cpu_time() - cpu, wall.elapsed().as_secs_f64());
                let total = plant.get(hb::SOLVER_RHS)?;
                r.push([wall, cpu, total - rhs]);
                rhs = total;
            }
        }
        if let Some(c) = controller.as_deref_mut() {
            c.step(t, STEP)?;
        }
    }
    Ok(())
}

/// CPU time of the calling thread [s]: unlike wall time, it leaves out the time the thread
/// waits for a core on a loaded machine.
fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: a valid timespec for the call to fill.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Median, 99th and 99.9th percentile (nearest rank) and maximum of `v`.
pub fn quantiles(v: &mut [f64]) -> [f64; 4] {
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    [rank(0.5), rank(0.99), rank(0.999), v[v.len() - 1]]
}

/// The doStep distribution of one case, boom and `solver.mode` (`boomsim bench --realtime`).
#[derive(Debug, Clone)]
pub struct StepDistribution {
    pub case: &'static str,
    pub boom: &'static str,
    pub mode: &'static str,
    pub do_steps: usize,
    /// Quantiles ([`quantiles`]) of the wall time, the thread CPU time [s] and the RHS
    /// evaluations of one plant doStep.
    pub wall: [f64; 4],
    pub cpu: [f64; 4],
    pub rhs: [f64; 4],
    /// Closing steps of the real-time mode over the run, and those above the tolerance.
    pub inaccurate: u64,
}

/// Case "random", the worst case of a hardware-in-the-loop run: the operator's reference switched
/// every 0.5 s to a value drawn uniformly from [-1, 1] (a fixed-seed linear congruential
/// generator), lifting when the stroke is below 150 mm and lowering above 600 mm, `duration` s.
fn case_random(plant: &mut dyn Slave, duration: f64, record: &mut Vec<[f64; 3]>) -> Result<(), String> {
    let mut seed = 12345u64;
    for k in 0..(duration / 0.5).ceil() as usize {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let u = (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
        let x = plant.get(hb::X)?;
        plant.set(hb::U_REF, if x < 0.15 { u.abs() } else if x > 0.6 { -u.abs() } else { u })?;
        let t0 = k as f64 * 0.5;
        steps(plant, None, t0, (duration - t0).min(0.5), Some(record))?;
    }
    Ok(())
}

/// Cases U, B (rigid and flexible boom) and random (flexible), adaptive and real-time
/// (`solver.mode` 0 and 1, default `solver.rhs_budget`), each run `repeats` times from the start
/// for `duration` s on fresh instances (in-process): the distribution of the plant's doStep over
/// all of them.
pub fn step_distributions(repeats: usize, duration: f64) -> Result<Vec<StepDistribution>, String> {
    let mut out = Vec::new();
    let cases = [
        ("U", "rigid", false),
        ("B", "rigid", false),
        ("U", "flexible", true),
        ("B", "flexible", true),
        ("random", "flexible", true),
    ];
    for (case, boom, flexible) in cases {
        for (mode, code) in [("adaptive", 0), ("realtime", 1)] {
            let start = [(hb::FLEXIBLE, Value::Boolean(flexible)), (hb::SOLVER_MODE, Value::Integer(code))];
            let (mut record, mut inaccurate) = (Vec::with_capacity(repeats * (duration / STEP) as usize), 0);
            for _ in 0..repeats {
                let mut p = InProcess::<HydraulicBoom>::new(RTOL, &start)?;
                if case == "U" {
                    p.set(hb::U_REF, -0.1)?;
                    steps(&mut p, None, 0.0, duration, Some(&mut record))?;
                } else if case == "B" {
                    let c_start = [(pfc::P, Value::Real(p.get(hb::P4)?))];
                    let mut c = InProcess::<PressureFeedbackController>::new(RTOL, &c_start)?;
                    c.set(pfc::U_REF, -0.05)?;
                    steps(&mut p, Some(&mut c), 0.0, duration, Some(&mut record))?;
                } else {
                    case_random(&mut p, duration, &mut record)?;
                }
                inaccurate += p.get(hb::INACCURATE_STEPS)? as u64;
            }
            let column = |i: usize| quantiles(&mut record.iter().map(|r| r[i]).collect::<Vec<_>>());
            let (wall, cpu, rhs) = (column(0), column(1), column(2));
            out.push(StepDistribution { case, boom, mode, do_steps: record.len(), wall, cpu, rhs, inaccurate });
        }
    }
    Ok(out)
}

/// Runs `case` on `plant` and reads the solver counters afterwards.
fn timed(
    (case, boom, via): (&'static str, &'static str, &'static str),
    plant: &mut dyn Slave,
    run: impl FnOnce(&mut dyn Slave) -> Result<(), String>,
    duration: f64,
) -> Result<BenchResult, String> {
    let start = Instant::now();
    run(plant)?;
    let wall_s = start.elapsed().as_secs_f64();
    let count = |plant: &mut dyn Slave, r| plant.get(r).map(|x| x as u64);
    Ok(BenchResult {
        case,
        boom,
        via,
        simulated_s: duration,
        wall_s,
        steps: count(plant, hb::SOLVER_STEPS)?,
        rhs_evals: count(plant, hb::SOLVER_RHS)?,
        jac_evals: count(plant, hb::SOLVER_JACOBIANS)?,
    })
}

/// Every benchmark: cases U, B and R (at rest) with the rigid and the flexible (4 + 5) boom,
/// in-process and through the C ABI of the libraries in `library_dir` (`lib<ModelIdentifier>.so`, as
/// `cargo build --release` leaves them); `changes`: the HydraulicBoom's parameters besides the
/// boom switch (value reference, value).
pub fn run_all(library_dir: &Path, duration: f64, changes: &[(u32, Value)]) -> Result<Vec<BenchResult>, String> {
    let lib = |id: &str| library_dir.join(format!("lib{id}.so"));
    let (hb_lib, pfc_lib) = (lib(HydraulicBoom::INFO.identifier), lib(PressureFeedbackController::INFO.identifier));
    let mut out = Vec::new();
    for (boom, flexible) in [("rigid", false), ("flexible", true)] {
        let start: Vec<_> =
            [(hb::FLEXIBLE, Value::Boolean(flexible))].into_iter().chain(changes.iter().cloned()).collect();
        for via in ["in-process", "c-abi"] {
            let plant = || -> Result<Box<dyn Slave>, String> {
                Ok(match via {
                    "in-process" => Box::new(InProcess::<HydraulicBoom>::new(RTOL, &start)?),
                    _ => Box::new(CAbi::new::<HydraulicBoom>(&hb_lib, RTOL, &start)?),
                })
            };
            let mut p = plant()?;
            out.push(timed(("U", boom, via), p.as_mut(), |p| case_u(p, duration), duration)?);
            let mut p = plant()?;
            let c_start = [(pfc::P, Value::Real(p.get(hb::P4)?))];
            let mut c: Box<dyn Slave> = match via {
                "in-process" => Box::new(InProcess::<PressureFeedbackController>::new(RTOL, &c_start)?),
                _ => Box::new(CAbi::new::<PressureFeedbackController>(&pfc_lib, RTOL, &c_start)?),
            };
            out.push(timed(("B", boom, via), p.as_mut(), |p| case_b(p, c.as_mut(), duration), duration)?);
            let mut p = plant()?;
            out.push(timed(("R", boom, via), p.as_mut(), |p| case_rest(p, duration), duration)?);
        }
    }
    Ok(out)
}
/// Cost of one setReal + doStep + getReal cycle of the controller, in seconds, over `n` cycles.
pub fn controller_cycle(slave: &mut dyn Slave, n: usize) -> Result<f64, String> {
    let start = Instant::now();
    for k in 0..n {
        let t = k as f64 * STEP;
        slave.set(pfc::P, 50e5 + 1e5 * (t * 20.0).sin())?;
        slave.step(t, STEP)?;
        std::hint::black_box(slave.get(pfc::U)?);
    }
    Ok(start.elapsed().as_secs_f64() / n as f64)
}
