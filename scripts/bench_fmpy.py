"""Cost of one setReal + doStep + getReal cycle of the PressureFeedbackController through fmpy
(Python ctypes). A benchmark: it prints, it asserts nothing. Run after `boomsim pack`."""

import argparse
import math
import sys
import time

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from boomsim.errors import UsageError, cli
from boomsim.paths import fmu


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=20000, help="cycles to time (default 20000)")
    n = parser.parse_args(argv).cycles
    if n < 1:
        raise UsageError(f"--cycles {n}: must be at least 1")
    path = str(fmu("PressureFeedbackController"))
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier)
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    p, u, h = [vr["p"]], [vr["u"]], 1e-3
    start = time.perf_counter()
    for k in range(n):
        s.setReal(p, [50e5 + 1e5 * math.sin(0.02 * k)])
        s.doStep(k * h, h)
        s.getReal(u)
    cycle = (time.perf_counter() - start) / n
    s.terminate()
    s.freeInstance()
    print(f"fmpy: setReal + doStep + getReal = {cycle * 1e6:.1f} us per cycle over {n} cycles")


if __name__ == "__main__":
    sys.exit(cli(main))
