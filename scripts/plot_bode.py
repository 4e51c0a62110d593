"""The Bode plot of docs/linearize.md: p4's response to the spool reference of the HydraulicBoom
with the flexible arm, linearised at experiment B's steady lowering (u_ref = -0.05 at 250 mm) by
`boomsim linearize`, open and closed with experiment B's filter, beside section 2.3's reduced
model at the same point (eq. 2.76, 2.81, 6.4, 6.8), and the sine test's points measured on the
nonlinear closed loop.

Usage: plot_bode.py [OUT.png] (default docs/figures/linearize_bode.png); needs `cargo build
--release`. About 5 s.
"""

import json
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
BOOMSIM = ROOT / "target" / "release" / "boomsim"
SINE_HZ = "0.5,1,1.5,2,2.5,3,4,5,7,10"


def linearize(*args):
    cmd = [str(BOOMSIM), "linearize", "--boom", "flexible", "--output", "p4", "--bode", "--json", *args]
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: {out.stderr.strip()}")
    return json.loads(out.stdout)


def main(path):
    open_loop = linearize()
    closed = linearize("--feedback", "--sine", SINE_HZ)
    f = open_loop["bode"]["frequency_hz"]
    fig, (gain, phase) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    curves = [
        (open_loop["bode"]["channels"][0], "full plant, flexible arm, open loop", "C0", "-"),
        (open_loop["bode"]["reduced_p4"], "reduced model (section 2.3), open loop", "C0", "--"),
        (closed["bode"]["channels"][0], "full plant, flexible arm, with B's filter", "C3", "-"),
        (closed["bode"]["reduced_p4"], "reduced model, with B's filter (eq. 6.8)", "C3", "--"),
    ]
    for c, label, color, style in curves:
        gain.loglog(f, [g / 1e5 for g in c["gain"]], style, color=color, label=label)
        phase.semilogx(f, c["phase_deg"], style, color=color, label=label)
    points = closed["sine"]["points"]
    # The measured phases in the branch of the closed-loop curve they sit on.
    curve = closed["bode"]["channels"][0]
    def branch(p):
        near = min(range(len(f)), key=lambda k: abs(f[k] - p["frequency_hz"]))
        return p["phase_deg"] + 360 * round((curve["phase_deg"][near] - p["phase_deg"]) / 360)
    label = f"sine test on the nonlinear closed loop ({closed['sine']['amplitude']:g} swing)"
    gain.loglog([p["frequency_hz"] for p in points], [p["gain"] / 1e5 for p in points], "ko", mfc="none", label=label)
    phase.semilogx([p["frequency_hz"] for p in points], [branch(p) for p in points], "ko", mfc="none", label=label)
    gain.set_ylabel("|p4 / u_ref| [bar per unit opening]")
    phase.set_ylabel("phase of p4 / u_ref [deg]")
    phase.set_xlabel("frequency [Hz]")
    for ax in (gain, phase):
        ax.grid(True, which="both", alpha=0.3)
    gain.legend(fontsize=8, loc="lower left")
    fig.suptitle("HydraulicBoom, flexible arm: spool reference to p4\n"
                 "steady lowering at u_ref = -0.05 through 250 mm (boomsim linearize)", fontsize=11)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return fig


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "figures" / "linearize_bode.png")
