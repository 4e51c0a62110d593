//! Linear models of the HydraulicBoom at an operating point, for control design
//! (`boomsim linearize`): `dx = A x + B u`, `y = C x + D u` of the whole nonlinear plant (the
//! circuit of Fig. 2.8 with the rigid or lumped flexible boom), rigid or flexible, from the exact
//! derivatives of its right-hand side (forward-mode dual numbers through the same equations the
//! FMUs integrate), and the same closed with the high-pass pressure feedback (eq. 6.2).
//!
//! States are the plant's native coordinates, those Co-Simulation integrates: the circuit's five
//! (p2, p3, p4, spool position, load-holding opening), then the boom's coordinates and rates
//! (rigid: the stroke and its rate; flexible: each section's absolute angle and rate). Model
//! Exchange's layout pads the flexible arm to 32 sections and gives the rigid boom its angle in
//! every slot; a linear model of it would carry those copies as uncontrollable modes.
//!
//! Operating points ([`Point`]):
//! - a steady lowering at the reference `u_ref` through the stroke `x`: every derivative zero but
//!   the coordinates', which move at the lowering's rate, found by Newton's method
//!   ([`steady_lowering`]);
//! - rest at a stroke, spool and CBV closed (friction left out, as in [`super::modes`]);
//! - the state at time `t` after the reference steps from 0 to `u_ref` at rest (the time-point
//!   form, for a lowering without a steady state).

use super::modes::{plant_values, rest};
use super::poly::eigenvalues;
use super::sine_test::run_to;
use boomsim::control::HighPassFeedback;
use boomsim::fmu::variables::Kind;
use boomsim::fmu::{Causality, Model, Value};
use boomsim::hydraulics::circuit::{N_STATES as N_CIRCUIT, P2, P3, P4, STATE_NAMES};
use boomsim::models::hydraulic_boom::{Boom, Plant};
use boomsim::models::port::Ramp;
use boomsim::models::HydraulicBoom;
use boomsim::scalar::Dual64;
use boomsim::solver::OdeSystem;
use boomsim::solver::Radau5;
use boomsim::units::P_ATM;
use nalgebra::{Complex, DMatrix, DVector};

/// A named signal of a linear model (state, input or output) with its SI unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Signal {
    pub name: String,
    pub unit: String,
}

/// `dx = A x + B u`, `y = C x + D u` in deviations from the operating point `(x0, u0, y0)`.
#[derive(Debug, Clone)]
pub struct LinearModel {
    pub states: Vec<Signal>,
    pub inputs: Vec<Signal>,
    pub outputs: Vec<Signal>,
    pub a: DMatrix<f64>,
    pub b: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub d: DMatrix<f64>,
    pub x0: Vec<f64>,
    pub u0: Vec<f64>,
    pub y0: Vec<f64>,
}

impl LinearModel {
    /// The eigenvalues of `A` (1/s), by ascending magnitude.
    pub fn eigenvalues(&self) -> Vec<Complex<f64>> {
        let mut l = eigenvalues(self.a.clone());
        l.sort_by(|a, b| a.norm().total_cmp(&b.norm()).then(a.im.total_cmp(&b.im)));
        l
    }

    /// The frequency response `C (j w I - A)^-1 B + D` at `omega` (rad/s): outputs x inputs.
    pub fn frequency_response(&self, omega: f64) -> DMatrix<Complex<f64>> {
        self.c.map(complex) * self.state_responses(omega) + self.d.map(complex)
    }

    /// `(j w I - A)^-1 B` at `omega` (rad/s): the states' responses to each input (NaN where
    /// `j w` is an eigenvalue).
    pub fn state_responses(&self, omega: f64) -> DMatrix<Complex<f64>> {
        let n = self.a.nrows();
        let m = DMatrix::<Complex<f64>>::identity(n, n) * Complex::new(0.0, omega) - self.a.map(complex);
        let b = self.b.map(complex);
        m.lu().solve(&b).unwrap_or_else(|| DMatrix::from_element(n, b.ncols(), Complex::new(f64::NAN, 0.0)))
    }

    /// The index of the state `name`.
    pub fn state(&self, name: &str) -> Result<usize, String> {
        self.states.iter().position(|s| s.name == name).ok_or_else(|| format!("the model has no state \"{name}\""))
    }

    /// The loop closed with the high-pass pressure feedback `f` (eq. 6.2, as the
    /// PressureFeedbackController computes it, without its clamp of u): the spool reference
    /// becomes `u_ref + g (p4 - x_f)` with `g = K_f omega_f / Q_rated` and the filter state
    /// `x_f' = omega_f (p4 - x_f)` is appended as `filter.p_lp`, at p4 (u_comp = 0 at the point).
    /// The first input, `valve.u_ref`, becomes the operator's reference; others stay.
    pub fn closed_loop(&self, f: &HighPassFeedback) -> Result<LinearModel, String> {
        if self.inputs.first().is_none_or(|i| i.name != "valve.u_ref") {
            return Err("the feedback acts on valve.u_ref, the model's first input".into());
        }
        let (n, m, p) = (self.a.nrows(), self.b.ncols(), self.state("p4")?);
        let g = f.k_f * f.omega_f / f.q_rated;
        let mut a = DMatrix::zeros(n + 1, n + 1);
        a.view_mut((0, 0), (n, n)).copy_from(&self.a);
        for i in 0..n {
            a[(i, p)] += self.b[(i, 0)] * g;
            a[(i, n)] = -self.b[(i, 0)] * g;
        }
        a[(n, p)] = f.omega_f;
        a[(n, n)] = -f.omega_f;
        let mut b = DMatrix::zeros(n + 1, m);
        b.view_mut((0, 0), (n, m)).copy_from(&self.b);
        let mut c = DMatrix::zeros(self.c.nrows(), n + 1);
        c.view_mut((0, 0), (self.c.nrows(), n)).copy_from(&self.c);
        for j in 0..self.c.nrows() {
            c[(j, p)] += self.d[(j, 0)] * g;
            c[(j, n)] = -self.d[(j, 0)] * g;
        }
        let mut states = self.states.clone();
        states.push(Signal { name: "filter.p_lp".into(), unit: "Pa".into() });
        let mut x0 = self.x0.clone();
        x0.push(self.x0[p]);
        Ok(LinearModel { states, a, b, c, x0, ..self.clone() })
    }

    /// The open loop of the feedback `f` at `omega` (rad/s), cut at the spool reference:
    /// `L = -G_f(j w) / Q_rated * P(j w)` with `P` from `valve.u_ref` to p4, so that the closed
    /// loop is `1 / (1 + L)` (negative feedback): the pressure a lowering (u < 0) raises closes
    /// the spool. Eq. 6.5's `G_v G_f / (C2 s + H)` in flows, with the whole plant for `G_v` and
    /// `1 / (C2 s + H)`.
    pub fn open_loop(&self, f: &HighPassFeedback, omega: f64) -> Result<Complex<f64>, String> {
        let p = self.state_responses(omega)[(self.state("p4")?, 0)];
        let jw = Complex::new(0.0, omega);
        Ok(-jw * (f.k_f / f.q_rated) / (jw / f.omega_f + 1.0) * p)
    }
}

fn complex(x: f64) -> Complex<f64> {
    Complex::new(x, 0.0)
}

/// Where to linearise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Point {
    /// A steady lowering at the spool reference `u_ref` through the stroke `stroke` (m).
    Lowering { u_ref: f64, stroke: f64 },
    /// At rest with the boom horizontal, spool and CBV closed, the rod side at `p4` (Pa) or at
    /// tank pressure, friction left out ([`super::modes::rest`]).
    Rest { p4: Option<f64> },
    /// The state at time `t` (s) after the reference steps from 0 to `u_ref` at rest at `stroke`
    /// (m), the loop open or closed by `feedback` from the step on: a scenario's lowering (U, B)
    /// run by the FMU's integrator (Radau IIA, rtol 1e-8).
    Time { u_ref: f64, stroke: f64, t: f64, feedback: Option<HighPassFeedback> },
}

/// The plant's steady lowering at `u_ref` through `stroke` ([`steady_lowering`]): the plant,
/// its state and the stroke's velocity there.
pub fn plant_point(changes: &[(&str, Value)], u_ref: f64, stroke: f64) -> Result<(Plant, Vec<f64>, f64), String> {
    let Operating { plant, x, .. } = operating_point(Point::Lowering { u_ref, stroke }, changes)?;
    let dof = plant.boom.mechanics().dof();
    let (q, qd) = x[N_CIRCUIT..].split_at(dof);
    let velocity = plant.boom.kinetics().stroke_rate(q, qd);
    Ok((plant, x, velocity))
}

/// The plant at an operating point.
pub struct Operating {
    pub plant: Plant,
    /// The plant's state.
    pub x: Vec<f64>,
    pub u_ref: f64,
    /// The feedback filter's state `filter.p_lp` of a time point run with the loop closed.
    pub filter: Option<f64>,
}

/// The plant with the parameter `changes` and its state and reference at `point`.
pub fn operating_point(point: Point, changes: &[(&str, Value)]) -> Result<Operating, String> {
    let plant = |x0: f64| -> Result<Plant, String> {
        let x = [("start.x", Value::Real(x0))];
        Plant::from_values(&plant_values(changes.iter().cloned().chain(x))?)
    };
    match point {
        Point::Lowering { u_ref, stroke } => {
            let plant = plant(stroke)?;
            let x = steady_lowering(&plant, u_ref, stroke)?;
            Ok(Operating { plant, x, u_ref, filter: None })
        }
        Point::Rest { p4 } => {
            // rest() sets the boom before `changes`: a boom.flexible there decides.
            let r = rest(true, p4, changes)?;
            Ok(Operating { plant: r.plant, x: r.state, u_ref: 0.0, filter: None })
        }
        Point::Time { u_ref, stroke, t, feedback } => {
            let plant = plant(stroke)?;
            let (x, x_f) = time_point(&plant, stroke, u_ref, t, feedback.as_ref())?;
            Ok(Operating { plant, x, u_ref, filter: feedback.map(|_| x_f) })
        }
    }
}

/// The plant's state `t` seconds after the reference steps to `u_ref` at rest at `stroke`, and
/// the filter state there with the `feedback` (without, p4).
pub fn time_point(
    plant: &Plant,
    stroke: f64,
    u_ref: f64,
    t: f64,
    feedback: Option<&HighPassFeedback>,
) -> Result<(Vec<f64>, f64), String> {
    let rest = plant.equilibrium(stroke, None)?;
    match feedback {
        Some(f) => run_to(plant, &rest, u_ref, f, t),
        None => {
            let mut plant = plant.clone();
            plant.u_ref = Ramp::new(0.0, u_ref, 0.0);
            let mut x = rest;
            let mut solver = Radau5::new(x.len());
            solver.set_tolerance(1e-8, || plant.state_scale()).map_err(|e| e.to_string())?;
            solver.integrate(&plant, 0.0, &mut x, t).map_err(|e| format!("the run to t = {t} s failed: {e}"))?;
            let p4 = x[boomsim::hydraulics::circuit::P4];
            Ok((x, p4))
        }
    }
}

/// The outputs a linear model has unless others are asked for.
pub const DEFAULT_OUTPUTS: [&str; 5] = ["p3", "p4", "cylinder.x", "cylinder.v", "boom.tip_deflection"];

/// The names and units of the plant's native states (module doc).
fn state_signals(plant: &Plant) -> Vec<Signal> {
    let unit = |name: &str| HydraulicBoom::VARIABLES.iter().find(|v| v.name == name).map_or("1".into(), unit_of);
    let mut s: Vec<Signal> = STATE_NAMES.iter().map(|n| Signal { name: n.to_string(), unit: unit(n) }).collect();
    match &plant.boom {
        Boom::Rigid(_) => {
            s.push(Signal { name: "cylinder.x".into(), unit: "m".into() });
            s.push(Signal { name: "cylinder.v".into(), unit: "m/s".into() });
        }
        Boom::Flexible(_) => {
            let dof = plant.boom.mechanics().dof();
            s.extend((1..=dof).map(|k| Signal { name: format!("boom.section[{k}].phi"), unit: "rad".into() }));
            s.extend((1..=dof).map(|k| Signal { name: format!("boom.section[{k}].omega"), unit: "rad/s".into() }));
        }
    }
    s
}

/// The seed of a dual number: 1 in the direction differentiated, else 0.
fn seed(seeded: bool) -> f64 {
    if seeded {
        1.0
    } else {
        0.0
    }
}

/// A Real variable's unit ("1" for none).
pub(crate) fn unit_of(v: &boomsim::fmu::Variable) -> String {
    match v.kind {
        Kind::Real { unit, .. } if !unit.is_empty() => unit.to_string(),
        _ => "1".to_string(),
    }
}

/// The value references and signals of the outputs `names` (outputs or locals of the plant).
fn output_signals(plant: &Plant, names: &[&str]) -> Result<Vec<(u32, Signal)>, String> {
    let x = vec![0.0; plant.dim()];
    let rows: Vec<u32> = plant.output_rows(0.0, &x).map(|(r, _)| r).collect();
    names
        .iter()
        .map(|name| {
            HydraulicBoom::VARIABLES
                .iter()
                .find(|v| v.name == *name && rows.contains(&v.vr))
                .map(|v| (v.vr, Signal { name: v.name.to_string(), unit: unit_of(v) }))
                .ok_or_else(|| {
                    let known: Vec<&str> = HydraulicBoom::VARIABLES
                        .iter()
                        .filter(|v| rows.contains(&v.vr) && v.causality == Causality::Output)
                        .map(|v| v.name)
                        .filter(|n| !n.starts_with("boom.section["))
                        .collect();
                    let known = known.join(", ");
                    let sections = "boom.section[k].phi and .omega";
                    format!("--output {name}: not an output of the HydraulicBoom; outputs: {known}, {sections}")
                })
        })
        .collect()
}

/// The plant linearised at the state `x0` and reference `u_ref` with the outputs `outputs`, from
/// exact derivatives: one dual-number evaluation per state and one for the input.
pub fn linearize(plant: &Plant, x0: &[f64], u_ref: f64, outputs: &[&str]) -> Result<LinearModel, String> {
    let n = plant.dim();
    let outs = output_signals(plant, outputs)?;
    let (mut a, mut b) = (DMatrix::zeros(n, n), DMatrix::zeros(n, 1));
    let (mut c, mut d) = (DMatrix::zeros(outs.len(), n), DMatrix::zeros(outs.len(), 1));
    let mut y0 = vec![0.0; outs.len()];
    // Seed k < n: the state k (column k of A and C); seed n: the input (B and D).
    for k in 0..=n {
        let x: Vec<Dual64> = x0.iter().enumerate().map(|(i, &x)| Dual64::new(x, seed(i == k))).collect();
        let u = Dual64::new(u_ref, seed(k == n));
        let mut dx = vec![Dual64::from(0.0); n];
        plant.rhs_with(u, &x, &mut dx);
        let rows: Vec<(u32, Dual64)> = plant.output_rows(u, &x).collect();
        let (m, f, col) = if k < n { (&mut a, &mut c, k) } else { (&mut b, &mut d, 0) };
        for (i, dx) in dx.iter().enumerate() {
            m[(i, col)] = dx.eps;
        }
        for (j, (r, _)) in outs.iter().enumerate() {
            let y = rows.iter().find(|(vr, _)| vr == r).expect("an output row").1;
            f[(j, col)] = y.eps;
            y0[j] = y.re;
        }
    }
    let bad = a.iter().chain(b.iter()).chain(c.iter()).chain(d.iter()).any(|x| !x.is_finite());
    if bad {
        return Err("the plant's derivatives are not finite at this point".into());
    }
    Ok(LinearModel {
        states: state_signals(plant),
        inputs: vec![Signal { name: "valve.u_ref".into(), unit: "1".into() }],
        outputs: outs.into_iter().map(|(_, s)| s).collect(),
        a,
        b,
        c,
        d,
        x0: x0.to_vec(),
        u0: vec![u_ref],
        y0,
    })
}

/// The steady lowering at `u_ref` through `stroke`: the plant state where every derivative is
/// zero except the coordinates', which move together at one rate (rigid: the stroke at the
/// lowering speed; flexible: every section angle at the boom's angular rate, the arm turning
/// with its shape held). Unknowns: the circuit's five states, the coordinates and that rate;
/// equations: the circuit's five derivatives, the accelerations, and the stroke. Newton's method
/// with exact Jacobians and a step halved until the scaled residual falls, from the load held at
/// rest with the spool at its steady opening, the CBV at its static opening and the rate of the
/// flow the spool passes.
pub fn steady_lowering(plant: &Plant, u_ref: f64, stroke: f64) -> Result<Vec<f64>, String> {
    if u_ref >= 0.0 {
        return Err(format!(
            "valve.u_ref = {u_ref}: a steady lowering needs a reference below 0 (the spool open towards lowering); \
             at rest use --rest, lifting has no steady state here"
        ));
    }
    let dof = plant.boom.mechanics().dof();
    let n = N_CIRCUIT + dof + 1;
    let scale = plant.state_scale();
    // The unknowns' scales: the states' up to the first rate, which the common rate takes.
    let z_scale = &scale[..n];
    // The plant state of the unknowns: every rate the common one.
    fn state<T: Copy>(z: &[T], dof: usize) -> Vec<T> {
        let (head, rate) = z.split_at(z.len() - 1);
        head.iter().copied().chain(std::iter::repeat_n(rate[0], dof)).collect()
    }
    // The residual in units of each unknown's scale (per second for the derivatives).
    let residual = |z: &[Dual64]| -> Vec<Dual64> {
        let s = state(z, dof);
        let mut ds = vec![Dual64::from(0.0); s.len()];
        plant.rhs_with(Dual64::from(u_ref), &s, &mut ds);
        let mut r: Vec<Dual64> = ds[..N_CIRCUIT].to_vec();
        r.extend_from_slice(&ds[N_CIRCUIT + dof..]);
        r.push(plant.boom.kinetics().stroke(&s[N_CIRCUIT..N_CIRCUIT + dof]) - stroke);
        r.iter_mut().zip(z_scale).for_each(|(r, s)| *r = *r / *s);
        r
    };
    let eval = |z: &[f64]| -> (Vec<f64>, DMatrix<f64>) {
        let mut j = DMatrix::zeros(n, n);
        let mut r0 = vec![0.0; n];
        for k in 0..n {
            let zd: Vec<Dual64> = z.iter().enumerate().map(|(i, &x)| Dual64::new(x, seed(i == k))).collect();
            for (i, r) in residual(&zd).into_iter().enumerate() {
                j[(i, k)] = r.eps;
                r0[i] = r.re;
            }
        }
        (r0, j)
    };
    let norm = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut z = initial_guess(plant, u_ref, stroke)?;
    let (mut r, mut j) = eval(&z);
    for _ in 0..200 {
        let step = j.clone().lu().solve(&DVector::from_vec(r.iter().map(|x| -x).collect())).ok_or_else(|| {
            format!("no steady lowering at valve.u_ref = {u_ref} through {stroke} m: a singular Jacobian")
        })?;
        // The Newton step in units of each unknown's scale.
        let size = step.iter().zip(z_scale).map(|(d, s)| (d / s).abs()).fold(0.0, f64::max);
        if size < STEP_TOLERANCE {
            return cavitation_free(state(&z, dof), u_ref, stroke);
        }
        let mut lambda = 1.0;
        loop {
            let trial: Vec<f64> = z.iter().zip(step.iter()).map(|(z, d)| z + lambda * d).collect();
            let (rt, jt) = eval(&trial);
            if rt.iter().all(|x| x.is_finite()) && norm(&rt) < norm(&r) * (1.0 - 1e-4 * lambda) {
                (z, r, j) = (trial, rt, jt);
                break;
            }
            lambda *= 0.5;
            if lambda < 1e-10 {
                return Err(no_steady_state(u_ref, stroke, norm(&r)));
            }
        }
    }
    Err(no_steady_state(u_ref, stroke, norm(&r)))
}

/// The Newton step of [`steady_lowering`] (in each unknown's scale: 1 kPa, 1 um of spool,
/// 2 urad, ...) below which the state counts as found: 1e-6 of the scales, where the residual's
/// round-off (the pressure rates of 100 bar at 1e-16) stops the iteration from converging further.
const STEP_TOLERANCE: f64 = 1e-6;

/// Refuses a steady state with a line near absolute zero: there the entrained air's bulk modulus
/// vanishes (`Fluid::bulk_modulus`), every pressure rate does with it whatever the flows, and
/// Newton's method finds "steady states" with unbalanced flows (line 2 at -1.013 bar from a
/// start at tank pressure, before the start below). Above half an atmosphere absolute the oil
/// holds 97 % of its bulk modulus at the default air fraction.
fn cavitation_free(state: Vec<f64>, u_ref: f64, stroke: f64) -> Result<Vec<f64>, String> {
    for k in [P2, P3, P4] {
        let p = state[k];
        if p < -0.5 * P_ATM {
            return Err(format!(
                "the steady lowering at valve.u_ref = {u_ref} through stroke {} mm has {} at {:.3} bar: the line \
                 cavitates there, where the linearisation means nothing; linearise at a time point of the run \
                 instead (--at T)",
                stroke * 1e3,
                STATE_NAMES[k],
                p / 1e5
            ));
        }
    }
    Ok(state)
}

fn no_steady_state(u_ref: f64, stroke: f64, residual: f64) -> String {
    format!(
        "no steady lowering at valve.u_ref = {u_ref} through stroke {} mm: Newton's method stalled with a \
         scaled residual of {residual:.3e} (the lowering may have no steady state); linearise at a time point \
         of the run instead (--at T)",
        stroke * 1e3
    )
}

/// Newton's start for [`steady_lowering`] (unknowns: circuit, coordinates, rate): the load held
/// at rest at `stroke` (the arm's static shape), the spool at its steady position, the
/// compensator holding its spring pressure `p_pcv` across the metering edge so that the rod side
/// fills with `K1 |u| sqrt(p_pcv)` (eq. 2.43), the cylinder retracting at that flow over the
/// annulus, the piston side's flow leaving line 2 through the spool's A-T edge (eq. 2.41: p2
/// above tank by `(A_a v / (K1 u))^2`), and p3, p4 where the CBV is a fifth open (eq. 2.56) with
/// the load balanced (eq. 2.69).
fn initial_guess(plant: &Plant, u_ref: f64, stroke: f64) -> Result<Vec<f64>, String> {
    let rest = plant.equilibrium(stroke, None)?;
    let dof = plant.boom.mechanics().dof();
    let c = &plant.circuit;
    let (cyl, cbv) = (&c.cylinder, &c.cbv);
    let x_v = c.dcv.spool_reference(u_ref);
    let u = c.dcv.opening(x_v).abs();
    let v = -c.dcv.k1() * u * c.pcv.p_spring.sqrt() / cyl.area_b();
    let f_load = rest[1] * cyl.area_a() - rest[2] * cyl.area_b();
    let p_t = c.supply.p_t;
    // mu_p p4 + p3 = p_set + (1 + mu_p) p_t + 0.2 p_fo and p3 A_a - p4 A_b = f_load.
    let open = cbv.p_set + (1.0 + cbv.mu_p) * p_t + 0.2 * cbv.p_fo_cbv;
    let p4 = ((open - f_load / cyl.area_a()) / (cbv.mu_p + cyl.mu_c())).max(p_t);
    let p3 = (f_load + p4 * cyl.area_b()) / cyl.area_a();
    let p2 = p_t + (cyl.area_a() * v / (c.dcv.k1() * u)).powi(2);
    let mut z = vec![p2, p3, p4, x_v, cbv.holding_opening(p3, p4, p_t)];
    let q = &rest[N_CIRCUIT..N_CIRCUIT + dof];
    z.extend_from_slice(q);
    let ones = vec![1.0; dof];
    z.push(v / plant.boom.kinetics().stroke_rate(q, &ones));
    Ok(z)
}

/// A crossover of an open loop: its frequency and the margin there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossover {
    /// rad/s
    pub omega: f64,
    /// Gain margin (dB, `-20 log10 |L|` where `L` is negative real) or phase margin (deg,
    /// `180 + arg L` in (-180, 180] where `|L| = 1`).
    pub margin: f64,
}

/// The phase crossovers with their gain margins and the gain crossovers with their phase
/// margins of the open loop `l` between `lo` and `hi` (rad/s): `l` sampled at 400 points per
/// decade, each sign change of `Im L` (with `Re L < 0`) or of `|L| - 1` refined by bisection to
/// 1e-12 relative. Unlike [`super::margins`], which finds them as polynomial roots of a transfer
/// function, this needs only `L(j w)`: a second implementation for the same loop.
pub fn crossovers(l: impl Fn(f64) -> Complex<f64>, lo: f64, hi: f64) -> (Vec<Crossover>, Vec<Crossover>) {
    let n = (400.0 * (hi / lo).log10()).ceil() as usize;
    let w: Vec<f64> = (0..=n).map(|k| lo * (hi / lo).powf(k as f64 / n as f64)).collect();
    let refine = |f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64| {
        let fa = f(a);
        while (b - a) > 1e-12 * b {
            let m = 0.5 * (a + b);
            if (f(m) > 0.0) == (fa > 0.0) {
                a = m
            } else {
                b = m
            }
        }
        0.5 * (a + b)
    };
    let (mut gain, mut phase) = (Vec::new(), Vec::new());
    let im = |w: f64| l(w).im;
    let above_one = |w: f64| l(w).norm() - 1.0;
    for pair in w.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if (im(a) > 0.0) != (im(b) > 0.0) {
            let w = refine(&im, a, b);
            let z = l(w);
            if z.re < 0.0 {
                gain.push(Crossover { omega: w, margin: -20.0 * z.norm().log10() });
            }
        }
        if (above_one(a) > 0.0) != (above_one(b) > 0.0) {
            let w = refine(&above_one, a, b);
            let mut pm = 180.0 + l(w).arg().to_degrees();
            if pm > 180.0 {
                pm -= 360.0;
            }
            phase.push(Crossover { omega: w, margin: pm });
        }
    }
    (gain, phase)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::modes::{hydraulic_boom_modes, Mode};
    use crate::analysis::sine_test::sine_response;

    fn lowering(flexible: bool) -> (Plant, Vec<f64>) {
        let changes = [("boom.flexible", Value::Boolean(flexible))];
        let o = operating_point(Point::Lowering { u_ref: U_REF, stroke: STROKE }, &changes).unwrap();
        (o.plant, o.x)
    }

    /// Experiment B's reference at Table 6.1's stroke.
    const U_REF: f64 = -0.05;
    const STROKE: f64 = 0.25;

    /// The oscillatory modes of a linear model, as `boomsim eigen` lists them.
    fn modes_of(m: &LinearModel) -> Vec<Mode> {
        crate::analysis::modes::modes(m.a.clone())
    }

    /// At rest, the exact Jacobian's modes equal `boomsim eigen`'s, computed at the same point
    /// by central differences (a second implementation of the derivatives). Tolerances: the
    /// differences' own spread over steps of 1e-8 to 1e-4 of the states' scales, 2e-9 of the
    /// rigid boom's frequency and 2e-4 of the flexible arm's lowest (2.5394-2.5400 Hz, round-off
    /// through the arm's mass matrix); damping ratios within 2e-7 of each other. One entry
    /// differs by design: at rest the load-holding valve sits at its closed stop (`u_cbv` = 0,
    /// clamped in eq. 2.59's flow), where the exact derivative is the opening side's and central
    /// differences average it with the closed side's zero (dp2/du_cbv: half).
    #[test]
    fn modes_at_rest_equal_eigens() {
        for (flexible, tolerance) in [(false, 1e-8), (true, 5e-4)] {
            let changes = [("boom.flexible", Value::Boolean(flexible))];
            let o = operating_point(Point::Rest { p4: Some(1e5) }, &changes).unwrap();
            let exact = modes_of(&linearize(&o.plant, &o.x, o.u_ref, &DEFAULT_OUTPUTS).unwrap());
            let (_, eigen) = hydraulic_boom_modes(flexible, Some(1e5), &[]).unwrap();
            assert_eq!(exact.len(), eigen.len(), "flexible {flexible}");
            for (a, b) in exact.iter().zip(&eigen) {
                assert!((a.frequency_hz / b.frequency_hz - 1.0).abs() < tolerance, "{a:?} vs {b:?}");
                assert!((a.damping_ratio - b.damping_ratio).abs() < 2e-7, "{a:?} vs {b:?}");
            }
        }
    }

    /// The steady lowering conserves oil: the rod side fills with what the spool passes less the
    /// B port's laminar leakage (eq. 2.47), `-Q4 - dQ_L p4 = -v A_b`; line 2 passes what leaves
    /// the piston side through the CBV on to the spool, `Q2 = Q3 + dQ_L p2` (a state with line 2
    /// near absolute zero, where the air stops every pressure rate, would not); and the cylinder force
    /// balances the load: for one degree of freedom with the effective mass `m(x)` (eq. 2.68),
    /// Lagrange's equation `m a + m'(x) v^2 / 2 = F - F_static(x)` (eq. 2.19 for `F_static`) at
    /// `a = 0` leaves `F - F_static = m' v^2 / 2` (0.21 N here, 1e-5 of the load).
    #[test]
    fn steady_lowering_balances_flow_and_force() {
        let (plant, x) = lowering(false);
        let outputs = ["Q2", "Q3", "Q4", "cylinder.v", "p2", "p3", "p4", "cylinder.F_fr"];
        let m = linearize(&plant, &x, U_REF, &outputs).unwrap();
        let [q2, q3, q4, v, p2, p3, p4, f_fr] = m.y0[..] else { panic!() };
        let c = &plant.circuit;
        let leak = |p: f64| c.dcv.dq_leak * (p - c.supply.p_t);
        // Q4 is the flow into line 4 through the spool: negative while lowering (boomsim sign).
        assert!(((-q4 - leak(p4)) / (-v * c.cylinder.area_b()) - 1.0).abs() < 1e-9, "{q4} {v}");
        assert!(((q3 + leak(p2)) / q2 - 1.0).abs() < 1e-9, "{q2} {q3} at p2 = {p2}");
        let Boom::Rigid(b) = &plant.boom else { panic!() };
        let load = b.static_force(STROKE);
        let f = p3 * c.cylinder.area_a() - p4 * c.cylinder.area_b() - f_fr;
        // m' by central differences over 0.1 mm: truncation error ~1e-8 relative.
        let h = 1e-4;
        let dm = (b.m_eff(STROKE + h) - b.m_eff(STROKE - h)) / (2.0 * h);
        // 1e-4 of the 0.21 N: the force's round-off (1e-16 of 2e5 N pressure forces: 2e-11 N)
        // and the steady state's residual (below 1e-6 of the scales per second: mu-N).
        let expected = 0.5 * dm * v * v;
        assert!(((f - load) / expected - 1.0).abs() < 1e-4, "{} vs {expected}", f - load);
    }

    /// The small-signal test ([`crate::analysis::sine_test`]): the nonlinear closed loop
    /// (experiment B's filter) from the steady lowering at 250 mm, its reference swinging by 2 %
    /// of u_ref at 1, 2.5 and 5 Hz (around the closed loop's 2.2 Hz pair), against the
    /// closed-loop linear model's response from `valve.u_ref` to p4. The boom lowers meanwhile
    /// (9 mm/s): the linear model is taken at the steady lowering through the mean stroke of the
    /// fitted window (~215 mm); at the start's 250 mm it is 1.4 % off at 2.5 and 5 Hz, for either
    /// amplitude 1e-3 or 2.5e-4: the drift, not the amplitude, is what separates them. Measured:
    /// within 0.02 % in gain and 0.04 deg in phase; tolerance 0.2 % and 0.2 deg for the stroke's
    /// change within the window (+-5 mm) and the amplitude.
    #[test]
    fn small_sine_matches_the_linear_response() {
        let feedback = HighPassFeedback::default();
        for flexible in [false, true] {
            let (plant, x0) = lowering(flexible);
            for f_hz in [1.0, 2.5, 5.0] {
                let measured = sine_response(&plant, &x0, U_REF, &feedback, f_hz).unwrap();
                let changes = [("boom.flexible", Value::Boolean(flexible))];
                let point = Point::Lowering { u_ref: U_REF, stroke: measured.stroke };
                let o = operating_point(point, &changes).unwrap();
                let closed = linearize(&o.plant, &o.x, U_REF, &["p4"]).unwrap().closed_loop(&feedback).unwrap();
                let h = closed.frequency_response(std::f64::consts::TAU * f_hz)[(0, 0)];
                let (gain, phase) = (measured.response.norm() / h.norm(), (measured.response / h).arg().to_degrees());
                assert!(
                    (gain - 1.0).abs() < 2e-3 && phase.abs() < 0.2,
                    "flexible {flexible}, {f_hz} Hz at {} m: gain ratio {gain}, phase {phase} deg",
                    measured.stroke
                );
            }
        }
    }

    /// Section 2.3's assumptions in the full model: no hose compliance, no friction, a fast
    /// CBV (as tests/models/analysis.rs matches them), rigid boom.
    const MATCHED: [(&str, Value); 5] = [
        ("boom.flexible", Value::Boolean(false)),
        ("line.c_hose", Value::Real(0.0)),
        ("friction.c_p_bak", Value::Real(0.0)),
        ("friction.p_static", Value::Real(0.0)),
        ("cbv.omega_cbv", Value::Real(2000.0)),
    ];

    /// The full rigid-boom plant under section 2.3's assumptions against the reduced model at the
    /// same point, both from the spool reference to p4: the reduced one is
    /// `-Q_rated G_v(s) / (C2 s + H(s))` (the compensated valve's flow per opening, its lag eq.
    /// 6.4, eq. 2.76 and 2.81). Below 3 Hz the phases agree within 3 deg and the full model's
    /// gain is 0-15 % higher: Fig. 2.18 lets the CBV discharge to tank, while the full circuit
    /// passes it through line 2 and the spool's A-T edge at p2 = 15.6 bar, so eq. 2.79's
    /// `K_qu = K2 sqrt(p3)` is `K2 sqrt(p3 - p2)`, 9 % less (the gain grows as 1/K_qu), and p2
    /// itself rises with the flow. The loop closed with experiment B's filter has the same
    /// crossovers as `boomsim analyze`'s margins on the reduced model (eq. 6.5 as polynomial
    /// roots; here `L(j w)` of the full model, bisected): frequencies within 5 %, gain margins
    /// within 1 dB, phase margins within 3 deg. As shipped (hose compliance, friction, the CBV's
    /// lag of eq. 2.57) the full model departs near its first pair: the resonance moves to 5 Hz
    /// and the gain margin by 4 dB, which the reduced model cannot show.
    #[test]
    fn matched_plant_agrees_with_the_reduced_model() {
        use crate::analysis::feedback::{filter, open_loop, valve};
        use crate::analysis::plant::{admittance, HParams};
        let Operating { plant, x, u_ref, .. } =
            operating_point(Point::Lowering { u_ref: U_REF, stroke: STROKE }, &MATCHED).unwrap();
        let m = linearize(&plant, &x, u_ref, &["p4"]).unwrap();
        let Boom::Rigid(boom) = &plant.boom else { panic!("rigid") };
        let op = crate::analysis::OperatingPoint::of_circuit(&plant.circuit, boom, STROKE, m.y0[0]);
        let lin = op.linearise().unwrap();
        let h = HParams::new(&op, &lin).h();
        let dcv = &plant.circuit.dcv;
        for f_hz in [0.1, 0.3, 1.0, 2.0, 3.0] {
            let w = std::f64::consts::TAU * f_hz;
            let full = m.frequency_response(w)[(0, 0)];
            let jw = Complex::new(0.0, w);
            let red = -dcv.q_rated / (jw / dcv.omega_v + 1.0) / admittance(lin.c2, &h).at(w);
            let ratio = full.norm() / red.norm();
            let phase = (full / red).arg().to_degrees();
            assert!((1.0..1.15).contains(&ratio) && phase.abs() < 3.0, "{f_hz} Hz: gain ratio {ratio}, phase {phase}");
        }
        let fb = HighPassFeedback::default();
        let analyze = crate::analysis::margins::margins(&open_loop(lin.c2, &h, &valve(dcv.omega_v), &filter(&fb)));
        let (gain, phase) = crossovers(|w| m.open_loop(&fb, w).unwrap(), 1e-2, 1e4);
        assert_eq!((gain.len(), phase.len()), (analyze.gain.len(), analyze.phase.len()));
        for (a, b) in gain.iter().zip(&analyze.gain) {
            assert!((a.omega / b.omega - 1.0).abs() < 0.05 && (a.margin - b.db).abs() < 1.0, "{a:?} vs {b:?}");
        }
        for (a, b) in phase.iter().zip(&analyze.phase) {
            assert!((a.omega / b.omega - 1.0).abs() < 0.05 && (a.margin - b.deg).abs() < 3.0, "{a:?} vs {b:?}");
        }
    }
}
