//! The iteration matrices of Radau IIA, `E1 = a·I - J` (real `a = γ/h`) and
//! `E2 = a·I - J` (complex `a = (α + iβ)/h`), factorised once per step size and solved once or
//! twice per Newton iteration.
//!
//! **Second-order structure.** A mechanical model written in first-order form has position
//! states whose derivative *is* a velocity state, `f_(p+k)(t, x) = x_(v+k)` ([`SecondOrder`]).
//! Their rows of `E` are `a Δp_k - Δv_k = r_p,k`, so `Δp_k = (r_p,k + Δv_k) / a`, and
//! substituting this into the other rows leaves a system in the remaining `n - m` unknowns:
//!
//! ```text
//! Ê = a·I - J_RR - J_RP / a · S,      Ê Δ_R = r_R + J_RP r_P / a,      Δ_P = (r_P + Δ_V) / a
//! ```
//!
//! (R: every state but the positions; S picks the velocity columns out of R; `J_RP`: the
//! Jacobian's position columns). This is Gaussian elimination of the position block, exact in
//! exact arithmetic, and it needs no Jacobian rows of the positions (they are identity rows by
//! the declaration, whatever a finite-difference Jacobian says). For the flexible boom (6
//! circuit states, 9 angles, 9 rates) the LU shrinks from 24 to 15 unknowns: a quarter of the
//! factorisation work and 40 % of each solve. Without the structure, R is every state and the
//! same code is the plain dense LU of `E`.
//!
//! **Decoupled states.** A state whose Jacobian row is zero off the diagonal (its derivative
//! depends on itself and the inputs only, like the main spool's first-order lag, eq. 2.40) is
//! solved first, `Δd = r_d / (a - J_dd)`, and moves to the right-hand side of the others:
//! `Ê Δ_R = r_R + J_RP r_P / a + J_RD Δ_D`. The rows are detected exactly in each Jacobian
//! (a finite difference of an independent quantity is exactly zero), so nothing is declared.
//! The flexible boom's system drops to 14 unknowns (3 % fewer instructions in its limit cycle).
//!
//! **Reused factors.** Once the factors have served [`INVERT_AFTER`] solves (a co-simulation step
//! of constant size keeps them for hundreds of steps), both reduced matrices are inverted from
//! them and later solves are matrix-vector products: full-length column updates instead of two
//! triangular sweeps. The count is part of the integrator's saved state, so a restored
//! integrator switches at the same solve.

use super::lu;
use nalgebra::DMatrix;

/// Solves served by one factorisation before the inverses are formed. Forming them costs about
/// 20 solves, so only factors that keep serving pay off: a co-simulation step of constant size
/// keeps them for hundreds of steps, an integration with changing step sizes refactorises after a
/// handful (on the flexible boom's limit cycle, 128 saves 1.3 % of the instructions of 32).
pub(crate) const INVERT_AFTER: u32 = 128;

/// Declares that the states `x[pos + k]`, `k < len`, are positions whose time derivative is
/// exactly the state `x[vel + k]` (`f_(pos+k)(t, x) = x_(vel+k)`); the two ranges are disjoint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SecondOrder {
    pub pos: usize,
    pub vel: usize,
    pub len: usize,
}

impl SecondOrder {
    /// Whether the ranges lie within `n` states and do not overlap.
    pub fn fits(&self, n: usize) -> bool {
        let (p, v, m) = (self.pos, self.vel, self.len);
        p + m <= n && v + m <= n && (p + m <= v || v + m <= p)
    }
}

/// Factors of `E1` and `E2`, reduced by the second-order structure and the decoupled states;
/// work space for the largest size, allocated once.
#[derive(Clone, Debug)]
pub(crate) struct IterationMatrices {
    n: usize,
    structure: Option<SecondOrder>,
    /// The unknowns of the reduced system (R: neither positions nor decoupled), ascending, and
    /// the decoupled states D with their Jacobian diagonal.
    keep: Vec<usize>,
    decoupled: Vec<usize>,
    j_dd: Vec<f64>,
    /// The shifts `a` of `E1` and `E2` and `1 / a` (complex as (re, im)).
    fac1: f64,
    fac2: (f64, f64),
    inv1: f64,
    inv2: (f64, f64),
    e1: Vec<f64>,
    e2_re: Vec<f64>,
    e2_im: Vec<f64>,
    piv1: Vec<usize>,
    piv2: Vec<usize>,
    /// `J_RP / a` of `E1` and of `E2` (r × m, column-major), and `J_RD` (r × |D|).
    jp1: Vec<f64>,
    jp2_re: Vec<f64>,
    jp2_im: Vec<f64>,
    jd: Vec<f64>,
    /// Reduced right-hand sides, and one product.
    b_re: Vec<f64>,
    b_im: Vec<f64>,
    col: Vec<f64>,
    col_im: Vec<f64>,
    /// Solves served by the current factors; the inverses (column-major r × r) once formed.
    uses: u32,
    inverted: bool,
    x1: Vec<f64>,
    x2_re: Vec<f64>,
    x2_im: Vec<f64>,
}

impl IterationMatrices {
    /// Work space for `n` states, without structure.
    pub(crate) fn new(n: usize) -> Self {
        let v = |len| vec![0.0; len];
        Self {
            n,
            structure: None,
            keep: Vec::with_capacity(n),
            decoupled: Vec::with_capacity(n),
            j_dd: Vec::with_capacity(n),
            fac1: 0.0,
            fac2: (0.0, 0.0),
            inv1: 0.0,
            inv2: (0.0, 0.0),
            e1: v(n * n),
            e2_re: v(n * n),
            e2_im: v(n * n),
            piv1: Vec::with_capacity(n),
            piv2: Vec::with_capacity(n),
            jp1: v(n * n),
            jp2_re: v(n * n),
            jp2_im: v(n * n),
            jd: v(n * n),
            b_re: v(n),
            b_im: v(n),
            col: v(n),
            col_im: v(n),
            uses: 0,
            inverted: false,
            x1: v(n * n),
            x2_re: v(n * n),
            x2_im: v(n * n),
        }
    }

    /// The structure the factors use.
    pub(crate) fn structure(&self) -> Option<SecondOrder> {
        self.structure
    }

    /// Uses `structure` (checked by the caller with [`SecondOrder::fits`]) for the next
    /// factorisation.
    pub(crate) fn set_structure(&mut self, structure: Option<SecondOrder>) {
        self.structure = structure;
    }

    /// The position states (empty without structure).
    fn positions(&self) -> std::ops::Range<usize> {
        self.structure.map_or(0..0, |s| s.pos..s.pos + s.len)
    }

    /// Factorises `E1 = fac1·I - J` and `E2 = (alphn + i·betan)·I - J`; `false` if singular.
    /// Does not allocate (the index lists stay within the capacity of [`new`](Self::new)).
    pub(crate) fn factor(&mut self, jac: &DMatrix<f64>, fac1: f64, alphn: f64, betan: f64) -> bool {
        let (n, jac) = (self.n, jac.as_slice());
        let (structure, positions) = (self.structure, self.positions());
        // The position whose derivative is state j, if j is a velocity.
        let position_of =
            |j: usize| structure.and_then(|s| (s.vel..s.vel + s.len).contains(&j).then(|| s.pos + j - s.vel));
        (self.fac1, self.fac2) = (fac1, (alphn, betan));
        let norm = alphn * alphn + betan * betan;
        self.inv1 = 1.0 / fac1;
        self.inv2 = (alphn / norm, -betan / norm);
        let (inv1, (ir, ii)) = (self.inv1, self.inv2);
        (self.uses, self.inverted) = (0, false);
        self.keep.clear();
        self.decoupled.clear();
        self.j_dd.clear();
        for i in (0..n).filter(|i| !positions.contains(i)) {
            if position_of(i).is_none() && (0..n).all(|j| j == i || jac[i + j * n] == 0.0) {
                self.decoupled.push(i);
                self.j_dd.push(jac[i + i * n]);
            } else {
                self.keep.push(i);
            }
        }
        if self.j_dd.iter().any(|&j| !(fac1 - j != 0.0 && (fac1 - j).is_finite())) {
            return false;
        }
        let r = self.keep.len();
        let keep = &self.keep;
        for (jr, &j) in keep.iter().enumerate() {
            let (cj, cp) = (&jac[j * n..(j + 1) * n], position_of(j).map(|p| &jac[p * n..(p + 1) * n]));
            let c = jr * r..(jr + 1) * r;
            let (e1, e2r, e2i) = (&mut self.e1[c.clone()], &mut self.e2_re[c.clone()], &mut self.e2_im[c]);
            for (k, &i) in keep.iter().enumerate() {
                let jp = cp.map_or(0.0, |cp| cp[i]);
                (e1[k], e2r[k], e2i[k]) = (-cj[i] - jp * inv1, -cj[i] - jp * ir, -jp * ii);
            }
            e1[jr] += fac1;
            e2r[jr] += alphn;
            e2i[jr] += betan;
        }
        for (kp, p) in positions.enumerate() {
            let c = kp * r..(kp + 1) * r;
            let (j1, j2r, j2i) = (&mut self.jp1[c.clone()], &mut self.jp2_re[c.clone()], &mut self.jp2_im[c]);
            for (k, &i) in keep.iter().enumerate() {
                let x = jac[i + p * n];
                (j1[k], j2r[k], j2i[k]) = (x * inv1, x * ir, x * ii);
            }
        }
        for (kd, &d) in self.decoupled.iter().enumerate() {
            for (k, &i) in keep.iter().enumerate() {
                self.jd[k + kd * r] = jac[i + d * n];
            }
        }
        self.piv1.resize(r, 0);
        self.piv2.resize(r, 0);
        lu::factor(&mut self.e1[..r * r], &mut self.piv1)
            && lu::factor_complex(&mut self.e2_re[..r * r], &mut self.e2_im[..r * r], &mut self.piv2)
    }

    /// Solves served by the current factors.
    pub(crate) fn uses(&self) -> u32 {
        self.uses
    }

    /// Restores the count of [`uses`](Self::uses) after a refactorisation from a saved state. An
    /// empty reduced system (every state decoupled) has nothing to invert.
    pub(crate) fn set_uses(&mut self, uses: u32) {
        self.uses = uses;
        if uses >= INVERT_AFTER && !self.keep.is_empty() {
            self.invert();
        }
    }

    /// Counts a solve; forms the inverses when the factors have served [`INVERT_AFTER`].
    fn count_use(&mut self) {
        if !self.inverted {
            self.set_uses(self.uses + 1);
        }
    }

    /// The inverses of both reduced matrices, column by column from the LU factors.
    fn invert(&mut self) {
        let r = self.keep.len();
        for j in 0..r {
            let c = j * r..(j + 1) * r;
            let x1 = &mut self.x1[c.clone()];
            x1.fill(0.0);
            x1[j] = 1.0;
            lu::solve(&self.e1[..r * r], &self.piv1, x1);
            let (xr, xi) = (&mut self.x2_re[c.clone()], &mut self.x2_im[c]);
            xr.fill(0.0);
            xi.fill(0.0);
            xr[j] = 1.0;
            lu::solve_complex(&self.e2_re[..r * r], &self.e2_im[..r * r], &self.piv2, xr, xi);
        }
        self.inverted = true;
    }

    /// Solves `E1 x = b` in place.
    pub(crate) fn solve_real(&mut self, b: &mut [f64]) {
        let (r, positions) = (self.keep.len(), self.positions());
        for (&d, &j_dd) in self.decoupled.iter().zip(&self.j_dd) {
            b[d] /= self.fac1 - j_dd;
        }
        let br = &mut self.b_re[..r];
        for (x, &i) in br.iter_mut().zip(&self.keep) {
            *x = b[i];
        }
        for (kp, p) in positions.enumerate() {
            axpy(br, &self.jp1[kp * r..(kp + 1) * r], b[p]);
        }
        for (kd, &d) in self.decoupled.iter().enumerate() {
            axpy(br, &self.jd[kd * r..(kd + 1) * r], b[d]);
        }
        if self.inverted {
            let y = &mut self.col[..r];
            y.fill(0.0);
            for (col, &x) in self.x1[..r * r].chunks_exact(r).zip(br.iter()) {
                axpy(y, col, x);
            }
            br.copy_from_slice(y);
        } else {
            lu::solve(&self.e1[..r * r], &self.piv1, br);
        }
        for (&x, &i) in br.iter().zip(&self.keep) {
            b[i] = x;
        }
        if let Some(s) = self.structure {
            for k in 0..s.len {
                b[s.pos + k] = (b[s.pos + k] + b[s.vel + k]) * self.inv1;
            }
        }
        self.count_use();
    }

    /// Solves `E2 (x + i y) = bre + i bim` in place.
    pub(crate) fn solve_complex(&mut self, bre: &mut [f64], bim: &mut [f64]) {
        let (r, positions) = (self.keep.len(), self.positions());
        let (ar, ai) = self.fac2;
        for (&d, &j_dd) in self.decoupled.iter().zip(&self.j_dd) {
            // (x + iy) / (c + i ai) = ((xc + y ai) + i(yc - x ai)) / (c² + ai²), c = ar - J_dd.
            let (x, y, c) = (bre[d], bim[d], ar - j_dd);
            let ns = c * c + ai * ai;
            (bre[d], bim[d]) = ((x * c + y * ai) / ns, (y * c - x * ai) / ns);
        }
        let (xr, xi) = (&mut self.b_re[..r], &mut self.b_im[..r]);
        for ((xr, xi), &i) in xr.iter_mut().zip(xi.iter_mut()).zip(&self.keep) {
            (*xr, *xi) = (bre[i], bim[i]);
        }
        for (kp, p) in positions.enumerate() {
            let (pr, pi) = (bre[p], bim[p]);
            let col = kp * r..(kp + 1) * r;
            let jp = self.jp2_re[col.clone()].iter().zip(&self.jp2_im[col]);
            for ((xr, xi), (&jr, &ji)) in xr.iter_mut().zip(xi.iter_mut()).zip(jp) {
                *xr += jr * pr - ji * pi;
                *xi += jr * pi + ji * pr;
            }
        }
        for (kd, &d) in self.decoupled.iter().enumerate() {
            let col = &self.jd[kd * r..(kd + 1) * r];
            axpy(xr, col, bre[d]);
            axpy(xi, col, bim[d]);
        }
        if self.inverted {
            let (yr, yi) = (&mut self.col[..r], &mut self.col_im[..r]);
            yr.fill(0.0);
            yi.fill(0.0);
            let cols = self.x2_re[..r * r].chunks_exact(r).zip(self.x2_im[..r * r].chunks_exact(r));
            for ((cr, ci), (&pr, &pi)) in cols.zip(xr.iter().zip(xi.iter())) {
                for ((yr, yi), (&ar, &ai)) in yr.iter_mut().zip(yi.iter_mut()).zip(cr.iter().zip(ci)) {
                    *yr += ar * pr - ai * pi;
                    *yi += ar * pi + ai * pr;
                }
            }
            xr.copy_from_slice(yr);
            xi.copy_from_slice(yi);
        } else {
            lu::solve_complex(&self.e2_re[..r * r], &self.e2_im[..r * r], &self.piv2, xr, xi);
        }
        for ((&xr, &xi), &i) in xr.iter().zip(xi.iter()).zip(&self.keep) {
            (bre[i], bim[i]) = (xr, xi);
        }
        if let Some(s) = self.structure {
            let (ar, ai) = self.inv2;
            for k in 0..s.len {
                let (p, v) = (s.pos + k, s.vel + k);
                let (sr, si) = (bre[p] + bre[v], bim[p] + bim[v]);
                (bre[p], bim[p]) = (sr * ar - si * ai, sr * ai + si * ar);
            }
        }
        self.count_use();
    }
}

/// `y += a x`.
fn axpy(y: &mut [f64], a: &[f64], x: f64) {
    for (y, &a) in y.iter_mut().zip(a) {
        *y += a * x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Complex, DVector};

    /// A Jacobian with the declared structure (identity rows for the positions), row `d`
    /// decoupled (zero off the diagonal) and otherwise arbitrary, well-conditioned entries.
    fn structured_jacobian(n: usize, s: SecondOrder, d: usize) -> DMatrix<f64> {
        let mut j =
            DMatrix::from_fn(n, n, |i, k| ((i * 7 + k * 13) % 11) as f64 - 5.0 + if i == k { -30.0 } else { 0.0 });
        for k in 0..s.len {
            j.row_mut(s.pos + k).fill(0.0);
            j[(s.pos + k, s.vel + k)] = 1.0;
        }
        let j_dd = j[(d, d)];
        j.row_mut(d).fill(0.0);
        j[(d, d)] = j_dd;
        j
    }

    /// The reduced solves equal the dense solve of the full `a·I - J` (nalgebra's LU, a second
    /// implementation), for the real and the complex shift, with the positions before and after
    /// the velocities, and without structure, each with a decoupled state; by triangular sweeps
    /// and by the inverses. Bound: 1e-12 relative, a few hundred ulps of the two eliminations'
    /// round-off on a matrix of condition ~10.
    #[test]
    fn reduced_solve_equals_full_solve() {
        let n = 8;
        let (fac1, alphn, betan) = (3.6, 2.7, 1.9);
        let cases = [
            (Some(SecondOrder { pos: 2, vel: 5, len: 3 }), 0),
            (Some(SecondOrder { pos: 5, vel: 1, len: 3 }), 4),
            (None, 3),
        ];
        for (structure, d) in cases {
            let j = structured_jacobian(n, structure.unwrap_or(SecondOrder { pos: 0, vel: 0, len: 0 }), d);
            let mut m = IterationMatrices::new(n);
            m.set_structure(structure);
            assert!(m.factor(&j, fac1, alphn, betan));
            assert_eq!(m.decoupled, [d], "the decoupled row is found");
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.1).collect();
            let c: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos()).collect();
            // Every solve before and after the factors are inverted (INVERT_AFTER) is checked.
            for _ in 0..INVERT_AFTER + 2 {
                let e1 = DMatrix::identity(n, n) * fac1 - &j;
                let want = e1.lu().solve(&DVector::from_column_slice(&b)).unwrap();
                let mut got = b.clone();
                m.solve_real(&mut got);
                let err = (DVector::from_column_slice(&got) - &want).amax() / want.amax();
                assert!(err < 1e-12, "{structure:?}: real error {err}");

                let a = Complex::new(alphn, betan);
                let e2 = DMatrix::from_fn(n, n, |i, k| if i == k { a } else { Complex::new(0.0, 0.0) } - j[(i, k)]);
                let rhs = DVector::from_fn(n, |i, _| Complex::new(b[i], c[i]));
                let want = e2.lu().solve(&rhs).unwrap();
                let (mut gr, mut gi) = (b.clone(), c.clone());
                m.solve_complex(&mut gr, &mut gi);
                let err = (0..n).map(|i| (Complex::new(gr[i], gi[i]) - want[i]).norm()).fold(0.0, f64::max);
                let scale = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
                assert!(err < 1e-12 * scale, "{structure:?}: complex error {err}");
            }
            assert!(m.inverted, "the last solves used the inverses");
        }
    }

    /// With every state decoupled (a diagonal Jacobian, e.g. a circuit whose valves are all
    /// closed) nothing is left to factorise: x_i = b_i / (a - J_ii) exactly, also after
    /// INVERT_AFTER solves.
    #[test]
    fn all_states_decoupled() {
        let j = DMatrix::from_diagonal(&DVector::from_column_slice(&[-2.0, -30.0, -0.5]));
        let mut m = IterationMatrices::new(3);
        assert!(m.factor(&j, 4.0, 3.0, 1.5));
        for _ in 0..2 * INVERT_AFTER {
            let mut x = [1.0, 2.0, 3.0];
            m.solve_real(&mut x);
            assert_eq!(x, [1.0 / 6.0, 2.0 / 34.0, 3.0 / 4.5]);
            let (mut xr, mut xi) = ([1.0; 3], [0.0; 3]);
            m.solve_complex(&mut xr, &mut xi);
            let want = |jii: f64| Complex::new(1.0, 0.0) / Complex::new(3.0 - jii, 1.5);
            for (k, jii) in [-2.0, -30.0, -0.5].into_iter().enumerate() {
                assert!((Complex::new(xr[k], xi[k]) - want(jii)).norm() < 1e-15, "{k}");
            }
        }
    }

    #[test]
    fn structure_must_fit() {
        assert!(SecondOrder { pos: 0, vel: 3, len: 3 }.fits(6));
        assert!(!SecondOrder { pos: 0, vel: 2, len: 3 }.fits(6), "overlap");
        assert!(!SecondOrder { pos: 3, vel: 0, len: 4 }.fits(6), "beyond n");
    }
}
