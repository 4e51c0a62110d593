"""SSP 1.0 packages of the boom systems and their runs in three SSP importers.

    boomsim-ssp [--scenario B] [--boom rigid] [--coupling tlm] [--fmi 2|3] [--out out/ssp]

writes
    out/ssp/BoomSystem.ssp       HydraulicBoom + PressureFeedbackController (two FMUs)
    out/ssp/BoomSystemSplit.ssp  HydraulicCircuit + BoomMechanics + PressureFeedbackController
each a zip of SystemStructure.ssd (components, connectors, connections, inline parameter bindings
of the scenario, default experiment) and resources/<FMU>.fmu; then runs both in fmpy's SSP
simulator, libcosimpy (CosimExecution.from_ssp_file) and ecospy (EcosSimulation(ssp_path=...))
and compares the regression metrics with the fmpy runner (cosim.py / split.py, Jacobi for the
split system, as these masters step all FMUs from the same values). The controller is bound with
p.extrapolation = true: these masters pass no input derivatives and read its command before they
pass the new p4, so it extrapolates p4 from its last two samples (docs/python.md, "Coupling").

`--fmi 3` embeds the FMI 3.0 .fmu files of target/fmu/fmi3 instead (written to out/ssp/fmi3)
and tries them in the same three importers; where one runs them (ecospy), the run is compared with
the FMI 2.0 SSP in the same importer as well (expected: the same record, bit for bit); NOT_FMI3
has the errors of the others (fmpy's SSP simulator, libcosimpy) and why.

The operator reference of the scenario must be constant (U, B, ...): it is bound as the start value
of the controller's u_ref input. Masters that start the connections at 0 (fmpy's simulate_ssp) get
the documented first-step deviation; see docs/python.md, "SSP".
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys
import tempfile
import zipfile
from xml.sax.saxutils import quoteattr

import numpy as np

from . import cosim
from .errors import UsageError, cli
from .fmus import FmuFile, item_value
from .paths import OUT
from .result import Result
from .scenarios import load_scenario
from . import metrics as mx
from . import split, terminals

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
#: Recorded outputs: (component, variable, metric column).
RECORD = {
    "monolithic": [("Plant", c, c) for c in ("p3", "cbv.u_cbv", "Q3", "cylinder.x", "cylinder.v")],
    "split": [("Circuit", c, c) for c in ("p3", "cbv.u_cbv", "Q3")]
    + [("Mechanics", c, c) for c in ("cylinder.x", "cylinder.v")],
}
for _r in RECORD.values():
    _r.append(("Controller", "u_comp", "u_comp"))
#: Name of every component's inline parameter set (ecos applies a set by name at init).
PARAMETER_SET = "scenario"
NAMES = {"monolithic": "BoomSystem", "split": "BoomSystemSplit"}
#: SSP 1.0 type of an FMI variable type (SystemStructureParameterValues.xsd has Real, Integer,
#: Boolean, String, Enumeration, Binary: FMI 3.0's Float64 and Int32 are Real and Integer there;
#: an Enumeration's value is its item's name).
SSP_TYPE = {"Float64": "Real", "Int32": "Integer"}


def components(system: str, sc: dict, boom: str, coupling: str, fmi: int = 2) -> tuple[dict, list]:
    """({component: (FMU id, {parameter: value})}, [(from comp, output, to comp, input)]): the
    connections are those of the FMUs' terminals (boomsim.terminals)."""
    ctrl = {k: sc["controller"][k] for k in ("K_f", "omega_f") if k in sc["controller"]}
    ctrl["enable"] = bool(sc["controller"]["enable"])
    u_ref = float(sc["reference"][0, 1])
    if np.ptp(sc["reference"][:, 1]) != 0:
        raise ValueError(f"{sc['id']}: the SSP binds a constant operator reference; this one varies")
    ctrl["u_ref"] = u_ref
    # the importers are Jacobi masters (no input derivatives, u read before p4 of the step end is
    # passed): the controller extrapolates p4 from its last two samples (docs/python.md, "SSP")
    ctrl["p.extrapolation"] = True
    flexible = boom == "flexible"
    if system == "monolithic":
        plant = {"start.x": sc["start_stroke"], "boom.flexible": flexible, **sc["plant"]}
        comps = {"Plant": ("HydraulicBoom", plant), "Controller": ("PressureFeedbackController", ctrl)}
        return comps, wired(comps, [("Plant", "Controller", ["pressure", "valve"])])
    mode = 1 if coupling.startswith("tlm") else 0
    mech = {"start.x": sc["start_stroke"], "boom.flexible": flexible, "port.coupling": mode}
    f_start = start_force(mech, fmi)
    circ = {"start.x": sc["start_stroke"], "start.F": f_start, "port.coupling": mode, "port.c_m": f_start,
            "cylinder.x": sc["start_stroke"]}
    mech["port.c_h"] = mech["cylinder.F"] = f_start
    comps = {"Circuit": ("HydraulicCircuit", circ), "Mechanics": ("BoomMechanics", mech),
             "Controller": ("PressureFeedbackController", ctrl)}
    return comps, wired(comps, [("Circuit", "Controller", ["pressure", "valve"]),
                                ("Circuit", "Mechanics", ["rod_tlm" if mode else "rod"])])


def wired(comps: dict, terminal_pairs: list) -> list:
    """The connections of the components' terminals: for each (component a, component b, terminal
    names), the members of each terminal connected by `terminals.connect`; a parameter member must
    have the same value on both sides (the binding, else the FMU's start value)."""
    def value(comp: str, name: str) -> float:
        fmu, params = comps[comp]
        return float(params.get(name, FmuFile.get(fmu).vars[name].start))

    conns = []
    for a, b, names in terminal_pairs:
        for name in names:
            c, params = terminals.connect((a, comps[a][0]), (b, comps[b][0]), name)
            conns += c
            for pa, pb in params:
                if value(a, pa) != value(b, pb):
                    raise UsageError(f"terminal \"{name}\": {a}.{pa} = {value(a, pa):g} and {b}.{pb} = "
                                     f"{value(b, pb):g} must be equal")
    return conns


def start_force(mech: dict, fmi: int = 2) -> float:
    """BoomMechanics' start.F for these parameters (the circuit's start.F binding), through the
    FMI `fmi` .fmu."""
    f = FmuFile.get("BoomMechanics", fmi)
    s = f.slave("start_force")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    for k, v in mech.items():
        f.set(s, k, v)
    s.exitInitializationMode()
    value = s.getReal([f.vr["start.F"]])[0]
    s.terminate()
    s.freeInstance()
    return value


def ssv_text(var, ty: str, v) -> str:
    """The value `v` of FMU variable `var` as the text of its SSV element of type `ty`: an
    Enumeration's item by its name."""
    if ty == "Boolean":
        return str(v).lower()
    if ty == "Enumeration":
        value = item_value(var.name, var, v)
        return next(i.name for i in var.declaredType.items if int(i.value) == value)
    return repr(int(v) if ty == "Integer" else float(v))


def ssd(system: str, sc: dict, boom: str, coupling: str, fmi: int = 2) -> str:
    """SystemStructure.ssd of `system` for scenario `sc` with the FMI `fmi` .fmu files."""
    comps, conns = components(system, sc, boom, coupling, fmi)
    kinds = {}
    for a, out, b, inp in conns:
        kinds.setdefault(a, {})[out] = "output"
        kinds.setdefault(b, {})[inp] = "input"
    for comp, var, _ in RECORD[system]:
        kinds.setdefault(comp, {})[var] = "output"
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" xmlns:ssv="{SSV}" '
             f'version="1.0" name="{NAMES[system]}">',
             f'  <ssd:System name="{NAMES[system]}">', "    <ssd:Elements>"]
    for name, (fmu, params) in comps.items():
        md = FmuFile.get(fmu, fmi)
        lines.append(f'      <ssd:Component name="{name}" type="application/x-fmu-sharedlibrary" '
                     f'source="resources/{fmu}.fmu">')
        lines.append("        <ssd:Connectors>")
        for var, kind in kinds.get(name, {}).items():
            lines.append(f"          <ssd:Connector name={quoteattr(var)} kind=\"{kind}\"><ssc:Real/></ssd:Connector>")
        lines.append("        </ssd:Connectors>")
        lines += ["        <ssd:ParameterBindings>", "          <ssd:ParameterBinding>", "            <ssd:ParameterValues>",
                  f'              <ssv:ParameterSet version="1.0" name="{PARAMETER_SET}">', "                <ssv:Parameters>"]
        for k, v in params.items():
            ty = SSP_TYPE.get(md.vars[k].type, md.vars[k].type)
            text = ssv_text(md.vars[k], ty, v)
            lines.append(f"                  <ssv:Parameter name={quoteattr(k)}><ssv:{ty} value=\"{text}\"/></ssv:Parameter>")
        lines += ["                </ssv:Parameters>", "              </ssv:ParameterSet>", "            </ssd:ParameterValues>",
                  "          </ssd:ParameterBinding>", "        </ssd:ParameterBindings>", "      </ssd:Component>"]
    lines += ["    </ssd:Elements>", "    <ssd:Connections>"]
    for a, out, b, inp in conns:
        lines.append(f'      <ssd:Connection startElement="{a}" startConnector={quoteattr(out)} '
                     f'endElement="{b}" endConnector={quoteattr(inp)}/>')
    lines += ["    </ssd:Connections>", "  </ssd:System>",
              f'  <ssd:DefaultExperiment startTime="0" stopTime="{sc["stop_time"]:g}"/>',
              "</ssd:SystemStructureDescription>", ""]
    return "\n".join(lines)


def write(system: str, sc: dict, boom: str = "rigid", coupling: str = "tlm", out=None, fmi: int = 2):
    """Writes <out>/<BoomSystem|BoomSystemSplit>.ssp with the FMI `fmi` .fmu files (default out:
    out/ssp, out/ssp/fmi3 for FMI 3.0); returns its path."""
    out = pathlib.Path(out or default_out(fmi))
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{NAMES[system]}.ssp"
    comps, _ = components(system, sc, boom, coupling, fmi)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", ssd(system, sc, boom, coupling, fmi))
        for fmu, _ in comps.values():
            z.write(FmuFile.get(fmu, fmi).path, f"resources/{fmu}.fmu")
    return path


def default_out(fmi: int) -> pathlib.Path:
    return OUT / "ssp" / ("fmi3" if fmi == 3 else "")


# --------------------------------------------------------------------------- importers


def bindings(path) -> dict:
    """{component: {parameter: value}} from the SSD's inline parameter bindings."""
    from fmpy.ssp.ssd import read_ssd

    out = {}

    def walk(system):
        for c in system.elements:
            for b in c.parameterBindings:
                for ps in b.parameterValues:
                    out.setdefault(c.name, {}).update({p.name: p.value for p in ps.parameters})

    walk(read_ssd(str(path)).system)
    return out


def run_fmpy(path, system: str, stop: float, step: float) -> dict:
    """fmpy.ssp.simulation.simulate_ssp; it validates the SSD against the SSP schema but does not
    apply its parameter bindings, so they go in as its `parameter_set` (names <component>.<var>,
    Booleans as 0/1)."""
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import Parameter, ParameterSet, read_ssd

    sources = {c.name: pathlib.Path(c.source).stem for c in read_ssd(str(path)).system.elements}

    # its set_value writes a Boolean as `value != 0.0`, so a literal "false" would set true, and
    # an Enumeration as int(value), so an item's name goes in as its value
    def number(c, k, v):
        var = FmuFile.get(sources[c]).vars[k]
        if var.type == "Enumeration":
            return item_value(k, var, v)
        return {"true": 1.0, "false": 0.0}.get(str(v).lower(), v)

    params = [Parameter(name=f"{c}.{k}", value=number(c, k, v))
              for c, kv in bindings(path).items() for k, v in kv.items()]
    r = simulate_ssp(str(path), stop_time=stop, step_size=step, parameter_set=ParameterSet(parameters=params))
    # each row holds the outputs after the step that starts at its time
    data = {"time": r["time"] + step}
    for comp, var, col in RECORD[system]:
        data[col] = r[f"{comp}.{var}"]
    return data


def run_libcosim(path, system: str, stop: float, step: float) -> dict:
    """libcosimpy: CosimExecution.from_ssp_file (fixed-step Jacobi master), a time-series observer."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy._internal import get_last_error_message

    log_output_level(CosimLogLevel.WARNING)
    try:
        ex = CosimExecution.from_ssp_file(str(path), step_size=int(round(step * 1e9)))
    except AssertionError:  # its message says only "check if path is correct"; libcosim's says why
        raise RuntimeError(f"Unable to create execution from path: {get_last_error_message()}") from None
    obs = CosimObserver.create_time_series(buffer_size=int(round(stop / step)) + 10)
    ex.add_observer(obs)
    index = {s.name.decode(): s.index for s in ex.slave_infos()}
    refs = []
    for comp, var, col in RECORD[system]:
        i = index[comp]
        vr = next(v.reference for v in ex.slave_variables(i) if v.name.decode() == var)
        obs.start_time_series(i, vr, CosimVariableType.REAL)
        refs.append((i, vr, col))
    ex.simulate_until(stop * 1e9)
    data = {}
    n = int(round(stop / step)) + 1
    for i, vr, col in refs:
        times, _, values = obs.time_series_real_samples(i, vr, from_step=0, sample_count=n)
        data[col] = np.asarray(values)
        data["time"] = np.asarray(times) * 1e-9
    return data


def run_ecos(path, system: str, stop: float, step: float) -> dict:
    """ecospy: EcosSimulation(step_size, ssp_path); values read after every step."""
    from ecospy import EcosSimulation

    rows = []
    ids = [f"{comp}::{var}" for comp, var, _ in RECORD[system]]
    with EcosSimulation(step_size=step, ssp_path=str(path)) as sim:
        sim.init(parameter_set=PARAMETER_SET)
        for _ in range(int(round(stop / step))):
            t = sim.step()
            rows.append([t] + [sim.get_real(i) for i in ids])
        sim.terminate()
    a = np.array(rows)
    return {"time": a[:, 0], **{col: a[:, k + 1] for k, (_, _, col) in enumerate(RECORD[system])}}


IMPORTERS = {"fmpy": run_fmpy, "libcosimpy": run_libcosim, "ecospy": run_ecos}
#: The importers that do not read an SSP of FMI 3.0 FMUs (tried with `--fmi 3`): the start of the
#: error each gives, and why. ecospy 0.7.2 reads them (its fmi4c loads FMI 3.0).
NOT_FMI3 = {
    # simulate_ssp instantiates every FMU that is not FMI 1.0 as an FMU2Slave, whose FMI 2.0
    # loader looks for binaries/linux64 (an FMI 3.0 archive has binaries/x86_64-linux)
    "fmpy": "Cannot find shared library",
    # libcosim's FMU loader (FMI Library) takes FMI 1.0 and 2.0 only
    "libcosimpy": "Unable to create execution from path: Unsupported feature: Unsupported FMI version",
}


def as_result(data: dict, sc: dict, boom: str, step: float) -> Result:
    """The importer's record as a Result for metrics.compute (u_ref constant)."""
    d = dict(data)
    d["u_ref"] = np.full_like(d["time"], sc["reference"][0, 1])
    return Result(sc, boom, step, False, d, 0.0)


def reference(system: str, sc: dict, boom: str, coupling: str, step: float) -> dict:
    """Metrics of the fmpy runner for the same system (Jacobi for the split one)."""
    if system == "monolithic":
        return mx.compute(cosim.run(sc, boom, step))
    return mx.compute(split.run(sc, boom, {"tlm": "tlm-jacobi", "plain": "jacobi"}[coupling], step))


def run(tool: str, path, system: str, sc: dict, boom: str, step: float) -> tuple[dict, dict]:
    """(record, metrics) of the SSP `path` in importer `tool`."""
    data = IMPORTERS[tool](path, system, sc["stop_time"], step)
    return data, mx.compute(as_result(data, sc, boom, step))


def record_difference(a: dict, b: dict) -> float:
    """Largest |a - b| over the recorded columns of two runs (inf if their lengths differ)."""
    if any(len(a[k]) != len(b[k]) for k in a):
        return math.inf
    return max(float(np.max(np.abs(np.asarray(a[k]) - np.asarray(b[k])), initial=0.0)) for k in a)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="B")
    ap.add_argument("--boom", default="rigid")
    ap.add_argument("--coupling", default="tlm", choices=("plain", "tlm"))
    ap.add_argument("--step", type=float, default=1e-3)
    ap.add_argument("--fmi", type=int, choices=(2, 3), default=2,
                    help="FMI version of the embedded FMUs: 2 (target/fmu) or 3 (target/fmu/fmi3)")
    ap.add_argument("--out", default=None, help="output folder (default out/ssp, out/ssp/fmi3 with --fmi 3)")
    ap.add_argument("--no-run", action="store_true", help="only write the .ssp files")
    args = ap.parse_args(argv)
    sc = load_scenario(args.scenario)
    for system in ("monolithic", "split"):
        path = write(system, sc, args.boom, args.coupling, args.out, args.fmi)
        print(path)
        if args.no_run:
            continue
        ref = reference(system, sc, args.boom, args.coupling, args.step)
        fmi2_path = write(system, sc, args.boom, args.coupling, tempfile.mkdtemp(), 2) if args.fmi == 3 else None
        for tool in IMPORTERS:
            try:
                data, m = run(tool, path, system, sc, args.boom, args.step)
            except Exception as e:  # noqa: BLE001 - report any importer failure
                known = args.fmi == 3 and str(e).startswith(NOT_FMI3.get(tool, "\0"))
                print(f"  {tool}: " + ("does not read FMI 3.0: " if known else "FAILED: ") + f"{type(e).__name__}: {e}")
                continue
            cmp = split.compare(ref, m)
            bad = {k: (a, b) for k, (a, b, ok) in cmp.items() if not ok}
            print(f"  {tool}: " + ("matches the fmpy runner" if not bad else f"differs: {bad}"))
            if fmi2_path:
                data2, m2 = run(tool, fmi2_path, system, sc, args.boom, args.step)
                same = {k for k in m if m[k] == m2.get(k)}
                print(f"  {tool}: FMI 3.0 vs FMI 2.0 SSP: largest record difference {record_difference(data, data2):.3g}, "
                      + ("every metric identical" if same == set(m) else f"metrics differ: "
                         f"{ {k: (m2.get(k), m[k]) for k in set(m) - same} }"))


if __name__ == "__main__":
    sys.exit(cli(main))
