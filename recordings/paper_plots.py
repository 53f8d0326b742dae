"""Small PNG figures for ``agv-fleet paper``, drawn from recordings read back:
global plans on their maps (Figs. 6/7), trajectories (Figs. 8-10), v(t) and ω(t)
(Fig. 11) and the 50x50 spread. Matplotlib's object API on the Agg canvas."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from planner.core.motion import world_velocity
from planner.maps.grid import GridMap
from recordings.plan_metrics import MapPlans
from recordings.plots import draw_map, draw_temporary_cells, save_figure
from recordings.series import RunSeries

DPI = 80
PLAN_STYLE = {"traditional": ("tab:red", "--"), "improved": ("tab:blue", "-")}
ALGORITHM_COLOUR = {"fusion": "tab:blue", "astar-dwa": "tab:red", "dwa": "tab:green"}


def _panels(count: int, columns: int, size: float = 3.0):
    rows = math.ceil(count / columns)
    cols = min(columns, count)
    figure = Figure(figsize=(size * cols, size * rows + 0.3))
    axes = figure.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[count:]:
        ax.set_axis_off()
    return figure, axes[:count]


def _draw_map(ax, grid: GridMap | None) -> None:
    if grid is None:
        return
    draw_map(ax, grid)
    ax.tick_params(labelsize="x-small")


def plans_figure(
    maps: Sequence[MapPlans], titles: Sequence[str], path: Path, columns=5, size: float = 3.0
) -> Path:
    """Each map with the traditional (dashed red) and improved (solid blue) key-node paths
    (``size``: inches per panel)."""
    figure, axes = _panels(len(maps), columns, size)
    for ax, plans, title in zip(axes, maps, titles, strict=True):
        _draw_map(ax, plans.grid)
        for algorithm, plan in plans.plans.items():
            if not plan.found:
                continue
            colour, style = PLAN_STYLE.get(algorithm, ("k", "-"))
            nodes = np.asarray(plan.key_nodes)
            ax.plot(nodes[:, 0], nodes[:, 1], color=colour, ls=style, lw=1.3, label=algorithm)
            ax.plot(nodes[:, 0], nodes[:, 1], ".", color=colour, ms=4)
        ax.set_title(title, fontsize="small")
    axes[0].legend(fontsize="x-small", loc="lower right")
    figure.tight_layout()
    return save_figure(figure, path, DPI)


def spread_figure(values: dict[str, dict[str, list[float]]], labels: dict[str, str], path: Path):
    """Box plots per metric of the traditional and improved values over the seeded maps.
    ``values[metric][algorithm]`` lists one value per map."""
    figure, axes = _panels(len(values), len(values), size=2.6)
    for ax, (metric, per_algorithm) in zip(axes, values.items(), strict=True):
        names = list(per_algorithm)
        ax.boxplot([per_algorithm[n] for n in names], widths=0.5)
        ax.set_xticks(range(1, len(names) + 1), names, fontsize="small")
        ax.set_title(labels.get(metric, metric), fontsize="small")
        ax.tick_params(labelsize="x-small")
        ax.grid(True, axis="y", lw=0.4, alpha=0.6)
    figure.tight_layout()
    return save_figure(figure, path, DPI)


def trajectories_figure(
    runs: Sequence[RunSeries], titles: Sequence[str], path: Path, columns: int = 4
) -> Path:
    """One panel per run: map, temporary obstacles (orange), moving obstacles (grey
    dashed), the first global plan (dotted, key nodes o) and the driven trajectory."""
    figure, axes = _panels(len(runs), columns, size=3.4)
    for ax, series, title in zip(axes, runs, titles, strict=True):
        _draw_map(ax, series.grid)
        draw_temporary_cells(ax, series)
        mov = series.moving.columns
        for m in range(len(series.moving.names)):
            ax.plot(mov["x"][:, m], mov["y"][:, m], color="tab:gray", lw=1.0, ls="--")
        cols = series.agvs.columns
        for i, name in enumerate(series.agvs.names):
            first = next((p for p in series.plans.get(name, []) if p.get("found")), None)
            if first is not None:
                nodes = np.asarray(first["key_nodes"], dtype=float).reshape(-1, 2)
                ax.plot(nodes[:, 0], nodes[:, 1], "k:", lw=1.0)
                ax.plot(nodes[:, 0], nodes[:, 1], "o", mfc="none", mec="k", ms=4)
            x, y = cols["x"][:, i], cols["y"][:, i]
            ax.plot(x, y, color="tab:red", lw=1.5)
            if len(x):
                ax.plot(x[0], y[0], "^", color="tab:blue", ms=6)
        ax.set_title(title, fontsize="small")
    figure.tight_layout()
    return save_figure(figure, path, DPI)


def velocity_figure(runs: Sequence[RunSeries], labels: Sequence[str], path: Path) -> Path:
    """v(t) and ω(t) of the first AGV of each run, overlaid (the paper's Fig. 11)."""
    figure = Figure(figsize=(7.0, 4.2))
    speed_ax, omega_ax = figure.subplots(2, 1, sharex=True)
    for n, (series, label) in enumerate(zip(runs, labels, strict=True)):
        c = {f: v[:, 0] for f, v in series.agvs.columns.items()}
        colour = ALGORITHM_COLOUR.get(label, f"C{n}")
        if series.dt is not None:
            v = world_velocity(c["theta"], c["vx"], c["vy"], c["omega"], series.dt)
            speed_ax.plot(
                series.time, np.hypot(v[:, 0], v[:, 1]), color=colour, lw=1.0, label=label
            )
        omega_ax.plot(series.time, np.degrees(c["omega"]), color=colour, lw=1.0, label=label)
    speed_ax.set_ylabel("v (m/s)")
    omega_ax.set_ylabel("ω (°/s)")
    omega_ax.set_xlabel("sim time (s)")
    for ax in (speed_ax, omega_ax):
        ax.grid(True, lw=0.4, alpha=0.6)
        ax.legend(fontsize="x-small", loc="upper right")
    figure.tight_layout()
    return save_figure(figure, path, DPI)
