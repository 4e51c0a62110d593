"""The experiments at the rig's control-loop period, with either model of the valve electronics.

    boomsim-rig-loop [--step 5e-3] [--boom rigid] [--p4 BAR] [--only B,C2.1]
        [--out out/rig_loop]

The rig's real-time controller runs its loops at 5 ms and slower (thesis 4.2.2), so the
feedback's command is held for 5 ms. Every compensated scenario of the catalogue (A, B, C)
runs at that step twice: with the first-order spool lag of eq. 2.45 (the thesis' model and the
FMU's default) and with the PVES position loop (`valve.omega_loop`, speeds of Table 4.2). The
table (stdout and <out>/summary.md) gives, per run, the lowering speed against the rated one
(metrics.expected_velocity), the p3 peak-to-peak of the last third, its dominant frequency, the 2 %
settling time and the thesis' verdict (chapter 8.2), for the README's "Valve electronics" notes.
About 1 s per run with the rigid boom (24 runs), 10 s per run with the flexible one.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from . import cosim
from .errors import cli
from .paths import OUT
from .scenarios import load_scenario
from . import metrics

#: The rig's loop period: the real-time controller's cycle times start at 5 ms (thesis 4.2.2).
RIG_STEP = 5e-3
#: Gain of the PVES position loop (rad/s) used for the rig. Neither the thesis nor the data sheet
#: gives it; from about 300 rad/s on, the speed limits of Table 4.2 decide (README, "Valve
#: electronics": the catalogue at 1 ms is the same to 3 digits for 1000, 3000 and 10000 rad/s).
LOOP_GAIN = 1000.0
#: The two models of the valve electronics: FMU parameters by name.
MODELS = {"lag": {}, "PVES loop": {"valve.omega_loop": LOOP_GAIN}}
#: The compensated experiments of chapter 7.
CATALOGUE = ["A", "B", "C1.1", "C1.2", "C1.3", "C2.1", "C2.2", "C2.3", "C3.1", "C3.2", "C3.3"]


def run(scenario: dict, model: str, step: float = RIG_STEP, boom: str = "rigid", p4: float | None = None,
        tolerance: float | None = None):
    """One run at `step` with the valve model `model`, the feedback from the step (t0), the
    rod side pre-charged to `p4` bar if given, the plant's integrator at `tolerance` (default:
    the scenario's)."""
    params = dict(MODELS[model])
    if p4 is not None:
        params["start.p4"] = p4 * metrics.BAR
    return cosim.run(scenario, boom, step=step, feedback_start="t0", params=params, tolerance=tolerance)


def row(scenario: dict, model: str, step: float, boom: str, p4: float | None) -> dict:
    """The table's numbers of one run (`run`)."""
    m = metrics.compute(run(scenario, model, step, boom, p4))
    return {
        "speed": m["v_steady"] / m["v_expected"],
        "p3_pp_late": m["p3_pp_late"],
        "f_dom": m["f_dom"],
        "t_settle": m["t_settle"],
    }


def table(results: dict, scenarios: dict) -> str:
    """The Markdown table: one line per scenario, both models side by side."""
    head = "| run | " + " | ".join(f"{m}: speed, p3 pp (bar), f (Hz), settled (s)" for m in MODELS)
    lines = [head + " | thesis (8.2) |", "|" + " --- |" * (len(MODELS) + 2)]
    for sid, by_model in results.items():
        cells = []
        for m in MODELS:
            r = by_model[m]
            settled = "-" if r["t_settle"] is None else f"{r['t_settle']:.2f}"
            cells.append(f"{r['speed']:.2f}, {r['p3_pp_late']:.1f}, {r['f_dom']:.1f}, {settled}")
        lines.append(f"| {sid} | " + " | ".join(cells) + f" | {scenarios[sid]['expect']} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--step", type=float, default=RIG_STEP, help="communication step [s] (default 5e-3)")
    ap.add_argument("--boom", choices=["rigid", "flexible"], default="rigid")
    ap.add_argument("--p4", type=float, help="pre-charged rod side at the start [bar] (start.p4)")
    ap.add_argument("--only", help="comma-separated scenario ids (default: A, B and C)")
    ap.add_argument("--out", type=pathlib.Path, default=OUT / "rig_loop")
    args = ap.parse_args(argv)
    ids = args.only.split(",") if args.only else CATALOGUE
    scenarios = {sid: load_scenario(sid) for sid in ids}
    results, k, n = {}, 0, len(ids) * len(MODELS)
    for sid, sc in scenarios.items():
        results[sid] = {}
        for m in MODELS:
            k += 1
            print(f"rig_loop: [{k}/{n}] {sid}, {m}, {args.boom} boom, step {args.step * 1e3:g} ms",
                  file=sys.stderr, flush=True)
            results[sid][m] = row(sc, m, args.step, args.boom, args.p4)
    text = table(results, scenarios)
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    start = "tank pressure" if args.p4 is None else f"start.p4 = {args.p4:g} bar"
    (args.out / "summary.md").write_text(
        f"# Step {args.step * 1e3:g} ms, {args.boom} boom, rod side at {start}\n\n{text}\n")
    return 0


if __name__ == "__main__":
    sys.exit(cli(main))
