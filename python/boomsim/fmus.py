"""The fmpy adapter: an extracted .fmu with its variables by name, its Co-Simulation and Model
Exchange instances (FMI 3.0 ones behind the FMI 2.0 method names), typed setting by name, the
boom switch, and the set-up of a plant and its controller before a run of either interface."""

from __future__ import annotations

import functools
import math

from .errors import Skip, UsageError
from .paths import fmu
from .scenarios import plant_start

#: Names the flexible-boom switch may get in HydraulicBoom (structural parameter, Integer or
#: Boolean). Until one of them exists the FMU has the rigid boom only.
FLEXIBLE_SWITCH = ("boom.flexible", "boom.model", "boom.type")


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
        raise UsageError("FMI 3.0 has no input derivatives: pass ramped inputs by intermediate update "
                         "(boomsim.fmus.LinearInputs), or run FMI 3.0 Co-Simulation with --hold")

    def getDerivatives(self, p, n):
        return self.m.getContinuousStateDerivatives(p, n)

    def newDiscreteStates(self):
        return self.m.updateDiscreteStates()


class LinearInputs:
    """A master's inputs linear over each communication step, passed to an FMI 3.0 Co-Simulation
    FMU by intermediate update (FMI 3.0, 4.2.3), FMI 3.0's replacement for FMI 2.0's input
    derivatives: where the FMU's callback requests them, each input `vrs` is set on the line from
    its value at the step's start to its value at the step's end (that exactly at the end). Give
    it to `FmuFile.slave(..., inputs=...)` and call `over` before each doStep."""

    def __init__(self, vrs: list[int]):
        self.vrs = list(vrs)
        self.line = None
        self.slave = None

    def over(self, t: float, h: float, start: list[float], end: list[float]) -> None:
        """The inputs' line over the step from `t` of size `h`."""
        self.line = (t, h, list(start), list(end))

    def callback(self, _env, t, set_requested, _get_allowed, _finished, _can_return_early, early_return_requested,
                 _early_return_time):
        """fmi3IntermediateUpdateCallback: sets the inputs where requested, never asks for an early return."""
        early_return_requested[0] = False
        if set_requested and self.line is not None:
            t0, h, y0, y1 = self.line
            values = y1 if t == t0 + h else [a + (b - a) * (t - t0) / h for a, b in zip(y0, y1)]
            self.slave.setFloat64(self.vrs, values)


class FmuFile:
    """An extracted FMU (FMI `fmi` 2 or 3): model description and value references by name."""

    _cache: dict[tuple[str, int], "FmuFile"] = {}

    def __init__(self, identifier: str, fmi: int = 2):
        import fmpy
        from fmpy import extract, read_model_description

        self.fmi = fmi
        self.path = str(fmu(identifier, fmi))
        supported = fmpy.supported_platforms(self.path)
        if fmpy.platform not in supported and fmpy.platform_tuple not in supported:
            raise UsageError(f"{identifier} (FMI {fmi}.0) has no binary for this platform, {fmpy.platform_tuple}: "
                             f"its binaries are for {', '.join(supported)} (docs/platforms.md)")
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

    def _instance(self, interface: str, name: str, **instantiate):
        """An instantiated fmpy instance of `interface` ("CoSimulation" or "ModelExchange"),
        FMI 3.0 ones behind the FMI 2.0 method names (class Fmi3); `instantiate`: the arguments
        of fmpy's instantiate."""
        from fmpy import fmi2, fmi3

        kind = "Slave" if interface == "CoSimulation" else "Model"
        cls = getattr(fmi3, f"FMU3{kind}") if self.fmi == 3 else getattr(fmi2, f"FMU2{kind}")
        description = self.md.coSimulation if interface == "CoSimulation" else self.md.modelExchange
        i = tracked(cls)(guid=self.md.guid, unzipDirectory=self.dir,
                         modelIdentifier=description.modelIdentifier, instanceName=name)
        i.instantiate(**instantiate)
        return Fmi3(i) if self.fmi == 3 else i

    def slave(self, name: str, event_mode: bool = False, inputs: LinearInputs | None = None):
        """A Co-Simulation instance; `event_mode`: FMI 3.0 with Event Mode (eventModeUsed); `inputs`:
        FMI 3.0 inputs linear over a step, set by intermediate update."""
        args = {"eventModeUsed": True} if event_mode else {}
        if inputs is not None:
            args.update(intermediateUpdate=inputs.callback, requiredIntermediateVariables=inputs.vrs)
        s = self._instance("CoSimulation", name, **args)
        if inputs is not None:
            inputs.slave = s.m
        return s

    def model(self, name: str):
        """A Model Exchange instance."""
        return self._instance("ModelExchange", name)

    def set(self, slave, name: str, value):
        """Sets variable `name` of instance `slave`; an Enumeration's by its item's name or value
        (FMI 3.0 writes Enumerations with fmi3SetInt64)."""
        v = self.vars[name]
        if v.type in ("Real", "Float64"):
            slave.setReal([v.valueReference], [float(value)])
        elif v.type == "Boolean":
            slave.setBoolean([v.valueReference], [bool(value)])
        elif v.type in ("Integer", "Int32"):
            slave.setInteger([v.valueReference], [int(value)])
        elif v.type == "Enumeration":
            (slave.setInt64 if self.fmi == 3 else slave.setInteger)([v.valueReference], [item_value(name, v, value)])
        else:
            raise TypeError(f"{name}: unsupported type {v.type}")


class Direct:
    """GetReal/GetFloat64, SetReal/SetFloat64, ramped inputs and DoStep of one fmpy Co-Simulation
    instance (FMI 2.0, or FMI 3.0 behind `Fmi3`) called straight through ctypes with each
    value-reference list's arrays built once: fmpy's methods build them on every call, which in a
    loop of 1 ms steps costs more than the FMU's own work. A status above Warning raises
    FMICallException, as fmpy's calls do."""

    def __init__(self, instance):
        self.i = instance
        self.fmi = 3 if isinstance(instance, Fmi3) else 2

    def _function(self, name: str):
        """The FMU's function `name` and the instance's component (fmpy set its argtypes)."""
        return getattr(self.i.dll, name), self.i.component

    @staticmethod
    def _refused(name: str, status: int):
        from fmpy.fmi1 import FMICallException

        raise FMICallException(function=name, status=status)

    # Each call tests its status inline: a wrapper function per call is a third of its cost.
    def getter(self, vrs: list[int]):
        """A function returning the values of `vrs` (a ctypes array, reused)."""
        from ctypes import c_double, c_uint

        n, refs, out = len(vrs), (c_uint * len(vrs))(*vrs), (c_double * len(vrs))()
        name = "fmi3GetFloat64" if self.fmi == 3 else "fmi2GetReal"
        f, c = self._function(name)
        args = (c, refs, n, out, n) if self.fmi == 3 else (c, refs, n, out)

        def get():
            status = f(*args)
            if status > 1:
                self._refused(name, status)
            return out

        return get

    def setter(self, vrs: list[int]):
        """A function setting `vrs` to its argument's values."""
        from ctypes import c_double, c_uint

        n, refs, values = len(vrs), (c_uint * len(vrs))(*vrs), (c_double * len(vrs))()
        name = "fmi3SetFloat64" if self.fmi == 3 else "fmi2SetReal"
        f, c = self._function(name)
        args = (c, refs, n, values, n) if self.fmi == 3 else (c, refs, n, values)

        def put(x):
            values[:] = x
            status = f(*args)
            if status > 1:
                self._refused(name, status)

        return put

    def ramp(self, vrs: list[int], inputs: LinearInputs | None = None):
        """A function ramp(t, h, start, end) making the inputs `vrs` linear over the step from
        `t` of size `h`, from `start` (already set) to `end`: FMI 2.0 their first derivatives
        (fmi2SetRealInputDerivatives), FMI 3.0 by intermediate update through `inputs`, the
        LinearInputs of `vrs` the instance was made with."""
        if self.fmi == 3:
            if inputs is None or list(inputs.vrs) != list(vrs):
                raise UsageError(f"FMI 3.0 ramps inputs {vrs} by intermediate update: make the instance with "
                                 f"LinearInputs({vrs})")
            return lambda t, h, start, end: inputs.over(t, h, start, end)
        from ctypes import c_double, c_int, c_uint

        n, refs, values = len(vrs), (c_uint * len(vrs))(*vrs), (c_double * len(vrs))()
        order, (f, c) = (c_int * n)(*[1] * n), self._function("fmi2SetRealInputDerivatives")

        def ramp(_t, h, start, end):
            values[:] = [(b - a) / h for a, b in zip(start, end)]
            status = f(c, refs, n, order, values)
            if status > 1:
                self._refused("fmi2SetRealInputDerivatives", status)

        return ramp

    def stepper(self):
        """DoStep(t, h) with noSetFMUStatePriorToCurrentPoint = true; FMI 3.0: a step that asks to
        terminate the simulation is refused too (FMI 3.0, 4.2.4: the master stops)."""
        if self.fmi == 2:
            f, c = self._function("fmi2DoStep")

            def step(t, h):
                status = f(c, t, h, 1)
                if status > 1:
                    self._refused("fmi2DoStep", status)

            return step
        from ctypes import byref, c_bool, c_double

        f, c = self._function("fmi3DoStep")
        event, terminate, early, last = c_bool(), c_bool(), c_bool(), c_double()
        flags = (byref(event), byref(terminate), byref(early), byref(last))

        def step3(t, h):
            status = f(c, t, h, True, *flags)
            if status > 1 or terminate.value:
                self._refused("fmi3DoStep", max(status, 2))

        return step3


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
    raise UsageError(f"boom={boom!r}: \"rigid\" or \"flexible\"")


@functools.cache
def tracked(base):
    """The fmpy instance class `base` remembering whether the instance has left Initialization
    Mode since it was instantiated or reset (`initialized`): only then is Terminate legal (FMI 2.0
    state tables, 4.3.1 and 3.2.3: not in Instantiated or Initialization Mode; FMI 3.0 likewise),
    so `release` frees the others without the call that their FMU refuses with an error message."""

    class Tracked(base):
        initialized = False

        def exitInitializationMode(self):
            out = super().exitInitializationMode()
            self.initialized = True
            return out

        def reset(self):
            out = super().reset()
            self.initialized = False
            return out

    Tracked.__name__ = Tracked.__qualname__ = base.__name__
    return Tracked


def release(*instances):
    """Terminates where the state allows it (an instance of `FmuFile` that left Initialization
    Mode; any other is tried) and frees FMU instances."""
    for m in instances:
        if getattr(m, "initialized", True):
            try:
                m.terminate()
            except Exception:  # noqa: BLE001 - terminate after an error may be refused
                pass
        m.freeInstance()


def initialize_plant(plant_f: FmuFile, plant, ctrl, scenario: dict, switch, tolerance, t_end: float):
    """Sets both instances up and into Initialization Mode, and initialises the plant with the
    scenario's start stroke, boom and parameters (either interface)."""
    for m in (plant, ctrl):
        m.setupExperiment(tolerance=tolerance, startTime=0.0, stopTime=t_end)
        m.enterInitializationMode()
    for name, value in plant_start(scenario, switch).items():
        plant_f.set(plant, name, value)
    plant.exitInitializationMode()


def item_value(name: str, v, value) -> int:
    """The value of the item `value` (its name, or its value) of Enumeration variable `v`, or a
    UsageError naming the parameter, the value and the items."""
    items = {i.name: int(i.value) for i in v.declaredType.items}
    if isinstance(value, str) and value in items:
        return items[value]
    if not isinstance(value, (bool, str)) and value in items.values():
        return int(value)
    listed = ", ".join(f"{n!r} ({k})" for n, k in items.items())
    raise UsageError(f"params[{name!r}] = {value!r} is no item of {v.declaredType.name}: {listed}")


def check_params(params: dict, *files: FmuFile) -> None:
    """Every entry of `params` is a parameter of one of the FMUs `files` with a value its
    modelDescription allows (a number within [min, max]; a whole number for an Integer, true or
    false for a Boolean, an item's name or value for an Enumeration), or a UsageError naming the
    parameter, the value and what is allowed, before any instance exists."""
    for name, value in params.items():
        v = next((f.vars[name] for f in files if name in f.vars), None)
        if v is None or v.causality not in ("parameter", "structuralParameter"):
            what = "a variable that is not a parameter" if v is not None else "no such variable"
            raise UsageError(f"params[{name!r}]: {what} of {' or '.join(f.md.modelName for f in files)} "
                             "(docs/fmus.md lists the parameters)")
        if v.type == "Boolean":
            if value not in (True, False, 0, 1):
                raise UsageError(f"params[{name!r}] = {value!r}: true or false")
            continue
        if v.type == "Enumeration":
            item_value(name, v, value)
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise UsageError(f"params[{name!r}] = {value!r}: a finite number")
        lo, hi = (float(b) if b is not None else None for b in (v.min, v.max))
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            raise UsageError(f"params[{name!r}] = {value!r} is outside its valid range [{v.min}, {v.max}]"
                             + (f" {v.unit}" if getattr(v, "unit", None) not in (None, "", "1") else ""))
        if v.type in ("Integer", "Int32") and value != int(value):
            raise UsageError(f"params[{name!r}] = {value!r}: a whole number")


def with_params(scenario: dict, plant_f: FmuFile, params: dict | None) -> tuple[dict, dict]:
    """The scenario with the plant's `params` among its start values, and the controller's; each
    checked (`check_params`) against the plant and the PressureFeedbackController of the same
    FMI version."""
    params = params or {}
    check_params(params, plant_f, FmuFile.get("PressureFeedbackController", plant_f.fmi))
    plant = {k: v for k, v in params.items() if k in plant_f.vars}
    return {**scenario, "plant": {**scenario["plant"], **plant}}, {k: v for k, v in params.items() if k not in plant}
