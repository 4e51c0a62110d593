"""The packed FMUs driven through raw ctypes exactly as the Modelica Association's reference
importer fmusim (modelica/Reference-FMUs, fmusim/FMI2CSSimulation.c and src/FMI2.c) drives an
FMI 2.0 Co-Simulation FMU with `--interface-type cs --output-interval 0.001 --logging-on`:

    fmi2Instantiate("instance1", fmi2CoSimulation, guid, "file://<unzipdir>/resources/",
                    {logger, allocateMemory=calloc, freeMemory=free, stepFinished=NULL,
                     componentEnvironment=<non-NULL>}, visible=fmi2False, loggingOn=fmi2True)
    fmi2Set<Type>(start values)            only for --start-value, before the experiment
    fmi2SetupExperiment(toleranceDefined=fmi2False, 0, startTime=0, stopTimeDefined=fmi2False, stop)
    fmi2EnterInitializationMode(); fmi2ExitInitializationMode()
    fmi2GetReal/Integer/Boolean(every variable of that type, in modelDescription order)
    fmi2GetReal/...(the outputs)           sample at t = 0
    repeat: fmi2DoStep(t, t_(n+1) - t, noSetFMUStatePriorToCurrentPoint=fmi2True); get outputs
    fmi2Terminate(); fmi2FreeInstance()

fmusim never calls fmi2SetDebugLogging, fmi2SetReal of inputs (without an input file), or
fmi2Reset. It computes each step as the difference of regular points, start + (n + 1) * h - t,
so the step sizes are 0.001 +- 1 ulp (e.g. 0.001000000000000001), and it stops when t is within
1e-5 of stopTime. These are the calls fmusim logged with --log-fmi-calls for all four FMUs.

fmusim passes libc's calloc and free. An importer may also pass NULL for both because the FMUs
declare canNotUseMemoryManagementFunctions="true" (FMI 2.0, sections 2.1.5 and 4.3.1), so both
are tested."""

import ctypes
import math
import xml.etree.ElementTree as ET
import zipfile

import pytest

from conftest import fmu_path

FMI2_OK, FMI2_CO_SIMULATION, FMI2_TRUE, FMI2_FALSE = 0, 1, 1, 0
STOP_TIME, OUTPUT_INTERVAL, EPSILON = 0.2, 1e-3, 1e-5  # EPSILON: fmusim's FMIIsClose

#: fmi2CallbackLogger(componentEnvironment, instanceName, status, category, message, ...). The
#: FMU always calls it with message "%s" and the text as the one variadic argument. On x86-64
#: System V, variadic pointer arguments are passed in the same registers as fixed ones, so the
#: text can be read as a sixth parameter. It is declared c_void_p so that ctypes does not
#: dereference it unless the format is "%s".
LOGGER = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                          ctypes.c_char_p, ctypes.c_void_p)


class CallbackFunctions(ctypes.Structure):
    """fmi2CallbackFunctions. The memory functions are plain C function pointers (libc's calloc
    and free, as in fmusim), not Python callbacks."""

    _fields_ = [("logger", LOGGER),
                ("allocateMemory", ctypes.c_void_p),
                ("freeMemory", ctypes.c_void_p),
                ("stepFinished", ctypes.c_void_p),
                ("componentEnvironment", ctypes.c_void_p)]


_LIBC = ctypes.CDLL(None)
CALLOC = ctypes.cast(_LIBC.calloc, ctypes.c_void_p).value
FREE = ctypes.cast(_LIBC.free, ctypes.c_void_p).value

#: The FMU keeps the callbacks pointer and calls the logger until fmi2FreeInstance, and possibly
#: after a test has failed midway. Every ctypes callback, callback struct and library therefore
#: stays referenced for the whole session: if one were garbage-collected and the library then
#: called it, the interpreter would crash.
_ALIVE = []

#: (identifier, fmusim --start-value settings) for each FMU. The booms are run both in their
#: default configuration (flexible) and rigid (boom.flexible = false, vr 31).
CASES = [
    ("PressureFeedbackController", {}),
    ("HydraulicCircuit", {}),
    ("HydraulicBoom", {}),
    ("HydraulicBoom", {"boom.flexible": False}),
    ("BoomMechanics", {}),
    ("BoomMechanics", {"boom.flexible": False}),
]

C_TYPES = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int,
           "String": ctypes.c_char_p}
TYPE_ORDER = ("Real", "Integer", "Boolean", "String")  # fmusim's FMIVariableType order for FMI 2.0


def model_description(unzipdir):
    """GUID, model identifier and variables as (name, valueReference, type, causality), in
    document order. Enumeration is read with fmi2GetInteger, as fmusim does."""
    root = ET.parse(unzipdir / "modelDescription.xml").getroot()
    variables = []
    for sv in root.find("ModelVariables").findall("ScalarVariable"):
        kind = next(c.tag for c in sv if c.tag in ("Real", "Integer", "Enumeration", "Boolean", "String"))
        kind = "Integer" if kind == "Enumeration" else kind
        variables.append((sv.get("name"), int(sv.get("valueReference")), kind, sv.get("causality", "local")))
    return root.get("guid"), root.find("CoSimulation").get("modelIdentifier"), variables


def is_close(a, b):
    """fmusim's FMIIsClose: absolute or relative difference within 1e-5."""
    return math.isfinite(a) and math.isfinite(b) and (
        abs(a - b) <= EPSILON or abs(a - b) <= EPSILON * max(abs(a), abs(b)))


class Importer:
    """One FMU loaded with ctypes. Every call is recorded in self.calls, and its status must be
    fmi2OK."""

    def __init__(self, so):
        self.dll = ctypes.CDLL(str(so))
        _ALIVE.append(self.dll)
        self.calls, self.messages = [], []
        d = self.dll
        d.fmi2Instantiate.restype = ctypes.c_void_p
        d.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                      ctypes.POINTER(CallbackFunctions), ctypes.c_int, ctypes.c_int]
        d.fmi2SetupExperiment.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double, ctypes.c_double,
                                          ctypes.c_int, ctypes.c_double]
        d.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        for f in ("fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate"):
            getattr(d, f).argtypes = [ctypes.c_void_p]
        for t in TYPE_ORDER:
            for f in (f"fmi2Get{t}", f"fmi2Set{t}"):
                getattr(d, f).argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint), ctypes.c_size_t,
                                          ctypes.POINTER(C_TYPES[t])]
        for f in ("fmi2SetupExperiment", "fmi2DoStep", "fmi2EnterInitializationMode",
                  "fmi2ExitInitializationMode", "fmi2Terminate") + tuple(
                      f"fmi2{a}{t}" for a in ("Get", "Set") for t in TYPE_ORDER):
            getattr(d, f).restype = ctypes.c_int
        d.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
        d.fmi2FreeInstance.restype = None

        def log(env, instance_name, status, category, message, arg):
            text = ctypes.string_at(arg).decode() if message == b"%s" and arg else message.decode()
            self.messages.append((status, (category or b"").decode(), text))

        self.logger = LOGGER(log)
        self.env = ctypes.c_int(1)  # fmusim passes its FMIInstance*; any non-NULL pointer
        _ALIVE.extend([self.logger, self.env])

    def call(self, name, *args, record=True):
        status = getattr(self.dll, name)(*args)
        if record:
            self.calls.append(name)
        assert status == FMI2_OK, f"{name} returned {status}; last messages: {self.messages[-5:]}"
        return status

    def get(self, component, kind, vrs, record=True):
        n = len(vrs)
        values = (C_TYPES[kind] * n)()
        self.call(f"fmi2Get{kind}", component, (ctypes.c_uint * n)(*vrs), n, values, record=record)
        return list(values)


def sample(imp, component, variables):
    """fmusim's FMISample: one fmi2Get<Type> per type present, the variables in document order.
    Returns the Real values by name."""
    reals = {}
    for kind in TYPE_ORDER:
        group = [(name, vr) for name, vr, k, _ in variables if k == kind]
        if group:
            values = imp.get(component, kind, [vr for _, vr in group])
            if kind == "Real":
                reals.update(zip((name for name, _ in group), values))
    return reals


@pytest.mark.parametrize("memory", ["calloc-free", "null"])
@pytest.mark.parametrize("identifier,start", CASES,
                         ids=[i + ("-rigid" if s else "") for i, s in CASES])
def test_fmusim_calling_sequence(identifier, start, memory, tmp_path):
    """FMI 2.0 CS, section 4.2.4 (state machine) and 2.1.5 (callbacks): the importer sequence
    Instantiate, [set start values], SetupExperiment without tolerance and stop time, Enter/Exit
    initialization mode, get every variable, then 200 x (DoStep 1 ms, get the outputs), Terminate
    and FreeInstance. Every status is fmi2OK, every Real is finite at every sample, the FMU logs
    nothing above OK, and fmi2FreeInstance returns."""
    with zipfile.ZipFile(fmu_path(identifier)) as z:
        z.extractall(tmp_path)
    guid, model_identifier, variables = model_description(tmp_path)
    assert model_identifier == identifier
    imp = Importer(tmp_path / "binaries" / "linux64" / f"{identifier}.so")

    callbacks = CallbackFunctions(
        logger=imp.logger,
        allocateMemory=CALLOC if memory == "calloc-free" else None,
        freeMemory=FREE if memory == "calloc-free" else None,
        stepFinished=None,
        componentEnvironment=ctypes.addressof(imp.env))
    _ALIVE.append(callbacks)
    resource_uri = (tmp_path / "resources").as_uri() + "/"

    c = imp.dll.fmi2Instantiate(b"instance1", FMI2_CO_SIMULATION, guid.encode(), resource_uri.encode(),
                                ctypes.byref(callbacks), FMI2_FALSE, FMI2_TRUE)
    imp.calls.append("fmi2Instantiate")
    assert c, f"fmi2Instantiate returned NULL: {imp.messages}"

    # fmusim's --start-value: one fmi2Set<Type> per value, before fmi2SetupExperiment.
    by_name = {name: (vr, kind) for name, vr, kind, _ in variables}
    for name, value in start.items():
        vr, kind = by_name[name]
        imp.call(f"fmi2Set{kind}", c, (ctypes.c_uint * 1)(vr), 1, (C_TYPES[kind] * 1)(value))

    imp.call("fmi2SetupExperiment", c, FMI2_FALSE, 0.0, 0.0, FMI2_FALSE, STOP_TIME)
    imp.call("fmi2EnterInitializationMode", c)
    imp.call("fmi2ExitInitializationMode", c)

    initial = sample(imp, c, variables)
    assert all(math.isfinite(v) for v in initial.values()), {k: v for k, v in initial.items() if not math.isfinite(v)}
    for name, value in start.items():
        vr, kind = by_name[name]
        assert imp.get(c, kind, [vr], record=False) == [int(value)], name  # not in fmusim's sequence

    outputs = [v for v in variables if v[3] == "output"]
    assert outputs
    rows = [sample(imp, c, outputs)]

    t, n_steps = 0.0, 0
    while not (t > STOP_TIME or is_close(t, STOP_TIME)):
        next_regular = (n_steps + 1) * OUTPUT_INTERVAL  # startTime = 0
        next_point = next_regular
        if next_point > STOP_TIME and not is_close(next_point, STOP_TIME):
            next_point = STOP_TIME  # canHandleVariableCommunicationStepSize="true"
        imp.call("fmi2DoStep", c, t, next_point - t, FMI2_TRUE)
        t = next_point
        if is_close(t, next_regular):
            n_steps += 1
        rows.append(sample(imp, c, outputs))

    imp.call("fmi2Terminate", c)
    assert imp.dll.fmi2FreeInstance(c) is None
    imp.calls.append("fmi2FreeInstance")

    n = round(STOP_TIME / OUTPUT_INTERVAL)
    assert n_steps == n and len(rows) == n + 1
    bad = [(i, k, v) for i, row in enumerate(rows) for k, v in row.items() if not math.isfinite(v)]
    assert not bad, bad[:5]

    per_sample = [f"fmi2Get{k}" for k in TYPE_ORDER if any(v[2] == k for v in outputs)]
    expected = (["fmi2Instantiate"] + [f"fmi2Set{by_name[s][1]}" for s in start]
                + ["fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode"]
                + [f"fmi2Get{k}" for k in TYPE_ORDER if any(v[2] == k for v in variables)]
                + per_sample + (["fmi2DoStep"] + per_sample) * n + ["fmi2Terminate", "fmi2FreeInstance"])
    assert imp.calls == expected

    assert imp.messages, "loggingOn = fmi2True: the FMU logs through the callback"
    assert [m for m in imp.messages if m[0] != FMI2_OK] == []
