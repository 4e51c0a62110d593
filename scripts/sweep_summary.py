"""The outputs of a sweep (scripts/sweep.py): DIR/summary.md (points, failures, the metrics'
min / median / max over the points that ran) and, when exactly two parameters vary on a grid and
none is drawn, DIR/heatmap.png of the first metric over them."""

from __future__ import annotations

import pathlib

import numpy as np

from metrics import DEFINITIONS


def write(sweep: dict, rows: list[dict], out: pathlib.Path):
    ok = [r for r in rows if r["status"] == "ok"]
    failed = [r for r in rows if r["status"] != "ok"]
    lines = [f"# Sweep of {sweep['scenario']['id']}-{sweep['boom']}, {sweep['stop_time']:g} s", "",
             f"{len(rows)} of {len(sweep['points'])} points run, {len(failed)} failed.", "",
             "| metric | unit | points with a value | min | median | max |", "|---|---|---|---|---|---|"]
    for m in sweep["metrics"]:
        v = np.array([r[m] for r in ok if r[m] is not None], dtype=float)
        stats = " | ".join(f"{x:.4g}" for x in (v.min(), np.median(v), v.max())) if len(v) else "- | - | -"
        lines.append(f"| {m} | {DEFINITIONS[m][0]} | {len(v)} of {len(ok)} | {stats} |")
    if failed:
        lines += ["", "Failed points:", ""] + [
            f"- {', '.join(f'{p} = {r[p]:g}' for p in sweep['parameters'])}: {r['error']}" for r in failed]
    varying = [p for p, g in sweep["grids"].items() if len(g) > 1]
    if len(varying) == 2 and len(sweep["grids"]) == len(sweep["parameters"]):
        heatmap(sweep, ok, varying, out / "heatmap.png")
        lines += ["", f"![{sweep['metrics'][0]}](heatmap.png)"]
    (out / "summary.md").write_text("\n".join(lines) + "\n")


def heatmap(sweep: dict, rows: list[dict], axes: list[str], path: pathlib.Path):
    """The first metric over the two grid parameters (blank: failed, missing or no value)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    (px, xs), (py, ys) = [(p, sorted(sweep["grids"][p])) for p in axes]
    m = sweep["metrics"][0]
    z = np.full((len(ys), len(xs)), np.nan)
    for r in rows:
        if r[m] is not None:
            z[ys.index(r[py]), xs.index(r[px])] = r[m]
    fig, ax = plt.subplots(figsize=(5, 4))
    im = ax.imshow(z, origin="lower", aspect="auto", cmap="viridis")
    ax.set(xticks=range(len(xs)), xticklabels=[f"{x:.3g}" for x in xs], xlabel=px,
           yticks=range(len(ys)), yticklabels=[f"{y:.3g}" for y in ys], ylabel=py,
           title=f"{sweep['scenario']['id']}-{sweep['boom']}: {m}")
    for (i, j), v in np.ndenumerate(z):
        if np.isfinite(v):
            ax.text(j, i, f"{v:.3g}", ha="center", va="center", color="w", fontsize=8)
    fig.colorbar(im, ax=ax, label=f"{m} [{DEFINITIONS[m][0]}]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
