//! The lumped flexible boom (thesis 2.1.4, eq. 2.34-2.39, layout of 3.1.2 and Fig. 3.5).
//!
//! The arm is a planar chain of rigid sections pinned at the joint B: part I (behind B) is rigid
//! and fixed to the first section; part II (B to the cylinder mount at `x_mount`) has n2 sections
//! of equal length, or is one rigid body for n2 = 0; part III (mount to the arm's end) has n3.
//! The mount is always a section boundary. Neighbouring sections are joined by torsional springs
//! and dampers; there is no spring at B and none at the free end.
//!
//! Generalised coordinates q: the absolute angle of every section's centre line to the global x
//! axis (q[0] is the first section of part II; all equal theta2 for the undeformed arm). The
//! chain starts at B; section i runs from node i to node i + 1.
//!
//! - Springs: a section of length l has k_sec = 2 E I / l at each end (2.34); a joint is the
//!   series of the two neighbours' half-springs (2.35), k = 2 E I / (l_a + l_b), i.e. E I / l_sec
//!   for equal sections; a rigid part II contributes no compliance.
//! - Dampers: c_sec = 2 xi sqrt(k_sec J_sec) (2.36, 2.37) in series like the springs (2.38),
//!   with J_sec = m_sec l^2 / 3 (2.39) of the section's own arm mass. For equal sections that is
//!   stiffness-proportional damping c = beta k with beta = 2 xi / omega_sec, omega_sec =
//!   sqrt(6 E I / (mu l^4)) a single section's frequency: xi is reached at omega_sec, a mode at
//!   omega gets xi omega / omega_sec, and omega_sec grows with n^2. So the arm's modal damping
//!   falls as the lumping is refined (the 47.5 Hz mode: 1.4 % at 1 + 2 sections, 0.21 % at
//!   4 + 5, 0.023 % at 12 + 15; the frequencies converge) and its first bending mode, the one
//!   that [3, p. 97]'s 1-2 % for steel structures is about, keeps 0.01 %. `boom.damping` =
//!   `structural` ([`DampingLaw::Structural`], not in the thesis) anchors beta instead at the
//!   arm's first bending frequency omega_b ([`FlexibleBoom::bending_frequency`], 3.4 Hz for the rig), beta =
//!   2 xi / omega_b: that mode gets xi whatever the sections, higher modes xi omega / omega_b.
//!   `boom.damping` = `modal` ([`DampingLaw::Modal`], not in the thesis; the default) is modal
//!   damping: each mode of the arm with the cylinder locked ([`FlexibleBoom::locked_modes`]) below the
//!   band of interest ([`BAND`], 50 Hz: the first bending mode, 3.4 Hz) keeps the damping ratio
//!   the thesis' law gives it, and every mode above it is damped at least critically
//!   ([`QUASI_STATIC`]). Those modes (70 Hz to 10 kHz at 4 + 5 sections) are the lumping's:
//!   their frequencies and the thesis' damping of them move with n. Made non-oscillating, they
//!   follow the slow motion quasi-statically (with a lag of 2 / omega, under 5 ms), as a modal
//!   truncation with static correction keeps them (Craig & Kurdila, Fundamentals of Structural
//!   Dynamics, 2nd ed., the mode-acceleration method), and the integrator no longer resolves
//!   their ringing after each stick of the cylinder. The joints' dampers then form one
//!   symmetric matrix C (each joint's torque from every joint's rate, [`FlexibleBoom::damper`]).
//!   The band is decided on the locked modes: coupled to the oil column, the second locked mode
//!   (70 Hz) is a plant mode at 47.5 Hz (0.2 % under the thesis' law) that this law moves to
//!   55.5 Hz at 12 % (`boomsim eigen`), damped but not quasi-static;
//!   the rigid turn about B has no deflection and no damping, as under the thesis' law.
//! - Masses: the arm is uniform (m_arm / l_arm per length), each section a slender rod. Its
//!   inertia about its inner node, m l^2 / 3, is (2.39) and is what the equations use; part I adds
//!   its mass and inertia to the first section; the payload is a point mass at (x2, h_pl) of
//!   (2.8) fixed to the section that contains x2.
//! - The cylinder's upper pin C sits at its rigid-boom position (x1, -w1 sin phi2) (2.1, 2.5)
//!   on the last section of part II, i.e. the bracket is rigid with the section inboard of the
//!   mount (it lies 6 mm outboard of the thesis' x_mount = 0.59 m for x1 = 0.596 m). So a rigid
//!   part II stays put at a given cylinder length and part III is a cantilever (experiment II).
//! - The cylinder force acts on C along A -> C; the rod and piston translate along the cylinder
//!   axis with the stroke, loaded by m_rod g sin(theta1), as in [`super::rigid_boom`].
//!
//! Equations of motion (Lagrange, absolute angles):
//!
//! ```text
//! (M(q) + m_rod g g^T) q_ddot = Q_gravity + Q_spring + Q_damper - h(q, q_dot)
//!                               + g (F_cyl - m_rod (kappa + g_acc sin theta1))
//! M_jk = A_jk cos(q_j - q_k) + B_jk sin(q_j - q_k),  h_j = sum_k (A_jk sin - B_jk cos)(q_j - q_k) q_dot_k^2
//! A_jk = l_j (l_k m_out,k + S_k,x), B_jk = l_j S_k,y  (j < k),   M_jj = l_j^2 m_out,j + J_j
//! ```
//!
//! with m_out,k the mass outboard of section k, S_k and J_k the first and second moments of
//! section k's masses about its inner node in its own frame, g = dl_cyl/dq and
//! kappa = d^2 l_cyl/dt^2 - g . q_ddot.
//!
//! [`Mechanics::accelerations`] does not assemble M: it solves the same equations in O(n)
//! by the articulated-body recursion of the planar chain (Featherstone's, with the joint
//! constraint forces as unknowns), i.e. Gaussian elimination of the chain from its free end.
//! Node j (section j's inner node) accelerates by a_j, a_0 = 0 at B; r_j = l_j (cos q_j, sin q_j)
//! runs to node j + 1, so a_(j+1) = a_j + q_ddot_j perp(r_j) - q_dot_j^2 r_j (perp turns by
//! +90 deg, v x w = perp(v) . w). The chain outboard of node j + 1 pushes back on section j with
//! the force F_(j+1) = K_(j+1) a_(j+1) + b_(j+1) (K symmetric 2 x 2, the articulated inertia;
//! K_n = 0, b_n = 0 at the free end). With S_j, J_j, m_j of section j turned into the global
//! frame, gravity g_vec and tau_j = tau_(j,j+1) - tau_(j-1,j) the spring and damper torques of
//! its two joints (k (dq) + c (dq_dot), 2.34-2.38), section j's moment balance about node j
//! (the Lagrange row of q_j) and its force balance give
//!
//! ```text
//! q_ddot_j = (e_j - h_j . a_j) / d_j                  (moment: J q_ddot + S x a + r x F_(j+1) = tau + S x g_vec)
//! d_j  = J_j + perp(r_j)^T K_(j+1) perp(r_j)
//! h_j  = perp(S_j) + K_(j+1) perp(r_j)
//! beta = b_(j+1) - q_dot_j^2 K_(j+1) r_j
//! e_j  = tau_j + S_j x g_vec - perp(r_j) . beta
//! K_j  = m_j I + K_(j+1) - h_j h_j^T / d_j           (force: F_j = m_j a_cm - m_j g_vec + F_(j+1))
//! b_j  = beta - q_dot_j^2 S_j - m_j g_vec + h_j e_j / d_j
//! ```
//!
//! The rod is a second attachment of the last section of part II, at C (rho = node -> C): a point
//! with inertia m_rod u u^T only (it moves along the cylinder axis u) pushing with
//! F_rod = F_cyl - m_rod (g_acc sin theta1 + (|C_dot|^2 - l_dot^2) / l_cyl), the second term being
//! l_ddot - u . a_C. It adds m_rod u u^T to K, m_rod (u . perp(rho))^2 to d,
//! m_rod (u . perp(rho)) u to h, and the load F_rod + m_rod q_dot^2 u . rho along u to e (lever
//! u . perp(rho)) and, negated, to b: exactly the m_rod g g^T and g (...) terms above.
//!
//! A backward sweep from the free end gives K, b and h / d, e / d of every section, a forward
//! sweep from B the accelerations. Both run in the frame turned by q_0: the section angles in it,
//! q_j - q_0, are the beam's small deflections, whose sin and cos are short polynomials; only
//! gravity and B turn with q_0 (one library sin_cos). Some 100 flops and four divisions per
//! section, no matrix, nothing allocated; the test `equations_of_motion_hold` checks the sweeps against
//! M q_ddot = Q assembled from the formulas above.
//!
//! The integrator's Jacobian ([`FlexibleBoom::acceleration_jacobian`], issue 48) differentiates
//! that Lagrange form instead of the sweeps: M_jk and h_j depend on q_j - q_k only, so each
//! derivative of M q_ddot + h is one entry per pair of sections; M~ is assembled densely,
//! factorised once (Cholesky) and solved for the accelerations and the 2n + 1 columns
//! (q, q_dot, F_cyl) at once, O(n^2) work plus the solves' n^2 (2n + 1), against n sweeps
//! per column for differences or dual numbers.

use nalgebra::{DMatrix, DVector, Vector2};

use super::kinematics::{law_of_cosines, Triangle};
use super::params::{BeamParams, BoomParams, DampingLaw};
use super::rigid_boom::RigidBoom;
use super::{Energy, Equilibrium, Kinetics, Mechanics, MechanicsError};
use crate::scalar::Scalar;
use crate::solver::cholesky;

/// The modal law's band of interest (rad/s): 50 Hz, numerics issue 27's "the boom's dynamics of
/// interest are below 50 Hz" (the rig's mode is 2.85 Hz, thesis 5.1.3; the feedback's filter
/// corner is at most 168 rad/s = 27 Hz, section 6.1).
pub const BAND: f64 = 50.0 * std::f64::consts::TAU;

/// The modal law's least damping ratio above [`BAND`]: critical, the fastest decay without
/// oscillation.
pub const QUASI_STATIC: f64 = 1.0;

/// A locked mode is converged when its frequency moves less than this from the chain's section
/// counts to twice them (issue 48).
pub const CONVERGED: f64 = 0.01;

/// Most sections the chain may have: max(n2, 1) + n3.
pub const MAX_SECTIONS: usize = 32;

pub type Column = [f64; MAX_SECTIONS];

/// The most numbers of [`ArmJacobian::rows`]: n rows of 2n + 1 at n = [`MAX_SECTIONS`].
const JACOBIAN_ROWS: usize = MAX_SECTIONS * (2 * MAX_SECTIONS + 1);

/// The lumped flexible boom; see the module documentation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlexibleBoom {
    rigid: RigidBoom,
    triangle: Triangle,
    n: usize,
    /// Sections of part II as bodies: max(n2, 1).
    n_ii: usize,
    /// Section lengths and the arm coordinate of each inner node (from B).
    len: Column,
    start: Column,
    /// Mass of each section (with part I and the payload) and the mass outboard of it.
    mass: Column,
    m_out: Column,
    /// First and second moments of each section's masses about its inner node (section frame).
    first: [Vector2<f64>; MAX_SECTIONS],
    second: Column,
    /// Spring and damper of the joint between section i and i + 1.
    k: Column,
    c: Column,
    /// The damping law (`boom.damping`) and, for the modal law, the joints' damping matrix
    /// (rows of MAX_SECTIONS, the first n - 1 of each).
    damping: DampingLaw,
    modal: [f64; MAX_SECTIONS * MAX_SECTIONS],
    /// Upper cylinder pin, in the frame of the last section of part II.
    pin: Vector2<f64>,
    payload_section: usize,
    payload: Vector2<f64>,
    /// The joint B in the global frame (origin A).
    b: Vector2<f64>,
    l_retracted: f64,
    m_rod: f64,
    g: f64,
}

/// The cylinder pin C: position, unit vector and length of A -> C (C = B + sum_j r_j over the
/// sections up to the mount, each lever r_j turning with q_j; see [`FlexibleBoom::lever`]).
struct Pin<T: Scalar> {
    c: Vector2<T>,
    u: Vector2<T>,
    l: T,
}

/// What the backward sweep keeps of section j for the forward sweep: h_j / d_j and e_j / d_j
/// (module documentation).
#[derive(Debug, Clone, Copy)]
struct Sweep<T> {
    hx: T,
    hy: T,
    e: T,
}

/// The arm's accelerations and their derivatives ([`FlexibleBoom::acceleration_jacobian`]).
#[derive(Debug, Clone)]
pub struct ArmJacobian {
    /// The accelerations q_ddot (the first n).
    pub qdd: Column,
    /// d q_ddot / d q, d q_ddot / d q_dot at a fixed cylinder force, then d q_ddot / d F_cyl:
    /// n rows of 2n + 1, one after the other (the rest zero).
    pub rows: [f64; JACOBIAN_ROWS],
    /// g = d x / d q = d v / d q_dot of the stroke x and its rate v (zero beyond part II).
    pub gradient: Column,
    /// d v / d q = H q_dot.
    pub rate_gradient: Column,
}

/// Sine and cosine of the section angles (the first n, or the first n_ii for the pin alone).
#[derive(Clone, Copy)]
struct Trig<T> {
    s: [T; MAX_SECTIONS],
    c: [T; MAX_SECTIONS],
}

impl<T: Scalar> Trig<T> {
    /// The first `m` angles turned by `q0`: relative to q_0 ([`FlexibleBoom::relative_trig`])
    /// into absolute.
    fn turned(mut self, q0: T, m: usize) -> Self {
        let (s0, c0) = q0.sin_cos();
        for (s, c) in self.s[..m].iter_mut().zip(&mut self.c[..m]) {
            (*s, *c) = (s0 * *c + c0 * *s, c0 * *c - s0 * *s);
        }
        self
    }
}

/// sin and cos of |d| <= [`SMALL_ANGLE`] by their Taylor series to d^9 and d^10 (Horner in
/// d^2): the first omitted terms, d^11 / 11! and d^12 / 12!, are below 3e-18 of the result there,
/// under a fortieth of an ulp.
fn sin_cos_small<T: Scalar>(d: T) -> (T, T) {
    const SIN: [f64; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0];
    const COS: [f64; 5] = [-1.0 / 2.0, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0, -1.0 / 3628800.0];
    let z = d * d;
    let s = SIN.iter().rev().fold(T::from(0.0), |acc, &k| z * (acc + k));
    let c = COS.iter().rev().fold(T::from(0.0), |acc, &k| z * (acc + k));
    (d + d * s, c + 1.0)
}

/// Largest angle difference evaluated by [`sin_cos_small`] (the beam's deflections are
/// hundredths of a radian); beyond it the library `sin_cos`.
const SMALL_ANGLE: f64 = 0.1;

/// `v` turned by +90 deg: the derivative of a rotating vector with respect to its angle.
fn perp<T: Scalar>(v: Vector2<T>) -> Vector2<T> {
    Vector2::new(-v.y, v.x)
}

/// |v|, as nalgebra's `norm` (the square root of the dot product) for any [`Scalar`].
fn norm<T: Scalar>(v: Vector2<T>) -> T {
    v.dot(&v).sqrt()
}

/// The constant vector `v` in the number type `T`.
fn lift<T: Scalar>(v: Vector2<f64>) -> Vector2<T> {
    Vector2::new(T::from(v.x), T::from(v.y))
}

/// Series combination of two springs or dampers (2.35, 2.38); infinity is a rigid side.
/// The converged-modal law's damping ratio at `ratio` = omega / omega_c: `zeta` up to 1, then a
/// C1 smoothstep in log2(ratio) to [`QUASI_STATIC`] at 2 (one octave), at least `zeta`.
fn converged_ratio(zeta: f64, ratio: f64) -> f64 {
    let s = ratio.log2().clamp(0.0, 1.0);
    zeta + (QUASI_STATIC - zeta).max(0.0) * s * s * (3.0 - 2.0 * s)
}

fn series(a: f64, b: f64) -> f64 {
    1.0 / (1.0 / a + 1.0 / b)
}

impl FlexibleBoom {
    /// Builds the chain; `stroke` is the cylinder's stroke as for [`RigidBoom::new`].
    pub fn new(p: &BoomParams, beam: &BeamParams, stroke: f64) -> Result<Self, MechanicsError> {
        let rigid = RigidBoom::new(p, stroke)?;
        let triangle = *rigid.kinematics().triangle();
        let b7 = p.b[6];
        let x_end = p.l_arm - b7;
        let n_ii = beam.n2.max(1);
        let n = n_ii + beam.n3;
        if beam.n3 == 0 || n > MAX_SECTIONS {
            return Err(MechanicsError::InvalidBeam("need n3 >= 1 and max(n2, 1) + n3 <= 32"));
        }
        if !(0.0 < beam.x_mount && beam.x_mount < x_end) {
            return Err(MechanicsError::InvalidBeam("the mount must lie between the joint B and the arm's end"));
        }
        let per_length = p.m_arm / p.l_arm;
        let ei = beam.ei();
        let mut boom = Self {
            rigid,
            triangle,
            n,
            n_ii,
            len: [0.0; MAX_SECTIONS],
            start: [0.0; MAX_SECTIONS],
            mass: [0.0; MAX_SECTIONS],
            m_out: [0.0; MAX_SECTIONS],
            first: [Vector2::zeros(); MAX_SECTIONS],
            second: [0.0; MAX_SECTIONS],
            k: [0.0; MAX_SECTIONS],
            c: [0.0; MAX_SECTIONS],
            damping: beam.damping,
            modal: [0.0; MAX_SECTIONS * MAX_SECTIONS],
            pin: Vector2::zeros(),
            payload_section: 0,
            payload: Vector2::new(p.l_pl() - b7, p.h_pl),
            b: rigid.kinematics().point(0.0, Vector2::zeros()),
            l_retracted: p.l_retracted,
            m_rod: p.m_rod,
            g: p.g,
        };
        let (mut k_sec, mut c_sec) = ([f64::INFINITY; MAX_SECTIONS], [f64::INFINITY; MAX_SECTIONS]);
        let l_iii = (x_end - beam.x_mount) / beam.n3 as f64;
        for i in 0..n {
            let (start, l) = if i < n_ii {
                let l = beam.x_mount / n_ii as f64;
                (i as f64 * l, l)
            } else {
                (beam.x_mount + (i - n_ii) as f64 * l_iii, l_iii)
            };
            let m = per_length * l;
            boom.len[i] = l;
            boom.start[i] = start;
            boom.mass[i] = m;
            boom.first[i] = Vector2::new(m * l / 2.0, 0.0);
            boom.second[i] = m * l * l / 3.0;
            if i >= n_ii || beam.n2 > 0 {
                k_sec[i] = 2.0 * ei / l;
                c_sec[i] = 2.0 * beam.xi * (k_sec[i] * boom.second[i]).sqrt();
            }
        }
        let m_i = per_length * b7;
        boom.mass[0] += m_i;
        boom.first[0].x -= m_i * b7 / 2.0;
        boom.second[0] += m_i * b7 * b7 / 3.0;
        let ip = boom.section_at(boom.payload.x);
        boom.payload_section = ip;
        boom.payload.x -= boom.start[ip];
        boom.mass[ip] += p.m_pl;
        boom.first[ip] += p.m_pl * boom.payload;
        boom.second[ip] += p.m_pl * boom.payload.norm_squared();
        for i in (0..n - 1).rev() {
            boom.m_out[i] = boom.m_out[i + 1] + boom.mass[i + 1];
            boom.k[i] = series(k_sec[i], k_sec[i + 1]);
            boom.c[i] = series(c_sec[i], c_sec[i + 1]);
        }
        let (w1, phi2) = (triangle.w1, triangle.phi2);
        boom.pin = Vector2::new(w1 * phi2.cos() - boom.start[n_ii - 1], -w1 * phi2.sin());
        if beam.damping == DampingLaw::Structural {
            let beta = 2.0 * beam.xi / boom.bending_frequency()?;
            for i in 0..n - 1 {
                boom.c[i] = beta * boom.k[i];
            }
        }
        if beam.damping == DampingLaw::Modal {
            boom.modal_damping()?;
        }
        if beam.damping == DampingLaw::ConvergedModal {
            let refined = BeamParams {
                n2: (2 * beam.n2).min(16),
                n3: (2 * beam.n3).min(16),
                damping: DampingLaw::Thesis,
                ..*beam
            };
            let reference = Self::new(p, &refined, stroke)?.locked_frequencies()?;
            boom.converged_modal_damping(beam.xi, &reference)?;
        }
        Ok(boom)
    }

    /// The section containing the arm coordinate `x_a` (the first for x_a < 0, the last beyond
    /// the end).
    fn section_at(&self, x_a: f64) -> usize {
        (1..self.n).rev().find(|&i| x_a >= self.start[i]).unwrap_or(0)
    }

    /// Number of sections, n = max(n2, 1) + n3: the degrees of freedom.
    pub fn sections(&self) -> usize {
        self.n
    }

    /// The generalised mass matrix M(q) of the module documentation, without the rod's
    /// m_rod g g^T.
    fn mass_matrix(&self, q: &[f64]) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.n, self.n);
        for j in 0..self.n {
            m[(j, j)] = self.len[j] * self.len[j] * self.m_out[j] + self.second[j];
            for k in j + 1..self.n {
                let (a, b) = self.coupling(j, k);
                let (sin, cos) = (q[j] - q[k]).sin_cos();
                m[(j, k)] = a * cos + b * sin;
                m[(k, j)] = m[(j, k)];
            }
        }
        m
    }

    /// A_jk and B_jk of the module documentation (j < k).
    fn coupling(&self, j: usize, k: usize) -> (f64, f64) {
        (self.len[j] * (self.len[k] * self.m_out[k] + self.first[k].x), self.len[j] * self.first[k].y)
    }

    /// g = d l_cyl / d q: the levers of part II's sections along the cylinder axis.
    fn cylinder_gradient(&self, t: &Trig<f64>) -> Column {
        let u = self.pin_of(t).u;
        std::array::from_fn(|j| if j < self.n_ii { u.dot(&perp(self.lever(t, j))) } else { 0.0 })
    }

    /// The arm's first bending frequency (rad/s): the lowest of [`Self::locked_modes`]. The
    /// gravity-loaded rest shape and gravity's geometric stiffness are left out (together 0.03 %
    /// against the whole plant linearised with a rigid oil column, `boomsim_tools`' test
    /// `structural_damping_sits_at_the_arms_bending_mode`). `boom.damping` = `structural` sets
    /// beta at it.
    pub fn bending_frequency(&self) -> Result<f64, MechanicsError> {
        Ok(self.locked_modes()?.0.min().sqrt())
    }

    /// The frequencies of [`Self::locked_modes`] (rad/s), ascending.
    pub fn locked_frequencies(&self) -> Result<Vec<f64>, MechanicsError> {
        let mut omega: Vec<f64> = self.locked_modes()?.0.iter().map(|w2| w2.sqrt()).collect();
        omega.sort_by(f64::total_cmp);
        Ok(omega)
    }

    /// The arm's modes with the cylinder locked: omega^2 and the shapes w of K w = omega^2 M w,
    /// undeformed and horizontal (q = 0), g^T w = 0 (the rotation about B and the rod stand
    /// still), springs only; the shapes (columns, in q) normalised to w^T M w = 1.
    fn locked_modes(&self) -> Result<(DVector<f64>, DMatrix<f64>), MechanicsError> {
        let n = self.n;
        let q = [0.0; MAX_SECTIONS];
        let g = DVector::from_column_slice(&self.cylinder_gradient(&self.trig(&q[..n]))[..n]);
        let mut k = DMatrix::zeros(n, n);
        for i in 0..n - 1 {
            k[(i, i)] += self.k[i];
            k[(i + 1, i + 1)] += self.k[i];
            k[(i, i + 1)] -= self.k[i];
            k[(i + 1, i)] -= self.k[i];
        }
        // The Householder reflection that maps g onto e_0: its other columns span g^T w = 0.
        let mut v = g.clone();
        v[0] += g[0].signum() * g.norm();
        let h = DMatrix::identity(n, n) - &v * v.transpose() * (2.0 / v.norm_squared());
        let z = h.columns(1, n - 1);
        let (m, k) = (z.transpose() * self.mass_matrix(&q[..n]) * z, z.transpose() * k * z);
        let bad = MechanicsError::InvalidBeam("the arm's mass matrix is not positive definite");
        let l_inv = m.cholesky().ok_or(bad)?.l().try_inverse().ok_or(bad)?;
        let eigen = (&l_inv * k * l_inv.transpose()).symmetric_eigen();
        Ok((eigen.eigenvalues, z * l_inv.transpose() * eigen.eigenvectors))
    }

    /// `boom.damping` = `modal`, the modal law (module doc): each locked mode keeps the per-section law's
    /// own damping below [`BAND`], at least [`QUASI_STATIC`] above it ([`Self::set_modal_damping`]).
    fn modal_damping(&mut self) -> Result<(), MechanicsError> {
        let c = self.c;
        self.set_modal_damping(|omega, shape| {
            let thesis = (0..shape.len()).map(|l| c[l] * shape[l].powi(2)).sum::<f64>();
            if omega < BAND { thesis } else { thesis.max(2.0 * QUASI_STATIC * omega) }
        })
    }

    /// `boom.damping` = `converged_modal`, the converged-modal law: each locked mode j whose frequency is within
    /// [`CONVERGED`] of the refined chain's (`reference`: omega^2 of the chain with twice the
    /// sections, ascending) gets the damping ratio `zeta`, a steel structure's (the thesis' 2 %,
    /// [3, p. 97]); above the frequency omega_c where the relative difference reaches
    /// [`CONVERGED`] the ratio rises smoothly to [`QUASI_STATIC`] over an octave
    /// ([`converged_ratio`]). omega_c follows the modes: interpolated in log-log between the last
    /// mode inside and the first outside (the lumping's error grows as omega^2), so no mode's
    /// damping jumps when a parameter moves it.
    fn converged_modal_damping(&mut self, zeta: f64, reference: &[f64]) -> Result<(), MechanicsError> {
        let omega = self.locked_frequencies()?;
        let error: Vec<f64> = omega.iter().zip(reference).map(|(w, r)| (w / r - 1.0).abs()).collect();
        let omega_c = match error.iter().position(|&e| e >= CONVERGED) {
            None => f64::INFINITY,
            // Below the first mode: its error as omega^2.
            Some(0) => omega[0] * (CONVERGED / error[0]).sqrt(),
            Some(j) => {
                let (w0, w1, e0, e1) = (omega[j - 1].ln(), omega[j].ln(), error[j - 1].max(1e-300).ln(), error[j].ln());
                (w0 + (w1 - w0) * (CONVERGED.ln() - e0) / (e1 - e0)).exp()
            }
        };
        self.set_modal_damping(|omega, _| 2.0 * converged_ratio(zeta, omega / omega_c) * omega)
    }

    /// The joints' damping matrix C that gives each locked mode j its own damping,
    /// psi_j^T C psi_j = `modal(omega_j, psi_j)` (2 zeta_j omega_j) and psi_i^T C psi_j = 0, with
    /// psi_j the mode's joint deflections: C = Psi^-T diag(modal) Psi^-1 (Psi is regular: the
    /// n - 1 deflections of a locked shape fix it, g^T w = 0 excluding the rigid turn about B that
    /// has none).
    fn set_modal_damping(&mut self, modal: impl Fn(f64, &[f64]) -> f64) -> Result<(), MechanicsError> {
        let m = self.n - 1;
        let (omega2, shapes) = self.locked_modes()?;
        let psi = DMatrix::from_fn(m, m, |i, j| shapes[(i + 1, j)] - shapes[(i, j)]);
        let modal = DVector::from_fn(m, |j, _| modal(omega2[j].sqrt(), psi.column(j).as_slice()));
        let modal = DMatrix::from_diagonal(&modal);
        let inv = psi.try_inverse().ok_or(MechanicsError::InvalidBeam("the arm's locked modes are not independent"))?;
        let c = inv.transpose() * modal * &inv;
        for (i, row) in self.modal.chunks_exact_mut(MAX_SECTIONS).take(m).enumerate() {
            row[..m].iter_mut().enumerate().for_each(|(j, c_ij)| *c_ij = c[(i, j)]);
        }
        Ok(())
    }

    /// Torque of the damper of joint i (between sections i and i + 1): its own rate's under the
    /// per-section and structural laws (2.36-2.38), every joint's under the modal law.
    fn damper<T: Scalar>(&self, qd: &[T], i: usize) -> T {
        let (first, row) = self.damper_row(i);
        row.iter().zip(first..).fold(T::from(0.0), |tau, (&c, j)| tau + (qd[j + 1] - qd[j]) * c)
    }

    /// The coefficients of the damper of joint i on the joints' rates q_dot_(j+1) - q_dot_j,
    /// j = first, first + 1, ...: (i, [c_i]) under the per-section and structural laws
    /// (2.36-2.38), (0, row i of C) under the modal laws.
    fn damper_row(&self, i: usize) -> (usize, &[f64]) {
        if matches!(self.damping, DampingLaw::Modal | DampingLaw::ConvergedModal) {
            (0, &self.modal[i * MAX_SECTIONS..][..self.n - 1])
        } else {
            (i, std::slice::from_ref(&self.c[i]))
        }
    }

    /// The rigid boom of the same geometry (reference line of [`Self::tip_deflection`]).
    pub fn rigid(&self) -> &RigidBoom {
        &self.rigid
    }

    fn trig<T: Scalar>(&self, q: &[T]) -> Trig<T> {
        self.trig_to(q, self.n)
    }

    /// sin and cos of the first `m` angles. The sections differ from q[0] by the beam's
    /// deflection, so one library `sin_cos` of q[0] and the rotation by the small difference
    /// d = q[i] - q[0] ([`sin_cos_small`]) give them to an ulp or two; a difference beyond
    /// [`SMALL_ANGLE`] takes the library call.
    fn trig_to<T: Scalar>(&self, q: &[T], m: usize) -> Trig<T> {
        self.relative_trig(q, m).turned(q[0], m)
    }

    /// sin and cos of the first `m` angles relative to the first, q[i] - q[0].
    fn relative_trig<T: Scalar>(&self, q: &[T], m: usize) -> Trig<T> {
        let mut t = Trig { s: [T::from(0.0); MAX_SECTIONS], c: [T::from(0.0); MAX_SECTIONS] };
        for (i, &a) in q[..m].iter().enumerate() {
            let d = a - q[0];
            (t.s[i], t.c[i]) = if d.abs() <= SMALL_ANGLE { sin_cos_small(d) } else { d.sin_cos() };
        }
        t
    }

    /// The lever r_j of section j <= n_ii - 1 towards the pin C: the section itself, or for the
    /// last section of part II its inner node -> C.
    fn lever<T: Scalar>(&self, t: &Trig<T>, j: usize) -> Vector2<T> {
        let (s, c) = (t.s[j], t.c[j]);
        if j + 1 < self.n_ii {
            Vector2::new(c * self.len[j], s * self.len[j])
        } else {
            Vector2::new(c * self.pin.x - s * self.pin.y, s * self.pin.x + c * self.pin.y)
        }
    }

    fn pin_of<T: Scalar>(&self, t: &Trig<T>) -> Pin<T> {
        let c = (0..self.n_ii).fold(lift(self.b), |c, j| c + self.lever(t, j));
        let l = norm(c);
        Pin { c, u: c / l, l }
    }

    /// Velocity of the pin C.
    fn pin_velocity<T: Scalar>(&self, t: &Trig<T>, qd: &[T]) -> Vector2<T> {
        (0..self.n_ii).fold(Vector2::zeros(), |v, j| v + perp(self.lever(t, j)) * qd[j])
    }

    /// Generalised forces of gravity, springs and dampers.
    fn forces(&self, q: &[f64], qd: &[f64], t: &Trig<f64>, out: &mut [f64]) {
        for (i, o) in out[..self.n].iter_mut().enumerate() {
            let s = self.first[i];
            *o = -self.g * ((self.m_out[i] * self.len[i] + s.x) * t.c[i] - s.y * t.s[i]);
        }
        for i in 0..self.n - 1 {
            let tau = self.k[i] * (q[i + 1] - q[i]) + self.damper(qd, i);
            out[i] += tau;
            out[i + 1] -= tau;
        }
    }

    /// The accelerations of [`Kinetics::accelerations`] and their derivatives (issue 48), in
    /// closed form from the equations of motion of the module documentation,
    /// M~(q) q_ddot = Phi(q, q_dot, F_cyl) with M~ = M + m_rod g g^T, assembled densely: one Cholesky
    /// factorisation of M~ ([`cholesky`]) gives q_ddot, and with q_ddot held,
    /// d q_ddot / dz = M~^-1 d(Phi - M~ q_ddot) / dz, 2n + 1 solves. `f_cyl` is the cylinder force
    /// at the stroke and its rate, as for [`Kinetics::accelerations`]. The differentiated
    /// residual:
    ///
    /// - gravity (2.16's potential of each section): diagonal, g_acc (P_i sin q_i + S_i,y cos q_i),
    ///   P_i = l_i m_out,i + S_i,x;
    /// - springs (2.34, 2.35) and dampers (2.36-2.38 or the modal C): constant, tridiagonal in q
    ///   and [`Self::damper_row`]'s pattern in q_dot;
    /// - the chain's inertia, -h - M q_ddot: M_jk and h_j depend on q_j - q_k only, so
    ///   d M / d q_k is zero outside row and column k; with W_jk = A_jk sin - B_jk cos
    ///   (= -d M_jk / d(q_j - q_k)) the entry (j, k != j) is M_jk q_dot_k^2 - W_jk q_ddot_k and
    ///   the diagonal the negated sum of its row (a rigid turn of every section changes neither);
    ///   d(-h_j) / d q_dot_k = -2 W_jk q_dot_k;
    /// - the rod, g phi with phi = F_cyl - m_rod (kappa + g_acc sin theta1 + g . q_ddot) the force
    ///   it passes on and kappa = q_dot^T H q_dot, H = d g / d q the Hessian of l_cyl:
    ///   H_jk = (r_j . r_k - g_j g_k) / l - delta_jk u . r_j over part II's levers r_j (2.1, 2.5),
    ///   so d(g phi) / d q = H phi + g (d phi / d q)^T and d(g phi) / d q_dot = -2 m_rod g (H q_dot)^T.
    ///
    /// The stroke x and its rate v (which the circuit sees) have dx / dq = dv / dq_dot = g and
    /// dv / dq = H q_dot. `None` if M~ is not positive definite.
    pub fn acceleration_jacobian(&self, q: &[f64], qd: &[f64], f_cyl: &mut dyn FnMut(f64, f64) -> f64) -> Option<ArmJacobian> {
        let (n, m, cols) = (self.n, self.n_ii, 2 * self.n + 1);
        let rel = self.relative_trig(q, n);
        let t = rel.turned(q[0], n);
        let pin = self.pin_of(&t);
        let (u, l) = (pin.u, pin.l);
        let r: [Vector2<f64>; MAX_SECTIONS] =
            std::array::from_fn(|j| if j < m { self.lever(&t, j) } else { Vector2::zeros() });
        let g = self.cylinder_gradient(&t);
        // Every matrix on the stack, at the chain's largest size: a real-time doStep never
        // allocates (tests/leaks).
        let mut hessian = [0.0; MAX_SECTIONS * MAX_SECTIONS];
        for (j, row) in hessian[..m * m].chunks_exact_mut(m).enumerate() {
            for (k, h) in row.iter_mut().enumerate() {
                *h = (r[j].dot(&r[k]) - g[j] * g[k]) / l;
            }
            row[j] -= u.dot(&r[j]);
        }
        let times_h = |x: &[f64]| -> Column {
            std::array::from_fn(|j| if j < m { hessian[j * m..][..m].iter().zip(x).map(|(h, x)| h * x).sum() } else { 0.0 })
        };
        let h_qd = times_h(qd);
        // C_dot, l_dot, the levers' centripetal sum and kappa = q_dot^T H q_dot (module doc).
        let c_dot = self.pin_velocity(&t, qd);
        let v = u.dot(&c_dot);
        let centripetal = (0..m).fold(Vector2::zeros(), |a, j| a - r[j] * (qd[j] * qd[j]));
        let kappa = (0..m).map(|j| qd[j] * h_qd[j]).sum::<f64>();
        let force = f_cyl(l - self.l_retracted, v);
        // M~ (its lower triangle, for [`cholesky`]); M_jk above the diagonal of `mw`, W_jk below.
        let (mut mass, mut mw) = ([0.0; MAX_SECTIONS * MAX_SECTIONS], [0.0; MAX_SECTIONS * MAX_SECTIONS]);
        // The right-hand side Phi: gravity, springs and dampers, -h, the rod.
        let mut qdd = [0.0; MAX_SECTIONS];
        self.forces(q, qd, &t, &mut qdd);
        for j in 0..n {
            mass[j * n + j] = self.len[j] * self.len[j] * self.m_out[j] + self.second[j] + self.m_rod * g[j] * g[j];
            qdd[j] += g[j] * (force - self.m_rod * (kappa + self.g * u.y));
            for k in j + 1..n {
                let (aa, bb) = self.coupling(j, k);
                let (sin, cos) = (rel.s[j] * rel.c[k] - rel.c[j] * rel.s[k], rel.c[j] * rel.c[k] + rel.s[j] * rel.s[k]);
                let (m_jk, w_jk) = (aa * cos + bb * sin, aa * sin - bb * cos);
                (mw[j * n + k], mw[k * n + j]) = (m_jk, w_jk);
                mass[k * n + j] = m_jk + self.m_rod * g[j] * g[k];
                // h_j = sum_k W_jk q_dot_k^2, W_kj = -W_jk.
                qdd[j] -= w_jk * qd[k] * qd[k];
                qdd[k] += w_jk * qd[j] * qd[j];
            }
        }
        let mut inv_diag = [0.0; MAX_SECTIONS];
        let mass = &mut mass[..n * n];
        if !cholesky::factor(mass, &mut inv_diag[..n]) {
            return None;
        }
        cholesky::solve_rows(mass, &inv_diag[..n], &mut qdd[..n]);
        let h_qdd = times_h(&qdd);
        let phi = force - self.m_rod * (kappa + self.g * u.y + (0..m).map(|j| g[j] * qdd[j]).sum::<f64>());
        let mut a = [0.0; JACOBIAN_ROWS];
        for j in 0..n {
            let s = self.first[j];
            a[j * cols + j] += self.g * ((self.m_out[j] * self.len[j] + s.x) * t.s[j] + s.y * t.c[j]);
            a[j * cols + 2 * n] = g[j];
            for k in j + 1..n {
                let (m_jk, w_jk) = (mw[j * n + k], mw[k * n + j]);
                let (jk, kj) = (m_jk * qd[k] * qd[k] - w_jk * qdd[k], m_jk * qd[j] * qd[j] + w_jk * qdd[j]);
                a[j * cols + k] += jk;
                a[j * cols + j] -= jk;
                a[k * cols + j] += kj;
                a[k * cols + k] -= kj;
                a[j * cols + n + k] -= 2.0 * w_jk * qd[k];
                a[k * cols + n + j] += 2.0 * w_jk * qd[j];
            }
        }
        for i in 0..n - 1 {
            let k = self.k[i];
            a[i * cols + i] -= k;
            a[i * cols + i + 1] += k;
            a[(i + 1) * cols + i + 1] -= k;
            a[(i + 1) * cols + i] += k;
            let (first, row) = self.damper_row(i);
            for (&c, j) in row.iter().zip(first..) {
                a[i * cols + n + j + 1] += c;
                a[i * cols + n + j] -= c;
                a[(i + 1) * cols + n + j + 1] -= c;
                a[(i + 1) * cols + n + j] += c;
            }
        }
        for k in 0..m {
            // d u / d q_k = (perp(r_k) - u g_k) / l; d kappa / d q_k from kappa =
            // u . centripetal + (|C_dot|^2 - l_dot^2) / l.
            let du = (perp(r[k]) - u * g[k]) / l;
            let d_kappa = du.dot(&centripetal) - g[k] * qd[k] * qd[k]
                - 2.0 * (qd[k] * c_dot.dot(&r[k]) + v * h_qd[k]) / l
                - (c_dot.norm_squared() - v * v) * g[k] / (l * l);
            let d_phi = -self.m_rod * (d_kappa + self.g * du.y + h_qdd[k]);
            for j in 0..m {
                a[j * cols + k] += hessian[j * m + k] * phi + g[j] * d_phi;
                a[j * cols + n + k] -= 2.0 * self.m_rod * g[j] * h_qd[k];
            }
        }
        cholesky::solve_rows(mass, &inv_diag[..n], &mut a[..n * cols]);
        Some(ArmJacobian { qdd, rows: a, gradient: g, rate_gradient: h_qd })
    }

    /// Cylinder length |A C| for the section angles `q`.
    pub fn l_cyl<T: Scalar>(&self, q: &[T]) -> T {
        self.pin_of(&self.trig_to(q, self.n_ii)).l
    }

    /// Global position (origin A) of the centre-line point at arm coordinate `x_a` from B
    /// (x_a < 0 is part I).
    pub fn point(&self, q: &[f64], x_a: f64) -> Vector2<f64> {
        self.point_at(&self.trig(q), x_a)
    }

    /// [`Self::point`] with the sections' sin and cos.
    fn point_at<T: Scalar>(&self, t: &Trig<T>, x_a: f64) -> Vector2<T> {
        let i = self.section_at(x_a);
        let node = (0..i).fold(lift(self.b), |r, j| r + Vector2::new(t.c[j] * self.len[j], t.s[j] * self.len[j]));
        let d = x_a - self.start[i];
        node + Vector2::new(t.c[i] * d, t.s[i] * d)
    }

    /// Deflection of the arm's end normal to the rigid boom's centre line at the same cylinder
    /// length, positive up in the boom frame (the sign of v in 2.22).
    pub fn tip_deflection<T: Scalar>(&self, q: &[T]) -> T {
        let t = self.trig(q);
        let theta2 = self.triangle.theta2(self.pin_of(&t).l);
        let end = self.start[self.n - 1] + self.len[self.n - 1];
        let (s, c) = theta2.sin_cos();
        Vector2::new(-s, c).dot(&(self.point_at(&t, end) - lift(self.b)))
    }

    /// Section angles for the spring deflections `delta` (q[i + 1] - q[i]) at cylinder length
    /// `l_cyl`: the chain's shape fixes |B C|, and the triangle A-B-C (2.3) turns it into place.
    fn pose(&self, delta: &[f64], l_cyl: f64, q: &mut [f64]) -> Result<(), MechanicsError> {
        q[0] = 0.0;
        for i in 1..self.n {
            q[i] = q[i - 1] + delta[i - 1];
        }
        let c = self.pin_of(&self.trig(q)).c - self.b;
        let beta = law_of_cosines(c.norm(), self.triangle.w2, l_cyl);
        if !beta.is_finite() {
            return Err(MechanicsError::NoConvergence { l_cyl });
        }
        let turn = beta - self.triangle.phi1 - c.y.atan2(c.x);
        q[..self.n].iter_mut().for_each(|a| *a += turn);
        Ok(())
    }

    /// Static residual: the spring-deflection forces (tail sums of the generalised forces, the
    /// virtual work of each joint angle) with the cylinder force F' = F_cyl - m_rod g sin(theta1)
    /// that balances the rotation about B. Returns F'.
    fn static_residual(&self, delta: &[f64], l_cyl: f64, q: &mut [f64], r: &mut [f64]) -> Result<f64, MechanicsError> {
        self.pose(delta, l_cyl, q)?;
        let t = self.trig(q);
        let mut f = [0.0; MAX_SECTIONS];
        self.forces(q, &[0.0; MAX_SECTIONS], &t, &mut f);
        let g = self.cylinder_gradient(&t);
        let f_cyl = -f[..self.n].iter().sum::<f64>() / g.iter().sum::<f64>();
        let mut tail = 0.0;
        for i in (1..self.n).rev() {
            tail += f[i] + g[i] * f_cyl;
            r[i - 1] = tail;
        }
        Ok(f_cyl)
    }

    /// Gravity-loaded rest shape at cylinder length `l_cyl`: Newton on the n - 1 spring
    /// deflections with a forward-difference Jacobian (step 1e-9 rad against deflections of
    /// 1e-3 rad), converged when a step is below 1e-14 rad.
    pub fn equilibrium_at(&self, l_cyl: f64) -> Result<Equilibrium, MechanicsError> {
        const MAX_ITERATIONS: usize = 50;
        let m = self.n - 1;
        let (mut q, mut r, mut r_h) = (vec![0.0; self.n], vec![0.0; m], vec![0.0; m]);
        let mut delta = vec![0.0; m];
        let mut jac = DMatrix::zeros(m, m);
        for _ in 0..MAX_ITERATIONS {
            self.static_residual(&delta, l_cyl, &mut q, &mut r)?;
            for col in 0..m {
                let mut d = delta.clone();
                d[col] += 1e-9;
                self.static_residual(&d, l_cyl, &mut q, &mut r_h)?;
                for row in 0..m {
                    jac[(row, col)] = (r_h[row] - r[row]) / 1e-9;
                }
            }
            let step = jac
                .clone()
                .lu()
                .solve(&-DVector::from_column_slice(&r))
                .ok_or(MechanicsError::NoConvergence { l_cyl })?;
            delta.iter_mut().zip(step.iter()).for_each(|(d, s)| *d += s);
            if step.amax() < 1e-14 {
                let f = self.static_residual(&delta, l_cyl, &mut q, &mut r)?;
                let theta1 = self.pin_of(&self.trig(&q)).u;
                return Ok(Equilibrium { f_cyl: f + self.m_rod * self.g * theta1.y, q });
            }
        }
        Err(MechanicsError::NoConvergence { l_cyl })
    }
}

impl<T: Scalar> Kinetics<T> for FlexibleBoom {
    fn stroke(&self, q: &[T]) -> T {
        self.l_cyl(q) - self.l_retracted
    }

    fn stroke_rate(&self, q: &[T], qd: &[T]) -> T {
        let t = self.trig_to(q, self.n_ii);
        self.pin_of(&t).u.dot(&self.pin_velocity(&t, qd))
    }

    /// The articulated-body sweeps of the module documentation, in the frame turned by q_0
    /// (where a vector is written (x, y) below, it is in that frame).
    fn accelerations(&self, q: &[T], qd: &[T], f_cyl: &mut dyn FnMut(T, T) -> T, out: &mut [T]) {
        let zero = T::from(0.0);
        let n = self.n;
        let p = self.n_ii - 1;
        let t = self.relative_trig(q, n);
        let (s0, c0) = q[0].sin_cos();
        // Gravity g_vec and the joint B (from A) turned by -q_0.
        let (gx, gy) = (s0 * -self.g, c0 * -self.g);
        let b0 = Vector2::new(c0 * self.b.x + s0 * self.b.y, c0 * self.b.y - s0 * self.b.x);
        let pin = (0..self.n_ii).fold(b0, |c, j| c + self.lever(&t, j));
        let l = norm(pin);
        let u = pin / l;
        let c_dot = self.pin_velocity(&t, qd);
        let l_dot = u.dot(&c_dot);
        // F_rod: g_acc sin(theta1) = -u . g_vec.
        let f_rod = f_cyl(l - self.l_retracted, l_dot)
            - ((c_dot.dot(&c_dot) - l_dot * l_dot) / l - (u.x * gx + u.y * gy)) * self.m_rod;
        let mut sweep = [Sweep { hx: zero, hy: zero, e: zero }; MAX_SECTIONS];
        // K_(j+1) and b_(j+1); zero beyond the free end.
        let (mut kxx, mut kxy, mut kyy, mut bx, mut by) = (zero, zero, zero, zero, zero);
        // Torque of the joint j, j + 1 on section j (outboard minus inboard neighbour).
        let mut tau_out = zero;
        for j in (0..n).rev() {
            let (s, c, l) = (t.s[j], t.c[j], self.len[j]);
            // r_j = (x, y), S_j = (sx, sy).
            let (x, y) = (c * l, s * l);
            let f = self.first[j];
            let (sx, sy) = (c * f.x - s * f.y, s * f.x + c * f.y);
            let w2 = qd[j] * qd[j];
            let tau_in = if j > 0 { (q[j] - q[j - 1]) * self.k[j - 1] + self.damper(qd, j - 1) } else { zero };
            // K perp(r); d = J + perp(r)^T K perp(r) from the squares (off the K -> d path).
            let (kpx, kpy) = (kxy * x - kxx * y, kyy * x - kxy * y);
            let mut d = (y * y) * kxx + self.second[j] + ((x * x) * kyy - (x * 2.0 * y) * kxy);
            let (mut hx, mut hy) = (kpx - sy, kpy + sx);
            let (betax, betay) = (bx - w2 * (kxx * x + kxy * y), by - w2 * (kxy * x + kyy * y));
            let m = self.mass[j];
            // e without the perp(r) . beta term, and b without beta and h e / d.
            let mut e0 = tau_out - tau_in + (sx * gy - sy * gx);
            let (mut fx, mut fy) = (-w2 * sx - gx * m, -w2 * sy - gy * m);
            let (mut ixx, mut ixy, mut iyy) = (kxx + m, kxy, kyy + m);
            if j == p {
                let rho = self.lever(&t, p);
                let lever = u.dot(&perp(rho));
                let load = f_rod + w2 * self.m_rod * u.dot(&rho);
                let mu = Vector2::new(u.x * self.m_rod, u.y * self.m_rod);
                d += lever * self.m_rod * lever;
                hx += lever * mu.x;
                hy += lever * mu.y;
                e0 += lever * load;
                fx -= u.x * load;
                fy -= u.y * load;
                ixx += mu.x * u.x;
                ixy += mu.x * u.y;
                iyy += mu.y * u.y;
            }
            let inv_d = T::from(1.0) / d;
            let (hdx, hdy) = (hx * inv_d, hy * inv_d);
            (kxx, kxy, kyy) = (ixx - hx * hdx, ixy - hx * hdy, iyy - hy * hdy);
            let ed = (e0 - (x * betay - y * betax)) * inv_d;
            // b = beta + (fx, fy) + h e / d, written as a linear map of beta (shorter b -> b path).
            (bx, by) = (
                (betax * (hdx * y + 1.0) - betay * (hdx * x)) + (fx + hdx * e0),
                (betay * (-(hdy * x) + 1.0) + betax * (hdy * y)) + (fy + hdy * e0),
            );
            sweep[j] = Sweep { hx: hdx, hy: hdy, e: ed };
            tau_out = tau_in;
        }
        // a_(j+1) = a_j + q_ddot_j perp(r_j) - q_dot_j^2 r_j with q_ddot_j = (e - h . a_j) / d, as
        // the map a_(j+1) = (I - perp(r_j) (h / d)^T) a_j + (e / d) perp(r_j) - q_dot_j^2 r_j.
        let (mut ax, mut ay) = (zero, zero);
        for (j, (o, sw)) in out[..n].iter_mut().zip(&sweep).enumerate() {
            *o = sw.e - (sw.hx * ax + sw.hy * ay);
            let (s, c, l) = (t.s[j], t.c[j], self.len[j]);
            let (x, y, w2) = (c * l, s * l, qd[j] * qd[j]);
            let (cx, cy) = (-y * sw.e - w2 * x, x * sw.e - w2 * y);
            let (txx, txy, tyx, tyy) = (y * sw.hx + 1.0, y * sw.hy, -x * sw.hx, -(x * sw.hy) + 1.0);
            (ax, ay) = (txx * ax + (txy * ay + cx), tyx * ax + (tyy * ay + cy));
        }
    }

    fn payload(&self, q: &[T]) -> Vector2<T> {
        let (i, t) = (self.payload_section, self.trig(q));
        let (s, c, p) = (t.s[i], t.c[i], self.payload);
        self.point_at(&t, self.start[i]) + Vector2::new(c * p.x - s * p.y, s * p.x + c * p.y)
    }
}

impl Mechanics for FlexibleBoom {
    fn dof(&self) -> usize {
        self.n
    }

    fn equilibrium(&self, x: f64) -> Result<Equilibrium, MechanicsError> {
        self.equilibrium_at(self.l_retracted + x)
    }

    /// Kinetic energy of the sections and payload (node velocity v and angular velocity w of each:
    /// m |v|^2 / 2 + w v . perp(S) + J w^2 / 2) and of the rod (m_rod l_dot^2 / 2); potential energy of
    /// gravity on sections and payload and of the springs. The rod's weight is a load along the
    /// cylinder axis without a potential (module doc): its work is not included.
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        let t = self.trig(q);
        let n = self.n;
        let (mut v, mut kinetic) = (Vector2::zeros(), 0.0);
        for (i, &w) in qd[..n].iter().enumerate() {
            let (s, c) = (t.s[i], t.c[i]);
            let f = self.first[i];
            let moment = Vector2::new(c * f.x - s * f.y, s * f.x + c * f.y);
            kinetic += 0.5 * self.mass[i] * v.norm_squared() + w * v.dot(&perp(moment)) + 0.5 * self.second[i] * w * w;
            v += w * self.len[i] * Vector2::new(-s, c);
        }
        let l_dot = self.stroke_rate(q, qd);
        let mut y = self.b.y;
        let mut potential = 0.0;
        for i in 0..n {
            let s = self.first[i];
            potential += self.g * (self.mass[i] * y + t.s[i] * s.x + t.c[i] * s.y);
            y += self.len[i] * t.s[i];
        }
        for i in 0..n - 1 {
            potential += 0.5 * self.k[i] * (q[i + 1] - q[i]).powi(2);
        }
        Energy { kinetic: kinetic + 0.5 * self.m_rod * l_dot * l_dot, potential }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::deflection::AnalyticDeflection;

    const STROKE: f64 = 0.5;

    fn build(p: &BoomParams, beam: &BeamParams) -> FlexibleBoom {
        FlexibleBoom::new(p, beam, STROKE).unwrap()
    }

    /// Cylinder length of the horizontal boom: the pin (x1, -w1 sin phi2) at theta2 = 0.
    fn horizontal(boom: &FlexibleBoom) -> f64 {
        let t = boom.triangle;
        boom.rigid.kinematics().point(0.0, Vector2::new(t.w1 * t.phi2.cos(), -t.w1 * t.phi2.sin())).norm()
    }

    /// Stiffness scaled by 1000 (E = 210 TPa): deflections of ~20 um keep the chain's
    /// geometric nonlinearity (slope^2 ~ 1e-10) out of discretisation studies.
    fn linear_beam(n2: usize, n3: usize) -> BeamParams {
        let b = BeamParams::default();
        BeamParams { n2, n3, e: b.e * 1e3, ..b }
    }

    /// A point load P at the end of part III, cantilevered from a rigid part II, horizontal
    /// arm, massless arm. With n sections of h = L / n the joint moments are P (L - i h) and the
    /// joint compliances h / EI (h / 2EI at the root), so the end deflects by
    /// P h / EI (L^2 / 2 + sum_{i=1}^{n-1} (L - i h)^2) = P L^3 / 3EI (1 + 1 / (2 n^2)):
    /// the cantilever formula P L^3 / 3EI with the trapezoid rule's O(n^-2) error. A 1 kg load
    /// (~50 um) keeps the nonlinearity at (v / L)^2 ~ 1e-10; 1e-8 relative also covers the Newton
    /// tolerance (1e-14 rad against joint angles of ~1e-5 rad).
    #[test]
    fn tip_load_matches_cantilever_formula() {
        let p = BoomParams { m_arm: 0.0, m_pl: 1.0, x_pl_inboard: 0.0, h_pl: 0.0, ..BoomParams::default() };
        for n in [1, 2, 5, 15] {
            // The thesis' damping law: the modal law's modes need the arm's mass (statics ignore damping).
            let beam = BeamParams { n2: 0, n3: n, damping: DampingLaw::Thesis, ..BeamParams::default() };
            let boom = build(&p, &beam);
            let l_cyl = horizontal(&boom);
            let q = boom.equilibrium_at(l_cyl).unwrap().q;
            let span = p.l_arm - p.b[6] - beam.x_mount;
            let cantilever = -p.m_pl * p.g * span.powi(3) / (3.0 * beam.ei());
            let expected = cantilever * (1.0 + 0.5 / (n * n) as f64);
            let v = boom.tip_deflection(&q);
            println!(
                "n3 = {n:2}: {:.6} um, lumped formula {:.6} um, cantilever {:.6} um",
                v * 1e6,
                expected * 1e6,
                cantilever * 1e6
            );
            assert!((v / expected - 1.0).abs() < 1e-8, "n3 = {n}: {v} vs {expected}");
        }
    }

    /// Experiment II: rigid part II, part III in n sections, full load, against the analytic
    /// cantilever of part III. The lumped end deflection is the trapezoid rule on
    /// f(x) = M(x) (x_end - x) / EI, so by Euler-Maclaurin its error is
    /// (h^2 / 12) (f'(x_end) - f'(x_m)) / EI = (L^2 / 12 n^2) ((P + w L) L + M(x_m)) / EI
    /// (sag positive; P = m_pl g cos theta2, w = q cos theta2, M(x_m) the root moment):
    /// second order. The payload's kink inside the last section adds an O(h^2) term of at most
    /// P (x_end - x2) h^2 / 8, under 2 % of that; 3 % is the bound.
    #[test]
    fn cantilever_converges_at_second_order() {
        let p = BoomParams::default();
        for n in [4, 8, 16] {
            let beam = linear_beam(0, n);
            let boom = build(&p, &beam);
            let d = AnalyticDeflection::new(&p, &beam, 0.93).unwrap();
            let q = boom.equilibrium_at(0.93).unwrap().q;
            let error = d.cantilever_tip(beam.x_mount) - boom.tip_deflection(&q);
            let (c2, s2) = (d.theta2.cos(), d.theta2.sin());
            let span = d.x_end - beam.x_mount;
            let (pl, w) = (p.m_pl * p.g * c2, p.m_arm * p.g / p.l_arm * c2);
            let a = d.x2 - beam.x_mount;
            let root = pl * a + w * span * span / 2.0 - p.m_pl * p.g * p.h_pl * s2;
            let predicted = span * span / (12.0 * (n * n) as f64) * ((pl + w * span) * span + root) / beam.ei();
            println!("n3 = {n:2}: error {:.4e} m, Euler-Maclaurin {:.4e} m", error, predicted);
            assert!((error / predicted - 1.0).abs() < 0.03, "n3 = {n}: {error} vs {predicted}");
        }
    }

    /// The whole beam (n2 = n3 = n, mount on the pin, x_mount = x1) against (2.23-2.33),
    /// measured like the analytic v: normal to the chord through B and the mount node (the
    /// analytic model keeps the mount on the rigid line, the lumped one lets the bracket turn).
    /// Expected rate: first order. The bracket's couple w1 sin(phi2) cos(theta1 - theta2) F_cyl
    /// (the jump of M at x1, eq. 2.24) acts on the last section of part II, so the mount spring
    /// bends its inboard half-section (x1 / 2n) under the outboard moment instead of the inboard
    /// one: error -jump (x1 / 2n) (x_end - x1) / EI; the trapezoid terms are O(n^-2). Checked:
    /// n e(n) tends to that coefficient, its remainder halving with n (ratio 0.5 +- 0.1).
    #[test]
    fn lumped_converges_to_analytic() {
        let p = BoomParams::default();
        let mut remainder = Vec::new();
        for n in [4, 8, 16] {
            let mut beam = linear_beam(n, n);
            let d = AnalyticDeflection::new(&p, &beam, 0.93).unwrap();
            beam.x_mount = d.x1;
            let boom = build(&p, &beam);
            let q = boom.equilibrium_at(0.93).unwrap().q;
            let (b, mount, end) = (boom.point(&q, 0.0), boom.point(&q, d.x1), boom.point(&q, d.x_end));
            let chord = (mount - b).normalize();
            let v = chord.perp(&(end - b));
            let t = boom.triangle;
            let jump = t.w1 * t.phi2.sin() * (t.theta1(0.93) - d.theta2).cos() * d.f_cyl;
            let first = -jump * d.x1 / 2.0 * (d.x_end - d.x1) / beam.ei();
            let error = v - d.tip();
            println!(
                "n = {n:2}: error {error:.4e} m, n error {:.4e}, first-order coefficient {first:.4e}",
                error * n as f64
            );
            remainder.push(error * n as f64 - first);
        }
        for w in remainder.windows(2) {
            assert!((w[1] / w[0] - 0.5).abs() < 0.1, "{remainder:?}");
        }
    }

    /// With zero damping and the cylinder force a given function of time, the work of the
    /// cylinder and of the rod weight equals the change of T + V (energy of the sections,
    /// payload, springs and rod). Start: the straight (unloaded) beam at rest at l_cyl = 0.93 m,
    /// so every mode swings, under F = F_rest + 3 kN sin(2 pi t / 20 ms). RK4 with h = 0.5 us for
    /// 20 ms: the stiffest mode (~7e4 rad/s) has h omega ~ 0.035, an RK4 energy error of
    /// ~(h omega)^6 / 144 per step, ~1e-7 of its energy over the run; 1e-6 of the largest
    /// kinetic energy is the bound. The work is integrated as an extra state.
    #[test]
    fn energy_is_conserved_without_damping() {
        let p = BoomParams::default();
        // xi = 0 under the thesis' law: no damper at all (the modal law damps the high modes whatever xi).
        let boom = build(&p, &BeamParams { xi: 0.0, damping: DampingLaw::Thesis, ..BeamParams::default() });
        let n = boom.sections();
        let f_rest = boom.equilibrium_at(0.93).unwrap().f_cyl;
        let force = |t: f64| f_rest + 3000.0 * (2.0 * std::f64::consts::PI * t / 0.02).sin();
        let dim = 2 * n + 1;
        let rhs = |t: f64, y: &[f64], dy: &mut [f64]| {
            let (q, qd) = (&y[..n], &y[n..2 * n]);
            let f = force(t);
            dy[..n].copy_from_slice(qd);
            boom.accelerations(q, qd, &mut |_, _| f, &mut dy[n..2 * n]);
            let theta1 = boom.pin_of(&boom.trig(q)).u;
            dy[2 * n] = (f - p.m_rod * p.g * theta1.y) * boom.stroke_rate(q, qd);
        };
        let energy = |y: &[f64]| {
            let e = boom.energy(&y[..n], &y[n..2 * n]);
            (e.kinetic, e.kinetic + e.potential - y[2 * n])
        };
        let mut y = vec![0.0; dim];
        boom.pose(&vec![0.0; n - 1], 0.93, &mut y[..n]).unwrap();
        let (_, e0) = energy(&y);
        let h = 5e-7;
        let (mut k1, mut k2, mut k3, mut k4, mut tmp) =
            (vec![0.0; dim], vec![0.0; dim], vec![0.0; dim], vec![0.0; dim], vec![0.0; dim]);
        let (mut t_max, mut drift) = (0.0f64, 0.0f64);
        for i in 0..40_000 {
            let t = i as f64 * h;
            rhs(t, &y, &mut k1);
            tmp.iter_mut().enumerate().for_each(|(j, v)| *v = y[j] + h / 2.0 * k1[j]);
            rhs(t + h / 2.0, &tmp, &mut k2);
            tmp.iter_mut().enumerate().for_each(|(j, v)| *v = y[j] + h / 2.0 * k2[j]);
            rhs(t + h / 2.0, &tmp, &mut k3);
            tmp.iter_mut().enumerate().for_each(|(j, v)| *v = y[j] + h * k3[j]);
            rhs(t + h, &tmp, &mut k4);
            y.iter_mut().enumerate().for_each(|(j, v)| *v += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
            let (kinetic, e) = energy(&y);
            t_max = t_max.max(kinetic);
            drift = drift.max((e - e0).abs());
        }
        println!("max kinetic energy {t_max:.4} J, work {:.4} J, max |E - E0| {drift:.3e} J", y[2 * n]);
        assert!(t_max > 1.0, "the run must exchange energy");
        assert!(drift < 1e-6 * t_max, "{drift} J");
    }

    /// A practically rigid beam (E = 1e20 Pa) holds the load with the rigid boom's static
    /// force (2.19 plus rod weight) and carries the payload where the rigid boom does. Its
    /// deflections are ~1e-13 rad, so 1e-9 relative / 1e-9 m are rounding bounds.
    #[test]
    fn stiff_beam_is_the_rigid_boom() {
        let p = BoomParams::default();
        let boom = build(&p, &BeamParams { e: 1e20, ..BeamParams::default() });
        for x in [0.0, 0.18, 0.45] {
            let eq = boom.equilibrium(x).unwrap();
            let rigid = boom.rigid().static_force(x);
            assert!((eq.f_cyl / rigid - 1.0).abs() < 1e-9, "x = {x}: {} vs {rigid}", eq.f_cyl);
            assert!((boom.payload(&eq.q) - boom.rigid().state(x, 0.0).payload).amax() < 1e-9);
            assert!((boom.stroke(&eq.q) - x).abs() < 1e-12);
        }
    }

    /// The equations of motion of the module documentation assembled densely, with the
    /// library's sin and cos: the generalised mass matrix (M + m_rod g g^T) and the right-hand
    /// side Q - h + g (F_cyl - m_rod (kappa + g_acc sin theta1)).
    fn lagrange(boom: &FlexibleBoom, q: &[f64], qd: &[f64], f_cyl: f64) -> (DMatrix<f64>, DVector<f64>) {
        let n = boom.sections();
        let mut t = Trig { s: [0.0; MAX_SECTIONS], c: [0.0; MAX_SECTIONS] };
        for (i, a) in q.iter().enumerate() {
            (t.s[i], t.c[i]) = a.sin_cos();
        }
        let pin = boom.pin_of(&t);
        let (mut g, mut c_dot, mut centripetal) = (DVector::zeros(n), Vector2::zeros(), Vector2::zeros());
        for j in 0..boom.n_ii {
            let r = boom.lever(&t, j);
            g[j] = pin.u.dot(&perp(r));
            c_dot += perp(r) * qd[j];
            centripetal -= r * (qd[j] * qd[j]);
        }
        let l_dot = pin.u.dot(&c_dot);
        let kappa = pin.u.dot(&centripetal) + (c_dot.norm_squared() - l_dot * l_dot) / pin.l;
        let mut rhs = vec![0.0; n];
        boom.forces(q, qd, &t, &mut rhs);
        let mut rhs = DVector::from_vec(rhs) + &g * (f_cyl - boom.m_rod * (kappa + boom.g * pin.u.y));
        for j in 0..n {
            for k in j + 1..n {
                let (a, b) = boom.coupling(j, k);
                let (sin, cos) = (q[j] - q[k]).sin_cos();
                let w = a * sin - b * cos;
                rhs[j] -= w * qd[k] * qd[k];
                rhs[k] += w * qd[j] * qd[j];
            }
        }
        let m = boom.mass_matrix(q);
        (m + boom.m_rod * &g * g.transpose(), rhs)
    }

    /// Pseudo-random numbers uniform in [-1, 1) (xorshift64 from `seed`).
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// The sweeps of `accelerations` satisfy (M + m_rod g g^T) q_ddot = rhs (module doc) on
    /// random states of several layouts: section angles spread by 1e-4 rad (the stiff springs
    /// dominate), 1e-2 rad and 0.3 rad (beyond the polynomial sin and cos), speeds up to 20 rad/s.
    /// Each row's residual is a rounding error of the row's terms: below 1e-13 of
    /// sum_k |M_jk q_ddot_k| + |rhs_j|, whatever the conditioning (the dense Cholesky solve of
    /// M that this replaced differed from a 60-digit reference by up to 4e-12 of max |q_ddot|
    /// for 16 + 16 sections; these sweeps by 1.2e-13).
    #[test]
    fn equations_of_motion_hold() {
        let mut rand = uniform(0x2545_f491_4f6c_dd1d);
        let p = BoomParams::default();
        let mut worst = 0.0f64;
        for (n2, n3) in [(4, 5), (0, 1), (0, 5), (1, 1), (3, 1), (8, 2), (16, 16)] {
            let boom = build(&p, &BeamParams { n2, n3, ..BeamParams::default() });
            let n = boom.sections();
            for x in [0.0, 0.18, 0.45] {
                let q0 = boom.equilibrium(x).unwrap().q;
                for trial in 0..100 {
                    let q: Vec<f64> = q0.iter().map(|a| a + [1e-4, 1e-2, 0.3][trial % 3] * rand()).collect();
                    let qd: Vec<f64> = (0..n).map(|_| [0.1, 2.0, 20.0][trial % 3] * rand()).collect();
                    let f = 24e3 * (1.0 + 0.5 * rand());
                    let mut qdd = vec![0.0; n];
                    boom.accelerations(&q, &qd, &mut |_, _| f, &mut qdd);
                    let (m, rhs) = lagrange(&boom, &q, &qd, f);
                    for j in 0..n {
                        let terms: f64 = (0..n).map(|k| (m[(j, k)] * qdd[k]).abs()).sum::<f64>() + rhs[j].abs();
                        let residual = (0..n).map(|k| m[(j, k)] * qdd[k]).sum::<f64>() - rhs[j];
                        worst = worst.max(residual.abs() / terms);
                        assert!(residual.abs() < 1e-13 * terms, "{n2} + {n3}, row {j}: {residual} of {terms}");
                    }
                }
            }
        }
        println!("largest residual / row terms: {worst:.2e}");
    }

    /// [`FlexibleBoom::acceleration_jacobian`] against a second implementation: the
    /// articulated-body sweeps of `accelerations` in dual numbers, seeded with one coordinate,
    /// rate or the cylinder force at a time, on the random states of `equations_of_motion_hold`
    /// (angles spread by up to 0.3 rad, rates up to 20 rad/s), every damping law, several layouts.
    /// The accelerations, the stroke's gradient g and d l_dot / dq come along. Both are exact;
    /// they differ by rounding, which each solve with M~ amplifies by up to its condition number
    /// kappa (4e2 at 0 + 3 sections, 8e4 at 4 + 5, 2.4e6 at 16 + 16): the bound is
    /// 10 eps kappa(M~) of the largest entry of a row (the accelerations: of max |q_ddot|), the
    /// 10 for the few roundings of each entry before the solve. g and H q_dot involve no solve:
    /// 1e-12 m/rad and 1e-10 m/s/rad (entries up to 0.6 and 10) are rounding bounds.
    #[test]
    fn acceleration_jacobian_matches_dual_numbers() {
        use crate::scalar::Dual64;
        let mut rand = uniform(0x9e37_79b9_7f4a_7c15);
        let p = BoomParams::default();
        let mut worst = 0.0f64;
        let laws = [DampingLaw::Thesis, DampingLaw::Structural, DampingLaw::Modal];
        for (n2, n3, damping) in [(4, 5, 0), (4, 5, 1), (4, 5, 2), (0, 3, 0), (1, 2, 2), (8, 8, 0), (16, 16, 2)] {
            let boom = build(&p, &BeamParams { n2, n3, damping: laws[damping], ..BeamParams::default() });
            let n = boom.sections();
            for x in [0.0, 0.45] {
                let q0 = boom.equilibrium(x).unwrap().q;
                for trial in 0..12 {
                    let q: Vec<f64> = q0.iter().map(|a| a + [1e-4, 1e-2, 0.3][trial % 3] * rand()).collect();
                    let qd: Vec<f64> = (0..n).map(|_| [0.1, 2.0, 20.0][trial % 3] * rand()).collect();
                    let f = 24e3 * (1.0 + 0.5 * rand());
                    let a = boom.acceleration_jacobian(&q, &qd, &mut |_, _| f).unwrap();
                    let g = DVector::from_column_slice(&boom.cylinder_gradient(&boom.trig(&q))[..n]);
                    let singular = (boom.mass_matrix(&q) + boom.m_rod * &g * g.transpose()).singular_values();
                    let bound = 10.0 * f64::EPSILON * singular.max() / singular.min();
                    let mut qdd = vec![0.0; n];
                    boom.accelerations(&q, &qd, &mut |_, _| f, &mut qdd);
                    let size = qdd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    let error = qdd.iter().zip(&a.qdd).fold(0.0f64, |m, (e, c)| m.max((e - c).abs()));
                    worst = worst.max(error / size / bound);
                    assert!(error < bound * size, "{n2} + {n3}: q_ddot {error} of {size}");
                    // Column c of the closed form: q (c < n), q_dot (c < 2n), F_cyl.
                    let mut exact = vec![0.0; n * (2 * n + 1)];
                    for c in 0..=2 * n {
                        let seeded = |x: &[f64], k: usize| -> Vec<Dual64> {
                            x.iter().enumerate().map(|(i, &v)| Dual64::new(v, (i == k) as u8 as f64)).collect()
                        };
                        let (q_s, qd_s) = (seeded(&q, c), seeded(&qd, c.wrapping_sub(n)));
                        let force = Dual64::new(f, (c == 2 * n) as u8 as f64);
                        let mut out = vec![Dual64::from(0.0); n];
                        boom.accelerations(&q_s, &qd_s, &mut |_, _| force, &mut out);
                        (0..n).for_each(|j| exact[j * (2 * n + 1) + c] = out[j].eps);
                        if c < n {
                            let (dx, dv) = (boom.stroke(&q_s).eps, boom.stroke_rate(&q_s, &seeded(&qd, n)).eps);
                            assert!((dx - a.gradient[c]).abs() < 1e-12 && (dv - a.rate_gradient[c]).abs() < 1e-10, "g, H q_dot");
                        }
                    }
                    for (row, closed) in exact.chunks_exact(2 * n + 1).zip(a.rows.chunks_exact(2 * n + 1)) {
                        let size = row.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                        let error = row.iter().zip(closed).fold(0.0f64, |m, (e, c)| m.max((e - c).abs()));
                        worst = worst.max(error / size / bound);
                        assert!(error < bound * size, "{n2} + {n3}, {:?}: {error} of {size}", laws[damping]);
                    }
                }
            }
        }
        println!("largest difference / row's largest entry, over 10 eps cond(M~): {worst:.2e}");
    }

    /// The polynomial sin and cos agree with the library's to an ulp on [-0.1, 0.1].
    #[test]
    fn small_angle_sin_cos() {
        for i in -1000..=1000 {
            let d = SMALL_ANGLE * i as f64 / 1000.0;
            let (s, c) = sin_cos_small(d);
            assert!((s - d.sin()).abs() <= f64::EPSILON * d.abs() && (c - d.cos()).abs() <= f64::EPSILON, "{d}");
        }
    }

    /// Cost of one `accelerations` call for the 4 + 5 beam (printed, not asserted):
    /// `cargo test --release --lib accelerations_cost -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn accelerations_cost() {
        let boom = build(&BoomParams::default(), &BeamParams::default());
        let q = boom.equilibrium(0.18).unwrap().q;
        let qd: Vec<f64> = (0..q.len()).map(|i| 0.01 * i as f64).collect();
        let mut out = vec![0.0; q.len()];
        let calls = 1_000_000;
        let start = std::time::Instant::now();
        for i in 0..calls {
            boom.accelerations(std::hint::black_box(&q), &qd, &mut |_, _| 24e3 + i as f64 * 1e-6, &mut out);
            std::hint::black_box(&out);
        }
        println!("accelerations, 4 + 5 sections: {:.0} ns per call", start.elapsed().as_nanos() as f64 / calls as f64);
    }
}
