"""The split system through fmpy: HydraulicCircuit + BoomMechanics + PressureFeedbackController,
the same scenarios and recorded columns as boomsim.cosim (which runs the monolithic
HydraulicBoom), and the sweep of the communication step that finds each coupling's stable limit.

    boomsim-split U --coupling tlm [--boom rigid] [--step 1e-3]
    boomsim-split --sweep [--boom flexible]
    boomsim-split --table                           docs/coupling.md's equivalence tables

The couplings are boomsim.coupled's (docs/coupling.md); the mechanics is BoomMechanics through
boomsim.mechanics. The controller is coupled to the circuit exactly as cosim.py couples it to
HydraulicBoom.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from fmpy.fmi1 import FMICallException

from . import cosim
from .coupled import COUPLINGS, PORT_CODES, Drive, Unstable, loop, start_circuit, start_controller
from .errors import cli
from .fmus import FmuFile, release
from .mechanics import BoomMechanicsFmu
from .result import COLUMNS, Result
from .scenarios import load_scenario, reference
from . import metrics as mx
from . import regression


def own_params(fmu: FmuFile, plant: dict) -> dict:
    """The entries of a scenario's [plant] table that `fmu` has."""
    return {k: v for k, v in plant.items() if k in fmu.vars}


def run(scenario: dict, boom: str = "rigid", coupling: str = "tlm", step: float | None = None,
        stop_time: float | None = None, tolerance: float | None = None) -> Result:
    """Co-simulate one scenario with the split plant (feedback from t = 0). Raises Unstable when
    the coupled system diverges."""
    if coupling not in COUPLINGS:
        raise ValueError(f"coupling must be one of {COUPLINGS}")
    circ_f, mech_f, ctrl_f = (FmuFile.get(i) for i in ("HydraulicCircuit", "BoomMechanics",
                                                               "PressureFeedbackController"))
    t_end = scenario["stop_time"] if stop_time is None else stop_time
    step = scenario["step"] if step is None else step
    n = int(round(t_end / step))
    ctrl_cfg, table = scenario["controller"], scenario["reference"]
    port = "tlm" if coupling.startswith("tlm") else "plain"
    circ = circ_f.slave(f"{scenario['id']}.circuit")
    mech = mech_f.slave(f"{scenario['id']}.mechanics")
    ctrl = ctrl_f.slave(f"{scenario['id']}.controller")
    try:
        for s in (circ, mech, ctrl):
            s.setupExperiment(tolerance=tolerance, startTime=0.0, stopTime=t_end)
            s.enterInitializationMode()
        x0 = scenario["start_stroke"]
        mech_f.set(mech, "start.x", x0)
        mech_f.set(mech, "boom.flexible", boom == "flexible")
        mech_f.set(mech, "port.coupling", PORT_CODES[port])
        for k, v in own_params(mech_f, scenario["plant"]).items():
            mech_f.set(mech, k, v)
        mech.exitInitializationMode()
        mechanics = BoomMechanicsFmu(mech_f, mech, port)
        (x,), (v,) = mechanics.motion()
        start_circuit(circ_f, circ, port, x, v, mechanics.holding_force()[0], own_params(circ_f, scenario["plant"]))
        start_controller(ctrl_f, ctrl, ctrl_cfg, circ.getReal([circ_f.vr["p4"]])[0], reference(table, 0.0))
        drive = Drive(circ, circ_f, table, ctrl, ctrl_f)
        data, = loop([drive], mechanics, coupling, step, n, max(1, int(round(1e-3 / step))))
    except FMICallException as e:
        raise Unstable(f"{coupling}, h = {step:g} s: an FMU refused a call ({e}), the run diverged") from e
    finally:
        release(circ, mech, ctrl)
    return Result(scenario, boom, step, True, {c: data[:, i] for i, c in enumerate(COLUMNS)}, 0.0)


#: Steps of the stability sweep [s].
SWEEP_STEPS = (2.5e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2)

#: The stability scenario: lift at 30 % from 250 mm for 1 s, then close the valve and hold for 2 s.
#: Physically the boom then rings down on the oil column (the check valve and friction damp it):
#: a coupling that feeds energy in shows as an oscillation that does not decay.
LIFT = {"id": "lift", "stop_time": 3.0, "start_stroke": 0.25, "plant": {}, "step": 1e-3,
        "controller": {"enable": False}, "starts": ["t0"], "reference": np.array([[0.0, 0.3], [1.0, 0.3], [1.0, 0.0], [3.0, 0.0]])}
#: p3 swing below which the boom counts as at rest [Pa].
REST_PTP = 0.1e5


def rings_down(r: Result) -> tuple[bool, str]:
    """Whether p3 of a LIFT run comes to rest: its swing over the last 0.5 s is below REST_PTP or
    below 80 % of the swing over the 0.5 s before (a decaying ring-down); a sustained or growing
    oscillation fails."""
    t, p3 = r.data["time"], r.data["p3"]
    late = float(np.ptp(p3[t >= t[-1] - 0.5]))
    mid = float(np.ptp(p3[(t >= t[-1] - 1.0) & (t < t[-1] - 0.5)]))
    return late < REST_PTP or late < 0.8 * mid, f"p3 swing {mid / 1e5:.3g} -> {late / 1e5:.3g} bar over the last 2 x 0.5 s"


def stable(boom: str, coupling: str, step: float, alpha: float = 0.0, runner=None) -> tuple[bool, str]:
    """(stable, why) for the LIFT scenario with `step` and TLM wave damping `alpha`: the run
    completes within the stroke and p3 rings down (`rings_down`). `runner(scenario, coupling,
    step)`: the coupled run (default: `run` with BoomMechanics and `boom`)."""
    sc = dict(LIFT, plant={"port.alpha": alpha})
    runner = runner or (lambda s, c, h: run(s, boom, c, h))
    try:
        return rings_down(runner(sc, coupling, step))
    except Unstable as e:
        return False, str(e)


def sweep(boom: str, couplings=COUPLINGS, steps=SWEEP_STEPS, alpha: float = 0.0, runner=None) -> dict:
    """{coupling: (largest stable step, {step: (stable, why)})}; the sweep of a coupling stops at
    its first unstable step."""
    out = {}
    for c in couplings:
        rows, largest = {}, None
        for h in steps:
            rows[h] = stable(boom, c, h, alpha, runner)
            if not rows[h][0]:
                break
            largest = h
        out[c] = (largest, rows)
    return out


def print_sweep(label: str, result: dict) -> None:
    """One line per coupling of a `sweep` result."""
    for c, (largest, rows) in result.items():
        print(f"{label} {c:10s} largest stable step {largest}:",
              "; ".join(f"{h * 1e3:g} ms {'stable' if ok else 'UNSTABLE'} ({why})" for h, (ok, why) in rows.items()),
              flush=True)


def compare(a: dict, b: dict, rel: float = 0.02) -> dict:
    """{metric: (monolithic, split, ok)}: ok when |split - mono| <= rel |mono| + the absolute floor
    of the package's baselines/tolerances.toml (a 2 % band around a near-zero value, e.g. the residual
    p3 swing of a settled run, is below the metric's own resolution)."""
    tol = regression.load_tolerances()
    out = {}
    for k in regression.ORDER:
        if k not in a:
            continue
        m, s = a[k], b.get(k)
        rule = tol.get(k, {})
        cond = rule.get("only_if")
        if cond and (a.get(cond[0]) or 0.0) < cond[1] and (b.get(cond[0]) or 0.0) < cond[1]:
            out[k] = (m, s, True)
            continue
        if m is None or s is None:
            out[k] = (m, s, m is s)
            continue
        out[k] = (m, s, abs(s - m) <= rel * abs(m) + rule.get("abs", 0.0))
    return out


#: The equivalence tables of docs/coupling.md: per scenario and boom, the couplings and steps
#: against HydraulicBoom + controller at 1 ms.
TABLES = {
    ("U", "rigid"): [("tlm", 1e-3), ("plain", 1e-3), ("plain", 5e-4), ("plain", 2.5e-4), ("plain", 1e-4)],
    ("B", "rigid"): [("tlm", 1e-3), ("plain", 1e-3)],
    ("B", "flexible"): [("tlm", 1e-3), ("plain", 1e-3)],
    ("U", "flexible"): [("tlm", 2e-3), ("tlm", 1e-3), ("tlm", 5e-4), ("tlm", 2.5e-4), ("tlm-jacobi", 1e-3)],
}


def print_tables() -> None:
    """docs/coupling.md's equivalence tables: each metric of the monolithic run and of the split
    one per coupling and step, (!) where it leaves 2 % + the metric's floor (`compare`)."""
    for (sid, boom), cases in TABLES.items():
        sc = load_scenario(sid)
        mono = mx.compute(cosim.run(sc, boom, 1e-3))
        got = [compare(mono, mx.compute(run(sc, boom, c, h))) for c, h in cases]
        print(f"\n{sid}-{boom}:\n")
        print("| metric | monolithic | " + " | ".join(f"{c} {h * 1e3:g} ms" for c, h in cases) + " |")
        print("|---|---|" + "---|" * len(cases))
        for k in got[0]:
            cells = [f"{regress_fmt(g[k][1])}{'' if g[k][2] else ' (!)'}" for g in got]
            print(f"| {k} | {regress_fmt(mono[k])} | " + " | ".join(cells) + " |", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", nargs="?", default="U")
    ap.add_argument("--boom", default="rigid")
    ap.add_argument("--coupling", default="tlm", choices=COUPLINGS)
    ap.add_argument("--step", type=float, default=None)
    ap.add_argument("--sweep", action="store_true", help="largest stable step of each coupling")
    ap.add_argument("--alpha", type=float, default=0.0, help="TLM wave damping port.alpha of the sweep")
    ap.add_argument("--table", action="store_true", help="docs/coupling.md's equivalence tables (TABLES)")
    args = ap.parse_args(argv)
    if args.table:
        print_tables()
        return
    sc = load_scenario(args.scenario)
    if args.sweep:
        couplings = COUPLINGS if args.alpha == 0 else ("tlm", "tlm-jacobi")
        print_sweep(f"{args.boom} alpha {args.alpha:g}", sweep(args.boom, couplings, alpha=args.alpha))
        return
    mono = mx.compute(cosim.run(sc, args.boom, args.step))
    split = mx.compute(run(sc, args.boom, args.coupling, args.step))
    for k, (m, s, ok) in compare(mono, split).items():
        print(f"{k:16s} {regress_fmt(m):>10s} {regress_fmt(s):>10s} {'ok' if ok else 'DIFFERS'}")


def regress_fmt(x) -> str:
    return "-" if x is None else f"{x:.4g}"


if __name__ == "__main__":
    sys.exit(cli(main))
