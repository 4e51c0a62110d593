//! Rigid boom kinetics (thesis 2.1.2, eq. 2.16-2.19) and its equation of motion in the cylinder
//! stroke, the form the hydraulic model needs.
//!
//! With the stroke x as the single generalised coordinate (l_cyl = l_retracted + x, dl/dx = 1)
//! and theta2 = theta2(l_cyl) from the vector triangle, Lagrange's equation gives
//!
//! ```text
//! T = J_B theta2_dot^2 / 2 + m_rod x_dot^2 / 2,   theta2_dot = theta2'(l) x_dot
//! V = m_D g y_D(l) + V_rod(l),                    dV_rod/dl = m_rod g sin(theta1)   (2.62)
//! (J_B theta2'^2 + m_rod) x_ddot + J_B theta2' theta2'' x_dot^2 = F_cyl - dV/dl
//! dV/dl = m_D g w_cm cos(theta2 + phi_cm) theta2' + m_rod g sin(theta1)
//! ```
//!
//! so m_eff = J_B theta2'^2 + m_rod (the m_eff of eq. 2.68) and the load force is
//! F_L = dV/dl + J_B theta2' theta2'' x_dot^2. theta2' = 1 / (w1 sin(theta1 - theta2 + phi2)),
//! the inverse moment arm of (2.18), so at rest F_cyl - m_rod g sin(theta1) is the F_cyl of (2.19).
//!
//! Deviation: the rod and piston (m_rod, thesis 2.2.3) are a mass translating along the cylinder
//! axis with the stroke, loaded by G_rod = m_rod g sin(theta1) (2.62); their swing with the
//! cylinder angle is neglected (5 kg against the 464 kg boom), as in (2.68). The cylinder barrel
//! is not modelled (the thesis gives no mass for it).

use nalgebra::{Matrix3, Vector2, Vector3};

use super::kinematics::BoomKinematics;
use super::params::BoomParams;
use super::{Mechanics, Energy, Equilibrium, Kinetics, MechanicsError};
use crate::scalar::Scalar;

/// The rigid boom driven by the cylinder stroke.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidBoom {
    kin: BoomKinematics,
    l_retracted: f64,
    m_rod: f64,
    g: f64,
    /// Payload mass centre relative to B in the boom frame: (l_pl - b7, h_pl), eq. (2.8).
    payload: Vector2<f64>,
    /// Outer end of the arm on its centre line relative to B: (l_arm - b7, 0).
    tip: Vector2<f64>,
    /// Constants of the equation of motion, see [`Geometry`].
    geo: Geometry,
}

/// Constants that turn the closed-form angles of [`super::kinematics::Triangle`] into algebra:
/// with `cos beta = (w1² + w2² - l²) / (2 w1 w2)` and `cos alpha = (w2² + l² - w1²) / (2 w2 l)`
/// (law of cosines; beta, alpha in (0, pi), so their sines are the positive roots), the boom
/// angle theta2 = beta + (phi2 - phi1) and the cylinder angle theta1 = pi - phi1 - alpha need no
/// acos, atan or sin/cos: by the addition theorems
///
/// ```text
/// lever(theta2) = e_x cos theta2 - e_y sin theta2 = cos beta · lc - sin beta · ls
/// sin theta1    = sin(phi1 + alpha) = sin phi1 cos alpha + cos phi1 sin alpha
/// ```
///
/// with `lc = e_x cos(phi2 - phi1) - e_y sin(phi2 - phi1)`, `ls = e_x sin(phi2 - phi1) +
/// e_y cos(phi2 - phi1)` (e_cm = (e_x, e_y)). Same quantities as [`Triangle::theta2_derivatives`],
/// [`super::kinematics::Body::lever`] and [`Triangle::theta1`], equal to rounding.
///
/// [`Triangle::theta2_derivatives`]: super::kinematics::Triangle::theta2_derivatives
/// [`Triangle::theta1`]: super::kinematics::Triangle::theta1
#[derive(Debug, Clone, Copy, PartialEq)]
struct Geometry {
    /// w1 w2 and w1² + w2².
    ww: f64,
    w_sq: f64,
    /// w2 and w2² - w1².
    w2: f64,
    w21: f64,
    /// sin phi1, cos phi1.
    sin_phi1: f64,
    cos_phi1: f64,
    /// lc, ls (see above).
    lc: f64,
    ls: f64,
}

impl Geometry {
    fn new(kin: &BoomKinematics) -> Self {
        let t = kin.triangle();
        let e = kin.body().e_cm;
        let (sd, cd) = (t.phi2 - t.phi1).sin_cos();
        let (sin_phi1, cos_phi1) = t.phi1.sin_cos();
        Self {
            ww: t.w1 * t.w2,
            w_sq: t.w1 * t.w1 + t.w2 * t.w2,
            w2: t.w2,
            w21: t.w2 * t.w2 - t.w1 * t.w1,
            sin_phi1,
            cos_phi1,
            lc: e.x * cd - e.y * sd,
            ls: e.x * sd + e.y * cd,
        }
    }
}

/// `sin` of an angle in [0, pi] from its cosine, `sqrt((1 - c)(1 + c))` (accurate also near
/// c = ±1, where `1 - c²` would cancel).
fn sin_from_cos<T: Scalar>(c: T) -> T {
    ((-c + 1.0) * (c + 1.0)).sqrt()
}

/// Positions and angles of the boom at one stroke position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoomState {
    /// Cylinder angle, eq. (2.7) (rad).
    pub theta1: f64,
    /// Boom angle (rad), positive up.
    pub theta2: f64,
    /// Boom angular velocity (rad/s).
    pub theta2_dot: f64,
    /// Payload mass centre in the global frame (origin: lower cylinder pin A) (m).
    pub payload: Vector2<f64>,
    /// Outer end of the arm's centre line in the global frame (m).
    pub tip: Vector2<f64>,
}

/// Joint reactions and cylinder force on the boom, the vector f of eq. (2.19).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reactions {
    /// Force of the joint on the boom, x (N).
    pub r_bx: f64,
    /// Force of the joint on the boom, y (N).
    pub r_by: f64,
    /// Force of the cylinder on the boom along A -> C (N). The force the rod must be pushed with
    /// is this plus m_rod (x_ddot + g sin theta1).
    pub f_cyl: f64,
}

/// The coefficients of the equation of motion at one stroke position.
struct Eom<T> {
    m_eff: T,
    /// J_B theta2' theta2'', multiplies x_dot^2.
    c_v2: T,
    /// dV/dl, gravity on boom and rod.
    f_gravity: T,
}

impl RigidBoom {
    /// Builds the boom; `stroke` is the cylinder's stroke (s_c), the triangle must close for
    /// every l_cyl in [l_retracted, l_retracted + stroke].
    pub fn new(p: &BoomParams, stroke: f64) -> Result<Self, MechanicsError> {
        let kin = BoomKinematics::new(p);
        let t = kin.triangle();
        let (l_min, l_max) = (p.l_retracted, p.l_retracted + stroke);
        if !((t.w1 - t.w2).abs() < l_min && l_max < t.w1 + t.w2) {
            return Err(MechanicsError::TriangleOpen { l_min, l_max, w1: t.w1, w2: t.w2 });
        }
        let b7 = p.b[6];
        Ok(Self {
            geo: Geometry::new(&kin),
            kin,
            l_retracted: p.l_retracted,
            m_rod: p.m_rod,
            g: p.g,
            payload: Vector2::new(p.l_pl() - b7, p.h_pl),
            tip: Vector2::new(p.l_arm - b7, 0.0),
        })
    }

    pub fn kinematics(&self) -> &BoomKinematics {
        &self.kin
    }

    /// Pin-to-pin cylinder length at stroke `x`.
    pub fn l_cyl<T: Scalar>(&self, x: T) -> T {
        x + self.l_retracted
    }

    /// The coefficients at stroke `x`: theta2' and theta2'' as in
    /// [`Triangle::theta2_derivatives`](super::kinematics::Triangle::theta2_derivatives), the
    /// lever and sin theta1 by the algebra of [`Geometry`] (no transcendental functions).
    fn eom<T: Scalar>(&self, x: T) -> Eom<T> {
        let l = self.l_cyl(x);
        let g = &self.geo;
        let body = self.kin.body();
        let c = (-(l * l) + g.w_sq) / (2.0 * g.ww);
        let s = sin_from_cos(c);
        let d1 = l / (s * g.ww);
        let d2 = (s - l * c * d1) / (s * g.ww * s);
        let ca = (l * l + g.w21) / (l * (2.0 * g.w2));
        let sin_theta1 = ca * g.sin_phi1 + sin_from_cos(ca) * g.cos_phi1;
        let lever = c * g.lc - s * g.ls;
        Eom {
            m_eff: d1 * body.j_b * d1 + self.m_rod,
            c_v2: d1 * body.j_b * d2,
            f_gravity: (lever * body.m_d * d1 + sin_theta1 * self.m_rod) * self.g,
        }
    }

    /// Effective mass at the cylinder, m_eff = J_B (dtheta2/dl)^2 + m_rod (eq. 2.68, module doc).
    pub fn m_eff(&self, x: f64) -> f64 {
        self.eom(x).m_eff
    }

    /// Load force F_L opposing extension at stroke `x` and velocity `v`: gravity on boom and rod
    /// plus the velocity term J_B theta2' theta2'' v^2 (module doc).
    pub fn load_force(&self, x: f64, v: f64) -> f64 {
        let e = self.eom(x);
        e.f_gravity + e.c_v2 * v * v
    }

    /// Cylinder force that holds the boom at rest at stroke `x` (2.19 with zero accelerations,
    /// plus the rod weight along the axis, 2.62).
    pub fn static_force(&self, x: f64) -> f64 {
        self.eom(x).f_gravity
    }

    /// Stroke acceleration for the net cylinder force `f_cyl` (pressure forces minus friction)
    /// at stroke `x` and velocity `v`: (f_cyl - F_L) / m_eff. Allocation-free, no iteration.
    pub fn acceleration<T: Scalar>(&self, x: T, v: T, f_cyl: T) -> T {
        let e = self.eom(x);
        (f_cyl - e.f_gravity - e.c_v2 * v * v) / e.m_eff
    }

    /// Angles, boom angular velocity, payload and tip positions at stroke `x`, velocity `v`.
    pub fn state(&self, x: f64, v: f64) -> BoomState {
        let l = self.l_cyl(x);
        let t = self.kin.triangle();
        let (theta2, d1, _) = t.theta2_derivatives(l);
        BoomState {
            theta1: t.theta1(l),
            theta2,
            theta2_dot: d1 * v,
            payload: self.kin.point(theta2, self.payload),
            tip: self.kin.point(theta2, self.tip),
        }
    }

    /// Joint reactions and cylinder force on the boom for stroke `x`, velocity `v` and
    /// acceleration `a`, eq. (2.19), with q, q_dot, q_ddot from (2.11), (2.13), (2.15).
    pub fn reactions(&self, x: f64, v: f64, a: f64) -> Result<Reactions, MechanicsError> {
        let l = self.l_cyl(x);
        let t = self.kin.triangle();
        let body = self.kin.body();
        let q = self.kin.q(l);
        let q_dot = self.kin.velocity(&q, l, v)?;
        let q_ddot = self.kin.acceleration(&q, &q_dot, l, v, a)?;
        let (theta1, theta2) = (t.theta1(l), q.z);
        #[rustfmt::skip]
        let r = Matrix3::new(
            1.0, 0.0, theta1.cos(),
            0.0, 1.0, theta1.sin(),
            0.0, 0.0, t.w1 * (theta1 - theta2 + t.phi2).sin(),
        );
        let m = Matrix3::from_diagonal(&Vector3::new(body.m_d, body.m_d, body.j_b));
        let b = Vector3::new(0.0, body.m_d * self.g, body.lever(theta2) * body.m_d * self.g);
        let f = r.lu().solve(&(m * q_ddot + b)).ok_or(MechanicsError::SingularJacobian { l_cyl: l })?;
        Ok(Reactions { r_bx: f.x, r_by: f.y, f_cyl: f.z })
    }
}

/// The rigid boom with q = [stroke x], q_dot = [v].
impl<T: Scalar> Kinetics<T> for RigidBoom {
    fn stroke(&self, q: &[T]) -> T {
        q[0]
    }

    fn stroke_rate(&self, _q: &[T], qd: &[T]) -> T {
        qd[0]
    }

    fn accelerations(&self, q: &[T], qd: &[T], f_cyl: &mut dyn FnMut(T, T) -> T, out: &mut [T]) {
        out[0] = self.acceleration(q[0], qd[0], f_cyl(q[0], qd[0]));
    }

    fn payload(&self, q: &[T]) -> Vector2<T> {
        self.kin.point(self.kin.triangle().theta2(self.l_cyl(q[0])), self.payload)
    }
}

impl Mechanics for RigidBoom {
    fn dof(&self) -> usize {
        1
    }

    fn equilibrium(&self, x: f64) -> Result<Equilibrium, MechanicsError> {
        Ok(Equilibrium { q: vec![x], f_cyl: self.static_force(x) })
    }

    /// J_B theta2_dot^2 / 2 + m_rod v^2 / 2 and m_D g y_D (module doc; the rod weight has no
    /// potential here either).
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        let body = self.kin.body();
        let omega = self.state(q[0], qd[0]).theta2_dot;
        Energy {
            kinetic: 0.5 * body.j_b * omega * omega + 0.5 * self.m_rod * qd[0] * qd[0],
            potential: body.m_d * self.g * self.kin.q(self.l_cyl(q[0])).y,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::{mm, DEG};

    const STROKE: f64 = 0.5;

    fn boom() -> RigidBoom {
        RigidBoom::new(&BoomParams::default(), STROKE).unwrap()
    }

    /// The equation of motion against the energy balance, integrated with RK4 along a trajectory
    /// driven by F(t, x) = F_static(x) + 5 kN sin(pi t / 2 s) from rest at 50 mm for 2 s:
    /// the work of cylinder and rod weight equals the change of the kinetic energy
    /// J_B theta2_dot^2 / 2 + m_rod v^2 / 2 plus that of the potential energy m_D g y_D, with
    /// theta2_dot and y_D from the constraint equations (2.11, 2.13), i.e. independent of the
    /// closed-form theta2', theta2'' used in the equation of motion. The work is integrated as a
    /// third RK4 state. h = 1 ms: the RK4 error (O(h^4), smooth motion on a time scale of
    /// seconds) is ~1e-15 relative, well inside 1e-9; dropping the velocity term of the equation
    /// of motion shows as 3e-2.
    #[test]
    fn energy_balance_along_trajectory() {
        let boom = boom();
        let p = BoomParams::default();
        let body = *boom.kinematics().body();
        let (t_end, h) = (2.0, 1e-3);
        let force = |t: f64, x: f64| boom.static_force(x) + 5000.0 * (std::f64::consts::PI * t / t_end).sin();
        let rhs = |t: f64, y: Vector3<f64>| {
            let f = force(t, y.x);
            let rod_weight = p.m_rod * p.g * boom.kinematics().triangle().theta1(boom.l_cyl(y.x)).sin();
            Vector3::new(y.y, boom.acceleration(y.x, y.y, f), (f - rod_weight) * y.y)
        };
        let energy = |y: &Vector3<f64>| {
            let l = boom.l_cyl(y.x);
            let q = boom.kinematics().solve_position(l, 0.0).unwrap();
            let q_dot = boom.kinematics().velocity(&q, l, y.y).unwrap();
            (0.5 * body.j_b * q_dot.z * q_dot.z + 0.5 * p.m_rod * y.y * y.y, body.m_d * p.g * q.y)
        };
        let y0 = Vector3::new(0.05, 0.0, 0.0);
        let mut y = y0;
        let steps = (t_end / h).round() as usize;
        for i in 0..steps {
            let t = i as f64 * h;
            let k1 = rhs(t, y);
            let k2 = rhs(t + h / 2.0, y + h / 2.0 * k1);
            let k3 = rhs(t + h / 2.0, y + h / 2.0 * k2);
            let k4 = rhs(t + h, y + h * k3);
            y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        let ((t0, v0), (t1, v1)) = (energy(&y0), energy(&y));
        let (dt, dv, work) = (t1 - t0, v1 - v0, y.z);
        let error = (work - dt - dv).abs() / work.abs().max(dv.abs());
        println!(
            "x: 50 mm -> {:.1} mm, v = {:.3} m/s, work {work:.3} J, dT {dt:.3} J, dV {dv:.3} J, \
             relative error {error:.1e}",
            y.x * 1e3,
            y.y
        );
        assert!(y.x > 0.3 && dt > 100.0, "the trajectory must exercise the stroke and the velocity term");
        assert!(error < 1e-9, "{work} vs {}", dt + dv);
    }

    /// The Lagrange equation of motion against the Newton-Euler kinetics (2.16-2.19) with the
    /// accelerations of (2.15): the cylinder force on the boom from (2.19) plus the rod's
    /// m_rod (a + g sin theta1) must return the applied force. Both are exact; 1e-9 relative of
    /// ~2.4e4 N covers rounding in the two linear solves.
    #[test]
    fn equation_of_motion_matches_kinetics() {
        let boom = boom();
        let p = BoomParams::default();
        for (x, v, f) in [(0.0, 0.0, 30e3), (0.1, 0.2, 20e3), (0.25, -0.3, 24e3), (0.48, 0.5, 15e3), (0.5, -0.1, 28e3)]
        {
            let a = boom.acceleration(x, v, f);
            let r = boom.reactions(x, v, a).unwrap();
            let theta1 = boom.kinematics().triangle().theta1(boom.l_cyl(x));
            let f_total = r.f_cyl + p.m_rod * (a + p.g * theta1.sin());
            assert!((f_total - f).abs() < 1e-9 * f, "x = {x}: {f_total} vs {f}");
        }
    }

    /// (2.19)'s forces satisfy Newton-Euler with moments taken about the mass centre D instead
    /// of the joint B (J_D = J_B - m_D |e_cm|^2, lever arms from global point coordinates): an
    /// identity check of the matrix form. Tolerance 1e-9 of the force scale (rounding).
    #[test]
    fn reactions_satisfy_newton_euler() {
        let boom = boom();
        let p = BoomParams::default();
        let k = boom.kinematics();
        let body = *k.body();
        let t = *k.triangle();
        for (x, v, a) in [(0.02, 0.1, 0.3), (0.25, -0.4, -1.0), (0.45, 0.3, 2.0)] {
            let l = boom.l_cyl(x);
            let r = boom.reactions(x, v, a).unwrap();
            let q = k.q(l);
            let q_dot = k.velocity(&q, l, v).unwrap();
            let q_ddot = k.acceleration(&q, &q_dot, l, v, a).unwrap();
            let theta1 = t.theta1(l);
            let f = r.f_cyl * Vector2::new(theta1.cos(), theta1.sin());
            let rb = Vector2::new(r.r_bx, r.r_by);
            let weight = Vector2::new(0.0, -body.m_d * p.g);
            let sum = rb + f + weight - body.m_d * Vector2::new(q_ddot.x, q_ddot.y);
            let d = Vector2::new(q.x, q.y);
            let c = Vector2::new(l * theta1.cos(), l * theta1.sin()); // A = origin
            let b = k.point(q.z, Vector2::zeros());
            let cross = |u: Vector2<f64>, w: Vector2<f64>| u.x * w.y - u.y * w.x;
            let j_d = body.j_b - body.m_d * body.e_cm.norm_squared();
            let moment = cross(c - d, f) + cross(b - d, rb) - j_d * q_ddot.z;
            let scale = r.f_cyl.abs();
            assert!(sum.amax() < 1e-9 * scale, "forces {sum}");
            assert!(moment.abs() < 1e-9 * scale, "moment {moment}");
        }
    }

    /// Static holding force against moments about the joint computed by hand at the horizontal
    /// boom (theta2 = 0): B = (-(l2 + b2 - b1), b8 - b3), C = B + (l1 + b4 - b7, -(b5 + b6)),
    /// moment arm |(C - B) x (C / |C|)|, weight moment g (m_arm (l_arm/2 - b7) + m_pl (l_pl - b7))
    /// (h_pl has no lever at theta2 = 0), plus the rod weight m_rod g sin(theta1). Same
    /// arithmetic in a different order: 1e-12 relative.
    #[test]
    fn static_force_by_hand() {
        let p = BoomParams::default();
        let [b1, b2, b3, b4, b5, b6, b7, b8] = p.b;
        let (bx, by) = (-(p.l2 + b2 - b1), b8 - b3);
        let (cbx, cby) = (p.l1 + b4 - b7, -(b5 + b6));
        let (cx, cy) = (bx + cbx, by + cby);
        let l = cx.hypot(cy);
        let arm = (cbx * cy - cby * cx) / l;
        let moment = p.g * (p.m_arm * (p.l_arm / 2.0 - b7) + p.m_pl * (p.l_pl() - b7));
        let expected = moment / arm + p.m_rod * p.g * cy / l;
        let boom = boom();
        let x = l - p.l_retracted;
        println!("horizontal boom: l_cyl = {l:.5} m, stroke {:.1} mm, F = {expected:.1} N", x * 1e3);
        assert!((boom.static_force(x) - expected).abs() < 1e-12 * expected);
        assert!(boom.acceleration(x, 0.0, expected).abs() < 1e-12);
    }

    /// The numbers the hydraulic model needs, reported: boom angle over the stroke, m_eff and the
    /// static force at 0, 250 and 480 mm. Asserted only for plausibility: the boom angle range
    /// contains the horizontal, and F_static / g at 250 mm is within 1 % of the 2456 kg that
    /// omega_n = 83.82 rad/s of Table 6.1 implies (see params::L_RETRACTED_DEFAULT).
    #[test]
    fn report_operating_range() {
        let boom = boom();
        let (lo, hi) = (boom.state(0.0, 0.0).theta2, boom.state(STROKE, 0.0).theta2);
        println!("theta2 over the stroke: {:.2} deg .. {:.2} deg", lo / DEG, hi / DEG);
        assert!(lo < 0.0 && hi > 0.0);
        for x in [0.0, mm(250.0), mm(480.0)] {
            let s = boom.state(x, 0.0);
            println!(
                "x = {:5.1} mm: l_cyl = {:.3} m, theta2 = {:6.2} deg, theta1 = {:6.2} deg, m_eff = {:8.1} kg, \
                 F_static = {:8.1} N, payload = ({:.3}, {:.3}) m, tip = ({:.3}, {:.3}) m",
                x * 1e3,
                boom.l_cyl(x),
                s.theta2 / DEG,
                s.theta1 / DEG,
                boom.m_eff(x),
                boom.static_force(x),
                s.payload.x,
                s.payload.y,
                s.tip.x,
                s.tip.y
            );
        }
        let a_c = std::f64::consts::PI / 4.0 * 0.065f64.powi(2);
        let m_table_6_1 = a_c * 1.3e9 / (0.25 * 83.82f64.powi(2));
        assert!((boom.static_force(mm(250.0)) / 9.807 / m_table_6_1 - 1.0).abs() < 0.01);
    }

    /// The transcendental-free coefficients of `eom` against the closed-form angles (acos of
    /// the law of cosines, sin/cos of theta2 and theta1) over the stroke and beyond: equal to
    /// rounding (1e-13 relative; the triangle is far from degenerate, sin beta >= 0.3).
    #[test]
    fn algebraic_eom_matches_closed_form_angles() {
        let boom = boom();
        let t = *boom.kinematics().triangle();
        let body = *boom.kinematics().body();
        let p = BoomParams::default();
        for i in 0..=70 {
            let x = -0.1 + 0.01 * i as f64;
            let l = boom.l_cyl(x);
            let (theta2, d1, d2) = t.theta2_derivatives(l);
            let f_gravity = p.g * (body.m_d * body.lever(theta2) * d1 + p.m_rod * t.theta1(l).sin());
            let e = boom.eom(x);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs();
            assert!(close(e.m_eff, body.j_b * d1 * d1 + p.m_rod), "x = {x}: m_eff");
            assert!(close(e.c_v2, body.j_b * d1 * d2), "x = {x}: c_v2 {} vs {}", e.c_v2, body.j_b * d1 * d2);
            assert!(close(e.f_gravity, f_gravity), "x = {x}: f_gravity {} vs {f_gravity}", e.f_gravity);
        }
    }

    #[test]
    fn open_triangle_is_rejected() {
        let p = BoomParams { l_retracted: 0.3, ..BoomParams::default() };
        assert!(matches!(RigidBoom::new(&p, STROKE), Err(MechanicsError::TriangleOpen { .. })));
        let p = BoomParams { l_retracted: 1.5, ..BoomParams::default() };
        assert!(matches!(RigidBoom::new(&p, STROKE), Err(MechanicsError::TriangleOpen { .. })));
    }
}
