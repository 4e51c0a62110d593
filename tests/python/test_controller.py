"""PressureFeedbackController through fmpy: validation, archive, analytic responses of eq. 6.2,
independent instances, FMU states, and misuse (FMI 2.0 rules)."""

import ctypes
import math
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu
from fmpy.fmi1 import FMICallException

from conftest import EXPORTED

ID = "PressureFeedbackController"
# Experiment B defaults (Table 7.2) and the rated flow per unit opening (section 2.2.1).
K_F, OMEGA_F, Q_RATED = 1.24e-11, 35.8, 25e-3 / 60


def g_f(omega, k_f=K_F, omega_f=OMEGA_F):
    """u_comp/p of eq. 6.2 in spool units: (K_f/Q_rated) j w / (j w/omega_f + 1)."""
    s = 1j * omega
    return k_f / Q_RATED * s / (s / omega_f + 1)


def test_validate_finds_no_problem(controller):
    assert validate_fmu(controller.path) == []


def test_archive_layout_symbols_and_dependencies(controller, tmp_path):
    with zipfile.ZipFile(controller.path) as z:
        names = set(z.namelist())
        assert {"modelDescription.xml", f"binaries/linux64/{ID}.so", "documentation/index.html"} <= names
        z.extract(f"binaries/linux64/{ID}.so", tmp_path)
        doc = z.read("documentation/index.html").decode()
    assert "K_f" in doc and "eq. 6.2" in doc
    so = tmp_path / "binaries" / "linux64" / f"{ID}.so"
    nm = subprocess.run(["nm", "-D", "--defined-only", so], capture_output=True, text=True, check=True)
    exported = {line.split()[-1] for line in nm.stdout.splitlines()}
    assert exported == EXPORTED, "exactly the 44 FMI 2.0 and the 75 FMI 3.0 functions"
    ldd = subprocess.run(["ldd", so], capture_output=True, text=True, check=True)
    libs = {line.split()[0] for line in ldd.stdout.splitlines()}
    allowed = ("linux-vdso", "libc.so", "libm.so", "libgcc_s.so", "/lib64/ld-linux", "ld-linux")
    assert all(lib.startswith(allowed) for lib in libs), libs


def test_simulate_default_experiment_with_a_pressure_ramp(controller):
    # Inputs: u_ref -0.05 and p falling 10 bar/s from 160 bar. fmpy interpolates inputs linearly
    # and passes no derivatives, so the FMU sees p held over each 1 ms step (zero-order hold).
    t = np.array([0.0, 15.0])
    signals = np.array(list(zip(t, [-0.05, -0.05], [160e5, 10e5]))
                       , dtype=[("time", float), ("u_ref", float), ("p", float)])
    r = simulate_fmu(controller.path, fmi_type="CoSimulation", input=signals, output=["u", "u_comp"])
    assert r["time"][-1] == pytest.approx(15.0)
    # A ramp a held over steps h is a staircase of jumps a*h; in steady state the filter state
    # z = p - x swings between a*h*e^(-wh)/(1 - e^(-wh)) (before a jump) and a*h/(1 - e^(-wh))
    # (after it), around the continuous-ramp value a/w; u_comp = K_f w z / Q_rated lies in that band.
    a, h, wh = -10e5, 1e-3, OMEGA_F * 1e-3
    lo, hi = sorted(K_F * OMEGA_F / Q_RATED * a * h / (1 - math.exp(-wh)) * np.array([math.exp(-wh), 1.0]))
    assert lo <= r["u_comp"][-1] <= hi
    assert np.allclose(r["u"], -0.05 + r["u_comp"], atol=1e-15)


@pytest.mark.parametrize("factor", [0.2, 1.0, 5.0])
def test_frequency_response_matches_eq_6_2(controller, factor):
    """Sinusoidal p, given to the FMU as a piecewise-linear signal (value + slope per step);
    the fitted first harmonic of u_comp is G_f(j w) within 1 % and 1 degree."""
    s = controller.slave(p=50e5)
    w = factor * OMEGA_F
    period = 2 * math.pi / w
    n_per, periods = 400, 12  # settle for 8 periods (e^-8*2pi*... >> decay), fit the last 4
    h = period / n_per
    amp, p0 = 2e5, 50e5
    p = lambda t: p0 + amp * math.sin(w * t)
    times, u = [], []
    for k in range(n_per * periods):
        t = k * h
        s.setReal([controller.vr["p"]], [p(t)])
        s.setRealInputDerivatives([controller.vr["p"]], [1], [(p(t + h) - p(t)) / h])
        s.doStep(t, h)
        times.append(t + h)
        u.append(s.getReal([controller.vr["u_comp"]])[0])
    t, u = np.array(times[-4 * n_per:]), np.array(u[-4 * n_per:])
    basis = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
    a, b, _ = np.linalg.lstsq(basis, u, rcond=None)[0]
    gain, phase = math.hypot(a, b) / amp, math.atan2(b, a)
    expected = g_f(w)
    assert gain == pytest.approx(abs(expected), rel=0.01)
    assert math.degrees(phase - np.angle(expected)) == pytest.approx(0.0, abs=1.0)
    s.terminate()
    s.freeInstance()


def test_step_response_is_the_analytic_exponential(controller):
    s = controller.slave(p=40e5, u_ref=-0.1)
    assert s.getReal([controller.vr["u_comp"]]) == [0.0], "filter at rest at the initial pressure"
    dp, h = 3e5, 1e-3
    s.setReal([controller.vr["p"]], [40e5 + dp])
    for k in range(300):
        t = k * h
        u_comp, u = s.getReal([controller.vr["u_comp"], controller.vr["u"]])
        expected = K_F * OMEGA_F * dp / Q_RATED * math.exp(-OMEGA_F * t)
        assert u_comp == pytest.approx(expected, rel=1e-9, abs=1e-15)
        assert u == pytest.approx(-0.1 + u_comp, abs=1e-15)
        s.doStep(t, h)
    s.terminate()
    s.freeInstance()


def test_any_partition_of_a_piecewise_linear_input_gives_the_same_output(controller):
    vr = controller.vr
    ramp = lambda t: 50e5 - 20e5 * t + (8e5 * (t - 0.05) if t > 0.05 else 0.0)

    def run(steps):
        s = controller.slave(p=ramp(0.0))
        t = 0.0
        for h in steps:
            slope = (ramp(t + h) - ramp(t)) / h
            s.setReal([vr["p"]], [ramp(t)])
            s.setRealInputDerivatives([vr["p"]], [1], [slope])
            s.doStep(t, h)
            t += h
        s.setReal([vr["p"]], [ramp(t)])
        out = s.getReal([vr["u_comp"]])[0]
        s.freeInstance()
        return out

    coarse = run([0.05, 0.05])
    fine = run([0.05 / 37] * 37 + [0.05 / 11] * 11)
    assert fine == pytest.approx(coarse, rel=1e-12)


def test_two_instances_with_different_gains_stay_independent(controller):
    a = controller.slave("a", p=50e5, K_f=1e-11)
    b = controller.slave("b", p=50e5, K_f=4e-11)
    for s in (a, b):
        s.setReal([controller.vr["p"]], [49e5])
    ua = a.getReal([controller.vr["u_comp"]])[0]
    ub = b.getReal([controller.vr["u_comp"]])[0]
    assert ua == pytest.approx(1e-11 * OMEGA_F * -1e5 / Q_RATED, rel=1e-12)
    assert ub == pytest.approx(4 * ua, rel=1e-12)
    a.freeInstance()
    assert b.getReal([controller.vr["u_comp"]])[0] == ub, "freeing one leaves the other intact"
    b.freeInstance()


def test_fmu_state_and_serialisation_continue_bit_exactly(controller):
    vr = controller.vr
    s = controller.slave(p=50e5, u_ref=-0.05)

    def run(k0):
        out = []
        for k in range(k0, k0 + 100):
            s.setReal([vr["p"]], [50e5 + 3e5 * math.sin(0.05 * k)])
            s.doStep(k * 1e-3, 1e-3)
            out.append(s.getReal([vr["u"]])[0])
        return out

    run(0)
    state = s.getFMUstate()
    blob = s.serializeFMUstate(state)
    reference = run(100)
    s.setFMUstate(state)
    assert run(100) == reference
    restored = s.deSerializeFMUstate(blob)
    s.setFMUstate(restored)
    assert run(100) == reference
    s.freeFMUstate(state)
    s.freeFMUstate(restored)
    s.freeInstance()


def expect_error(s, call, *words):
    """The call fails with fmi2Error, logs a message with the given words, the instance lives."""
    s.recorder.messages.clear()
    with pytest.raises(FMICallException) as e:
        call()
    assert e.value.status == 3
    errors = s.recorder.errors()
    assert errors and all(w in errors[-1] for w in words), errors


def test_misuse_is_refused_with_a_message(controller):
    vr = controller.vr
    fresh = controller.slave("fresh", guid=controller.md.guid)  # instantiated only
    expect_error(fresh, lambda: fresh.doStep(0.0, 1e-3), "fmi2DoStep", "Instantiated")
    fresh.freeInstance()

    s = controller.slave("misuse", p=50e5)
    expect_error(s, lambda: s.setReal([vr["p"]], [float("nan")]), "p = NaN", "valid range")
    expect_error(s, lambda: s.setReal([vr["u_ref"]], [2.0]), "u_ref = 2", "[-1, 1]")
    expect_error(s, lambda: s.getReal([4711]), "4711")
    expect_error(s, lambda: s.setReal([vr["Q_rated"]], [1e-3]), "Q_rated", "fixed")
    expect_error(s, lambda: s.doStep(0.0, -1e-3), "communicationStepSize = -0.001")
    expect_error(s, lambda: s.doStep(0.5, 1e-3), "currentCommunicationPoint = 0.5")
    # After every refusal the instance still works and is unchanged.
    s.doStep(0.0, 1e-3)
    assert s.getReal([vr["u"], vr["p"]]) == [0.0, 50e5]

    state = s.getFMUstate()
    blob = bytearray(s.serializeFMUstate(state))
    blob[len(blob) // 2] ^= 0xFF
    expect_error(s, lambda: s.deSerializeFMUstate(bytes(blob)), "corrupted")
    expect_error(s, lambda: s.deSerializeFMUstate(bytes(blob[:10])), "too few")
    s.freeFMUstate(state)
    s.doStep(1e-3, 1e-3)
    s.terminate()
    s.freeInstance()


def test_wrong_guid_is_refused_with_a_message(controller):
    with pytest.raises(Exception, match="Failed to instantiate"):
        controller.slave("wrong", guid="{00000000-0000-0000-0000-000000000000}")


def test_null_pointers_through_ctypes(controller):
    """Raw calls with NULL arrays and NULL instances: fmi2Error, a message, no crash."""
    vr = controller.vr
    s = controller.slave("null", p=50e5)
    dll = s.dll
    for f in ("fmi2GetReal", "fmi2SetReal"):
        fn = getattr(dll, f)
        fn.restype = ctypes.c_int
        fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p]
        s.recorder.messages.clear()
        assert fn(s.component, None, 1, None) == 3
        assert "NULL" in s.recorder.errors()[-1]
    dll.fmi2DoStep.restype = ctypes.c_int
    dll.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    assert dll.fmi2DoStep(None, 0.0, 1e-3, 1) == 3
    dll.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
    dll.fmi2FreeInstance(None)
    dll.fmi2Instantiate.restype = ctypes.c_void_p
    assert dll.fmi2Instantiate(b"x", 1, controller.md.guid.encode(), None, None, 0, 0) is None
    assert s.getReal([vr["p"]]) == [50e5], "the instance is untouched"
    s.freeInstance()
