"""`boomsim linearize` at a scenario's conditions: its reference, its start stroke, its filter (the
loop closed when its controller is enabled) and its plant parameters, from the scenario file
(the catalogue's scenarios/*.toml, as `boomsim.scenarios` reads it).

Usage: boomsim-linearize SCENARIO [--boom rigid|flexible] [--at T | --stroke MM]
       [--param NAME=VALUE ...] [-- more boomsim linearize options, e.g. --json --out m.mat]

Without --at: the steady lowering at the scenario's final reference through --stroke (default:
Table 6.1's 250 mm). With --at T: the state T seconds into the scenario's run, which steps the
reference at t = 0 from rest at its start stroke (every scenario here does). Under a second.
"""

import argparse
import subprocess
import sys

from .errors import UsageError, cli, parse_params
from .paths import boomsim_binary
from .scenarios import load_scenario, scenario_ids


def linearize_args(sc: dict, boom: str, at: float | None, stroke: float | None, params: dict) -> list[str]:
    """The `boomsim linearize` options of scenario `sc`."""
    ref = sc["reference"]
    if at is not None and not (ref[0, 0] == 0.0 and all(ref[:, 1] == ref[0, 1])):
        raise UsageError(f"{sc['id']}: --at needs a reference stepped at t = 0 and held; it has {ref.tolist()}")
    args = ["--boom", boom, "--u-ref", repr(float(ref[-1, 1]))]
    if at is not None:
        args += ["--at", repr(at), "--start", repr(sc["start_stroke"] * 1e3)]
    elif stroke is not None:
        args += ["--stroke", repr(stroke)]
    ctrl = sc["controller"]
    if ctrl["enable"]:
        args.append("--feedback")
        args += [a for k, flag in (("K_f", "--k-f"), ("omega_f", "--omega-f")) if k in ctrl for a in (flag, repr(ctrl[k]))]
    for name, value in {**sc["plant"], **params}.items():
        args += ["--set", f"{name}={value}"]
    return args


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    rest = argv[argv.index("--") + 1:] if "--" in argv else []
    own = argv[: argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", help=f"a scenario id ({', '.join(scenario_ids())}) or a .toml file")
    ap.add_argument("--boom", choices=["rigid", "flexible"], default="flexible")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--at", type=float, metavar="T", help="the state T seconds into the scenario's run")
    where.add_argument("--stroke", type=float, metavar="MM", help="the steady lowering's stroke [mm]")
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE", help="a plant parameter")
    a = ap.parse_args(own)
    sc = load_scenario(a.scenario)
    cmd = [str(boomsim_binary()), "linearize",
           *linearize_args(sc, a.boom, a.at, a.stroke, parse_params(ap, a.param)), *rest]
    return subprocess.run(cmd, check=False).returncode


if __name__ == "__main__":
    sys.exit(cli(main))
