"""Shared helpers for the fmpy tests: paths of the packed FMUs and slaves whose log messages are
recorded (fmpy's logger proxy formats the FMU's printf-style "%s" messages)."""

import ctypes
import os
import pathlib

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy import calloc, free
from fmpy.logging import addLoggerProxy

ROOT = pathlib.Path(__file__).resolve().parents[2]

# Every figure a script saves while the tests run, in this process or a child, is checked
# (python/boomsim/figures.py): text inside the canvas, every axis labelled with its unit.
os.environ["BOOMSIM_STRICT_FIGURES"] = "1"
FMU_DIR = ROOT / "target" / "fmu"
#: fmi-sim (rust-fmi's fmusim, an independent importer) as scripts/setup builds it.
FMI_SIM = ROOT / ".tools" / "bin" / "fmi-sim"


#: The 34 functions of FMI 2.0 Co-Simulation (25 common + 9 co-simulation), without "fmi2".
FMI2_CS_FUNCTIONS = """GetTypesPlatform GetVersion SetDebugLogging Instantiate FreeInstance SetupExperiment
EnterInitializationMode ExitInitializationMode Terminate Reset GetReal GetInteger GetBoolean GetString
SetReal SetInteger SetBoolean SetString GetFMUstate SetFMUstate FreeFMUstate SerializedFMUstateSize
SerializeFMUstate DeSerializeFMUstate GetDirectionalDerivative SetRealInputDerivatives
GetRealOutputDerivatives DoStep CancelStep GetStatus GetRealStatus GetIntegerStatus GetBooleanStatus
GetStringStatus""".split()

#: The 10 Model Exchange functions (FMI 2.0, 3.2.2) beside the 25 common and 9 CS ones.
FMI2_ME_FUNCTIONS = """EnterEventMode NewDiscreteStates EnterContinuousTimeMode CompletedIntegratorStep SetTime
SetContinuousStates GetDerivatives GetEventIndicators GetContinuousStates GetNominalsOfContinuousStates""".split()

#: Every function a boomsim FMU exports: both interfaces.
FMI2_FUNCTIONS = FMI2_CS_FUNCTIONS + FMI2_ME_FUNCTIONS

#: The 75 functions of fmi3FunctionTypes.h (FMI 3.0), without "fmi3": the same binary exports
#: them beside the FMI 2.0 ones (Scheduled Execution, clocks and the types no variable has are
#: exported too and answer fmi3Error with a message).
FMI3_FUNCTIONS = """GetVersion SetDebugLogging InstantiateModelExchange InstantiateCoSimulation
InstantiateScheduledExecution FreeInstance EnterInitializationMode ExitInitializationMode EnterEventMode
Terminate Reset GetFloat32 GetFloat64 GetInt8 GetUInt8 GetInt16 GetUInt16 GetInt32 GetUInt32 GetInt64
GetUInt64 GetBoolean GetString GetBinary GetClock SetFloat32 SetFloat64 SetInt8 SetUInt8 SetInt16 SetUInt16
SetInt32 SetUInt32 SetInt64 SetUInt64 SetBoolean SetString SetBinary SetClock GetNumberOfVariableDependencies
GetVariableDependencies GetFMUState SetFMUState FreeFMUState SerializedFMUStateSize SerializeFMUState
DeserializeFMUState GetDirectionalDerivative GetAdjointDerivative EnterConfigurationMode
ExitConfigurationMode GetIntervalDecimal GetIntervalFraction GetShiftDecimal GetShiftFraction
SetIntervalDecimal SetIntervalFraction SetShiftDecimal SetShiftFraction EvaluateDiscreteStates
UpdateDiscreteStates EnterContinuousTimeMode CompletedIntegratorStep SetTime SetContinuousStates
GetContinuousStateDerivatives GetEventIndicators GetContinuousStates GetNominalsOfContinuousStates
GetNumberOfEventIndicators GetNumberOfContinuousStates EnterStepMode GetOutputDerivatives DoStep
ActivateModelPartition""".split()

#: Every symbol of a boomsim FMU library.
EXPORTED = {"fmi2" + f for f in FMI2_FUNCTIONS} | {"fmi3" + f for f in FMI3_FUNCTIONS}


def fmu_path(identifier):
    path = FMU_DIR / f"{identifier}.fmu"
    assert path.exists(), f"{path} is missing: run target/release/boomsim pack"
    return str(path)


#: fmpy's logger proxy keeps the logger registered last in one global of its C library and
#: forwards every proxied message there (also those of FMUs instantiated with fmpy's default
#: callbacks). A Recorder therefore lives as long as the session: a collected one would leave
#: the proxy calling a freed callback, which crashed the interpreter when a later FMU logged.
_ALIVE = []


class Recorder:
    """FMI callbacks whose logger records (status, category, message)."""

    def __init__(self):
        _ALIVE.append(self)
        self.messages = []

        def log(env, name, status, category, message):
            self.messages.append((status, category.decode(), message.decode()))

        self._log = fmi2CallbackLoggerTYPE(log)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._log
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(ctypes.byref(self.callbacks))

    def errors(self):
        return [m for s, _, m in self.messages if s == 3]


class Fmu:
    """An extracted FMU: model description, value references by name, slaves with recorders."""

    def __init__(self, identifier, tmp_path_factory):
        self.path = fmu_path(identifier)
        self.md = read_model_description(self.path)
        self.dir = extract(self.path, unzipdir=str(tmp_path_factory.mktemp(identifier)))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.type = {v.name: v.type for v in self.md.modelVariables}
        #: The items of each Enumeration by name: {variable: {item: value}}.
        self.items = {v.name: {i.name: int(i.value) for i in v.declaredType.items}
                      for v in self.md.modelVariables if v.type == "Enumeration"}

    def slave(self, name="instance", guid=None, tolerance=None, **start):
        """An instantiated slave, set up (with the relative tolerance `tolerance`, None: the
        FMU's default) and initialised with the given start values (unless guid is given: then
        only instantiated). Structured names go in as **{"start.x": 0.3}, an Enumeration's value
        by its item's name (fmi2SetInteger of its value, FMI 2.0, 2.2.7)."""
        rec = Recorder()
        s = FMU2Slave(guid=guid or self.md.guid, unzipDirectory=self.dir,
                      modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        s.recorder = rec
        s.instantiate(callbacks=rec.callbacks)
        if guid is None:
            s.setupExperiment(tolerance=tolerance, startTime=0.0)
            s.enterInitializationMode()
            for k, v in start.items():
                if k in self.items:
                    s.setInteger([self.vr[k]], [self.items[k][v]])
                    continue
                setter = {"Real": s.setReal, "Integer": s.setInteger, "Boolean": s.setBoolean}[self.type[k]]
                setter([self.vr[k]], [v])
            s.exitInitializationMode()
        return s


def _fmu_fixture(identifier):
    """A session fixture: the FMU `identifier`, unpacked once."""
    return pytest.fixture(scope="session")(lambda tmp_path_factory: Fmu(identifier, tmp_path_factory))


controller = _fmu_fixture("PressureFeedbackController")
boom = _fmu_fixture("HydraulicBoom")
circuit = _fmu_fixture("HydraulicCircuit")
mechanics = _fmu_fixture("BoomMechanics")
