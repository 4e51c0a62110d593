"""Records every output a refactor must leave unchanged, for `scripts/same-outputs`: the time
series of every scenario variant of the regression (Co-Simulation, FMI 2.0), of scenario B over
the regression's communication steps, of U and B through `boomsim cosim` (the native runner) and
the split system (HydraulicCircuit + BoomMechanics, each coupling, 5 s), in
FMI 3.0 Co-Simulation (inputs held) and in
Model Exchange under fmpy's CVode (FMI 2.0 and 3.0, rigid boom, 1 s), with the work counts of each
run, and the counts of `boomsim bench --json` (steps, right-hand sides, Jacobians; not its
times).

    python scripts/record_outputs.py OUT.npz          record (the boomsim package and FMUs on the path: pack first)
    python scripts/record_outputs.py --compare A.npz B.npz
                                                      every array bit for bit; exit 1 on a difference

Each key is one array ("<run>/<column>"); the comparison lists the keys that differ or exist on one
side only. About 4 minutes on the 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import subprocess
import sys

import numpy as np

from boomsim import cosim, regression, split
from boomsim.model_exchange import run_me
from boomsim.native import run_native
from boomsim.paths import boomsim_binary
from boomsim.result import Result
from boomsim.scenarios import load_scenario, variant_name

STEPS = [1e-4, 1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3, 8e-3, 1e-2, 2e-2]


def put(out: dict, name: str, res: Result) -> None:
    for column, values in res.data.items():
        out[f"{name}/{column}"] = np.asarray(values)
    for key, value in res.counts.items():
        out[f"{name}/count.{key}"] = np.asarray(value)


def record(path: pathlib.Path) -> None:
    out: dict[str, np.ndarray] = {}
    runs = [(f"regress/{variant_name(sc, boom, fb)}", lambda sc=sc, boom=boom, fb=fb:
             cosim.run(sc, boom, feedback_start=fb)) for sc, boom, fb in regression.variants()]
    b = load_scenario("B")
    runs += [(f"step/{h:g}", lambda h=h: cosim.run(b, "rigid", step=h)) for h in STEPS]
    for sid in ("U", "B"):
        sc = load_scenario(sid)
        for coupling in split.COUPLINGS:
            runs.append((f"split/{sid} {coupling}", lambda sc=sc, c=coupling: split.run(sc, "rigid", c, 1e-3, 5.0)))
        runs.append((f"fmi3/{sid}", lambda sc=sc: cosim.run(sc, "rigid", fmi=3, interpolate=False)))
        runs.append((f"native/{sid}", lambda sc=sc: run_native(sc, "rigid")))
        for fmi in (2, 3):
            runs.append((f"me{fmi}/{sid}", lambda sc=sc, fmi=fmi: run_me(sc, "rigid", stop_time=1.0, fmi=fmi)))
    for k, (name, run) in enumerate(runs, 1):
        print(f"[{k}/{len(runs)}] {name}", flush=True)
        put(out, name, run())
    bench = subprocess.run([str(boomsim_binary()), "bench", "--json", "--duration", "2"],
                           check=True, capture_output=True, text=True).stdout
    for case in json.loads(bench):
        for key in ("steps", "rhs_evals", "jac_evals"):
            out[f"bench/{case['case']} {case['boom']} {case['via']}/{key}"] = np.asarray(case[key])
    np.savez_compressed(path, **out)
    print(f"{len(out)} arrays -> {path}")


def compare(a: pathlib.Path, b: pathlib.Path) -> int:
    x, y = np.load(a), np.load(b)
    differ = [k for k in sorted(set(x) & set(y))
              if x[k].shape != y[k].shape or x[k].tobytes() != y[k].tobytes()]
    only = sorted(set(x) ^ set(y))
    for k in differ:
        print(f"differs: {k}")
    for k in only:
        print(f"only in {'the first' if k in x else 'the second'}: {k}")
    print(f"{len(set(x) | set(y))} arrays, {len(differ)} differ, {len(only)} on one side only")
    return 1 if differ or only else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", nargs="?", help="the .npz to write")
    ap.add_argument("--compare", nargs=2, metavar=("A", "B"), help="compare two recordings")
    args = ap.parse_args(argv)
    if args.compare:
        return compare(*map(pathlib.Path, args.compare))
    if not args.out:
        ap.error("give OUT.npz or --compare A B")
    record(pathlib.Path(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
