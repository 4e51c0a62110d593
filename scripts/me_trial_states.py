"""Model Exchange at importers' tolerances where CVode tries states below vacuum (issue 49).

HydraulicBoom alone, rigid and flexible, lowering from rest with valve.u_ref in COMMANDS for 2 s,
through stock fmpy.simulate_fmu (CVode) at each rtol, against the FMU's own Co-Simulation at rtol
1e-9. One row a run: completed, min/max of p1..p4 at the output points (bar), p3's largest error
over the first 0.3 s (bar), and over 1-2 s the relative errors of p3's peak-to-peak, its dominant
frequency (only where the reference oscillates) and the lowering speed (cylinder.x's displacement
over the whole cycles of p3 there, as boomsim.metrics' v_steady: a window with a fraction of a
period left over would be biased by the oscillation's phase).

    PYTHONPATH=python .venv/bin/python scripts/me_trial_states.py [--rtol 1e-4 1e-3] [--u -0.3]
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

from boomsim.metrics import OSCILLATING, dominant_frequency, whole_cycles

FMU = str(Path(__file__).resolve().parent.parent / "target" / "fmu" / "HydraulicBoom.fmu")
COMMANDS = [-1.0, -0.7, -0.5, -0.3, -0.2, -0.1, -0.05]
OUTPUTS = ["p1", "p2", "p3", "p4", "cylinder.x"]


def run(interface, u, flexible, rtol, reached=None):
    """One run; `reached[0]`: the last output time."""
    def step_finished(t, _recorder):
        if reached is not None:
            reached[0] = t
        return True

    return simulate_fmu(FMU, fmi_type=interface, relative_tolerance=rtol, stop_time=2.0, output_interval=1e-3,
                        output=OUTPUTS, start_values={"boom.flexible": flexible, "valve.u_ref": u},
                        step_finished=step_finished)


def late(r):
    """Over 1-2 s: p3's peak-to-peak [bar], its dominant frequency [Hz] and that peak's amplitude
    [bar], and the lowering speed [m/s]."""
    k = r["time"] >= 1.0
    t, p3, x = r["time"][k], r["p3"][k], r["cylinder.x"][k]
    f, amp = dominant_frequency(t, p3)
    cycles = whole_cycles(t, p3) if amp / 1e5 >= OSCILLATING else None
    t_a, t_b = cycles if cycles else (t[0], t[-1])
    return np.ptp(p3) / 1e5, f, amp / 1e5, (np.interp(t_b, t, x) - np.interp(t_a, t, x)) / (t_b - t_a)


def row(u, flexible, rtol, ref):
    t0, reached = time.time(), [0.0]
    try:
        me = run("ModelExchange", u, flexible, rtol, reached)
    except Exception:  # fmpy raises on CVode's failure
        return [u, "flexible" if flexible else "rigid", rtol, f"no (t = {reached[0]:.3f} s)"] + ["-"] * 6, \
            time.time() - t0
    p = np.concatenate([me[n] for n in ("p1", "p2", "p3", "p4")]) / 1e5
    first = ref["time"] <= 0.3
    err = np.abs(np.interp(ref["time"][first], me["time"], me["p3"]) - ref["p3"][first]).max() / 1e5
    (pp_m, f_m, _, v_m), (pp_r, f_r, amp_r, v_r) = late(me), late(ref)
    rel = lambda a, b: f"{100 * (a / b - 1):+.2f}"
    return [u, "flexible" if flexible else "rigid", rtol, "yes", f"{p.min():.5f}", f"{p.max():.1f}", f"{err:.3f}",
            rel(pp_m, pp_r), rel(f_m, f_r) if amp_r >= OSCILLATING else "-", rel(v_m, v_r)], time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtol", type=float, nargs="+", default=[1e-4, 1e-3])
    ap.add_argument("--u", type=float, nargs="+", default=COMMANDS)
    ap.add_argument("--boom", nargs="+", choices=["rigid", "flexible"], default=["rigid", "flexible"])
    a = ap.parse_args()
    head = ["u_ref", "boom", "rtol", "completed", "min p [bar]", "max p [bar]", "p3 err 0-0.3 s [bar]",
            "p3 ptp 1-2 s [%]", "f_dom [%]", "speed [%]"]
    rows = []
    for boom in a.boom:
        for u in a.u:
            t0 = time.time()
            ref = run("CoSimulation", u, boom == "flexible", 1e-9)
            low = min(ref[n].min() for n in ("p2", "p3", "p4")) + 1.01325e5
            print(f"reference {boom} u_ref {u}: {time.time() - t0:.1f} s, lowest absolute pressure {low:.0f} Pa",
                  file=sys.stderr, flush=True)
            for rtol in a.rtol:
                r, dt = row(u, boom == "flexible", rtol, ref)
                print(f"  rtol {rtol:g}: {r[3]} ({dt:.1f} s)", file=sys.stderr, flush=True)
                rows.append(r)
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for r in rows:
        print("| " + " | ".join(f"{x:g}" if isinstance(x, float) else str(x) for x in r) + " |")
    return 0 if all(r[3] == "yes" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
