"""The scripts' wrong-argument paths: one line naming the value, the valid choices and the fix,
and exit status 2 (argparse's), never a traceback or a silent pass."""

import pathlib
import subprocess
import sys

import pytest

from boomsim import cosim
from boomsim.errors import UsageError
from boomsim.fmus import FmuFile
from boomsim.plots import series
from boomsim.scenarios import load_scenario

ROOT = pathlib.Path(__file__).resolve().parents[2]


def run(command, *args):
    """A package module's command line (`python -m boomsim.<command>`) or a script of the checkout."""
    cmd = [str(ROOT / command)] if command.endswith(".py") else ["-m", f"boomsim.{command}"]
    r = subprocess.run([sys.executable, *cmd, *args], capture_output=True, text=True)
    return r.returncode, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""


@pytest.mark.parametrize("args,says", [
    (["Q"], ['unknown scenario "Q"', "U, A, S, B", ".toml"]),
    (["B", "--step", "0"], ["--step 0.0 must be a positive number"]),
    (["B", "--stop-time", "-1"], ["--stop-time -1.0 must be a positive number"]),
    (["B", "--boom", "wobbly"], ["invalid choice: 'wobbly'", "rigid", "flexible"]),
])
def test_cosim_refuses_bad_arguments_in_one_line(args, says):
    code, last = run("cosim", *args)
    assert code == 2 and all(s in last for s in says), last
    assert "Traceback" not in last


def test_regress_refuses_a_filter_that_matches_nothing(tmp_path):
    """`--only Q` used to pass with "all 0 variants within tolerance" and overwrite the report."""
    code, last = run("regression", "--only", "Q", "--out", str(tmp_path))
    assert code == 2 and "unknown scenario Q" in last and "U, A, S, B" in last, last
    assert not (tmp_path / "report.md").exists()


@pytest.mark.parametrize("args,says", [
    (["--param", "solver.mode"], ["--param solver.mode: expected NAME=VALUE"]),
    (["--param", "boom.damping=viscous"], ["'viscous' is no item of DampingLaw: 'thesis' (0)"]),
    (["--param", "payload.m=heavy"], ["params['payload.m'] = 'heavy': a finite number"]),
    (["--update", "--param", "solver.mode=1"], ["--update writes the baselines of the default FMUs"]),
])
def test_regress_refuses_bad_parameters_in_one_line(tmp_path, args, says):
    """A variant with FMU parameters (the real-time mode's accuracy) never re-baselines."""
    code, last = run("regression", *args, "--out", str(tmp_path))
    assert code == 2 and all(s in last for s in says), last
    assert not (tmp_path / "report.md").exists()


def test_a_missing_fmu_names_the_command_that_builds_it(tmp_path, monkeypatch):
    monkeypatch.setenv("BOOMSIM_FMU_DIR", str(tmp_path))
    with pytest.raises(UsageError, match="boomsim pack"):
        FmuFile("HydraulicBoom")


def test_plots_use_the_signs_of_the_csv_and_the_title():
    """One sign convention in a figure and its CSV: lowering is negative in the FMU variables, the
    CSV columns and the title's u_ref, so the plotted velocity, openings and reference line are
    too (they were flipped to the thesis tool's lowering-positive)."""
    sc = load_scenario("B")
    res = cosim.run(sc, "rigid", stop_time=0.5)
    drawn = {label: y for _, label, y in series(res)}
    assert (drawn["v_c"] == res.data["cylinder.v"] * 1e3).all()
    assert (drawn["u_ref (operator)"] == res.data["u_ref"]).all()
    u_title = sc["reference"][-1, 1]
    assert u_title < 0 and (drawn["Q_rated u_ref / A_rod"] < 0).all() and (drawn["u_ref (operator)"] < 0).all()


@pytest.mark.parametrize("args", [["split", "Q"], ["ssp", "--scenario", "Q", "--no-run"]])
def test_the_other_runners_refuse_an_unknown_scenario_in_one_line(args):
    code, last = run(*args)
    assert code == 2 and 'unknown scenario "Q"' in last, last


def test_ssp_refuses_an_unknown_fmi_version_in_one_line():
    code, last = run("ssp", "--fmi", "4", "--no-run")
    assert code == 2 and "--fmi: invalid choice: 4 (choose from 2, 3)" in last, last


@pytest.mark.parametrize("script,args,says", [
    ("scripts/bench_fmpy.py", ["--bogus"], "unrecognized arguments: --bogus"),
    ("scripts/bench_fmpy.py", ["--cycles", "0"], "--cycles 0: must be at least 1"),
    ("instability", ["--bogus"], "unrecognized arguments: --bogus"),
    ("scripts/bench_sweep.py", ["--repeat", "0"], "--duration must be > 0 and --repeat at least 1"),
])
def test_the_benchmark_and_study_scripts_refuse_bad_arguments_in_one_line(script, args, says):
    """bench_fmpy.py took no arguments and ignored any it was given."""
    code, last = run(script, *args)
    assert code == 2 and says in last, last
