"""The arm's damping laws over a swept parameter (issue 48's jump test): `boomsim eigen` with
boom.m_arm from 1 to 1000 kg in 50 steps under the thesis' law, the modal law and the
converged-modal law (`boom.damping` thesis, modal, converged_modal); prints, per law and mode
(the five lowest of the plant), the largest change of the damping ratio between neighbouring steps and where it is. A critically damped mode
is not oscillating and leaves `boomsim eigen`'s list: its place is empty. A few seconds.

    .venv/bin/python scripts/damping_sweep.py [--param boom.m_arm --from 1 --to 1000 --steps 50]
"""

import argparse
import json
import pathlib
import subprocess
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
MODES = 5


def modes(law: str, name: str, value: float) -> np.ndarray:
    """(frequency [Hz], damping ratio) of the plant's MODES lowest modes, NaN where fewer."""
    out = subprocess.run([str(ROOT / "target/release/boomsim"), "eigen", "--json", "--count", str(MODES),
                          "--set", f"{name}={value}", "--set", f"boom.damping={law}"],
                         capture_output=True, text=True, check=True).stdout
    rows = [(m["frequency_hz"], m["damping_ratio"]) for m in json.loads(out)["modes"]]
    return np.array(rows + [(np.nan, np.nan)] * (MODES - len(rows)))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--param", default="boom.m_arm")
    ap.add_argument("--from", dest="lo", type=float, default=1.0)
    ap.add_argument("--to", dest="hi", type=float, default=1000.0)
    ap.add_argument("--steps", type=int, default=50)
    args = ap.parse_args(argv)
    values = np.linspace(args.lo, args.hi, args.steps)
    print(f"| law | mode | largest change of zeta between steps of {args.param} | at {args.param} |")
    print("|---|---|---|---|")
    for law in ("thesis", "modal", "converged_modal"):
        zeta = np.array([modes(law, args.param, v)[:, 1] for v in values])
        step = np.abs(np.diff(zeta, axis=0))
        for k in range(MODES):
            if np.all(np.isnan(step[:, k])):
                continue
            i = int(np.nanargmax(step[:, k]))
            print(f"| {law} | {k + 1} | {step[i, k]:.4f} | {values[i]:.4g} -> {values[i + 1]:.4g} |")


if __name__ == "__main__":
    sys.exit(main())
