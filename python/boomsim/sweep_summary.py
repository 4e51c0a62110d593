"""The outputs of a sweep (python/boomsim/parameter_sweep.py): DIR/summary.md (points, failures, the metrics'
min / median / max over the points that ran) and maps of p3_pp_late and t_settle (else the first
metric) over two grid parameters, DIR/map-<metric>.png: over (n_K, n_omega) when both are grids,
else over the first two parameters that vary on a grid.

A cell of a map holds the worst value (the largest; "not settled" for t_settle when any point
has none; blank when any point failed) over the points that share its two values and its panel:
one panel per value of the next one or two varying grid parameters (e.g. cbv.mu_p, payload.m),
any further parameter and the Monte Carlo draws within the cell. Over (n_K, n_omega), with
t_settle among the metrics, the summary also gives
- the region where every point settles: the cells whose points all ran and have a settling time,
  in every panel;
- the recommended filter: the cell of that region farthest from the nearest grid cell outside it,
  the distance measured in log factors, sqrt(ln(n_K/n_K')^2 + ln(n_omega/n_omega')^2), and
  written as the factor exp(distance); ties go to the smaller worst settling time;
- the linear analysis' stability boundary (`boomsim analyze`, every pole of eq. 6.8 in the left
  half plane) at each panel's operating point, drawn over the maps, and the grid cells where the
  linear and the nonlinear verdicts differ."""

from __future__ import annotations

import itertools
import math
import pathlib
import textwrap

import numpy as np

from .fmus import FmuFile
from . import figures
from . import linear
from .metrics import DEFINITIONS

#: The maps' metrics, when the sweep has them.
MAPPED = ("p3_pp_late", "t_settle")
#: Points of the linear analysis' boundary along each axis (log-spaced over the grid's range).
FINE = 48


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
            f"- {', '.join(f'{p} = {r[p]:g}' for p in sweep['parameters'])}: {r['error']}" for r in failed[:20]]
        lines += [f"- and {len(failed) - 20} more (the Parquet rows have every one)"] if len(failed) > 20 else []
    axes = map_axes(sweep)
    if axes:
        lines += maps(sweep, rows, axes, out)
    (out / "summary.md").write_text("\n".join(lines) + "\n")


def map_axes(sweep: dict) -> list[str] | None:
    varying = [p for p, g in sweep["grids"].items() if len(g) > 1]
    if all(f in varying for f in ("n_K", "n_omega")):
        return ["n_K", "n_omega"]
    return varying[:2] if len(varying) >= 2 else None


class Grid:
    """The sweep's rows as cells over the two axes and the panels of up to two further varying
    grid parameters."""

    def __init__(self, sweep: dict, rows: list[dict], axes: list[str]):
        self.axes = axes
        self.xs, self.ys = (sorted(set(sweep["grids"][a])) for a in axes)
        self.panel_params = [p for p, g in sweep["grids"].items() if len(g) > 1 and p not in axes][:2]
        self.panel_values = [sorted(set(sweep["grids"][p])) for p in self.panel_params]
        self.panels = list(itertools.product(*self.panel_values))
        self.cells: dict[tuple, list[dict]] = {}
        for r in rows:
            key = (tuple(r[p] for p in self.panel_params), self.xs.index(r[axes[0]]), self.ys.index(r[axes[1]]))
            self.cells.setdefault(key, []).append(r)
        self.expected = len(sweep["points"]) // (len(self.xs) * len(self.ys) * max(1, len(self.panels)))

    def worst(self, metric: str, panel: tuple) -> np.ndarray:
        """[y, x] the largest value of the cell's points; nan: a point failed or is missing;
        inf: a point has no value (t_settle: not settled)."""
        z = np.full((len(self.ys), len(self.xs)), np.nan)
        for (i, j) in np.ndindex(z.shape):
            rs = self.cells.get((panel, j, i), [])
            if len(rs) == self.expected and all(r["status"] == "ok" for r in rs):
                z[i, j] = max(math.inf if r[metric] is None else r[metric] for r in rs)
        return z

    def label(self, panel: tuple) -> str:
        return ", ".join(f"{p} = {v:g}" for p, v in zip(self.panel_params, panel)) or "every point"


def settle_region(grid: Grid) -> np.ndarray:
    """[y, x] True where every point of every panel ran and settled."""
    return np.logical_and.reduce([np.isfinite(grid.worst("t_settle", p)) for p in grid.panels])


def recommend(xs: list[float], ys: list[float], region: np.ndarray, t_settle: np.ndarray):
    """(i, j, distance) of the cell of `region` farthest from the cells outside it in log
    factors (inf when every cell is inside), ties to the smaller `t_settle`; None if the region
    is empty."""
    lx, ly = np.log(xs), np.log(ys)
    outside = [(ly[i], lx[j]) for i, j in zip(*np.nonzero(~region))]
    best = None
    for i, j in zip(*np.nonzero(region)):
        d = min((math.hypot(ly[i] - a, lx[j] - b) for a, b in outside), default=math.inf)
        key = (-round(d, 9), t_settle[i, j])
        if best is None or key < best[0]:
            best = (key, (int(i), int(j), d))
    return best and best[1]


def linear_stability(sweep: dict, grid: Grid, panel: tuple, xs, ys) -> list[tuple[dict, np.ndarray]]:
    """(operating point, [y, x] stable) of the linear analysis for every distinct operating
    point of the panel's points (several when e.g. the stroke varies within the panel)."""
    ops = {tuple(linear.operating_point(sweep, r).items())
           for (pn, _, _), rs in grid.cells.items() if pn == panel for r in rs}
    result = []
    for op in sorted(ops):
        j = linear.analyze(op, tuple(float(x) for x in xs), tuple(float(y) for y in ys))
        stable = np.array([f["stable"] for f in j["filters"]], dtype=bool).reshape(len(xs), len(ys)).T
        result.append((dict(op), stable))
    return result


def edges(v: list[float]) -> np.ndarray:
    """Cell edges of log-spaced centres: geometric midpoints, the ends mirrored."""
    v = np.asarray(v, dtype=float)
    if len(v) == 1:
        return np.array([v[0] / 1.5, v[0] * 1.5])
    mid = np.sqrt(v[1:] * v[:-1])
    return np.concatenate([[v[0] ** 2 / mid[0]], mid, [v[-1] ** 2 / mid[-1]]])


def maps(sweep: dict, rows: list[dict], axes: list[str], out: pathlib.Path) -> list[str]:
    import matplotlib.pyplot as plt

    grid = Grid(sweep, rows, axes)
    factors = axes == ["n_K", "n_omega"]
    region = rec = fine_xy = None
    lines = []
    if factors and "t_settle" in sweep["metrics"]:
        region = settle_region(grid)
        ts_worst = np.nanmax([np.where(np.isfinite(z), z, np.inf) for z in
                              (grid.worst("t_settle", p) for p in grid.panels)], axis=0)
        rec = recommend(grid.xs, grid.ys, region, ts_worst)
        lines += ["", "## Where every point settles", "",
                  f"{int(region.sum())} of {region.size} ({axes[0]}, {axes[1]}) grid cells settle at every point "
                  f"({grid.expected * len(grid.panels)} points per cell: {', '.join(grid.panel_params) or 'no panel parameter'} "
                  "and any further parameter or draw)."]
        if rec is None:
            lines += ["", "No grid cell settles at every point: no recommendation."]
        else:
            i, j, d = rec
            far = (f"{d:.3f} in log factor (a factor {math.exp(d):.3g}) from the nearest grid cell that does not"
                   if math.isfinite(d) else "inside the grid's whole extent: every cell settles, the boundary is "
                   "outside the grid")
            lines += ["", f"Recommended filter: **n_K = {grid.xs[j]:g}, n_omega = {grid.ys[i]:g}**, {far}; "
                      f"worst settling time {ts_worst[i, j]:.3g} s" + (
                          f", worst p3_pp_late {np.nanmax([grid.worst('p3_pp_late', p)[i, j] for p in grid.panels]):.3g} bar"
                          if "p3_pp_late" in sweep["metrics"] else "") + "."]
            lines += [f"- {grid.label(p)}: K_f = {r['K_f']:.4g} m^3/Pa, omega_f = {r['omega_f']:.4g} rad/s"
                      for p in grid.panels for r in grid.cells.get((p, j, i), [])[:1] if "K_f" in r and "omega_f" in r]
    linear = {}
    if factors:
        fx, fy = (np.geomspace(min(v) / 1.2, max(v) * 1.2, FINE) for v in (grid.xs, grid.ys))
        lines += ["", "## The linear analysis", "",
                  "Stable: every pole of the closed loop of eq. 6.8 (`boomsim analyze`) in the left half plane, "
                  "at the panel's operating point (stroke start.x, the final reference's flow). The maps draw its "
                  "boundary (white dashed line); "
                  "the table counts the grid cells where it and the co-simulation (settles) differ.", "",
                  "| panel | operating point | linear stable, not settled | settled, linear unstable |", "|---|---|---|---|"]
        for p in grid.panels:
            settled = np.isfinite(grid.worst("t_settle", p)) if "t_settle" in sweep["metrics"] else None
            linear[p] = linear_stability(sweep, grid, p, fx, fy)
            for op, coarse in linear_stability(sweep, grid, p, grid.xs, grid.ys):
                desc = ", ".join(f"{k} {v:.4g}" for k, v in op.items())
                a, b = (("-", "-") if settled is None else
                        (int((coarse & ~settled).sum()), int((settled & ~coarse).sum())))
                lines.append(f"| {grid.label(p)} | {desc} | {a} | {b} |")
        fine_xy = (fx, fy)
    for m in [m for m in MAPPED if m in sweep["metrics"]] or sweep["metrics"][:1]:
        path = out / f"map-{m}.png"
        draw(sweep, grid, m, region, rec, linear, fine_xy, path, plt)
        lines += ["", f"![{m}]({path.name})"]
    return lines


def outline(ax, region: np.ndarray, ex: np.ndarray, ey: np.ndarray):
    """The cell edges between the region's cells and the others (or the grid's border)."""
    inside = np.pad(region, 1)
    for i, j in zip(*np.nonzero(region)):
        for di, dj, xs, ys in ((-1, 0, ex[j:j + 2], [ey[i]] * 2), (1, 0, ex[j:j + 2], [ey[i + 1]] * 2),
                               (0, -1, [ex[j]] * 2, ey[i:i + 2]), (0, 1, [ex[j + 1]] * 2, ey[i:i + 2])):
            if not inside[i + 1 + di, j + 1 + dj]:
                ax.plot(xs, ys, color="r", lw=1.5)


def axis_label(name: str) -> str:
    """A swept parameter with its unit: the FMUs' declared one, "-" for the filter factors n_K,
    n_omega and a dimensionless parameter, seconds for the communication step."""
    if name == "step":
        return "communication step [s]"
    for identifier in ("HydraulicBoom", "PressureFeedbackController"):
        v = FmuFile.get(identifier).vars.get(name)
        if v is not None:
            return f"{name} [{v.unit if v.unit not in (None, '', '1') else '-'}]"
    return f"{name} [-]"


def draw(sweep, grid: Grid, m: str, region, rec, linear: dict, fine_xy, path: pathlib.Path, plt):
    """One panel per panel value: the metric's worst value per cell (grey: not settled, white:
    failed), the settle region's cells outlined, the recommendation starred, the linear
    boundary drawn."""
    nr, nc = (len(grid.panel_values[1]) if len(grid.panel_values) > 1 else 1,
              len(grid.panel_values[0]) if grid.panel_values else 1)
    width = 3.6 * nc + 1.6
    fig, axs = plt.subplots(nr, nc, figsize=(width, 3.2 * nr + 1.2), squeeze=False, sharex=True, sharey=True,
                            layout="constrained")
    zs = [grid.worst(m, p) for p in grid.panels]
    finite = np.concatenate([z[np.isfinite(z)] for z in zs]) if zs else np.array([])
    vmin, vmax = (finite.min(), finite.max()) if len(finite) else (0.0, 1.0)
    cmap = plt.get_cmap("viridis").with_extremes(over="0.6")
    log = grid.axes == ["n_K", "n_omega"] or all(min(v) > 0 for v in (grid.xs, grid.ys))
    ex, ey = (edges(v) if log else np.arange(len(v) + 1) - 0.5 for v in (grid.xs, grid.ys))
    im = None
    for k, p in enumerate(grid.panels):
        ax = axs[k // nc if len(grid.panel_values) > 1 else 0, k % nc]
        z = np.where(np.isinf(zs[k]), vmax * 2 + 1, zs[k])  # not settled: the "over" colour
        im = ax.pcolormesh(ex, ey, np.ma.masked_invalid(z), cmap=cmap, vmin=vmin, vmax=vmax)
        if region is not None:
            outline(ax, region, ex, ey)
        if rec is not None:
            ax.plot(grid.xs[rec[1]], grid.ys[rec[0]], "*", color="r", ms=12, mec="w")
        for op, stable in linear.get(p, []):
            ax.contour(*fine_xy, stable.astype(float), [0.5], colors="w", linewidths=1.5, linestyles="--")
        if log:
            ax.set(xscale="log", yscale="log")
        else:
            ax.set(xticks=range(len(grid.xs)), xticklabels=[f"{x:.3g}" for x in grid.xs],
                   yticks=range(len(grid.ys)), yticklabels=[f"{y:.3g}" for y in grid.ys])
        ax.set_title(grid.label(p), fontsize=9)
    for ax in axs[-1]:
        ax.set_xlabel(axis_label(grid.axes[0]))
    for ax in axs[:, 0]:
        ax.set_ylabel(axis_label(grid.axes[1]))
    drawn = [(True, "grey: not settled"), (region is not None and region.any(), "red outline: every point settles"),
             (rec is not None, "star: recommended"),
             (any(linear.get(p) for p in grid.panels), "white dashed: linear boundary")]
    key = "; ".join(what for shown, what in drawn if shown)  # only what the panels show
    # About 15 characters of 8 pt text per inch of width.
    fig.suptitle(f"{sweep['scenario']['id']}-{sweep['boom']}, {sweep['stop_time']:g} s: worst {m}\n"
                 + textwrap.fill(key, int(15 * width)), fontsize=8)
    fig.colorbar(im, ax=axs, label=f"{m} [{DEFINITIONS[m][0]}]")
    figures.save(fig, path, dpi=90)
    plt.close(fig)
