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
    ax.set_xlabel("x (m)", fontsize="x-small")
    ax.set_ylabel("y (m)", fontsize="x-small")


def _legend_below(figure: Figure, axes) -> None:
    """One legend for every panel, under them: off the maps and the curves."""
    entries: dict[str, object] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    if entries:
        figure.legend(
            list(entries.values()), list(entries), loc="lower center",
            ncol=min(len(entries), 3), fontsize="small", frameon=False,
        )  # fmt: skip
        lines = math.ceil(len(entries) / 3)  # a legend line is about 0.25 in high
        bottom = min(0.4, (0.25 * lines + 0.2) / figure.get_figheight())
        figure.tight_layout(rect=(0, bottom, 1, 0.97))  # room for the panels' titles
    else:
        figure.tight_layout()


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
    _legend_below(figure, axes)
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
        ax.set_xlabel("A* variant, over the seeded maps", fontsize="x-small")
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
            track = mov["x"][:, m], mov["y"][:, m]
            ax.plot(*track, color="tab:gray", lw=1.0, ls="--", label="moving obstacle's track")
        cols = series.agvs.columns
        for i, name in enumerate(series.agvs.names):
            first = next((p for p in series.plans.get(name, []) if p.get("found")), None)
            if first is not None:
                nodes = np.asarray(first["key_nodes"], dtype=float).reshape(-1, 2)
                ax.plot(nodes[:, 0], nodes[:, 1], "k:", lw=1.0, label="first global plan")
                ax.plot(nodes[:, 0], nodes[:, 1], "o", mfc="none", mec="k", ms=4, label="key nodes")
            x, y = cols["x"][:, i], cols["y"][:, i]
            ax.plot(x, y, color="tab:red", lw=1.5, label="driven trajectory")
            if len(x):
                ax.plot(x[0], y[0], "^", color="tab:blue", ms=6, label="start")
        ax.set_title(title, fontsize="small")
    _legend_below(figure, axes)
    return save_figure(figure, path, DPI)


def velocity_figure(runs: Sequence[RunSeries], labels: Sequence[str], path: Path) -> Path:
    """v(t) and ω(t) of the first AGV of each run, overlaid (the paper's Fig. 11)."""
    figure = Figure(figsize=(8.2, 4.2))
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
    speed_ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    figure.tight_layout()  # the legend right of the curves: it covers none of them
    return save_figure(figure, path, DPI)


def changes_figure(
    changes: dict[str, list[float]], paper: dict[str, float | None], title: str, path: Path
) -> Path:
    """One box per effect: our % changes (one per walker timing, as dots) with the paper's
    value marked (an effect the paper shows only in a figure has none)."""
    figure = Figure(figsize=(max(6.0, 1.6 * len(changes) + 2.5), 4.2))
    ax = figure.add_subplot()
    names = list(changes)
    ax.boxplot([changes[n] or [math.nan] for n in names], widths=0.5, showmeans=True)
    labels = {"ours": "ours, one walker timing each", "paper": "the paper's value"}
    for i, name in enumerate(names, 1):
        values = changes[name]
        ax.plot([i] * len(values), values, ".", color="tab:blue", alpha=0.5, ms=5,
                label=labels.pop("ours", None))  # fmt: skip
        if paper.get(name) is not None:
            ax.plot(i, paper[name], "x", color="tab:red", ms=10, mew=2.5,
                    label=labels.pop("paper", None))  # fmt: skip
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(range(1, len(names) + 1), names, fontsize="small")
    ax.set_ylabel("change, fusion vs astar-dwa (%)")
    ax.set_xlabel("effect (box: quartiles, line: median, ▲: mean)")
    ax.set_title(title, fontsize="small")
    ax.grid(True, axis="y", lw=0.4, alpha=0.6)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    figure.tight_layout()
    return save_figure(figure, path, DPI)
