#!/usr/bin/env python3
"""Instability study of the HydraulicBoom FMU without pressure feedback (issue 3, item 5).

Lowering through the counterbalance valve (CBV) with a pressure-compensated valve oscillates
when the piston-side capacitance is large against the rod-side one (thesis section 2.3). This
script

1. computes the critical stroke x_c of the stability criterion of section 2.3 with the model's
   parameters (read from the FMU's modelDescription), at three levels of detail:
   - eq. 2.87: x_c = s_c / (1 + mu_p) (no line or dead volumes, u_cbv << 1);
   - eq. 2.86 with line and dead volumes (rigid lines, constant bulk modulus):
     C2(x) / C1(x) = mu_c mu_p, C1 = (V_L3 + V_CH1 + A x) / beta,
     C2 = (V_L4 + V_CH2 + mu_c A (s_c - x)) / beta;
   - eq. 2.84 with everything the model has: the hose compliance C_w = c_hose V_L (eq. 5.2)
     added to C1 and C2, the effective bulk modulus of the oil-air law at the steady pressures
     (runtime/src/hydraulics/line.rs), and the factor 2 dp / (2 dp + u_cbv p_fo,cbv) of the steady
     lowering state of eq. 2.72, 2.73, 2.85 (with the back pressure p2 of the A->T metering
     edge in the CBV pressure drop dp = p3 - p2, which the thesis neglects);
   The linearised model's frequency: omega_n = A / sqrt(C1 m) of eq. 2.81 (piston side only)
   and with both chambers as springs, sqrt((A^2 / C1 + (mu_c A)^2 / C2) / m); m = F / g, the
   equivalent mass of eq. 2.69 (the load seen at the cylinder).
2. simulates lowering with u = -0.05 and -0.1 from a range of start strokes (10 s, 1 ms steps,
   no feedback) and reports the p3 peak-to-peak amplitude and frequency early (1-2 s) and late
   (the last second before t = 10 s or the bottom stop), and whether the large limit cycle was
   reached (p3 peak-to-peak > 150 bar in some 0.5 s window);
3. bisects the start stroke where the behaviour changes (to 1 mm) and compares it with x_c.

Usage: boomsim-instability [--csv] [--png] [--quick]
(--csv/--png write out/instability.csv, out/instability.png; --quick skips the bisection).
Needs target/fmu/HydraulicBoom.fmu (cargo build --release && target/release/boomsim pack).
"""

import argparse
import math
import sys

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from . import figures
from .errors import cli
from .paths import OUT, fmu

P_ATM = 101325.0
G = 9.807
LARGE = 150e5  # p3 peak-to-peak of the large limit cycle (vacuum .. ~p_set)


class Boom:
    """The FMU, its parameters (start values) and a lowering run."""

    def __init__(self, path=None):
        path = path or fmu("HydraulicBoom")
        self.md = read_model_description(str(path))
        self.dir = extract(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.par = {v.name: float(v.start) for v in self.md.modelVariables
                    if v.type == "Real" and v.start is not None}

    def run(self, u, x0, t_end=10.0, h=1e-3):
        """Lowering with spool reference u from rest at stroke x0: t, p3, x (p3 at t = 0 is the
        static holding pressure, the FMU's equilibrium)."""
        s = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                      modelIdentifier="HydraulicBoom", instanceName="study")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setReal([self.vr["start.x"]], [x0])
        s.exitInitializationMode()
        s.setReal([self.vr["valve.u_ref"]], [u])
        refs = [self.vr["p3"], self.vr["cylinder.x"]]
        n = int(round(t_end / h))
        out = [s.getReal(refs)]
        for k in range(n):
            s.doStep(k * h, h)
            out.append(s.getReal(refs))
        s.terminate()
        s.freeInstance()
        r = np.array(out)
        return np.arange(n + 1) * h, r[:, 0], r[:, 1]


# ---------------------------------------------------------------------------------------------
# 1. The criterion of section 2.3


def bulk_modulus(par, p):
    """Effective bulk modulus of the model's oil-air law (line.rs): p_abs (e p_abs + a) /
    (e p_abs^2 / beta + a), e = exp(-p / beta), a = x0 P_ATM."""
    beta, a = par["fluid.beta"], par["fluid.air_fraction"] * P_ATM
    p_abs, e = p + P_ATM, math.exp(-p / par["fluid.beta"])
    return p_abs * (e * p_abs + a) / (e * p_abs ** 2 / beta + a)


def areas(par):
    a = math.pi / 4 * par["cylinder.d_piston"] ** 2
    b = math.pi / 4 * (par["cylinder.d_piston"] ** 2 - par["cylinder.d_rod"] ** 2)
    return a, b


def steady_lowering(par, u, force):
    """Steady lowering at spool opening u < 0 with the ideal compensated flow |u| Q_rated into the
    rod side: v = |u| Q_rated / (mu_c A), Q3 = A v leaves the piston side through the CBV
    (eq. 2.72 with the pressure drop p3 - p2) and line 2 through the A->T edge, p2 = (Q3 / (K1 |u|))^2
    (eq. 2.42); the CBV opening follows the pilot (eq. 2.73, p_T = 0) and the force balance is
    eq. 2.85 (friction neglected): p3 A - p4 mu_c A = F. Returns p2, p3, p4, u_cbv."""
    a, b = areas(par)
    q3 = a * abs(u) * par["valve.q_rated"] / b
    k1 = par["valve.q_rated"] / math.sqrt(par["valve.dp_rated"])
    k2 = par["cbv.q_nom"] / math.sqrt(par["cbv.dp_nom"])
    p2 = (q3 / (k1 * abs(u))) ** 2
    mu_p, p_set, p_fo = par["cbv.mu_p"], par["cbv.p_set"], par["cbv.p_fo_cbv"]

    def residual(p4):  # CBV flow at the opening the pilot gives, minus the flow needed
        p3 = (force + p4 * b) / a
        u_cbv = (mu_p * p4 + p3 - p_set) / p_fo
        return k2 * u_cbv * math.sqrt(max(p3 - p2, 0.0)) - q3

    lo, hi = 0.0, p_set  # residual < 0 with the CBV closed, > 0 far open
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if residual(mid) < 0 else (lo, mid)
    p4 = 0.5 * (lo + hi)
    p3 = (force + p4 * b) / a
    return p2, p3, p4, (mu_p * p4 + p3 - p_set) / p_fo


def capacitances(par, x, p3=None, p4=None, hoses=False):
    """C1 (line 3 + piston side), C2 (rod side + line 4) in m^3/Pa at stroke x: constant beta if
    p3/p4 are None, else the effective bulk modulus at those pressures; hose compliance if asked."""
    a, b = areas(par)
    v3 = par["line.v_l3"] + par["cylinder.v_dead_a"] + a * x
    v4 = par["line.v_l4"] + par["cylinder.v_dead_b"] + b * (par["cylinder.stroke"] - x)
    b3 = par["fluid.beta"] if p3 is None else bulk_modulus(par, p3)
    b4 = par["fluid.beta"] if p4 is None else bulk_modulus(par, p4)
    c1, c2 = v3 / b3, v4 / b4
    if hoses:
        c1 += par["line.c_hose"] * par["line.v_l3"]
        c2 += par["line.c_hose"] * par["line.v_l4"]
    return c1, c2


def critical_stroke(margin, s_c):
    """Largest stroke in [0, s_c] with margin(x) = C2/C1 - bound >= 0 (margin falls with x):
    None if the criterion fails at every stroke, s_c if it holds at every stroke."""
    if margin(0.0) < 0:
        return None
    if margin(s_c) >= 0:
        return s_c
    lo, hi = 0.0, s_c
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if margin(mid) >= 0 else (lo, mid)
    return 0.5 * (lo + hi)


def criterion(par, force, u):
    """x_c of eq. 2.87, 2.86 (with volumes) and 2.84 (full), and the steady state used."""
    s_c, mu_p = par["cylinder.stroke"], par["cbv.mu_p"]
    a, b = areas(par)
    mu_c = b / a
    x_287 = s_c / (1 + mu_p)

    def m286(x):
        c1, c2 = capacitances(par, x)
        return c2 / c1 - mu_c * mu_p
    x_286 = critical_stroke(m286, s_c)

    p2, p3, p4, u_cbv = steady_lowering(par, u, force)
    dp = p3 - p2
    factor = 2 * dp / (2 * dp + u_cbv * par["cbv.p_fo_cbv"])

    def m284(x):
        c1, c2 = capacitances(par, x, p3, p4, hoses=True)
        return c2 / c1 - mu_c * mu_p * factor
    x_284 = critical_stroke(m284, s_c)
    # the same without the hose compliance, to show what moves the boundary
    def m284r(x):
        c1, c2 = capacitances(par, x, p3, p4, hoses=False)
        return c2 / c1 - mu_c * mu_p * factor
    x_284r = critical_stroke(m284r, s_c)
    return {"x_287": x_287, "x_286": x_286, "x_284": x_284, "x_284_rigid": x_284r,
            "p2": p2, "p3": p3, "p4": p4, "u_cbv": u_cbv, "factor": factor}


def theta2(par, x):
    """Boom angle at stroke x: the cylinder l_retracted + x closes the triangle joint B - lower pin
    A - upper pin C (Fig. 2.1, eq. 2.1-2.7), solved by bisection."""
    q = lambda k: par["boom." + k]
    ax, ay = q("l2") + q("b2") - q("b1"), -(q("b8") - q("b3"))
    cx, cy = q("l1") + q("b4") - q("b7"), -(q("b5") + q("b6"))
    length = par["cylinder.l_retracted"] + x
    f = lambda th: math.hypot(math.cos(th) * cx - math.sin(th) * cy - ax,
                              math.sin(th) * cx + math.cos(th) * cy - ay) - length
    lo, hi = -1.2, 1.2
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if f(lo) * f(mid) <= 0 else (mid, hi)
    return 0.5 * (lo + hi)


def effective_mass(par, x):
    """Mass at the cylinder of the rigid boom, m_eff = J_B theta2'(x)^2 + m_rod (eq. 2.68), J_B of
    arm (uniform beam) and payload (point mass) about the joint (eq. 2.18)."""
    b7, l_arm, m_arm, m_pl = par["boom.b7"], par["boom.l_arm"], par["boom.m_arm"], par["payload.m"]
    pl = (l_arm - par["payload.x_inboard"] - b7, par["payload.h"])
    j_b = m_arm * l_arm ** 2 / 12 + m_arm * (l_arm / 2 - b7) ** 2 + m_pl * (pl[0] ** 2 + pl[1] ** 2)
    h = 1e-5
    d1 = (theta2(par, x + h) - theta2(par, x - h)) / (2 * h)
    return j_b * d1 * d1 + par["cylinder.m_rod"]


def frequencies(par, x, force, p3, p4):
    """Linearised eigenfrequencies (Hz) at stroke x with oil + hose capacitances: eq. 2.81's
    omega_n = A / sqrt(C1 m) with the thesis' m = F / g (eq. 2.69), and with both chambers as
    springs, sqrt((A^2 / C1 + (mu_c A)^2 / C2) / m), for m = F / g and for the boom's m_eff."""
    a, b = areas(par)
    c1, c2 = capacitances(par, x, p3, p4, hoses=True)
    w = lambda m, k: math.sqrt(k / m) / (2 * math.pi)
    m_g, m_eff = force / G, effective_mass(par, x)
    return (w(m_g, a * a / c1), w(m_g, a * a / c1 + b * b / c2), m_eff,
            w(m_eff, a * a / c1), w(m_eff, a * a / c1 + b * b / c2))


def mm(x):
    return "none (unstable at every stroke)" if x is None else f"{x * 1e3:.1f} mm"


# ---------------------------------------------------------------------------------------------
# 2. Simulation metrics


def p2p_and_frequency(t, p3):
    """Peak-to-peak of p3 and its frequency from upward crossings of the mid level."""
    if len(p3) < 3:
        return float("nan"), float("nan")
    level = 0.5 * (p3.max() + p3.min())
    i = np.where((p3[:-1] < level) & (p3[1:] >= level))[0]
    f = (len(i) - 1) / (t[i[-1]] - t[i[0]]) if len(i) >= 2 and np.ptp(p3) > 1e3 else float("nan")
    return np.ptp(p3), f


def metrics(boom, u, x0):
    t, p3, x = boom.run(u, x0)
    # valid until the bottom stop comes near (10 mm)
    end = t[-1] if x.min() > 0.01 else t[np.argmax(x <= 0.01)]
    early = (t >= 1.0) & (t <= 2.0)
    late = (t >= end - 1.0) & (t <= end)
    a_early, f_early = p2p_and_frequency(t[early], p3[early])
    a_late, f_late = p2p_and_frequency(t[late], p3[late])
    largest = max(np.ptp(p3[(t >= s) & (t < s + 0.5)]) for s in np.arange(0.0, end - 0.49, 0.25))
    return {"u": u, "x0": x0, "p3_hold": p3[0], "p2p_early": a_early, "f_early": f_early,
            "p2p_late": a_late, "f_late": f_late, "t_late": end, "x_late": x[t <= end][-1],
            "largest": largest, "limit_cycle": largest > LARGE}


def boundary(boom, u, lo, hi, tol=1e-3):
    """Bisection on the start stroke between lo (stays small) and hi (large limit cycle)."""
    assert not metrics(boom, u, lo)["limit_cycle"] and metrics(boom, u, hi)["limit_cycle"]
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if metrics(boom, u, mid)["limit_cycle"] else (mid, hi)
    return lo, hi


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--csv", action="store_true", help="write out/instability.csv")
    ap.add_argument("--png", action="store_true", help="write out/instability.png")
    ap.add_argument("--quick", action="store_true", help="skip the boundary bisection")
    args = ap.parse_args(argv)
    boom = Boom()
    par = boom.par
    a, b = areas(par)
    print(f"A = {a * 1e6:.1f} mm^2, mu_c A = {b * 1e6:.1f} mm^2, mu_c = {b / a:.4f}, "
          f"mu_p = {par['cbv.mu_p']:g}, s_c = {par['cylinder.stroke'] * 1e3:g} mm")

    print("\n1. Stability criterion of section 2.3 (stable for x <= x_c)")
    force = boom.run(0.0, 0.25, t_end=1e-3)[1][0] * a  # static load at mid stroke, FMU equilibrium
    crit = {}
    for u in (-0.05, -0.1):
        c = criterion(par, force, u)
        crit[u] = c
        f1, f2, m_eff, f3, f4 = frequencies(par, 0.25, force, c["p3"], c["p4"])
        print(f"  u = {u:+.2f}: steady lowering p2 = {c['p2'] / 1e5:.1f}, p3 = {c['p3'] / 1e5:.1f}, "
              f"p4 = {c['p4'] / 1e5:.1f} bar, u_cbv = {c['u_cbv']:.4f}, factor of 2.84 = {c['factor']:.4f}")
        print(f"    x_c eq. 2.87 (no volumes)          : {mm(c['x_287'])}")
        print(f"    x_c eq. 2.86 + line/dead volumes   : {mm(c['x_286'])}")
        print(f"    x_c eq. 2.84, oil-air beta, rigid  : {mm(c['x_284_rigid'])}")
        print(f"    x_c eq. 2.84 + hose compliance 5.2 : {mm(c['x_284'])}")
        print(f"    linear frequency at 250 mm, m = F/g = {force / G:.0f} kg: omega_n (2.81) {f1:.2f} Hz, "
              f"both chambers {f2:.2f} Hz; m_eff = {m_eff:.0f} kg: {f3:.2f} Hz, {f4:.2f} Hz")

    print("\n2. Lowering without pressure feedback, 10 s (p3 peak-to-peak in bar, frequency in Hz;"
          " 'late' = last second before 10 s or the bottom stop)")
    head = (f"{'u':>6} {'x0 mm':>6} {'p3 hold':>8} | {'early p2p':>9} {'f':>5} | "
            f"{'late p2p':>8} {'f':>5} {'at t':>5} {'x mm':>5} | {'max p2p':>7}  behaviour")
    print(head)
    rows = []
    for u in (-0.05, -0.1):
        for x0 in (0.06, 0.08, 0.10, 0.11, 0.12, 0.13, 0.14, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.48):
            m = metrics(boom, u, x0)
            rows.append(m)
            print(f"{u:6.2f} {x0 * 1e3:6.0f} {m['p3_hold'] / 1e5:8.1f} | {m['p2p_early'] / 1e5:9.1f} "
                  f"{m['f_early']:5.2f} | {m['p2p_late'] / 1e5:8.1f} {m['f_late']:5.2f} "
                  f"{m['t_late']:5.1f} {m['x_late'] * 1e3:5.0f} | {m['largest'] / 1e5:7.1f}  "
                  f"{'large limit cycle' if m['limit_cycle'] else 'stays small'}")

    if not args.quick:
        print("\n3. Start stroke where the behaviour changes (bisection to 1 mm) vs the criterion")
        for u in (-0.05, -0.1):
            small = [r["x0"] for r in rows if r["u"] == u and not r["limit_cycle"]]
            large = [r["x0"] for r in rows if r["u"] == u and r["limit_cycle"]]
            if not small or not large:
                print(f"  u = {u:+.2f}: no change of behaviour in the sweep")
                continue
            lo, hi = boundary(boom, u, max(x for x in small if x < min(large)), min(large))
            c = crit[u]
            print(f"  u = {u:+.2f}: boundary start stroke {lo * 1e3:.1f}..{hi * 1e3:.1f} mm; "
                  f"criterion 2.87: {mm(c['x_287'])}, 2.86 with volumes: {mm(c['x_286'])}, "
                  f"2.84 full: {mm(c['x_284'])}")

    out = OUT
    if args.csv or args.png:
        out.mkdir(exist_ok=True)
    if args.csv:
        keys = list(rows[0].keys())
        with open(out / "instability.csv", "w") as f:
            f.write(",".join(keys) + "\n")
            for r in rows:
                f.write(",".join(str(r[k]) for k in keys) + "\n")
        print(f"\nwrote {out / 'instability.csv'}")
    if args.png:
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        for u, c in ((-0.05, "C0"), (-0.1, "C1")):
            rs = [r for r in rows if r["u"] == u]
            ax[0].plot([r["x0"] * 1e3 for r in rs], [r["largest"] / 1e5 for r in rs], "o-", color=c,
                       label=f"u = {u}")
            t, p3, _ = boom.run(u, 0.48)
            ax[1].plot(t, p3 / 1e5, color=c, lw=0.6, label=f"u = {u}, from 480 mm")
        ax[0].axvline(crit[-0.05]["x_287"] * 1e3, color="k", ls="--", label="x_c eq. 2.87")
        ax[0].set(xlabel="start stroke [mm]", ylabel="largest p3 peak-to-peak [bar]")
        ax[1].set(xlabel="t [s]", ylabel="p3 [bar]")
        for a_ in ax:
            a_.legend()
            a_.grid(alpha=0.3)
        fig.tight_layout()
        figures.save(fig, out / "instability.png", dpi=120)
        print(f"wrote {out / 'instability.png'}")


if __name__ == "__main__":
    sys.exit(cli(main))
