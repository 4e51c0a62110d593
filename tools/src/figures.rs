//! The figures of the FMUs' documentation pages, generated at pack time from the models: the
//! circuit schematic (thesis Fig. 2.8) labelled with the variables' names, and plots of runs
//! through the FMI layer (the same instance code an importer drives).

use crate::chart::{chart, escape, Panel};
use crate::in_process::{InProcess, Slave};
use boomsim::control::FEEDBACK_PARAMS;
use boomsim::fmu::log::num;
use boomsim::fmu::variables::Kind;
use boomsim::fmu::Model;
use boomsim::fmu::{Value, Variable};
use boomsim::models::pressure_feedback_controller::vr as pfc;
use boomsim::models::vr;
use boomsim::models::{
    BoomMechanics, ClockedPressureFeedbackController, HydraulicBoom, HydraulicCircuit, PressureFeedbackController,
};
use std::fmt::Write;

/// The figures of a model's documentation/index.html (HTML with inline SVG), generated when the
/// FMU is packed.
pub trait Figures: Model {
    fn figures() -> String;
}

impl Figures for HydraulicBoom {
    fn figures() -> String {
        schematic::<Self>("the boom") + &lowering::<Self>(U_REFERENCE)
    }
}

impl Figures for HydraulicCircuit {
    fn figures() -> String {
        schematic::<Self>("the mechanical port")
    }
}

impl Figures for BoomMechanics {
    fn figures() -> String {
        force_step::<Self>()
    }
}

/// None yet: the page's reference results show its sampled response.
impl Figures for ClockedPressureFeedbackController {
    fn figures() -> String {
        String::new()
    }
}

impl Figures for PressureFeedbackController {
    /// The step response: p steps by 1 bar.
    fn figures() -> String {
        const T_STEP: f64 = 0.05;
        const DP: f64 = 1e5;
        let record = [pfc::P, pfc::U_COMP];
        let step = |t: f64, _: &[f64]| vec![(pfc::P, if t >= T_STEP - 1e-12 { DP } else { 0.0 })];
        let title = "PressureFeedbackController: p steps by 1 bar at t = 0.05 s";
        let plotted = plot::<PressureFeedbackController>(title, 0.25, &[], step, &record, &[&[0], &[1]]);
        figure(plotted, |t, data| {
            let at = |time: f64| t.iter().position(|&x| x >= time - 1e-12).map_or(f64::NAN, |k| data[1][k]);
            let tau = 1.0 / FEEDBACK_PARAMS[1].spec.default;
            format!(
                "With the start values (K_f = {}, omega_f = {} rad/s, Q_rated = {} l/min), the compensation follows \
                 the high-pass filter of eq. 6.2: u_comp jumps to {} % when p rises by 1 bar and {} ms (1/omega_f) \
                 later is {} %, then decays to zero while p stays. Computed by this FMU's model when it was packed.",
                num(FEEDBACK_PARAMS[0].spec.default),
                num(FEEDBACK_PARAMS[1].spec.default),
                num(FEEDBACK_PARAMS[2].spec.default * 60_000.0),
                num((at(T_STEP + 1e-3) * 1e4).round() / 100.0),
                num((tau * 1e4).round() / 10.0),
                num((at(T_STEP + 1e-3 + tau) * 1e4).round() / 100.0),
            )
        })
    }
}

/// A Co-Simulation run of `M` (in-process through the FMI layer, as `boomsim bench` runs it)
/// with the default experiment's start, step and tolerance, to `stop`: `setup` set in
/// Initialization Mode, `inputs(t, recorded values at t)` before each step; returns the
/// communication times and, per `record`ed variable, its values (SI).
pub(crate) fn run<M: Model>(
    stop: f64,
    setup: &[(u32, Value)],
    inputs: impl Fn(f64, &[f64]) -> Vec<(u32, f64)>,
    record: &[u32],
) -> Result<(Vec<f64>, Vec<Vec<f64>>), String> {
    let i = &M::INFO;
    let mut slave = InProcess::<M>::new(i.default_tolerance, setup)?;
    let n = ((stop - i.start_time) / i.step_size).round() as usize;
    let (mut t, mut out) = (Vec::with_capacity(n + 1), vec![Vec::with_capacity(n + 1); record.len()]);
    let read = |slave: &mut InProcess<M>| record.iter().map(|&r| slave.get(r)).collect::<Result<Vec<f64>, _>>();
    for k in 0..=n {
        let time = i.start_time + k as f64 * i.step_size;
        let mut row = read(&mut slave)?;
        let set = inputs(time, &row);
        for &(r, x) in &set {
            slave.set(r, x)?;
        }
        if !set.is_empty() {
            // The values at t with the inputs of t.
            row = read(&mut slave)?;
        }
        t.push(time);
        out.iter_mut().zip(&row).for_each(|(o, x)| o.push(*x));
        if k < n {
            slave.step(time, i.step_size)?;
        }
    }
    Ok((t, out))
}

/// The reference of experiment U (thesis 7.1: a step of the spool reference to 0.10, lowering;
/// python/boomsim/scenarios/U.toml).
pub(crate) const U_REFERENCE: f64 = -0.10;

/// The variable of `M` with value reference `r`.
fn variable<M: Model>(r: u32) -> &'static Variable {
    M::VARIABLES.iter().find(|v| v.vr == r).expect("a variable of the table")
}

/// `r`'s name and its values in its display unit, with the unit: ("p3", [bar values], "bar").
fn shown<M: Model>(r: u32, si: &[f64]) -> (String, Vec<f64>, String) {
    let v = variable::<M>(r);
    let (unit, display) = match v.kind {
        Kind::Real { unit, display_unit, .. } => (unit, display_unit),
        _ => ("", ""),
    };
    match boomsim::units::display_unit(unit, display) {
        Some(d) => (v.name.to_owned(), si.iter().map(|x| d.factor * x + d.offset).collect(), display.to_owned()),
        None => (v.name.to_owned(), si.to_vec(), unit.to_owned()),
    }
}

/// Panels of recorded variables grouped as `groups` (indices into `record`).
fn panels<M: Model>(record: &[u32], data: &[Vec<f64>], groups: &[&[usize]]) -> Vec<Panel> {
    groups
        .iter()
        .map(|g| {
            let curves: Vec<(String, Vec<f64>, String)> = g.iter().map(|&k| shown::<M>(record[k], &data[k])).collect();
            let names: Vec<&str> = curves.iter().map(|c| c.0.as_str()).collect();
            Panel {
                axis: format!("{} [{}]", names.join(", "), curves[0].2),
                curves: curves.into_iter().map(|c| (c.0, c.1)).collect(),
            }
        })
        .collect()
}

/// Peak-to-peak of `y` over its last `fraction`.
fn swing(y: &[f64], fraction: f64) -> f64 {
    let tail = &y[((1.0 - fraction) * y.len() as f64) as usize..];
    tail.iter().copied().fold(f64::NEG_INFINITY, f64::max) - tail.iter().copied().fold(f64::INFINITY, f64::min)
}

/// A chart of a [`run`] of `M`: the `record`ed variables in display units, in panels of
/// `groups` (indices into `record`); also returns the data (SI).
pub(crate) fn plot<M: Model>(
    title: &str,
    stop: f64,
    setup: &[(u32, Value)],
    inputs: impl Fn(f64, &[f64]) -> Vec<(u32, f64)>,
    record: &[u32],
    groups: &[&[usize]],
) -> Result<(String, Vec<f64>, Vec<Vec<f64>>), String> {
    let (t, data) = run::<M>(stop, setup, inputs, record)?;
    Ok((chart(title, &t, &panels::<M>(record, &data, groups)), t, data))
}

/// A figure of a [`plot`] and its caption, or the reason the run failed.
pub(crate) fn figure(
    plotted: Result<(String, Vec<f64>, Vec<Vec<f64>>), String>,
    caption: impl Fn(&[f64], &[Vec<f64>]) -> String,
) -> String {
    match plotted {
        Ok((svg, t, data)) => format!("<figure>\n{svg}<figcaption>{}</figcaption>\n</figure>\n", caption(&t, &data)),
        Err(e) => format!("<p>(The run for this plot failed: {})</p>\n", escape(&e)),
    }
}

/// The default experiment as in FMI 2.0's DefaultExperiment, for captions.
pub(crate) fn experiment<M: Model>() -> String {
    let i = &M::INFO;
    format!("{} to {} s, communication step {} s", num(i.start_time), num(i.stop_time), num(i.step_size))
}

/// The plant's default experiment with the operator lowering at `u_ref` (experiment U of thesis
/// 7.1, without the controller): pressures, velocity, spool; the caption states what the run
/// shows.
pub(crate) fn lowering<M: Model>(u_ref: f64) -> String {
    let title = format!("{}: default experiment with valve.u_ref = {}", M::INFO.identifier, num(u_ref));
    let record = [vr::P3, vr::P4, vr::V, vr::X];
    let plotted = plot::<M>(
        &title,
        M::INFO.stop_time,
        &[(vr::U_REF, Value::Real(u_ref))],
        |_, _| vec![],
        &record,
        &[&[0, 1], &[2], &[3]],
    );
    figure(plotted, |_, data| {
        format!(
            "The default experiment ({}, every other value at its start) with <code>valve.u_ref</code> = {} from \
             t = 0, as experiment U of the thesis (section 7.1, Fig. 7.1) without the controller: the load is lowered \
             through the counterbalance valve, and over the last third of the run p3 still swings by {} bar peak to \
             peak and the cylinder velocity by {} mm/s, while the stroke falls from {} to {} mm. Computed by this \
             FMU's model when it was packed.",
            experiment::<M>(),
            num(u_ref),
            num((swing(&data[0], 1.0 / 3.0) / 1e4).round() / 10.0),
            num((swing(&data[2], 1.0 / 3.0) * 1e4).round() / 10.0),
            num((data[3][0] * 1e4).round() / 10.0),
            num((data[3][data[3].len() - 1] * 1e4).round() / 10.0),
        )
    })
}

/// The mechanics alone: the cylinder force steps from the static equilibrium `start.F` by
/// +2 % at t = 0.05 s and is held; the boom lifts and (flexible) its arm rings.
pub(crate) fn force_step<M: Model>() -> String {
    const T_STEP: f64 = 0.05;
    let record = [boomsim::models::port::vr::START_F, vr::F, vr::X, vr::TIP_DEFLECTION];
    let force = |t: f64, row: &[f64]| vec![(vr::F, row[0] * if t >= T_STEP - 1e-12 { 1.02 } else { 1.0 })];
    let title = format!("{}: cylinder.F steps by +2 % at t = {} s", M::INFO.identifier, num(T_STEP));
    let plotted = plot::<M>(&title, 0.5, &[], force, &record, &[&[1], &[2], &[3]]);
    figure(plotted, |t, data| {
        // The arm's ringing: mean crossings of the tip deflection after the first 0.1 s.
        let from = t.iter().position(|&x| x >= T_STEP + 0.1 - 1e-9).unwrap_or(0);
        let tip = &data[3][from..];
        let mean = tip.iter().sum::<f64>() / tip.len() as f64;
        let crossings = tip.windows(2).filter(|w| (w[0] - mean) * (w[1] - mean) < 0.0).count();
        let span = t[t.len() - 1] - t[from];
        format!(
            "The default boom from rest at <code>start.x</code>, first held by its static equilibrium force \
             <code>start.F</code> = {} kN, then pushed by 2 % more from t = {} s (1 ms steps): the stroke rises by {} mm \
             within the run, and the tip deflection oscillates at about {} Hz ({} mean crossings in the last {} s). \
             Computed by this FMU's model when it was packed.",
            num((data[0][0] / 100.0).round() / 10.0),
            num(T_STEP),
            num(((data[2][data[2].len() - 1] - data[2][0]) * 1e4).round() / 10.0),
            num((crossings as f64 / 2.0 / span * 10.0).round() / 10.0),
            crossings,
            num(span),
        )
    })
}

/// The circuit of thesis Fig. 2.8 as SVG, each line and valve labelled with the names of its
/// variables in `M`; `load`: what the rod drives (the boom, or the mechanical port).
pub(crate) fn schematic<M: Model>(load: &str) -> String {
    let n = |r: u32| escape(variable::<M>(r).name);
    let mut s = String::from(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 760 330\" width=\"760\" font-family=\"sans-serif\" \
         font-size=\"12\">\n<defs><marker id=\"a\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"7\" \
         markerHeight=\"7\" orient=\"auto\"><path d=\"M0 0L10 5L0 10z\"/></marker></defs>\n\
         <g fill=\"none\" stroke=\"#222\" stroke-width=\"1.5\">\n",
    );
    // Components: supply, compensator, directional valve, CBV, cylinder, tank.
    s += "<circle cx=\"40\" cy=\"250\" r=\"18\"/><path d=\"M40 236L50 256H30z\"/>\n\
          <rect x=\"100\" y=\"225\" width=\"80\" height=\"50\"/>\n\
          <rect x=\"250\" y=\"210\" width=\"160\" height=\"80\"/>\n\
          <rect x=\"420\" y=\"80\" width=\"100\" height=\"60\"/>\n\
          <rect x=\"590\" y=\"60\" width=\"120\" height=\"50\"/><line x1=\"650\" y1=\"60\" x2=\"650\" y2=\"110\" stroke-width=\"4\"/>\
          <line x1=\"650\" y1=\"85\" x2=\"745\" y2=\"85\" stroke-width=\"4\"/>\n\
          <path d=\"M300 310H330M305 316H325M310 322H320\"/><line x1=\"315\" y1=\"290\" x2=\"315\" y2=\"310\"/>\n";
    // Lines: 1 (PCV to DCV), 2 (port A to CBV), 3 (CBV to piston side), 4 (rod side to port B).
    s += "<line x1=\"58\" y1=\"250\" x2=\"100\" y2=\"250\" marker-end=\"url(#a)\"/>\n\
          <line x1=\"180\" y1=\"250\" x2=\"250\" y2=\"250\" marker-end=\"url(#a)\"/>\n\
          <polyline points=\"285,210 285,110 420,110\" marker-end=\"url(#a)\"/>\n\
          <polyline points=\"520,110 560,110 560,100 590,100\" marker-end=\"url(#a)\"/>\n\
          <polyline points=\"690,110 690,170 345,170 345,210\" marker-end=\"url(#a)\"/>\n\
          <polyline points=\"470,170 470,140\" stroke-dasharray=\"5 4\" marker-end=\"url(#a)\"/>\n\
          <polyline points=\"250,270 215,270 215,300 140,300 140,275\" stroke-dasharray=\"5 4\" marker-end=\"url(#a)\"/>\n\
</g>\n";
    let label = |s: &mut String, x: u32, y: u32, text: String| {
        let _ = writeln!(s, "<text x=\"{x}\" y=\"{y}\">{text}</text>");
    };
    label(&mut s, 14, 285, "supply".into());
    label(&mut s, 108, 244, "<tspan font-weight=\"bold\">PCV</tspan>".into());
    label(&mut s, 108, 262, n(vr::U_PCV));
    label(&mut s, 62, 240, n(vr::Q1));
    label(&mut s, 190, 240, format!("{}", n(vr::P1)));
    label(&mut s, 258, 228, "<tspan font-weight=\"bold\">DCV (PVG32)</tspan>".into());
    label(&mut s, 258, 246, format!("{}, {}", n(vr::U), n(vr::X_V)));
    label(&mut s, 258, 264, format!("{} sets the spool", n(vr::U_REF)));
    label(&mut s, 270, 206, "A".into());
    label(&mut s, 350, 206, "B".into());
    label(&mut s, 336, 318, "tank".into());
    label(&mut s, 150, 318, format!("load sensing {}", n(vr::P_X)));
    label(&mut s, 292, 100, format!("line 2: {}, {}", n(vr::P2), n(vr::Q2)));
    label(&mut s, 428, 98, "<tspan font-weight=\"bold\">CBV</tspan>".into());
    label(&mut s, 428, 116, n(vr::U_CV));
    label(&mut s, 428, 132, n(vr::U_CBV));
    label(&mut s, 478, 160, "pilot".into());
    label(&mut s, 526, 128, format!("line 3: {}, {}", n(vr::P3), n(vr::Q3)));
    label(&mut s, 560, 188, format!("line 4: {}, {}", n(vr::P4), n(vr::Q4)));
    let _ = writeln!(
        s,
        "<text x=\"750\" y=\"34\" text-anchor=\"end\">cylinder: {}, {}, {}</text>\n\
         <text x=\"750\" y=\"50\" text-anchor=\"end\">the rod drives {}</text>",
        n(vr::X),
        n(vr::V),
        n(vr::F),
        escape(load)
    );
    s += "</svg>\n";
    format!(
        "<figure>\n{s}<figcaption>{}</figcaption>\n</figure>\n",
        "The circuit of thesis Fig. 2.8 with the names of its variables: the pressure compensator (PCV) feeds line 1 \
         to the directional valve (DCV); port A feeds line 2 to the counterbalance valve (CBV) and through it line 3, \
         the piston side; the rod side, line 4, returns through port B and pilots the CBV (dashed); the load-sensing \
         pressure (dashed) sets the compensator. The arrows point the way the flows are positive (lifting); lowering reverses \
         them."
    )
}

#[cfg(test)]
mod tests {
    /// The plants' pages plot experiment U: the same reference as its scenario file.
    #[test]
    fn the_lowering_plot_uses_experiment_u() {
        let toml =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../python/boomsim/scenarios/U.toml")).unwrap();
        let line = toml.lines().find(|l| l.starts_with("reference")).unwrap();
        assert_eq!(
            line.split(['[', ']', ',']).filter_map(|x| x.trim().parse::<f64>().ok()).nth(1),
            Some(super::U_REFERENCE)
        );
    }
}
