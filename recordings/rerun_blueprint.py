"""The viewer layout: the 2-D map beside the velocity plots, events under the map."""

from __future__ import annotations

import rerun.blueprint as rrb

from recordings.rerun_rows import EVENTS, TIMELINE, VELOCITY, WORLD, agv_path

PLOTS = (
    ("speed", "|v| (m/s)"),
    ("omega", "ω (rad/s)"),
    ("vx", "vx (m/s, body frame)"),
    ("vy", "vy (m/s, body frame)"),
)


def blueprint(agv_names: list[str]) -> rrb.Blueprint:
    # The map view's origin is the root, not `world`: a view ignores the transform of
    # its own origin, and `world` holds the y flip.
    whole_history = rrb.VisibleTimeRanges(
        timeline=TIMELINE,
        start=rrb.TimeRangeBoundary.infinite(),
        end=rrb.TimeRangeBoundary.cursor_relative(),
    )
    map_view = rrb.Spatial2DView(
        name="map",
        origin="/",
        contents=f"+ /{WORLD}/**",
        overrides={f"/{agv_path(n, 'trail')}": whole_history for n in agv_names},
    )
    events = rrb.TextLogView(name="events", origin=f"/{EVENTS}")
    plots = [rrb.TimeSeriesView(name=title, origin=f"/{VELOCITY}/{q}") for q, title in PLOTS]
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(map_view, events, row_shares=[4, 1]),
            rrb.Vertical(*plots),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=TIMELINE),
        collapse_panels=True,
    )
