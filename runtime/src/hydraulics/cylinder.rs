//! Asymmetric double-acting cylinder (PMC 25 CA), section 2.2.3 / 4.1.3: pressure forces
//! (eq. 2.60-2.61), chamber volumes and physical end stops. Stroke `x` is 0 fully retracted and
//! positive extending; `v = dx/dt`.

use crate::scalar::{min, Scalar};
use std::f64::consts::FRAC_PI_4;

/// Penetration over which the end-stop damping fades in (m). Damping applied at zero
/// penetration would make the stop pull or jump on contact.
const STOP_DAMPING_RAMP: f64 = 1e-4;
/// Force scale of the C1 rounding of the end-stop force at zero (N).
const STOP_FORCE_ROUNDING: f64 = 10.0;

/// Cylinder parameters (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    /// Bore (piston diameter) `d_c` (m), 65 mm.
    pub d_piston: f64,
    /// Rod diameter `d_r` (m), 35 mm. (Section 4.1.3 calls both "areas" in mm^2; they are the
    /// diameters of the parameter list.)
    pub d_rod: f64,
    /// Stroke `s_c` (m), 500 mm.
    pub stroke: f64,
    /// Dead volume of the piston-side chamber `V_CH1` (m^3), 50 cm^3 (assumed, 5.1.1).
    pub v_dead_a: f64,
    /// Dead volume of the rod-side chamber `V_CH2` (m^3), 50 cm^3 (assumed, 5.1.1).
    pub v_dead_b: f64,
    /// End-stop contact stiffness (N/m). The thesis has no end stops; 1e8 N/m lets a stop
    /// yield 0.9 mm under the largest pressure force (280 bar on the piston, 93 kN).
    pub k_stop: f64,
    /// End-stop contact damping (N s/m), 2e5 N s/m: about critical for 100 kg on `k_stop`.
    pub c_stop: f64,
}

impl Cylinder {
    /// Piston area `A = pi d_c^2 / 4` (m^2).
    pub fn area_a(&self) -> f64 {
        FRAC_PI_4 * self.d_piston * self.d_piston
    }

    /// Rod-side annulus area `mu_c A = pi (d_c^2 - d_r^2) / 4` (m^2).
    pub fn area_b(&self) -> f64 {
        FRAC_PI_4 * (self.d_piston * self.d_piston - self.d_rod * self.d_rod)
    }

    /// Area ratio `mu_c` = annulus / piston area (-), 0.710 (nomenclature: "cylinder/rod area
    /// ratio", used as `F2 = p4 mu_c A`, eq. 2.61).
    pub fn mu_c(&self) -> f64 {
        self.area_b() / self.area_a()
    }

    /// Pressure force on the rod `F1 - F2 = p3 A - p4 mu_c A` (eq. 2.60, 2.61), N,
    /// positive extending.
    pub fn pressure_force<T: Scalar>(&self, p3: T, p4: T) -> T {
        p3 * self.area_a() - p4 * self.area_b()
    }

    /// Piston-side chamber volume `V_CH1 + A x` (m^3).
    pub fn volume_a<T: Scalar>(&self, x: T) -> T {
        x * self.area_a() + self.v_dead_a
    }

    /// Rod-side chamber volume `V_CH2 + mu_c A (s_c - x)` (m^3).
    pub fn volume_b<T: Scalar>(&self, x: T) -> T {
        (T::from(self.stroke) - x) * self.area_b() + self.v_dead_b
    }

    /// The strokes at which a chamber's volume `V_CH + A x` is gone (m): the piston pressed past
    /// an end stop through the dead volume, into the barrel's end or the rod's gland. Between them
    /// the stops are contacts that yield (1e8 N/m: 15 mm at the piston side takes 1.5 MN, 16 times
    /// the largest pressure force); outside them the cylinder is broken, and no model of it is
    /// valid. The thesis has no such limit (its simulations never reach the stops).
    pub fn stroke_domain(&self) -> (f64, f64) {
        (-self.v_dead_a / self.area_a(), self.stroke + self.v_dead_b / self.area_b())
    }

    /// End-stop force on the rod (N, positive extending): zero inside `[0, s_c]`, pushing
    /// outward at the bottom stop (`x < 0`) and inward at the top stop (`x > s_c`).
    ///
    /// Not in the thesis (its simulations never reach the stops). Per stop, with penetration
    /// `d` and its rate: `F = r(k d + c w(d) d')`, where `w` is a C1 smoothstep from 0 at
    /// contact to 1 at 0.1 mm penetration (no damping force before contact) and `r` the C1
    /// rounding of `max(0, .)` over 10 N (`r(y) = y^2 / 20 N` below 10 N). So the force is C1
    /// in `(x, v)`, exactly zero out of contact, never pulls, and finite for finite inputs.
    pub fn end_stop_force<T: Scalar>(&self, x: T, v: T) -> T {
        self.stop_push(-x, -v) - self.stop_push(x - self.stroke, v)
    }

    /// Magnitude of the contact force of one stop at penetration `d` with rate `d_dot`.
    fn stop_push<T: Scalar>(&self, d: T, d_dot: T) -> T {
        if d <= 0.0 {
            return T::from(0.0);
        }
        let s = min(d / STOP_DAMPING_RAMP, 1.0);
        let w = s * s * (T::from(3.0) - s * 2.0);
        let y = d * self.k_stop + w * self.c_stop * d_dot;
        if y <= 0.0 {
            T::from(0.0)
        } else if y < STOP_FORCE_ROUNDING {
            y * y / (2.0 * STOP_FORCE_ROUNDING)
        } else {
            y - 0.5 * STOP_FORCE_ROUNDING
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::hydraulics::circuit::Circuit;
    use crate::units::{bar, mm};

    #[test]
    fn areas_and_forces() {
        let c = Circuit::default().cylinder;
        let a = std::f64::consts::PI / 4.0 * 0.065f64.powi(2);
        assert!((c.area_a() / a - 1.0).abs() < 1e-12);
        // mu_c = 1 - (35/65)^2
        assert!((c.mu_c() - (1.0 - (35.0f64 / 65.0).powi(2))).abs() < 1e-12);
        assert!((c.pressure_force(bar(100.0), bar(10.0)) - (bar(100.0) - bar(10.0) * c.mu_c()) * a).abs() < 1e-6);
        assert!((c.volume_a(0.25) - (50e-6 + a * 0.25)).abs() < 1e-15);
        assert!((c.volume_b(c.stroke) - 50e-6).abs() < 1e-15);
    }

    /// The end-stop force only pushes away from the stop, is zero inside the stroke, continuous
    /// at contact, and finite everywhere.
    #[test]
    fn end_stop_only_pushes() {
        let c = Circuit::default().cylinder;
        let speeds = [-10.0, -1.0, -0.1, 0.0, 0.1, 1.0, 10.0];
        for i in -200..=200 {
            let x = mm(i as f64 * 0.01); // bottom stop region
            let xt = c.stroke + x; // top stop region
            for v in speeds {
                let f = c.end_stop_force(x, v);
                let ft = c.end_stop_force(xt, v);
                assert!(f.is_finite() && ft.is_finite());
                assert!(f >= 0.0, "bottom stop pulls: x {x}, v {v}, F {f}");
                assert!(ft <= 0.0, "top stop pulls: x {xt}, v {v}, F {ft}");
                if x >= 0.0 {
                    assert_eq!(f, 0.0);
                }
                if x <= 0.0 {
                    assert_eq!(ft, 0.0);
                }
            }
        }
        for v in speeds {
            assert_eq!(c.end_stop_force(0.25, v), 0.0);
            assert!(c.end_stop_force(-1e-12, v) < 1e-3, "continuous at contact");
        }
        // static stiffness deep in the stop: k d - rounding offset
        let f = c.end_stop_force(-mm(1.0), 0.0);
        assert!((f - (c.k_stop * mm(1.0) - 5.0)).abs() < 1e-6);
        assert!(c.end_stop_force(-1e3_f64, 1e3).is_finite());
    }
}
