"""Model Exchange against Co-Simulation, the comparison a user makes before choosing an interface:
cases U and B (10 s, as `boomsim bench`), rigid and flexible boom, plant and controller

    CS: fmpy drives both FMUs' fmi2DoStep at 1 ms (boomsim.cosim `run`, the internal Radau IIA
        solver at rtol 1e-6, the controller fed p4 with its slope over each step);
    ME: fmpy's CVode (BDF, rtol 1e-6, atol = rtol x nominals) integrates both FMUs as one ODE
        (boomsim.model_exchange `run_me`: no communication step, no delay in the loop);

with wall time, real-time factor, the plant's right-hand-side evaluations, and the error against a
reference: ME at rtol 1e-9, the continuous loop without a communication step. A second table
measures the event indicators (rigid boom, B and C1.3, where the compensated spool command
crosses the dead band): ME with and without CVode's root finding on them. A third one is the
tolerance an ME user picks: HydraulicBoom alone (rigid, valve.u_ref = -0.3 from rest, 1 s)
through fmpy.simulate_fmu with CVode at rtol 1e-3 to 1e-7, against CS at rtol 1e-9; a fourth
the same at rtol 1e-3 to 1e-5 with CVode's largest BDF order limited to 2 or 1, or its stability
limit detection on (`--only orders`, 10 s), and a fifth with CVode on the boom's own states
(7 rigid, 23 flexible) instead of the FMU's 69 padded slots (`--only layout`, a second). A
benchmark: it prints, it asserts nothing. Run after `boomsim pack`; under a minute on 2 cores
(the flexible references take most of it).
Usage: .venv/bin/python scripts/bench_interfaces.py [--rigid-only | --flexible-only] [--only TABLE]
       [--param NAME=VALUE ...]
"""

import argparse
import sys
import time

import numpy as np

from boomsim import cosim, paths
from boomsim.errors import cli, parse_params
from boomsim.model_exchange import run_me
from boomsim.scenarios import load_scenario

STOP = 10.0
CASES = [("U", "rigid"), ("B", "rigid"), ("U", "flexible"), ("B", "flexible")]


def timed(f, *args, **kw):
    t0 = time.perf_counter()
    r = f(*args, **kw)
    return r, time.perf_counter() - t0


def interface_rows(cases, params: dict) -> list:
    """CS and ME per case, against the ME reference at rtol 1e-9; `params`: the plant's and
    controller's parameters for every run."""
    rows = []
    start = time.perf_counter()
    for k, (sid, boom) in enumerate(cases, 1):
        sc = load_scenario(sid)
        print(f"[{k}/{len(cases)} {time.perf_counter() - start:.0f} s] {sid} {boom}: reference (ME, rtol 1e-9) ...",
              flush=True)
        ref = run_me(sc, boom, stop_time=STOP, tolerance=1e-9, params=params)
        for interface, run in (("CS 1 ms", lambda: cosim.run(sc, boom, stop_time=STOP, params=params)),
                               ("ME CVode", lambda: run_me(sc, boom, stop_time=STOP, params=params))):
            res, wall = timed(run)
            d, r = res.data, ref.data
            rows.append((sid, boom, interface, wall, STOP / wall, res.counts["rhs"],
                         np.abs(d["p3"] - r["p3"]).max() / 1e5, np.abs(d["cylinder.x"] - r["cylinder.x"]).max() * 1e3))
            print(f"    {interface}: {wall:.2f} s", flush=True)
    return rows


def event_rows() -> list:
    """ME with and without root finding on the event indicators (rigid boom, B and C1.3)."""
    print("Event indicators (rigid boom, 15 s, against ME at rtol 1e-9 with events) ...", flush=True)
    rows = []
    for sid in ("B", "C1.3"):
        sc = load_scenario(sid)
        ref = run_me(sc, "rigid", tolerance=1e-9)
        for events in (True, False):
            res, wall = timed(run_me, sc, "rigid", events=events)
            rows.append((sid, "on" if events else "off", res.counts["events"], res.counts["rhs"], wall,
                         np.abs(res.data["p3"] - ref.data["p3"]).max() / 1e5))
    return rows


def tolerance_case(flexible: bool = False):
    """HydraulicBoom ME alone (rigid unless `flexible`, u_ref -0.3 from rest, 1 s): the FMU, the
    simulate_fmu arguments and the reference (CS at rtol 1e-9)."""
    from fmpy import simulate_fmu

    fmu = str(paths.fmu("HydraulicBoom"))
    kw = dict(stop_time=1.0, output_interval=1e-3, output=["p1", "p2", "p3", "p4"],
              start_values={"boom.flexible": flexible, "valve.u_ref": -0.3})
    return fmu, kw, simulate_fmu(fmu, fmi_type="CoSimulation", relative_tolerance=1e-9, **kw)


def p3_error(r, ref) -> float:
    """Largest p3 error of run r against the reference at its output points [bar]."""
    return np.abs(np.interp(ref["time"], r["time"], r["p3"]) - ref["p3"]).max() / 1e5


def tolerance_rows() -> tuple:
    """HydraulicBoom ME alone through fmpy.simulate_fmu at several CVode tolerances."""
    print("Tolerance (HydraulicBoom ME alone, rigid, u_ref -0.3, 1 s) ...", flush=True)
    from fmpy import simulate_fmu

    fmu, kw, cs_ref = tolerance_case()
    rows = []
    for tol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7):
        run = lambda: simulate_fmu(fmu, fmi_type="ModelExchange", relative_tolerance=tol, **kw)  # noqa: E731
        p3, error, p_max, wall = case_row(run, cs_ref)
        rows.append((f"{tol:g}", p3, error, p_max, wall))
    return cs_ref["p3"][-1] / 1e5, rows


def with_cvode(adapt, run):
    """run() with fmpy's CVodeSolver built through adapt(init, self, *args, **kw) instead of its
    own __init__ (init): the options and state vectors fmpy gives CVode, changed for a study."""
    import fmpy.sundials as sundials

    init = sundials.CVodeSolver.__init__
    sundials.CVodeSolver.__init__ = lambda self, *args, **kw: adapt(init, self, *args, **kw)
    try:
        return run()
    finally:
        sundials.CVodeSolver.__init__ = init


def case_row(run, cs_ref) -> tuple:
    """p3 at 1 s, its largest error and the largest pressure of a tolerance-case run [bar], and its
    wall time; a failed run as such."""
    try:
        r, wall = timed(run)
    except Exception as e:  # noqa: BLE001 - a failed run is a row of the table
        # fmpy's CVode errors name SUNDIALS' source file before saying what happened.
        text = str(e)
        what = text.split(" in module")[0] + ": " + text.rsplit(": ", 1)[-1] if " in module" in text else text
        return ("failed", what[:120], "-", "-")
    p_max = max(np.abs(r[p]).max() for p in ("p1", "p2", "p3", "p4")) / 1e5
    return (f"{r['p3'][-1] / 1e5:.4g}", f"{p3_error(r, cs_ref):.3g}", f"{p_max:.4g}", f"{wall:.2f}")


def order_rows() -> list:
    """The tolerance case under CVode with its largest BDF order limited (CVodeSetMaxOrd, bound
    through ctypes: fmpy leaves SUNDIALS' default 5) and with its stability limit detection
    (CVodeSetStabLimDet, default off): whether the orders 3-5, not stable near the imaginary
    axis, are what fails at loose tolerances."""
    print("BDF order (the tolerance case, CVode's maximum order and stability limit detection) ...", flush=True)
    import ctypes

    from fmpy import simulate_fmu
    from fmpy.sundials.libraries import sundials_cvode

    for name in ("CVodeSetMaxOrd", "CVodeSetStabLimDet"):
        getattr(sundials_cvode, name).argtypes = [ctypes.c_void_p, ctypes.c_int]
    setting = {}

    def configured(init, self, *args, **kw):
        init(self, *args, **kw)
        assert sundials_cvode.CVodeSetMaxOrd(self.cvode_mem, setting["order"]) == 0
        assert sundials_cvode.CVodeSetStabLimDet(self.cvode_mem, setting["detection"]) == 0

    fmu, kw, cs_ref = tolerance_case()
    rows = []
    for tol in (1e-3, 1e-4, 1e-5):
        for order, detection in ((5, 0), (5, 1), (2, 0), (1, 0)):
            setting.update(order=order, detection=detection)
            run = lambda: simulate_fmu(fmu, fmi_type="ModelExchange", relative_tolerance=tol, **kw)  # noqa: E731
            rows.append((f"{tol:g}", str(order), "on" if detection else "off")
                        + case_row(lambda: with_cvode(configured, run), cs_ref))
    return rows


def layout_rows() -> list:
    """The tolerance case, rigid and flexible (the default 4 + 5 sections), with CVode given the
    FMU's Model Exchange slots (the circuit's 5 states, 32 section angles and 32 rates, the
    slots beyond the last section copies of it) or only the boom's own states (7 rigid, 23
    flexible), the copies filled in before every call to the FMU: whether the padding, which
    leaves the pressures 3 of CVode's 69 error-norm components, is what fails at loose
    tolerances."""
    print("Layout (the tolerance case, CVode on the 69 slots or on the boom's own states) ...", flush=True)
    import ctypes

    from fmpy import read_model_description, simulate_fmu

    sections = 32
    slots = len(read_model_description(tolerance_case()[0]).derivatives)
    circuit = slots - 2 * sections
    pointer = ctypes.POINTER(ctypes.c_double)

    def sized(n):
        """CVode on the circuit's states and the first n sections' angles and rates."""
        real = [*range(circuit + n), *range(circuit + sections, circuit + sections + n)]

        def adapt(init, self, nx, nz, get_x, set_x, get_dx, get_z, get_nominals, *args, **kw):
            assert nx == slots, nx
            full = np.zeros(slots)
            p_full = full.ctypes.data_as(pointer)

            def picked(get):
                def f(p, m):
                    get(p_full, slots)
                    np.ctypeslib.as_array(p, (m,))[:] = full[real]
                return f

            def expanded(p, m):
                x = np.ctypeslib.as_array(p, (m,))
                phi, omega = x[circuit:circuit + n], x[circuit + n:]
                full[:circuit], full[circuit:circuit + n] = x[:circuit], phi
                full[circuit + n:circuit + sections] = phi[-1]
                full[circuit + sections:circuit + sections + n], full[circuit + sections + n:] = omega, omega[-1]
                set_x(p_full, slots)

            init(self, len(real), nz, picked(get_x), expanded, picked(get_dx), get_z, picked(get_nominals),
                 *args, **kw)
        return adapt

    rows = []
    for boom, n in (("rigid", 1), ("flexible", 9)):
        fmu, kw, cs_ref = tolerance_case(flexible=boom == "flexible")
        for tol in (1e-3, 1e-4, 1e-5, 1e-6):
            run = lambda: simulate_fmu(fmu, fmi_type="ModelExchange", relative_tolerance=tol, **kw)  # noqa: E731
            rows.append((boom, f"{tol:g}", f"{slots} slots") + case_row(run, cs_ref))
            rows.append((boom, f"{tol:g}", f"{circuit + 2 * n} states")
                        + case_row(lambda: with_cvode(sized(n), run), cs_ref))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    booms = ap.add_mutually_exclusive_group()
    booms.add_argument("--rigid-only", action="store_true", help="skip the flexible boom")
    booms.add_argument("--flexible-only", action="store_true", help="skip the rigid boom")
    ap.add_argument("--only", choices=("interfaces", "events", "tolerance", "orders", "layout"), help="one table")
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter of the interfaces table's runs (repeatable), e.g. boom.damping=1")
    args = ap.parse_args(argv)
    params = parse_params(ap, args.param)
    cases = [c for c in CASES if not (args.rigid_only and c[1] == "flexible")
             and not (args.flexible_only and c[1] == "rigid")]
    if args.only in (None, "interfaces"):
        print_table(("case", "boom", "interface", "wall [s]", "real-time factor", "RHS", "max abs p3 error [bar]",
                     "max abs stroke error [mm]"),
                    [(sid, boom, interface, f"{wall:.2f}", f"{rtf:.1f}x", str(rhs), f"{ep3:.3g}", f"{ex:.3g}")
                     for sid, boom, interface, wall, rtf, rhs, ep3, ex in interface_rows(cases, params)])
    if args.only in (None, "events"):
        print_table(("case", "event indicators", "state events", "RHS", "wall [s]", "max abs p3 error [bar]"),
                    [(sid, str(on), str(n_events), str(rhs), f"{wall:.2f}", f"{ep3:.3g}")
                     for sid, on, n_events, rhs, wall, ep3 in event_rows()])
    if args.only in (None, "tolerance"):
        p3_ref, rows = tolerance_rows()
        print_table(("CVode rtol", f"p3 at 1 s [bar] (CS rtol 1e-9: {p3_ref:.4g})", "max abs p3 error [bar]",
                     "max abs p1..p4 [bar]", "wall [s]"), rows)
    measured = ("p3 at 1 s [bar]", "max abs p3 error [bar]", "max abs p1..p4 [bar]", "wall [s]")
    if args.only in (None, "orders"):
        print_table(("CVode rtol", "max BDF order", "stability limit detection") + measured, order_rows())
    if args.only in (None, "layout"):
        print_table(("boom", "CVode rtol", "CVode's states") + measured, layout_rows())


def print_table(columns: tuple, rows: list) -> None:
    """A Markdown table of the given column titles and rows of text."""
    print("\n| " + " | ".join(columns) + " |")
    print("|" + " --- |" * len(columns))
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    sys.exit(cli(main))
