//! The boom a model drives, from its parameter values: rigid or lumped flexible, its outputs, its
//! tolerance scales and its Model Exchange states ([`super::states`]).

use super::table::param_value;
use super::vr;
use crate::fmu::log::num;
use crate::fmu::{Value, Values};
use crate::mechanics::flexible_boom::{FlexibleBoom, MAX_SECTIONS};
use crate::mechanics::params::{BeamParams, BoomParams, BEAM_PARAMS, BOOM_PARAMS};
use crate::mechanics::rigid_boom::RigidBoom;
use crate::mechanics::{Mechanics, Kinetics};
use crate::scalar::Scalar;

/// Rows of [`Boom::output_rows`]: angle, rate, payload x and y, tip deflection, the section
/// angles and rates.
pub(crate) const N_OUTPUT_ROWS: usize = 5 + 2 * MAX_SECTIONS;

/// The parameter settings that change a boom model's equations: rigid, the default flexible
/// arm (4 + 5 sections), and the most sections (16 + 16, every Model Exchange slot live).
pub(crate) fn boom_configurations() -> Vec<Vec<(u32, Value)>> {
    let beam = |name| vr::BEAM + BEAM_PARAMS.iter().position(|p| p.spec.name == name).expect("beam parameter") as u32;
    vec![
        vec![(vr::FLEXIBLE, Value::Boolean(false))],
        vec![],
        vec![(beam("boom.n2"), Value::Integer(16)), (beam("boom.n3"), Value::Integer(16))],
    ]
}

/// The boom parameters of the values ([`BOOM_PARAMS`] at [`vr::BOOM`]).
pub(crate) fn boom_params(values: &Values) -> BoomParams {
    BoomParams::from_values(|k| param_value(values, vr::BOOM + k as u32, &BOOM_PARAMS[k].spec))
}

/// The boom the cylinder drives.
#[derive(Debug, Clone)]
pub enum Boom {
    Rigid(RigidBoom),
    Flexible(FlexibleBoom),
}

impl Boom {
    /// The boom of the parameter values (boom, beam, `boom.flexible`) for a cylinder `stroke`.
    pub(crate) fn from_values(values: &Values, stroke: f64) -> Result<Self, String> {
        let params = boom_params(values);
        let boom = if values.boolean(vr::FLEXIBLE) {
            let beam = BeamParams::from_values(|k| param_value(values, vr::BEAM + k as u32, &BEAM_PARAMS[k].spec));
            FlexibleBoom::new(&params, &beam, stroke).map(Boom::Flexible)
        } else {
            RigidBoom::new(&params, stroke).map(Boom::Rigid)
        };
        boom.map_err(|e| format!("boom geometry (boom.*, cylinder.l_retracted, cylinder.stroke): {e}"))
    }

    /// The boom's mechanics.
    pub fn mechanics(&self) -> &dyn Mechanics {
        match self {
            Boom::Rigid(b) => b,
            Boom::Flexible(b) => b,
        }
    }

    /// The boom's kinetics in the number type `T` (dual numbers for directional derivatives).
    pub fn kinetics<T: Scalar>(&self) -> &dyn Kinetics<T> {
        match self {
            Boom::Rigid(b) => b,
            Boom::Flexible(b) => b,
        }
    }

    /// Typical magnitudes of q and q_dot (atol = rtol x scale). Rigid: 1 mm and 1 mm/s of
    /// stroke. Flexible: 2 mrad for the section angles (1 mm of stroke through the cylinder's
    /// lever about B, dx/dtheta2 = 0.55 m at 465 mm; away from the horizontal rtol |q| binds
    /// anyway) and 0.1 rad/s for their rates, the boom's angular rate while lowering (U peaks at
    /// 0.24 rad/s). Convergence study (scenario U, 15 s, against rtol 1e-9): every output stays as
    /// close to the reference as with 2 mrad/s (pressures within 28 Pa, stroke 2e-8 m, tip
    /// deflection 1e-7 m, section angles 5e-8 rad, regression metrics to 5 digits, both at a Newton
    /// tolerance of 1e-3), while the tighter scale made the integrator resolve the beam's chatter
    /// during cylinder stiction (v < v_s) to 1e-9 rad/s at a third more steps.
    pub(crate) fn scale(&self) -> impl Iterator<Item = f64> {
        let dof = self.mechanics().dof();
        let (q, qd) = if let Boom::Rigid(_) = self { (1e-3, 1e-3) } else { (2e-3, 0.1) };
        std::iter::repeat_n(q, dof).chain(std::iter::repeat_n(qd, dof))
    }

    /// The boom's Model Exchange states ([`crate::models::states`]) at coordinates `q`,
    /// velocities `qd`: the section angles and rates, the slots beyond the last section the last
    /// one's. Rigid: the boom angle theta2(l_cyl) and its rate theta2' v (eq. 2.7 in closed form,
    /// [`crate::mechanics::kinematics::Triangle::theta2_derivatives`]) in every slot.
    pub(crate) fn me_states<T: Scalar>(&self, q: &[T], qd: &[T], out: &mut [T]) {
        let (phi, omega) = out.split_at_mut(MAX_SECTIONS);
        match self {
            Boom::Rigid(b) => {
                let (theta, d1, _) = b.kinematics().triangle().theta2_derivatives(b.l_cyl(q[0]));
                phi.fill(theta);
                omega.fill(d1 * qd[0]);
            }
            Boom::Flexible(_) => {
                for k in 0..MAX_SECTIONS {
                    let i = k.min(q.len() - 1);
                    (phi[k], omega[k]) = (q[i], qd[i]);
                }
            }
        }
    }

    /// Coordinates `q` and velocities `qd` from the boom's Model Exchange states `x` (the slots
    /// of the sections the boom has; the others are the importer's copies of the last one).
    pub(crate) fn read_me_states<T: Scalar>(&self, x: &[T], q: &mut [T], qd: &mut [T]) -> Result<(), String> {
        let (phi, omega) = x.split_at(MAX_SECTIONS);
        match self {
            Boom::Rigid(b) => {
                let t = b.kinematics().triangle();
                let l = t.l_cyl(phi[0]).ok_or_else(|| {
                    let (lo, hi) = t.theta2_range();
                    format!(
                        "boom.section[1].phi = {} rad is outside ({}, {}) rad, where the cylinder triangle closes (rigid boom)",
                        num(phi[0].re()),
                        num(lo),
                        num(hi)
                    )
                })?;
                let (_, d1, _) = t.theta2_derivatives(l);
                let v = omega[0] / d1;
                if !v.re().is_finite() || !(v * d1).re().is_finite() {
                    return Err(format!(
                        "boom.section[1].omega = {} rad/s at boom.section[1].phi = {} rad is beyond the largest \
                         number the rigid boom can hold (v = omega / dtheta2/dl_cyl and back)",
                        num(omega[0].re()),
                        num(phi[0].re())
                    ));
                }
                (q[0], qd[0]) = (l - b.l_cyl(0.0), v);
            }
            Boom::Flexible(_) => {
                let n = q.len();
                q.copy_from_slice(&phi[..n]);
                qd.copy_from_slice(&omega[..n]);
            }
        }
        Ok(())
    }

    /// The derivatives of the Model Exchange states from the velocities `qd` and accelerations
    /// `qdd` at `q`. Rigid: dtheta2/dt = theta2' v, domega/dt = theta2'' v^2 + theta2' a.
    pub(crate) fn me_derivatives<T: Scalar>(&self, q: &[T], qd: &[T], qdd: &[T], out: &mut [T]) {
        let (dphi, domega) = out.split_at_mut(MAX_SECTIONS);
        match self {
            Boom::Rigid(b) => {
                let (_, d1, d2) = b.kinematics().triangle().theta2_derivatives(b.l_cyl(q[0]));
                let v = qd[0];
                dphi.fill(d1 * v);
                domega.fill(d2 * v * v + d1 * qdd[0]);
            }
            Boom::Flexible(_) => {
                for k in 0..MAX_SECTIONS {
                    let i = k.min(q.len() - 1);
                    (dphi[k], domega[k]) = (qd[i], qdd[i]);
                }
            }
        }
    }

    /// The boom outputs (angle, angular velocity, payload, tip deflection, section angles and
    /// rates) at coordinates `q`, velocities `qd` as (value reference, value); `theta`, `omega`
    /// and the payload use the value references `r = [theta, omega, payload.x, payload.y]` of the
    /// model.
    pub(crate) fn output_rows<T: Scalar>(&self, q: &[T], qd: &[T], r: [u32; 4]) -> [(u32, T); N_OUTPUT_ROWS] {
        // The section angles and rates; the first is the boom angle and rate, rigid or flexible.
        let mut sections = [T::from(0.0); 2 * MAX_SECTIONS];
        self.me_states(q, qd, &mut sections);
        let (theta, omega) = (sections[0], sections[MAX_SECTIONS]);
        let tip = if let Boom::Flexible(f) = self { f.tip_deflection(q) } else { T::from(0.0) };
        let payload = self.kinetics().payload(q);
        let mut rows = [(0, T::from(0.0)); N_OUTPUT_ROWS];
        let head = [theta, omega, payload.x, payload.y, tip];
        let refs = r.into_iter().chain([vr::TIP_DEFLECTION]);
        let refs = refs.chain((vr::SECTIONS..).take(MAX_SECTIONS)).chain((vr::SECTION_RATES..).take(MAX_SECTIONS));
        for (row, x) in rows.iter_mut().zip(refs.zip(head.into_iter().chain(sections))) {
            *row = x;
        }
        rows
    }

    /// Writes [`Self::output_rows`] into `values`.
    pub(crate) fn outputs(&self, q: &[f64], qd: &[f64], r: [u32; 4], values: &mut Values) {
        for (r, x) in self.output_rows(q, qd, r) {
            values.set_real(r, x);
        }
    }
}
