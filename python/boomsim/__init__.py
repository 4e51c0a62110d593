"""boomsim: the hydraulically actuated boom of the thesis *Stabilization of hydraulically actuated
boom using pressure feedback* as FMUs, and the tools to run them from Python.

    import boomsim
    path = boomsim.fmu("HydraulicBoom", fmi=3)      # the packaged .fmu
    r = boomsim.run("B", boom="rigid")              # experiment B through fmpy
    r.time, r["p3"], r.metrics                      # NumPy arrays [SI units], the regression metrics

The scenario ids are `boomsim.scenario_ids()`; `boomsim.sweep` runs a parameter sweep on Dask
(`pip install boomsim[sweeps]`) and `boomsim.regress` the catalogue against its baselines.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from .errors import Skip, UsageError
from .paths import FMI3_MODELS, MODELS, fmu
from .result import Result
from .scenarios import load_scenario, scenario_ids

try:
    __version__ = version("boomsim")
except PackageNotFoundError:  # running from a checkout without an install
    __version__ = "unknown"

__all__ = ["FMI3_MODELS", "MODELS", "Result", "Skip", "UsageError", "fmu", "load_scenario", "regress", "run", "scenario_ids",
           "sweep", "__version__"]

INTERFACES = ("cs", "me", "native")


def run(scenario: str | dict = "B", boom: str = "rigid", params: dict | None = None, step: float | None = None,
        stop_time: float | None = None, interface: str = "cs", fmi: int = 2, feedback_start: str | None = None,
        tolerance: float | None = None) -> Result:
    """Runs one variant of a scenario (an id of `scenario_ids()`, a .toml file or a loaded scenario)
    with the plant HydraulicBoom and the PressureFeedbackController coupled, and returns its
    Result (columns as NumPy arrays, `.metrics`, `.to_pandas()`).

    boom: "rigid" or "flexible"; params: FMU parameters by variable name (either FMU);
    step: the communication step [s] (default the scenario's, 1 ms); interface: "cs" (both
    FMUs' doStep through fmpy, Gauss-Seidel; FMI 3.0 holds the inputs over a step), "me" (one
    ODE under fmpy's CVode, no communication step) or "native" (`boomsim cosim`, the Rust loop of
    a checkout, FMI 2.0 Co-Simulation, the same rows as "cs"); feedback_start: "t0" or "cbv_open"
    (default: the scenario's first); tolerance: the relative tolerance of the FMUs' solver ("cs",
    default theirs, 1e-6) or of CVode ("me", default 1e-6)."""
    from . import cosim, model_exchange, native

    sc = scenario if isinstance(scenario, dict) else load_scenario(scenario)
    if interface == "cs":
        return cosim.run(sc, boom, step, stop_time, interpolate=fmi == 2, feedback_start=feedback_start,
                         tolerance=tolerance, fmi=fmi, params=params)
    if interface == "me":
        if step is not None:
            raise UsageError(f"step={step!r}: Model Exchange has no communication step")
        return model_exchange.run_me(sc, boom, stop_time, 1e-6 if tolerance is None else tolerance,
                                     feedback_start=feedback_start, fmi=fmi, params=params)
    if interface == "native":
        if fmi != 2 or tolerance is not None:
            raise UsageError("the native runner runs FMI 2.0 Co-Simulation at the FMUs' default tolerance: "
                             "give fmi=2 and no tolerance")
        return native.run_native(sc, boom, step, stop_time, feedback_start=feedback_start, params=params)
    raise UsageError(f"interface=\"{interface}\": one of {', '.join(INTERFACES)}")


def sweep(file: str, workers: int | None = None, out=None, resume: bool = False) -> list[dict]:
    """Runs a parameter sweep (a .toml file or a packaged sweep's name: "filter", "robustness") on
    a Dask LocalCluster of `workers` processes; returns one row per point (parameters, metrics,
    status) and writes the rows, a summary and the maps to `out` (default out/sweep/<name>).
    Needs the extra `boomsim[sweeps]` (Dask, pyarrow)."""
    from .parameter_sweep import run_sweep

    return run_sweep(file, workers, resume=resume, out=out)


def regress(only: list[str] | None = None, out=None) -> int:
    """Runs the scenario catalogue (or the ids in `only`) against the packaged baselines within their
    tolerances and writes the report to `out` (default out/regress); returns 0 when every variant
    is within tolerance, 1 otherwise (the regressions are printed)."""
    from .regression import main

    unknown = sorted(set(only or []) - set(scenario_ids()))
    if unknown:
        raise UsageError(f"only={only!r}: unknown scenario {', '.join(unknown)}; the scenarios are "
                         f"{', '.join(scenario_ids())}")
    args = ["--step-sweep", ""] + (["--only", ",".join(only)] if only else []) + (["--out", str(out)] if out else [])
    return main(args)
