//! The cost of one Jacobian of the HydraulicBoom's flexible plant, in right-hand-side
//! evaluations (issue 48, item 4; `boomsim bench --jacobian`): the integrator's finite
//! differences (one RHS per state and one at the point, as Radau5 forms them) against the exact
//! Jacobian in dual numbers (the plant's RHS once per state in `Dual64`, seeded with that state)
//! and the structured one the integrator uses (`OdeSystem::jacobian`: the circuit in dual numbers,
//! the arm in closed form), each timed in the same process as the RHS itself, so that the
//! machine's load cancels.

use crate::analysis::modes::plant_values;
use boomsim::fmu::Value;
use boomsim::mechanics::params::DampingLaw;
use boomsim::params::Choice;
use boomsim::models::hydraulic_boom::Plant;
use boomsim::scalar::Dual64;
use boomsim::solver::OdeSystem;
use nalgebra::DMatrix;
use std::time::Instant;

/// One law's measurement.
pub struct JacobianCost {
    /// `boom.damping`'s item.
    pub law: &'static str,
    /// Continuous states of the plant.
    pub states: usize,
    /// Wall time of one RHS [s].
    pub rhs_s: f64,
    /// Finite differences: RHS evaluations per Jacobian, and its time over one RHS's.
    pub fd_rhs: usize,
    pub fd_equivalents: f64,
    /// Dual numbers: time of the exact Jacobian over one RHS's.
    pub dual_equivalents: f64,
    /// Largest difference of the two Jacobians over the largest entry of its row (the
    /// differences' truncation error: a check that both are the same matrix).
    pub difference: f64,
    /// The structured Jacobian: its time over one RHS's, and its largest difference from the
    /// dual numbers' over the largest entry of the row (round-off).
    pub structured_equivalents: f64,
    pub structured_difference: f64,
}

/// Seconds per call of `f`, the best of 5 rounds of `n` calls.
fn timed(n: usize, mut f: impl FnMut()) -> f64 {
    (0..5)
        .map(|_| {
            let t = Instant::now();
            (0..n).for_each(|_| f());
            t.elapsed().as_secs_f64() / n as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// The flexible plant at U's start (480 mm, the load held, spool closed) under each law.
pub fn measure(laws: &[&'static str]) -> Result<Vec<JacobianCost>, String> {
    laws.iter().map(|&law| one(law)).collect()
}

fn one(law: &'static str) -> Result<JacobianCost, String> {
    let item = DampingLaw::ENUMERATION.value(law).ok_or_else(|| format!("no damping law {law}"))? as i32;
    let values = plant_values([("boom.flexible", Value::Boolean(true)), ("boom.damping", Value::Integer(item))])?;
    let plant = Plant::from_values(&values)?;
    let x = plant.equilibrium(values.real(boomsim::models::vr::X0), None)?;
    let n = x.len();
    let mut dx = vec![0.0; n];
    let rhs_s = timed(20_000, || plant.rhs_with(0.0, &x, &mut dx));
    let scale = plant.state_scale();
    let (mut fd, mut plus, mut xp) = (vec![0.0; n * n], vec![0.0; n], x.clone());
    let mut f0 = vec![0.0; n];
    let fd_s = timed(500, || {
        plant.rhs_with(0.0, &x, &mut f0);
        for k in 0..n {
            let d = 1e-7 * x[k].abs().max(scale[k]);
            xp[k] = x[k] + d;
            plant.rhs_with(0.0, &xp, &mut plus);
            xp[k] = x[k];
            (0..n).for_each(|i| fd[i * n + k] = (plus[i] - f0[i]) / d);
        }
    });
    let mut exact = vec![0.0; n * n];
    let dual_s = timed(500, || dual_jacobian(&plant, &x, &mut exact));
    let mut structured = vec![0.0; n * n];
    let structured_s = timed(5000, || {
        structured_jacobian(&plant, &x, &mut structured);
    });
    if !structured_jacobian(&plant, &x, &mut structured) {
        return Err("the flexible plant has no structured Jacobian".into());
    }
    let difference = |other: &[f64]| row_difference(&exact, other);
    Ok(JacobianCost {
        law,
        states: n,
        rhs_s,
        fd_rhs: n + 1,
        fd_equivalents: fd_s / rhs_s,
        dual_equivalents: dual_s / rhs_s,
        difference: difference(&fd),
        structured_equivalents: structured_s / rhs_s,
        structured_difference: difference(&structured),
    })
}

/// The exact Jacobian of the plant at `x` (t = 0) by rows, `out[i n + k] = d f_i / d x_k`: the
/// RHS once per state in `Dual64`, seeded with that state.
fn dual_jacobian(plant: &Plant, x: &[f64], out: &mut [f64]) {
    let n = x.len();
    let (mut s, mut ds) = (vec![Dual64::from(0.0); n], vec![Dual64::from(0.0); n]);
    for k in 0..n {
        s.iter_mut().zip(x).enumerate().for_each(|(i, (si, &xi))| *si = Dual64::new(xi, (i == k) as u8 as f64));
        plant.rhs_with(plant.u_ref.at(0.0).into(), &s, &mut ds);
        (0..n).for_each(|i| out[i * n + k] = ds[i].eps);
    }
}

/// The plant's own Jacobian ([`OdeSystem::jacobian`]) at `x` (t = 0) by rows, as
/// [`dual_jacobian`]; `false` if it has none.
fn structured_jacobian(plant: &Plant, x: &[f64], out: &mut [f64]) -> bool {
    let n = x.len();
    let mut jac = DMatrix::zeros(n, n);
    let made = plant.jacobian(0.0, x, &mut jac);
    out.iter_mut().enumerate().for_each(|(e, o)| *o = jac[(e / n, e % n)]);
    made
}

/// The largest difference of `other` from `exact` (both n x n by rows) over the largest entry
/// of the row.
fn row_difference(exact: &[f64], other: &[f64]) -> f64 {
    let n = exact.len().isqrt();
    (0..n)
        .map(|i| {
            let row = &exact[i * n..][..n];
            let size = row.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
            row.iter().zip(&other[i * n..][..n]).fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / size))
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use boomsim::solver::Radau5;

    /// The structured Jacobian (the arm in closed form, the circuit in dual numbers, joined by
    /// the chain rule) is the dual numbers' through the whole RHS, a second implementation of the
    /// same derivatives (the articulated-body sweeps differentiated): at rest at U's start, and
    /// lowering (u_ref = -0.8) and lifting (0.6) 0.3 s after it, under both damping laws, at
    /// 4 + 5, 1 + 2 and 8 + 8 sections. Both are exact; they differ by rounding, amplified in the
    /// arm's rows by the condition number of the mass matrix M~ that both solve (the sweeps by
    /// elimination from the free end, the closed form by Cholesky): up to 5.5e5 at 8 + 8
    /// (`flexible_boom`'s `acceleration_jacobian_matches_dual_numbers`), eps times that is 1.2e-10
    /// of a row's largest entry; 1e-9 is the bound (measured: 1.7e-11).
    #[test]
    fn structured_jacobian_is_the_dual_numbers_one() {
        let mut worst = 0.0f64;
        for (law, n2, n3) in [("thesis", 4, 5), ("modal", 4, 5), ("thesis", 1, 2), ("modal", 8, 8)] {
            for u_ref in [0.0, -0.8, 0.6] {
                let item = DampingLaw::ENUMERATION.value(law).unwrap() as i32;
                let values = plant_values([
                    ("boom.flexible", Value::Boolean(true)),
                    ("boom.damping", Value::Integer(item)),
                    ("boom.n2", Value::Integer(n2)),
                    ("boom.n3", Value::Integer(n3)),
                    ("valve.u_ref", Value::Real(u_ref)),
                ])
                .unwrap();
                let plant = Plant::from_values(&values).unwrap();
                let mut x = plant.equilibrium(values.real(boomsim::models::vr::X0), None).unwrap();
                if u_ref != 0.0 {
                    let mut solver = Radau5::new(x.len());
                    solver.set_tolerance(1e-6, || plant.state_scale()).unwrap();
                    solver.integrate(&plant, 0.0, &mut x, 0.3).unwrap();
                }
                let n = x.len();
                let (mut exact, mut structured) = (vec![0.0; n * n], vec![0.0; n * n]);
                dual_jacobian(&plant, &x, &mut exact);
                assert!(structured_jacobian(&plant, &x, &mut structured));
                let d = row_difference(&exact, &structured);
                println!("{law}, {n2} + {n3}, u_ref = {u_ref}: {d:.1e}");
                worst = worst.max(d);
            }
        }
        assert!(worst < 1e-9, "{worst}");
    }

    /// Both ways give the same matrix: forward differences with steps of 1e-7 of a state's size
    /// carry a truncation error of about that step times the second derivative, so the two agree
    /// to 1e-3 of each row's largest entry (measured: 4e-5) and not much better.
    #[test]
    fn finite_differences_and_dual_numbers_agree() {
        for c in super::measure(&["thesis"]).unwrap() {
            assert_eq!(c.fd_rhs, c.states + 1);
            assert!(c.difference < 1e-3, "{}: {}", c.law, c.difference);
        }
    }
}
