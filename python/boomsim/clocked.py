"""The rig's sampled loop in Model Exchange: HydraulicBoom (FMI 3.0 Model Exchange) under fmpy's
CVode with ClockedPressureFeedbackController, whose input Clock `sample` the master activates as
a time event every 5 ms.

    boomsim-clocked B [--model lag|"PVES loop"] [--boom rigid] [--stop-time 15] [--out out/clocked]

At every activation t_k = k T (T = the Clock's intervalDecimal, first at its shiftDecimal) the
master integrates the plant to t_k, enters Event Mode on both FMUs, activates the Clock
(fmi3SetClock), sets the controller's clocked inputs p = p4(t_k) and u_ref(t_k), reads its
clocked output u, ends the instant (fmi3UpdateDiscreteStates, which deactivates the Clock),
passes u to the plant and restarts CVode: one ODE (the plant's), the controller's filter a
discrete-time state advanced at the ticks. This reproduces `rig_loop.py`'s 5 ms Co-Simulation
(the continuous controller stepped by 5 ms with the slope of p4) up to the plant's integration
error. Written from the FMI 3.0 text (2.2.8 Clocks, 2.3.5 Event Mode); fmpy provides the calls,
not the master.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

from . import metrics
from .errors import UsageError, cli
from .fmus import FmuFile, boom_switch, initialize_plant, release, with_params
from .model_exchange import Integrator
from .paths import OUT
from .result import COLUMNS, PLANT_OUT, Result, write_csv
from . import rig_loop
from .rig_loop import MODELS
from .scenarios import controller_start, load_scenario, reference

CONTROLLER = "ClockedPressureFeedbackController"


def clock(ctrl_f: FmuFile, ctrl):
    """The controller's Clock: value reference, interval and shift, as the FMU gives them in
    Initialization Mode (fmi3GetIntervalDecimal, fmi3GetShiftDecimal)."""
    from ctypes import c_double, c_int, c_uint32

    vr = next(v for v in ctrl_f.md.modelVariables if v.type == "Clock").valueReference
    vrs, interval, qualifier, shift = (c_uint32 * 1)(vr), (c_double * 1)(), (c_int * 1)(), (c_double * 1)()
    ctrl.getIntervalDecimal(vrs, interval, qualifier)
    ctrl.getShiftDecimal(vrs, shift)
    return vr, interval[0], shift[0]


def run_clocked(scenario: dict, boom: str = "rigid", stop_time: float | None = None, tolerance: float = 1e-6,
                params: dict | None = None, interface: str = "me") -> Result:
    """The scenario variant with the sampled controller (feedback from t0, as the rig runs it),
    rows every millisecond. `interface` "me": both FMUs in Model Exchange, the plant under CVode,
    the Clock's activations time events; "cs": both in Co-Simulation, the plant stepped by 1 ms
    with the command held, the controller with Event Mode (eventModeUsed) stepped to each
    activation, which it handles in Event Mode. `params`: FMU parameters by name (HydraulicBoom's
    or the controller's). `counts`: the plant's right-hand sides (`rhs`: CVode's, or the FMU's
    integrator's), CVode's state events (`events`) and the Clock's activations (`ticks`)."""
    if interface not in ("me", "cs"):
        raise UsageError(f"interface={interface!r}: \"me\" (Model Exchange) or \"cs\" (Co-Simulation with Event Mode)")
    me = interface == "me"
    plant_f, ctrl_f = FmuFile.get("HydraulicBoom", 3), FmuFile.get(CONTROLLER, 3)
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end = scenario["stop_time"] if stop_time is None else stop_time
    table = scenario["reference"]
    name = scenario["id"]
    plant = plant_f.model(f"{name}.plant") if me else plant_f.slave(f"{name}.plant")
    ctrl = ctrl_f.model(f"{name}.controller") if me else ctrl_f.slave(f"{name}.controller", event_mode=True)
    vp, vc = plant_f.vr, ctrl_f.vr
    counts = {"rhs": 0, "events": 0, "ticks": 0}
    try:
        initialize_plant(plant_f, plant, ctrl, scenario, switch, tolerance, t_end)
        sample, interval, shift = clock(ctrl_f, ctrl)
        per_tick = round(interval / 1e-3)
        if abs(per_tick * 1e-3 - interval) > 1e-12 or abs(shift - interval) > 1e-12:
            raise UsageError(f"the Clock's interval {interval} s and shift {shift} s must be one multiple of 1 ms")
        for key, value in controller_start(scenario, ctrl_params).items():
            ctrl_f.set(ctrl, key, value)
        ctrl_f.set(ctrl, "enable", bool(scenario["controller"]["enable"]))
        ctrl.setReal([vc["p"], vc["u_ref"]], [plant.getReal([vp["p4"]])[0], reference(table, 0.0)])
        u, u_comp = ctrl.getReal([vc["u"], vc["u_comp"]])  # clocked: readable in Initialization Mode
        ctrl.exitInitializationMode()  # Event Mode: Model Exchange, and Co-Simulation with eventModeUsed
        plant.setReal([vp["valve.u_ref"]], [u])
        ctrl.newDiscreteStates()
        if me:
            plant.newDiscreteStates()
            for m in (plant, ctrl):
                m.enterContinuousTimeMode()
            cvode = plant_integrator(plant_f, plant, tolerance, counts)
        else:
            ctrl.enterStepMode()

        def activate(t: float):
            """The Clock's activation at t, the controller already in Event Mode: its command.
            Activation k (from 0) is due at shift + k interval: one at another time would skip
            or repeat one (FMI 3.0, 2.2.8.2), and the master stops."""
            due = shift + counts["ticks"] * interval
            if abs(t - due) > 1e-9 * interval:
                raise RuntimeError(f"activation {counts['ticks'] + 1} of the Clock is due at t = {due:.9g} s, "
                                   f"not t = {t:.9g} s: the master would {'skip' if t > due else 'repeat'} one")
            counts["ticks"] += 1
            ctrl.setClock([sample], [True])
            ctrl.setReal([vc["p"], vc["u_ref"]], [plant.getReal([vp["p4"]])[0], reference(table, t)])
            command = ctrl.getReal([vc["u"], vc["u_comp"]])
            ctrl.newDiscreteStates()
            return command

        out_p = [vp[k] for k in PLANT_OUT]
        rows = []
        for k in range(int(round(t_end / 1e-3)) + 1):
            t = k * 1e-3
            tick = k > 0 and k % per_tick == 0
            if k > 0 and me:
                cvode.advance(t)
            elif k > 0:
                plant.doStep(t - 1e-3, 1e-3)
                ctrl.doStep(t - 1e-3, 1e-3)
            if tick and me:
                # A time event of both FMUs.
                ctrl.setTime(t)
                for m in (plant, ctrl):
                    m.enterEventMode()
                u, u_comp = activate(t)
                plant.setReal([vp["valve.u_ref"]], [u])
                plant.newDiscreteStates()
                for m in (ctrl, plant):
                    m.enterContinuousTimeMode()
                cvode.reset(t)
            elif tick:
                ctrl.enterEventMode()
                u, u_comp = activate(t)
                ctrl.enterStepMode()
                plant.setReal([vp["valve.u_ref"]], [u])
            rows.append([t, reference(table, t), u_comp, u, *plant.getReal(out_p)])
        data = np.array(rows)
        due = int(np.floor((t_end - shift) / interval + 1e-9)) + 1
        if counts["ticks"] != due:
            raise RuntimeError(f"{counts['ticks']} activations of the Clock in {t_end} s; its times give {due}")
        if not me:
            counts["rhs"] = int(plant.getReal([vp["solver.rhs_evals"]])[0])
    finally:
        release(plant, ctrl)
    how = f"Model Exchange, CVode rtol {tolerance:g}" if me else "Co-Simulation with Event Mode, 1 ms"
    return Result(scenario, boom, interval, False, {c: data[:, i] for i, c in enumerate(COLUMNS)}, 0.0, "t0",
                  counts=counts, interface=f"{how} + {interval * 1e3:g} ms Clock")


def plant_integrator(plant_f: FmuFile, plant, tolerance: float, counts: dict) -> Integrator:
    """CVode over the plant's Model Exchange instance alone; a state event (the plant's: no
    discrete state changes) counted in `counts["events"]`, each right-hand side in `rhs`."""

    def get_dx(ptr, n):
        counts["rhs"] += 1
        plant.getDerivatives(ptr, n)

    def state_event():
        counts["events"] += 1
        plant.enterEventMode()
        plant.newDiscreteStates()
        plant.enterContinuousTimeMode()

    return Integrator(len(plant_f.md.derivatives), plant_f.md.numberOfEventIndicators, tolerance,
                      plant.getContinuousStates, plant.setContinuousStates, get_dx, plant.getEventIndicators,
                      plant.getNominalsOfContinuousStates, plant.setTime, state_event)


#: The runs of the table: label -> run_clocked's interface (None: rig_loop's 5 ms Co-Simulation).
RUNS = {"Clock in Model Exchange": "me", "Clock in Co-Simulation with Event Mode": "cs", "5 ms Co-Simulation": None}


def runs_of(scenario: dict, model: str) -> dict:
    """Experiment `scenario` with valve model `model` (rig_loop.MODELS) in each of RUNS."""
    return {label: run_clocked(scenario, params=MODELS[model], interface=i) if i else rig_loop.run(scenario, model)
            for label, i in RUNS.items()}


def table(runs: dict) -> str:
    """The Markdown table of docs/interfaces.md: per valve model its runs_of: speed against the
    rated one, p3 peak-to-peak of the last third, dominant frequency, 2 % settling time, and the
    Clock's activations."""
    lines = ["| B, rigid boom | speed / rated | p3 pp late (bar) | f (Hz) | settled (s) | activations |",
             "| --- | --- | --- | --- | --- | --- |"]
    for model, by_run in runs.items():
        for how, res in by_run.items():
            m = metrics.compute(res)
            settled = "-" if m["t_settle"] is None else f"{m['t_settle']:.2f}"
            ticks = res.counts.get("ticks", "")
            lines.append(f"| {model}, {how} | {m['v_steady'] / m['v_expected']:.3f} | {m['p3_pp_late']:.3f} | "
                         f"{m['f_dom']:.1f} | {settled} | {ticks} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", help="scenario file or id (e.g. B)")
    ap.add_argument("--model", choices=list(MODELS), default="PVES loop", help="valve electronics (rig_loop.MODELS)")
    ap.add_argument("--boom", choices=["rigid", "flexible"], default="rigid")
    ap.add_argument("--interface", choices=["me", "cs"], default="me",
                    help="Model Exchange (CVode, activations as time events) or Co-Simulation with Event Mode")
    ap.add_argument("--stop-time", type=float)
    ap.add_argument("--out", type=pathlib.Path, default=OUT / "clocked")
    args = ap.parse_args(argv)
    sc = load_scenario(args.scenario)
    res = run_clocked(sc, args.boom, args.stop_time, params=MODELS[args.model], interface=args.interface)
    m = metrics.compute(res)
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / f"{sc['id']}-{args.boom}.csv"
    write_csv(res, path)
    print(f"{sc['id']} ({args.model}, {args.boom}): speed {m['v_steady'] / m['v_expected']:.3f} of rated, "
          f"p3 pp {m['p3_pp_late']:.1f} bar, f {m['f_dom']:.1f} Hz, {res.counts['ticks']} activations -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(cli(main))
