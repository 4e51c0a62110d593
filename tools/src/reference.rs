//! Reference results inside every .fmu (issue 29 item 4), so that any importer can check itself
//! against the packed model: `documentation/reference/` holds, in the layout of the FMI
//! cross-check (no layered standard for reference results has a readable draft here),
//! `<Id>_in.csv` (the inputs: piecewise linear between rows, held after the last),
//! `<Id>_ref.opt` (start time, stop time, step size, relative tolerance), `<Id>_ref.csv` (the
//! outputs at every communication point) and `README.txt`. They are computed at pack time by the
//! packed model's own code (the same instance code the exported functions call), driven as an
//! importer such as fmpy drives a Co-Simulation FMU: the experiment's tolerance and stop time set
//! up, the inputs set at the start in Initialization Mode and before every step at its start
//! time, the outputs read after it.

use crate::in_process::{InProcess, Slave};
use boomsim::fmu::log::num;
use boomsim::fmu::model::clock_row;
use boomsim::fmu::Model;
use boomsim::models::clocked_pressure_feedback_controller::INTERVAL;
use boomsim::models::port::vr as port;
use boomsim::models::{
    BoomMechanics, ClockedPressureFeedbackController, HydraulicBoom, HydraulicCircuit, PressureFeedbackController,
};
use std::fmt::Write;

/// One reference experiment of a model.
pub struct Experiment {
    /// What it is, for the README.
    pub description: String,
    pub stop: f64,
    /// Communication step and output interval [s].
    pub step: f64,
    pub tolerance: f64,
    /// Each input by name with its (time, value) rows.
    pub inputs: Vec<(&'static str, Vec<(f64, f64)>)>,
    pub outputs: &'static [&'static str],
}

/// A model with its reference experiment.
pub trait Referenced: Model {
    fn experiment() -> Result<Experiment, String>;
}

impl Referenced for HydraulicBoom {
    /// Experiment U without the controller (thesis 7.1): the spool reference at -0.10 from rest.
    fn experiment() -> Result<Experiment, String> {
        Ok(Experiment {
            description: "Experiment U without the controller (thesis 7.1): valve.u_ref = -0.10 from rest at \
                          start.x = 480 mm, the default flexible boom; the lowering starts to oscillate."
                .into(),
            inputs: vec![("valve.u_ref", vec![(0.0, -0.10)])],
            outputs: &["p3", "p4", "cylinder.x", "cylinder.v"],
            ..standard()
        })
    }
}

impl Referenced for HydraulicCircuit {
    /// The rod held at 480 mm (plain port) while the spool opens to lift.
    fn experiment() -> Result<Experiment, String> {
        Ok(Experiment {
            description: "The rod held at cylinder.x = 480 mm, cylinder.v = 0 (plain port) while valve.u_ref ramps \
                          from 0 to 0.2 in 1 s: the circuit pressurises against the held load."
                .into(),
            inputs: vec![
                ("valve.u_ref", vec![(0.0, 0.0), (1.0, 0.2)]),
                ("cylinder.x", vec![(0.0, 0.48)]),
                ("cylinder.v", vec![(0.0, 0.0)]),
            ],
            outputs: &["p1", "p2", "p3", "p4", "cylinder.F"],
            ..standard()
        })
    }
}

impl Referenced for BoomMechanics {
    /// The default boom held by its static force, then pushed by 5 kN more (a ramp over 0.5 s).
    fn experiment() -> Result<Experiment, String> {
        let mut s = InProcess::<Self>::new(standard().tolerance, &[])?;
        let f0 = s.get(port::START_F)?;
        Ok(Experiment {
            description: format!(
                "The default boom from rest at start.x, held by its static force start.F = {} N, then pushed by \
                 5 kN more: cylinder.F ramps from start.F to start.F + 5 kN between 0.5 and 1 s (plain port).",
                num(f0)
            ),
            inputs: vec![("cylinder.F", vec![(0.0, f0), (0.5, f0), (1.0, f0 + 5e3)])],
            outputs: &["cylinder.x", "cylinder.v", "boom.theta"],
            ..standard()
        })
    }
}

impl Referenced for PressureFeedbackController {
    /// The fed-back pressure ramps by 10 bar (eq. 6.2's high pass answers its slope).
    fn experiment() -> Result<Experiment, String> {
        Ok(Experiment {
            description: "valve.u_ref = -0.05 held, p ramps from 50 to 60 bar between 0.5 and 1 s (eq. 6.2: u_comp \
                          follows the high-passed slope)."
                .into(),
            inputs: vec![("u_ref", vec![(0.0, -0.05)]), ("p", vec![(0.0, 50e5), (0.5, 50e5), (1.0, 60e5)])],
            outputs: &["u", "u_comp"],
            ..standard()
        })
    }
}

impl Referenced for ClockedPressureFeedbackController {
    /// PressureFeedbackController's experiment, sampled by the Clock.
    fn experiment() -> Result<Experiment, String> {
        Ok(Experiment { step: INTERVAL, ..PressureFeedbackController::experiment()? })
    }
}

/// 2 s at 10 ms with the models' default tolerance.
fn standard() -> Experiment {
    Experiment { description: String::new(), stop: 2.0, step: 0.01, tolerance: 1e-6, inputs: vec![], outputs: &[] }
}

/// Piecewise linear through `rows`, held before the first and after the last, in the weights
/// fmpy interpolates an input table with (w0 = (t1 - t) / (t1 - t0), w1 = 1 - w0), so that an fmpy
/// run sets the same bits.
fn at(rows: &[(f64, f64)], t: f64) -> f64 {
    match rows.iter().position(|&(ti, _)| ti > t) {
        None => rows[rows.len() - 1].1,
        Some(0) => rows[0].1,
        Some(i) => {
            let ((t0, v0), (t1, v1)) = (rows[i - 1], rows[i]);
            let w0 = (t1 - t) / (t1 - t0);
            w0 * v0 + (1.0 - w0) * v1
        }
    }
}

/// A number of the CSV files: shortest round-trip digits, in exponent form when small or large.
fn csv(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// The value reference of variable `name` of model `M`.
fn vr<M: Model>(name: &str) -> Result<u32, String> {
    M::VARIABLES.iter().find(|v| v.name == name).map(|v| v.vr).ok_or_else(|| format!("{name}: no such variable"))
}

/// The files of `documentation/reference/` for model `M`: (name, content).
pub fn files<M: Referenced>() -> Result<Vec<(String, String)>, String> {
    let e = M::experiment()?;
    let id = M::INFO.identifier;
    let inputs: Vec<(u32, &[(f64, f64)])> =
        e.inputs.iter().map(|(n, rows)| Ok((vr::<M>(n)?, rows.as_slice()))).collect::<Result<_, String>>()?;
    let outputs: Vec<u32> = e.outputs.iter().map(|n| vr::<M>(n)).collect::<Result<_, String>>()?;
    let set = |s: &mut InProcess<M>, t: f64| inputs.iter().try_for_each(|(r, rows)| s.set(*r, at(rows, t)));
    let n = (e.stop / e.step).round() as usize;
    let mut out = format!("time,{}\n", e.outputs.join(","));
    let row = |s: &mut InProcess<M>, t: f64, out: &mut String| -> Result<(), String> {
        let values: Vec<String> = outputs.iter().map(|r| s.get(*r).map(csv)).collect::<Result<_, _>>()?;
        let _ = writeln!(out, "{t},{}", values.join(","));
        Ok(())
    };
    let clocked = clock_row::<M>().is_some();
    if clocked {
        // Model Exchange: the outputs of Initialization Mode, then at every activation of the
        // Clock (every step from one step after the start) the inputs of that time set.
        let mut s = InProcess::<M>::clocked(e.stop)?;
        set(&mut s, 0.0)?;
        row(&mut s, 0.0, &mut out)?;
        s.exit_initialization_mode()?;
        for k in 1..=n {
            let t = k as f64 * e.step;
            s.tick(t, |s| set(s, t), |s| row(s, t, &mut out))?;
        }
    } else {
        let mut s = InProcess::<M>::initializing(Some(e.tolerance), 0.0, Some(e.stop), &[])?;
        set(&mut s, 0.0)?;
        s.exit_initialization_mode()?;
        row(&mut s, 0.0, &mut out)?;
        for k in 0..n {
            let (t, next) = (k as f64 * e.step, (k + 1) as f64 * e.step);
            set(&mut s, t)?;
            s.step(t, next - t)?;
            row(&mut s, next, &mut out)?;
        }
    }
    let mut input = format!("time,{}\n", e.inputs.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(","));
    let mut times: Vec<f64> = e.inputs.iter().flat_map(|(_, rows)| rows.iter().map(|r| r.0)).collect();
    times.push(e.stop);
    times.sort_by(f64::total_cmp);
    times.dedup();
    for t in times {
        let values: Vec<String> = e.inputs.iter().map(|(_, rows)| csv(at(rows, t))).collect();
        let _ = writeln!(input, "{t},{}", values.join(","));
    }
    let opt = format!("StartTime, 0\nStopTime, {}\nStepSize, {}\nRelTol, {}\n", e.stop, e.step, e.tolerance);
    let how = if clocked {
        "{id}_ref.opt: start and stop time [s], the Clock's interval = output interval [s], relative tolerance.\n\
         {id}_ref.csv: the outputs of Initialization Mode, then at every activation of the Clock, SI units.\n\
         Model Exchange: at every multiple of the interval after the start, enter Event Mode, activate the Clock \
         (fmi3SetClock), set the inputs of that time, read the outputs, fmi3UpdateDiscreteStates.\n"
    } else {
        "{id}_ref.opt: start and stop time [s], communication step = output interval [s], relative tolerance.\n\
         {id}_ref.csv: the outputs at every communication point, SI units.\n\
         Co-Simulation: set the inputs at each step's start time (held over the step), step, read the outputs.\n"
    };
    let readme = format!(
        "Reference results of {id}, computed by this FMU's model when it was packed.\n\n{}\n\n\
         {id}_in.csv: the inputs, linear between rows, held after the last.\n{}\
         Compare each column within 10 x RelTol of its largest magnitude: an importer whose times or input values \
         differ from these by rounding makes the integrator take other steps, and two runs at RelTol differ by \
         that much.\n",
        e.description,
        how.replace("{id}", id)
    );
    Ok(vec![
        (format!("{id}_in.csv"), input),
        (format!("{id}_ref.opt"), opt),
        (format!("{id}_ref.csv"), out),
        ("README.txt".into(), readme),
    ])
}
