//! The Routh-Hurwitz array of a real polynomial ([6, p. 112-114] of the thesis): the number of
//! sign changes in its first column is the number of roots in the right half plane.

use super::poly::Poly;

/// First column of the Routh array of `p`, highest power first. A zero leading element of a
/// row is replaced by `eps` times the row scale (the textbook epsilon method); a row of zeros
/// (roots symmetric about the origin) is replaced by the derivative of the auxiliary
/// polynomial.
pub fn first_column(p: &Poly) -> Vec<f64> {
    let c: Vec<f64> = p.coeffs().iter().rev().copied().collect(); // highest power first
    let n = c.len();
    let width = n.div_ceil(2);
    let mut rows: Vec<Vec<f64>> = vec![
        (0..width).map(|k| c.get(2 * k).copied().unwrap_or(0.0)).collect(),
        (0..width).map(|k| c.get(2 * k + 1).copied().unwrap_or(0.0)).collect(),
    ];
    let scale = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    while rows.len() < n {
        let a = rows[rows.len() - 2].clone();
        let mut b = rows[rows.len() - 1].clone();
        let row_scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if row_scale <= 1e-14 * scale {
            // auxiliary polynomial from the row above: derivative of sum a_k s^(d - 2k)
            let d = n + 1 - rows.len(); // degree of the auxiliary polynomial (row above)
            b = (0..width).map(|k| a[k] * d.saturating_sub(2 * k) as f64).collect();
        }
        if b[0] == 0.0 {
            b[0] = 1e-12 * b.iter().chain(a.iter()).fold(0.0f64, |m, x| m.max(x.abs()));
        }
        let last = rows.len() - 1;
        rows[last] = b.clone();
        let next: Vec<f64> = (0..width)
            .map(|k| {
                let (a1, b1) = (a.get(k + 1).copied().unwrap_or(0.0), b.get(k + 1).copied().unwrap_or(0.0));
                (b[0] * a1 - a[0] * b1) / b[0]
            })
            .collect();
        rows.push(next);
    }
    rows.into_iter().take(n).map(|r| r[0]).collect()
}

/// Number of right-half-plane roots of `p`: sign changes in the first column.
pub fn rhp_roots(p: &Poly) -> usize {
    first_column(p).windows(2).filter(|w| w[0].signum() != w[1].signum()).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the real parts of the roots of polynomials built from known roots (products of
    /// (s - r) and (s^2 - 2 a s + a^2 + b^2)); root counts are exact integers.
    #[test]
    fn counts_right_half_plane_roots() {
        let lin = |r: f64| Poly::new(&[-r, 1.0]);
        let pair = |a: f64, b: f64| Poly::new(&[a * a + b * b, -2.0 * a, 1.0]);
        let cases: Vec<(Poly, usize)> = vec![
            (&(&lin(-1.0) * &lin(-2.0)) * &lin(-3.0), 0),
            (&(&lin(1.0) * &lin(-2.0)) * &pair(-0.5, 3.0), 1),
            (&(&lin(-1.0) * &pair(0.2, 5.0)) * &pair(-3.0, 1.0), 2),
            (&(&lin(2.0) * &pair(0.2, 5.0)) * &pair(1.0, 1.0), 5),
            (&pair(0.0, 2.0) * &lin(-1.0), 0), // roots on the axis: none in the open RHP
        ];
        for (p, want) in cases {
            let by_roots = p.roots().iter().filter(|z| z.re > 1e-9).count();
            assert_eq!(by_roots, want, "roots of {p:?}");
            assert_eq!(rhp_roots(&p), want, "Routh for {p:?}: {:?}", first_column(&p));
        }
        // K / (s (s+1)(s+2)) in unity feedback: s^3 + 3 s^2 + 2 s + K, stable for K < 6.
        for (k, want) in [(5.9, 0), (6.1, 2)] {
            assert_eq!(rhp_roots(&Poly::new(&[k, 2.0, 3.0, 1.0])), want);
        }
    }
}
