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
    let (mut s, mut ds) = (vec![Dual64::from(0.0); n], vec![Dual64::from(0.0); n]);
    let dual_s = timed(500, || {
        for k in 0..n {
            s.iter_mut().zip(&x).enumerate().for_each(|(i, (si, &xi))| *si = Dual64::new(xi, (i == k) as u8 as f64));
            plant.rhs_with(Dual64::from(0.0), &s, &mut ds);
            (0..n).for_each(|i| exact[i * n + k] = ds[i].eps);
        }
    });
    let mut jac = DMatrix::zeros(n, n);
    let structured_s = timed(5000, || {
        plant.jacobian(0.0, &x, &mut jac);
    });
    if !plant.jacobian(0.0, &x, &mut jac) {
        return Err("the flexible plant has no structured Jacobian".into());
    }
    let structured: Vec<f64> = (0..n * n).map(|e| jac[(e / n, e % n)]).collect();
    let difference = |other: &[f64]| {
        (0..n)
            .map(|i| {
                let row = &exact[i * n..][..n];
                let size = row.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
                row.iter().zip(&other[i * n..][..n]).fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / size))
            })
            .fold(0.0, f64::max)
    };
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

#[cfg(test)]
mod tests {
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
