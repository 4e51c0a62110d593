"""boomsim.parameter_sweep: a sweep on a LocalCluster gives the metrics of the same points run serially
in-process, a failing point is a row with fmpy's error, --resume runs only the missing points, and
a bad sweep file is refused in one line before anything runs; the filter factors n_K / n_omega
follow eq. 6.6 / 6.7, a point beyond its timeout is a failed row, reused FMU instances give the
fresh instances' results bit for bit, so does the native runner, and the summary finds the settle region and the recommended
filter of a grid whose answer is counted by hand. Short rigid-boom runs of B."""

import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from boomsim import cosim
from boomsim.native import run_native
from boomsim.result import COLUMNS
from boomsim.scenarios import load_scenario
from boomsim import metrics
from boomsim import parameter_sweep as sweep
from boomsim import sweep_summary

ROOT = pathlib.Path(__file__).resolve().parents[2]

METRICS = ["p3_pp_max", "p3_pp_late", "u_comp_max", "v_steady"]


def sweep_file(tmp_path, parameters: str, head: str = 'scenario = "B"\nstop_time = 1.0\n', name="s.toml"):
    path = tmp_path / name
    path.write_text(head + f"metrics = {METRICS!r}\n[parameters]\n" + parameters)
    return path


def cli(*args):
    r = subprocess.run([sys.executable, "-m", "boomsim.parameter_sweep", *map(str, args)],
                       capture_output=True, text=True)
    return r.returncode, r.stderr


def rows_by_id(s, out):
    return {r["id"]: r for r in sweep.read_rows(s, out)}


def test_two_workers_give_the_serial_metrics_exactly(tmp_path):
    f = sweep_file(tmp_path, "K_f = {grid = [1.0e-11, 1.24e-11]}\nomega_f = {grid = [30.0, 35.8]}\n"
                             '"cbv.mu_p" = {grid = [3.0, 4.0]}\n')
    code, err = cli(f, "--workers", "2", "--out", tmp_path / "out")
    assert code == 0, err
    s = sweep.load(f)
    rows = rows_by_id(s, tmp_path / "out")
    assert len(rows) == 8 and {r["status"] for r in rows.values()} == {"ok"}
    assert "local" not in {r["worker"] for r in rows.values()}  # ran on the cluster
    for p in s["points"]:
        serial = sweep.run_point(s, p)
        assert serial["status"] == "ok" and serial["worker"] == "local"
        assert {m: rows[p["id"]][m] for m in METRICS} == {m: serial[m] for m in METRICS}
    assert "8 of 8 points run, 0 failed" in (tmp_path / "out" / "summary.md").read_text()
    assert (tmp_path / "out" / "map-p3_pp_late.png").exists()


def test_a_failing_point_is_a_row_with_its_error(tmp_path):
    """fluid.beta = 5e9 is above its range [1e8, 3e9] in the modelDescription: the run refuses it
    with a UsageError naming the parameter, the value and the range, before any FMU is made."""
    f = sweep_file(tmp_path, '"fluid.beta" = {grid = [1.4e9, 5e9, 2.0e9]}\n')
    code, err = cli(f, "--workers", "1", "--out", tmp_path / "out")
    assert code == 0, err
    rows = sorted(sweep.read_rows(sweep.load(f), tmp_path / "out"), key=lambda r: r["fluid.beta"])
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    assert rows[2]["error"].startswith("UsageError: params['fluid.beta'] = 5000000000.0 is outside its valid range [")
    assert all(rows[2][m] is None for m in METRICS) and all(r["p3_pp_max"] > 0 for r in rows[:2])
    assert "1 failed" in err and "3 of 3 points run, 1 failed" in (tmp_path / "out" / "summary.md").read_text()


def test_resume_runs_only_the_missing_points(tmp_path):
    f = sweep_file(tmp_path, "K_f = {grid = [0.9e-11, 1.0e-11, 1.1e-11, 1.24e-11]}\n")
    s, out = sweep.load(f), tmp_path / "out"
    first = [sweep.run_point(s, p) for p in s["points"][:2]]  # what a killed sweep left behind
    sweep.write_rows(s, out, first)
    code, err = cli(f, "--resume", "--workers", "1", "--out", out)
    assert code == 0, err
    assert "4 points, 2 already done, 2 to run" in err
    rows = rows_by_id(s, out)
    assert sorted(rows) == sorted(p["id"] for p in s["points"])
    assert [rows[r["id"]]["worker"] for r in first] == ["local", "local"]  # not run again
    assert {rows[p["id"]]["worker"] for p in s["points"][2:]} != {"local"}
    code, err = cli(f, "--workers", "1", "--out", out)  # without --resume: refused
    assert code == 2 and "--resume" in err


@pytest.mark.parametrize("head,parameters,says", [
    ('scenario = "Q"\n', "K_f = {grid = [1e-11]}\n", ['unknown scenario "Q"', "U, A, S, B"]),
    ('scenario = "B"\n', "K_g = {grid = [1e-11]}\n", ['unknown parameter "K_g"', "K_f", "fluid.beta", "omega_f"]),
    ('scenario = "B"\n', "K_f = {grid = []}\n", ['parameter "K_f": empty grid']),
    ('scenario = "B"\nsamples = 3\nseed = 1\n', 'K_f = {dist = "beta", a = 1}\n',
     ['unknown distribution "beta"', "uniform, normal"]),
    ('scenario = "B"\nmetrics = ["t_settl"]\n', "K_f = {grid = [1e-11]}\n", ['unknown metric "t_settl"', "t_settle"]),
    ('scenario = "B"\n', "K_f = {grid = [1e-11]}\nn_K = {grid = [2.0]}\n", ['"n_K" and "K_f" both set K_f']),
    ('scenario = "B"\ntimeout = -1\n', "n_K = {grid = [2.0]}\n", ["timeout = -1", "> 0"]),
    ('scenario = "B"\nrunner = "rust"\n', "n_K = {grid = [2.0]}\n", ['unknown runner "rust"', "fmpy, native"]),
    ('scenario = "B"\n', "n_K = {grid = [2.0]}\n\"payload.m\" = {grid = [2500.0]}\n",
     ["no linear analysis at", "payload = 2500", "outside [0, 2000] kg"]),
])
def test_a_bad_sweep_file_is_refused_before_any_run(tmp_path, head, parameters, says):
    path = tmp_path / "bad.toml"
    metrics = "" if "metrics" in head else f"metrics = {METRICS!r}\n"
    path.write_text(head + metrics + "[parameters]\n" + parameters)
    code, err = cli(path, "--out", tmp_path / "out")
    last = err.strip().splitlines()[-1]
    assert code == 2 and len(err.strip().splitlines()) == 1 and all(s in last for s in says), err
    assert not (tmp_path / "out").exists()


def test_monte_carlo_points_are_seeded_and_crossed_with_the_grid(tmp_path):
    f = sweep_file(tmp_path, 'K_f = {grid = [1e-11, 1.24e-11]}\n"fluid.beta" = {dist = "uniform", low = 1.2e9, high = 1.8e9}\n'
                   'omega_f = {dist = "normal", mean = 35.8, sd = 3.0}\n',
                   head='scenario = "B"\nsamples = 5\nseed = 7\n')
    a, b = sweep.load(f)["points"], sweep.load(f)["points"]
    assert a == b and len(a) == 10 and len({p["id"] for p in a}) == 10
    assert all(1.2e9 <= p["fluid.beta"] <= 1.8e9 for p in a)
    assert [p["fluid.beta"] for p in a[:5]] == [p["fluid.beta"] for p in a[5:]]  # the same draws per grid point


def test_filter_factors_follow_eq_6_6_and_6_7(tmp_path):
    """K_f = n_K C1 mu_c mu_p (eq. 6.6) with C1 = A x_c / beta (eq. 2.70, no extra volume, as
    section 2.3), x_c the start stroke, the cylinder's areas of the parameter list (metrics.py);
    omega_f = n_omega omega_n (eq. 6.7) with omega_n^2 = A^2 / (C1 m) (eq. 2.81): independent of
    mu_p, proportional to beta, and 1 / omega_n^2 affine in the payload (the boom's effective
    mass is J_B (dtheta/dl)^2 + m_rod, J_B affine in the payload mass). 1e-12 relative: rounding."""
    f = sweep_file(tmp_path, 'n_K = {grid = [1.0, 3.0]}\nn_omega = {grid = [0.5, 2.0]}\n"cbv.mu_p" = {grid = [2.0, 5.0]}\n'
                   '"payload.m" = {grid = [0.0, 200.0, 382.6]}\n"fluid.beta" = {grid = [1.3e9, 1.6e9]}\n')
    points = sweep.load(f)["points"]
    assert len(points) == 48
    mu_c = metrics.A_ROD_SIDE / metrics.A_PISTON
    omega_n = {}
    for p in points:
        c1 = metrics.A_PISTON * 0.480 / p["fluid.beta"]
        assert p["K_f"] == pytest.approx(p["n_K"] * c1 * mu_c * p["cbv.mu_p"], rel=1e-12)
        omega_n.setdefault((p["payload.m"], p["fluid.beta"]), []).append(p["omega_f"] / p["n_omega"])
    assert all(max(w) / min(w) - 1 < 1e-12 for w in omega_n.values())  # the same for every mu_p and n_K
    w = {k: v[0] for k, v in omega_n.items()}
    for m in (0.0, 200.0, 382.6):
        assert w[m, 1.6e9] ** 2 / w[m, 1.3e9] ** 2 == pytest.approx(1.6 / 1.3, rel=1e-12)
    inv = [1 / w[m, 1.3e9] ** 2 for m in (0.0, 200.0, 382.6)]
    assert (inv[2] - inv[0]) / 382.6 == pytest.approx((inv[1] - inv[0]) / 200.0, rel=1e-9)


def test_a_point_beyond_its_timeout_is_a_failed_row(tmp_path):
    """A 1 s run cannot take less than 1 ms of wall time (1000 communication steps); the next point
    (no timeout) runs on."""
    s = sweep.load(sweep_file(tmp_path, "K_f = {grid = [1.0e-11, 1.24e-11]}\n",
                              head='scenario = "B"\nstop_time = 1.0\ntimeout = 0.001\n'))
    row = sweep.run_point(s, s["points"][0])
    assert row["status"] == "failed" and all(row[m] is None for m in METRICS)
    assert row["error"].startswith("TimeoutError: exceeded the timeout of 0.001 s at t = "), row["error"]
    assert sweep.run_point({**s, "timeout": None}, s["points"][1])["status"] == "ok"


def test_the_communication_step_is_a_sweep_parameter(tmp_path):
    """`step` runs each point at its communication step: the rows equal cosim.run's metrics at
    that step, and a step the stop time is not a multiple of is a failed row saying so."""
    s = sweep.load(sweep_file(tmp_path, "step = {grid = [1e-3, 5e-3, 3e-3]}\n"))
    rows = [sweep.run_point(s, p) for p in s["points"]]
    for p, row in zip(s["points"][:2], rows):
        ref = metrics.compute(cosim.run(s["scenario"], "rigid", step=p["step"], stop_time=1.0))
        assert row["status"] == "ok" and {m: row[m] for m in METRICS} == {m: ref[m] for m in METRICS}
    assert rows[0]["p3_pp_max"] != rows[1]["p3_pp_max"]
    assert rows[2]["status"] == "failed" and "stop_time=1.0: a whole multiple of the step 0.003 s" in rows[2]["error"]


def test_reused_instances_give_the_fresh_results_bit_for_bit():
    """fmi2Reset returns an instance to its state after instantiation: every parameter a run set
    before (fluid.beta, cbv.mu_p, the filter) is back at its start value. A sequence of runs on
    reused instances, a failing one (fmi2Error: a rod wider than the bore, which each parameter's
    range allows and the model's cross-check refuses) and a timed-out one among them, against the
    same runs on fresh instances: every recorded value equal."""
    sc = load_scenario("B")
    sequence = [{"fluid.beta": 1.4e9, "K_f": 1.0e-11}, {}, {"cbv.mu_p": 5.0, "omega_f": 50.0, "payload.m": 200.0},
                {"cylinder.d_rod": 0.07}, "timeout", {"u_max": 0.5}, {}]
    for params in sequence:
        if params == "timeout":
            with pytest.raises(TimeoutError):
                cosim.run(sc, stop_time=1.0, reuse=True, timeout=1e-4)
            continue
        if "cylinder.d_rod" in params:
            with pytest.raises(Exception, match="fmi2ExitInitializationMode failed"):
                cosim.run(sc, stop_time=1.0, params=params, reuse=True)
            continue
        reused = cosim.run(sc, stop_time=1.0, params=params, reuse=True)
        fresh = cosim.run(sc, stop_time=1.0, params=params)
        for c in COLUMNS:
            assert np.array_equal(reused.data[c], fresh.data[c]), (params, c)
        assert metrics.compute(reused) == metrics.compute(fresh)


def test_summary_finds_the_region_and_the_recommendation_of_a_known_grid(tmp_path):
    """Made-up rows on a grid of factor-2 steps: with mu_p = 3 nothing settles at n_K = 8, with
    mu_p = 5 the cell (1, 0.5) does not; the other 8 of the 12 cells settle in both panels.
    Counted by hand, in grid steps of ln 2 to the nearest cell outside: (1, 2) and (2, 2) are 2
    steps away, every other cell of the region 1 or sqrt(2); t_settle = 2 - 0.1 n_K breaks the tie
    for (2, 2): distance 2 ln 2, a factor 4."""
    f = sweep_file(tmp_path, 'n_K = {grid = [1.0, 2.0, 4.0, 8.0]}\nn_omega = {grid = [0.5, 1.0, 2.0]}\n'
                   '"cbv.mu_p" = {grid = [3.0, 5.0]}\n', head='scenario = "B"\nstop_time = 5.0\n')
    s = {**sweep.load(f), "metrics": ["p3_pp_late", "t_settle"]}
    rows = []
    for p in s["points"]:
        settles = not ((p["cbv.mu_p"] == 3.0 and p["n_K"] == 8.0) or (p["cbv.mu_p"] == 5.0 and p["n_K"] == 1.0 and p["n_omega"] == 0.5))
        rows.append({**p, "p3_pp_late": 0.1 * p["n_K"], "t_settle": 2 - 0.1 * p["n_K"] if settles else None,
                     "status": "ok", "error": "", "wall_time": 0.0, "worker": "made up"})
    sweep_summary.write(s, rows, tmp_path)
    text = (tmp_path / "summary.md").read_text()
    assert "8 of 12 (n_K, n_omega) grid cells settle at every point" in text
    assert f"**n_K = 2, n_omega = 2**, {2 * math.log(2):.3f} in log factor (a factor 4)" in text, text
    assert "worst settling time 1.8 s" in text
    assert (tmp_path / "map-t_settle.png").exists() and (tmp_path / "map-p3_pp_late.png").exists()


@pytest.mark.parametrize("scenario,boom,kw", [
    # K_f and omega_f as the sweep derives them: 17 digits that a parser off by one ulp misreads
    ("B", "rigid", {"params": {"cbv.mu_p": 2.0, "K_f": 8.699795040710195e-13, "omega_f": 10.824302619103424,
                               "payload.m": 200.0, "friction.model": 1}}),
    ("B", "rigid", {"feedback_start": "cbv_open"}),  # the controller re-initialised mid-run
    ("U", "flexible", {}),
])
def test_the_native_runner_gives_fmpys_rows_bit_for_bit(scenario, boom, kw):
    """`boomsim cosim` makes the calls of cosim.run in the same order with the same arguments,
    the FMUs' code in-process: every recorded value, the RHS count and the feedback start equal."""
    sc = load_scenario(scenario)
    a, b = cosim.run(sc, boom, stop_time=1.0, **kw), run_native(sc, boom, stop_time=1.0, **kw)
    for c in COLUMNS:
        assert np.array_equal(a.data[c], b.data[c]), c
    assert (a.counts, a.feedback_on_at) == (b.counts, b.feedback_on_at)
    with pytest.raises(TimeoutError, match="exceeded the timeout of 0.0001 s"):
        run_native(sc, boom, stop_time=1.0, timeout=1e-4, **kw)


def test_the_filter_sweeps_map_is_readable(tmp_path):
    """The packaged sweep "filter"'s map (one narrow panel: its title was cut off at both ends and
    its axes named without units) from made-up rows: boomsim.figures' checks pass (text inside
    the canvas, the K_f and omega_f axes and the colour bar with units), as for every figure the
    tests write (BOOMSIM_STRICT_FIGURES)."""
    s = sweep.load("filter")
    rows = [{**p, "p3_pp_late": 1e11 * p["K_f"], "t_settle": 0.01 * p["omega_f"], "status": "ok", "error": "",
             "wall_time": 0.0, "worker": "made up"} for p in s["points"]]
    sweep_summary.write(s, rows, tmp_path)
    assert sweep_summary.axis_label("K_f") == "K_f [m4.s2/kg]" and sweep_summary.axis_label("n_K") == "n_K [-]"
    assert (tmp_path / "map-t_settle.png").exists()
