"""The viewer layout: a tab for the fleet, and a tab per AGV that follows it.

Fleet tab: the map, fitted to its panel, over the events; beside it the fleet as a
whole (``recordings.rerun_fleet``: AGVs driving, waiting, stopped; arrivals so far)
over the whole run, the time axis running past the end so that the legend (a corner
of the plot) sits beside the data, not on it. AGV tabs, one for every AGV: a view
centred on the AGV (its ``pose/follow`` frame) beside its own plots (|v|, ω, body-frame
vx and vy), each with a legend naming it. (Twenty AGVs' curves in one plot could not
be told apart, and Rerun's legend showed only the first ten.) A replay opens paused
at the start of the run (or playing it at a given rate); a live run follows the
latest data. Send it before the data: until a blueprint arrives the viewer lays out
views of its own guessing.
"""

from __future__ import annotations

import rerun.blueprint as rrb

from recordings.rerun_fleet import ARRIVED_PLOT, STATE_PLOT
from recordings.rerun_rows import EVENTS, TIMELINE, WORLD, agv_path, velocity_path

FLEET_PLOTS = ((STATE_PLOT, "AGVs driving / waiting / stopped"), (ARRIVED_PLOT, "AGVs arrived"))
AGV_PLOTS = (
    ("speed", "|v| (m/s)"),
    ("omega", "ω (rad/s)"),
    ("vx", "vx (m/s, body frame: forward)"),
    ("vy", "vy (m/s, body frame: left)"),
)
FOLLOW_HALF_SIZE = (6.0, 4.0)  # m around the followed AGV
MAP_MARGIN = 0.05  # of the map's larger side, around the fitted map
LEGEND_ROOM = 0.3  # of the run's duration, after its end: where the legend goes

Bounds = tuple[float, float, float, float]

# a trail is one segment per tick: show every segment up to the time cursor
_HISTORY = rrb.VisibleTimeRanges(
    timeline=TIMELINE,
    start=rrb.TimeRangeBoundary.infinite(),
    end=rrb.TimeRangeBoundary.cursor_relative(),
)


def blueprint(
    agv_names: list[str],
    map_bounds: Bounds | None = None,
    end_time: float | None = None,
    *,
    follow: str | None = None,
    rate: float | None = None,
) -> rrb.Blueprint:
    """``map_bounds`` (x0, y0, x1, y1 in m) fits the map view; ``end_time`` (s: a
    whole recording) makes the plots show the whole run and the viewer open paused
    at its start (playing at ``rate`` x real time, if given); ``follow`` (an AGV's
    name) opens on that AGV's tab."""
    shown = [n for n in agv_names if n != follow]
    if follow is not None:
        shown.insert(0, follow)
    tabs = [_fleet_tab(agv_names, map_bounds, end_time)]
    tabs += [_agv_tab(n, agv_names, end_time) for n in shown]
    return rrb.Blueprint(
        rrb.Tabs(*tabs, active_tab=1 if follow is not None else 0),
        _time_panel(end_time, rate),
        collapse_panels=True,
    )


def _fleet_tab(agv_names: list[str], map_bounds: Bounds | None, end_time: float | None):
    # The map view's origin is the root, not `world`: a view ignores the transform of
    # its own origin, and `world` holds the y flip.
    map_view = rrb.Spatial2DView(
        name="map",
        origin="/",
        contents=f"+ /{WORLD}/**",
        overrides={f"/{agv_path(n, 'trail')}": _HISTORY for n in agv_names},
        visual_bounds=None if map_bounds is None else _fit(map_bounds),
    )
    events = rrb.TextLogView(
        name="events",
        origin=f"/{EVENTS}",
        columns=rrb.TextLogColumns(
            text_log_columns=[
                rrb.encodings.TextLogColumn("LogLevel"),
                rrb.encodings.TextLogColumn("Body"),
                rrb.encodings.TextLogColumn("EntityPath", visible=False),
            ]
        ),
    )
    plots = [
        rrb.TimeSeriesView(
            name=title,
            origin=f"/{path}",
            axis_x=_whole_run(end_time, LEGEND_ROOM),
            plot_legend=_legend(end_time),
        )
        for path, title in FLEET_PLOTS
    ]
    return rrb.Horizontal(
        rrb.Vertical(map_view, events, row_shares=[3, 1]),
        rrb.Vertical(*plots),
        column_shares=[3, 2],
        name="fleet",
    )


def _agv_tab(name: str, agv_names: list[str], end_time: float | None):
    w, h = FOLLOW_HALF_SIZE
    follow = rrb.Spatial2DView(
        name=f"following {name}",
        origin=f"/{agv_path(name, 'pose/follow')}",
        contents=f"+ /{WORLD}/**",
        visual_bounds=rrb.VisualBounds2D(x_range=[-w, w], y_range=[-h, h]),
        overrides={f"/{agv_path(n, 'trail')}": _HISTORY for n in agv_names},
    )
    plots = [
        rrb.TimeSeriesView(
            name=f"{name} {title}",
            origin=f"/{velocity_path(q, name)}",
            axis_x=_whole_run(end_time, LEGEND_ROOM),
            plot_legend=_legend(end_time),
        )
        for q, title in AGV_PLOTS
    ]
    return rrb.Horizontal(follow, rrb.Vertical(*plots), column_shares=[3, 2], name=name)


def _legend(end_time: float | None) -> rrb.PlotLegend:
    """Beside the data: right of a whole run (its axis runs past the end), left while live."""
    return rrb.PlotLegend("RightTop" if end_time else "LeftTop")


def _time_panel(end_time: float | None, rate: float | None) -> rrb.TimePanel:
    if not end_time:
        return rrb.TimePanel(timeline=TIMELINE, play_state="following")
    if rate is not None:
        return rrb.TimePanel(timeline=TIMELINE, play_state="playing", playback_speed=rate)
    return rrb.TimePanel(timeline=TIMELINE, play_state="paused")


def _fit(bounds: Bounds) -> rrb.VisualBounds2D:
    """The map with a margin, in the root's coordinates (y flipped by ``world``)."""
    x0, y0, x1, y1 = bounds
    pad = MAP_MARGIN * max(x1 - x0, y1 - y0)
    return rrb.VisualBounds2D(x_range=[x0 - pad, x1 + pad], y_range=[-y1 - pad, -y0 + pad])


def _whole_run(end_time: float | None, room: float) -> rrb.TimeAxis | None:
    """A time axis from 0 to the end of the run and ``room`` x its duration more
    (None while the run goes on: the plot then follows the data)."""
    if not end_time:
        return None
    end = rrb.TimeRangeBoundary.absolute(seconds=end_time * (1.0 + room))
    return rrb.TimeAxis(
        view_range=rrb.TimeRange(start=rrb.TimeRangeBoundary.absolute(seconds=0.0), end=end)
    )
