"""Coupled co-simulation of the two boomsim FMUs through fmpy (FMI 2.0 Co-Simulation; FMI 3.0
with --fmi 3).

    HydraulicBoom.p4 --> PressureFeedbackController.p
    operator reference u_ref(t) (time table) --> PressureFeedbackController.u_ref
    PressureFeedbackController.u --> HydraulicBoom.valve.u_ref

Usage:
    .venv/bin/python scripts/cosim.py scripts/scenarios/B.toml [--boom rigid] [--step 1e-3]
        [--stop-time 15] [--hold] [--interface cs|me] [--fmi 2|3] [--out out/cosim]
writes <out>/<scenario>-<boom>.csv and .png (p3, p4, cylinder velocity, u_ref / u_comp / u).

Coupling (Gauss-Seidel, loop-free). The plant's outputs do not depend directly on valve.u_ref
(the spool has dynamics); the controller has direct feedthrough p -> u. One communication step
[t_k, t_k+1] is
    plant.doStep(t_k, h)                         with valve.u_ref = u_k held over the step
    p4_k+1 = plant.p4
    controller.setRealInputDerivatives(p, (p4_k+1 - p4_k) / h)      (unless --hold)
    controller.doStep(t_k, h)                    the filter sees p4 linear over the step
    controller.p = p4_k+1, controller.u_ref = u_ref(t_k+1);  u_k+1 = controller.u
    plant.valve.u_ref = u_k+1
The controller therefore *interpolates* p4 (the plant has already been stepped, so the slope is
known, not guessed): no extrapolation is needed, and the filter state is exact for a
piecewise-linear p4. What the coupling cannot remove is the hold of u: the command applied over
[t_k, t_k+1] is computed from p4(t_k), i.e. the feedback acts with up to one communication step of
delay (h/2 on average, a phase lag of omega*h/2). That limits the usable step (see
scripts/README.md and `scripts/regress --step-sweep`).

FMI 3.0 (`--fmi 3`, the .fmu files of target/fmu/fmi3: the same binaries) has no input
derivatives, so its Co-Simulation runs with `--hold`; with the same hold, FMI 2.0 and FMI 3.0
give bit-identical results (tests/python/test_fmi3.py).

The scenario files (scripts/scenarios/*.toml) are documented in scripts/scenarios/README.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import pathlib
import sys
import time
import tomllib

import numpy as np

import figures
from metrics import CBV_OPEN

ROOT = pathlib.Path(__file__).resolve().parents[1]
FMU_DIR = ROOT / "target" / "fmu"
BOOMSIM = ROOT / "target" / "release" / "boomsim"
SCENARIO_DIR = ROOT / "scripts" / "scenarios"

#: Names the flexible-boom switch may get in HydraulicBoom (structural parameter, Integer or
#: Boolean). Until one of them exists the FMU has the rigid boom only.
FLEXIBLE_SWITCH = ("boom.flexible", "boom.model", "boom.type")

#: Recorded columns: (CSV name, source, FMU variable).
PLANT_OUT = ["p1", "p2", "p3", "p4", "valve.u", "cbv.u_cbv", "cylinder.x", "cylinder.v", "Q3", "Q4"]
CTRL_OUT = ["u", "u_comp"]
COLUMNS = ["time", "u_ref", "u_comp", "u_cmd"] + PLANT_OUT


class Skip(Exception):
    """A scenario variant that cannot run with the FMUs at hand (reason in the message)."""


class UsageError(Exception):
    """A wrong argument or a missing file: one line for the user, naming the value and the fix."""


def cli(main) -> int:
    """Runs a script's `main()`; a UsageError (a missing FMU, an unknown scenario) becomes one
    line on stderr and exit status 2 instead of a traceback."""
    try:
        return main() or 0
    except UsageError as e:
        print(f"{pathlib.Path(sys.argv[0]).name}: error: {e}", file=sys.stderr)
        return 2


def parse_params(ap, pairs: list[str]) -> dict:
    """The FMU parameters of a script's repeatable `--param NAME=VALUE` as {name: float}; a pair
    that is not one ends the script through `ap.error` with one line."""
    try:
        return {k: float(v) for k, v in (p.split("=", 1) for p in pairs)}
    except ValueError:
        ap.error(f"--param {' '.join(pairs)}: expected NAME=VALUE with a number")


def scenario_ids() -> list[str]:
    """The scenario ids of scripts/scenarios/, in the catalogue's order."""
    order = {"U": 0, "A": 1, "S": 2, "B": 3}
    return sorted((p.stem for p in SCENARIO_DIR.glob("*.toml")), key=lambda s: (order.get(s, 4), s))


# --------------------------------------------------------------------------- scenarios


def load_scenario(path) -> dict:
    path = pathlib.Path(path)
    if not path.exists() and (SCENARIO_DIR / f"{path}.toml").exists():
        path = SCENARIO_DIR / f"{path}.toml"  # a scenario id
    if not path.exists():
        raise UsageError(f"unknown scenario \"{path}\": give an id ({', '.join(scenario_ids())}) or a .toml file")
    with open(path, "rb") as f:
        sc = tomllib.load(f)
    sc.setdefault("id", path.stem)
    sc["file"] = str(path)
    sc.setdefault("booms", ["rigid"])
    sc.setdefault("stop_time", 15.0)
    sc.setdefault("start_stroke", 0.480)
    sc.setdefault("plant", {})
    ctrl = sc.setdefault("controller", {})
    ctrl.setdefault("enable", True)
    starts = ctrl.setdefault("feedback_start", "t0")
    sc["starts"] = [starts] if isinstance(starts, str) else list(starts)
    if not ctrl["enable"]:
        sc["starts"] = ["t0"]
    sc.setdefault("step", 1e-3)
    ref = np.asarray(sc["reference"], dtype=float)
    if ref.ndim != 2 or ref.shape[1] != 2 or np.any(np.diff(ref[:, 0]) < 0):
        raise ValueError(f"{path}: reference must be [[t, u_ref], ...] with non-decreasing t")
    sc["reference"] = ref
    return sc


def all_scenarios() -> list[dict]:
    return [load_scenario(SCENARIO_DIR / f"{s}.toml") for s in scenario_ids()]


def reference(table: np.ndarray, t: float) -> float:
    """Operator reference: piecewise linear through the table rows, right-continuous at
    repeated times (a row pair [t, a], [t, b] is a step from a to b at t); held after the end."""
    ts, us = table[:, 0], table[:, 1]
    i = np.searchsorted(ts, t, side="right")
    if i == 0:
        return float(us[0])
    if i >= len(ts):
        return float(us[-1])
    t0, t1, u0, u1 = ts[i - 1], ts[i], us[i - 1], us[i]
    return float(u0 + (u1 - u0) * (t - t0) / (t1 - t0))


# --------------------------------------------------------------------------- FMUs


class Fmi3:
    """An fmpy FMI 3.0 instance (FMU3Slave or FMU3Model) under the FMI 2.0 names this runner
    calls: the experiment goes with enterInitializationMode, Real is Float64, Integer is Int32."""

    def __init__(self, instance):
        self.m = instance
        self._experiment = {}

    def __getattr__(self, name):
        return getattr(self.m, name)

    def setupExperiment(self, tolerance=None, startTime=0.0, stopTime=None):
        self._experiment = dict(tolerance=tolerance, startTime=startTime, stopTime=stopTime)

    def enterInitializationMode(self):
        return self.m.enterInitializationMode(**self._experiment)

    def getReal(self, vrs):
        return self.m.getFloat64(vrs)

    def setReal(self, vrs, values):
        return self.m.setFloat64(vrs, values)

    def setInteger(self, vrs, values):
        return self.m.setInt32(vrs, values)

    def doStep(self, t, h):
        return self.m.doStep(t, h)

    def setRealInputDerivatives(self, *_):
        raise UsageError("FMI 3.0 has no input derivatives: run FMI 3.0 Co-Simulation with --hold")

    def getDerivatives(self, p, n):
        return self.m.getContinuousStateDerivatives(p, n)

    def newDiscreteStates(self):
        return self.m.updateDiscreteStates()


class FmuFile:
    """An extracted FMU (FMI `fmi` 2 or 3): model description and value references by name."""

    _cache: dict[tuple[str, int], "FmuFile"] = {}

    def __init__(self, identifier: str, fmu_dir=FMU_DIR, fmi: int = 2):
        from fmpy import extract, read_model_description

        self.fmi = fmi
        fmu_dir = pathlib.Path(fmu_dir) / ("fmi3" if fmi == 3 else "")
        self.path = str(fmu_dir / f"{identifier}.fmu")
        if not pathlib.Path(self.path).exists():
            raise UsageError(f"{self.path} is missing: run `cargo build --release && target/release/boomsim pack`")
        self.md = read_model_description(self.path)
        self.dir = extract(self.path)
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.vr = {n: v.valueReference for n, v in self.vars.items()}
        self._idle = []  # Co-Simulation instances handed back for reuse

    def reused_slave(self, name: str):
        """A Co-Simulation instance handed back by `give_back`, fmi2Reset to the state after
        instantiation (every parameter at its start value), or a new one."""
        if not self._idle:
            return self.slave(name)
        s = self._idle.pop()
        s.reset()
        return s

    def give_back(self, slave):
        """Keeps an instance of a finished run for `reused_slave`."""
        self._idle.append(slave)

    @classmethod
    def get(cls, identifier: str, fmi: int = 2) -> "FmuFile":
        if (identifier, fmi) not in cls._cache:
            cls._cache[identifier, fmi] = FmuFile(identifier, fmi=fmi)
        return cls._cache[identifier, fmi]

    def _instance(self, interface: str, name: str):
        """An instantiated fmpy instance of `interface` ("CoSimulation" or "ModelExchange"),
        FMI 3.0 ones behind the FMI 2.0 method names (class Fmi3)."""
        from fmpy import fmi2, fmi3

        kind = "Slave" if interface == "CoSimulation" else "Model"
        cls = getattr(fmi3, f"FMU3{kind}") if self.fmi == 3 else getattr(fmi2, f"FMU2{kind}")
        description = self.md.coSimulation if interface == "CoSimulation" else self.md.modelExchange
        i = cls(guid=self.md.guid, unzipDirectory=self.dir,
                modelIdentifier=description.modelIdentifier, instanceName=name)
        i.instantiate()
        return Fmi3(i) if self.fmi == 3 else i

    def slave(self, name: str):
        """A Co-Simulation instance."""
        return self._instance("CoSimulation", name)

    def model(self, name: str):
        """A Model Exchange instance."""
        return self._instance("ModelExchange", name)

    def set(self, slave, name: str, value):
        v = self.vars[name]
        if v.type in ("Real", "Float64"):
            slave.setReal([v.valueReference], [float(value)])
        elif v.type == "Boolean":
            slave.setBoolean([v.valueReference], [bool(value)])
        elif v.type in ("Integer", "Int32", "Enumeration"):
            slave.setInteger([v.valueReference], [int(value)])
        else:
            raise TypeError(f"{name}: unsupported type {v.type}")


def boom_switch(plant: FmuFile, boom: str):
    """(name, value) of the structural parameter selecting `boom`, or None for the rigid boom of
    an FMU without the switch; raises Skip when the FMU cannot give `boom`."""
    name = next((n for n in FLEXIBLE_SWITCH if n in plant.vars), None)
    if boom == "rigid":
        return None if name is None else (name, 0 if plant.vars[name].type != "Boolean" else False)
    if boom == "flexible":
        if name is None:
            raise Skip("HydraulicBoom has the rigid boom only (no flexible-boom switch "
                       f"{' / '.join(FLEXIBLE_SWITCH)} in its modelDescription yet)")
        return name, (1 if plant.vars[name].type != "Boolean" else True)
    raise ValueError(f"unknown boom {boom!r} (rigid or flexible)")


# --------------------------------------------------------------------------- run


def variant_name(scenario: dict, boom: str, feedback_start: str = "t0") -> str:
    """`<id>-<boom>`, with `-cbv` appended for feedback_start = cbv_open."""
    return f"{scenario['id']}-{boom}" + ("-cbv" if feedback_start == "cbv_open" else "")


@dataclasses.dataclass
class Result:
    scenario: dict
    boom: str
    step: float
    interpolate: bool
    data: dict  # column -> np.ndarray
    feedback_on_at: float | None  # time the feedback was switched on (feedback_start)
    feedback_start: str = "t0"
    status: str = "ok"
    #: Work counts: `rhs`, the plant's right-hand-side evaluations (CS: its solver's; ME: CVode's
    #: fmi2GetDerivatives calls).
    counts: dict = dataclasses.field(default_factory=dict)
    #: "CS 1 ms" (fmi2DoStep at the step) or "Model Exchange, CVode rtol ..." (`run_me`).
    interface: str = ""

    @property
    def name(self) -> str:
        return variant_name(self.scenario, self.boom, self.feedback_start)


def release(*instances):
    """Terminates (where the state allows) and frees FMU instances."""
    for m in instances:
        try:
            m.terminate()
        except Exception:  # noqa: BLE001 - terminate after an error may be refused
            pass
        m.freeInstance()


def plant_start(scenario: dict, switch) -> dict:
    """The plant's start values: the scenario's start stroke, the boom switch and its parameters."""
    return {"start.x": scenario["start_stroke"], **dict([switch] if switch else []), **scenario["plant"]}


def controller_start(scenario: dict, ctrl_params: dict) -> dict:
    """The controller's start values: the scenario's filter and limits where it gives them, then
    `ctrl_params`."""
    cfg = scenario["controller"]
    return {**{k: cfg[k] for k in ("K_f", "omega_f", "u_min", "u_max") if k in cfg}, **ctrl_params}


def initialize_plant(plant_f: FmuFile, plant, ctrl, scenario: dict, switch, tolerance, t_end: float):
    """Sets both instances up and into Initialization Mode, and initialises the plant with the
    scenario's start stroke, boom and parameters (either interface)."""
    for m in (plant, ctrl):
        m.setupExperiment(tolerance=tolerance, startTime=0.0, stopTime=t_end)
        m.enterInitializationMode()
    for name, value in plant_start(scenario, switch).items():
        plant_f.set(plant, name, value)
    plant.exitInitializationMode()


def with_params(scenario: dict, plant_f: FmuFile, params: dict | None) -> tuple[dict, dict]:
    """The scenario with the plant's `params` among its start values, and the controller's."""
    params = params or {}
    plant = {k: v for k, v in params.items() if k in plant_f.vars}
    return {**scenario, "plant": {**scenario["plant"], **plant}}, {k: v for k, v in params.items() if k not in plant}


def schedule(scenario: dict, step, stop_time, record_every, feedback_start):
    """(stop time, step, steps, record_every, feedback start) of a Co-Simulation run: the
    arguments, else the scenario's; record_every defaults to one row per millisecond or per step,
    whichever is coarser."""
    t_end = scenario["stop_time"] if stop_time is None else stop_time
    step = scenario["step"] if step is None else step
    n = int(round(t_end / step))
    if abs(n * step - t_end) > 1e-9 * t_end:
        raise ValueError(f"stop time {t_end} is not a multiple of the step {step}")
    if record_every is None:
        record_every = max(1, int(round(1e-3 / step)))
    fb_start = feedback_start or scenario["starts"][0]
    if fb_start not in ("t0", "cbv_open"):
        raise ValueError(f"feedback_start must be 't0' or 'cbv_open', got {fb_start!r}")
    return t_end, step, n, record_every, fb_start


def run(scenario: dict, boom: str = "rigid", step: float | None = None, stop_time: float | None = None,
        interpolate: bool = True, record_every: int | None = None, feedback_start: str | None = None,
        tolerance: float | None = None, fmi: int = 2, params: dict | None = None, reuse: bool = False,
        timeout: float | None = None) -> Result:
    """Co-simulate one scenario variant. `record_every` thins the recorded rows (default: one
    row per millisecond or per step, whichever is coarser); `fmi`: the FMUs' FMI version (3: no
    input derivatives, so `interpolate` must be False); `params`: FMU parameters by variable name
    (HydraulicBoom's or the controller's), set after the scenario's. `reuse`: take the instances
    of an earlier run with `reuse` (fmi2Reset) instead of instantiating, and keep them after a
    run that succeeds (a failed run frees them). `timeout` [s]: a TimeoutError when the wall
    time exceeds it, checked between communication steps (a single doStep is not interrupted)."""
    if fmi == 3 and interpolate:
        raise UsageError("FMI 3.0 has no input derivatives: run FMI 3.0 Co-Simulation with --hold")
    plant_f, ctrl_f = FmuFile.get("HydraulicBoom", fmi), FmuFile.get("PressureFeedbackController", fmi)
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end, step, n, record_every, fb_start = schedule(scenario, step, stop_time, record_every, feedback_start)
    enable = bool(scenario["controller"]["enable"])
    table = scenario["reference"]

    deadline = time.monotonic() + timeout if timeout is not None else math.inf
    new = (lambda f, name: f.reused_slave(name)) if reuse else (lambda f, name: f.slave(name))
    plant = new(plant_f, f"{scenario['id']}.plant")
    ctrl = new(ctrl_f, f"{scenario['id']}.controller")
    vp, vc = plant_f.vr, ctrl_f.vr
    ok = False
    try:
        initialize_plant(plant_f, plant, ctrl, scenario, switch, tolerance, t_end)
        p4 = plant.getReal([vp["p4"]])[0]

        def init_controller(t0: float, feedback: bool, first: bool):
            """(Re-)initialise the controller at t0: its filter starts at rest at the present p4."""
            if not first:
                ctrl.reset()
                ctrl.setupExperiment(tolerance=tolerance, startTime=t0, stopTime=t_end)
                ctrl.enterInitializationMode()
            for name, value in controller_start(scenario, ctrl_params).items():
                ctrl_f.set(ctrl, name, value)
            ctrl_f.set(ctrl, "enable", feedback)
            ctrl.setReal([vc["p"], vc["u_ref"]], [p4, reference(table, t0)])
            ctrl.exitInitializationMode()

        on = enable and fb_start == "t0"
        init_controller(0.0, on, True)
        fb_on_at = 0.0 if on else None

        out_p = [vp[k] for k in PLANT_OUT]
        i_p4, i_cbv = PLANT_OUT.index("p4"), PLANT_OUT.index("cbv.u_cbv")
        out_c = [vc["u"], vc["u_comp"]]
        rows = []
        y = plant.getReal(out_p)
        t = 0.0
        u_ref = reference(table, 0.0)
        for k in range(n + 1):
            t = k * step
            u, u_comp = ctrl.getReal(out_c)
            plant.setReal([vp["valve.u_ref"]], [u])
            if k % record_every == 0:
                rows.append([t, u_ref, u_comp, u, *y])
            if k == n:
                break
            if time.monotonic() > deadline:
                raise TimeoutError(f"exceeded the timeout of {timeout:g} s at t = {t:g} s of {t_end:g} s")
            plant.doStep(t, step)
            y = plant.getReal(out_p)
            p4_next = y[i_p4]
            if interpolate:
                ctrl.setRealInputDerivatives([vc["p"]], [1], [(p4_next - p4) / step])
            ctrl.doStep(t, step)
            p4 = p4_next
            u_ref = reference(table, t + step)
            if enable and not on and y[i_cbv] > CBV_OPEN:
                # feedback_start = "cbv_open": the feedback starts when the CBV cracks open, from
                # rest (the controller is re-initialised: filter state = present p4, no kick)
                on, fb_on_at = True, t + step
                init_controller(t + step, True, False)
            ctrl.setReal([vc["p"], vc["u_ref"]], [p4, u_ref])
        data = np.array(rows)
        rhs = plant.getReal([vp["solver.rhs_evals"]])[0]
        ok = True
    finally:
        if reuse and ok:
            plant_f.give_back(plant)
            ctrl_f.give_back(ctrl)
        else:
            release(plant, ctrl)
    return Result(scenario, boom, step, interpolate, {c: data[:, i] for i, c in enumerate(COLUMNS)}, fb_on_at,
                  fb_start, counts={"rhs": int(rhs)})


def run_native(scenario: dict, boom: str = "rigid", step: float | None = None, stop_time: float | None = None,
               interpolate: bool = True, record_every: int | None = None, feedback_start: str | None = None,
               params: dict | None = None, timeout: float | None = None) -> Result:
    """`run` (FMI 2.0) through `boomsim cosim`: the same coupling with the FMUs' code called
    in-process by the Rust loop instead of through fmpy, the same rows bit for bit. `timeout`:
    the process is killed beyond it (TimeoutError); a failure is a RuntimeError with the
    message."""
    import subprocess

    plant_f = FmuFile.get("HydraulicBoom")
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end, step, n, record_every, fb_start = schedule(scenario, step, stop_time, record_every, feedback_start)
    table = scenario["reference"]
    # The reference at the communication points as `run` computes them (t = k step, then t + step).
    u_ref = [reference(table, 0.0)] + [reference(table, k * step + step) for k in range(n)]
    request = {"stop_time": t_end, "step": step, "record_every": record_every, "interpolate": interpolate,
               "feedback_start": fb_start, "enable": bool(scenario["controller"]["enable"]),
               "u_ref": u_ref, "outputs": PLANT_OUT, "cbv_open": CBV_OPEN,
               "plant": plant_start(scenario, switch), "controller": controller_start(scenario, ctrl_params)}
    if not BOOMSIM.exists():
        raise UsageError(f"{BOOMSIM} is missing: run `cargo build --release`")
    try:
        r = subprocess.run([str(BOOMSIM), "cosim"], input=json.dumps(request).encode(), capture_output=True,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        raise TimeoutError(f"exceeded the timeout of {timeout:g} s (boomsim cosim killed)") from None
    if r.returncode:
        raise RuntimeError(r.stderr.decode().strip())
    head, _, body = r.stdout.partition(b"\n")
    h = json.loads(head)
    data = np.frombuffer(body, dtype="<f8").reshape(h["rows"], h["columns"])
    return Result(scenario, boom, step, interpolate, {c: data[:, i] for i, c in enumerate(COLUMNS)},
                  h["feedback_on_at"], fb_start, counts={"rhs": int(h["rhs"])})


def run_me(scenario: dict, boom: str = "rigid", stop_time: float | None = None, tolerance: float = 1e-6,
           feedback_start: str | None = None, events: bool = True, fmi: int = 2,
           params: dict | None = None) -> Result:
    """The scenario variant with both FMUs as Model Exchange, integrated together by fmpy's CVode
    (BDF, dense Newton with difference-quotient Jacobian, rtol `tolerance`, atol = rtol x the
    FMUs' nominal values): one ODE of the plant's and the controller's states, with
    valve.u_ref = controller.u and controller.p = plant.p4 at every right-hand side, so there is
    no communication step and no delay in the loop. Rows every millisecond; CVode is restarted
    at the reference table's breakpoints and where the feedback switches on (its discontinuities),
    and, with `events`, where one of the plant's event indicators changes sign (CVode's root
    finding: the dead-band jump of the spool demand, the load-sensing switch).
    `counts`: CVode's right-hand-side evaluations (`rhs`, fmi2GetDerivatives of each FMU) and the
    state events (`events`). `fmi` 3: the FMI 3.0 FMUs (the same event indicators); `params`: as
    for `run`."""
    from ctypes import POINTER, c_double
    from fmpy.sundials import CVodeSolver

    plant_f, ctrl_f = FmuFile.get("HydraulicBoom", fmi), FmuFile.get("PressureFeedbackController", fmi)
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end = scenario["stop_time"] if stop_time is None else stop_time
    ctrl_cfg = scenario["controller"]
    fb_start = feedback_start or scenario["starts"][0]
    enable = bool(ctrl_cfg["enable"])
    table = scenario["reference"]
    plant = plant_f.model(f"{scenario['id']}.plant")
    ctrl = ctrl_f.model(f"{scenario['id']}.controller")
    vp, vc = plant_f.vr, ctrl_f.vr
    np_, nc = len(plant_f.md.derivatives), len(ctrl_f.md.derivatives)
    nz = plant_f.md.numberOfEventIndicators if events else 0
    counts = {"rhs": 0, "events": 0}
    try:
        initialize_plant(plant_f, plant, ctrl, scenario, switch, tolerance, t_end)
        for name, value in controller_start(scenario, ctrl_params).items():
            ctrl_f.set(ctrl, name, value)
        on = enable and fb_start == "t0"
        ctrl_f.set(ctrl, "enable", on)
        ctrl.setReal([vc["p"], vc["u_ref"]], [plant.getReal([vp["p4"]])[0], reference(table, 0.0)])
        ctrl.exitInitializationMode()
        for m in (plant, ctrl):
            m.newDiscreteStates()
            m.enterContinuousTimeMode()

        def couple(t: float):
            """The loop at time t: the controller reads p4 and u_ref(t), the plant reads u."""
            ctrl.setReal([vc["p"], vc["u_ref"]], [plant.getReal([vp["p4"]])[0], reference(table, t)])
            plant.setReal([vp["valve.u_ref"]], ctrl.getReal([vc["u"]]))

        def parts(ptr):
            a = np.ctypeslib.as_array(ptr, (np_ + nc,))
            return [(m, a[sl].ctypes.data_as(POINTER(c_double)), n)
                    for m, sl, n in ((plant, slice(0, np_), np_), (ctrl, slice(np_, None), nc))]

        def get_x(ptr, _n):
            for m, p, n in parts(ptr):
                m.getContinuousStates(p, n)

        def set_x(ptr, _n):
            for m, p, n in parts(ptr):
                m.setContinuousStates(p, n)

        def get_dx(ptr, _n):
            counts["rhs"] += 1
            couple(now[0])
            for m, p, n in parts(ptr):
                m.getDerivatives(p, n)

        def get_z(ptr, n):
            couple(now[0])
            plant.getEventIndicators(ptr, n)

        def get_nominals(ptr, _n):
            for m, p, n in parts(ptr):
                m.getNominalsOfContinuousStates(p, n)

        now = [0.0]

        def set_time(t):
            now[0] = t
            for m in (plant, ctrl):
                m.setTime(t)

        class NoInput:
            def apply(self, t):
                pass

        solver = CVodeSolver(nx=np_ + nc, nz=nz, get_x=get_x, set_x=set_x, get_dx=get_dx,
                             get_z=get_z, get_nominals=get_nominals, set_time=set_time,
                             input=NoInput(), startTime=0.0, relativeTolerance=tolerance, maxNumSteps=100000)
        breaks = set(np.round(table[:, 0], 9))
        out_p = [vp[k] for k in PLANT_OUT]
        i_cbv = PLANT_OUT.index("cbv.u_cbv")
        fb_on_at = 0.0 if on else None
        rows = []
        n = int(round(t_end / 1e-3))
        for k in range(n + 1):
            t = k * 1e-3
            while k > 0:
                event, _, t_reached = solver.step(now[0], t)
                set_time(t_reached)
                if not event:
                    break
                # A state event: nothing is reinitialised (no discrete states), CVode restarts.
                counts["events"] += 1
                for m in (plant, ctrl):
                    m.enterEventMode()
                    m.newDiscreteStates()
                    m.enterContinuousTimeMode()
                solver.reset(t_reached)
            couple(t)
            y = plant.getReal(out_p)
            u, u_comp = ctrl.getReal([vc["u"], vc["u_comp"]])
            rows.append([t, reference(table, t), u_comp, u, *y])
            restart = round(t, 9) in breaks
            if enable and not on and y[i_cbv] > CBV_OPEN:
                # feedback_start = "cbv_open": from rest, the filter state at the present p4
                on, fb_on_at, restart = True, t, True
                ctrl.enterEventMode()
                ctrl_f.set(ctrl, "enable", True)
                ctrl.newDiscreteStates()
                ctrl.enterContinuousTimeMode()
                p4 = np.array([plant.getReal([vp["p4"]])[0]])
                ctrl.setContinuousStates(p4.ctypes.data_as(POINTER(c_double)), 1)
            if restart:
                solver.reset(t)
        data = np.array(rows)
    finally:
        release(plant, ctrl)
    return Result(scenario, boom, 1e-3, False, {c: data[:, i] for i, c in enumerate(COLUMNS)}, fb_on_at, fb_start,
                  counts=counts, interface=f"Model Exchange, CVode rtol {tolerance:g}")


# --------------------------------------------------------------------------- output

BAR = 1e5


def write_csv(res: Result, path):
    cols = list(res.data)
    arr = np.column_stack([res.data[c] for c in cols])
    header = ",".join(cols)
    np.savetxt(path, arr, delimiter=",", header=header, comments="", fmt="%.9g")


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
    import matplotlib

    matplotlib.use("Agg")
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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", help="scenario file or id (e.g. B or scripts/scenarios/B.toml)")
    ap.add_argument("--boom", default=None, choices=("rigid", "flexible"),
                    help="rigid or flexible (default: every boom of the scenario)")
    ap.add_argument("--step", type=float, default=None,
                    help="communication step [s] (default: the scenario's `step`, else 1e-3)")
    ap.add_argument("--stop-time", type=float, default=None)
    ap.add_argument("--hold", action="store_true", help="hold p4 over a step in the controller (no slope)")
    ap.add_argument("--interface", choices=("cs", "me"), default="cs",
                    help="cs: both FMUs' fmi2DoStep (default); me: both as Model Exchange under fmpy's CVode, one ODE")
    ap.add_argument("--fmi", type=int, choices=(2, 3), default=2,
                    help="FMI version of the FMUs: 2 (target/fmu, default) or 3 (target/fmu/fmi3; CS needs --hold)")
    ap.add_argument("--feedback-start", choices=("t0", "cbv_open"), default=None,
                    help="only this feedback start (default: every start listed by the scenario)")
    ap.add_argument("--out", default=str(ROOT / "out" / "cosim"))
    args = ap.parse_args(argv)
    if args.interface == "me" and (args.step is not None or args.hold):
        ap.error("--step and --hold are Co-Simulation options: Model Exchange has no communication step")
    for name, value in (("--step", args.step), ("--stop-time", args.stop_time)):
        if value is not None and not (0 < value < float("inf")):
            ap.error(f"{name} {value} must be a positive number of seconds (e.g. 1e-3)")
    sys.path.insert(0, str(pathlib.Path(__file__).parent))
    from metrics import compute

    try:
        sc = load_scenario(args.scenario)
    except UsageError as e:
        ap.error(str(e))
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    variants = [(b, f) for b in ([args.boom] if args.boom else sc["booms"])
                for f in ([args.feedback_start] if args.feedback_start else sc["starts"])]
    for boom, fb in variants:
        try:
            if args.interface == "me":
                res = run_me(sc, boom, args.stop_time, feedback_start=fb, fmi=args.fmi)
            else:
                res = run(sc, boom, args.step, args.stop_time, not args.hold, feedback_start=fb, fmi=args.fmi)
        except UsageError as e:
            ap.error(str(e))
        except Skip as e:
            print(f"{variant_name(sc, boom, fb)}: skipped: {e}")
            continue
        m = compute(res)
        write_csv(res, out / f"{res.name}.csv")
        plot(res, out / f"{res.name}.png", m)
        print(f"{res.name}: " + ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}"
                                          for k, v in m.items()))


if __name__ == "__main__":
    main()
