"""Wall time per sweep point of the runners: cosim.run through fmpy (fresh instances, and
instances reused with fmi2Reset as the sweep's workers do) and run_native (`boomsim cosim`),
for U and B with the rigid and the flexible boom, with the metrics. A benchmark: it prints, it
asserts nothing. Run after `cargo build --release && target/release/boomsim pack`.

    .venv/bin/python scripts/bench_sweep.py [--duration 5] [--repeat 5]
"""

import argparse
import sys
import time

from boomsim import cosim
from boomsim.errors import UsageError, cli
from boomsim.native import run_native
from boomsim.scenarios import load_scenario
from boomsim import metrics

RUNNERS = {
    "fmpy": lambda sc, boom, t: cosim.run(sc, boom, stop_time=t),
    "fmpy reused": lambda sc, boom, t: cosim.run(sc, boom, stop_time=t, reuse=True),
    "native": lambda sc, boom, t: run_native(sc, boom, stop_time=t),
}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=5.0, help="simulated time per run [s] (default 5)")
    ap.add_argument("--repeat", type=int, default=5, help="runs per case and runner; the median counts (default 5)")
    args = ap.parse_args(argv)
    if not (args.duration > 0 and args.repeat >= 1):
        raise UsageError("--duration must be > 0 and --repeat at least 1")
    print(f"{'case':<12} " + " ".join(f"{r + ' [ms]':>17}" for r in RUNNERS) + "  fmpy / native")
    for sid in ("U", "B"):
        sc = load_scenario(sid)
        for boom in ("rigid", "flexible"):
            med = {}
            for name, run in RUNNERS.items():
                times = []
                for _ in range(args.repeat):
                    t0 = time.perf_counter()
                    metrics.compute(run(sc, boom, args.duration))
                    times.append(time.perf_counter() - t0)
                med[name] = sorted(times)[len(times) // 2]
            print(f"{sid + '-' + boom:<12} " + " ".join(f"{v * 1e3:>17.1f}" for v in med.values())
                  + f"  {med['fmpy'] / med['native']:>12.1f}", flush=True)


if __name__ == "__main__":
    sys.exit(cli(main))
