"""The native runner: a scenario variant through `boomsim cosim`, the Rust loop that calls the FMUs'
code in-process (the sweeps' fast runner; a checkout's binary)."""

from __future__ import annotations

import json
import subprocess

import numpy as np

from .cosim import schedule
from .fmus import FmuFile, boom_switch, with_params
from .metrics import CBV_OPEN
from .paths import boomsim_binary
from .result import COLUMNS, PLANT_OUT, Result
from .scenarios import communication_references, controller_start, plant_start


def run_native(scenario: dict, boom: str = "rigid", step: float | None = None, stop_time: float | None = None,
               interpolate: bool = True, record_every: int | None = None, feedback_start: str | None = None,
               params: dict | None = None, timeout: float | None = None) -> Result:
    """`run` (FMI 2.0) through `boomsim cosim`: the same coupling with the FMUs' code called
    in-process by the Rust loop instead of through fmpy, the same rows bit for bit. `timeout`:
    the process is killed beyond it (TimeoutError); a failure is a RuntimeError with the
    message."""
    plant_f = FmuFile.get("HydraulicBoom")
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end, step, n, record_every, fb_start = schedule(scenario, step, stop_time, record_every, feedback_start)
    table = scenario["reference"]
    # The reference at the communication points as `run` computes them (t = k step, then t + step).
    u_ref = communication_references(table, step, n)
    request = {"stop_time": t_end, "step": step, "record_every": record_every, "interpolate": interpolate,
               "feedback_start": fb_start, "enable": bool(scenario["controller"]["enable"]),
               "u_ref": u_ref, "outputs": PLANT_OUT, "cbv_open": CBV_OPEN,
               "plant": plant_start(scenario, switch), "controller": controller_start(scenario, ctrl_params)}
    binary = boomsim_binary()
    try:
        r = subprocess.run([str(binary), "cosim"], input=json.dumps(request).encode(), capture_output=True,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        raise TimeoutError(f"exceeded the timeout of {timeout:g} s (boomsim cosim killed)") from None
    if r.returncode:
        raise RuntimeError(r.stderr.decode().strip())
    head, _, body = r.stdout.partition(b"\n")
    h = json.loads(head)
    data = np.frombuffer(body, dtype="<f8").reshape(h["rows"], h["columns"])
    return Result(scenario, boom, step, interpolate, {c: data[:, i] for i, c in enumerate(COLUMNS)},
                  h["feedback_on_at"], fb_start, counts={"rhs": int(h["rhs"])},
                  interface=f"native Co-Simulation FMI 2.0, step {step * 1e3:g} ms")
