"""One run's result: the recorded columns as NumPy arrays, what was run, its work counts and its
metrics; CSV and pandas out."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from . import metrics as mx
from .scenarios import variant_name

#: Recorded columns: (CSV name, source, FMU variable).
PLANT_OUT = ["p1", "p2", "p3", "p4", "valve.u", "cbv.u_cbv", "cylinder.x", "cylinder.v", "Q3", "Q4"]
CTRL_OUT = ["u", "u_comp"]
COLUMNS = ["time", "u_ref", "u_comp", "u_cmd"] + PLANT_OUT


@dataclasses.dataclass
class Result:
    """One run of a scenario variant: its recorded columns (`data`, COLUMNS, SI units: pressures in
    Pa gauge, strokes in m, velocities in m/s), how it ran (boom, step, interface, the feedback's
    start) and, on demand, its regression `metrics` (their units: `metric_units`)."""

    scenario: dict
    boom: str
    step: float
    interpolate: bool
    data: dict  # column -> np.ndarray
    feedback_on_at: float | None  # time the feedback was switched on (feedback_start)
    feedback_start: str = "t0"
    status: str = "ok"
    #: Work counts: `rhs`, the plant's right-hand-side evaluations (CS: its solver's; ME: CVode's
    #: fmi2GetDerivatives calls).
    counts: dict = dataclasses.field(default_factory=dict)
    #: How it ran: "Co-Simulation FMI 2.0, step 1 ms", "native Co-Simulation ..." or "Model Exchange,
    #: CVode rtol ..." (`run_me`).
    interface: str = ""

    @property
    def name(self) -> str:
        return variant_name(self.scenario, self.boom, self.feedback_start)

    @property
    def time(self) -> np.ndarray:
        """The recorded times [s]."""
        return self.data["time"]

    def __getitem__(self, column: str) -> np.ndarray:
        """A recorded column by name (COLUMNS: SI units, pressures in Pa gauge)."""
        return self.data[column]

    @property
    def metric_units(self) -> dict:
        """The unit of each of `metrics` (bar, s, mm/s, Hz, ...: the regression's, docs/python.md)."""
        return {k: unit for k, (unit, _) in mx.DEFINITIONS.items()}

    @functools.cached_property
    def metrics(self) -> dict:
        """The regression metrics of the run (definitions in docs/python.md, "Metrics")."""
        return mx.compute(self)

    def to_pandas(self):
        """The recorded columns as a pandas DataFrame indexed by time (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.data).set_index("time")


def write_csv(res: Result, path):
    cols = list(res.data)
    arr = np.column_stack([res.data[c] for c in cols])
    header = ",".join(cols)
    np.savetxt(path, arr, delimiter=",", header=header, comments="", fmt="%.9g")
