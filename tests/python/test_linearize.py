"""`boomsim linearize`'s files read by the formats' own readers: the .mat by scipy.io (MATLAB
Level 5), the .npz by numpy, both against the JSON the same command prints; and the eigenvalues it
reports against LAPACK's (numpy.linalg.eigvals) of the matrix it wrote, a second eigensolver."""

import json
import subprocess

import numpy as np
import pytest
import scipy.io

from conftest import ROOT

BOOMSIM = ROOT / "target" / "release" / "boomsim"


def linearize(*args):
    out = subprocess.run([str(BOOMSIM), "linearize", *args], capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.fixture(scope="module")
def flexible(tmp_path_factory):
    """The acceptance command's model (flexible boom, steady lowering at -0.05), as JSON and as
    the .mat and .npz files the same run wrote."""
    d = tmp_path_factory.mktemp("linearize")
    args = ["--boom", "flexible", "--u-ref", "-0.05", "--json"]
    report = json.loads(linearize(*args, "--out", str(d / "model.mat")))
    linearize(*args, "--out", str(d / "model.npz"))
    return report, scipy.io.loadmat(d / "model.mat"), np.load(d / "model.npz")


def test_the_mat_file_holds_the_json_model(flexible):
    report, mat, _ = flexible
    for key in "ABCD":
        # Bit for bit: both carry the same doubles (JSON with round-trip precision).
        np.testing.assert_array_equal(mat[key], np.array(report[key]), err_msg=key)
    n = len(report["states"])
    assert mat["A"].shape == (n, n) and mat["B"].shape == (n, 1) and mat["C"].shape == (5, n)
    cells = lambda k: [str(c[0]) for c in mat[k].ravel()]  # noqa: E731 (a cell of char rows)
    assert cells("state_names") == [s["name"] for s in report["states"]]
    assert cells("state_units") == [s["unit"] for s in report["states"]]
    assert cells("output_names") == ["p3", "p4", "cylinder.x", "cylinder.v", "boom.tip_deflection"]
    assert cells("input_names") == ["valve.u_ref"]
    np.testing.assert_array_equal(mat["x0"].ravel(), report["x0"])
    np.testing.assert_array_equal(mat["y0"].ravel(), report["y0"])


def test_the_npz_file_holds_the_json_model(flexible):
    report, _, npz = flexible
    for key in "ABCD":
        np.testing.assert_array_equal(npz[key], np.array(report[key]), err_msg=key)
    assert list(npz["state_names"]) == [s["name"] for s in report["states"]]
    assert list(npz["output_units"]) == [s["unit"] for s in report["outputs"]]
    assert npz["eigenvalues"].dtype == np.complex128


def test_eigenvalues_match_lapack(flexible):
    """The reported eigenvalues (nalgebra's Schur form) against LAPACK's of the written A:
    within 1e-10 of the largest |lambda| (7e4 1/s; measured 4e-12): both balance the 24 x 24
    matrix, whose entries span 1e-6 to 1e13, before their QR iterations."""
    report, mat, _ = flexible
    ours = np.array([complex(e["re"], e["im"]) for e in report["eigenvalues"]])
    lapack = np.linalg.eigvals(mat["A"])
    scale = np.abs(lapack).max()
    for z in lapack:
        assert np.abs(ours - z).min() < 1e-10 * scale, z
    # The damping and frequency columns follow from the eigenvalue.
    for e in report["eigenvalues"]:
        z = complex(e["re"], e["im"])
        assert e["frequency_hz"] == pytest.approx(abs(z) / (2 * np.pi), rel=1e-12)


def test_feedback_adds_the_filter_state_and_margins():
    report = json.loads(linearize("--boom", "rigid", "--feedback", "--bode", "--json"))
    assert [s["name"] for s in report["states"]][-1] == "filter.p_lp"
    assert report["margins"]["gain"] and report["margins"]["phase"]
    # The loop transfer function crosses |L| = 1 at the reported gain crossovers (between the
    # Bode grid's neighbours, 40 per decade).
    f, gain = np.array(report["bode"]["frequency_hz"]), np.array(report["bode"]["open_loop"]["gain"])
    crossings = f[1:][np.diff(np.sign(np.log(gain))) != 0]
    for p in report["margins"]["phase"]:
        if 0.1 < p["frequency_hz"] < 100:
            assert np.min(np.abs(np.log10(crossings / p["frequency_hz"]))) < 1 / 40, p
    # Closed loop of experiment B at 250 mm: every eigenvalue but the stroke's neutral one
    # (|lambda| < 1e-3 1/s: a lowering through another stroke is as steady) in the left half
    # plane (Fig. 6.10: B settles); without the feedback a pair is in the right one (Fig. 7.1).
    stable = lambda r: all(e["re"] < 0 or abs(complex(e["re"], e["im"])) < 1e-3 for e in r["eigenvalues"])  # noqa: E731
    assert stable(report)
    assert not stable(json.loads(linearize("--boom", "rigid", "--json")))


def test_the_circuit_has_the_ports_inputs(tmp_path):
    """HydraulicCircuit's model (its plain port): three inputs in the FMU's names, the force on
    the rod first among the outputs, written to .mat like the HydraulicBoom's."""
    report = json.loads(linearize("--model", "HydraulicCircuit", "--json", "--out", str(tmp_path / "c.mat")))
    assert [i["name"] for i in report["inputs"]] == ["valve.u_ref", "cylinder.x", "cylinder.v"]
    assert [o["name"] for o in report["outputs"]] == ["cylinder.F", "p3", "p4"]
    mat = scipy.io.loadmat(tmp_path / "c.mat")
    assert mat["B"].shape == (5, 3) and mat["D"].shape == (3, 3)
    np.testing.assert_array_equal(mat["D"], np.array(report["D"]))


def test_the_bode_figure_has_the_sine_points_on_its_curve(tmp_path):
    """boomsim.plot_bode (docs/linearize.md's figure; boomsim.figures checks its text and
    units as it saves): the sine test's points on the closed-loop curve within 5 % (they are
    measured some 35 mm further down the stroke than the curve's point: about 1 %)."""
    from boomsim import plot_bode

    fig = plot_bode.plot(tmp_path / "bode.png")
    assert (tmp_path / "bode.png").stat().st_size > 10_000
    gain, _ = fig.axes
    closed = json.loads(linearize("--boom", "flexible", "--output", "p4", "--feedback", "--bode", "--json"))
    f, g = closed["bode"]["frequency_hz"], closed["bode"]["channels"][0]["gain"]
    points = gain.lines[-1]
    for x, y in zip(points.get_xdata(), points.get_ydata()):
        assert y * 1e5 == pytest.approx(np.interp(np.log(x), np.log(f), g), rel=0.05), x


def test_a_scenario_file_sets_the_point_and_the_filter():
    """boomsim-linearize-scenario: C2.1's filter (K_f 2e-11, omega_f 17.91, Table 7.3) closes
    the loop at its final reference; U (controller off) at 5 s into its run stays open."""
    import sys

    def run(*args):
        cmd = [sys.executable, "-m", "boomsim.linearize_scenario", *args, "--", "--json"]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    c21 = run("C2.1", "--boom", "rigid")
    assert c21["feedback"]["K_f"] == 2e-11 and c21["feedback"]["omega_f"] == 17.91
    assert c21["point"] == {"kind": "lowering", "u_ref": -0.05, "stroke_mm": 250.0}
    u = run("U", "--boom", "rigid", "--at", "5")
    assert u["feedback"] is None and u["point"] == {"kind": "time", "u_ref": -0.1, "start_mm": 480.0, "t": 5.0}
