#!/usr/bin/env python3
"""Instability study of the HydraulicBoom FMU without pressure feedback (issue 3, item 5).

Lowering through the counterbalance valve (CBV) with a pressure-compensated valve oscillates
when the piston-side capacitance is large against the rod-side one (thesis section 2.3). This
script

1. prints the critical stroke x_c of the stability criterion of section 2.3 with the model's
   parameters at three levels of detail (eq. 2.87; eq. 2.86 with line and dead volumes; eq. 2.84
   with the oil-air law's bulk modulus at the steady pressures, the back pressure of the A->T
   edge, and with the hose compliance of eq. 5.2), the steady lowering state and the linear
   frequencies (eq. 2.81) at 250 mm: `boomsim criterion` (tools/src/analysis/criterion_cli.rs,
   the Rust physics; this script computes none of it);
2. simulates lowering with u = -0.05 and -0.1 from a range of start strokes (10 s, 1 ms steps,
   no feedback) and reports the p3 peak-to-peak amplitude and frequency early (1-2 s) and late
   (the last second before t = 10 s or the bottom stop), and whether the large limit cycle was
   reached (p3 peak-to-peak > 150 bar in some 0.5 s window);
3. bisects the start stroke where the behaviour changes (to 1 mm) and compares it with x_c.

Usage: boomsim-instability [--csv] [--png] [--quick]
(--csv/--png write out/instability.csv, out/instability.png; --quick skips the bisection).
Needs target/fmu/HydraulicBoom.fmu and the checkout's `boomsim` binary (cargo build --release &&
target/release/boomsim pack).
"""

import argparse
import json
import subprocess
import sys

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from . import figures
from .errors import UsageError, cli
from .paths import OUT, boomsim_binary, fmu

U_REFS = (-0.05, -0.1)
LARGE = 150e5  # p3 peak-to-peak of the large limit cycle (vacuum .. ~p_set)


class Boom:
    """The FMU and a lowering run."""

    def __init__(self, path=None):
        path = path or fmu("HydraulicBoom")
        self.md = read_model_description(str(path))
        self.dir = extract(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}

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
# 1. The criterion of section 2.3: `boomsim criterion`


def criterion(*args):
    """`boomsim criterion` at the lowerings U_REFS with `args` (e.g. "--json")."""
    cmd = [str(boomsim_binary()), "criterion", f"--u-ref={','.join(map(repr, U_REFS))}", *args]
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if r.returncode:
        raise UsageError(f"{' '.join(cmd)}: {r.stderr.strip()}")
    return r.stdout


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
    print(criterion(), end="")
    study = json.loads(criterion("--json"))
    crit = {c["u_ref"]: c["x_c_mm"] for c in study["lowerings"]}

    print("\n2. Lowering without pressure feedback, 10 s (p3 peak-to-peak in bar, frequency in Hz;"
          " 'late' = last second before 10 s or the bottom stop)")
    head = (f"{'u':>6} {'x0 mm':>6} {'p3 hold':>8} | {'early p2p':>9} {'f':>5} | "
            f"{'late p2p':>8} {'f':>5} {'at t':>5} {'x mm':>5} | {'max p2p':>7}  behaviour")
    print(head)
    rows = []
    for u in U_REFS:
        for x0 in (0.06, 0.08, 0.10, 0.11, 0.12, 0.13, 0.14, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.48):
            m = metrics(boom, u, x0)
            rows.append(m)
            print(f"{u:6.2f} {x0 * 1e3:6.0f} {m['p3_hold'] / 1e5:8.1f} | {m['p2p_early'] / 1e5:9.1f} "
                  f"{m['f_early']:5.2f} | {m['p2p_late'] / 1e5:8.1f} {m['f_late']:5.2f} "
                  f"{m['t_late']:5.1f} {m['x_late'] * 1e3:5.0f} | {m['largest'] / 1e5:7.1f}  "
                  f"{'large limit cycle' if m['limit_cycle'] else 'stays small'}")

    if not args.quick:
        print("\n3. Start stroke where the behaviour changes (bisection to 1 mm) vs the criterion")
        for u in U_REFS:
            small = [r["x0"] for r in rows if r["u"] == u and not r["limit_cycle"]]
            large = [r["x0"] for r in rows if r["u"] == u and r["limit_cycle"]]
            if not small or not large:
                print(f"  u = {u:+.2f}: no change of behaviour in the sweep")
                continue
            lo, hi = boundary(boom, u, max(x for x in small if x < min(large)), min(large))
            c = crit[u]
            print(f"  u = {u:+.2f}: boundary start stroke {lo * 1e3:.1f}..{hi * 1e3:.1f} mm; "
                  f"criterion 2.87: {c['2.87']:.1f} mm, 2.86 with volumes: {c['2.86']:.1f} mm, "
                  f"2.84 full: {c['2.84']:.1f} mm")

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
        ax[0].axvline(crit[-0.05]["2.87"], color="k", ls="--", label="x_c eq. 2.87")
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
