//! Gain and phase margins of an open loop `L(s) = N/D` under negative unity feedback, with every
//! crossover frequency found as a real root of a polynomial in `w` (no frequency grid):
//!
//! - phase crossovers (`L(jw)` on the negative real axis): `Im(N(jw) conj D(jw)) = 0` with
//!   `Re(N conj D) < 0`; the gain margin there is `-20 log10 |L(jw)|` dB;
//! - gain crossovers (`|L(jw)| = 1`): `|N(jw)|^2 - |D(jw)|^2 = 0`; the phase margin there is
//!   `180 deg + arg L(jw)`, wrapped into (-180, 180].
//!
//! With several crossovers, or an open loop with right-half-plane poles (the uncompensated
//! boom with `C2 s + H(s)` unstable, Fig. 6.3), the classical "the one margin" is ambiguous.
//! The *stability-relevant* gain margin is the one at the nearest (smallest |dB|) phase
//! crossover at which scaling the loop gain actually moves a closed-loop pole across the
//! imaginary axis, checked with the closed-loop poles just below and just above that gain.
//! A negative value (an open loop that must keep a gain above 1, Fig. 6.4a) means the loop
//! loses stability when its gain *drops* by that much. The stability-relevant phase margin is
//! the smallest |PM|: rotating `L` by that angle first puts a closed-loop pole on `j w`.

use super::poly::Poly;
use super::tf::Tf;

/// A phase crossover and the gain margin there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainMargin {
    /// Phase crossover frequency (rad/s).
    pub omega: f64,
    /// `-20 log10 |L(j omega)|` (dB): the gain change that puts a closed-loop pole at `j omega`.
    pub db: f64,
    /// Whether crossing that gain changes the closed loop between stable and unstable.
    pub changes_stability: bool,
}

/// A gain crossover and the phase margin there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseMargin {
    /// Gain crossover frequency (rad/s).
    pub omega: f64,
    /// `180 + arg L(j omega)` (deg), in (-180, 180].
    pub deg: f64,
}

/// All crossovers of an open loop and the stability-relevant margins.
#[derive(Debug, Clone, PartialEq)]
pub struct Margins {
    pub gain: Vec<GainMargin>,
    pub phase: Vec<PhaseMargin>,
    /// The stability-relevant gain margin (module doc), `None` without a boundary crossing.
    pub relevant_gain: Option<GainMargin>,
    /// The stability-relevant phase margin: smallest |PM|; `None` without gain crossover.
    pub relevant_phase: Option<PhaseMargin>,
    /// The closed loop `L / (1 + L)` is asymptotically stable.
    pub closed_loop_stable: bool,
}

/// Relative gain step used to test whether a phase crossover is a stability boundary.
const GAIN_PROBE: f64 = 1e-4;

/// Margins of the open loop `l` (negative unity feedback).
pub fn margins(l: &Tf) -> Margins {
    // Scale frequency by w0 so the polynomials in w have O(1) roots: L(s) = N(w0 z) / D(w0 z).
    let d = l.den.coeffs();
    let n = d.len() - 1;
    let lead = d.iter().position(|&c| c != 0.0).unwrap_or(0);
    let w0 = if n > lead { (d[lead] / d[n]).abs().powf(1.0 / (n - lead) as f64) } else { 1.0 };
    let scaled =
        |p: &Poly| Poly::new(&p.coeffs().iter().enumerate().map(|(k, c)| c * w0.powi(k as i32)).collect::<Vec<_>>());
    let (nr, ni) = scaled(&l.num).on_imaginary_axis();
    let (dr, di) = scaled(&l.den).on_imaginary_axis();
    let im = &(&ni * &dr) - &(&nr * &di);
    let mag = &(&(&nr * &nr) + &(&ni * &ni)) - &(&(&dr * &dr) + &(&di * &di));

    let stable_at = |k: f64| Tf { num: l.num.clone(), den: &l.den + &l.num.scale(k) }.is_stable();
    let gain: Vec<GainMargin> = im
        .real_roots_in(0.0, f64::INFINITY)
        .into_iter()
        .map(|z| z * w0)
        .filter(|&w| l.at(w).re < 0.0)
        .map(|omega| {
            let k = 1.0 / l.at(omega).norm();
            let changes_stability = stable_at(k * (1.0 - GAIN_PROBE)) != stable_at(k * (1.0 + GAIN_PROBE));
            GainMargin { omega, db: 20.0 * k.log10(), changes_stability }
        })
        .collect();
    let phase: Vec<PhaseMargin> = mag
        .real_roots_in(0.0, f64::INFINITY)
        .into_iter()
        .map(|z| {
            let omega = z * w0;
            let mut deg = 180.0 + l.at(omega).arg().to_degrees();
            if deg > 180.0 {
                deg -= 360.0;
            }
            PhaseMargin { omega, deg }
        })
        .collect();
    let relevant_gain =
        gain.iter().filter(|g| g.changes_stability).min_by(|a, b| a.db.abs().total_cmp(&b.db.abs())).copied();
    let relevant_phase = phase.iter().min_by(|a, b| a.deg.abs().total_cmp(&b.deg.abs())).copied();
    Margins { gain, phase, relevant_gain, relevant_phase, closed_loop_stable: stable_at(1.0) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// L = K / (s (s+1)(s+2)): phase crossover at w = sqrt(2) where |L| = K/6, so
    /// GM = 20 log10(6/K) (textbook, e.g. Ogata ex. 7-24); for K = 2 the gain crossover solves
    /// w^2 (w^2+1)(w^2+4) = 4, w = 0.7494 (the real root of x^3 + 5x^2 + 4x - 4 = 0 with
    /// x = w^2), PM = 180 - 90 - atan(w) - atan(w/2) = 32.6 deg. Tolerances: 1e-9 relative
    /// for the algebraic crossover, 1e-6 for the closed form evaluated here.
    #[test]
    fn third_order_type_one() {
        for k in [1.0, 2.0, 4.0, 10.0] {
            let m = margins(&Tf::new(&[k], &[0.0, 2.0, 3.0, 1.0]));
            assert_eq!(m.gain.len(), 1);
            let g = m.relevant_gain.expect("one boundary");
            assert!((g.omega - 2f64.sqrt()).abs() < 1e-9, "{g:?}");
            assert!((g.db - 20.0 * (6.0 / k).log10()).abs() < 1e-9, "{g:?}");
            assert_eq!(m.closed_loop_stable, k < 6.0);
        }
        let m = margins(&Tf::new(&[2.0], &[0.0, 2.0, 3.0, 1.0]));
        // x^3 + 5x^2 + 4x - 4 = 0 by bisection, independent of the polynomial root finder.
        let x = boomsim::hydraulics::solve::bisect(|x| ((x + 5.0) * x + 4.0) * x - 4.0, 0.0, 1.0, 1e-15);
        let w = x.sqrt();
        let pm = 90.0 - w.atan().to_degrees() - (w / 2.0).atan().to_degrees();
        let p = m.relevant_phase.unwrap();
        assert!((p.omega - w).abs() < 1e-9 && (p.deg - pm).abs() < 1e-6, "{p:?} vs {w} {pm}");
        assert!((p.deg - 32.6).abs() < 0.05);
    }

    /// Open-loop unstable L = K (s + 1) / (s (s - 1)) (Franklin-Powell-Emami-Naeini's
    /// conditionally stable example): closed loop s^2 + (K - 1) s + K, stable for K > 1 only.
    /// Phase crossover at w = 1 with |L| = K, so GM = -20 log10 K < 0: the loop becomes
    /// unstable when the gain *drops* by |GM|; that crossover is the stability-relevant one.
    #[test]
    fn open_loop_unstable_negative_gain_margin() {
        let k = 3.0;
        let m = margins(&Tf::new(&[k, k], &[0.0, -1.0, 1.0]));
        assert!(m.closed_loop_stable);
        let g = m.relevant_gain.unwrap();
        assert!((g.omega - 1.0).abs() < 1e-9 && (g.db + 20.0 * k.log10()).abs() < 1e-9, "{g:?}");
        assert!(g.changes_stability);
    }

    /// Several crossovers: a lightly damped resonance gives the loop
    /// L = 0.5 (s^2 + 0.2 s + 4) / (s (s+1)(s^2 + 0.02 s + 1)) more than one phase crossover;
    /// every listed phase crossover must satisfy Im L = 0 (checked by evaluation), and the
    /// relevant one must be the nearest boundary.
    #[test]
    fn several_crossovers_are_all_reported() {
        let num = Poly::new(&[2.0, 0.1, 0.5]);
        let den = &(&Poly::new(&[0.0, 1.0]) * &Poly::new(&[1.0, 1.0])) * &Poly::new(&[1.0, 0.02, 1.0]);
        let l = Tf { num, den };
        let m = margins(&l);
        assert!(m.gain.len() >= 2, "{m:?}");
        for g in &m.gain {
            let z = l.at(g.omega);
            assert!(z.im.abs() < 1e-7 * z.norm() && z.re < 0.0, "{g:?} {z}");
        }
        for p in &m.phase {
            assert!((l.at(p.omega).norm() - 1.0).abs() < 1e-7, "{p:?}");
        }
        let nearest = m.gain.iter().filter(|g| g.changes_stability).map(|g| g.db.abs()).fold(f64::INFINITY, f64::min);
        assert_eq!(m.relevant_gain.map(|g| g.db.abs()), Some(nearest));
    }
}
