//! The small-signal sine test of the nonlinear plant: what a linear model's frequency response
//! claims, measured on the equations the FMUs integrate (`boomsim linearize --sine`).
//!
//! From a steady lowering the reference swings by `a sin(w t)` around `u_ref`, with the loop
//! closed by the high-pass pressure feedback (eq. 6.2 in its continuous form, as the
//! PressureFeedbackController computes it without its clamp): the open-loop lowering is unstable
//! (Fig. 7.1), so its response never settles. The response is the difference from the same run
//! without the swing (the point drifts as the boom lowers), fitted by its fundamental and a
//! linear trend over whole periods after a settling time. The plant's own Radau IIA integrates at
//! rtol 1e-10.

use boomsim::control::HighPassFeedback;
use boomsim::hydraulics::circuit::{N_STATES as N_CIRCUIT, P4};
use boomsim::models::hydraulic_boom::Plant;
use boomsim::solver::{OdeSystem, Radau5, SecondOrder};
use nalgebra::{Complex, DMatrix, DVector};

/// The swing's amplitude in spool opening: 2 % of experiment B's reference.
pub const AMPLITUDE: f64 = 1e-3;
/// Settling time before the fit (s): the closed loop's slowest oscillatory pair at B's point
/// decays at 5.5 1/s (flexible arm; rigid 10 1/s), by e^-16 in 3 s.
pub const SETTLE: f64 = 3.0;

/// The plant closed with the feedback and driven by `u_ref + a sin(w t)`; the filter state last.
struct Driven<'a> {
    plant: &'a Plant,
    feedback: &'a HighPassFeedback,
    u_ref: f64,
    amplitude: f64,
    omega: f64,
}

impl OdeSystem for Driven<'_> {
    fn dim(&self) -> usize {
        self.plant.dim() + 1
    }

    fn rhs(&self, t: f64, s: &[f64], dx: &mut [f64]) {
        let n = self.plant.dim();
        let (p4, x_f) = (s[P4], s[n]);
        let u = self.u_ref + self.amplitude * (self.omega * t).sin() + self.feedback.u_comp(p4, x_f);
        self.plant.rhs_with(u, &s[..n], &mut dx[..n]);
        dx[n] = self.feedback.state_derivative(p4, x_f);
    }

    fn second_order(&self) -> Option<SecondOrder> {
        self.plant.second_order()
    }
}

/// The measured response of p4 to the reference at one frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SineResponse {
    pub frequency_hz: f64,
    /// p4 / u_ref (Pa per unit opening), complex.
    pub response: Complex<f64>,
    /// The mean stroke over the fitted window (m): the lowering moves the point.
    pub stroke: f64,
}

/// Samples (t, p4, stroke) of the driven closed loop from the state `x0` (the plant's state at
/// a steady lowering, the filter at its p4) over `periods` whole periods after [`SETTLE`], 64
/// per period.
fn run(sys: &Driven<'_>, x0: &[f64], periods: usize) -> Result<Vec<[f64; 3]>, String> {
    let plant = sys.plant;
    let mut x = x0.to_vec();
    x.push(x0[P4]);
    let mut solver = Radau5::new(x.len());
    solver
        .set_tolerance(1e-10, || plant.state_scale().into_iter().chain([1e5]).collect())
        .map_err(|e| e.to_string())?;
    let period = std::f64::consts::TAU / sys.omega;
    let t0 = SETTLE + period - SETTLE % period;
    let dof = plant.boom.mechanics().dof();
    let sample = |t: f64, x: &[f64]| [t, x[P4], plant.boom.kinetics().stroke(&x[N_CIRCUIT..N_CIRCUIT + dof])];
    let fail = |e: boomsim::solver::SolveError| format!("the sine test's run failed: {e}");
    solver.integrate(sys, 0.0, &mut x, t0).map_err(fail)?;
    let mut out = vec![sample(t0, &x)];
    for k in 1..=64 * periods {
        let (a, b) = (t0 + (k - 1) as f64 * period / 64.0, t0 + k as f64 * period / 64.0);
        solver.integrate(sys, a, &mut x, b).map_err(fail)?;
        out.push(sample(b, &x));
    }
    Ok(out)
}

/// The closed loop from the plant state `x0` with the filter at rest at its p4 (the controller
/// starting with the step, as in the thesis) under the held reference `u_ref` until `t_end`:
/// (the plant's state, the filter state `filter.p_lp`). The time-point form of `boomsim
/// linearize --at T --feedback`.
pub fn run_to(
    plant: &Plant,
    x0: &[f64],
    u_ref: f64,
    feedback: &HighPassFeedback,
    t_end: f64,
) -> Result<(Vec<f64>, f64), String> {
    let sys = Driven { plant, feedback, u_ref, amplitude: 0.0, omega: 0.0 };
    let mut x = x0.to_vec();
    x.push(x0[P4]);
    let mut solver = Radau5::new(x.len());
    solver.set_tolerance(1e-8, || plant.state_scale().into_iter().chain([1e5]).collect()).map_err(|e| e.to_string())?;
    solver.integrate(&sys, 0.0, &mut x, t_end).map_err(|e| format!("the run to t = {t_end} s failed: {e}"))?;
    let x_f = x.pop().expect("the filter state");
    Ok((x, x_f))
}

/// p4's response to a swing of the reference at `frequency_hz` around the steady lowering `x0`
/// at `u_ref`, the loop closed by `feedback`: over at least two periods and one second.
pub fn sine_response(
    plant: &Plant,
    x0: &[f64],
    u_ref: f64,
    feedback: &HighPassFeedback,
    frequency_hz: f64,
) -> Result<SineResponse, String> {
    let omega = std::f64::consts::TAU * frequency_hz;
    let periods = (2.0 * frequency_hz).ceil().max(2.0) as usize;
    let driven = |amplitude| Driven { plant, feedback, u_ref, amplitude, omega };
    let with = run(&driven(AMPLITUDE), x0, periods)?;
    let without = run(&driven(0.0), x0, periods)?;
    let d: Vec<(f64, f64)> = with.iter().zip(&without).map(|(p, q)| (p[0], p[1] - q[1])).collect();
    let c = fundamental(&d, omega)?;
    Ok(SineResponse {
        frequency_hz,
        response: c / AMPLITUDE,
        stroke: without.iter().map(|s| s[2]).sum::<f64>() / without.len() as f64,
    })
}

/// The fundamental at `omega` of samples `(t, y)` over whole periods: the least-squares fit of
/// `y = c1 sin(w t) + c2 cos(w t) + c3 + c4 (t - t0)` (a linear trend takes the drift), as the
/// complex amplitude `c1 + j c2` of `sin(w t)`: `|c| sin(w t + arg c)`.
pub fn fundamental(samples: &[(f64, f64)], omega: f64) -> Result<Complex<f64>, String> {
    let t0 = samples.first().ok_or("no samples")?.0;
    let m = DMatrix::from_fn(samples.len(), 4, |i, j| {
        let t = samples[i].0;
        [(omega * t).sin(), (omega * t).cos(), 1.0, t - t0][j]
    });
    let y = DVector::from_iterator(samples.len(), samples.iter().map(|s| s.1));
    let c = (m.transpose() * &m).lu().solve(&(m.transpose() * y)).ok_or("the sine fit is singular")?;
    Ok(Complex::new(c[0], c[1]))
}
