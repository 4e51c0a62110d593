"""The scenario catalogue: the thesis' experiments as TOML files (scenarios/*.toml, documented in
scenarios/README.md), their operator reference and the start values they give the FMUs."""

from __future__ import annotations

import pathlib
import tomllib

import numpy as np

from .errors import UsageError
from .paths import SCENARIO_DIR


def scenario_ids() -> list[str]:
    """The scenario ids of the catalogue, in its order."""
    order = {"U": 0, "A": 1, "S": 2, "B": 3}
    return sorted((p.stem for p in SCENARIO_DIR.glob("*.toml")), key=lambda s: (order.get(s, 4), s))


def load_scenario(path) -> dict:
    """A scenario by id (e.g. "B") or .toml file, with the catalogue's defaults filled in."""
    path = pathlib.Path(path)
    if not path.exists() and (SCENARIO_DIR / f"{path}.toml").exists():
        path = SCENARIO_DIR / f"{path}.toml"  # a scenario id
    if not path.exists():
        raise UsageError(f"unknown scenario \"{path}\": give an id ({', '.join(scenario_ids())}) or a .toml file")
    with open(path, "rb") as f:
        sc = tomllib.load(f)
    sc.setdefault("id", path.stem)
    sc["file"] = str(path)
    sc.setdefault("booms", ["rigid"])
    sc.setdefault("stop_time", 15.0)
    sc.setdefault("start_stroke", 0.480)
    sc.setdefault("plant", {})
    ctrl = sc.setdefault("controller", {})
    ctrl.setdefault("enable", True)
    starts = ctrl.setdefault("feedback_start", "t0")
    sc["starts"] = [starts] if isinstance(starts, str) else list(starts)
    if not ctrl["enable"]:
        sc["starts"] = ["t0"]
    sc.setdefault("step", 1e-3)
    ref = np.asarray(sc["reference"], dtype=float)
    if ref.ndim != 2 or ref.shape[1] != 2 or np.any(np.diff(ref[:, 0]) < 0):
        raise ValueError(f"{path}: reference must be [[t, u_ref], ...] with non-decreasing t")
    sc["reference"] = ref
    return sc


def all_scenarios() -> list[dict]:
    return [load_scenario(SCENARIO_DIR / f"{s}.toml") for s in scenario_ids()]


def reference(table: np.ndarray, t: float) -> float:
    """Operator reference: piecewise linear through the table rows, right-continuous at
    repeated times (a row pair [t, a], [t, b] is a step from a to b at t); held after the end."""
    ts, us = table[:, 0], table[:, 1]
    i = np.searchsorted(ts, t, side="right")
    if i == 0:
        return float(us[0])
    if i >= len(ts):
        return float(us[-1])
    t0, t1, u0, u1 = ts[i - 1], ts[i], us[i - 1], us[i]
    return float(u0 + (u1 - u0) * (t - t0) / (t1 - t0))


def communication_references(table: np.ndarray, step: float, n: int) -> list[float]:
    """The reference at the communication points of `n` steps of `step` as the runners step them:
    t = 0, then t_k + step with t_k = k step."""
    return [reference(table, 0.0)] + [reference(table, k * step + step) for k in range(n)]


def check_feedback_start(value) -> str:
    """`value` if it is a feedback start ("t0" or "cbv_open"), else a UsageError."""
    if value not in ("t0", "cbv_open"):
        raise UsageError(f"feedback_start={value!r}: \"t0\" (from the start) or \"cbv_open\" (from the CBV's opening)")
    return value


def positive(name: str, value, unit: str):
    """`value` if it is a finite number > 0, else a UsageError naming the argument `name`."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < float("inf"):
        raise UsageError(f"{name}={value!r}: a finite number > 0 [{unit}]")
    return value


def variant_name(scenario: dict, boom: str, feedback_start: str = "t0") -> str:
    """`<id>-<boom>`, with `-cbv` appended for feedback_start = cbv_open."""
    return f"{scenario['id']}-{boom}" + ("-cbv" if feedback_start == "cbv_open" else "")


def plant_start(scenario: dict, switch) -> dict:
    """The plant's start values: the scenario's start stroke, the boom switch and its parameters."""
    return {"start.x": scenario["start_stroke"], **dict([switch] if switch else []), **scenario["plant"]}


def controller_start(scenario: dict, ctrl_params: dict) -> dict:
    """The controller's start values: the scenario's filter and limits where it gives them, then
    `ctrl_params`."""
    cfg = scenario["controller"]
    return {**{k: cfg[k] for k in ("K_f", "omega_f", "u_min", "u_max") if k in cfg}, **ctrl_params}
