"""Early return at events in FMI 3.0 Co-Simulation (issue 29 item 1), driven by two independent
importers: fmi-sim 0.7.0 (the Rust fmusim of rust-fmi, from crates.io, installed by scripts/setup)
with `--early-return-allowed --event-mode-used`, and fmpy's simulate_fmu with
`early_return_allowed=True, use_event_mode=True`, run HydraulicBoom with an input whose valve.u_ref
crosses zero twice, and the FMU returns early at every dead-band crossing of the spool; the
crossings are counted against the roots of the event indicators that fmpy's CVode finds in a Model
Exchange run of the same FMU and input. Rigid boom (CVode runs the flexible arm slowly, issue 27);
about a second."""

import csv
import pathlib
import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu

import boomsim
from conftest import FMI_SIM

#: fmi-sim's communication step; its inputs are held over each step.
H = 0.01
STOP = 2.0
#: Lower, reverse through zero to lift, reverse again: four dead-band crossings of the spool and
#: the one at the start (the spool leaves the closed dead band), five in all.
U_REF = [(0.0, 0.0), (0.2, -0.3), (0.6, -0.3), (0.8, 0.3), (1.2, 0.3), (1.4, -0.3), (2.0, -0.3)]
INDICATORS = ("event.spool_reference", "event.dead_band_upper", "event.dead_band_lower")


def fmi_sim(tmp_path: pathlib.Path, *flags: str) -> list[dict]:
    """fmi-sim's co-simulation of HydraulicBoom (FMI 3.0, rigid boom) with the input file; its rows
    (a communication point, or an early return, recorded before and after Event Mode)."""
    if not FMI_SIM.exists():
        pytest.fail(f"{FMI_SIM} is missing: run scripts/setup")
    inputs = tmp_path / "in.csv"
    inputs.write_text("time,valve.u_ref\n" + "".join(f"{t},{u}\n" for t, u in U_REF))
    out = tmp_path / "out.csv"
    subprocess.run([FMI_SIM, "--model", boomsim.fmu("HydraulicBoom", 3), "-i", inputs, "-o", out,
                    "co-simulation", "--init-values", "boom.flexible=false", "-f", str(STOP),
                    "--output-interval", str(H), *flags], check=True, capture_output=True, timeout=120)
    with out.open() as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def fmpy_cs(early_return: bool) -> list[float]:
    """fmpy's Co-Simulation of the same: the recorded times."""
    signal = np.array(U_REF, dtype=[("time", float), ("valve.u_ref", float)])
    r = simulate_fmu(str(boomsim.fmu("HydraulicBoom", 3)), fmi_type="CoSimulation",
                     start_values={"boom.flexible": False}, stop_time=STOP, output_interval=H, input=signal,
                     output=["p3"], early_return_allowed=early_return, use_event_mode=early_return)
    return [float(t) for t in r["time"]]


def off_grid(times: list[float]) -> list[float]:
    """The times that are no communication point k H: the early returns (each once)."""
    return [t for t in sorted(set(times)) if abs(t / H - round(t / H)) > 1e-9]


@pytest.fixture(scope="module")
def me_roots():
    """The dead-band roots of a Model Exchange run of the same FMU and input (fmpy's CVode, rtol 1e-6,
    its root finding on the FMU's event indicators): at each event (a time recorded twice) the
    indicator at its root is the one nearest 0; the events of event.spool_reference (u_ref
    crossing zero, which fmi-sim's held input does within no step) are left out."""
    signal = np.array(U_REF, dtype=[("time", float), ("valve.u_ref", float)])
    r = simulate_fmu(str(boomsim.fmu("HydraulicBoom", 3)), fmi_type="ModelExchange", solver="CVode",
                     relative_tolerance=1e-6, start_values={"boom.flexible": False}, stop_time=STOP,
                     output_interval=H, input=signal, output=list(INDICATORS))
    events = np.where(np.diff(r["time"]) == 0)[0]
    at_root = [INDICATORS[int(np.argmin([abs(r[n][k]) for n in INDICATORS]))] for k in events]
    return [float(r["time"][k]) for k, name in zip(events, at_root) if name != "event.spool_reference"]


@pytest.mark.parametrize("importer", ["fmi-sim", "fmpy"])
def test_the_importers_return_early_at_every_dead_band_crossing(tmp_path, me_roots, importer):
    """As many early returns as Model Exchange has dead-band roots (five), each at most one
    communication step after its root: the masters hold u_ref at its value at the step's start, so
    the spool follows the ramp up to H late (FMI 3.0 has no input derivatives)."""
    if importer == "fmi-sim":
        times = [r["time"] for r in fmi_sim(tmp_path, "--early-return-allowed", "--event-mode-used")]
    else:
        times = fmpy_cs(True)
    early = off_grid(times)
    assert len(me_roots) == 5, me_roots
    assert len(early) == len(me_roots), (early, me_roots)
    for t_cs, t_me in zip(early, me_roots):
        assert 0 <= t_cs - t_me <= H, (early, me_roots)


@pytest.mark.parametrize("importer", ["fmi-sim", "fmpy"])
def test_without_early_return_the_importers_step_on_their_grid(tmp_path, importer):
    """Without earlyReturnAllowed the FMU never returns early (FMI 3.0, 4.2.3): every recorded time
    is a communication point, up to the stop time."""
    times = [r["time"] for r in fmi_sim(tmp_path, "--event-mode-used")] if importer == "fmi-sim" else fmpy_cs(False)
    assert off_grid(times) == []
    assert times[-1] == STOP
