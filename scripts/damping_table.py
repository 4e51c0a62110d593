"""The arm's damping laws side by side (issue 48): every regression metric of the flexible
variants of U, B and the C scenarios under the thesis' per-section law (boom.damping = 0), the
converged-modal law (3) at boom.xi = 0.5 %, 2 % and 5 %, and the modal law (2, the default),
through fmpy as the regression runs them (boomsim.regression's variants, cosim.run). Prints a
Markdown table: per variant and metric the thesis' value and each law's relative difference to it.
About 10 minutes on the 2-core machine; progress on stderr.

    .venv/bin/python scripts/damping_table.py [--only U,B] > table.md
"""

import argparse
import sys
import time

from boomsim import cosim
from boomsim import metrics as mx
from boomsim.regression import variants
from boomsim.scenarios import variant_name

#: (column heading, the parameters of its runs).
LAWS = [
    ("thesis (0)", {"boom.damping": "thesis"}),
    ("converged-modal (3), xi 0.5 %", {"boom.damping": "converged_modal", "boom.xi": 0.005}),
    ("converged-modal (3), xi 2 %", {"boom.damping": "converged_modal", "boom.xi": 0.02}),
    ("converged-modal (3), xi 5 %", {"boom.damping": "converged_modal", "boom.xi": 0.05}),
    ("modal (2), default", {"boom.damping": "modal"}),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="U,B,C1.1,C1.2,C1.3,C2.1,C2.2,C2.3,C3.1,C3.2,C3.3",
                    help="comma-separated scenario ids")
    args = ap.parse_args(argv)
    todo = [(sc, fb) for sc, boom, fb in variants(args.only.split(",")) if boom == "flexible"]
    t0 = time.time()
    print("| variant | metric | " + " | ".join(name for name, _ in LAWS) + " |")
    print("|---|---|" + "---|" * len(LAWS))
    for k, (sc, fb) in enumerate(todo, 1):
        got = [mx.compute(cosim.run(sc, "flexible", feedback_start=fb, params=params)) for _, params in LAWS]
        print(f"[{k}/{len(todo)} {time.time() - t0:.0f} s] {variant_name(sc, 'flexible', fb)}", file=sys.stderr)
        thesis = got[0]
        for metric, value in thesis.items():
            if value is None:
                continue
            cells = [f"{value:.4g}"]
            for m in got[1:]:
                other = m[metric]
                cells.append("-" if other is None else f"{other:.4g}" if value == 0 else
                             f"{(other - value) / abs(value) * 100:+.1f} %")
            print(f"| {variant_name(sc, 'flexible', fb)} | {metric} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    sys.exit(main())
