"""HydraulicBoom with the lumped flexible boom (thesis 2.1.4, 3.1.2): the free vibration of the FMU
against the linearised modes of `boomsim eigen` (a second method: eigenvalues of the Jacobian at
rest), and the rigid-vs-flexible comparison of thesis 3.3."""

import json
import subprocess

import numpy as np
import pytest

from conftest import ROOT


@pytest.fixture(scope="module")
def eigen():
    out = subprocess.run([str(ROOT / "target" / "release" / "boomsim"), "eigen", "--json"],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def run(boom, u_ref, t_end, h=1e-3, output="p3", **start):
    s = boom.slave(**start)
    n = int(round(t_end / h))
    y = np.empty(n)
    for k in range(n):
        s.setReal([boom.vr["valve.u_ref"]], [u_ref(k * h)])
        s.doStep(k * h, h)
        y[k] = s.getReal([boom.vr[output]])[0]
    s.freeInstance()
    return np.arange(1, n + 1) * h, y


def crossing_frequency(t, y):
    """Frequency from the upward zero crossings of y - mean (linear interpolation between samples):
    (number of periods) / (time between first and last crossing)."""
    y = y - y.mean()
    k = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    tc = t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])
    return (len(tc) - 1) / (tc[-1] - tc[0])


def test_free_vibration_matches_the_lowest_linearised_mode(boom, eigen):
    """At rest with the boom horizontal, friction off (as in the linearisation), a spool pulse of
    +3 % for 0.6 s just opens the check valve and lifts the boom by a few micrometres; p3 then
    oscillates at the lowest mode (the payload swinging on the oil column and the flexible arm).
    The linearisation holds for small amplitudes only: at rest the rod side is drained to tank,
    where the entrained air makes its bulk modulus steep in p4 (92 MPa at 0 bar gauge, ~1 GPa at
    10 bar), so a larger pulse that swings p4 over several bar stiffens the rod side and raises the
    frequency (+3.6 % for a 0.7 s pulse, p4 up to 3 bar). Tolerance 3 % (the issue's bound), with
    p4 kept within 0..2 bar; the crossings of the 2.5 Hz wave over 8 s average out the ripple of
    the 47 Hz beam mode."""
    mode = eigen["modes"][0]
    expected = mode["frequency_hz"] * np.sqrt(1 - mode["damping_ratio"] ** 2)
    start = {"start.x": eigen["stroke_mm"] / 1e3, "friction.c_p_bak": 0.0, "friction.p_static": 0.0}
    pulse = lambda t: 0.03 if t < 0.6 else 0.0
    t, p3 = run(boom, pulse, 10.0, **start)
    _, p4 = run(boom, pulse, 10.0, output="p4", **start)
    window = t > 2.0
    assert p3[window].max() - p3[window].min() > 1e5, "the pulse excites a measurable oscillation"
    assert 0.0 < p4[window].min() and p4[window].max() < 2e5, "small amplitude in the rod side"
    assert crossing_frequency(t[window], p3[window]) == pytest.approx(expected, rel=0.03)


def test_structural_damping_decays_as_the_linearised_mode(boom):
    """`boom.damping = structural` (the arm's Rayleigh damping, xi at its first bending mode) in
    the nonlinear FMU against the linearisation of `boomsim eigen --set boom.damping=structural`: after the
    pulse of the test above, the envelope of p3's oscillation decays as exp(-zeta omega_n t) with
    the lowest mode's zeta (0.8 %, against 0.01 % under the thesis' per-section law). The decay
    rate is a line fitted to the log of one peak per period over 8 s (some 20 periods, to e^-1
    of the amplitude). Measured 0.136 1/s against the linearisation's 0.120: the rod side's air
    stiffens with the amplitude (the frequency is 1.8 % above the linear one, see the test
    above), which moves the mode towards the arm, whose damping it carries; 20 % covers that and
    still tells the two laws apart by a factor of 60."""
    out = subprocess.run([str(ROOT / "target" / "release" / "boomsim"), "eigen", "--json", "--set",
                          "boom.damping=structural"], capture_output=True, text=True, check=True)
    linear = json.loads(out.stdout)
    mode = linear["modes"][0]
    start = {"start.x": linear["stroke_mm"] / 1e3, "friction.c_p_bak": 0.0, "friction.p_static": 0.0,
             "boom.damping": "structural"}
    t, p3 = run(boom, lambda t: 0.03 if t < 0.6 else 0.0, 10.0, **start)
    window = t > 2.0
    t, y = t[window], p3[window] - p3[window].mean()
    # One peak per period: the largest sample between two upward zero crossings.
    up = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    tops = [a + np.argmax(y[a:b]) for a, b in zip(up[:-1], up[1:])]
    slope = np.polyfit(t[tops], np.log(y[tops]), 1)[0]
    sigma = mode["frequency_hz"] * 2 * np.pi * mode["damping_ratio"]
    assert 0.005 < mode["damping_ratio"] < 0.02
    assert crossing_frequency(t, y) == pytest.approx(mode["frequency_hz"], rel=0.03)
    assert -slope == pytest.approx(sigma, rel=0.2), (slope, mode)


def test_flexible_boom_lowers_the_oscillation_frequency(boom, eigen):
    """Thesis 3.3: the boom's flexibility lowers the system's natural frequency, so the limit
    cycle of the uncompensated lowering (480 mm, u = -0.1) oscillates slower with the flexible
    boom than with the rigid one; the linearised modes predict the same order."""
    assert eigen["modes"][0]["frequency_hz"] < eigen["rigid_modes"][0]["frequency_hz"]
    f = {}
    for flexible in (False, True):
        t, p3 = run(boom, lambda t: -0.1, 8.0, **{"boom.flexible": flexible})
        window = t > 4.0
        f[flexible] = crossing_frequency(t[window], p3[window])
    assert f[True] < f[False], f


def test_the_modal_law_makes_the_feedback_independent_of_the_lumping():
    """Why the modal damping law (`boom.damping` = modal) is the default: scenario B with the
    feedback started at the CBV's opening, u_comp_rms (the regression metric the law moves most),
    with the arm in 4 + 5 and in 8 + 10 sections. Under the modal law the two agree within 5 %
    (a converged lumping: at 4 + 5 the first bending frequency is within 1.4 % of 16 + 16
    sections', docs/models.md; measured 0.1 %); under the thesis' per-section law the finer
    arm's value is more than twice the coarser's (measured 0.00120 -> 0.00345, and 0.00546 at
    12 + 15): the modes above 50 Hz, whose damping that law divides by n^2, ring, and the
    high-pass feedback passes them on."""
    from boomsim import cosim, metrics
    from boomsim.scenarios import load_scenario

    def u_comp_rms(law, n2, n3):
        params = {"boom.damping": law, "boom.n2": n2, "boom.n3": n3}
        run = cosim.run(load_scenario("B"), "flexible", feedback_start="cbv_open", params=params)
        return metrics.compute(run)["u_comp_rms"]

    modal = u_comp_rms("modal", 4, 5), u_comp_rms("modal", 8, 10)
    thesis = u_comp_rms("thesis", 4, 5), u_comp_rms("thesis", 8, 10)
    assert modal[1] == pytest.approx(modal[0], rel=0.05), modal
    assert thesis[1] > 2 * thesis[0], thesis
