"""The package's shape (issue 28): no module reaches another through sys.path, the modules import
each other without a circle, the package's version is the project's, and the public API refuses
wrong input with a UsageError naming the value."""

import ast
import pathlib
import re
import subprocess
import sys

import pytest

import boomsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "python" / "boomsim"


def tracked_python_files():
    out = subprocess.run(["git", "ls-files", "*.py"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [ROOT / f for f in out.split()]


def test_nothing_reaches_a_module_through_sys_path():
    files = tracked_python_files()
    assert len(files) > 40
    offenders = [str(f.relative_to(ROOT)) for f in files if "sys.path.insert" in f.read_text()
                 and f != pathlib.Path(__file__)]
    assert offenders == []


def imports(module: pathlib.Path) -> set[str]:
    """The package's modules that `module` imports (relative or absolute, at any depth of the file)."""
    found = set()
    for node in ast.walk(ast.parse(module.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level == 1 or base.split(".")[0] == "boomsim":
                base = base.removeprefix("boomsim").lstrip(".")
                names = [base] if base else [a.name for a in node.names]
                found |= {n.split(".")[0] for n in names}
        elif isinstance(node, ast.Import):
            found |= {a.name.split(".")[1] for a in node.names if a.name.startswith("boomsim.")}
    modules = {p.stem for p in PACKAGE.glob("*.py")}
    return (found & modules) - {module.stem}


def test_the_modules_import_each_other_without_a_circle():
    """Depth-first search of the import graph (the package's __init__ aside: it is the facade
    that imports the rest, and no module imports it)."""
    graph = {p.stem: imports(p) for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    assert all("__init__" not in deps for deps in graph.values())
    state = {}

    def visit(m, path):
        state[m] = "open"
        for d in sorted(graph[m]):
            assert state.get(d) != "open", " -> ".join(path + [m, d])
            if d not in state:
                visit(d, path + [m])
        state[m] = "done"

    for m in sorted(graph):
        if m not in state:
            visit(m, [])
    assert len(graph) > 20


def test_the_package_has_the_project_version():
    cargo = re.search(r'^version = "(.*)"', (ROOT / "Cargo.toml").read_text(), re.M).group(1)
    assert boomsim.__version__ == cargo


@pytest.mark.parametrize("call,says", [
    (lambda: boomsim.fmu("Crane"), 'unknown model "Crane"'),
    (lambda: boomsim.fmu("HydraulicBoom", fmi=1), "fmi=1: 2 (FMI 2.0) or 3 (FMI 3.0)"),
    (lambda: boomsim.run("Q"), 'unknown scenario "Q"'),
    (lambda: boomsim.run("B", interface="me", step=1e-3), "step=0.001: Model Exchange has no communication step"),
    (lambda: boomsim.run("B", interface="native", fmi=3), "the native runner runs FMI 2.0"),
    (lambda: boomsim.run("B", interface="native", tolerance=1e-8), "at the FMUs' default tolerance"),
    (lambda: boomsim.run("B", interface="simulink"), 'interface="simulink": one of cs, me, native'),
    (lambda: boomsim.regress(only=["Q"]), "only=['Q']: unknown scenario Q"),
])
def test_the_api_refuses_wrong_input_in_one_line(call, says):
    with pytest.raises(boomsim.UsageError, match=re.escape(says)):
        call()


def test_run_routes_each_interface_to_its_runner():
    """B's first 0.5 s at a 2 ms step: the native runner's rows are fmpy's bit for bit (the same
    Gauss-Seidel coupling of the same FMU code, tests/python/test_sweep.py); Model Exchange has
    no communication step, so its rows are CVode's every millisecond."""
    cs, native = (boomsim.run("B", stop_time=0.5, step=2e-3, interface=i) for i in ("cs", "native"))
    assert (cs["p4"] == native["p4"]).all() and (cs.time == native.time).all() and len(cs.time) == 251
    me = boomsim.run("B", stop_time=0.5, interface="me")
    assert me.interface.startswith("Model Exchange, CVode rtol 1e-06") and len(me.time) == 501


def test_a_result_is_numpy_columns_and_a_dataframe():
    """B's first 0.2 s: the columns by name and as a DataFrame indexed by time hold the same values."""
    r = boomsim.run("B", stop_time=0.2)
    frame = r.to_pandas()
    assert list(frame.columns) == [c for c in r.data if c != "time"]
    assert (frame.index.to_numpy() == r.time).all() and (frame["p3"].to_numpy() == r["p3"]).all()
    assert len(r.time) == 201  # one row per millisecond, both ends


def test_the_readmes_first_screen_states_the_models_numbers(monkeypatch):
    """The README's first screen against the code: the payload (BoomMechanics' payload.m, rounded
    to kg) and the arm's length (boom.l_arm), U's and B's valve commands (their scenario files),
    and its fmpy block run as written (matplotlib's window off): p3 of U swings by "some 200 bar"
    (within 25 %: the limit cycle's peak-to-peak over its last 2 s) between its own figures. Each
    licence that Cargo.toml declares has its file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from boomsim.fmus import FmuFile
    from boomsim.scenarios import load_scenario

    readme = (ROOT / "README.md").read_text()
    first = " ".join(readme.split("## The FMUs")[0].split())
    boom = FmuFile.get("BoomMechanics").vars
    assert f"lowering a {float(boom['payload.m'].start):.0f} kg load on a {float(boom['boom.l_arm'].start):g} m" in first
    for sid, words in (("U", "**U** lowers the load at a valve command of {:.2f} without feedback"),
                       ("B", "**B** lowers at {:.2f} with the feedback")):
        assert words.format(load_scenario(sid)["reference"][-1, 1]) in first, sid
    assert "swings by some 200 bar" in first
    block = readme.split("## Loading one in fmpy", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(plt, "show", lambda: None)
    scope = {}
    exec(block, scope)
    r = scope["r"]
    late = r["p3"][r["time"] >= r["time"][-1] - 2.0]
    assert 150e5 <= np.ptp(late) <= 250e5, np.ptp(late) / 1e5
    licences = re.search(r'^license = "(.*)"', (ROOT / "Cargo.toml").read_text(), re.M).group(1).split(" OR ")
    for name in licences:
        text = (ROOT / f"LICENSE-{name.split('-')[0].upper()}").read_text()
        assert {"MIT": "MIT License", "Apache-2.0": "Apache License"}[name] in text


def test_the_readme_is_read_in_five_minutes():
    """At most 200 lines (issue 28): what boomsim is in its first three lines, then the two
    commands; every page it links exists."""
    readme = (ROOT / "README.md").read_text()
    lines = readme.splitlines()
    assert len(lines) <= 200
    assert lines[0] == "# boomsim" and "FMU" in " ".join(lines[1:4])
    commands = [k for k, line in enumerate(lines) if line.startswith("bash scripts/")]
    assert [lines[k].split()[1] for k in commands[:2]] == ["scripts/demo", "scripts/test"]
    links = re.findall(r"\]\(([^)#]+)[^)]*\)", readme)
    assert links and [link for link in links if not (ROOT / link).exists()] == []


def test_a_command_without_its_extra_names_the_extra():
    """A console command whose optional dependency is missing (here mujoco, hidden from a fresh
    interpreter) prints one line naming the extra and exits with status 2, not a traceback."""
    code = ("import sys; sys.modules['mujoco'] = None; sys.argv = ['boomsim-mujoco', '--help']; "
            "from boomsim import commands; sys.exit(commands.mujoco())")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stderr.strip() == 'boomsim.mujoco needs mujoco: pip install "boomsim[mujoco]"', r.stderr


def test_an_unsupported_platform_is_named(monkeypatch):
    """On a platform the FMUs have no binary for (macOS here, faked in fmpy's platform names), an
    FmuFile is a UsageError naming the platform and the ones the binaries are for."""
    import fmpy

    from boomsim.fmus import FmuFile

    monkeypatch.setattr(fmpy, "platform", "darwin64")
    monkeypatch.setattr(fmpy, "platform_tuple", "aarch64-darwin")
    with pytest.raises(boomsim.UsageError, match="HydraulicBoom .FMI 2.0. has no binary for this platform, aarch64-darwin: its binaries are for linux64"):
        FmuFile("HydraulicBoom")


def test_a_result_says_how_it_ran_and_its_metrics_units():
    """Issue 50: `interface` names the interface, FMI version and step of a Co-Simulation run (it
    was empty), and `metric_units` gives every metric's unit: pressures' peak-to-peak in bar,
    times in s, speeds in mm/s, the dominant frequency in Hz (metrics.DEFINITIONS)."""
    r = boomsim.run("B", stop_time=1.0)
    assert r.interface == "Co-Simulation FMI 2.0, step 1 ms"
    units = r.metric_units
    assert set(units) == set(r.metrics)
    assert (units["p3_pp_max"], units["t_settle"], units["v_mean"], units["f_dom"]) == ("bar", "s", "mm/s", "Hz")


def test_release_terminates_only_instances_past_initialization():
    """fmi2Terminate is illegal in Instantiated and Initialization Mode (FMI 2.0 state table):
    `release` frees such an instance without it (its FMU would refuse it with a second, misleading
    error after a run refused at initialisation), terminates one that left Initialization Mode,
    and after fmi2Reset (back to Instantiated) again does not."""
    from boomsim.fmus import FmuFile, release

    f = FmuFile.get("PressureFeedbackController")
    calls = []

    def made(initialize: bool, reset: bool = False):
        s = f.slave("release-test")
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        if initialize:
            s.exitInitializationMode()
        if reset:
            s.reset()
        terminate = s.terminate
        s.terminate = lambda: (calls.append(initialize and not reset), terminate())[1]
        return s

    for initialize, reset in ((False, False), (True, False), (True, True)):
        calls.clear()
        release(made(initialize, reset))
        assert calls == ([True] if initialize and not reset else []), (initialize, reset, calls)
