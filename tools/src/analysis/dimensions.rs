//! Dimensional check of every coefficient and transfer function of sections 2.3 and 6.1, with
//! the SI exponents of `boomsim::units` (half-integer exponents for the orifice law's root).
//! It decides the inconsistency of eq. 6.5/6.8 (see [`super::feedback`]).

use boomsim::units::unit;
use std::ops::{Div, Mul};

/// Exponents of kg, m, s, doubled (so `sqrt` stays exact).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dim([i32; 3]);

impl Dim {
    fn of(name: &str) -> Dim {
        let b = unit(name).unwrap_or_else(|| panic!("unit {name}")).base;
        Dim([2 * b[0], 2 * b[1], 2 * b[2]])
    }
    fn sqrt(self) -> Dim {
        assert!(self.0.iter().all(|e| e % 2 == 0), "odd half exponent");
        Dim(self.0.map(|e| e / 2))
    }
}

impl Mul for Dim {
    type Output = Dim;
    fn mul(self, o: Dim) -> Dim {
        Dim([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}

impl Div for Dim {
    type Output = Dim;
    fn div(self, o: Dim) -> Dim {
        Dim([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}

#[test]
fn transfer_functions_are_dimensionally_consistent() {
    let one = Dim::of("1");
    let (pa, flow, area, mass) = (Dim::of("Pa"), Dim::of("m3/s"), Dim::of("m2"), Dim::of("kg"));
    let (vol, vel, s) = (Dim::of("m3"), Dim::of("m/s"), Dim::of("1/s"));
    let k2 = flow / pa.sqrt(); // 2.2.2: m^3/(s sqrt(Pa))
    let k_qu = k2 * pa.sqrt(); // eq. 2.79
    let k_qp = k2 * one / pa.sqrt(); // eq. 2.80
    let c1 = vol / pa; // C = V / beta
    assert_eq!(k_qu, flow);
    assert_eq!(k_qp, Dim::of("m3/(s.Pa)"));
    // eq. 2.81: kappa's two summands agree, and kappa has Table 6.1's unit m^4 s/kg
    assert_eq!(k_qu / pa, k_qp);
    let kappa = k_qp;
    assert_eq!(kappa, Dim([-2, 8, 2]), "m^4 s / kg");
    assert_eq!(c1 / kappa, Dim::of("s"), "tau");
    assert_eq!(area / (c1 * mass).sqrt(), s, "omega_n");
    assert_eq!((mass / c1).sqrt() * kappa / area, one, "zeta");
    // H = mu_c A V_c / P4 is a flow per pressure, as kappa (the static gain)
    let h = area * vel / pa;
    assert_eq!(h, kappa);
    // eq. 2.82: C2 s + H, and a3 s^3, a2 s^2, a1 s, a0 share one dimension
    assert_eq!(c1 * s, h);
    let (a3, a2, a1, a0) = (mass * c1 * c1 / (area * area), mass * c1 * kappa / (area * area), c1, kappa);
    assert_eq!(a3 * s * s * s, a0);
    assert_eq!(a2 * s * s, a0);
    assert_eq!(a1 * s, a0);
    // eq. 6.2, 6.3: K_f = C1 mu_c mu_p is a capacitance, [K_f] = m^4 s^2/kg = m^3/Pa
    let k_f = Dim::of("m4.s2/kg");
    assert_eq!(k_f, c1);
    let g_f = k_f * s; // G_f = K_f s / (s / omega_f + 1)
    assert_eq!(g_f, h, "G_f P4 is a flow");
    // eq. 6.5 and 6.8 with G_f of eq. 6.2: the loop is dimensionless only without the extra s
    let g_ol = g_f / (c1 * s);
    assert_eq!(g_ol, one, "G_v G_f / (C2 s + H)");
    assert_ne!(g_ol * s, one, "the printed s G_v G_f / (C2 s + H) is not dimensionless");
    assert_ne!(g_f * s, c1 * s, "the printed G_f G_v s cannot be added to C2 s");
    assert_eq!(h / (c1 * s), one, "G_cl = H G_v / (C2 s + H + G_f G_v)");
}
