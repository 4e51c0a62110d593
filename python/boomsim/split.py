"""The split system through fmpy: HydraulicCircuit + BoomMechanics + PressureFeedbackController,
the same scenarios and recorded columns as boomsim.cosim (which runs the monolithic
HydraulicBoom), and the sweep of the communication step that finds each coupling's stable limit.

    boomsim-split U --coupling tlm [--boom rigid] [--step 1e-3]
    boomsim-split --sweep [--boom flexible]

Couplings (the port is documented in the FMUs and in the README, "Coupling your own mechanics"):
    plain    Gauss-Seidel: mechanics.doStep with F_k held -> x_k+1, v_k+1 -> the circuit steps
             with v linear from v_k to v_k+1 (fmi2SetRealInputDerivatives) -> F_k+1
    jacobi   plain, both step from the values at t_k (v held), as a parallel master does
    tlm      port.coupling = 1: waves c_h, c_m exchanged once per step (Jacobi), held over it
The controller is coupled to the circuit exactly as cosim.py couples it to HydraulicBoom.
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np
from fmpy.fmi1 import FMICallException

from . import cosim
from .errors import cli
from .fmus import FmuFile
from .result import COLUMNS, PLANT_OUT, Result
from .scenarios import load_scenario, reference
from . import metrics as mx
from . import regression

COUPLINGS = ("plain", "jacobi", "tlm", "tlm-jacobi")
#: Circuit outputs recorded (PLANT_OUT without the stroke and velocity, which come from
#: the mechanics).
CIRCUIT_OUT = [c for c in PLANT_OUT if not c.startswith("cylinder.")]


class Unstable(Exception):
    """The coupled run diverged (a step was refused or the motion left the stroke)."""


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
    mode = 1 if coupling.startswith("tlm") else 0
    circ = circ_f.slave(f"{scenario['id']}.circuit")
    mech = mech_f.slave(f"{scenario['id']}.mechanics")
    ctrl = ctrl_f.slave(f"{scenario['id']}.controller")
    vh, vm, vc = circ_f.vr, mech_f.vr, ctrl_f.vr
    try:
        for s in (circ, mech, ctrl):
            s.setupExperiment(tolerance=tolerance, startTime=0.0, stopTime=t_end)
            s.enterInitializationMode()
        x0 = scenario["start_stroke"]
        mech_f.set(mech, "start.x", x0)
        mech_f.set(mech, "boom.flexible", boom == "flexible")
        mech_f.set(mech, "port.coupling", mode)
        for k, v in own_params(mech_f, scenario["plant"]).items():
            mech_f.set(mech, k, v)
        mech.exitInitializationMode()
        f_start, x, v = mech.getReal([vm["start.F"], vm["cylinder.x"], vm["cylinder.v"]])
        for name, value in (("start.x", x0), ("start.F", f_start), ("port.coupling", mode),
                            ("cylinder.x", x), ("cylinder.v", v)):
            circ_f.set(circ, name, value)
        for k, val in own_params(circ_f, scenario["plant"]).items():
            circ_f.set(circ, k, val)
        circ.exitInitializationMode()
        p4 = circ.getReal([vh["p4"]])[0]
        enable = bool(ctrl_cfg["enable"])
        for name in ("K_f", "omega_f", "u_min", "u_max"):
            if name in ctrl_cfg:
                ctrl_f.set(ctrl, name, ctrl_cfg[name])
        ctrl_f.set(ctrl, "enable", enable)
        ctrl.setReal([vc["p"], vc["u_ref"]], [p4, reference(table, 0.0)])
        ctrl.exitInitializationMode()

        data = _loop((circ, circ_f), (mech, mech_f), (ctrl, ctrl_f), scenario, coupling, step, n, (x, v, p4))
    except FMICallException as e:
        raise Unstable(f"{coupling}, h = {step:g} s: an FMU refused a call ({e}), the run diverged") from e
    finally:
        for s in (circ, mech, ctrl):
            try:
                s.terminate()
            except Exception:  # noqa: BLE001 - terminate after an error may be refused
                pass
            s.freeInstance()
    return Result(scenario, boom, step, True, {c: data[:, i] for i, c in enumerate(COLUMNS)}, 0.0)


def _loop(circuit, mechanics, controller, scenario, coupling, step, n, start) -> np.ndarray:
    """The communication steps of `run` from the initialised (slave, FmuFile) pairs and the start
    values (x, v, p4): the recorded rows (COLUMNS)."""
    (circ, circ_f), (mech, mech_f), (ctrl, ctrl_f) = circuit, mechanics, controller
    vh, vm, vc = circ_f.vr, mech_f.vr, ctrl_f.vr
    x, v, p4 = start
    table = scenario["reference"]
    record_every = max(1, int(round(1e-3 / step)))
    out_h = [vh[c] for c in CIRCUIT_OUT]
    i_p4 = CIRCUIT_OUT.index("p4")
    rows = []
    y = circ.getReal(out_h)
    u_ref = reference(table, 0.0)
    stroke = circ.getReal([vh["cylinder.stroke"]])[0]
    for k in range(n + 1):
        t = k * step
        u, u_comp = ctrl.getReal([vc["u"], vc["u_comp"]])
        circ.setReal([vh["valve.u_ref"]], [u])
        if k % record_every == 0:
            rec = dict(zip(CIRCUIT_OUT, y), **{"cylinder.x": x, "cylinder.v": v})
            rows.append([t, u_ref, u_comp, u, *(rec[c] for c in PLANT_OUT)])
        if k == n:
            break
        if not (-0.05 < x < stroke + 0.05) or not all(map(math.isfinite, y)):
            raise Unstable(f"{coupling}, h = {step:g} s: the motion diverged at t = {t:.4g} s (x = {x:.4g} m)")
        if coupling.startswith("tlm"):
            c_h, = circ.getReal([vh["port.c_h"]])
            c_m, = mech.getReal([vm["port.c_m"]])
            mech.setReal([vm["port.c_h"]], [c_h])
            circ.setReal([vh["port.c_m"]], [c_m])
            if coupling == "tlm":
                mech.doStep(t, step)
                c_m1, = mech.getReal([vm["port.c_m"]])
                circ.setRealInputDerivatives([vh["port.c_m"]], [1], [(c_m1 - c_m) / step])
                circ.doStep(t, step)
            else:
                circ.doStep(t, step)
                mech.doStep(t, step)
            x, v = mech.getReal([vm["cylinder.x"], vm["cylinder.v"]])
        else:
            mech.setReal([vm["cylinder.F"]], circ.getReal([vh["cylinder.F"]]))
            if coupling == "jacobi":
                circ.doStep(t, step)
            mech.doStep(t, step)
            x1, v1 = mech.getReal([vm["cylinder.x"], vm["cylinder.v"]])
            if coupling == "plain":
                circ.setRealInputDerivatives([vh["cylinder.v"]], [1], [(v1 - v) / step])
                circ.doStep(t, step)
            x, v = x1, v1
            circ.setReal([vh["cylinder.x"], vh["cylinder.v"]], [x, v])
        y = circ.getReal(out_h)
        p4_next = y[i_p4]
        ctrl.setRealInputDerivatives([vc["p"]], [1], [(p4_next - p4) / step])
        ctrl.doStep(t, step)
        p4 = p4_next
        u_ref = reference(table, t + step)
        ctrl.setReal([vc["p"], vc["u_ref"]], [p4, u_ref])
    return np.array(rows)


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


def stable(boom: str, coupling: str, step: float, alpha: float = 0.0) -> tuple[bool, str]:
    """(stable, why) for the LIFT scenario with `step` and TLM wave damping `alpha`: the run
    completes within the stroke and p3 rings down (`rings_down`)."""
    sc = dict(LIFT, plant={"port.alpha": alpha})
    try:
        return rings_down(run(sc, boom, coupling, step))
    except Unstable as e:
        return False, str(e)


def sweep(boom: str, couplings=COUPLINGS, steps=SWEEP_STEPS, alpha: float = 0.0) -> dict:
    """{coupling: (largest stable step, {step: (stable, why)})}; the sweep of a coupling stops at
    its first unstable step."""
    out = {}
    for c in couplings:
        rows, largest = {}, None
        for h in steps:
            rows[h] = stable(boom, c, h, alpha)
            if not rows[h][0]:
                break
            largest = h
        out[c] = (largest, rows)
    return out


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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", nargs="?", default="U")
    ap.add_argument("--boom", default="rigid")
    ap.add_argument("--coupling", default="tlm", choices=COUPLINGS)
    ap.add_argument("--step", type=float, default=None)
    ap.add_argument("--sweep", action="store_true", help="largest stable step of each coupling")
    ap.add_argument("--alpha", type=float, default=0.0, help="TLM wave damping port.alpha of the sweep")
    args = ap.parse_args(argv)
    sc = load_scenario(args.scenario)
    if args.sweep:
        couplings = COUPLINGS if args.alpha == 0 else ("tlm", "tlm-jacobi")
        for c, (largest, rows) in sweep(args.boom, couplings, alpha=args.alpha).items():
            print(f"{args.boom} alpha {args.alpha:g} {c:10s} largest stable step {largest}:",
                  "; ".join(f"{h * 1e3:g} ms {'stable' if ok else 'UNSTABLE'} ({why})" for h, (ok, why) in rows.items()),
                  flush=True)
        return
    mono = mx.compute(cosim.run(sc, args.boom, args.step))
    split = mx.compute(run(sc, args.boom, args.coupling, args.step))
    for k, (m, s, ok) in compare(mono, split).items():
        print(f"{k:16s} {regress_fmt(m):>10s} {regress_fmt(s):>10s} {'ok' if ok else 'DIFFERS'}")


def regress_fmt(x) -> str:
    return "-" if x is None else f"{x:.4g}"


if __name__ == "__main__":
    sys.exit(cli(main))
