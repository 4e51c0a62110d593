"""Compatibility matrix: every packed FMU through every FMI importer that installs from the
package registries here.

    .venv/bin/python scripts/compat.py [--json out/compat.json]

Columns per importer: loads (unzips, reads the model description, instantiates), validates (the
importer's own FMI conformance check; "-" where it has none), simulates (initialises with the
case's start values and steps with 1 ms to 1 s), matches (every Real output at 1 s equals fmpy's
to the integration tolerance, 1e-6 relative + 1e-9 SI: the FMUs are deterministic, but an importer
that accumulates t_k + h instead of k h restarts the integrator at times 1e-16 apart). An
importer that cannot be imported or run says why in the matrix; it is never skipped. Exit status
1 when any cell that the importer offers fails.

Importers: fmpy (simulate_fmu, fmpy.validation.validate_fmu), libcosimpy (a CosimLocalSlave in
a fixed-step execution), ecospy (EcosSimulationStructure.add_model), fmu-manipulation-toolbox
(`fmutool -check`: checker only, no simulation), the Rust `fmi` crate (examples/fmi_import.rs);
and fmpy and the `fmi` crate (0.8, feature `fmi3`) again with the FMI 3.0 .fmu of the same binary
(target/fmu/fmi3), matched against fmpy's FMI 2.0 run like every other row; their note also says
whether the outputs equal the same importer's FMI 2.0 run bit for bit (the same library, the same
calls: they should).
"""

from __future__ import annotations

import argparse
import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
FMU_DIR = ROOT / "target" / "fmu"
STOP, STEP = 1.0, 1e-3
#: Agreement of an output with fmpy's: the relative tolerance of the FMUs' integrators (default
#: 1e-6) and 1e-9 in SI units for values near 0 (1e-9 m3/s = 0.06 ml/min, 1e-9 Pa, 1e-9 m).
MATCH_REL, MATCH_ABS = 1e-6, 1e-9

#: Start values per FMU: each case moves the model (a lowering spool, a velocity, a force below
#: the holding force), so the outputs at 1 s depend on the dynamics.
CASES = {
    "PressureFeedbackController": {"u_ref": -0.05, "p": 3e6},
    "HydraulicBoom": {"valve.u_ref": -0.1, "boom.flexible": False},
    "HydraulicCircuit": {"valve.u_ref": 0.2, "cylinder.x": 0.3, "cylinder.v": 0.01},
    "BoomMechanics": {"cylinder.F": 2.0e4, "boom.flexible": False},
}
IMPORTERS = ["fmpy", "libcosimpy", "ecospy", "fmu-manipulation-toolbox", "fmi (Rust crate)", "fmpy (FMI 3.0)",
             "fmi (Rust crate, FMI 3.0)"]


class Cell(dict):
    """One importer x FMU result: loads / validates / simulates / matches (True, False or None =
    not offered) and a note."""


def model_description(path):
    from fmpy import read_model_description

    return read_model_description(str(path))


def real_outputs(md) -> dict:
    return {v.name: v.valueReference for v in md.modelVariables
            if v.causality == "output" and v.type in ("Real", "Float64")}


def run_fmpy(path, case) -> tuple[Cell, dict]:
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    md = model_description(path)
    problems = validate_fmu(str(path))
    outs = list(real_outputs(md))
    r = simulate_fmu(str(path), fmi_type="CoSimulation", start_time=0.0, stop_time=STOP, step_size=STEP,
                     output_interval=STEP, start_values=case, output=outs)
    values = {n: float(r[n][-1]) for n in outs}
    note = "; ".join(problems)
    return Cell(loads=True, validates=not problems, simulates=abs(r["time"][-1] - STOP) < 1e-9, note=note), values


def run_libcosim(path, case) -> tuple[Cell, dict]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    md = model_description(path)
    ex = CosimExecution.from_step_size(step_size=int(round(STEP * 1e9)))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    i = ex.add_local_slave(CosimLocalSlave(fmu_path=str(path), instance_name="compat"))
    types = {v.name: (v.type, v.valueReference) for v in md.modelVariables}
    for name, value in case.items():
        ty, vr = types[name]
        {"Real": ex.real_initial_value, "Integer": ex.integer_initial_value,
         "Boolean": ex.boolean_initial_value}[ty](i, vr, value)
    cell = Cell(loads=True, validates=None, simulates=False, note="")
    cell["simulates"] = bool(ex.simulate_until(int(round(STOP * 1e9))))
    outs = real_outputs(md)
    values = dict(zip(outs, obs.last_real_values(i, list(outs.values()))))
    return cell, values


def run_ecos(path, case) -> tuple[Cell, dict]:
    from ecospy import EcosSimulation, EcosSimulationStructure
    from ecospy.lib import EcosLib

    EcosLib.set_log_level("warn")
    md = model_description(path)
    with EcosSimulationStructure() as ss:
        ss.add_model("compat", str(path))
        ss.add_parameter_set("case", {f"compat::{k}": v for k, v in case.items()})
        with EcosSimulation(structure=ss, step_size=STEP) as sim:
            sim.init(parameter_set="case")
            sim.step(int(round(STOP / STEP)))  # step_until(1.0) stops at 0.999 (accumulated time)
            t = sim.get_time()
            values = {n: sim.get_real(f"compat::{n}") for n in real_outputs(md)}
            sim.terminate()
    return Cell(loads=True, validates=None, simulates=abs(t - STOP) < 1e-9, note=""), values


def run_fmutool(path, case) -> tuple[Cell, dict]:
    exe = pathlib.Path(sys.executable).parent / "fmutool"
    p = subprocess.run([str(exe), "-input", str(path), "-check"], capture_output=True, text=True, timeout=120)
    log = p.stdout + p.stderr
    ok = p.returncode == 0 and "seems to be compliant with FMI-2.0" in log and "No semantic error" in log
    bad = [l for l in log.splitlines() if "ERROR" in l or "WARNING" in l]
    return Cell(loads=p.returncode == 0, validates=ok, simulates=None, matches=None,
                note="; ".join(["checker only (no simulator)"] + bad)), {}


def run_rust(path, case) -> tuple[Cell, dict]:
    exe = ROOT / "target" / "release" / "examples" / "fmi_import"
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "--quiet", "--example", "fmi_import"], cwd=ROOT, check=True)
    args = [f"{k}={str(v).lower() if isinstance(v, bool) else v}" for k, v in case.items()]
    p = subprocess.run([str(exe), str(path), str(STOP), str(STEP), *args], capture_output=True, text=True, timeout=300)
    r = json.loads(p.stdout)
    expected = "3.0" if path.parent.name == "fmi3" else "2.0"
    if r.get("fmi_version") != expected:  # a stale example without the FMI 3.0 import
        raise RuntimeError(f"{exe.name} ran fmiVersion {r.get('fmi_version')!r}, not {expected}: "
                           "rebuild it with `cargo build --release --example fmi_import`")
    return Cell(loads=r["loads"], validates=r["validates"], simulates=r["simulates"], note=r.get("error", "")), \
        r.get("outputs", {})


def fmi3(run):
    """`run` with the FMI 3.0 .fmu beside the FMI 2.0 one (target/fmu/fmi3/<Id>.fmu)."""
    return lambda path, case: run(path.parent / "fmi3" / path.name, case)


RUNNERS = {"fmpy": run_fmpy, "libcosimpy": run_libcosim, "ecospy": run_ecos,
           "fmu-manipulation-toolbox": run_fmutool, "fmi (Rust crate)": run_rust,
           "fmpy (FMI 3.0)": fmi3(run_fmpy), "fmi (Rust crate, FMI 3.0)": fmi3(run_rust)}


#: The FMI 3.0 rows and the FMI 2.0 row of the same importer.
FMI2_ROW = {"fmpy (FMI 3.0)": "fmpy", "fmi (Rust crate, FMI 3.0)": "fmi (Rust crate)"}


def same_as_fmi2(values: dict, fmi2: dict) -> str:
    """Note on an FMI 3.0 row: its outputs against the same importer's FMI 2.0 run."""
    if not values or set(values) != set(fmi2):
        return "outputs differ from its FMI 2.0 run"
    d = {n: abs(values[n] - fmi2[n]) for n in fmi2 if values[n] != fmi2[n]}
    return "bit-identical to its FMI 2.0 run" if not d else \
        f"differs from its FMI 2.0 run by up to {max(d.values()):.3g} (in {max(d, key=d.get)})"


def matches(values: dict, reference: dict) -> tuple[bool, str]:
    """Whether every output equals fmpy's to MATCH_REL, MATCH_ABS."""
    if set(values) != set(reference):
        return False, f"outputs differ: {sorted(set(reference) ^ set(values))}"
    excess = {n: abs(values[n] - reference[n]) / (MATCH_REL * abs(reference[n]) + MATCH_ABS) for n in reference}
    worst = max(excess, key=excess.get)
    d = abs(values[worst] - reference[worst])
    return excess[worst] <= 1.0, f"largest difference {d:.3g} in {worst} ({excess[worst]:.2g} of the tolerance)"


def matrix() -> dict:
    """{fmu: {importer: Cell}}."""
    out = {}
    for fmu, case in CASES.items():
        path = FMU_DIR / f"{fmu}.fmu"
        row, reference, outputs = {}, None, {}
        for name in IMPORTERS:
            try:
                cell, values = RUNNERS[name](path, case)
            except Exception as e:  # noqa: BLE001 - an importer that fails is reported, not skipped
                cell, values = Cell(loads=False, validates=None, simulates=False, matches=False,
                                    note=f"{type(e).__name__}: {e}"), {}
            if name == "fmpy":
                reference = values
                cell["matches"] = cell["simulates"]
            elif "matches" not in cell:
                ok, why = matches(values, reference) if cell["simulates"] and reference else (False, "")
                cell["matches"] = ok
                cell["note"] = "; ".join(x for x in (cell["note"], why) if x)
            if name in FMI2_ROW and cell["simulates"]:
                cell["note"] = "; ".join(x for x in (cell["note"], same_as_fmi2(values, outputs[FMI2_ROW[name]])) if x)
            row[name], outputs[name] = cell, values
        out[fmu] = row
    return out


def mark(x) -> str:
    return "-" if x is None else ("yes" if x else "NO")


def render(m: dict) -> str:
    """The matrix as Markdown: one row per FMU and importer."""
    lines = ["| FMU | importer | loads | validates | simulates | matches fmpy | note |", "|---|---|---|---|---|---|---|"]
    for fmu, row in m.items():
        for name, c in row.items():
            lines.append(f"| {fmu} | {name} | {mark(c['loads'])} | {mark(c['validates'])} | {mark(c['simulates'])} "
                         f"| {mark(c['matches'])} | {c['note']} |")
    return "\n".join(lines)


def failures(m: dict) -> list[str]:
    """Cells an importer offers (not None) that failed."""
    return [f"{fmu} / {name}: {k}" for fmu, row in m.items() for name, c in row.items()
            for k in ("loads", "validates", "simulates", "matches") if c[k] is False]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    m = matrix()
    print(render(m))
    if args.json:
        pathlib.Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        pathlib.Path(args.json).write_text(json.dumps(m, indent=1, default=str))
    bad = failures(m)
    if bad:
        print("\nfailed: " + ", ".join(bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
