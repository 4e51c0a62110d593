"""Plots the CSV tables of `boomsim analyze --sweep` (called by it; usage: python -m boomsim.plot_analysis DIR).

stability_boundary.png: largest closed-loop pole real part of eq. 2.82 along the stroke and the
critical stroke over the lowering flow, per pilot ratio (Table 4.3).
margins.png: stability-relevant gain and phase margins over n_omega per n_K (Fig. 6.4).
"""
import argparse
import csv
from collections import defaultdict
from pathlib import Path

import matplotlib.pyplot as plt

from . import figures


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def grouped(rows, key):
    groups = defaultdict(list)
    for r in rows:
        groups[float(r[key])].append(r)
    return sorted(groups.items())


def num(r, k):
    return float(r[k]) if r[k] not in ("", None) else float("nan")


def plot(out):
    out = Path(out)
    flow = grouped(read(out / "boundary_flow.csv"), "mu_p")
    simplified = {mu_p: num(rows[0], "xc_crit_simplified_mm") for mu_p, rows in flow}
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    for mu_p, rows in grouped(read(out / "boundary_stroke.csv"), "mu_p"):
        x = [num(r, "x_c_mm") for r in rows]
        line, = ax1.plot(x, [num(r, "max_pole_re") for r in rows], label=f"mu_p = {mu_p:g} (p4 = {num(rows[0], 'p4_bar'):.1f} bar)")
        ax1.axvline(simplified[mu_p], color=line.get_color(), ls=":", lw=1)
    ax1.axhline(0, color="k", lw=0.8)
    ax1.set(xlabel="stroke x_c [mm]", ylabel="max Re(pole) of eq. 2.82 [1/s]",
            title="Uncompensated closed loop along the stroke\n(dotted: simplified boundary, eq. 2.87)")
    ax1.legend(fontsize=8)
    for mu_p, rows in flow:
        q = [num(r, "q4_lpm") for r in rows]
        line, = ax2.plot(q, [num(r, "xc_crit_exact_mm") for r in rows], label=f"mu_p = {mu_p:g}, exact (2.84)")
        ax2.plot(q, [num(r, "xc_crit_simplified_mm") for r in rows], color=line.get_color(), ls=":")
    ax2.set(xlabel="lowering flow Q4 [l/min]", ylabel="critical stroke [mm] (stable below)",
            title="Stability boundary over the flow (dotted: eq. 2.87)", ylim=(0, 500))
    ax2.legend(fontsize=8)
    fig.tight_layout()
    figures.save(fig, out / "stability_boundary.png", dpi=120)

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    for n_k, rows in grouped(read(out / "margins.csv"), "n_K"):
        w = [num(r, "n_omega") for r in rows]
        ax1.semilogx(w, [num(r, "gain_margin_db") for r in rows], label=f"n_K = {n_k:g}")
        ax2.semilogx(w, [num(r, "phase_margin_deg") for r in rows], label=f"n_K = {n_k:g}")
    ax1.set(xlabel="n_omega [-]", ylabel="gain margin [dB]", title="(a) Gain margin (Fig. 6.4a)")
    ax2.set(xlabel="n_omega [-]", ylabel="phase margin [deg]", title="(b) Phase margin (Fig. 6.4b)")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    figures.save(fig, out / "margins.png", dpi=120)
    print(out / "stability_boundary.png")
    print(out / "margins.png")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir", help="the folder of boomsim analyze --sweep's CSV tables")
    plot(ap.parse_args(argv).dir)


if __name__ == "__main__":
    main()
