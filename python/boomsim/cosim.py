"""Coupled co-simulation of the two boomsim FMUs through fmpy (FMI 2.0 Co-Simulation; FMI 3.0
with --fmi 3).

    HydraulicBoom.p4 --> PressureFeedbackController.p
    operator reference u_ref(t) (time table) --> PressureFeedbackController.u_ref
    PressureFeedbackController.u --> HydraulicBoom.valve.u_ref

Usage:
    .venv/bin/boomsim-cosim B [--boom rigid] [--step 1e-3]
        [--stop-time 15] [--hold] [--interface cs|me] [--fmi 2|3] [--out out/cosim]
writes <out>/<scenario>-<boom>.csv and .png (p3, p4, cylinder velocity, u_ref / u_comp / u).

Coupling (Gauss-Seidel, loop-free). The plant's outputs do not depend directly on valve.u_ref
(the spool has dynamics); the controller has direct feedthrough p -> u. One communication step
[t_k, t_k+1] is
    plant.doStep(t_k, h)                         with valve.u_ref = u_k held over the step
    p4_k+1 = plant.p4
    controller.setRealInputDerivatives(p, (p4_k+1 - p4_k) / h)      (unless --hold; FMI 3.0: below)
    controller.doStep(t_k, h)                    the filter sees p4 linear over the step
    controller.p = p4_k+1, controller.u_ref = u_ref(t_k+1);  u_k+1 = controller.u
    plant.valve.u_ref = u_k+1
The controller therefore *interpolates* p4 (the plant has already been stepped, so the slope is
known, not guessed): no extrapolation is needed, and the filter state is exact for a
piecewise-linear p4. What the coupling cannot remove is the hold of u: the command applied over
[t_k, t_k+1] is computed from p4(t_k), i.e. the feedback acts with up to one communication step of
delay (h/2 on average, a phase lag of omega*h/2). That limits the usable step (see
docs/python.md and `scripts/regress --step-sweep`).

FMI 3.0 (`--fmi 3`, the .fmu files of target/fmu/fmi3: the same binaries) has no input
derivatives: the controller gets p4 linear over the step by intermediate update instead
(`fmus.LinearInputs`: its callback sets p on the line from p4_k to p4_k+1 where the FMU asks),
and FMI 2.0 and FMI 3.0 give bit-identical results, with the slope and with `--hold`
(tests/python/test_fmi3.py).

The scenario files (scenarios/*.toml beside this module) are documented in docs/python.md, "Scenario files".
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import math
import time

import numpy as np

from .errors import Skip, UsageError, cli
from .fmus import FmuFile, LinearInputs, boom_switch, initialize_plant, release, with_params
from .metrics import CBV_OPEN
from .model_exchange import run_me
from .paths import OUT
from .plots import plot
from .result import COLUMNS, PLANT_OUT, Result, write_csv
from .scenarios import check_feedback_start, controller_start, load_scenario, positive, reference, variant_name


def schedule(scenario: dict, step, stop_time, record_every, feedback_start):
    """(stop time, step, steps, record_every, feedback start) of a Co-Simulation run: the
    arguments, else the scenario's; record_every defaults to one row per millisecond or per step,
    whichever is coarser."""
    t_end = scenario["stop_time"] if stop_time is None else stop_time
    step = scenario["step"] if step is None else step
    positive("step", step, "s")
    positive("stop_time", t_end, "s")
    n = int(round(t_end / step))
    if n < 1 or abs(n * step - t_end) > 1e-9 * t_end:
        raise UsageError(f"stop_time={t_end!r}: a whole multiple of the step {step!r} s")
    if record_every is None:
        record_every = max(1, int(round(1e-3 / step)))
    fb_start = check_feedback_start(feedback_start or scenario["starts"][0])
    return t_end, step, n, record_every, fb_start


def run(scenario: dict, boom: str = "rigid", step: float | None = None, stop_time: float | None = None,
        interpolate: bool = True, record_every: int | None = None, feedback_start: str | None = None,
        tolerance: float | None = None, fmi: int = 2, params: dict | None = None, reuse: bool = False,
        timeout: float | None = None) -> Result:
    """Co-simulate one scenario variant. `record_every` thins the recorded rows (default: one
    row per millisecond or per step, whichever is coarser); `fmi`: the FMUs' FMI version (3: the
    controller's p4, linear over a step with `interpolate`, by intermediate update, as FMI 3.0 has
    no input derivatives; that controller is never reused); `params`: FMU parameters by variable name
    (HydraulicBoom's or the controller's), set after the scenario's. `reuse`: take the instances
    of an earlier run with `reuse` (fmi2Reset) instead of instantiating, and keep them after a
    run that succeeds (a failed run frees them). `timeout` [s]: a TimeoutError when the wall
    time exceeds it, checked between communication steps (a single doStep is not interrupted)."""
    plant_f, ctrl_f = FmuFile.get("HydraulicBoom", fmi), FmuFile.get("PressureFeedbackController", fmi)
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end, step, n, record_every, fb_start = schedule(scenario, step, stop_time, record_every, feedback_start)
    if tolerance is not None:
        positive("tolerance", tolerance, "1")
    enable = bool(scenario["controller"]["enable"])
    table = scenario["reference"]

    deadline = time.monotonic() + timeout if timeout is not None else math.inf
    new = (lambda f, name: f.reused_slave(name)) if reuse else (lambda f, name: f.slave(name))
    vp, vc = plant_f.vr, ctrl_f.vr
    plant = new(plant_f, f"{scenario['id']}.plant")
    # FMI 3.0: p4 linear over a step by intermediate update (FMI 2.0: its derivative).
    p_line = LinearInputs([vc["p"]]) if fmi == 3 and interpolate else None
    ctrl = ctrl_f.slave(f"{scenario['id']}.controller", inputs=p_line) if p_line else new(
        ctrl_f, f"{scenario['id']}.controller")
    ok = False
    try:
        initialize_plant(plant_f, plant, ctrl, scenario, switch, tolerance, t_end)
        p4 = plant.getReal([vp["p4"]])[0]

        def init_controller(t0: float, feedback: bool, first: bool):
            """(Re-)initialise the controller at t0: its filter starts at rest at the present p4."""
            if not first:
                ctrl.reset()
                ctrl.setupExperiment(tolerance=tolerance, startTime=t0, stopTime=t_end)
                ctrl.enterInitializationMode()
            for name, value in controller_start(scenario, ctrl_params).items():
                ctrl_f.set(ctrl, name, value)
            ctrl_f.set(ctrl, "enable", feedback)
            ctrl.setReal([vc["p"], vc["u_ref"]], [p4, reference(table, t0)])
            ctrl.exitInitializationMode()

        on = enable and fb_start == "t0"
        init_controller(0.0, on, True)
        fb_on_at = 0.0 if on else None

        out_p = [vp[k] for k in PLANT_OUT]
        i_p4, i_cbv = PLANT_OUT.index("p4"), PLANT_OUT.index("cbv.u_cbv")
        out_c = [vc["u"], vc["u_comp"]]
        rows = []
        y = plant.getReal(out_p)
        t = 0.0
        u_ref = reference(table, 0.0)
        for k in range(n + 1):
            t = k * step
            u, u_comp = ctrl.getReal(out_c)
            plant.setReal([vp["valve.u_ref"]], [u])
            if k % record_every == 0:
                rows.append([t, u_ref, u_comp, u, *y])
            if k == n:
                break
            if time.monotonic() > deadline:
                raise TimeoutError(f"exceeded the timeout of {timeout:g} s at t = {t:g} s of {t_end:g} s")
            plant.doStep(t, step)
            y = plant.getReal(out_p)
            p4_next = y[i_p4]
            if p_line:
                p_line.over(t, step, [p4], [p4_next])
            elif interpolate:
                ctrl.setRealInputDerivatives([vc["p"]], [1], [(p4_next - p4) / step])
            ctrl.doStep(t, step)
            p4 = p4_next
            u_ref = reference(table, t + step)
            if enable and not on and y[i_cbv] > CBV_OPEN:
                # feedback_start = "cbv_open": the feedback starts when the CBV cracks open, from
                # rest (the controller is re-initialised: filter state = present p4, no kick)
                on, fb_on_at = True, t + step
                init_controller(t + step, True, False)
            ctrl.setReal([vc["p"], vc["u_ref"]], [p4, u_ref])
        data = np.array(rows)
        rhs = plant.getReal([vp["solver.rhs_evals"]])[0]
        ok = True
    finally:
        if reuse and ok:
            plant_f.give_back(plant)
            if p_line is None:
                ctrl_f.give_back(ctrl)
            else:
                release(ctrl)
        else:
            release(plant, ctrl)
    return Result(scenario, boom, step, interpolate, {c: data[:, i] for i, c in enumerate(COLUMNS)}, fb_on_at,
                  fb_start, counts={"rhs": int(rhs)}, interface=f"Co-Simulation FMI {fmi}.0, step {step * 1e3:g} ms")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", help="scenario file or id (e.g. B or a .toml file)")
    ap.add_argument("--boom", default=None, choices=("rigid", "flexible"),
                    help="rigid or flexible (default: every boom of the scenario)")
    ap.add_argument("--step", type=float, default=None,
                    help="communication step [s] (default: the scenario's `step`, else 1e-3)")
    ap.add_argument("--stop-time", type=float, default=None)
    ap.add_argument("--hold", action="store_true", help="hold p4 over a step in the controller (no slope)")
    ap.add_argument("--interface", choices=("cs", "me"), default="cs",
                    help="cs: both FMUs' fmi2DoStep (default); me: both as Model Exchange under fmpy's CVode, one ODE")
    ap.add_argument("--fmi", type=int, choices=(2, 3), default=2,
                    help="FMI version of the FMUs: 2 (target/fmu, default) or 3 (target/fmu/fmi3; "
                         "CS passes the slope of p4 by intermediate update)")
    ap.add_argument("--feedback-start", choices=("t0", "cbv_open"), default=None,
                    help="only this feedback start (default: every start listed by the scenario)")
    ap.add_argument("--out", default=str(OUT / "cosim"))
    args = ap.parse_args(argv)
    if args.interface == "me" and (args.step is not None or args.hold):
        ap.error("--step and --hold are Co-Simulation options: Model Exchange has no communication step")
    for name, value in (("--step", args.step), ("--stop-time", args.stop_time)):
        if value is not None and not (0 < value < float("inf")):
            ap.error(f"{name} {value} must be a positive number of seconds (e.g. 1e-3)")
    try:
        sc = load_scenario(args.scenario)
    except UsageError as e:
        ap.error(str(e))
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    variants = [(b, f) for b in ([args.boom] if args.boom else sc["booms"])
                for f in ([args.feedback_start] if args.feedback_start else sc["starts"])]
    for boom, fb in variants:
        try:
            if args.interface == "me":
                res = run_me(sc, boom, args.stop_time, feedback_start=fb, fmi=args.fmi)
            else:
                res = run(sc, boom, args.step, args.stop_time, not args.hold, feedback_start=fb, fmi=args.fmi)
        except UsageError as e:
            ap.error(str(e))
        except Skip as e:
            print(f"{variant_name(sc, boom, fb)}: skipped: {e}")
            continue
        m = res.metrics
        write_csv(res, out / f"{res.name}.csv")
        plot(res, out / f"{res.name}.png", m)
        print(f"{res.name}: " + ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}"
                                          for k, v in m.items()))


if __name__ == "__main__":
    sys.exit(cli(main))
