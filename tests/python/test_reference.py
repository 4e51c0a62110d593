"""The reference results inside every .fmu (issue 29 item 4; documentation/reference/, the FMI
cross-check layout): fmpy's simulate_fmu, given the FMU's own _in.csv and _ref.opt, reproduces its
_ref.csv, in Co-Simulation, FMI 2.0 and 3.0. The references were computed at pack time by the
same model code through the same FMI layer (tools/src/reference.rs), driven as fmpy drives a
Co-Simulation FMU, with fmpy's interpolation weights for the input rows, so the linux64 run
agrees bit for bit (measured; on another platform an importer should expect the model's relative
tolerance, RelTol of _ref.opt). The CSV numbers round-trip exactly (shortest digits)."""

import io
import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import FMU_DIR

MODELS = ["PressureFeedbackController", "HydraulicBoom", "HydraulicCircuit", "BoomMechanics"]


def reference(path, model):
    with zipfile.ZipFile(path) as z:
        read = lambda name: z.read(f"documentation/reference/{model}_{name}").decode()  # noqa: E731
        opt = dict(line.split(", ") for line in read("ref.opt").splitlines())
        ref = np.genfromtxt(io.StringIO(read("ref.csv")), delimiter=",", names=True)
        inputs = np.genfromtxt(io.StringIO(read("in.csv")), delimiter=",", names=True, deletechars="")
    return {k: float(v) for k, v in opt.items()}, ref, inputs


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_fmpy_reproduces_the_reference_results(model, fmi):
    path = FMU_DIR / ("fmi3" if fmi == 3 else "") / f"{model}.fmu"
    opt, ref, inputs = reference(path, model)
    names = [n for n in ref.dtype.names if n != "time"]
    columns = open_columns(path, model)
    got = simulate_fmu(str(path), fmi_type="CoSimulation", start_time=opt["StartTime"], stop_time=opt["StopTime"],
                       output_interval=opt["StepSize"], relative_tolerance=opt["RelTol"], input=inputs,
                       output=columns)
    assert len(got) == len(ref) and (got["time"] == ref["time"]).all()
    for name, column in zip(names, columns):
        assert (got[column] == ref[name]).all(), f"{model} FMI {fmi} {column}"


def open_columns(path, model):
    """The output names of _ref.csv's header as written (numpy's names replace the dots)."""
    with zipfile.ZipFile(path) as z:
        return z.read(f"documentation/reference/{model}_ref.csv").decode().splitlines()[0].split(",")[1:]
