"""Parameter sweeps of one scenario on Dask (issue 15): a grid and/or seeded Monte Carlo points,
one task per point, rows appended to Parquet as points finish.

Usage:
    boomsim-sweep filter|robustness|FILE.toml [--workers N]
        [--scheduler ADDRESS] [--resume] [--out DIR]
writes DIR/results/*.parquet (one file per batch of finished points), DIR/summary.md and, when
two or more parameters vary on a grid, maps DIR/map-<metric>.png (boomsim.sweep_summary).

Sweep file (TOML):
    scenario = "B"            # a scenario id (or a .toml path), as boomsim.run takes
    boom = "rigid"            # default rigid
    stop_time = 15.0          # default: the scenario's
    metrics = ["p3_pp_late", "t_settle"]        # names of metrics.compute
    timeout = 60.0            # s of wall time per point (default none): beyond it, a failed row
    runner = "native"         # "fmpy" (default) or "native": `boomsim cosim`, the same rows
    samples = 20; seed = 1    # needed by Monte Carlo parameters
    [parameters]              # FMU parameters by variable name (HydraulicBoom or controller)
    K_f = {grid = [1e-11, 1.24e-11]}
    "fluid.beta" = {dist = "uniform", low = 1.2e9, high = 1.8e9}   # or {dist = "normal", mean, sd}
    n_omega = {grid = [1.0, 2.0]}   # filter factors, instead of K_f / omega_f (FACTORS)
    step = {grid = [1e-3, 5e-3]}    # the communication step [s] (SETTINGS)
The points are the product of the grids with the `samples` Monte Carlo draws (numpy
default_rng(seed), parameters in file order). A point is identified by a hash of the scenario,
boom, stop time and its parameter values, which `--resume` uses to skip finished points.
With fmpy each worker keeps its two FMU instances from point to point (fmi2Reset, cosim.run's
`reuse`); the native runner is one `boomsim cosim` process per point (run_native).
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import pathlib
import sys
import time
import tomllib

import numpy as np

from . import cosim
from .errors import UsageError, cli
from .fmus import FmuFile
from .native import run_native
from .paths import OUT, SWEEP_DIR
from .scenarios import load_scenario, scenario_ids
from . import linear
from . import metrics as metrics_mod
from . import sweep_summary

DISTS = {"uniform": ("low", "high"), "normal": ("mean", "sd")}
#: Filter factors relative to the linear analysis at the point's operating point and the
#: controller parameter each sets: K_f = n_K C1 mu_c mu_p (thesis eq. 6.6), omega_f = n_omega
#: omega_n (eq. 6.7), from `boomsim analyze` (`linear.operating_point`).
FACTORS = {"n_K": "K_f", "n_omega": "omega_f"}
#: Sweepable settings of the co-simulation itself, passed to the runner by keyword.
SETTINGS = {"step": "communication step [s]; the stop time must be a multiple of it"}
#: How a point is co-simulated: fmpy on instances reused from point to point, or `boomsim cosim`.
RUNNERS = {"fmpy": lambda *a, **k: cosim.run(*a, **k, reuse=True), "native": run_native}


# --------------------------------------------------------------------------- sweep file


def sweep_names() -> list[str]:
    """The sweep files the package carries (sweeps/*.toml), by name."""
    return sorted(p.stem for p in SWEEP_DIR.glob("*.toml"))


def load(path) -> dict:
    """The validated sweep of a .toml file or of a packaged sweep's name (sweep_names): scenario,
    boom, stop time, metrics, parameters and points. Every mistake is a UsageError naming the
    item and the valid choices, before anything runs."""
    if not pathlib.Path(path).exists() and (SWEEP_DIR / f"{path}.toml").exists():
        path = SWEEP_DIR / f"{path}.toml"
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise UsageError(f"{path}: {e}") from None
    if "scenario" not in doc:
        raise UsageError(f"{path}: no scenario: give scenario = one of {', '.join(scenario_ids())}")
    scenario = load_scenario(doc["scenario"])
    boom = doc.get("boom", "rigid")
    if boom not in ("rigid", "flexible"):
        raise UsageError(f"unknown boom \"{boom}\": rigid or flexible")
    names = {**FmuFile.get("PressureFeedbackController").vars, **FmuFile.get("HydraulicBoom").vars}
    sweepable = sorted(n for n, v in names.items() if v.causality == "parameter" and v.type != "Boolean")
    keep = doc.get("metrics", [])
    for m in keep:
        if m not in metrics_mod.DEFINITIONS:
            raise UsageError(f"unknown metric \"{m}\": {', '.join(metrics_mod.DEFINITIONS)}")
    if not keep:
        raise UsageError(f"no metrics: give metrics = [...] from {', '.join(metrics_mod.DEFINITIONS)}")
    params = doc.get("parameters", {})
    if not params:
        raise UsageError("no [parameters]: give at least one grid or distribution")
    timeout = doc.get("timeout")
    if timeout is not None and not (isinstance(timeout, (int, float)) and timeout > 0):
        raise UsageError(f"timeout = {timeout!r}: give a number of seconds > 0")
    runner = doc.get("runner", "fmpy")
    if runner not in RUNNERS:
        raise UsageError(f"unknown runner \"{runner}\": {', '.join(RUNNERS)}")
    grids, dists = {}, {}
    for name, spec in params.items():
        if name not in sweepable and name not in FACTORS and name not in SETTINGS:
            known = sorted(sweepable + list(FACTORS) + list(SETTINGS))
            raise UsageError(f"unknown parameter \"{name}\": {', '.join(known)}")
        if FACTORS.get(name) in params:
            raise UsageError(f"parameters \"{name}\" and \"{FACTORS[name]}\" both set {FACTORS[name]}: give one")
        if not isinstance(spec, dict) or ("grid" in spec) == ("dist" in spec):
            raise UsageError(f"parameter \"{name}\": give {{grid = [...]}} or {{dist = ...}}")
        if "grid" in spec:
            if not spec["grid"]:
                raise UsageError(f"parameter \"{name}\": empty grid")
            grids[name] = list(spec["grid"])
            continue
        need = DISTS.get(spec["dist"])
        if need is None:
            raise UsageError(f"parameter \"{name}\": unknown distribution \"{spec['dist']}\": {', '.join(DISTS)}")
        if any(k not in spec for k in need):
            raise UsageError(f"parameter \"{name}\": {spec['dist']} needs {', '.join(need)}")
        dists[name] = spec
    draws = [{}]
    if dists:
        if "samples" not in doc or "seed" not in doc:
            raise UsageError(f"Monte Carlo parameters ({', '.join(dists)}) need samples and seed at the top level")
        rng = np.random.default_rng(doc["seed"])
        cols = {n: (rng.uniform(s["low"], s["high"], doc["samples"]) if s["dist"] == "uniform"
                    else rng.normal(s["mean"], s["sd"], doc["samples"])) for n, s in dists.items()}
        draws = [{n: float(c[i]) for n, c in cols.items()} for i in range(doc["samples"])]
    sweep = dict(scenario=scenario, boom=boom, stop_time=float(doc.get("stop_time", scenario["stop_time"])),
                 metrics=keep, grids=grids, parameters=list(params), timeout=timeout, runner=runner,
                 derived=[FACTORS[f] for f in FACTORS if f in params])
    sweep["points"] = [with_filter(sweep, point_id(sweep, {**dict(zip(grids, g)), **d}))
                       for g in itertools.product(*grids.values()) for d in draws]
    return sweep


def point_id(sweep: dict, values: dict) -> dict:
    """The point with its `id`: a hash of what determines its result."""
    key = json.dumps([sweep["scenario"]["id"], sweep["boom"], sweep["stop_time"], sorted(values.items())])
    return {"id": hashlib.sha256(key.encode()).hexdigest()[:16], **values}


# --------------------------------------------------------------------------- filter factors


def with_filter(sweep: dict, point: dict) -> dict:
    """The point with K_f and omega_f of its filter factors n_K and n_omega (FACTORS)."""
    if not sweep["derived"]:
        return point
    unit = linear.analyze(tuple(linear.operating_point(sweep, point).items()))["filters"][0]  # n_K = n_omega = 1
    return {**point, **{p: point[f] * unit[p] for f, p in FACTORS.items() if f in point}}


# --------------------------------------------------------------------------- one point


def run_point(sweep: dict, point: dict) -> dict:
    """One co-simulation: the row of the point (parameters, metrics, status, error, wall time,
    worker). Any exception, fmpy's FMICallException of an fmi2Error/Discard included, gives a
    failed row with its message."""
    t0 = time.perf_counter()
    params = {k: v for k, v in point.items() if k != "id" and k not in FACTORS and k not in SETTINGS}
    settings = {k: v for k, v in point.items() if k in SETTINGS}
    row = {**point, **{m: None for m in sweep["metrics"]}, "status": "ok", "error": ""}
    try:
        res = RUNNERS[sweep["runner"]](sweep["scenario"], sweep["boom"], stop_time=sweep["stop_time"], params=params,
                                       timeout=sweep["timeout"], **settings)
        m = metrics_mod.compute(res)
        row.update({k: m[k] for k in sweep["metrics"]})
    except Exception as e:  # noqa: BLE001 - every failure is a row
        row.update(status="failed", error=f"{type(e).__name__}: {e}")
    try:
        from distributed import get_worker

        worker = str(get_worker().name)
    except (ImportError, ValueError):
        worker = "local"
    return {**row, "wall_time": time.perf_counter() - t0, "worker": worker}


# --------------------------------------------------------------------------- results


def schema(sweep: dict):
    import pyarrow as pa

    def ptype(name):
        ints = name in sweep["grids"] and all(isinstance(v, int) for v in sweep["grids"][name])
        return pa.int64() if ints else pa.float64()

    return pa.schema([("id", pa.string())] + [(p, ptype(p)) for p in sweep["parameters"] + sweep["derived"]]
                     + [(m, pa.float64()) for m in sweep["metrics"]]
                     + [("status", pa.string()), ("error", pa.string()), ("wall_time", pa.float64()),
                        ("worker", pa.string())])


def write_rows(sweep: dict, out: pathlib.Path, rows: list[dict]):
    """One Parquet file of finished rows under out/results/ (written to a hidden temporary name,
    then renamed, so a kill never leaves half a file in the dataset)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    d = out / "results"
    d.mkdir(parents=True, exist_ok=True)
    name = f"part-{time.time_ns()}-{os.getpid()}.parquet"
    tmp = d / f".{name}"  # pyarrow.dataset skips names starting with "."
    pq.write_table(pa.Table.from_pylist(rows, schema=schema(sweep)), tmp)
    os.replace(tmp, d / name)


def read_rows(sweep: dict, out: pathlib.Path) -> list[dict]:
    import pyarrow.dataset as ds

    d = out / "results"
    if not d.exists():
        return []
    return ds.dataset(str(d), format="parquet", schema=schema(sweep)).to_table().to_pylist()


# --------------------------------------------------------------------------- execution


def client_for(workers: int | None, scheduler: str | None):
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout=10)
        except (OSError, TimeoutError, ValueError) as e:
            raise UsageError(f"cannot connect to the scheduler \"{scheduler}\": {e}") from None
    n = workers or os.cpu_count()
    return Client(LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None))


def progress(done: int, failed: int, total: int, t0: float, tty: bool):
    elapsed = time.monotonic() - t0
    left = elapsed / done * (total - done) if done else float("nan")
    print(f"sweep: {done}/{total} done, {failed} failed, {elapsed:.1f} s elapsed, ~{left:.0f} s left",
          end="\r" if tty and done < total else "\n", file=sys.stderr, flush=True)


def execute(sweep: dict, todo: list[dict], out: pathlib.Path, workers: int | None, scheduler: str | None):
    from distributed import as_completed

    if not todo:
        return
    t0, done, failed, tty = time.monotonic(), 0, 0, sys.stderr.isatty()
    with client_for(workers, scheduler) as client:
        # the sweep once to every worker, without its list of points (the tasks carry theirs)
        task_sweep = client.scatter({k: v for k, v in sweep.items() if k != "points"}, broadcast=True)
        futures = client.map(run_point, [task_sweep] * len(todo), todo, pure=False)
        try:
            for batch in as_completed(futures, with_results=True).batches():
                rows = [r for _, r in batch]
                write_rows(sweep, out, rows)
                done += len(rows)
                failed += sum(r["status"] != "ok" for r in rows)
                progress(done, failed, len(todo), t0, tty)
        except (ModuleNotFoundError, RuntimeError) as e:
            missing = e if isinstance(e, ModuleNotFoundError) else e.__cause__
            if not isinstance(missing, ModuleNotFoundError):
                raise
            raise UsageError(f"the scheduler or a worker cannot import {missing.name}: start them from the "
                             "environment where the boomsim package is installed") from None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file", help=f"a sweep file (.toml) or a packaged sweep: {', '.join(sweep_names())}")
    ap.add_argument("--workers", type=int, help="LocalCluster worker processes (default: the CPU count)")
    ap.add_argument("--scheduler", help="address of an existing Dask scheduler instead of a LocalCluster")
    ap.add_argument("--resume", action="store_true", help="run only the points DIR/results lacks")
    ap.add_argument("--out", default=None, help="output directory (default out/sweep/<file stem>)")
    args = ap.parse_args(argv)
    run_sweep(args.file, args.workers, args.scheduler, args.resume, args.out)


def run_sweep(file, workers: int | None = None, scheduler: str | None = None, resume: bool = False,
              out=None) -> list[dict]:
    """Runs the sweep of `file` (a .toml path or a packaged sweep's name) on a LocalCluster of
    `workers` processes (default: the CPU count) or an existing scheduler, writes the rows to
    out/results (default out/sweep/<name>) with the summary and maps, and returns every row."""
    if workers is not None and workers < 1:
        raise UsageError(f"--workers {workers} must be at least 1")
    sweep = load(file)
    out = pathlib.Path(out or OUT / "sweep" / pathlib.Path(file).stem)
    if (out / "results").exists() and not resume:
        raise UsageError(f"{out / 'results'} exists: give --resume to continue it or another --out")
    have = {r["id"] for r in read_rows(sweep, out)}
    todo = [p for p in sweep["points"] if p["id"] not in have]
    print(f"sweep: {len(sweep['points'])} points, {len(have)} already done, {len(todo)} to run", file=sys.stderr)
    execute(sweep, todo, out, workers, scheduler)
    rows = read_rows(sweep, out)
    sweep_summary.write(sweep, rows, out)
    print(f"sweep: wrote {out / 'summary.md'}", file=sys.stderr)
    return rows


if __name__ == "__main__":
    from boomsim import parameter_sweep as module  # the tasks pickle run_point by reference to this module, not __main__

    sys.exit(cli(module.main))
