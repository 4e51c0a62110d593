//! `boomsim cosim`: the co-simulation of `python/boomsim/cosim.py`'s `run` (HydraulicBoom and
//! PressureFeedbackController, FMI 2.0 Co-Simulation, Gauss-Seidel, p4 interpolated in the
//! controller) with the FMI layer called in-process instead of through fmpy: the native runner of
//! the sweeps. The Python runner is the reference; this loop makes the same calls with the same
//! arguments in the same order from the end of initialisation on (the start values are set in
//! Initialization Mode, where their order does not matter), so the recorded rows are the Python
//! runner's bit for bit (tests/python/test_sweep.py). What the scenario means (the operator's
//! reference, the recorded outputs, when the CBV counts as open) comes with the request, from
//! `cosim.py`, so it is defined once.
//!
//! Input (stdin, JSON): `stop_time`, `step`, `record_every`, `interpolate`, `feedback_start` ("t0" or
//! "cbv_open"), `enable`, `u_ref` (the operator's reference at the n + 1 communication points),
//! `outputs` (the plant's recorded variables, `p4` and `cbv.u_cbv` among them), `cbv_open` (the
//! opening above which the CBV counts as open), `plant` and `controller` (start values by variable
//! name, set in Initialization Mode). Output (stdout): one JSON line `{"rows", "columns", "rhs",
//! "feedback_on_at"}`, then the rows as little-endian f64.

use crate::in_process::{InProcess, Slave};
use boomsim::fmu::variables::BaseType;
use boomsim::fmu::{Model, Value};
use boomsim::models::pressure_feedback_controller::vr as pfc;
use boomsim::models::{HydraulicBoom, PressureFeedbackController};
use serde_json::{json, Map, Value as Json};
use std::io::Write;

/// The start values by name as (value reference, value) of `M`'s variables.
fn start_values<M: Model>(values: &Map<String, Json>) -> Result<Vec<(u32, Value)>, String> {
    let mut out = Vec::with_capacity(values.len());
    for (name, value) in values {
        let v = variable::<M>(name)?;
        let bad = || format!("{name} = {value}: not a {:?}", v.base_type());
        let x = match (v.base_type(), value) {
            (BaseType::Real, Json::Number(n)) => Value::Real(n.as_f64().ok_or_else(bad)?),
            (BaseType::Integer, Json::Number(n)) => {
                Value::Integer(n.as_f64().map(|x| x as i32).ok_or_else(bad)?) // int() of cosim.FmuFile.set
            }
            (BaseType::Boolean, Json::Bool(b)) => Value::Boolean(*b),
            (BaseType::Enumeration, Json::String(s)) => Value::Integer(v.item_value(s)?),
            // a whole number as Python's json writes it (0.0: "0" here) is an item's value
            (BaseType::Enumeration, Json::Number(n)) => {
                let whole = n.as_f64().filter(|x| x.fract() == 0.0).ok_or_else(bad)?;
                Value::Integer(v.item_value(&whole.to_string())?)
            }
            _ => return Err(bad()),
        };
        out.push((v.vr, x));
    }
    Ok(out)
}

/// A Co-Simulation instance of `M` set up for [t0, stop] without a tolerance, in Initialization
/// Mode with the `start` values set.
fn instance<M: Model>(t0: f64, stop: f64, start: &[(u32, Value)]) -> Result<InProcess<M>, String> {
    InProcess::initializing(None, t0, Some(stop), start)
}

/// `fmi2DoStep`, a discarded step an error naming the model and the time.
fn step(i: &mut dyn Slave, id: &str, t: f64, h: f64) -> Result<(), String> {
    i.step(t, h).map_err(|why| format!("fmi2DoStep of {id} at t = {t} discarded: {why}"))
}

/// Runs the co-simulation the JSON `request` describes; returns the header and the rows.
pub fn run(request: &Json) -> Result<(Json, Vec<f64>), String> {
    let field = |k: &str| request.get(k).ok_or_else(|| format!("the request has no \"{k}\""));
    let num = |k: &str| field(k)?.as_f64().ok_or_else(|| format!("\"{k}\" must be a number"));
    let (t_end, h) = (num("stop_time")?, num("step")?);
    let record_every = num("record_every")? as usize;
    let interpolate = field("interpolate")?.as_bool().ok_or("\"interpolate\" must be true or false")?;
    let enable = field("enable")?.as_bool().ok_or("\"enable\" must be true or false")?;
    let cbv_open = field("feedback_start")? == "cbv_open";
    let open_above = num("cbv_open")?;
    let list = |k: &str| field(k)?.as_array().ok_or_else(|| format!("\"{k}\" must be a list"));
    let u_refs: Vec<f64> =
        list("u_ref")?.iter().map(|u| u.as_f64().ok_or("\"u_ref\" must hold numbers")).collect::<Result<_, _>>()?;
    let recorded: Vec<&str> =
        list("outputs")?.iter().map(|o| o.as_str().ok_or("\"outputs\" must hold names")).collect::<Result<_, _>>()?;
    let map = |k: &str| field(k)?.as_object().cloned().ok_or_else(|| format!("\"{k}\" must be an object"));
    let (plant_start, ctrl_start) = (map("plant")?, map("controller")?);
    if u_refs.len() < 2 || !(h > 0.0 && record_every > 0) {
        return Err("the request needs u_ref at two points or more, step > 0 and record_every > 0".into());
    }
    let n = u_refs.len() - 1;

    let plant_vr = |name: &str| variable::<HydraulicBoom>(name).map(|v| v.vr);
    let (vr_p4, vr_u, vr_rhs) = (plant_vr("p4")?, plant_vr("valve.u_ref")?, plant_vr("solver.rhs_evals")?);
    let (plant_id, ctrl_id) = (HydraulicBoom::INFO.identifier, PressureFeedbackController::INFO.identifier);
    let mut plant = instance::<HydraulicBoom>(0.0, t_end, &start_values::<HydraulicBoom>(&plant_start)?)?;
    plant.exit_initialization_mode()?;
    let mut p4 = plant.get(vr_p4)?;
    let ctrl_start = start_values::<PressureFeedbackController>(&ctrl_start)?;
    // (Re-)initialises the controller at t0 from rest at the present p4 (`init_controller`).
    let controller =
        |t0: f64, u_ref: f64, feedback: bool, p4: f64| -> Result<InProcess<PressureFeedbackController>, String> {
            let own =
                [(pfc::ENABLE, Value::Boolean(feedback)), (pfc::P, Value::Real(p4)), (pfc::U_REF, Value::Real(u_ref))];
            let mut c = instance::<PressureFeedbackController>(t0, t_end, &[&ctrl_start[..], &own].concat())?;
            c.exit_initialization_mode()?;
            Ok(c)
        };
    let mut on = enable && !cbv_open;
    let mut ctrl = controller(0.0, u_refs[0], on, p4)?;
    let mut feedback_on_at = if on { Some(0.0) } else { None };

    let out_p: Vec<u32> = recorded.iter().map(|name| plant_vr(name)).collect::<Result<_, _>>()?;
    let at = |name: &str| recorded.iter().position(|&n| n == name).ok_or(format!("\"outputs\" must name {name}"));
    let (i_p4, i_cbv) = (at("p4")?, at("cbv.u_cbv")?);
    let outputs =
        |plant: &mut InProcess<HydraulicBoom>| out_p.iter().map(|&r| plant.get(r)).collect::<Result<Vec<_>, _>>();
    let mut rows = Vec::with_capacity((n / record_every + 1) * (4 + recorded.len()));
    let mut y = outputs(&mut plant)?;
    let mut u_ref = u_refs[0];
    for k in 0..=n {
        let t = k as f64 * h;
        let (u, u_comp) = (ctrl.get(pfc::U)?, ctrl.get(pfc::U_COMP)?);
        plant.set(vr_u, u)?;
        if k % record_every == 0 {
            rows.extend_from_slice(&[t, u_ref, u_comp, u]);
            rows.extend_from_slice(&y);
        }
        if k == n {
            break;
        }
        step(&mut plant, plant_id, t, h)?;
        y = outputs(&mut plant)?;
        let p4_next = y[i_p4];
        if interpolate {
            ctrl.set_slope(pfc::P, (p4_next - p4) / h)?;
        }
        step(&mut ctrl, ctrl_id, t, h)?;
        p4 = p4_next;
        u_ref = u_refs[k + 1];
        if enable && !on && y[i_cbv] > open_above {
            on = true;
            feedback_on_at = Some(t + h);
            ctrl = controller(t + h, u_ref, true, p4)?;
        }
        ctrl.set(pfc::P, p4)?;
        ctrl.set(pfc::U_REF, u_ref)?;
    }
    let rhs = plant.get(vr_rhs)?;
    let columns = 4 + recorded.len();
    let header =
        json!({"rows": rows.len() / columns, "columns": columns, "rhs": rhs, "feedback_on_at": feedback_on_at});
    Ok((header, rows))
}

/// `M`'s variable `name`.
fn variable<M: Model>(name: &str) -> Result<&'static boomsim::fmu::Variable, String> {
    M::VARIABLES
        .iter()
        .find(|v| v.name == name)
        .ok_or_else(|| format!("{} has no variable \"{name}\"", M::INFO.identifier))
}

/// `boomsim cosim`: the request from stdin, the result to stdout.
pub fn main() -> Result<(), String> {
    let request: Json = serde_json::from_reader(std::io::stdin().lock()).map_err(|e| format!("the request: {e}"))?;
    let (header, rows) = run(&request)?;
    let mut out = std::io::stdout().lock();
    let bytes: Vec<u8> = rows.iter().flat_map(|x| x.to_le_bytes()).collect();
    writeln!(out, "{header}").and_then(|()| out.write_all(&bytes)).map_err(|e| e.to_string())
}
