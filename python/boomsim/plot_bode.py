"""Bode plots of `boomsim linearize`: the responses of chosen outputs to the spool reference of
the HydraulicBoom at a steady lowering, open and closed with experiment B's filter; for p4 beside
section 2.3's reduced model at the same point (eq. 2.76, 2.81, 6.4, 6.8) and with the sine test's
points measured on the nonlinear closed loop. The defaults draw docs/linearize.md's figure: p4,
flexible arm, experiment B's steady lowering (u_ref = -0.05 at 250 mm).

Usage: plot_bode.py [--boom rigid|flexible] [--u-ref U] [--stroke MM] [--output NAME ...] [OUT.png]
(default docs/figures/linearize_bode.png); needs `cargo build --release`. About 5 s.
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt

from . import figures
from .errors import cli
from .paths import CHECKOUT, OUT, boomsim_binary

SINE_HZ = "0.5,1,1.5,2,2.5,3,4,5,7,10"


def linearize(point, *args):
    cmd = [str(boomsim_binary()), "linearize", *point, "--bode", "--json", *args]
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: {out.stderr.strip()}")
    return json.loads(out.stdout)


def plot(path, boom="flexible", u_ref=-0.05, stroke=250.0, outputs=("p4",)):
    """The Bode figure of `outputs` at the steady lowering (u_ref, stroke [mm]) saved to `path`."""
    path = Path(path)
    point = ["--boom", boom, "--u-ref", repr(u_ref), "--stroke", repr(stroke), *(a for o in outputs for a in ("--output", o))]
    open_loop = linearize(point)
    closed = linearize(point, "--feedback", *(["--sine", SINE_HZ] if "p4" in outputs else []))
    f = open_loop["bode"]["frequency_hz"]
    fig, (gain, phase) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    curves = []
    for k, name in enumerate(outputs):
        unit = open_loop["outputs"][k]["unit"]
        curves.append((open_loop["bode"]["channels"][k], f"{name}, full plant, {boom} boom, open loop", f"C{2 * k}", "-", unit))
        curves.append((closed["bode"]["channels"][k], f"{name}, full plant, {boom} boom, with B's filter", f"C{2 * k + 1}", "-", unit))
        if name == "p4":
            curves.append((open_loop["bode"]["reduced_p4"], "p4, reduced model (section 2.3), open loop", "C0", "--", unit))
            curves.append((closed["bode"]["reduced_p4"], "p4, reduced model, with B's filter (eq. 6.8)", "C1", "--", unit))
    for c, label, color, style, unit in curves:
        scale = 1e-5 if unit == "Pa" else 1.0  # pressures in bar
        gain.loglog(f, [abs(g) * scale for g in c["gain"]], style, color=color, label=label)
        phase.semilogx(f, c["phase_deg"], style, color=color, label=label)
    if "sine" in closed:
        points = closed["sine"]["points"]
        # The measured phases in the branch of the closed-loop curve they sit on.
        curve = closed["bode"]["channels"][list(outputs).index("p4")]

        def branch(p):
            near = min(range(len(f)), key=lambda k: abs(f[k] - p["frequency_hz"]))
            return p["phase_deg"] + 360 * round((curve["phase_deg"][near] - p["phase_deg"]) / 360)

        label = f"p4, sine test on the nonlinear closed loop ({closed['sine']['amplitude']:g} swing)"
        fx = [p["frequency_hz"] for p in points]
        gain.loglog(fx, [p["gain"] / 1e5 for p in points], "ko", mfc="none", label=label)
        phase.semilogx(fx, [branch(p) for p in points], "ko", mfc="none", label=label)
    units = sorted({"bar" if c[4] == "Pa" else c[4] for c in curves})
    gain.set_ylabel(f"|y / u_ref| [{', '.join(units)} per unit opening]")
    phase.set_ylabel("phase of y / u_ref [deg]")
    phase.set_xlabel("frequency [Hz]")
    for ax in (gain, phase):
        ax.grid(True, which="both", alpha=0.3)
    gain.legend(fontsize=8, loc="lower left")
    fig.suptitle(f"HydraulicBoom, {boom} boom: spool reference to {', '.join(outputs)}\n"
                 f"steady lowering at u_ref = {u_ref:g} through {stroke:g} mm (boomsim linearize)", fontsize=11)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figures.save(fig, path, dpi=110)
    return fig


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", nargs="?", type=Path, default=(CHECKOUT / "docs" / "figures" if CHECKOUT else OUT) / "linearize_bode.png")
    ap.add_argument("--boom", choices=["rigid", "flexible"], default="flexible")
    ap.add_argument("--u-ref", type=float, default=-0.05)
    ap.add_argument("--stroke", type=float, default=250.0, metavar="MM")
    ap.add_argument("--output", action="append", metavar="NAME", help="an output (repeatable; default p4)")
    a = ap.parse_args(argv)
    plot(a.out, a.boom, a.u_ref, a.stroke, tuple(a.output or ["p4"]))


if __name__ == "__main__":
    sys.exit(cli(main))
