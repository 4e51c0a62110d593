"""The FMI 3.0 .fmu files through fmpy (FMU3Slave / FMU3Model): validation, archive, every FMU
simulated in Co-Simulation and Model Exchange, and the thesis' U and B scenarios against the
FMI 2.0 .fmu of the same binary: Co-Simulation bit-identical, with p4 held over a step and with
p4 linear over a step (FMI 2.0: its input derivative; FMI 3.0, which has none: intermediate update,
4.2.3, the controller's callback setting p on the line to the next sample), Model Exchange
bit-identical to FMI 2.0 Model Exchange and within 2 % of the Co-Simulation regression metrics."""

import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from conftest import FMU_DIR, fmu_path

from boomsim import cosim
from boomsim.errors import UsageError
from boomsim.model_exchange import run_me
from boomsim.result import COLUMNS
from boomsim.scenarios import load_scenario
from boomsim import metrics
from boomsim import regression

IDS = ["PressureFeedbackController", "HydraulicBoom", "HydraulicCircuit", "BoomMechanics"]


def fmu3_path(identifier):
    path = FMU_DIR / "fmi3" / f"{identifier}.fmu"
    assert path.exists(), f"{path} is missing: run target/release/boomsim pack"
    return str(path)


@pytest.mark.parametrize("identifier", IDS)
def test_validates_and_ships_the_fmi2_binary_under_the_fmi3_platform_tuple(identifier):
    assert validate_fmu(fmu3_path(identifier)) == []
    with zipfile.ZipFile(fmu3_path(identifier)) as z3, zipfile.ZipFile(fmu_path(identifier)) as z2:
        md = z3.read("modelDescription.xml").decode()
        assert 'fmiVersion="3.0"' in md and "FMI 3.0" in z3.read("documentation/index.html").decode()
        # One library exports both versions' functions: the same bytes in both archives.
        assert z3.read(f"binaries/x86_64-linux/{identifier}.so") == z2.read(f"binaries/linux64/{identifier}.so")


@pytest.mark.parametrize("identifier", IDS)
def test_simulates_in_both_interfaces_as_in_fmi2(identifier):
    """0.2 s from the start values: FMI 3.0 CS gives FMI 2.0 CS's results bit for bit (same model,
    same solver, same steps). Model Exchange too: the FMI 3.0 FMUs declare the same event
    indicators as variables (ModelStructure <EventIndicator>), so fmpy's CVode takes the same
    steps and events in both versions. The plants lower (valve.u_ref = -0.3), so the spool
    crosses the dead band's edges: events that an FMU without indicators would step over."""
    kw = dict(stop_time=0.2, output_interval=1e-3)
    cs3 = simulate_fmu(fmu3_path(identifier), fmi_type="CoSimulation", **kw)
    cs2 = simulate_fmu(fmu_path(identifier), fmi_type="CoSimulation", **kw)
    assert len(cs3) == 201 and cs3.dtype.names == cs2.dtype.names
    for name in cs3.dtype.names:
        assert np.array_equal(cs3[name], cs2[name]), name
    lowering = {"valve.u_ref": -0.3} if identifier in ("HydraulicBoom", "HydraulicCircuit") else {}
    kw.update(fmi_type="ModelExchange", relative_tolerance=1e-6, start_values=lowering)
    me3 = simulate_fmu(fmu3_path(identifier), **kw)
    me2 = simulate_fmu(fmu_path(identifier), **kw)
    assert me3.dtype.names == me2.dtype.names
    if lowering:
        # Rows beyond the 201 output points are events (fmpy records both sides of each).
        assert len(me2) > 201, "the lowering run crosses the dead band"
    for name in me3.dtype.names:
        assert np.array_equal(me3[name], me2[name]), name


@pytest.mark.parametrize("interpolate", [False, True], ids=["held", "intermediate update"])
@pytest.mark.parametrize("scenario", ["U", "B"])
def test_scenarios_in_fmi3_co_simulation_are_bit_identical_to_fmi2(scenario, interpolate):
    """The Gauss-Seidel coupling of boomsim.cosim, the controller's p4 held or linear over a step
    (the issue asked 1e-9 of the ramped one; it is bit for bit: the controller takes the master's
    value at the step's end, the slope FMI 2.0's master passes)."""
    sc = load_scenario(scenario)
    for boom in sc["booms"]:
        two = cosim.run(sc, boom, interpolate=interpolate, fmi=2)
        three = cosim.run(sc, boom, interpolate=interpolate, fmi=3)
        for c in COLUMNS:
            assert np.array_equal(two.data[c], three.data[c]), f"{scenario}-{boom} {c}"


def test_fmi3_has_no_input_derivatives():
    """fmi3 has no fmi3SetRealInputDerivatives: the FMI 2.0 name on an FMI 3.0 instance says what
    to use instead."""
    slave = cosim.FmuFile.get("PressureFeedbackController", 3).slave("d")
    with pytest.raises(UsageError, match="intermediate update"):
        slave.setRealInputDerivatives([0], [1], [0.0])
    cosim.release(slave)


@pytest.mark.parametrize("scenario", ["U", "B"])
@pytest.mark.parametrize("boom", ["rigid", "flexible"])
def test_scenarios_in_fmi3_model_exchange_match_co_simulation(scenario, boom):
    """Both booms (the flexible one in seconds under the modal damping law; under the thesis' law it
    took 6 and 2 minutes). The rules of test_model_exchange.py: every regression metric within
    2 % of FMI 2.0 CS (with slope), with the suite's absolute floors."""
    sc = load_scenario(scenario)
    me = metrics.compute(run_me(sc, boom, fmi=3))
    cs = metrics.compute(cosim.run(sc, boom))
    rules = {k: {**r, "rel": 0.02} for k, r in regression.load_tolerances().items()}
    assert regression.compare(f"{scenario}-{boom} FMI 3.0 ME", me, cs, rules) == []
