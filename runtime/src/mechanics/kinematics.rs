//! Kinematics of the rigid boom (thesis 2.1.1, eq. 2.1-2.15, Fig. 2.1 and 2.2).
//!
//! Global frame (Fig. 2.2): origin in A, the lower cylinder pin on the lower beam; x horizontal
//! towards the payload, y up. B is the boom's revolute joint, C the upper cylinder pin on the arm,
//! D the common mass centre of arm and payload. The boom frame sits in B, its x axis along the
//! arm's centre line at the angle theta2 (positive = boom up); theta1 is the cylinder's angle
//! A -> C. Both angles are measured from the global x axis.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

use super::params::BoomParams;
use super::MechanicsError;
use crate::scalar::Scalar;

/// Angle opposite the side `opp` of a triangle whose other sides are `adj1`, `adj2` (law of
/// cosines).
pub(crate) fn law_of_cosines<T: Scalar>(adj1: T, adj2: T, opp: T) -> T {
    ((adj1 * adj1 + adj2 * adj2 - opp * opp) / (adj1 * 2.0 * adj2)).acos()
}

/// Rotation matrix A_2 of the boom frame (below eq. 2.10).
fn rotation(theta: f64) -> Matrix2<f64> {
    let (s, c) = theta.sin_cos();
    Matrix2::new(c, -s, s, c)
}

/// B_2 = dA_2/dtheta (below eq. 2.12).
fn rotation_derivative(theta: f64) -> Matrix2<f64> {
    let (s, c) = theta.sin_cos();
    Matrix2::new(-s, -c, c, -s)
}

/// The vector triangle B-A-C of Fig. 2.1: the constant sides w1 = |BC|, w2 = |BA| and their
/// angles, and the closed-form angles as functions of the third side l_cyl = |AC|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    /// |BC|, eq. (2.1).
    pub w1: f64,
    /// |BA|, eq. (2.2).
    pub w2: f64,
    /// Angle of A -> B below the horizontal, eq. (2.4): B lies at (-w2 cos phi1, w2 sin phi1).
    pub phi1: f64,
    /// Angle of B -> C below the arm's centre line, eq. (2.5).
    pub phi2: f64,
}

impl Triangle {
    /// Eq. (2.1), (2.2), (2.4), (2.5).
    pub fn new(p: &BoomParams) -> Self {
        let [b1, b2, b3, b4, b5, b6, b7, b8] = p.b;
        let (ux, uy) = (p.l1 + b4 - b7, b5 + b6);
        let (lx, ly) = (p.l2 + b2 - b1, b8 - b3);
        Self { w1: ux.hypot(uy), w2: lx.hypot(ly), phi1: ly.atan2(lx), phi2: uy.atan2(ux) }
    }

    /// The upper cylinder pin C from B in the boom frame, (w1 cos phi2, -w1 sin phi2) (eq. 2.1, 2.5).
    pub fn upper_pin(&self) -> Vector2<f64> {
        Vector2::new(self.w1 * self.phi2.cos(), -self.w1 * self.phi2.sin())
    }

    /// Angle at A between A -> B and A -> C, eq. (2.3).
    pub fn alpha(&self, l_cyl: f64) -> f64 {
        law_of_cosines(self.w2, l_cyl, self.w1)
    }

    /// Cylinder angle theta1, eq. (2.7).
    pub fn theta1(&self, l_cyl: f64) -> f64 {
        std::f64::consts::PI - self.phi1 - self.alpha(l_cyl)
    }

    /// Boom angle theta2 in closed form: the angle at B, beta = acos((w1^2 + w2^2 - l^2) /
    /// (2 w1 w2)), turns B -> A (at -phi1) into B -> C (at theta2 - phi2), so
    /// theta2 = beta - phi1 + phi2. The thesis solves (2.11) numerically instead.
    pub fn theta2<T: Scalar>(&self, l_cyl: T) -> T {
        law_of_cosines(T::from(self.w1), T::from(self.w2), l_cyl) - self.phi1 + self.phi2
    }

    /// The cylinder length at boom angle `theta2`, the inverse of [`Self::theta2`] by the law of
    /// cosines (eq. 2.3): l^2 = w1^2 + w2^2 - 2 w1 w2 cos beta with beta = theta2 + phi1 - phi2.
    /// `None` unless 0 < beta < pi, where the triangle closes.
    pub fn l_cyl<T: Scalar>(&self, theta2: T) -> Option<T> {
        let beta = theta2 + self.phi1 - self.phi2;
        (beta > 0.0 && beta < std::f64::consts::PI)
            .then(|| (T::from(self.w1 * self.w1 + self.w2 * self.w2) - beta.cos() * (2.0 * self.w1 * self.w2)).sqrt())
    }

    /// The boom angles in which the triangle closes, (phi2 - phi1, pi + phi2 - phi1).
    pub fn theta2_range(&self) -> (f64, f64) {
        (self.phi2 - self.phi1, std::f64::consts::PI + self.phi2 - self.phi1)
    }

    /// theta2 and its first two derivatives with respect to l_cyl, from [`Self::theta2`]:
    /// dtheta2/dl = l / (w1 w2 sin beta) (the inverse of the cylinder's moment arm about B,
    /// w1 sin(theta1 - theta2 + phi2) of eq. 2.18) and
    /// d2theta2/dl2 = (sin beta - l cos beta dtheta2/dl) / (w1 w2 sin^2 beta).
    pub fn theta2_derivatives<T: Scalar>(&self, l_cyl: T) -> (T, T, T) {
        let beta = law_of_cosines(T::from(self.w1), T::from(self.w2), l_cyl);
        let (s, c) = beta.sin_cos();
        let ww = self.w1 * self.w2;
        let d1 = l_cyl / (s * ww);
        let d2 = (s - l_cyl * c * d1) / (s * ww * s);
        (beta - self.phi1 + self.phi2, d1, d2)
    }
}

/// Arm and payload as one rigid body D (2.1.1; payload a point mass, arm a uniform slender beam).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// m_D = m_arm + m_pl.
    pub m_d: f64,
    /// Mass centre relative to the joint B in the boom frame, e_cm of eq. (2.8).
    pub e_cm: Vector2<f64>,
    /// Mass moment of inertia about B, J_B below eq. (2.18).
    pub j_b: f64,
}

impl Body {
    /// Eq. (2.8) and J_B of eq. (2.18).
    pub fn new(p: &BoomParams) -> Self {
        let b7 = p.b[6];
        let arm = Vector2::new(p.l_arm / 2.0 - b7, 0.0);
        let payload = Vector2::new(p.l_pl() - b7, p.h_pl);
        let m_d = p.m_arm + p.m_pl;
        Self {
            m_d,
            e_cm: (p.m_arm * arm + p.m_pl * payload) / m_d,
            j_b: p.m_arm * p.l_arm * p.l_arm / 12.0 + p.m_arm * arm.norm_squared() + p.m_pl * payload.norm_squared(),
        }
    }

    /// Horizontal distance from B to D, w_cm cos(theta2 + phi_cm) of eq. (2.18): the lever of
    /// the weight m_D g about the joint.
    pub fn lever(&self, theta2: f64) -> f64 {
        let (s, c) = theta2.sin_cos();
        self.e_cm.x * c - self.e_cm.y * s
    }
}

/// The rigid boom's position, velocity and acceleration constraints (2.9-2.15) in
/// q = (x_D, y_D, theta2), driven by the cylinder length l_cyl.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoomKinematics {
    triangle: Triangle,
    body: Body,
    /// s_{A,B}: the joint B in the global frame.
    s_ab: Vector2<f64>,
    /// s'_{D,B}: D -> B in the boom frame.
    s_db: Vector2<f64>,
    /// s'_{D,C}: D -> C in the boom frame.
    s_dc: Vector2<f64>,
}

impl BoomKinematics {
    /// The constant vectors below eq. (2.10).
    pub fn new(p: &BoomParams) -> Self {
        let triangle = Triangle::new(p);
        let body = Body::new(p);
        let Triangle { w2, phi1, .. } = triangle;
        Self {
            triangle,
            body,
            s_ab: Vector2::new(-w2 * phi1.cos(), w2 * phi1.sin()),
            s_db: -body.e_cm,
            s_dc: triangle.upper_pin() - body.e_cm,
        }
    }

    pub fn triangle(&self) -> &Triangle {
        &self.triangle
    }

    pub fn body(&self) -> &Body {
        &self.body
    }

    /// Global position of the point `local` given in the boom frame relative to the joint B
    /// (B + A_2 local, from eq. 2.9).
    pub fn point<T: Scalar>(&self, theta2: T, local: Vector2<f64>) -> Vector2<T> {
        let (s, c) = theta2.sin_cos();
        Vector2::new(c * local.x - s * local.y + self.s_ab.x, s * local.x + c * local.y + self.s_ab.y)
    }

    /// q = (x_D, y_D, theta2) in closed form: theta2 from [`Triangle::theta2`], r_D from the
    /// revolute constraint (2.9), r_D = s_AB - A_2 s'_DB.
    pub fn q(&self, l_cyl: f64) -> Vector3<f64> {
        let theta2 = self.triangle.theta2(l_cyl);
        let r_d = self.point(theta2, -self.s_db);
        Vector3::new(r_d.x, r_d.y, theta2)
    }

    /// The cylinder vector d = A -> C, below eq. (2.10).
    fn d(&self, q: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(q.x, q.y) + rotation(q.z) * self.s_dc
    }

    /// Position constraints Phi(q, t), eq. (2.11).
    pub fn constraints(&self, q: &Vector3<f64>, l_cyl: f64) -> Vector3<f64> {
        let r = Vector2::new(q.x, q.y) + rotation(q.z) * self.s_db - self.s_ab;
        Vector3::new(r.x, r.y, self.d(q).norm_squared() - l_cyl * l_cyl)
    }

    /// Constraint Jacobian Phi_q, the matrix of eq. (2.13).
    pub fn jacobian(&self, q: &Vector3<f64>) -> Matrix3<f64> {
        let b2 = rotation_derivative(q.z);
        let bs = b2 * self.s_db;
        let d = self.d(q);
        #[rustfmt::skip]
        let phi_q = Matrix3::new(
            1.0, 0.0, bs.x,
            0.0, 1.0, bs.y,
            2.0 * d.x, 2.0 * d.y, 2.0 * d.dot(&(b2 * self.s_dc)),
        );
        phi_q
    }

    fn solve(&self, q: &Vector3<f64>, rhs: Vector3<f64>, l_cyl: f64) -> Result<Vector3<f64>, MechanicsError> {
        self.jacobian(q).lu().solve(&rhs).ok_or(MechanicsError::SingularJacobian { l_cyl })
    }

    /// Solves the position constraints (2.11) for q by Newton-Raphson, starting from the boom
    /// angle `theta2_guess` with r_D on the revolute constraint (2.9).
    ///
    /// Converged when a Newton step is below 1e-12 (m or rad); with quadratic convergence the
    /// step after that is of order 1e-24, so the result is exact to rounding. The triangle has a
    /// mirror solution (C on the other side of A-B); a guess on the rig's side (e.g. theta2 = 0)
    /// finds the rig's configuration.
    pub fn solve_position(&self, l_cyl: f64, theta2_guess: f64) -> Result<Vector3<f64>, MechanicsError> {
        const MAX_ITERATIONS: usize = 50;
        let r_d = self.point(theta2_guess, -self.s_db);
        let mut q = Vector3::new(r_d.x, r_d.y, theta2_guess);
        for _ in 0..MAX_ITERATIONS {
            let step = self.solve(&q, -self.constraints(&q, l_cyl), l_cyl)?;
            q += step;
            if step.amax() < 1e-12 {
                return Ok(q);
            }
        }
        Err(MechanicsError::NoConvergence { l_cyl })
    }

    /// Velocity q_dot from the velocity constraints, eq. (2.13).
    pub fn velocity(&self, q: &Vector3<f64>, l_cyl: f64, l_dot: f64) -> Result<Vector3<f64>, MechanicsError> {
        self.solve(q, Vector3::new(0.0, 0.0, 2.0 * l_cyl * l_dot), l_cyl)
    }

    /// Acceleration q_ddot from the acceleration constraints (2.14), solved as in eq. (2.15).
    ///
    /// Deviation: eq. (2.15) drops the term 2 l_cyl l_cyl_ddot of (2.14) from the right-hand side,
    /// valid only for the constant cylinder velocity of the thesis' verification runs; it is
    /// kept here.
    pub fn acceleration(
        &self,
        q: &Vector3<f64>,
        q_dot: &Vector3<f64>,
        l_cyl: f64,
        l_dot: f64,
        l_ddot: f64,
    ) -> Result<Vector3<f64>, MechanicsError> {
        let (a2, b2) = (rotation(q.z), rotation_derivative(q.z));
        let w2 = q_dot.z * q_dot.z;
        let top = w2 * (a2 * self.s_db);
        let d_dot = Vector2::new(q_dot.x, q_dot.y) + q_dot.z * (b2 * self.s_dc);
        let bottom = 2.0 * w2 * self.d(q).dot(&(a2 * self.s_dc)) - 2.0 * d_dot.norm_squared()
            + 2.0 * l_dot * l_dot
            + 2.0 * l_cyl * l_ddot;
        self.solve(q, Vector3::new(top.x, top.y, bottom), l_cyl)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::DEG;

    fn kin() -> BoomKinematics {
        BoomKinematics::new(&BoomParams::default())
    }

    /// Newton-Raphson on (2.11) against the closed-form triangle (2.1-2.7) over the whole stroke
    /// and beyond. Both are exact to rounding; the quantities are O(1) m and rad, so 1e-12 allows
    /// for the few ulps of acos/atan2 and the Newton solve.
    #[test]
    fn newton_raphson_matches_closed_form_triangle() {
        let k = kin();
        let p = BoomParams::default();
        for i in 0..=60 {
            let l = p.l_retracted - 0.05 + 0.01 * i as f64;
            let q = k.solve_position(l, 0.0).unwrap();
            let exact = k.q(l);
            assert!((q - exact).amax() < 1e-12, "l = {l}: {q} vs {exact}");
            // theta1 (2.7) is the direction of d = A -> C.
            let d = k.d(&q);
            assert!((d.y.atan2(d.x) - k.triangle().theta1(l)).abs() < 1e-12);
            assert!((d.norm() - l).abs() < 1e-12);
        }
    }

    /// Independent check of the triangle: with theta2 = 0 the upper pin C lies at
    /// B + (l1 + b4 - b7, -(b5 + b6)), so |AC| computed from the coordinates must give theta2 = 0.
    #[test]
    fn horizontal_boom_from_coordinates() {
        let p = BoomParams::default();
        let [b1, b2, b3, b4, b5, b6, b7, b8] = p.b;
        let (bx, by) = (-(p.l2 + b2 - b1), b8 - b3);
        let (cx, cy) = (bx + p.l1 + b4 - b7, by - (b5 + b6));
        let l = cx.hypot(cy);
        let t = *kin().triangle();
        assert!(t.theta2(l).abs() < 1e-14);
        assert!((t.theta1(l) - cy.atan2(cx)).abs() < 1e-14);
    }

    /// Experiment I of chapter 3.1: l1 = 0.6 m, l2 = 0.3 m, l_cyl = 0.93 m, "approximately
    /// horizontal". The value is reported for later use; the assertion pins it to the triangle
    /// computed by hand (w1 = 0.61066 m, w2 = 1.10613 m, phi1 = 72.859 deg, phi2 = 12.580 deg,
    /// beta = acos((w1^2 + w2^2 - 0.93^2) / (2 w1 w2)) = 57.2143 deg) to the 1e-3 deg of the hand
    /// computation.
    #[test]
    fn theta2_in_experiment_one() {
        let theta2 = kin().triangle().theta2(0.93);
        println!("theta2(l_cyl = 0.93 m) = {:.4} deg", theta2 / DEG);
        assert!((theta2 / DEG - (57.2143 - 72.8592 + 12.5797)).abs() < 1e-3);
    }

    /// (2.13) and (2.15) against central differences of the closed-form q(l(t)) along
    /// l(t) = l0 + v t + a t^2 / 2: truncation O(h^2) ~ 1e-8 relative with h = 1e-4 s, rounding
    /// ~1e-16/h^2 = 1e-8 for the second difference, so 1e-6 relative is a safe bound.
    #[test]
    fn velocity_and_acceleration_match_differences() {
        let k = kin();
        let (l0, v, a, h) = (1.0, 0.3, -2.0, 1e-4);
        let l = |t: f64| l0 + v * t + 0.5 * a * t * t;
        let q = k.q(l0);
        let q_dot = k.velocity(&q, l0, v).unwrap();
        let q_ddot = k.acceleration(&q, &q_dot, l0, v, a).unwrap();
        let (qp, qm) = (k.q(l(h)), k.q(l(-h)));
        let fd_dot = (qp - qm) / (2.0 * h);
        let fd_ddot = (qp - 2.0 * q + qm) / (h * h);
        assert!((q_dot - fd_dot).amax() < 1e-6 * q_dot.amax(), "{q_dot} vs {fd_dot}");
        assert!((q_ddot - fd_ddot).amax() < 1e-6 * q_ddot.amax(), "{q_ddot} vs {fd_ddot}");
        // The closed-form derivatives of theta2 give the same velocity.
        let (_, d1, _) = k.triangle().theta2_derivatives(l0);
        assert!((q_dot.z - d1 * v).abs() < 1e-12);
    }
}
