"""The installed package (issue 28): the wheel of `scripts/wheel` installed into a fresh venv, used
from a folder outside the repository, without Rust, the checkout or its FMUs on any path.

- experiments U and B through the public API (`boomsim.run`) give the committed baselines'
  metrics within the regression's tolerances (python/boomsim/baselines/);
- a 4-point sweep on a LocalCluster (`boomsim.sweep`, the `sweeps` extra) gives the metrics of the
  same points run one by one;
- every FMU in the wheel (FMI 2.0 and 3.0) passes fmpy's validation and instantiates in both
  interfaces with fmpy.

One venv for the module (about a minute: pip installs the pinned versions of
scripts/requirements.txt as constraints, from pip's cache after the first time)."""

import json
import os
import pathlib
import subprocess
import sys
import textwrap

import pytest

from boomsim import regression

ROOT = pathlib.Path(__file__).resolve().parents[2]
VERSION = next(line.split('"')[1] for line in (ROOT / "python" / "pyproject.toml").read_text().splitlines()
               if line.startswith("version = "))
#: The wheel of scripts/wheel, tagged for its binaries' platforms (scripts/wheel_tag.py).
WHEEL = next((ROOT / "dist").glob(f"boomsim-{VERSION}-py3-none-*.whl"), ROOT / "dist" / f"boomsim-{VERSION}.whl")


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(python of a fresh venv with the wheel and its `sweeps` extra, a working folder outside the
    repository)."""
    assert WHEEL.exists(), f"{WHEEL} is missing: run `bash scripts/wheel`"
    venv = tmp_path_factory.mktemp("venv")
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check",
                    "-c", str(ROOT / "scripts" / "requirements.txt"), f"{WHEEL}[sweeps]"], check=True)
    return python, tmp_path_factory.mktemp("user")


def outside(installed, code: str):
    """Runs `code` in the fresh venv from the folder outside the repository, with an environment
    that names nothing of the checkout; returns what it prints as JSON."""
    python, cwd = installed
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "BOOMSIM_FMU_DIR", "VIRTUAL_ENV")}
    r = subprocess.run([str(python), "-c", textwrap.dedent(code)], cwd=cwd, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_the_package_is_the_installed_one(installed):
    where = outside(installed, """
        import json, boomsim
        print(json.dumps([boomsim.__file__, str(boomsim.paths.CHECKOUT), boomsim.__version__,
                          str(boomsim.fmu("HydraulicBoom", fmi=3))]))
    """)
    assert not where[0].startswith(str(ROOT)) and where[1] == "None" and where[2] == VERSION
    assert "site-packages/boomsim/fmus/fmi3/HydraulicBoom.fmu" in where[3]


def test_u_and_b_reproduce_the_baselines(installed):
    """The regression's metrics of U and B (rigid boom, feedback from t = 0) within its tolerances
    (python/boomsim/baselines/tolerances.toml, each with its reason there)."""
    got = outside(installed, """
        import json, boomsim
        print(json.dumps({sid: boomsim.run(sid, boom="rigid").metrics for sid in ("U", "B")}))
    """)
    tol = regression.load_tolerances()
    for sid, metrics in got.items():
        base = json.loads((ROOT / "python" / "boomsim" / "baselines" / f"{sid}-rigid.json").read_text())
        assert regression.compare(sid, metrics, base["metrics"], tol) == []


def test_a_sweep_on_a_local_cluster_equals_the_points_run_one_by_one(installed):
    """Four points (K_f x omega_f, B rigid, 1 s) on two worker processes; each row's metrics equal
    those of boomsim.run at the point in the same venv, bit for bit (the same FMU binaries)."""
    rows, serial = outside(installed, """
        import json, pathlib, boomsim
        pathlib.Path("four.toml").write_text('''scenario = "B"
        stop_time = 1.0
        metrics = ["p3_pp_max", "u_comp_max", "v_steady"]
        [parameters]
        K_f = {grid = [1.0e-11, 1.24e-11]}
        omega_f = {grid = [5.0, 10.0]}
        '''.replace("\\n        ", "\\n"))
        rows = boomsim.sweep("four.toml", workers=2, out="sweep")
        serial = [boomsim.run("B", stop_time=1.0, params={"K_f": r["K_f"], "omega_f": r["omega_f"]}).metrics
                  for r in rows]
        print(json.dumps([rows, serial]))
    """)
    assert len(rows) == 4 and {(r["K_f"], r["omega_f"]) for r in rows} == {
        (k, w) for k in (1.0e-11, 1.24e-11) for w in (5.0, 10.0)}
    for row, ref in zip(rows, serial):
        assert row["status"] == "ok", row["error"]
        assert {k: row[k] for k in ("p3_pp_max", "u_comp_max", "v_steady")} == {
            k: ref[k] for k in ("p3_pp_max", "u_comp_max", "v_steady")}


def test_every_fmu_in_the_wheel_validates_and_instantiates(installed):
    """fmpy's validation reports nothing (the issue's acceptance for boomsim.fmu(..., fmi=3)), and
    each interface instantiates and frees (the linux64 binary in the wheel's .fmu)."""
    problems = outside(installed, """
        import json, boomsim
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Model, FMU2Slave
        from fmpy.fmi3 import FMU3Model, FMU3Slave
        from fmpy.validation import validate_fmu
        out = {}
        for fmi, models in ((2, boomsim.MODELS), (3, boomsim.FMI3_MODELS)):
            for model in models:
                path = str(boomsim.fmu(model, fmi=fmi))
                found = list(validate_fmu(path))
                md, unzipped = read_model_description(path), extract(path)
                kinds = (FMU2Slave, FMU2Model) if fmi == 2 else (FMU3Slave, FMU3Model)
                for kind, interface in zip(kinds, (md.coSimulation, md.modelExchange)):
                    i = kind(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=interface.modelIdentifier)
                    # A Clock needs Event Mode in Co-Simulation (FMI 3.0, 2.3.1).
                    i.instantiate(**({"eventModeUsed": True} if getattr(interface, "hasEventMode", False) else {}))
                    i.freeInstance()
                out[f"{model} FMI {fmi}"] = found
        print(json.dumps(out))
    """)
    assert len(problems) == 9 and all(p == [] for p in problems.values()), problems


def test_every_console_script_answers_help(installed):
    """Issue 50: every console script of pyproject.toml, run from the wheel's venv (the `sweeps`
    extra only) outside the repository: `--help` prints its usage (exit 0), or, where the command
    needs an extra this venv lacks (mujoco), one line naming the extra to install (exit 2)."""
    import tomllib

    python, cwd = installed
    scripts = tomllib.loads((ROOT / "python" / "pyproject.toml").read_text())["project"]["scripts"]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "BOOMSIM_FMU_DIR", "VIRTUAL_ENV")}
    for name in scripts:
        r = subprocess.run([str(python.parent / name), "--help"], cwd=cwd, env=env, capture_output=True, text=True)
        lines = r.stderr.strip().splitlines()
        if r.returncode == 0:
            assert r.stdout.startswith("usage:"), (name, r.stdout[:200])
        else:
            assert r.returncode == 2 and len(lines) == 1 and 'pip install "boomsim[' in lines[0], (name, r.stderr)


def test_the_wheel_installs_only_where_its_binaries_run(tmp_path):
    """The wheel's tag names the three platforms of the FMUs' binaries (PEP 425 compressed tag
    set: manylinux x86_64 and aarch64 with the glibc the .so files need, win_amd64), so pip
    resolves it for those and refuses it for macOS ("is not a supported wheel on this platform"),
    where no FMU could run. pip's --dry-run with --platform asks exactly that question; the
    fixture `installed` installs it on this machine the ordinary way. The README
    states the glibc the tag names."""
    tags = WHEEL.name.removesuffix(".whl").split("-")[-1].split(".")
    assert sorted("_".join(t.split("_")[3:]) if t.startswith("manylinux") else t for t in tags) == \
        ["aarch64", "win_amd64", "x86_64"], tags

    def resolves(platform: str):
        return subprocess.run([sys.executable, "-m", "pip", "install", "--dry-run", "--no-deps", "-q",
                               "--disable-pip-version-check", "--only-binary=:all:", "--target", str(tmp_path),
                               "--platform", platform, str(WHEEL)], capture_output=True, text=True)

    for platform in tags:  # (pip 23's --platform does not widen a manylinux tag to older glibc)
        r = resolves(platform)
        assert r.returncode == 0, (platform, r.stderr)
    r = resolves("macosx_11_0_arm64")
    assert r.returncode != 0 and "is not a supported wheel on this platform" in r.stderr, r.stderr
    glibc = next(t for t in tags if t.startswith("manylinux")).split("_")[1:3]
    assert f"glibc {'.'.join(glibc)} or later" in (ROOT / "README.md").read_text(), "README's requirement"


def test_the_release_folder_has_every_fmu_and_checks_out():
    """scripts/release (after scripts/wheel, so no build is left): dist/release-<version>/ holds
    the five FMI 3.0 and four FMI 2.0 .fmu files with all three platforms' binaries, the wheel,
    the docs and licences, and `sha256sum -c SHA256SUMS` verifies every file."""
    import zipfile

    subprocess.run(["bash", str(ROOT / "scripts" / "release")], check=True, capture_output=True)
    out = ROOT / "dist" / f"release-{VERSION}"
    fmus = sorted(p.relative_to(out).as_posix() for p in out.glob("fmi*/*.fmu"))
    assert len([f for f in fmus if f.startswith("fmi2/")]) == 4 and len([f for f in fmus if f.startswith("fmi3/")]) == 5
    for f in fmus:
        names = zipfile.ZipFile(out / f).namelist()
        platforms = {n.split("/")[1] for n in names if n.startswith("binaries/") and n.count("/") >= 2}
        assert len(platforms) == 3, (f, platforms)
    assert (out / WHEEL.name).exists() and (out / "docs" / "mujoco.md").exists() and (out / "LICENSE-MIT").exists()
    check = subprocess.run(["sha256sum", "-c", "--quiet", "SHA256SUMS"], cwd=out, capture_output=True, text=True)
    assert check.returncode == 0, check.stdout + check.stderr
