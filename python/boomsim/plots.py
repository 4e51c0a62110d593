"""The figure of one run: pressures, cylinder velocity and spool openings over time."""

from __future__ import annotations

import math

import numpy as np

from . import figures
from .result import Result

BAR = 1e5


def series(res: Result) -> list[tuple[int, str, np.ndarray]]:
    """What the plot draws: (panel, legend label, values). The signs are the FMUs' and the
    CSVs' (lowering: v < 0, u < 0), the same as the title's u_ref; the thesis' figures show
    lowering as positive (its simulation tool's sign), which the axis labels say is not done here."""
    d, sc = res.data, res.scenario
    q_rated = 25e-3 / 60
    a_rod = math.pi / 4 * (0.065**2 - 0.035**2)
    v_expected = q_rated * sc["reference"][-1, 1] / a_rod * 1e3  # steady velocity, sign of u_ref
    return [
        (0, "p3 piston side", d["p3"] / BAR),
        (0, "p4 rod side (fed back)", d["p4"] / BAR),
        (0, "p2 CBV back pressure", d["p2"] / BAR),
        (1, "v_c", d["cylinder.v"] * 1e3),
        (1, "Q_rated u_ref / A_rod", np.full_like(d["time"], v_expected)),
        (2, "u_ref (operator)", d["u_ref"]),
        (2, "u_comp (feedback)", d["u_comp"]),
        (2, "u (main spool opening)", d["valve.u"]),
    ]


def plot(res: Result, path, metrics: dict | None = None, zoom: float = 3.0):
    """p3/p4, cylinder velocity and spool openings over time, like thesis Fig. 6.7-6.12
    (simulation) and 7.1-7.6 (rig), in the FMUs' signs ([`series`]: lowering < 0)."""
    import matplotlib.pyplot as plt

    d = res.data
    t = d["time"]
    sc = res.scenario
    fig, axes = plt.subplots(3, 2, sharex="col", figsize=(13, 9), constrained_layout=True,
                             gridspec_kw={"width_ratios": [3, 2]})
    drawn = series(res)
    for col, t_max in ((0, t[-1]), (1, min(zoom, t[-1]))):
        ax = axes[:, col]
        for panel, label, y in drawn:
            style = {"color": "k", "ls": ":", "lw": 1} if label.startswith("Q_rated") else {}
            ax[panel].plot(t, y, label=label, **style)
        ax[0].set_ylabel("pressure (gauge) [bar]")
        ax[1].set_ylabel("cylinder velocity, lowering < 0 [mm/s]")
        ax[2].set_ylabel("spool opening, lowering < 0 [-]")
        a = ax[2]
        a.set_xlabel("time [s]")
        a.set_xlim(0, t_max)
        for a in ax:
            a.grid(alpha=0.3)
            if col == 0:
                a.legend(loc="upper right", fontsize=8)
        ax[0].set_title("whole record" if col == 0 else f"first {t_max:g} s", fontsize=9)
    c = sc["controller"]
    filt = (f"K_f = {c['K_f']:.3g} m^4s^2/kg, omega_f = {c['omega_f']:.4g} rad/s" if c["enable"]
            else "no compensation")
    if c["enable"] and res.feedback_on_at not in (None, 0.0):
        filt += f", feedback on at {res.feedback_on_at:.3f} s (CBV open)"
    title = f"{sc['id']} ({res.boom} boom): u_ref = {sc['reference'][-1, 1]:+.2f}, {filt}, {res.interface or f'communication step {res.step:g} s'}"
    if metrics:
        tm = metrics.get("t_motion")
        title += "\nload starts lowering (CBV flow) at " + (f"{tm:.2f} s" if tm is not None else "- (never)")
        ts = metrics.get("t_settle")
        title += f"; p3 settles (2 %) at {ts:.2f} s" if ts is not None else "; p3 does not settle (2 %)"
    fig.suptitle(title, fontsize=10)
    axes[0, 0].figure.align_ylabels(axes[:, 0])
    figures.save(fig, path, dpi=90)
    plt.close(fig)


def plot_u_against_b(u: Result, b: Result, path) -> None:
    """The README's figure: the piston-side pressure p3 and the cylinder velocity of experiment U
    (no feedback: the lowering oscillates, thesis 7.1) against B (the high-pass-filtered pressure
    feedback: it settles, 9.1), in the FMUs' signs (lowering < 0)."""
    import matplotlib.pyplot as plt

    fig, (p, v) = plt.subplots(2, 1, sharex=True, figsize=(10, 5.5), constrained_layout=True)
    for res in (u, b):
        t = res.data["time"]
        p.plot(t, res.data["p3"] / BAR, label=res.scenario["title"], lw=1)
        v.plot(t, res.data["cylinder.v"] * 1e3, lw=1)
    p.set(ylabel="p3, piston side [bar]", title="Lowering the load: the counterbalance valve oscillates without "
          "the feedback (U) and settles with it (B)")
    v.set(ylabel="cylinder velocity [mm/s]", xlabel="time [s]", xlim=(0, max(u.data["time"][-1], b.data["time"][-1])))
    p.legend(loc="upper right")
    for a in (p, v):
        a.grid(alpha=0.3)
    figures.save(fig, path, dpi=100)
    plt.close(fig)
