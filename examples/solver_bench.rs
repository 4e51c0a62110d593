//! Benchmark that chose the stiff integrator: `cargo run --release --example solver_bench`.
//!
//! Every run is driven like an FMU: one `integrate` call per communication step, landing on
//! each communication point. Problems: Robertson (chemical kinetics, eigenvalues to -1e4 and a
//! conserved sum), Van der Pol with mu = 1e3 (relaxation oscillation, stiff/non-stiff switching),
//! and a hydraulic test modelled on the boom: pressure-compensated flow source with first-order
//! spool, 2 cm³ oil volume at 1.3 GPa feeding a cylinder (eigenvalues ~1e5 1/s, volume growing to
//! ~5e-5 m³), a regularised square-root orifice, and a 3-mass beam chain with lightly damped
//! modes (1-2 % damping) of tens to hundreds of Hz. Error is measured at every communication
//! point against a tight run (Radau IIA, rtol 1e-12), in tolerance units
//! `max |x - x_ref| / (atol_i + rtol |x_ref|)`; 1 means "as accurate as asked". The reference is
//! cross-checked against diffsol's BDF at rtol 1e-10 (printed as `ref check`).
//! The systems use finite-difference Jacobians (as the boom models will); diffsol gets the same
//! differences through its Jacobian-vector closure, with f(x) cached so that a column costs
//! one RHS evaluation as in Radau5.

use boomsim::solver::{OdeSystem, Radau5, SolverStats};
use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason, Vector};
use std::cell::{Cell, RefCell};
use std::time::Instant;

struct Robertson;
impl OdeSystem for Robertson {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
        dy[1] = 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] * y[1];
        dy[2] = 3e7 * y[1] * y[1];
    }
}

struct VanDerPol {
    mu: f64,
}
impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = self.mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
    }
}

/// Hydraulic test: states p, y, v, s (spool), then (x_i, v_i) of 3 beam masses (deflections).
struct Hydraulic;
impl Hydraulic {
    const BETA: f64 = 1.3e9;
    const V0: f64 = 2e-6;
    const AREA: f64 = 5e-4;
    const M0: f64 = 10.0;
    const M: [f64; 3] = [100.0, 30.0, 10.0];
    const K: [f64; 3] = [2e7, 5e6, 2e6];
    const C: [f64; 3] = [894.0, 245.0, 89.0];
    const LOAD: f64 = 4000.0;
    /// Regularised signed square root `x / (x² + r²)^(1/4)`.
    fn sqrt_reg(x: f64, r: f64) -> f64 {
        x / (x * x + r * r).sqrt().sqrt()
    }
}
impl OdeSystem for Hydraulic {
    fn dim(&self) -> usize {
        10
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        let (p, y, v, s) = (x[0], x[1], x[2], x[3]);
        let s_cmd = 0.5 + 0.4 * (2.0 * std::f64::consts::PI * t).sin();
        // Compensated flow (1e-4 m³/s at full opening) collapsing as p nears supply 2e7 Pa.
        let q_in = 1e-4 * s * ((2e7 - p) / 1e6).tanh();
        let q_out = 3e-9 * Self::sqrt_reg(p, 1e5);
        let vol = Self::V0 + Self::AREA * y;
        dx[0] = Self::BETA / vol * (q_in - q_out - Self::AREA * v);
        dx[1] = v;
        dx[3] = (s_cmd - s) / 2e-3;
        // Chain: piston -k0- m0 -k1- m1 -k2- m2, deflections relative to the piston.
        let g = 9.81;
        let mut f_prev = 0.0;
        let mut pos_prev = (y, v);
        for i in 0..3 {
            let (xi, vi) = (x[4 + 2 * i], x[5 + 2 * i]);
            let f = Self::K[i] * (pos_prev.0 - xi) + Self::C[i] * (pos_prev.1 - vi);
            if i == 0 {
                dx[2] = (p * Self::AREA - f - 50.0 * v - Self::M0 * g) / Self::M0;
            } else {
                let j = 5 + 2 * (i - 1);
                dx[j] = (f_prev - f - Self::M[i - 1] * g) / Self::M[i - 1];
            }
            dx[4 + 2 * i] = vi;
            f_prev = f;
            pos_prev = (xi, vi);
        }
        dx[9] = (f_prev - Self::M[2] * g - Self::LOAD) / Self::M[2];
    }
}

struct Problem {
    name: &'static str,
    sys: Box<dyn OdeSystem>,
    x0: Vec<f64>,
    /// Communication points (after t = 0).
    t_out: Vec<f64>,
    /// atol_i = rtol * nominal_i.
    nominal: Vec<f64>,
}

fn problems() -> Vec<Problem> {
    vec![
        Problem {
            name: "robertson",
            sys: Box::new(Robertson),
            x0: vec![1.0, 0.0, 0.0],
            t_out: (0..=8).map(|k| 1e-4 * 10f64.powi(k)).collect(),
            nominal: vec![1.0, 1e-4, 1.0],
        },
        Problem {
            name: "vdp mu=1e3",
            sys: Box::new(VanDerPol { mu: 1e3 }),
            x0: vec![2.0, 0.0],
            t_out: (1..=100).map(|k| 30.0 * k as f64).collect(),
            nominal: vec![1.0, 1.0],
        },
        Problem {
            name: "hydraulic",
            sys: Box::new(Hydraulic),
            x0: vec![1.1e7, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            t_out: (1..=1000).map(|k| 1e-3 * k as f64).collect(),
            nominal: vec![1e7, 0.1, 0.1, 1.0, 1e-3, 0.1, 1e-3, 0.1, 1e-3, 0.1],
        },
    ]
}

/// Work counters common to all methods.
#[derive(Default, Clone, Copy)]
struct Work {
    steps: u64,
    rejected: u64,
    rhs: u64,
    jac: u64,
    lu: u64,
}

type Trajectory = Vec<Vec<f64>>;
type Runner<'a> = Box<dyn Fn() -> Result<(Trajectory, Work), String> + 'a>;

fn run_radau(p: &Problem, rtol: f64) -> Result<(Trajectory, Work), String> {
    let n = p.x0.len();
    let mut s = Radau5::new(n);
    s.set_rtol(rtol).map_err(|e| e.to_string())?;
    let atol: Vec<f64> = p.nominal.iter().map(|v| v * rtol).collect();
    s.set_atol(&atol).map_err(|e| e.to_string())?;
    let mut x = p.x0.clone();
    let mut t = 0.0;
    let mut out = Vec::with_capacity(p.t_out.len());
    for &t1 in &p.t_out {
        s.integrate(p.sys.as_ref(), t, &mut x, t1).map_err(|e| e.to_string())?;
        out.push(x.clone());
        t = t1;
    }
    let st: SolverStats = *s.stats();
    let w = Work {
        steps: st.accepted_steps,
        rejected: st.rejected_steps,
        rhs: st.rhs_evals,
        jac: st.jacobian_evals,
        lu: st.lu_decompositions,
    };
    Ok((out, w))
}

#[derive(Clone, Copy, PartialEq)]
enum Diffsol {
    Bdf,
    Esdirk34,
    TrBdf2,
}

fn run_diffsol(p: &Problem, rtol: f64, method: Diffsol) -> Result<(Trajectory, Work), String> {
    let n = p.x0.len();
    let sys = p.sys.as_ref();
    let calls = Cell::new(0u64);
    // Cache of (t, x, f(t, x)) for the finite-difference Jacobian-vector product.
    let cache = RefCell::new((f64::NAN, vec![0.0; n], vec![0.0; n]));
    let scratch = RefCell::new((vec![0.0; n], vec![0.0; n]));
    let x0 = p.x0.clone();
    let problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .rtol(rtol)
        .atol(p.nominal.iter().map(|v| v * rtol))
        .rhs_implicit(
            |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| {
                calls.set(calls.get() + 1);
                sys.rhs(t, x, y);
            },
            |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
                let mut c = cache.borrow_mut();
                if c.0 != t || c.1 != x {
                    c.0 = t;
                    c.1.copy_from_slice(x);
                    sys.rhs(t, x, &mut c.2);
                    calls.set(calls.get() + 1);
                }
                let vn = v.iter().map(|a| a * a).sum::<f64>().sqrt();
                if vn == 0.0 {
                    y.fill(0.0);
                    return;
                }
                let xn = x.iter().map(|a| a * a).sum::<f64>().sqrt();
                let eps = (1e-16 * xn.max(1e-5)).sqrt() / vn;
                let mut s = scratch.borrow_mut();
                let (xp, fp) = &mut *s;
                for i in 0..x.len() {
                    xp[i] = x[i] + eps * v[i];
                }
                sys.rhs(t, xp, fp);
                calls.set(calls.get() + 1);
                for i in 0..x.len() {
                    y[i] = (fp[i] - c.2[i]) / eps;
                }
            },
        )
        .init(move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&x0), n)
        .build()
        .map_err(|e| e.to_string())?;
    let mut out = Vec::with_capacity(p.t_out.len());
    macro_rules! drive {
        ($solver:expr) => {{
            let mut s = $solver.map_err(|e| e.to_string())?;
            for &t1 in &p.t_out {
                s.set_stop_time(t1).map_err(|e| e.to_string())?;
                loop {
                    match s.step().map_err(|e| e.to_string())? {
                        OdeSolverStopReason::TstopReached => break,
                        _ => {}
                    }
                }
                out.push(s.state().y.clone_as_vec());
            }
            let st = s.get_statistics().clone();
            (st.number_of_steps as u64, st.number_of_error_test_failures as u64 + st.number_of_nonlinear_solver_fails as u64, st.number_of_linear_solver_setups as u64)
        }};
    }
    let (steps, rejected, lu) = match method {
        Diffsol::Bdf => drive!(problem.bdf::<NalgebraLU<f64>>()),
        Diffsol::Esdirk34 => drive!(problem.esdirk34::<NalgebraLU<f64>>()),
        Diffsol::TrBdf2 => drive!(problem.tr_bdf2::<NalgebraLU<f64>>()),
    };
    let jac = {
        use diffsol::{Op, OdeEquations};
        problem.eqn.rhs().statistics().number_of_matrix_evals as u64
    };
    Ok((out, Work { steps, rejected, rhs: calls.get(), jac, lu }))
}

fn err_tol_units(p: &Problem, rtol: f64, out: &Trajectory, reference: &Trajectory) -> f64 {
    let mut e: f64 = 0.0;
    for (x, r) in out.iter().zip(reference) {
        for i in 0..x.len() {
            let w = p.nominal[i] * rtol + rtol * r[i].abs();
            e = e.max((x[i] - r[i]).abs() / w);
        }
    }
    if e.is_nan() {
        f64::INFINITY
    } else {
        e
    }
}

fn main() {
    let rtols = [1e-4, 1e-6, 1e-8];
    println!(
        "{:<11} {:<17} {:>6} {:>7} {:>6} {:>8} {:>6} {:>6} {:>9} {:>10}",
        "problem", "method", "rtol", "steps", "rej", "rhs", "jac", "lu", "time ms", "err/tol"
    );
    for p in problems() {
        let (reference, _) = run_radau(&p, 1e-12).expect("reference run");
        let check = run_diffsol(&p, 1e-10, Diffsol::Bdf)
            .map(|(o, _)| err_tol_units(&p, 1e-10, &o, &reference))
            .unwrap_or(f64::NAN);
        println!("{:<11} ref check: diffsol BDF at rtol 1e-10 vs reference: {check:.2} tol units", p.name);
        for &rtol in &rtols {
            let methods: [(&str, Runner); 4] = [
                ("radau5 (ours)", Box::new(|| run_radau(&p, rtol))),
                ("diffsol bdf", Box::new(|| run_diffsol(&p, rtol, Diffsol::Bdf))),
                ("diffsol esdirk34", Box::new(|| run_diffsol(&p, rtol, Diffsol::Esdirk34))),
                ("diffsol tr_bdf2", Box::new(|| run_diffsol(&p, rtol, Diffsol::TrBdf2))),
            ];
            for (name, run) in methods {
                // Best of several repetitions (at least 3, at least 0.3 s in total).
                let (mut best, mut total, mut reps) = (f64::INFINITY, 0.0, 0);
                let mut result = None;
                while reps < 3 || (total < 0.3 && reps < 50) {
                    let t0 = Instant::now();
                    let r = run();
                    let dt = t0.elapsed().as_secs_f64();
                    best = best.min(dt);
                    total += dt;
                    reps += 1;
                    let failed = r.is_err();
                    result = Some(r);
                    if failed || dt > 2.0 {
                        break;
                    }
                }
                match result.unwrap() {
                    Ok((out, w)) => println!(
                        "{:<11} {:<17} {:>6.0e} {:>7} {:>6} {:>8} {:>6} {:>6} {:>9.2} {:>10.3}",
                        p.name,
                        name,
                        rtol,
                        w.steps,
                        w.rejected,
                        w.rhs,
                        w.jac,
                        w.lu,
                        best * 1e3,
                        err_tol_units(&p, rtol, &out, &reference)
                    ),
                    Err(e) => println!("{:<11} {:<17} {:>6.0e} failed: {e}", p.name, name, rtol),
                }
            }
        }
    }
}
