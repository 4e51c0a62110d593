"""scripts/sweep.py: a sweep on a LocalCluster gives the metrics of the same points run serially
in-process, a failing point is a row with fmpy's error, --resume runs only the missing points, and
a bad sweep file is refused in one line before anything runs. Short rigid-boom runs of B."""

import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import sweep  # noqa: E402

METRICS = ["p3_pp_max", "p3_pp_late", "u_comp_max", "v_steady"]


def sweep_file(tmp_path, parameters: str, head: str = 'scenario = "B"\nstop_time = 1.0\n', name="s.toml"):
    path = tmp_path / name
    path.write_text(head + f"metrics = {METRICS!r}\n[parameters]\n" + parameters)
    return path


def cli(*args):
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "sweep.py"), *map(str, args)],
                       capture_output=True, text=True)
    return r.returncode, r.stderr


def rows_by_id(s, out):
    return {r["id"]: r for r in sweep.read_rows(s, out)}


def test_two_workers_give_the_serial_metrics_exactly(tmp_path):
    f = sweep_file(tmp_path, "K_f = {grid = [1.0e-11, 1.24e-11]}\nomega_f = {grid = [30.0, 35.8]}\n")
    code, err = cli(f, "--workers", "2", "--out", tmp_path / "out")
    assert code == 0, err
    s = sweep.load(f)
    rows = rows_by_id(s, tmp_path / "out")
    assert len(rows) == 4 and {r["status"] for r in rows.values()} == {"ok"}
    assert "local" not in {r["worker"] for r in rows.values()}  # ran on the cluster
    for p in s["points"]:
        serial = sweep.run_point(s, p)
        assert serial["status"] == "ok" and serial["worker"] == "local"
        assert {m: rows[p["id"]][m] for m in METRICS} == {m: serial[m] for m in METRICS}
    assert "4 of 4 points run, 0 failed" in (tmp_path / "out" / "summary.md").read_text()
    assert (tmp_path / "out" / "heatmap.png").exists()


def test_a_failing_point_is_a_row_with_fmpys_error(tmp_path):
    """fluid.beta = 5e9 is above its range [1e8, 3e9]: fmi2SetReal answers fmi2Error, which fmpy
    raises as FMICallException."""
    f = sweep_file(tmp_path, '"fluid.beta" = {grid = [1.4e9, 5e9, 2.0e9]}\n')
    code, err = cli(f, "--workers", "1", "--out", tmp_path / "out")
    assert code == 0, err
    rows = sorted(sweep.read_rows(sweep.load(f), tmp_path / "out"), key=lambda r: r["fluid.beta"])
    assert [r["status"] for r in rows] == ["ok", "ok", "failed"]
    assert rows[2]["error"] == "FMICallException: fmi2SetReal failed with status 3 (error)."
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
