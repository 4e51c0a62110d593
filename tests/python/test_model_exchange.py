"""FMI 2.0 Model Exchange through fmpy: every FMU simulates with CVode, and the thesis' U and B
scenarios with plant and controller as ME reproduce the Co-Simulation regression metrics.

CVode settings (fmpy 0.3.32): BDF, dense Newton with a difference-quotient Jacobian,
rtol 1e-6 (the FMUs' default tolerance, as the CS runs), atol = rtol x the FMUs' nominal values.
"""


import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import fmu_path

from boomsim import cosim
from boomsim.model_exchange import run_me
from boomsim.scenarios import load_scenario
from boomsim import metrics
from boomsim import regression


def _both(identifier, stop_time, **kw):
    """The same experiment as ME (CVode) and as CS (the FMU's own solver)."""
    me = simulate_fmu(fmu_path(identifier), fmi_type="ModelExchange", stop_time=stop_time,
                      output_interval=1e-3, relative_tolerance=1e-6, **kw)
    cs = simulate_fmu(fmu_path(identifier), fmi_type="CoSimulation", stop_time=stop_time,
                      output_interval=1e-3, **kw)
    return me, cs


def _signal(name, rows):
    return np.array(rows, dtype=[("time", float), (name, float)])


@pytest.mark.parametrize("identifier, start, signal, outputs", [
    # Lowering with the valve opened 30 %: pilot pressure builds up, the CBV opens, the load moves.
    ("HydraulicBoom", {"boom.flexible": False}, ("valve.u_ref", -0.3), ["p3", "p4", "cylinder.x"]),
    ("HydraulicBoom", {"boom.flexible": True}, ("valve.u_ref", -0.3), ["p3", "p4", "cylinder.x"]),
    # The circuit with the rod held at 480 mm: the valve opens against the held load.
    ("HydraulicCircuit", {}, ("valve.u_ref", -0.3), ["p3", "p4", "valve.x_v"]),
    # The boom pushed by 3 % less than its holding force: it sinks onto the bottom stop.
    ("BoomMechanics", {"boom.flexible": False}, ("cylinder.F", 23000.0), ["cylinder.x", "cylinder.v"]),
    # The fed-back pressure falling 10 bar/s from 50 bar (fmpy interpolates it linearly). Only
    # the filter state: u and u_comp feed p through, and fmpy's CS loop reads them after a step
    # with the input of the step's start (a one-step lag that ME does not have).
    ("PressureFeedbackController", {}, ("p", 50e5, 40e5), ["filter.p_lp"]),
])
def test_every_fmu_simulates_as_model_exchange(identifier, start, signal, outputs):
    """ME and CS agree to 1e-3 of each output's range over the run: both integrate the same
    equations at rtol 1e-6 with local error control (the controller's CS step is exact); on the
    fast flanks (the CBV opening, the pilot pressure build-up) the two solvers' global errors
    show as time shifts of a few microseconds, which is up to 3.5e-4 of p4's range (rigid boom)."""
    name, first, last = (*signal, signal[-1]) if len(signal) == 2 else signal
    me, cs = _both(identifier, 1.0, start_values=start, input=_signal(name, [(0.0, first), (1.0, last)]), output=outputs)
    assert len(cs) == 1001 and me["time"][-1] == cs["time"][-1]
    for name in outputs:
        # fmpy records an extra row at each state event (the dead-band edges): compare on CS's grid.
        on_grid = np.interp(cs["time"], me["time"], me[name])
        span = np.ptp(cs[name]) + 1e-9 * np.abs(cs[name]).max()
        worst = np.abs(on_grid - cs[name]).max() / span
        assert worst < 1e-3, f"{identifier}.{name}: ME differs from CS by {worst:.2e} of its range"


@pytest.fixture(scope="module")
def tolerances():
    return regression.load_tolerances()


@pytest.mark.parametrize("scenario", ["U", "B"])
@pytest.mark.parametrize("boom", ["rigid", "flexible"])
def test_scenarios_as_model_exchange_match_co_simulation(scenario, boom, tolerances):
    """Plant and controller as one ME system under CVode (no communication step: the loop has no
    delay) against the CS runner at 1 ms: every regression metric within 2 % of the CS value,
    with the regression suite's absolute floors (the package's baselines/tolerances.toml: 10 ms for the
    times sampled at 1 ms, 0.2 bar for a settled p3's drift, 5e-4 for u_comp's numerical noise),
    and a missing metric (never settles) missing in both. Whole records: under the modal damping
    law (`boom.damping` = 2) CVode needs about 0.1 M right-hand sides for U flexible (2 M under
    the thesis' law, 10 minutes of the test command)."""
    sc = load_scenario(scenario)
    me, cs = metrics.compute(run_me(sc, boom)), metrics.compute(cosim.run(sc, boom))
    rules = {k: {**r, "rel": 0.02} for k, r in tolerances.items()}
    assert regression.compare(f"{scenario}-{boom} ME", me, cs, rules) == []


@pytest.mark.parametrize("flexible", [False, True])
def test_model_exchange_at_an_importers_tolerance(flexible):
    """HydraulicBoom alone, u_ref = -0.3 from rest, 1 s: the lowering oscillates (p3 swings
    between 3 and 239 bar at about 3 Hz). Under fmpy's CVode at rtol 1e-4, the default tolerance
    of Dymola and OMSimulator, against the FMU's own Radau IIA at rtol 1e-9 (a second
    integrator): p3 within 2 bar at every output point (issue 27's acceptance; 1 % of its swing),
    and every pressure within [-1.01325, 400] bar: above absolute vacuum, and below 400 bar, which
    no state of this circuit reaches (supply 200 bar, CBV setting 210 bar; the reference peaks at
    239 bar). Before line 1 was quasi-static, CVode's iterates overshot p1 through the
    compensator's kinks and the run reached 5e7 bar with OK statuses."""
    kw = dict(stop_time=1.0, output_interval=1e-3, output=["p1", "p2", "p3", "p4"],
              start_values={"boom.flexible": flexible, "valve.u_ref": -0.3})
    me = simulate_fmu(fmu_path("HydraulicBoom"), fmi_type="ModelExchange", relative_tolerance=1e-4, **kw)
    ref = simulate_fmu(fmu_path("HydraulicBoom"), fmi_type="CoSimulation", relative_tolerance=1e-9, **kw)
    error = np.abs(np.interp(ref["time"], me["time"], me["p3"]) - ref["p3"]).max() / 1e5
    assert error < 2.0, f"p3 {error:.3g} bar off"
    for p in ("p1", "p2", "p3", "p4"):
        assert -1.01325e5 <= me[p].min() and me[p].max() <= 400e5, (p, me[p].min(), me[p].max())


@pytest.mark.parametrize("u_ref, rtol", [(-0.1, 1e-4), (-0.3, 1e-3)])
def test_trial_states_below_vacuum_do_not_stop_cvode(u_ref, rtol):
    """Issue 49: HydraulicBoom alone, rigid, lowering from rest for 2 s under fmpy's own
    simulate_fmu (CVode, whose right-hand-side callback takes an fmi2Discard for an
    unrecoverable failure). CVode's trial states put p4 below absolute zero; when the plant
    answered them with Discard these runs stopped (at 1.62 s and 0.90 s); the equations are now
    continued there. Against the FMU's own Radau IIA at rtol 1e-9 (a second integrator): the run
    completes, p3 is within 2 bar over the first 0.3 s (the issue's tolerance, 1 % of p3's
    swing), and at rtol 1e-4 every pressure is within [-1.01325, 400] bar (absolute zero; no state
    of this circuit reaches 400 bar: supply 200 bar, CBV setting 210 bar) and p3's peak-to-peak,
    dominant frequency and the lowering over 1-2 s are within 2 % (the issue's). At 1e-3 CVode's
    output points reach 2.8 kPa below vacuum and the cycle's phase drifts (docs/interfaces.md),
    so only the completion and the first 0.3 s are checked there."""
    kw = dict(stop_time=2.0, output_interval=1e-3, output=["p1", "p2", "p3", "p4", "cylinder.x"],
              start_values={"boom.flexible": False, "valve.u_ref": u_ref})
    me = simulate_fmu(fmu_path("HydraulicBoom"), fmi_type="ModelExchange", relative_tolerance=rtol, **kw)
    ref = simulate_fmu(fmu_path("HydraulicBoom"), fmi_type="CoSimulation", relative_tolerance=1e-9, **kw)
    assert me["time"][-1] == pytest.approx(2.0)
    first = ref["time"] <= 0.3
    error = np.abs(np.interp(ref["time"][first], me["time"], me["p3"]) - ref["p3"][first]).max() / 1e5
    assert error < 2.0, f"p3 {error:.3g} bar off"
    if rtol > 1e-4:
        return
    for p in ("p1", "p2", "p3", "p4"):
        assert -1.01325e5 <= me[p].min() and me[p].max() <= 400e5, (p, me[p].min(), me[p].max())

    def late(r):
        k = r["time"] >= 1.0
        return np.ptp(r["p3"][k]), metrics.dominant_frequency(r["time"][k], r["p3"][k])[0], \
            r["cylinder.x"][-1] - np.interp(1.0, r["time"], r["cylinder.x"])

    for name, m, c in zip(("p3 peak-to-peak", "f_dom", "lowering"), late(me), late(ref)):
        assert abs(m / c - 1) < 0.02, f"{name}: {m:.4g} vs {c:.4g}"


@pytest.mark.parametrize("scenario, boom", [("B", "rigid"), ("B", "flexible"), ("U", "flexible")])
def test_compensated_lowering_at_an_importers_tolerance(scenario, boom, tolerances):
    """Plant and controller as one ME system under CVode at rtol 1e-4, the default tolerance of
    Dymola and OMSimulator: every regression metric within the regression suite's own
    tolerances of the CS run (the package's baselines/tolerances.toml; issue 27's row). The
    flexible arm passes under the modal damping law, the default (under the thesis' law B's
    u_comp_rms was 2.6 times the CS value). In U, CVode's trial states put p4 below absolute
    zero; the plant's equations are continued there (issue 49) and the controller takes such a
    fed-back pressure. Not covered, as measured
    (docs/interfaces.md): U rigid, which completes with v_mean 3.3 % slow (0.58 mm/s, tolerance
    0.23 mm/s): CVode's error at 1e-4 in the stick-slip cycle."""
    sc = load_scenario(scenario)
    me = metrics.compute(run_me(sc, boom, tolerance=1e-4))
    cs = metrics.compute(cosim.run(sc, boom))
    assert regression.compare(f"{scenario}-{boom} ME 1e-4", me, cs, tolerances) == []


def test_directional_derivatives_through_fmpy():
    """HydraulicCircuit's Jacobian column of the state cbv.u_cbv (the load-holding valve 30 %
    open while lowering: it drives p2, p3 and itself) through fmpy's getDirectionalDerivative
    against central differences of fmpy's getDerivatives: relative 1e-6 on the entries above
    1e-8 of the column's largest (h = 1e-7 of the opening: truncation h^2 f''' and round-off
    eps |f| / h both below 1e-8 of the entries)."""
    from ctypes import POINTER, c_double
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Model

    path = fmu_path("HydraulicCircuit")
    md = read_model_description(path)
    assert md.modelExchange.providesDirectionalDerivative
    vr = {v.name: v.valueReference for v in md.modelVariables}
    m = FMU2Model(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.modelExchange.modelIdentifier)
    m.instantiate()
    m.setupExperiment(startTime=0.0)
    m.enterInitializationMode()
    m.setReal([vr["valve.u_ref"], vr["cylinder.v"]], [-0.3, -0.01])
    m.exitInitializationMode()
    m.newDiscreteStates()
    m.enterContinuousTimeMode()
    n = len(md.derivatives)
    state = {d.variable.derivative.name: k for k, d in enumerate(md.derivatives)}
    x = np.zeros(n)
    m.getContinuousStates(x.ctypes.data_as(POINTER(c_double)), n)
    x[state["p4"]] += 20e5  # rod side pressurised: the valve and the CBV pilot act
    x[state["valve.x_v"]] = -2e-3  # spool open, lowering
    x[state["cbv.u_cbv"]] = 0.3

    def derivatives(x):
        m.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), n)
        dx = np.zeros(n)
        m.getDerivatives(dx.ctypes.data_as(POINTER(c_double)), n)
        return dx

    h = 1e-7
    seed = np.eye(n)[state["cbv.u_cbv"]]
    column = (derivatives(x + h * seed) - derivatives(x - h * seed)) / (2 * h)
    derivatives(x)
    ders = [d.variable.valueReference for d in md.derivatives]
    dd = np.array(m.getDirectionalDerivative(ders, [vr["cbv.u_cbv"]], [1.0]))
    big = np.abs(dd) > 1e-8 * np.abs(dd).max()
    assert big.sum() >= 2
    assert np.allclose(dd[big], column[big], rtol=1e-6, atol=0), (dd, column)
    m.terminate()
    m.freeInstance()
