"""The linear analysis of a sweep point (boomsim.parameter_sweep): its operating point and `boomsim
analyze` there, shared by the sweep (filter factors n_K, n_omega) and its summary (the stability
boundary)."""

from __future__ import annotations

import functools
import json
import subprocess

from .errors import UsageError
from .fmus import FmuFile
from .paths import boomsim_binary


def operating_point(sweep: dict, values: dict) -> dict:
    """The `boomsim analyze` options of a point's operating point: stroke start.x [mm], the
    CBV's pilot ratio and set pressure [bar], the rigid boom's payload [kg], bulk modulus [MPa]
    and the steady lowering flow Q4 = valve.q_rated |u_ref| [l/min] of the final reference (the
    pressure-compensated spool). Each from the point, else the scenario, else the FMU's start
    value."""
    sc = sweep["scenario"]
    plant = FmuFile.get("HydraulicBoom")

    def value(name: str) -> float:
        if name in values:
            return float(values[name])
        if name in sc["plant"]:
            return float(sc["plant"][name])
        return float(sc["start_stroke"]) if name == "start.x" else float(plant.vars[name].start)

    return {"xc": value("start.x") * 1e3, "mu-p": value("cbv.mu_p"), "p-set": value("cbv.p_set") / 1e5,
            "payload": value("payload.m"), "beta": value("fluid.beta") / 1e6,
            "q4": value("valve.q_rated") * abs(float(sc["reference"][-1, 1])) * 6e4}


@functools.cache
def analyze(op: tuple, n_k: tuple = (1.0,), n_omega: tuple = (1.0,)) -> dict:
    """`boomsim analyze --json` at the operating point `op` (the items of `operating_point`)
    for the filters n_k x n_omega."""
    exe = boomsim_binary()
    args = [f"--{k}={v!r}" for k, v in op] + ["--n-k", ",".join(map(repr, n_k)), "--n-omega", ",".join(map(repr, n_omega))]
    r = subprocess.run([str(exe), "analyze", "--json", *args], capture_output=True, text=True)
    if r.returncode:
        raise UsageError(f"no linear analysis at {', '.join(f'{k} = {v:g}' for k, v in op)}: {r.stderr.strip()}")
    return json.loads(r.stdout)
