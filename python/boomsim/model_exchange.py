"""The Model Exchange runner: a scenario variant with the plant and the controller as one ODE under
fmpy's CVode."""

from __future__ import annotations

import numpy as np

from .fmus import FmuFile, boom_switch, initialize_plant, release, with_params
from .metrics import CBV_OPEN
from .result import COLUMNS, PLANT_OUT, Result
from .scenarios import check_feedback_start, controller_start, positive, reference


#: fmi2Discard, fmi3Discard.
DISCARD = 2


class Integrator:
    """fmpy's CVode (BDF, dense Newton with difference-quotient Jacobian, rtol `tolerance`, atol =
    rtol x the nominals) over an ODE given by its callbacks from t = 0, stepped to output points;
    at every state event `on_event()` (in the event's time) and a restart."""

    def __init__(self, nx: int, nz: int, tolerance: float, get_x, set_x, get_dx, get_z, get_nominals, set_time,
                 on_event):
        from fmpy.fmi1 import FMICallException
        from fmpy.sundials import CVodeSolver

        class Solver(CVodeSolver):
            def f(self, t, y, ydot, user_data):
                """fmpy's right-hand side, with an FMU's Discard (FMI 2.0, 2.1.3: retry with a
                smaller step; the plants answer non-finite derivatives so, and take every finite
                state, issue 49) passed to CVode as a recoverable failure, which
                it answers with a smaller step, instead of fmpy's default: the exception lost in
                the callback and the derivatives left as they were. Any other failure is
                unrecoverable (-1: CVode stops with an error), not an exception, which ctypes
                would print and answer with 0, the stale derivatives taken as good."""
                try:
                    return super().f(t, y, ydot, user_data)
                except FMICallException as e:
                    return 1 if e.status == DISCARD else -1

        class NoInput:
            def apply(self, t):
                pass

        self.now = 0.0

        def at(t):
            self.now = t
            set_time(t)

        self.set_time, self.on_event = at, on_event
        self.solver = Solver(nx=nx, nz=nz, get_x=get_x, set_x=set_x, get_dx=get_dx, get_z=get_z,
                             get_nominals=get_nominals, set_time=at, input=NoInput(), startTime=0.0,
                             relativeTolerance=tolerance, maxNumSteps=100000)

    def advance(self, t: float) -> None:
        """Integrates to `t` through the state events on the way."""
        while True:
            event, _, t_reached = self.solver.step(self.now, t)
            self.set_time(t_reached)
            if not event:
                return
            self.on_event()
            self.solver.reset(t_reached)

    def reset(self, t: float) -> None:
        """A restart at `t` (a discontinuity of the right-hand side)."""
        self.solver.reset(t)


def run_me(scenario: dict, boom: str = "rigid", stop_time: float | None = None, tolerance: float = 1e-6,
           feedback_start: str | None = None, events: bool = True, fmi: int = 2,
           params: dict | None = None) -> Result:
    """The scenario variant with both FMUs as Model Exchange, integrated together by fmpy's CVode
    (BDF, dense Newton with difference-quotient Jacobian, rtol `tolerance`, atol = rtol x the
    FMUs' nominal values): one ODE of the plant's and the controller's states, with
    valve.u_ref = controller.u and controller.p = plant.p4 at every right-hand side, so there is
    no communication step and no delay in the loop. Rows every millisecond; CVode is restarted
    at the reference table's breakpoints and where the feedback switches on (its discontinuities),
    and, with `events`, where one of the plant's event indicators changes sign (CVode's root
    finding: the dead-band jump of the spool demand, the load-sensing switch).
    `counts`: CVode's right-hand-side evaluations (`rhs`, fmi2GetDerivatives of each FMU) and the
    state events (`events`). `fmi` 3: the FMI 3.0 FMUs (the same event indicators); `params`: as
    for `run`."""
    from ctypes import POINTER, c_double

    plant_f, ctrl_f = FmuFile.get("HydraulicBoom", fmi), FmuFile.get("PressureFeedbackController", fmi)
    switch = boom_switch(plant_f, boom)
    scenario, ctrl_params = with_params(scenario, plant_f, params)
    t_end = positive("stop_time", scenario["stop_time"] if stop_time is None else stop_time, "s")
    positive("tolerance", tolerance, "1")
    ctrl_cfg = scenario["controller"]
    fb_start = check_feedback_start(feedback_start or scenario["starts"][0])
    enable = bool(ctrl_cfg["enable"])
    table = scenario["reference"]
    plant = plant_f.model(f"{scenario['id']}.plant")
    ctrl = ctrl_f.model(f"{scenario['id']}.controller")
    vp, vc = plant_f.vr, ctrl_f.vr
    np_, nc = len(plant_f.md.derivatives), len(ctrl_f.md.derivatives)
    nz = plant_f.md.numberOfEventIndicators if events else 0
    counts = {"rhs": 0, "events": 0}
    try:
        initialize_plant(plant_f, plant, ctrl, scenario, switch, tolerance, t_end)
        for name, value in controller_start(scenario, ctrl_params).items():
            ctrl_f.set(ctrl, name, value)
        on = enable and fb_start == "t0"
        ctrl_f.set(ctrl, "enable", on)
        ctrl.setReal([vc["p"], vc["u_ref"]], [plant.getReal([vp["p4"]])[0], reference(table, 0.0)])
        ctrl.exitInitializationMode()
        for m in (plant, ctrl):
            m.newDiscreteStates()
            m.enterContinuousTimeMode()

        def couple(t: float):
            """The loop at time t: the controller reads p4 and u_ref(t), the plant reads u."""
            ctrl.setReal([vc["p"], vc["u_ref"]], [plant.getReal([vp["p4"]])[0], reference(table, t)])
            plant.setReal([vp["valve.u_ref"]], ctrl.getReal([vc["u"]]))

        def parts(ptr):
            a = np.ctypeslib.as_array(ptr, (np_ + nc,))
            return [(m, a[sl].ctypes.data_as(POINTER(c_double)), n)
                    for m, sl, n in ((plant, slice(0, np_), np_), (ctrl, slice(np_, None), nc))]

        def get_x(ptr, _n):
            for m, p, n in parts(ptr):
                m.getContinuousStates(p, n)

        def set_x(ptr, _n):
            for m, p, n in parts(ptr):
                m.setContinuousStates(p, n)

        def get_dx(ptr, _n):
            counts["rhs"] += 1
            couple(cvode.now)
            for m, p, n in parts(ptr):
                m.getDerivatives(p, n)

        def get_z(ptr, n):
            couple(cvode.now)
            plant.getEventIndicators(ptr, n)

        def get_nominals(ptr, _n):
            for m, p, n in parts(ptr):
                m.getNominalsOfContinuousStates(p, n)

        def set_time(t):
            for m in (plant, ctrl):
                m.setTime(t)

        def state_event():
            # Nothing is reinitialised (no discrete states), CVode restarts.
            counts["events"] += 1
            for m in (plant, ctrl):
                m.enterEventMode()
                m.newDiscreteStates()
                m.enterContinuousTimeMode()

        cvode = Integrator(np_ + nc, nz, tolerance, get_x, set_x, get_dx, get_z, get_nominals, set_time, state_event)
        breaks = set(np.round(table[:, 0], 9))
        out_p = [vp[k] for k in PLANT_OUT]
        i_cbv = PLANT_OUT.index("cbv.u_cbv")
        fb_on_at = 0.0 if on else None
        rows = []
        n = int(round(t_end / 1e-3))
        for k in range(n + 1):
            t = k * 1e-3
            if k > 0:
                cvode.advance(t)
            couple(t)
            y = plant.getReal(out_p)
            u, u_comp = ctrl.getReal([vc["u"], vc["u_comp"]])
            rows.append([t, reference(table, t), u_comp, u, *y])
            restart = round(t, 9) in breaks
            if enable and not on and y[i_cbv] > CBV_OPEN:
                # feedback_start = "cbv_open": from rest, the filter state at the present p4
                on, fb_on_at, restart = True, t, True
                ctrl.enterEventMode()
                ctrl_f.set(ctrl, "enable", True)
                ctrl.newDiscreteStates()
                ctrl.enterContinuousTimeMode()
                p4 = np.array([plant.getReal([vp["p4"]])[0]])
                ctrl.setContinuousStates(p4.ctypes.data_as(POINTER(c_double)), 1)
            if restart:
                cvode.reset(t)
        data = np.array(rows)
    finally:
        release(plant, ctrl)
    return Result(scenario, boom, 1e-3, False, {c: data[:, i] for i, c in enumerate(COLUMNS)}, fb_on_at, fb_start,
                  counts=counts, interface=f"Model Exchange, CVode rtol {tolerance:g}")
