"""Regression of the scenario catalogue: runs every scenario variant (scenario x boom x feedback
start; the flexible boom under the default damping law and the thesis' law, `-flexible-thesis`),
computes the metrics, compares them with the committed baselines within the tolerances of
the package's baselines/tolerances.toml and writes a Markdown report with the plots.

    scripts/regress                 compare; exit 1 on a regression or a missing baseline
    scripts/regress --update        re-baseline (explicit, never automatic)
    scripts/regress --only B,U      a subset (ids)
    scripts/regress --step-sweep ""  without the sweep of the communication step (default: B)
    scripts/regress --only U,B --step-sweep "" --param solver.mode=1 --rel 0.05 --out out/realtime
                                    a variant with FMU parameters against the same baselines, each
                                    metric within 5 % (+ its abs floor): the real-time mode's accuracy

Report: out/regress/report.md (+ one PNG and CSV per variant).
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import time
import tomllib

from . import cosim
from .errors import Skip, cli, parse_params
from .fmus import FmuFile
from .paths import BASELINE_DIR as BASELINES, OUT as OUT_ROOT, PACKAGE
from .plots import plot
from .result import write_csv
from .scenarios import all_scenarios, load_scenario, scenario_ids, variant_name
from . import metrics as mx

OUT = OUT_ROOT / "regress"
ORDER = ["p3_pp_max", "p3_pp_late", "t_settle", "t_settle_motion", "t_motion", "t_cbv_open", "v_expected",
         "v_mean", "v_steady", "f_dom", "f_dom_amp", "u_comp_rms", "u_comp_max"]


def shown(path: pathlib.Path, base: pathlib.Path) -> str:
    """`path` relative to `base` where it lies below it, else whole."""
    return str(path.relative_to(base) if path.is_relative_to(base) else path)


def load_tolerances() -> dict:
    with open(BASELINES / "tolerances.toml", "rb") as f:
        return tomllib.load(f)


def compare(name: str, new: dict, base: dict, tol: dict) -> list[str]:
    """Regressions of `new` against `base`: a list of readable lines, empty when all pass."""
    bad = []
    for key, rule in tol.items():
        if key not in base and key not in new:
            continue
        b, n = base.get(key), new.get(key)
        cond = rule.get("only_if")
        if cond:  # e.g. compare f_dom only when the spectral peak is large enough to mean something
            k, limit = cond
            if (base.get(k) or 0.0) < limit and (new.get(k) or 0.0) < limit:
                continue
        if b is None or n is None:
            if b is not n:
                bad.append(f"{name}: {key} = {fmt(n)}, baseline {fmt(b)} ({rule['why']})")
            continue
        allowed = rule.get("abs", 0.0) + rule.get("rel", 0.0) * abs(b)
        if abs(n - b) > allowed:
            bad.append(f"{name}: {key} = {fmt(n)}, baseline {fmt(b)}, |diff| {abs(n - b):.4g} > {allowed:.4g}")
    return bad


def cell(m: dict, key: str) -> str:
    """A metric for the report: f_dom only where p3 oscillates (its spectral peak of at least
    metrics.OSCILLATING bar); below that the peak is the window's spectral floor, not a frequency."""
    if key == "f_dom" and (m.get("f_dom_amp") or 0.0) < mx.OSCILLATING:
        return "-"
    return fmt(m[key])


def fmt(x, digits=4) -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:.{digits}g}"
    return str(x)


def fmu_info() -> dict:
    out = {}
    for ident in ("HydraulicBoom", "PressureFeedbackController"):
        f = FmuFile.get(ident)
        out[ident] = {"guid": f.md.guid, "version": f.md.version}
    return out


def variants(only=None):
    for sc in all_scenarios():
        if only and sc["id"] not in only:
            continue
        for boom in sc["booms"]:
            for fb in sc["starts"]:
                yield sc, boom, fb


#: The flexible arm's damping laws the regression keeps baselines for (issue 48): the default
#: (modal) and the thesis' per-section law (eq. 2.36-2.38), whose variants are named
#: <id>-flexible-thesis[-cbv].
LAWS = {"": {}, "-thesis": {"boom.damping": "thesis"}}


def runs(only=None):
    """(scenario, boom, feedback start, variant name, the law's parameters) of every variant the
    regression runs: `variants`, the flexible ones under each of LAWS."""
    for sc, boom, fb in variants(only):
        for suffix, law in LAWS.items() if boom == "flexible" else [("", {})]:
            yield sc, boom, fb, variant_name(sc, boom + suffix, fb), law


def step_sweep(sid: str, steps, feedback_start: str) -> list[dict]:
    """Metrics of scenario `sid` (rigid) for each communication step, with a verdict: settles =
    p3 settles (2 %) and the steady velocity is within 2 % of the expected one (a limit cycle of
    the coupling can leave p3 nearly flat while it chokes the valve)."""
    sc = load_scenario(sid)
    rows = []
    for h in steps:
        r = cosim.run(sc, "rigid", step=h, feedback_start=feedback_start)
        m = mx.compute(r)
        off = m["v_steady"] / m["v_expected"] - 1
        ok = m["t_settle"] is not None and abs(off) <= 0.02
        why = "yes" if ok else "no: p3 does not settle" if m["t_settle"] is None else f"no: v off by {off:+.0%}"
        rows.append({"step": h, "settles": ok, "verdict": why, **m})
    return rows


def c_ranking(results: dict) -> list[str]:
    """Markdown lines ranking the C experiments (rigid boom) per feedback start."""
    lines = []
    for suffix, label in (("", "feedback from t = 0 (thesis conditions)"), ("-cbv", "feedback from the CBV opening")):
        rows = [(n.split("-")[0], m) for n, m in results.items()
                if n.startswith("C") and n.endswith("-rigid" + suffix)]
        if not rows:
            continue

        def key(item):
            m = item[1]
            unsettled = m["t_settle"] is None
            return (unsettled, m["t_settle"] if not unsettled else math.inf, m["p3_pp_late"])

        rows.sort(key=key)
        lines.append(f"\n**{label}** (best first: settled before unsettled, then by 2 % settling time of p3):\n")
        lines.append("| rank | exp. | K_f | omega_f | load moves at [s] | p3 settles at [s] | after motion [s] "
                     "| p3 p-p max [bar] | v_steady / expected | u_comp RMS |")
        lines.append("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for i, (sid, m) in enumerate(rows, 1):
            sc = load_scenario(sid)
            c = sc["controller"]
            lines.append(f"| {i} | {sid} | {c['K_f']:.3g} | {c['omega_f']:g} | {fmt(m['t_motion'])} | "
                         f"{fmt(m['t_settle'])} | {fmt(m['t_settle_motion'])} | {m['p3_pp_max']:.3g} | "
                         f"{m['v_steady'] / m['v_expected']:.3f} | {m['u_comp_rms']:.2g} |")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--update", action="store_true", help="write the baselines from this run")
    ap.add_argument("--only", default="", help="comma-separated scenario ids")
    ap.add_argument("--step-sweep", default="B",
                    help="scenario id for the communication-step sweep (default B; '' skips it)")
    ap.add_argument("--out", default=str(OUT))
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                    help="an FMU parameter for every variant (repeatable), e.g. solver.mode=1")
    ap.add_argument("--rel", type=float, default=None,
                    help="compare every metric within this relative tolerance (plus its abs floor) "
                         "instead of tolerances.toml's")
    args = ap.parse_args(argv)
    params = parse_params(ap, args.param)
    if args.update and (params or args.rel is not None):
        ap.error("--update writes the baselines of the default FMUs: no --param or --rel with it")
    only = {s for s in args.only.split(",") if s}
    unknown = sorted(only - set(scenario_ids()))
    if unknown:  # a filter that matches nothing must not pass (nor overwrite the report)
        ap.error(f"--only {args.only}: unknown scenario {', '.join(unknown)}; "
                 f"the scenarios are {', '.join(scenario_ids())}")
    if args.step_sweep and args.step_sweep not in scenario_ids():
        ap.error(f"--step-sweep {args.step_sweep}: unknown scenario; the scenarios are {', '.join(scenario_ids())}")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tol = load_tolerances()
    if args.rel is not None:
        tol = {k: {**rule, "rel": args.rel} for k, rule in tol.items()}
    info = fmu_info()

    results, failures, skipped, lines = {}, [], [], []
    t_start = time.time()
    todo = list(runs(only))
    for k, (sc, boom, fb, name, law) in enumerate(todo, 1):

        def progress():
            """n of N and the elapsed time, for the line of a finished variant."""
            return f"[{k:2d}/{len(todo)} {time.time() - t_start:5.0f} s]"

        try:
            res = cosim.run(sc, boom, feedback_start=fb, params={**law, **params})
        except Skip as e:
            skipped.append(f"{name}: {e}")
            print(f"{progress()} {name:24s} skipped: {e}")
            continue
        m = mx.compute(res)
        results[name] = m
        write_csv(res, out / f"{name}.csv")
        plot(res, out / f"{name}.png", m)
        base_file = BASELINES / f"{name}.json"
        if args.update:
            base_file.write_text(json.dumps({"scenario": shown(pathlib.Path(sc["file"]), PACKAGE), "boom": boom,
                                             "feedback_start": fb, "step": res.step, "fmus": info,
                                             **({"params": law} if law else {}), "metrics": m}, indent=2) + "\n")
            verdict = "baselined"
        elif not base_file.exists():
            failures.append(f"{name}: no baseline {shown(base_file, PACKAGE)} (run scripts/regress --update)")
            verdict = "NO BASELINE"
        else:
            bad = compare(name, m, json.loads(base_file.read_text())["metrics"], tol)
            failures += bad
            verdict = "ok" if not bad else "REGRESSION"
        print(f"{progress()} {name:24s} {verdict:10s} " + " ".join(f"{k}={fmt(m[k])}" for k in
                                                     ("p3_pp_max", "t_motion", "t_settle", "v_steady", "u_comp_rms")))
        lines.append((name, sc, res, m, verdict))

    sweep = []
    if args.step_sweep:
        print(f"step sweep of {args.step_sweep} (10 steps from 0.1 to 20 ms, two feedback starts)", flush=True)
        for fb in ("t0", "cbv_open"):
            steps = [1e-4, 1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3, 8e-3, 1e-2, 2e-2]
            sweep.append((fb, step_sweep(args.step_sweep, steps, fb)))

    write_report(out / "report.md", lines, results, failures, skipped, sweep, args, info, time.time() - t_start)
    print(f"report: {shown(out / 'report.md', pathlib.Path.cwd())}")
    if args.update:
        print(f"baselines written to {BASELINES}/ ({len(results)} variants)")
        return 0
    if failures:
        print(f"\n{len(failures)} regression(s):")
        for f in failures:
            print("  " + f)
        return 1
    print(f"all {len(results)} variants within tolerance ({len(skipped)} skipped)")
    return 0


def write_report(path, lines, results, failures, skipped, sweep, args, info, wall):
    r = ["# boomsim co-simulation regression report", ""]
    r.append("FMUs: " + ", ".join(f"{k} {v['version']} ({v['guid']})" for k, v in info.items()))
    if args.param or args.rel is not None:
        r.append(f"Parameters: {', '.join(args.param) or 'none'}; tolerance: "
                 f"{'tolerances.toml' if args.rel is None else f'{args.rel:g} relative + the abs floors of tolerances.toml'}.")
    r.append(f"Mode: {'re-baseline (--update)' if args.update else 'compare with the baselines'}; "
             f"{len(results)} variants run, {len(skipped)} skipped, {len(failures)} regression(s); {wall:.0f} s.")
    r.append("")
    if failures:
        r += ["## Regressions", ""] + [f"- {f}" for f in failures] + [""]
    r += ["## Metrics", "",
          "Variant = scenario-boom, `-cbv` = feedback starts when the CBV opens (else at t = 0). "
          "Definitions below the table; velocities < 0 lower the load.", ""]
    head = ["variant", "step [ms]"] + [f"{k} [{mx.DEFINITIONS[k][0]}]" for k in ORDER] + ["verdict"]
    r.append("| " + " | ".join(head) + " |")
    r.append("|" + " --- |" * len(head))
    for name, sc, res, m, verdict in lines:
        r.append("| " + " | ".join([name, f"{res.step * 1e3:g}"] + [cell(m, k) for k in ORDER] + [verdict]) + " |")
    r += ["", "| metric | unit | definition |", "| --- | --- | --- |"]
    r += [f"| {k} | {u} | {d} |" for k, (u, d) in mx.DEFINITIONS.items()]
    if skipped:
        r += ["", "## Skipped", ""] + [f"- {s}" for s in skipped]
    r += ["", "## Ranking of the C experiments", ""] + c_ranking(results)
    r += ["", "Thesis 8.1-8.2: the gain matters more than the filter frequency; C1.1, C2.1 and C3.2 gave the "
          "most stable pressures (C2.1 the most oscillating of the three); in C3 the gain of C3.1 is too low, "
          "C3.2 appropriate, C3.3 too high (poor compensation). See docs/python.md for the comparison."]
    for fb, rows in sweep:
        r += ["", f"## Communication-step sweep: {args.step_sweep}, feedback start {fb}", "",
              "| step [ms] | settles | load moves at [s] | p3 settles at [s] | v_steady [mm/s] | f_dom [Hz] (p3 peak >= 0.5 bar) | u_comp RMS |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
        for x in rows:
            f_dom = cell(x, "f_dom")
            r.append(f"| {x['step'] * 1e3:g} | {x['verdict']} | {fmt(x['t_motion'])} | "
                     f"{fmt(x['t_settle'])} | {x['v_steady']:.3f} | {f_dom} | {x['u_comp_rms']:.2g} |")
        ok = [x["step"] for x in rows if x["settles"]]
        first_bad = next((x["step"] for x in rows if not x["settles"]), None)
        r.append("")
        r.append(f"Largest step at which it settles: {max(ok) * 1e3:g} ms" if ok else "It settles at no step tried.")
        if first_bad is not None:
            r[-1] += f"; first step that fails: {first_bad * 1e3:g} ms."
    r += ["", "## Plots", ""]
    for name, *_ in lines:
        r += [f"### {name}", "", f"![{name}]({name}.png)", ""]
    pathlib.Path(path).write_text("\n".join(r) + "\n")


if __name__ == "__main__":
    sys.exit(cli(main))
