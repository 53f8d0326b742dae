"""PNG plots of a run: the map with trajectories (the paper's Fig. 10) and v(t), ω(t)
per AGV (Fig. 11). Matplotlib's object API with the Agg canvas: no pyplot, no
global backend, nothing needs a display."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from matplotlib.patheffects import withStroke

from planner.core.motion import world_velocity
from planner.core.path_metrics import crossing_points
from planner.maps.grid import GridMap
from recordings.series import RunSeries

DPI = 100
LEGEND_MAX = 12  # more AGVs than this: no legend, it would cover the map


def save_plots(series: RunSeries, out_dir: Path, stem: str, label: str) -> list[Path]:
    """Write ``<stem>-map.png`` and ``<stem>-velocity-<agv>.png`` into ``out_dir``,
    titled with ``label`` (scenario and algorithm: which run it is)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [save_figure(map_figure(series, label), out_dir / f"{stem}-map.png", DPI)]
    for i, name in enumerate(series.agvs.names):
        figure = _velocity_figure(series, i, label)
        paths.append(save_figure(figure, out_dir / f"{stem}-velocity-{name}.png", DPI))
    return paths


def save_figure(figure: Figure, path: Path, dpi: int) -> Path:
    """``figure`` as an optimised PNG at ``path`` (its folder made if missing)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    FigureCanvasAgg(figure)
    figure.savefig(path, dpi=dpi, pil_kwargs={"optimize": True})
    return path


def draw_map(ax, grid: GridMap) -> None:
    """The map's obstacle cells in grey, the axes fitted to the map at equal scale."""
    x0, x1, y0, y1 = grid.extent
    ax.imshow(
        grid.blocked, origin="lower", extent=(x0, x1, y0, y1), cmap="Greys",
        vmin=0, vmax=1.4, interpolation="nearest",
    )  # fmt: skip
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")


def map_figure(series: RunSeries, label: str) -> Figure:
    """The map with each AGV's trajectory, first global path, key nodes and loops (the
    points where its track crossed itself, as ``analyze`` counts them)."""
    grid = series.grid
    width, height = grid.size_m if grid else (10.0, 10.0)
    x0, x1, y0, y1 = grid.extent if grid else (0.0, width, 0.0, height)
    scale = 8.0 / max(width, height)
    figure = Figure(figsize=(max(4.0, width * scale) + 2.5, max(3.0, height * scale) + 0.8))
    ax = figure.add_subplot()
    if grid is not None:
        draw_map(ax, grid)
        draw_temporary_cells(ax, series)
    mov = series.moving.columns
    for m in range(len(series.moving.names)):
        ax.plot(mov["x"][:, m], mov["y"][:, m], color="tab:gray", lw=0.8, ls="--")
    columns = series.agvs.columns
    for i, name in enumerate(series.agvs.names):
        colour = f"C{i % 10}"
        plans = series.plans.get(name, [])
        first = next((p for p in plans if p.get("found")), None)
        if first is not None:
            path = np.asarray(first["path"], dtype=float).reshape(-1, 2)
            nodes = np.asarray(first["key_nodes"], dtype=float).reshape(-1, 2)
            ax.plot(path[:, 0], path[:, 1], color=colour, lw=0.8, ls=":", alpha=0.8)
            ax.plot(nodes[:, 0], nodes[:, 1], "o", mfc="none", mec=colour, ms=5)
        x, y = columns["x"][:, i], columns["y"][:, i]
        ax.plot(x, y, color=colour, lw=1.6, label=name)
        if len(x):
            ax.plot(x[0], y[0], "s", color=colour, ms=5)
        track = np.column_stack((x, y))
        loops = crossing_points(track[np.isfinite(track).all(axis=1)])
        if len(loops):  # where the AGV looped: analyze's loops, each where it happened
            ax.plot(
                loops[:, 0], loops[:, 1], "x", color=colour, ms=10, mew=2.5, zorder=5,
                path_effects=[withStroke(linewidth=4.5, foreground="black")],
            )  # fmt: skip
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(
        f"{label}\ntrajectories (solid), first global path (dotted), key nodes (o), loops (x)"
    )
    if 0 < len(series.agvs.names) <= LEGEND_MAX:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    figure.tight_layout()
    return figure


def draw_temporary_cells(ax, series: RunSeries) -> None:
    """Every temporary obstacle cell shown during the run, as orange squares."""
    grid = series.grid
    if grid is None:
        return
    res = grid.resolution
    for col, row in sorted({c for shown in series.temporary for c in shown}):
        cx, cy = grid.centre_of((col, row))
        square = (cx - res / 2, cy - res / 2)
        ax.add_patch(Rectangle(square, res, res, color="tab:orange", alpha=0.8))


def _velocity_figure(series: RunSeries, i: int, label: str) -> Figure:
    c = {f: v[:, i] for f, v in series.agvs.columns.items()}
    t = series.time
    figure = Figure(figsize=(7.0, 4.5))
    speed_ax, omega_ax = figure.subplots(2, 1, sharex=True)
    if series.dt is not None:
        velocity = world_velocity(c["theta"], c["vx"], c["vy"], c["omega"], series.dt)
        speed_ax.plot(t, np.hypot(velocity[:, 0], velocity[:, 1]), color="tab:blue", lw=1.0)
    omega_ax.plot(t, c["omega"], color="tab:red", lw=1.0)
    speed_ax.set_ylabel("v (m/s)")
    omega_ax.set_ylabel("ω (rad/s)")
    omega_ax.set_xlabel("sim time (s)")
    speed_ax.set_title(f"{label}, {series.agvs.names[i]}: linear and angular velocity")
    for ax in (speed_ax, omega_ax):
        ax.grid(True, lw=0.4, alpha=0.6)
    figure.tight_layout()
    return figure
