"""Scenario B (rigid boom, feedback from t0): Gauss-Seidel vs Jacobi masters, with and without
an extrapolated slope of valve.u_ref passed to HydraulicBoom (canInterpolateInputs, order 1).

  a   Gauss-Seidel reference, boomsim.cosim.run() (plant first; controller gets the p4 slope)
  b   Jacobi, plant input held: both FMUs get the other's outputs at t_k, then both doStep;
      controller p.extrapolation = true, no slopes passed
  c   Jacobi as b, plus plant.setRealInputDerivatives(valve.u_ref, 1, (u_k - u_k-1)/h) (0 at k=0)
  d,e b,c at 5 ms; a5 = Gauss-Seidel at 5 ms (extra, for context)

Measures what HydraulicBoom's interpolation of valve.u_ref changes for a Jacobi master (PyFMI's
extrapolates inputs this way); the README's HydraulicBoom section quotes its table.

    .venv/bin/python -m boomsim.jacobi [--jobs 2] [--sweep]     # about 1 s (--sweep: 8 s)

Uses the packed FMUs of target/fmu (boomsim pack); writes out/jacobi/results.npz.
"""
from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from . import cosim
from .errors import cli
from .fmus import FmuFile
from .paths import OUT as OUT_ROOT
from .scenarios import load_scenario, reference

OUT = OUT_ROOT / "jacobi"

BAR = 1e5
V_MOVE = -1e-3  # m/s


def fmus():
    """The packed plant and controller."""
    return FmuFile.get("HydraulicBoom"), FmuFile.get("PressureFeedbackController")


def scenario():
    return load_scenario("B")


def run_gs(step: float) -> dict:
    fmus()
    res = cosim.run(scenario(), "rigid", step=step, feedback_start="t0", record_every=1)
    d = res.data
    return {"time": d["time"], "p3": d["p3"], "x": d["cylinder.x"], "v": d["cylinder.v"], "u": d["u_cmd"],
            "Q3": d["Q3"], "cbv": d["cbv.u_cbv"]}


def run_jacobi(step: float, slope_to_plant: bool) -> dict:
    """Fixed-step Jacobi master: outputs of both FMUs read right after their doStep (before the
    new inputs are set), then each gets the other's outputs of t_k, then both step from t_k."""
    plant_f, ctrl_f = fmus()
    sc = scenario()
    ctrl_cfg, table = sc["controller"], sc["reference"]
    t_end = sc["stop_time"]
    n = int(round(t_end / step))
    vp, vc = plant_f.vr, ctrl_f.vr
    plant = plant_f.slave("B.plant")
    ctrl = ctrl_f.slave("B.controller")
    out_p = [vp["p4"], vp["p3"], vp["cylinder.x"], vp["cylinder.v"], vp["Q3"], vp["cbv.u_cbv"]]
    rows = []
    try:
        for s in (plant, ctrl):
            s.setupExperiment(tolerance=None, startTime=0.0, stopTime=t_end)
            s.enterInitializationMode()
        plant_f.set(plant, "start.x", sc["start_stroke"])
        plant_f.set(plant, "boom.flexible", False)
        plant.exitInitializationMode()
        p4 = plant.getReal([vp["p4"]])[0]
        for name in ("K_f", "omega_f", "u_min", "u_max"):
            if name in ctrl_cfg:
                ctrl_f.set(ctrl, name, ctrl_cfg[name])
        ctrl_f.set(ctrl, "enable", bool(ctrl_cfg["enable"]))
        ctrl_f.set(ctrl, "p.extrapolation", True)
        ctrl.setReal([vc["p"], vc["u_ref"]], [p4, reference(table, 0.0)])
        ctrl.exitInitializationMode()
        u_prev = None
        for k in range(n + 1):
            t = k * step
            # outputs at t_k (read before any input of t_k is set)
            p4, p3, x, v, q3, cbv = plant.getReal(out_p)
            u = ctrl.getReal([vc["u"]])[0]
            rows.append([t, p3, x, v, u, q3, cbv])
            if k == n:
                break
            # inputs at t_k from the other's outputs at t_k
            plant.setReal([vp["valve.u_ref"]], [u])
            if slope_to_plant:
                du = 0.0 if u_prev is None else (u - u_prev) / step
                plant.setRealInputDerivatives([vp["valve.u_ref"]], [1], [du])
            ctrl.setReal([vc["p"], vc["u_ref"]], [p4, reference(table, t)])
            u_prev = u
            plant.doStep(t, step)
            ctrl.doStep(t, step)
    finally:
        for s in (plant, ctrl):
            try:
                s.terminate()
            except Exception:  # noqa: BLE001
                pass
            s.freeInstance()
    a = np.array(rows)
    return {"time": a[:, 0], "p3": a[:, 1], "x": a[:, 2], "v": a[:, 3], "u": a[:, 4], "Q3": a[:, 5], "cbv": a[:, 6]}


#: The masters by how the plant gets u_ref's slope (None: Gauss-Seidel through cosim.run).
MASTERS = {None: "Gauss-Seidel (cosim.run)", False: "Jacobi, u_ref held", True: "Jacobi, u_ref slope extrap."}
#: key: (master, step, slope_to_plant). Per step the keys of the three masters; the extras
#: (--sweep) are 0.5 and 2 ms, and a fine Gauss-Seidel run as a proxy of the continuous coupling.
RUNS = {
    key: (MASTERS[slope], step, slope)
    for step, keys in {1e-3: "a b c", 5e-3: "a5 d e", 5e-4: "a05 b05 c05", 2e-3: "a2 b2 c2"}.items()
    for key, slope in zip(keys.split(), MASTERS)
} | {"fine": (MASTERS[None], 1e-4, None)}
MAIN_RUNS = ["a", "b", "c", "a5", "d", "e"]
SWEEP_RUNS = ["fine", "a05", "b05", "c05", "a2", "b2", "c2"]
#: project motion start (python/boomsim/metrics.py): CBV outflow -Q3 above 10 % of the expected steady flow
Q_MOTION = 0.1 * (25e-3 / 60 * 0.05 / (np.pi / 4 * (0.065**2 - 0.035**2))) * (np.pi / 4 * 0.065**2)


def one(key: str):
    _, step, slope = RUNS[key]
    t0 = time.perf_counter()
    d = run_gs(step) if slope is None else run_jacobi(step, slope)
    return key, d, time.perf_counter() - t0


def common(d: dict, r: dict):
    """Index arrays into d and r of the instants of the coarser of the two (nested) grids."""
    hd, hr = d["time"][1] - d["time"][0], r["time"][1] - r["time"][0]
    tc = d["time"] if hd >= hr else r["time"]
    idx_d, idx_r = np.rint(tc / hd).astype(int), np.rint(tc / hr).astype(int)
    assert np.allclose(d["time"][idx_d], tc, atol=1e-9) and np.allclose(r["time"][idx_r], tc, atol=1e-9)
    return idx_d, idx_r


def first(t, mask):
    i = np.nonzero(mask)[0]
    return float(t[i[0]]) if len(i) else float("nan")


def metrics(d: dict, ref: dict, fine: dict | None) -> dict:
    t = d["time"]
    last = t >= t[-1] - 5.0 - 1e-9
    m = {
        "t_v1mm": first(t, d["v"] < V_MOVE),  # the brief's definition
        "t_motion": first(t, -d["Q3"] > Q_MOTION),  # python/boomsim/metrics.py's definition
        "p3_pp": float(np.ptp(d["p3"][last])) / BAR,
        "v_mean": float(np.mean(d["v"][last])) * 1e3,
    }
    for tag, r in (("a", ref), ("fine", fine)):
        if r is None:
            continue
        i, j = common(d, r)
        m[f"rms_p3_{tag}"] = float(np.sqrt(np.mean((d["p3"][i] - r["p3"][j]) ** 2))) / BAR
        m[f"max_p3_{tag}"] = float(np.max(np.abs(d["p3"][i] - r["p3"][j]))) / BAR
        m[f"rms_x_{tag}"] = float(np.sqrt(np.mean((d["x"][i] - r["x"][j]) ** 2))) * 1e3
    return m


def table(keys, results, ref, fine, title):
    print(title)
    hdr = (f"{'run':<5}{'master':<29}{'h[ms]':>6}{'t(v<-1mm/s)':>12}{'t_motion':>9}{'p3pp[bar]':>10}"
           f"{'v[mm/s]':>9}{'RMSdp3':>8}{'max|dp3|':>9}{'RMSdx':>8}")
    if fine is not None:
        hdr += f"{'|fine: RMSdp3':>14}{'RMSdx':>8}"
    hdr += f"{'wall[s]':>8}"
    print(hdr)
    print("-" * len(hdr))
    for k in keys:
        d, w = results[k]
        name, step, _ = RUNS[k]
        m = metrics(d, ref, fine)
        line = (f"{k:<5}{name:<29}{step * 1e3:>6g}{m['t_v1mm']:>12.3f}{m['t_motion']:>9.3f}{m['p3_pp']:>10.3f}"
                f"{m['v_mean']:>9.3f}{m['rms_p3_a']:>8.4f}{m['max_p3_a']:>9.3f}{m['rms_x_a']:>8.4f}")
        if fine is not None:
            line += f"{m['rms_p3_fine']:>14.4f}{m['rms_x_fine']:>8.4f}"
        print(line + f"{w:>8.1f}")


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--sweep", action="store_true", help="also the extras: 0.1 ms reference, 0.5 and 2 ms")
    args = ap.parse_args(argv)
    keys = MAIN_RUNS + (SWEEP_RUNS if args.sweep else [])
    t_all = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        # longest first
        order = sorted(keys, key=lambda k: RUNS[k][1])
        results = {k: (d, w) for k, d, w in ex.map(one, order)}
    wall = time.perf_counter() - t_all
    ref = results["a"][0]
    fine = results["fine"][0] if "fine" in results else None
    OUT.mkdir(parents=True, exist_ok=True)
    np.savez(OUT / "results.npz", **{f"{k}_{c}": v for k, (d, _) in results.items() for c, v in d.items()})
    print("Scenario B, rigid boom (boom.flexible = false), feedback from t0, 15 s. p3pp and v: last 5 s (10-15 s).")
    print("RMSdp3 [bar], max|dp3| [bar], RMSdx [mm]: whole run vs run a (Gauss-Seidel, 1 ms), on the coarser of the two grids.")
    print("t_motion: python/boomsim/metrics.py's motion start (CBV outflow -Q3 > 10 % of the expected steady flow).")
    table(MAIN_RUNS, results, ref, fine, "")
    if args.sweep:
        print("\nExtras; '|fine' columns: against Gauss-Seidel at 0.1 ms (proxy for the continuous coupling)")
        table(["fine", "a05", "b05", "c05", "a", "b", "c", "a2", "b2", "c2", "a5", "d", "e"], results, ref, fine, "")
    print(f"\nwall time: {wall:.1f} s in total ({args.jobs} processes); per run in the last column")


if __name__ == "__main__":
    sys.exit(cli(main))
