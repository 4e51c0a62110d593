//! Radau IIA of order 5 (3 stages, A- and L-stable, stiffly accurate), after RADAU5 of
//! E. Hairer and G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer 1996,
//! Sec. IV.8, and their Fortran code `radau5.f` (version of 2002), whose constants are used here.
//!
//! **Method.** Collocation at `c = ((4-√6)/10, (4+√6)/10, 1)`; the stage increments
//! `Z = (z1, z2, z3)`, `z_i = y(t + c_i h) - y(t)`, solve `Z = h (A ⊗ I) F(Z)`. The simplified
//! Newton iteration uses the transformation `T⁻¹ A⁻¹ T = diag(γ, [[α, -β], [β, α]])`, so each
//! iteration solves one real system with `γ/h·I - J` and one complex system with
//! `(α + iβ)/h·I - J`; both are LU-factorised (partial pivoting, `lu.rs`) once per step size,
//! after eliminating the positions of a second-order system and the decoupled states
//! (`iteration.rs`).
//! Convergence is judged by the contraction rate `θ` (stop when `θ/(1-θ)·‖ΔZ‖ ≤ κ`,
//! `κ = max(10ε/rtol, 0.01)` (`KAPPA`); abort and reduce `h` if `θ ≥ 0.99` or the predicted
//! error after 7 iterations is too large). Starting values extrapolate the collocation polynomial
//! of the previous accepted step, also across `integrate` calls when the call continues the
//! last one (see below); zero otherwise.
//!
//! **Error estimate** (Hairer–Wanner Sec. IV.8): with the embedded order-3 formula
//! `err = (γ/h·I - J)⁻¹ (f(t, y) + (e1 z1 + e2 z2 + e3 z3)/h)`, `e = -(13+7√6, 13-7√6, 1)/3`;
//! on the first step and after a rejection, if `‖err‖ ≥ 1` it is refined once by
//! `(γ/h·I - J)⁻¹ (f(t, y + err) + (e·Z)/h)` (filters the stiff components).
//! The norm is `‖e‖ = sqrt(mean((e_i / (atol_i + rtol·|y_i|))²))` with the user's tolerances.
//! This bounds the error of the embedded order-3 solution; the order-5 result is then typically
//! within about one tolerance unit of the exact solution (measured in `examples/solver_bench.rs`).
//! RADAU5's looser mapping `rtol' = 0.1·rtol^(2/3)` was measured to leave 12-60 units on the
//! hydraulic test problem and is not used.
//!
//! **Step size.** `h_new = h / clamp(err^(1/4)/fac, 1/8, 5)`, `fac = min(0.9, 0.9·15/(newt+14))`
//! (newt = Newton iterations); on accepted steps also Gustafsson's predictive controller
//! `h_new ≤ 0.9·h·(h/h_acc)·(err_acc/err²)^(1/4)` (previous accepted step `h_acc`, `err_acc`).
//! After a rejection the step is not increased; a rejected first step of an integration (no
//! continued call, `h` a guess) retries with `h/10`. The Jacobian is reused while the Newton
//! contraction `θ ≤ THET` (0.01); `h` and the LU are kept if `0.99 ≤ h_new/h ≤ 2`. A Newton
//! failure recomputes a Jacobian that is not fresh; an error-test rejection keeps it (the
//! step was too long for the accuracy, not for the iteration; CVODE's policy, where radau5.f
//! recomputes it: measured on the flexible boom's limit cycle, 10.9k -> 2.4k Jacobians at the
//! same number of steps). The LU factors are also reused, with the Jacobian, for any later step
//! whose size equals theirs up to rounding (`|h - h_lu| ≤ 1e-9·h_lu`), e.g. the step cut to land
//! on `t_end` or the first step of the next call when both are one communication step long.
//!
//! **Communication points.** Steps never pass `t_end`; if the wanted step reaches `t_end` it is cut
//! to land exactly, if it covers more than half the rest, the rest is split into two equal steps.
//! Unless the call has a *reach* beyond `t_end` ([`Radau5::integrate_until`]): then steps are
//! planned towards the reach, the first accepted step that passes `t_end` ends the call, and the
//! state at `t_end` comes from that step's collocation polynomial (the continuous output of order
//! 3, Hairer & Wanner IV.8, eq. 8.12, the one the event search uses). A later call with a reach
//! that starts on that polynomial (bit for bit: the state this call returned) continues from the
//! step's end, or, if the step covers its end too, only evaluates the polynomial there; any other
//! call starts from its own state. After [`Radau5::inputs_changed`] the next call has no reach: the
//! step past `t_end` was taken with the old inputs. Each `integrate` call starts with the carried
//! step-size hint and, as between steps, the Jacobian of the previous call unless the last Newton
//! contraction asked for a new one: it is only the iteration matrix, so a stale one (inputs
//! changed) costs iterations, never accuracy, and a Newton failure recomputes it; its LU factors
//! are kept too if the first step has their step size. A call *continues* the previous integration
//! if it starts at the time and (bit for bit) at the state where the last accepted step ended, as
//! an FMU's successive doStep calls do: then its first step is an ordinary step (starting values
//! extrapolated from the last collocation polynomial, a rejection reduces `h` by the controller). A
//! changed input only makes that starting value less accurate, which costs Newton iterations, never
//! accuracy. Hint, contraction, Jacobian, the step size of the LU factors, the last step (size, end
//! time, collocation polynomial, end state, `f` there) and whether the inputs changed are the
//! persistent state ([`Radau5::save_state`]); the LU factors are recomputed from them on loading,
//! so a restored integrator continues bit-identically.

// The tableau constants are kept with all digits as published in radau5.f.
#![allow(clippy::excessive_precision)]

use super::iteration::IterationMatrices;
use super::{FailureCause, OdeSystem, SolveError, SolveErrorKind, SolverStats};
use nalgebra::DMatrix;

/// Unit round-off used in RADAU5's formulas.
const UROUND: f64 = 1e-16;
/// Maximum Newton iterations per step.
const NIT: u32 = 7;
/// Newton iterations of the real-time mode's closing step ([`Radau5::tail_step`]): at most this
/// many, fewer once converged.
pub const NEWTON_BUDGET: u32 = 4;
/// Newton error left (units of the tolerance) above which the closing step of the real-time
/// mode holds the state instead of taking the Radau iterate ([`Radau5::hold`]). Measured: where
/// the compensator reaches its stop within the step (case B, small budgets) the iterates were
/// 1e6-1e9 units off and, taken, left p1 hundreds of bar off for good; in the stick-slip bursts
/// of case U the unconverged iterates stay below, and taking them kept case U with the flexible
/// arm (default budget, 10 s) within 0.5 % of the adaptive stroke, against 1.6 % when they were
/// held above 100 units.
const FALLBACK_LOSS: f64 = 1e5;

/// Most RHS evaluations of the real-time mode's closing step for `n` states
/// ([`Radau5::tail_step`]): a finite-difference Jacobian, the Newton budget, one refinement.
pub fn tail_rhs(n: usize) -> u64 {
    (n + 3 * NEWTON_BUDGET as usize + 1) as u64
}
/// Safety factor of the step-size controller.
const SAFE: f64 = 0.9;
/// Newton stopping tolerance κ, in units of the error tolerance: the lower end of the range
/// 1e-2..1e-1 that Hairer–Wanner (IV.8) recommend. radau5.f's default `min(0.03, √rtol')` with
/// its internal `rtol' = 0.1 rtol^(2/3)` gives 3e-3 at rtol 1e-6, and 1e-3 if applied to the
/// untransformed rtol used here. Measured against rtol 1e-9 references of the flexible boom's
/// U (15 s): pressures within 72 Pa (28 Pa at κ = 1e-3), stroke 5e-8 m (2e-8 m), regression
/// metrics unchanged to 6 digits; B unchanged; the oil column of the solver tests within 1.6
/// tolerance units (0.3); 10-12 % fewer RHS evaluations.
const KAPPA: f64 = 0.01;
/// Reuse the Jacobian while the Newton contraction rate is below this.
const THET: f64 = 0.01;
/// `h_new/h >= 1/FACL`.
const FACL: f64 = 5.0;
/// `h_new/h <= 1/FACR`.
const FACR: f64 = 0.125;
/// Keep `h` (and the LU) when `QUOT1 <= h_new/h <= QUOT2`: radau5.f's advice for "large full
/// systems" (its defaults are 1 and 1.2), where the LU decompositions dominate, as they do for
/// the flexible boom (24 states): 8 % fewer instructions in its limit cycle, neutral for the
/// rigid boom (`boomsim bench` under callgrind).
const QUOT1: f64 = 0.99;
const QUOT2: f64 = 2.0;
/// Consecutive rejections before giving up.
const MAX_REJECTIONS: u32 = 100;
/// First step size when there is no hint.
const H_INITIAL: f64 = 1e-6;
/// The LU factors of step size `h_lu` serve a step `h` with `|h - h_lu| <= H_SAME·h_lu`: the
/// same step up to the rounding of `t_end - t` (a few 1e-12 relative for 1 ms steps at t ~ 10 s).
const H_SAME: f64 = 1e-9;

/// Radau IIA constants: nodes, error-estimate weights, eigenvalues of `A⁻¹` and the
/// transformation `T`, `T⁻¹` (values of `radau5.f`).
const SQ6: f64 = 2.449_489_742_783_178;
const C1: f64 = (4.0 - SQ6) / 10.0;
const C2: f64 = (4.0 + SQ6) / 10.0;
const C1M1: f64 = C1 - 1.0;
const C2M1: f64 = C2 - 1.0;
const C1MC2: f64 = C1 - C2;
const DD1: f64 = -(13.0 + 7.0 * SQ6) / 3.0;
const DD2: f64 = (-13.0 + 7.0 * SQ6) / 3.0;
const DD3: f64 = -1.0 / 3.0;
const T11: f64 = 9.123_239_487_089_294_279_2e-02;
const T12: f64 = -0.141_255_295_020_954_208_43;
const T13: f64 = -3.002_919_410_514_742_449_2e-02;
const T21: f64 = 0.241_717_932_707_107_018_96;
const T22: f64 = 0.204_129_352_293_799_931_99;
const T23: f64 = 0.382_942_112_757_261_937_79;
const T31: f64 = 0.966_048_182_615_092_936_19;
const TI11: f64 = 4.325_579_890_063_155_351_0;
const TI12: f64 = 0.339_199_251_815_809_869_54;
const TI13: f64 = 0.541_770_539_935_874_871_19;
const TI21: f64 = -4.178_718_591_551_904_727_3;
const TI22: f64 = -0.327_682_820_761_062_387_08;
const TI23: f64 = 0.476_623_554_500_550_451_96;
const TI31: f64 = -0.502_872_634_945_786_875_95;
const TI32: f64 = 2.571_926_949_855_605_429_2;
const TI33: f64 = -0.596_039_204_828_224_924_97;

/// Real eigenvalue `γ` and complex pair `α ± iβ` of `A⁻¹` (`u1`, `alph`, `beta` of radau5.f).
fn eigen() -> (f64, f64, f64) {
    let (c81, c9) = (81f64.cbrt(), 9f64.cbrt());
    let u1 = (6.0 + c81 - c9) / 30.0;
    let alph = (12.0 - c81 + c9) / 60.0;
    let beta = (c81 + c9) * 3f64.sqrt() / 60.0;
    let cno = alph * alph + beta * beta;
    (1.0 / u1, alph / cno, beta / cno)
}

/// The Radau IIA (order 5) integrator with its preallocated work space.
///
/// Sized for one system dimension at construction; `integrate` does not allocate.
#[derive(Clone, Debug)]
pub struct Radau5 {
    n: usize,
    rtol: f64,
    /// The rtol for which [`Radau5::set_tolerance`] last scaled atol (NaN: none).
    scaled_for: f64,
    atol: Vec<f64>,
    max_step: f64,
    max_steps: u64,
    h_hint: f64,
    /// Newton contraction rate of the last step; with `jac_valid`, decides Jacobian reuse.
    theta: f64,
    jac_valid: bool,
    /// Step size the LU factors `e1`, `e2` belong to; 0 if they do not match `jac`.
    h_lu: f64,
    /// Size and end time of the last accepted step, whose collocation polynomial is `cont` and
    /// whose end state is `y` (`h_cont = 0`: none).
    h_cont: f64,
    t_cont: f64,
    stats: SolverStats,
    gamma: f64,
    alpha: f64,
    beta: f64,
    /// Newton convergence factor `θ/(1-θ)` carried from step to step (persistent state).
    faccon: f64,
    /// Accuracy-loss indicator of the last [`integrate_bounded`](Self::integrate_bounded) call
    /// (0 when it needed no closing step, and after [`integrate`](Self::integrate)).
    accuracy_loss: f64,
    /// The system's inputs changed since the last call ([`Radau5::inputs_changed`]).
    changed: bool,
    /// Current state, `f(t, y)`, error weights.
    y: Vec<f64>,
    y0: Vec<f64>,
    scal: Vec<f64>,
    /// Stage increments `Z` and transformed increments `W = T⁻¹ Z`.
    z: [Vec<f64>; 3],
    w: [Vec<f64>; 3],
    /// Collocation polynomial of the last accepted step (divided differences).
    cont: [Vec<f64>; 3],
    tmp: Vec<f64>,
    ftmp: Vec<f64>,
    jac: DMatrix<f64>,
    /// LU factors of `γ/h·I - J` and `(α + iβ)/h·I - J`.
    mats: IterationMatrices,
}

/// What the caller of [`Radau5::integrate_until`] does between the integrator's steps; it holds
/// the system.
pub trait Watch {
    type Ode: OdeSystem + ?Sized;

    /// The system integrated.
    fn ode(&self) -> &Self::Ode;

    /// Before each attempted step from `t` (again after a rejection, with a smaller one), with
    /// the times at which its Newton iteration evaluates the system ([`stage_times`]; the last is
    /// the step's end): may change the system's inputs over the step, keeping their values at `t`.
    fn attempt(&mut self, _t: f64, _stages: [f64; 3]) {}

    /// After each accepted step, shown as its collocation polynomial: a time within the step to
    /// end the integration there, or `None` to go on.
    fn accepted(&mut self, _dense: &Dense<'_>) -> Option<f64> {
        None
    }
}

/// A system integrated without a watch.
struct Plain<'a, S: ?Sized>(&'a S);

impl<S: OdeSystem + ?Sized> Watch for Plain<'_, S> {
    type Ode = S;
    fn ode(&self) -> &S {
        self.0
    }
}

/// The solution over the last accepted step `[t - h, t]`: its collocation polynomial, of degree
/// 3 through the step's start, its two inner stages and its end (radau5.f's CONTR5).
pub struct Dense<'a> {
    t: f64,
    h: f64,
    y: &'a [f64],
    cont: &'a [Vec<f64>; 3],
}

impl Dense<'_> {
    /// The step's start and end times.
    pub fn span(&self) -> (f64, f64) {
        (self.t - self.h, self.t)
    }

    /// The state at the step's end.
    pub fn end(&self) -> &[f64] {
        self.y
    }

    /// The state at `t` (within the step; beyond it, the polynomial extrapolated) into `x`.
    pub fn at(&self, t: f64, x: &mut [f64]) {
        let s = (t - self.t) / self.h;
        let [c0, c1, c2] = self.cont;
        for (i, x) in x.iter_mut().enumerate() {
            *x = self.y[i] + s * (c0[i] + (s - C2M1) * (c1[i] + (s - C1M1) * c2[i]));
        }
    }
}

/// Outcome of the Newton iteration that forces a smaller step.
struct NewtonFail {
    cause: FailureCause,
    /// Factor for the step size.
    hfac: f64,
}

impl Radau5 {
    /// An integrator for systems of dimension `n` with `rtol = 1e-6`, `atol_i = 1e-6`, no step
    /// limit and at most 100 000 steps per `integrate` call.
    pub fn new(n: usize) -> Self {
        let (gamma, alpha, beta) = eigen();
        let v = || vec![0.0; n];
        let mut s = Self {
            n,
            rtol: 0.0,
            scaled_for: f64::NAN,
            atol: vec![1e-6; n],
            max_step: f64::INFINITY,
            max_steps: 100_000,
            h_hint: 0.0,
            theta: THET,
            jac_valid: false,
            h_lu: 0.0,
            h_cont: 0.0,
            t_cont: 0.0,
            stats: SolverStats::default(),
            gamma,
            alpha,
            beta,
            faccon: 1.0,
            accuracy_loss: 0.0,
            changed: false,
            y: v(),
            y0: v(),
            scal: v(),
            z: [v(), v(), v()],
            w: [v(), v(), v()],
            cont: [v(), v(), v()],
            tmp: v(),
            ftmp: v(),
            jac: DMatrix::zeros(n, n),
            mats: IterationMatrices::new(n),
        };
        s.set_rtol(1e-6).expect("default tolerance is valid");
        s
    }

    /// System dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Sets the relative tolerance (`1e-14 < rtol < 1`).
    pub fn set_rtol(&mut self, rtol: f64) -> Result<(), SolveError> {
        if !(rtol > 1e-14 && rtol < 1.0) {
            return Err(invalid(format!("rtol = {rtol} outside (1e-14, 1)")));
        }
        self.rtol = rtol;
        self.scaled_for = f64::NAN;
        Ok(())
    }

    /// Sets `rtol` and `atol_i = rtol * scale_i` (`scale`: each state's typical magnitude), unless
    /// they are already set for this `rtol`: called every communication step, it costs nothing
    /// while the tolerance stays the same.
    pub fn set_tolerance(&mut self, rtol: f64, scale: impl FnOnce() -> Vec<f64>) -> Result<(), SolveError> {
        if rtol == self.scaled_for {
            return Ok(());
        }
        self.set_rtol(rtol)?;
        let atol: Vec<f64> = scale().iter().map(|s| s * rtol).collect();
        self.set_atol(&atol)?;
        self.scaled_for = rtol;
        Ok(())
    }

    /// Sets the absolute tolerances, one per state (positive, finite).
    pub fn set_atol(&mut self, atol: &[f64]) -> Result<(), SolveError> {
        if atol.len() != self.n {
            return Err(invalid(format!("atol has {} entries, expected {}", atol.len(), self.n)));
        }
        if let Some(a) = atol.iter().find(|a| !(**a > 0.0 && a.is_finite())) {
            return Err(invalid(format!("atol entry {a} is not positive and finite")));
        }
        self.atol.copy_from_slice(atol);
        self.scaled_for = f64::NAN;
        Ok(())
    }

    /// Relative tolerance.
    pub fn rtol(&self) -> f64 {
        self.rtol
    }

    /// Absolute tolerances.
    pub fn atol(&self) -> &[f64] {
        &self.atol
    }

    /// Limits the step size (default: unlimited). Use it when the model has features shorter
    /// than the integrator could see, e.g. pulses in an input.
    pub fn set_max_step(&mut self, h_max: f64) -> Result<(), SolveError> {
        if h_max.is_nan() || h_max <= 0.0 {
            return Err(invalid(format!("max step {h_max} is not positive")));
        }
        self.max_step = h_max;
        Ok(())
    }

    /// Limits the number of step attempts in one `integrate` call (default 100 000).
    pub fn set_max_steps(&mut self, max_steps: u64) {
        self.max_steps = max_steps;
    }

    /// Work counters.
    pub fn stats(&self) -> &SolverStats {
        &self.stats
    }

    /// Zeroes the work counters.
    pub fn reset_stats(&mut self) {
        self.stats = SolverStats::default();
    }

    /// Forgets the step-size hint, the Jacobian and its LU factors, e.g. after a discontinuity
    /// in the model.
    pub fn reset(&mut self) {
        self.h_hint = 0.0;
        self.jac_valid = false;
        self.h_lu = 0.0;
        self.h_cont = 0.0;
        self.faccon = 1.0;
    }

    /// The system's inputs changed where the last call ended: the next call neither continues a
    /// step that passed that point nor passes its own end (the inputs may change again).
    pub fn inputs_changed(&mut self) {
        self.changed = true;
    }

    /// Number of `f64` that [`save_state`](Self::save_state) writes for dimension `n`.
    pub fn saved_len(n: usize) -> usize {
        SAVED_HEAD + n * n + 5 * n
    }

    /// Number of `f64` in [`save_state`](Self::save_state): `17 + n² + 5n`.
    pub fn state_len(&self) -> usize {
        Self::saved_len(self.n)
    }

    /// The persistent state carried between calls: step-size hint (0 = none), last Newton
    /// contraction, Jacobian validity (0/1), the step size of the LU factors (0 = none), size
    /// and end time of the last accepted step (size 0 = none), the Newton convergence factor
    /// carried between steps (`θ/(1-θ)` of the last iteration), the number of solves the LU
    /// factors have served (`iteration.rs`: when they are inverted), the accuracy-loss indicator
    /// of the last call, the seven work counters of [`SolverStats`] (exact as f64 below 2^53),
    /// whether the inputs changed (0/1), the Jacobian (column-major), the collocation
    /// polynomial of the last step (3n), its end state (n) and `f` there (n). The LU factors are
    /// not saved: they are a deterministic function of the Jacobian and their step size, and
    /// [`load_state`](Self::load_state) recomputes them bit-identically.
    pub fn save_state(&self) -> Vec<f64> {
        let mut s = vec![
            self.h_hint,
            self.theta,
            self.jac_valid as u8 as f64,
            self.h_lu,
            self.h_cont,
            self.t_cont,
            self.faccon,
            self.mats.uses() as f64,
            self.accuracy_loss,
        ];
        s.extend(stats_array(&self.stats).map(|c| c as f64));
        s.push(self.changed as u8 as f64);
        s.extend_from_slice(self.jac.as_slice());
        for v in self.cont.iter().chain([&self.y, &self.y0]) {
            s.extend_from_slice(v);
        }
        s
    }

    /// Restores a state from [`save_state`](Self::save_state), refactorising the iteration
    /// matrices if the saved state had LU factors.
    pub fn load_state(&mut self, s: &[f64]) -> Result<(), SolveError> {
        if s.len() != self.state_len() || s.iter().any(|v| !v.is_finite()) {
            return Err(invalid(format!("expected {} finite numbers, got {}", self.state_len(), s.len())));
        }
        let jac_valid = s[2] == 1.0;
        let ok = s[0] >= 0.0 && s[1] >= 0.0 && (s[2] == 0.0 || jac_valid) && s[3] >= 0.0 && s[4] >= 0.0;
        let count = |x: f64, max: f64| (0.0..=max).contains(&x) && x.fract() == 0.0;
        let uses_ok = count(s[7], u32::MAX as f64);
        let counters = &s[9..SAVED_HEAD - 1];
        if !counters.iter().all(|&c| count(c, (1u64 << 53) as f64)) {
            return Err(invalid(format!("work counters {counters:?} are not counts")));
        }
        let changed = s[SAVED_HEAD - 1];
        if !(ok && (jac_valid || s[3] == 0.0) && s[6] >= 0.0 && uses_ok && s[8] >= 0.0 && count(changed, 1.0)) {
            return Err(invalid(format!(
                "step-size hint {}, contraction {}, flag {}, LU step size {}, last step {}, convergence factor {}, \
                 LU uses {}, accuracy loss {}, inputs changed {changed} are invalid",
                s[0], s[1], s[2], s[3], s[4], s[6], s[7], s[8]
            )));
        }
        let n = self.n;
        self.h_hint = s[0];
        self.theta = s[1];
        self.jac_valid = jac_valid;
        (self.h_cont, self.t_cont, self.faccon, self.accuracy_loss) = (s[4], s[5], s[6], s[8]);
        self.changed = changed == 1.0;
        let (jac, rest) = s[SAVED_HEAD..].split_at(n * n);
        self.jac.as_mut_slice().copy_from_slice(jac);
        for (v, saved) in self.cont.iter_mut().chain([&mut self.y, &mut self.y0]).zip(rest.chunks_exact(n)) {
            v.copy_from_slice(saved);
        }
        self.h_lu = 0.0;
        if s[3] > 0.0 {
            if !self.decompose(s[3]) {
                self.jac_valid = false;
                return Err(invalid(format!("the saved Jacobian is singular at step size {}", s[3])));
            }
            self.mats.set_uses(s[7] as u32);
        }
        // After the refactorisation, which is no work of the restored integration.
        let c = counters;
        self.stats = SolverStats {
            accepted_steps: c[0] as u64,
            rejected_steps: c[1] as u64,
            rhs_evals: c[2] as u64,
            jacobian_evals: c[3] as u64,
            lu_decompositions: c[4] as u64,
            newton_iterations: c[5] as u64,
            inaccurate_steps: c[6] as u64,
        };
        Ok(())
    }

    /// Advances `x` from `t0` to exactly `t_end`.
    ///
    /// On error, `x` holds the last accepted state, at time [`SolveError::t`]; the step-size
    /// hint is kept, so a retry (e.g. after the master restores an earlier FMU state) starts
    /// with a sensible step.
    pub fn integrate<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t0: f64,
        x: &mut [f64],
        t_end: f64,
    ) -> Result<(), SolveError> {
        self.integrate_until(&mut Plain(sys), (t0, t_end), x, None, None).map(|_| ())
    }

    /// The real-time mode: [`integrate`](Self::integrate) with at most `rhs_budget` RHS
    /// evaluations (Jacobian columns included), never rejected for accuracy. It steps
    /// adaptively, with error control, as long as the budget leaves room for one more worst-case
    /// attempt (a Jacobian, [`NIT`] Newton iterations, the refined error estimate, `f` at the new
    /// state: `n + 3·NIT + 2`) and for the closing step; then one closing step of bounded work
    /// reaches `t_end` ([`tail_step`](Self::tail_step), [`tail_rhs`]) and its accuracy loss is
    /// reported ([`accuracy_loss`](Self::accuracy_loss), [`SolverStats::inaccurate_steps`])
    /// instead of a rejection. A budget below `1 + n + 3·NIT + 2 + tail_rhs(n)` goes straight
    /// to the closing step. Fails only where no step size would help (non-finite values, a
    /// singular matrix) or as [`integrate`](Self::integrate) fails.
    pub fn integrate_bounded<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t0: f64,
        x: &mut [f64],
        t_end: f64,
        rhs_budget: u64,
    ) -> Result<(), SolveError> {
        self.integrate_until(&mut Plain(sys), (t0, t_end), x, Some(rhs_budget), None).map(|_| ())
    }

    /// [`integrate`](Self::integrate), or [`integrate_bounded`](Self::integrate_bounded) with
    /// a budget, of the system `watch` holds, which it lets change the system's inputs before
    /// each attempted step ([`Watch::attempt`]) and shows each accepted step as its collocation
    /// polynomial ([`Watch::accepted`], [`Dense`]): that may return a time within the step to end
    /// the integration there (the state there from the polynomial: continuous output of order 3,
    /// Hairer & Wanner IV.8, eq. 8.12). Returns the time reached: `t_end`, or where the watch
    /// ended it. A call that starts where one ended inside a step restarts the integration (its
    /// first step extrapolates nothing), as after any change of the state, unless it has a
    /// `reach`: a time at or after `t_end` up to which its steps may go (see the module's
    /// "Communication points"; for a watch that neither changes inputs nor ends steps).
    pub fn integrate_until<W: Watch + ?Sized>(
        &mut self,
        watch: &mut W,
        (t0, t_end): (f64, f64),
        x: &mut [f64],
        budget: Option<u64>,
        reach: Option<f64>,
    ) -> Result<f64, SolveError> {
        if budget.is_some() {
            self.accuracy_loss = 0.0;
        }
        let (n, rhs0) = (self.n as u64, self.stats.rhs_evals);
        // With a reach, steps are planned towards it and the call returns at the first step
        // that passes t_end, with the polynomial's state there.
        let changed = std::mem::take(&mut self.changed);
        let reach = reach.filter(|_| !changed);
        let (t_out, t_end) = (t_end, reach.map_or(t_end, |r| r.max(t_end)));
        let Some((mut t, continues)) = self.begin(watch.ode(), t0, x, t_out, reach.is_some())? else {
            return Ok(t_out);
        };

        let fnewt = (10.0 * UROUND / self.rtol).max(KAPPA);
        let h_min = 10.0 * f64::EPSILON * t0.abs().max(t_out.abs());
        let cfac = SAFE * (1 + 2 * NIT) as f64;

        let mut h_nat = if self.h_hint > 0.0 { self.h_hint } else { H_INITIAL }.min(self.max_step);
        let (mut h, mut last) = plan(t, t_end, h_nat);
        let (mut first, mut reject) = (true, false);
        let mut need_jac = !self.jac_valid || self.theta > THET;
        let (mut need_lu, mut caljac) = (need_jac || !self.lu_matches(h), false);
        let (mut theta, mut hold) = (self.theta, if continues { self.h_cont } else { h });
        // Extrapolating the last collocation polynomial over more than the largest step growth
        // within an integration (1/FACR) is no prediction: after a tiny step (1e-100 s) it would
        // be by 1e94. Start the Newton iteration from zero then.
        let mut zero_start = !continues || h > hold / FACR;
        let (mut hacc, mut erracc, mut n_acc) = (0.0, 0.0, 0u64);
        let (mut n_rej_row, mut n_attempts) = (0u32, 0u64);
        let mut fail: Option<FailureCause> = None;

        loop {
            // A failure from the previous attempt: shrink h (already done) and check limits.
            if let Some(cause) = fail.take() {
                self.stats.rejected_steps += 1;
                n_rej_row += 1;
                reject = true;
                (h, last) = plan(t, t_end, h);
                h_nat = h;
                need_lu = true;
                need_jac |= !caljac && cause != FailureCause::ErrorTest;
                let kind = if h < h_min {
                    Some(SolveErrorKind::StepSizeTooSmall(cause))
                } else if n_rej_row > MAX_REJECTIONS {
                    Some(SolveErrorKind::TooManyRejections(cause))
                } else {
                    None
                };
                if let Some(kind) = kind {
                    x.copy_from_slice(&self.y);
                    return Err(SolveError { kind, t, h });
                }
            }
            if let Some(budget) = budget {
                let attempt = if need_jac { n } else { 0 } + 3 * NIT as u64 + 2;
                if self.stats.rhs_evals - rhs0 + attempt + tail_rhs(self.n) > budget {
                    watch.attempt(t, stage_times(t, t_end - t, t_end));
                    let tail = self.tail_step(watch.ode(), t, t_end, (hold, zero_start));
                    x.copy_from_slice(&self.y);
                    self.accuracy_loss = tail?;
                    self.h_hint = h_nat.min(self.max_step);
                    return Ok(self.stop_at(watch.accepted(&self.dense()), x));
                }
            }
            n_attempts += 1;
            if n_attempts > self.max_steps {
                x.copy_from_slice(&self.y);
                return Err(SolveError { kind: SolveErrorKind::TooManySteps(self.max_steps), t, h });
            }
            if need_jac {
                if !self.compute_jacobian(watch.ode(), t) {
                    x.copy_from_slice(&self.y);
                    return Err(SolveError { kind: SolveErrorKind::NonFiniteJacobian, t, h });
                }
                caljac = true;
                need_jac = false;
                need_lu = true;
            }
            if need_lu {
                if !self.decompose(h) {
                    h *= 0.5;
                    fail = Some(FailureCause::SingularMatrix);
                    continue;
                }
                need_lu = false;
            }
            let tph = if last { t_end } else { t + h };
            watch.attempt(t, stage_times(t, h, tph));

            // Starting values for Z and W = T⁻¹ Z.
            if zero_start {
                for k in 0..3 {
                    self.z[k].fill(0.0);
                    self.w[k].fill(0.0);
                }
            } else {
                self.extrapolate(h / hold);
            }

            let newt = match self.newton(watch.ode(), t, h, tph, fnewt, &mut theta, None) {
                Ok((newt, _)) => newt,
                Err(NewtonFail { cause, hfac }) => {
                    h *= hfac;
                    last = false;
                    fail = Some(cause);
                    continue;
                }
            };

            let err = self.error_estimate(watch.ode(), t, h, first || reject);
            let fac = SAFE.min(cfac / (newt + 2 * NIT) as f64);
            let mut quot = FACR.max(FACL.min(err.powf(0.25) / fac));
            let mut hnew = h / quot;
            if err >= 1.0 {
                h = if first && !continues { 0.1 * h } else { hnew };
                last = false;
                fail = Some(FailureCause::ErrorTest);
                continue;
            }
            // Candidate new state and f there, which starts the next step; a non-finite f
            // rejects the step. The last step of a call skips it: the next call evaluates f
            // there itself (with its own inputs), and the Newton iteration's last evaluation
            // of the final stage lies within its tolerance of this state. A step past the
            // call's end does not: the next call may continue it.
            self.stage_end();
            if !last || tph > t_out {
                watch.ode().rhs(tph, &self.tmp, &mut self.ftmp);
                self.stats.rhs_evals += 1;
                if !all_finite(&self.ftmp) {
                    h *= 0.5;
                    fail = Some(FailureCause::NonFiniteRhs);
                    continue;
                }
            }

            // Accepted.
            self.stats.accepted_steps += 1;
            n_acc += 1;
            n_rej_row = 0;
            first = false;
            zero_start = false;
            if n_acc > 1 {
                let facgus = (hacc / h) * (err * err / erracc).powf(0.25) / SAFE;
                quot = quot.max(FACR.max(FACL.min(facgus)));
                hnew = h / quot;
            }
            hacc = h;
            erracc = err.max(1e-2);
            hold = h;
            t = tph;
            if !last || tph > t_out {
                self.y0.copy_from_slice(&self.ftmp);
            }
            self.accept(h, t);

            let stopped = watch.accepted(&self.dense());
            if last || stopped.is_some() || t >= t_out {
                // Carry the step the controller wanted, not the one cut to land on t_end.
                let hint = if hnew < h { hnew } else { hnew.max(h_nat) };
                self.h_hint = hint.min(self.max_step);
                self.theta = theta;
                x.copy_from_slice(&self.y);
                return Ok(self.stop_at(stopped.or((t > t_out).then_some(t_out)), x));
            }
            hnew = hnew.min(self.max_step);
            if reject {
                hnew = hnew.min(h);
            }
            reject = false;
            caljac = false;
            let (hn, lastn) = plan(t, t_end, hnew);
            h_nat = hnew;
            let qt = hn / h;
            if !lastn && theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                continue;
            }
            h = hn;
            last = lastn;
            need_jac = theta > THET;
            need_lu = need_jac || !self.lu_matches(h);
        }
    }

    /// The step of the real-time mode that ends a bounded call ([`integrate_bounded`]) when
    /// its budget allows no further adaptive attempt: one Radau IIA step from `t` (the last
    /// accepted state, `f` there in `y0`) to `t_end`, never rejected, with a Jacobian fresh at
    /// `t`, at most [`NEWTON_BUDGET`] Newton iterations and the embedded error estimate, refined
    /// once above the tolerance: at most `n + 3·NEWTON_BUDGET + 1` RHS evaluations
    /// ([`tail_rhs`]). If the Newton iteration leaves more than [`FALLBACK_LOSS`] tolerance
    /// units, the state is held instead ([`hold`]). Returns the accuracy-loss indicator: the
    /// larger of the error estimate and the Newton error left, or what the hold omits, in units
    /// of the tolerance.
    ///
    /// [`integrate_bounded`]: Self::integrate_bounded
    /// [`hold`]: Self::hold
    fn tail_step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        t_end: f64,
        (hold, zero_start): (f64, bool),
    ) -> Result<f64, SolveError> {
        let h = t_end - t;
        let failed = |cause| Err(SolveError { kind: SolveErrorKind::FixedStepFailed(cause), t, h });
        if !self.compute_jacobian(sys, t) {
            return Err(SolveError { kind: SolveErrorKind::NonFiniteJacobian, t, h });
        }
        if !self.decompose(h) {
            return failed(FailureCause::SingularMatrix);
        }
        if zero_start || h > hold / FACR {
            for k in 0..3 {
                self.z[k].fill(0.0);
                self.w[k].fill(0.0);
            }
        } else {
            self.extrapolate(h / hold);
        }
        let fnewt = (10.0 * UROUND / self.rtol).max(KAPPA);
        let mut theta = THET;
        let left = match self.newton(sys, t, h, t_end, fnewt, &mut theta, Some(NEWTON_BUDGET)) {
            Ok((_, left)) => left,
            Err(NewtonFail { cause, .. }) => return failed(cause),
        };
        let loss = if left > FALLBACK_LOSS {
            self.hold(h)
        } else {
            let err = self.error_estimate(sys, t, h, true);
            if !err.is_finite() {
                return failed(FailureCause::ErrorTest);
            }
            err.max(left)
        };
        self.stage_end();
        if !all_finite(&self.tmp) {
            return failed(FailureCause::NonFiniteRhs);
        }
        self.stats.accepted_steps += 1;
        self.stats.inaccurate_steps += (loss > 1.0) as u64;
        self.accept(h, t_end);
        self.theta = theta;
        Ok(loss)
    }

    /// The step's end state `y + Z_3` into `tmp`.
    fn stage_end(&mut self) {
        for ((x, &y), &z) in self.tmp.iter_mut().zip(&self.y).zip(&self.z[2]) {
            *x = y + z;
        }
    }

    /// Takes the step of size `h` that ended at `t` with state `tmp`: the new state, its error
    /// weights and the collocation polynomial the next step extrapolates.
    fn accept(&mut self, h: f64, t: f64) {
        self.y.copy_from_slice(&self.tmp);
        self.update_scal();
        self.update_cont();
        (self.h_cont, self.t_cont) = (h, t);
    }

    /// The closing step's fallback when its Newton iteration fails: the state is held (`Z = 0`)
    /// over the `h` left of the communication step, and the next call continues from it with
    /// its full budget. A Newton iterate that has not converged may be far off (at a switch of
    /// the right-hand side within the step, e.g. the compensator reaching its stop, it was
    /// measured hundreds of bar off, and the integration never recovered); a held state lags by
    /// at most `h`. Returns the state change the hold omits, `h·‖f(t, y)‖` in units of the
    /// tolerance, as its accuracy loss.
    fn hold(&mut self, h: f64) -> f64 {
        for z in &mut self.z {
            z.fill(0.0);
        }
        let omitted: f64 = self.y0.iter().zip(&self.scal).map(|(f, s)| (h * f / s).powi(2)).sum();
        (omitted / self.n as f64).sqrt()
    }

    /// The collocation polynomial of the last accepted step.
    fn dense(&self) -> Dense<'_> {
        Dense { t: self.t_cont, h: self.h_cont, y: &self.y, cont: &self.cont }
    }

    /// Where an integration that reached the last accepted step's end (its state in `x`) ends:
    /// there, or at the time `stop` chose within the step, with the polynomial's state in `x`.
    fn stop_at(&self, stop: Option<f64>, x: &mut [f64]) -> f64 {
        match stop {
            Some(t) if t < self.t_cont => {
                self.dense().at(t, x);
                t
            }
            _ => self.t_cont,
        }
    }

    /// Accuracy-loss indicator of the last [`integrate_bounded`](Self::integrate_bounded) call,
    /// in units of the tolerance: 0 if all its steps passed the error test (and after
    /// [`integrate`](Self::integrate)), else that of its closing step.
    pub fn accuracy_loss(&self) -> f64 {
        self.accuracy_loss
    }

    /// The start of an integration from `t0` to `t_end`: checks the arguments, refactorises
    /// for the system's structure, takes `x` and `f(t0, x)`. Returns whether the call continues
    /// the last integration, `None` if there is nothing to integrate (`t_end = t0`).
    fn begin<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t0: f64,
        x: &mut [f64],
        t_end: f64,
        ahead: bool,
    ) -> Result<Option<(f64, bool)>, SolveError> {
        let n = self.n;
        if sys.dim() != n || x.len() != n {
            return Err(invalid_at(t0, format!("system dimension {} / state length {} != {n}", sys.dim(), x.len())));
        }
        if !(t0.is_finite() && t_end.is_finite() && t_end >= t0) {
            return Err(invalid_at(t0, format!("time interval [{t0}, {t_end}] is not valid")));
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(invalid_at(t0, "initial state is not finite".into()));
        }
        if t_end == t0 {
            return Ok(None);
        }
        let structure = sys.second_order();
        if structure != self.mats.structure() {
            if let Some(s) = structure.filter(|s| !s.fits(n)) {
                return Err(invalid_at(t0, format!("second-order structure {s:?} does not fit {n} states")));
            }
            // Refactorise for the structure (first call after construction or loading), as
            // many solves into the factors' life as before.
            let uses = self.mats.uses();
            self.mats.set_structure(structure);
            if self.h_lu > 0.0 {
                if self.decompose(self.h_lu) {
                    self.mats.set_uses(uses);
                } else {
                    self.h_lu = 0.0;
                }
            }
        }
        // A call that may continue a step that passed its start, and starts on that step's
        // polynomial (bit for bit), continues from the step's end; if that is at or past
        // t_end too, the polynomial gives the state there.
        if ahead && self.h_cont > 0.0 && self.t_cont > t0 && t0 >= self.t_cont - self.h_cont {
            Dense { t: self.t_cont, h: self.h_cont, y: &self.y, cont: &self.cont }.at(t0, &mut self.tmp);
            if bit_equal(x, &self.tmp) {
                if t_end <= self.t_cont {
                    self.dense().at(t_end, x);
                    return Ok(None);
                }
                // The error weights at the step's end (not saved in a state: loaded, they are 0).
                self.update_scal();
                return Ok(Some((self.t_cont, true)));
            }
        }
        // A call that starts where the last accepted step ended continues that integration: its
        // first step extrapolates the last collocation polynomial like any other step.
        let continues = self.h_cont > 0.0 && t0 == self.t_cont && bit_equal(x, &self.y);
        if !continues {
            self.h_cont = 0.0;
        }
        self.y.copy_from_slice(x);
        sys.rhs(t0, &self.y, &mut self.y0);
        self.stats.rhs_evals += 1;
        if !all_finite(&self.y0) {
            return Err(SolveError { kind: SolveErrorKind::NonFiniteInitialRhs, t: t0, h: 0.0 });
        }
        self.update_scal();
        Ok(Some((t0, continues)))
    }

    fn update_scal(&mut self) {
        for ((s, &a), &y) in self.scal.iter_mut().zip(&self.atol).zip(&self.y) {
            *s = a + self.rtol * y.abs();
        }
    }

    /// Analytic Jacobian if the system has one, else forward differences with
    /// `δ_j = sqrt(ε·max(1e-5, |y_j|))` (radau5.f). Returns `false` if not finite.
    fn compute_jacobian<S: OdeSystem + ?Sized>(&mut self, sys: &S, t: f64) -> bool {
        self.stats.jacobian_evals += 1;
        self.h_lu = 0.0;
        if !sys.jacobian(t, &self.y, &mut self.jac) {
            self.tmp.copy_from_slice(&self.y);
            for (j, col) in self.jac.as_mut_slice().chunks_exact_mut(self.n).enumerate() {
                let delta = (UROUND * self.y[j].abs().max(1e-5)).sqrt();
                self.tmp[j] = self.y[j] + delta;
                sys.rhs(t, &self.tmp, &mut self.ftmp);
                self.tmp[j] = self.y[j];
                for ((c, &f), &f0) in col.iter_mut().zip(&self.ftmp).zip(&self.y0) {
                    *c = (f - f0) / delta;
                }
            }
            self.stats.rhs_evals += self.n as u64;
        }
        self.jac_valid = self.jac.iter().all(|v| v.is_finite());
        self.jac_valid
    }

    /// Whether the LU factors serve a step of size `h` (see [`H_SAME`]).
    fn lu_matches(&self, h: f64) -> bool {
        self.h_lu > 0.0 && (h - self.h_lu).abs() <= H_SAME * self.h_lu
    }

    /// Factorises `E1 = γ/h·I - J` and `E2 = (α + iβ)/h·I - J`; on success the factors belong to
    /// step size `h`.
    fn decompose(&mut self, h: f64) -> bool {
        self.stats.lu_decompositions += 1;
        let ok = self.mats.factor(&self.jac, self.gamma / h, self.alpha / h, self.beta / h);
        self.h_lu = if ok { h } else { 0.0 };
        ok
    }

    /// Starting values from the collocation polynomial of the last step; `r = h/h_old`.
    fn extrapolate(&mut self, r: f64) {
        let n = self.n;
        let cq = [C1 * r, C2 * r, r];
        let [c0, c1, c2] = &self.cont;
        let [z0, z1, z2] = &mut self.z;
        let [w0, w1, w2] = &mut self.w;
        let (c0, c1, c2) = (&c0[..n], &c1[..n], &c2[..n]);
        let (z0, z1, z2) = (&mut z0[..n], &mut z1[..n], &mut z2[..n]);
        let (w0, w1, w2) = (&mut w0[..n], &mut w1[..n], &mut w2[..n]);
        for i in 0..n {
            let (a1, a2, a3) = (c0[i], c1[i], c2[i]);
            let zi = cq.map(|c| c * (a1 + (c - C2M1) * (a2 + (c - C1M1) * a3)));
            (z0[i], z1[i], z2[i]) = (zi[0], zi[1], zi[2]);
            w0[i] = TI11 * zi[0] + TI12 * zi[1] + TI13 * zi[2];
            w1[i] = TI21 * zi[0] + TI22 * zi[1] + TI23 * zi[2];
            w2[i] = TI31 * zi[0] + TI32 * zi[1] + TI33 * zi[2];
        }
    }

    /// Divided differences of the collocation polynomial through `y_new - y_old` at `c_i - 1`,
    /// from the increments `Z` of the accepted step.
    fn update_cont(&mut self) {
        let n = self.n;
        let [z0, z1, z2] = &self.z;
        let [c0, c1, c2] = &mut self.cont;
        let (z0, z1, z2) = (&z0[..n], &z1[..n], &z2[..n]);
        let (c0, c1, c2) = (&mut c0[..n], &mut c1[..n], &mut c2[..n]);
        for i in 0..n {
            let (z1, z2, z3) = (z0[i], z1[i], z2[i]);
            let d1 = (z2 - z3) / C2M1;
            let ak = (z1 - z2) / C1MC2;
            let acont3 = (ak - z1 / C1) / C2;
            let d2 = (ak - d1) / C1M1;
            c0[i] = d1;
            c1[i] = d2;
            c2[i] = d2 - acont3;
        }
    }

    /// Simplified Newton iteration for `Z`; returns the number of iterations and the estimated
    /// error left in `Z`, in units of the tolerance.
    ///
    /// With a `budget` (the real-time mode) it stops after that many iterations and never fails
    /// for slow convergence: it returns the iterate it has, with `θ/(1-θ)·‖ΔZ‖` of the last
    /// iteration as the error left, and, if the iteration diverges (`θ ≥ 0.99`), the iterate
    /// before the diverging correction, with that correction's norm.
    #[allow(clippy::too_many_arguments)]
    fn newton<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        h: f64,
        tph: f64,
        fnewt: f64,
        theta: &mut f64,
        budget: Option<u32>,
    ) -> Result<(u32, f64), NewtonFail> {
        let n = self.n;
        let (fac1, alphn, betan) = (self.gamma / h, self.alpha / h, self.beta / h);
        let diverged = NewtonFail { cause: FailureCause::NewtonFailure, hfac: 0.5 };
        self.faccon = self.faccon.max(UROUND).powf(0.8);
        *theta = THET;
        let (mut dynold, mut thqold) = (0.0, 0.0);
        let mut newt = 0;
        loop {
            if let Some(b) = budget.filter(|&b| newt >= b) {
                return Ok((b, self.faccon * dynold));
            }
            if newt >= NIT {
                return Err(diverged);
            }
            let times = stage_times(t, h, tph);
            for (zk, &tk) in self.z.iter_mut().zip(&times) {
                for ((x, &y), &z) in self.tmp.iter_mut().zip(&self.y).zip(zk.iter()) {
                    *x = y + z;
                }
                sys.rhs(tk, &self.tmp, zk);
            }
            self.stats.rhs_evals += 3;
            if !self.z.iter().all(|zk| all_finite(zk)) {
                return Err(NewtonFail { cause: FailureCause::NonFiniteRhs, hfac: 0.5 });
            }
            // Right-hand sides of the transformed systems, then solve.
            {
                let [z0, z1, z2] = &mut self.z;
                let [w0, w1, w2] = &self.w;
                let (z0, z1, z2) = (&mut z0[..n], &mut z1[..n], &mut z2[..n]);
                let (w0, w1, w2) = (&w0[..n], &w1[..n], &w2[..n]);
                for i in 0..n {
                    let (a1, a2, a3) = (z0[i], z1[i], z2[i]);
                    let (w1, w2, w3) = (w0[i], w1[i], w2[i]);
                    z0[i] = TI11 * a1 + TI12 * a2 + TI13 * a3 - w1 * fac1;
                    let r2 = TI21 * a1 + TI22 * a2 + TI23 * a3 - w2 * alphn + w3 * betan;
                    let r3 = TI31 * a1 + TI32 * a2 + TI33 * a3 - w3 * alphn - w2 * betan;
                    z1[i] = r2;
                    z2[i] = r3;
                }
            }
            let [z0, z1, z2] = &mut self.z;
            self.mats.solve_real(z0);
            self.mats.solve_complex(z1, z2);
            let mut dyno = 0.0;
            {
                let [z0, z1, z2] = &self.z;
                let (z0, z1, z2, scal) = (&z0[..n], &z1[..n], &z2[..n], &self.scal[..n]);
                for i in 0..n {
                    let s = scal[i];
                    dyno += (z0[i] / s).powi(2) + (z1[i] / s).powi(2) + (z2[i] / s).powi(2);
                }
            }
            self.stats.newton_iterations += 1;
            newt += 1;
            let dyno = (dyno / (3 * n) as f64).sqrt();
            if newt > 1 && (newt < NIT || budget.is_some()) {
                let thq = dyno / dynold;
                *theta = if newt == 2 { thq } else { (thq * thqold).sqrt() };
                thqold = thq;
                if *theta < 0.99 {
                    self.faccon = *theta / (1.0 - *theta);
                    // The predicted error after the remaining iterations (adaptive mode only).
                    let left = NIT.saturating_sub(1 + newt) as i32;
                    let dyth = self.faccon * dyno * theta.powi(left) / fnewt;
                    if dyth >= 1.0 && budget.is_none() {
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        let hfac = 0.8 * qnewt.powf(-1.0 / (4.0 + left as f64));
                        return Err(NewtonFail { cause: FailureCause::NewtonFailure, hfac });
                    }
                } else if budget.is_some() && dyno.is_finite() {
                    return Ok((newt, dyno));
                } else {
                    return Err(diverged);
                }
            }
            dynold = dyno.max(UROUND);
            {
                let [z0, z1, z2] = &mut self.z;
                let [w0, w1, w2] = &mut self.w;
                let (z0, z1, z2) = (&mut z0[..n], &mut z1[..n], &mut z2[..n]);
                let (w0, w1, w2) = (&mut w0[..n], &mut w1[..n], &mut w2[..n]);
                for i in 0..n {
                    let a1 = w0[i] + z0[i];
                    let a2 = w1[i] + z1[i];
                    let a3 = w2[i] + z2[i];
                    w0[i] = a1;
                    w1[i] = a2;
                    w2[i] = a3;
                    z0[i] = T11 * a1 + T12 * a2 + T13 * a3;
                    z1[i] = T21 * a1 + T22 * a2 + T23 * a3;
                    z2[i] = T31 * a1 + a2;
                }
            }
            if !dyno.is_finite() {
                return Err(diverged);
            }
            if self.faccon * dyno <= fnewt {
                return Ok((newt, self.faccon * dyno));
            }
        }
    }

    /// Scaled norm of the embedded error estimate (module doc), at least 1e-10.
    fn error_estimate<S: OdeSystem + ?Sized>(&mut self, sys: &S, t: f64, h: f64, refine: bool) -> f64 {
        let n = self.n;
        let (h1, h2, h3) = (DD1 / h, DD2 / h, DD3 / h);
        // ftmp = (e·Z)/h, tmp = E1⁻¹ (f(t, y) + ftmp).
        {
            let [z0, z1, z2] = &self.z;
            let (z0, z1, z2, y0) = (&z0[..n], &z1[..n], &z2[..n], &self.y0[..n]);
            let (ftmp, tmp) = (&mut self.ftmp[..n], &mut self.tmp[..n]);
            for i in 0..n {
                ftmp[i] = h1 * z0[i] + h2 * z1[i] + h3 * z2[i];
                tmp[i] = ftmp[i] + y0[i];
            }
        }
        self.mats.solve_real(&mut self.tmp);
        let err = self.norm(&self.tmp);
        if err < 1.0 || !refine {
            return err;
        }
        for (x, &y) in self.tmp.iter_mut().zip(&self.y) {
            *x += y;
        }
        // w[0] is free here: the Newton iterate is no longer needed after Z.
        sys.rhs(t, &self.tmp, &mut self.w[0]);
        self.stats.rhs_evals += 1;
        for ((x, &w), &f) in self.tmp.iter_mut().zip(&self.w[0]).zip(&self.ftmp) {
            *x = w + f;
        }
        self.mats.solve_real(&mut self.tmp);
        let refined = self.norm(&self.tmp);
        if refined.is_finite() {
            refined
        } else {
            err
        }
    }

    fn norm(&self, e: &[f64]) -> f64 {
        let s: f64 = e.iter().zip(&self.scal).map(|(e, s)| (e / s).powi(2)).sum();
        let r = (s / self.n as f64).sqrt();
        if r.is_nan() {
            f64::INFINITY
        } else {
            r.max(1e-10)
        }
    }
}

/// The times at which a step from `t` of size `h` ending at `t_end_of_step` evaluates the
/// right-hand side in its Newton iteration: the collocation points `t + c_i h` (the last is the
/// step's end, given exactly).
pub fn stage_times(t: f64, h: f64, t_end_of_step: f64) -> [f64; 3] {
    [t + C1 * h, t + C2 * h, t_end_of_step]
}

/// Step towards `t_end`: land exactly if `h` reaches it (with 1e-4 relative slack), split the
/// rest into two equal steps if `h` covers more than half of it. Returns `(h, last)`.
pub fn plan(t: f64, t_end: f64, h: f64) -> (f64, bool) {
    let rest = t_end - t;
    if h * 1.0001 >= rest {
        (rest, true)
    } else if 2.0 * h > rest {
        (0.5 * rest, false)
    } else {
        (h, false)
    }
}

fn bit_equal(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits())
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Leading numbers of a saved state: nine of the integration, seven work counters.
const SAVED_HEAD: usize = 17;

/// The work counters in the order [`Radau5::save_state`] writes them.
fn stats_array(s: &SolverStats) -> [u64; 7] {
    [
        s.accepted_steps,
        s.rejected_steps,
        s.rhs_evals,
        s.jacobian_evals,
        s.lu_decompositions,
        s.newton_iterations,
        s.inaccurate_steps,
    ]
}

fn invalid(msg: String) -> SolveError {
    invalid_at(f64::NAN, msg)
}

fn invalid_at(t: f64, msg: String) -> SolveError {
    SolveError { kind: SolveErrorKind::InvalidArgument(msg), t, h: 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    /// `T⁻¹ A⁻¹ T` must be `diag(γ, [[α, -β], [β, α]])` for the Radau IIA matrix `A`
    /// (Hairer–Wanner Table IV.5.6); checks the transcribed constants to 1e-12 (they have ~18
    /// digits, the products lose a few to the condition of `T`).
    #[test]
    fn transformation_diagonalises_inverse_of_a() {
        let s6 = 6f64.sqrt();
        let a = Matrix3::new(
            (88.0 - 7.0 * s6) / 360.0,
            (296.0 - 169.0 * s6) / 1800.0,
            (-2.0 + 3.0 * s6) / 225.0,
            (296.0 + 169.0 * s6) / 1800.0,
            (88.0 + 7.0 * s6) / 360.0,
            (-2.0 - 3.0 * s6) / 225.0,
            (16.0 - s6) / 36.0,
            (16.0 + s6) / 36.0,
            1.0 / 9.0,
        );
        let t = Matrix3::new(T11, T12, T13, T21, T22, T23, T31, 1.0, 0.0);
        let ti = Matrix3::new(TI11, TI12, TI13, TI21, TI22, TI23, TI31, TI32, TI33);
        assert!((ti * t - Matrix3::identity()).abs().max() < 1e-12);
        let (g, al, be) = eigen();
        let d = Matrix3::new(g, 0.0, 0.0, 0.0, al, -be, 0.0, be, al);
        let lhs = ti * a.try_inverse().unwrap() * t;
        assert!((lhs - d).abs().max() < 1e-11, "{lhs} vs {d}");
        assert!((C1 - a.row(0).sum()).abs() < 1e-15 && (C2 - a.row(1).sum()).abs() < 1e-15);
    }
}
