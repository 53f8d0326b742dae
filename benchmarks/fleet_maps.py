"""The warehouses of ``fleet_bench``: a sparse and a dense map for 50 to 200 AGVs.

Shelf rows two metres deep run across the middle of the map with cross aisles; the
AGVs start in dock columns along both short sides (nearest the edge first, spread over
the whole height) and cross to the mirrored dock on the other side, so the fleet meets
in the aisles. 1 m cells.
"""

from __future__ import annotations

from dataclasses import dataclass

EDGE = 8  # m of open floor on each short side (the docks)
DOCK_COLUMNS = (1.0, 2.5, 4.0, 5.5)  # m from the edge
DOCK_PITCH = 1.5  # m between docks along the edge


@dataclass(frozen=True)
class Layout:
    width: int  # m
    height: int  # m
    row_pitch: int  # m from one shelf row to the next (rows are 2 m deep)
    cross_pitch: int  # m from one cross aisle to the next
    cross_width: int  # m

    def grid(self) -> str:
        rows = [["."] * self.width for _ in range(self.height)]  # rows[0] is the bottom row
        for y0 in range(self.row_pitch, self.height - self.row_pitch + 1, self.row_pitch):
            for y in (y0, y0 + 1):
                for x in range(EDGE, self.width - EDGE):
                    if (x - EDGE) % self.cross_pitch < self.cross_pitch - self.cross_width:
                        rows[y][x] = "#"
        return "\n".join("".join(r) for r in reversed(rows))

    def docks(self) -> list[tuple[float, float]]:
        count = int((self.height - 2) / DOCK_PITCH) + 1
        return [(x, 1.0 + DOCK_PITCH * i) for x in DOCK_COLUMNS for i in range(count)]


LAYOUTS = {
    "sparse": Layout(128, 80, row_pitch=8, cross_pitch=16, cross_width=4),
    "dense": Layout(64, 40, row_pitch=5, cross_pitch=12, cross_width=3),
}


def scenario_text(layout_name: str, agvs: int, sim_time: float) -> str:
    """A scenario of ``agvs`` AGVs on the named layout, cut at ``sim_time`` s."""
    layout = LAYOUTS[layout_name]
    docks = layout.docks()
    if agvs > 2 * len(docks):
        raise ValueError(f"the {layout_name} map has docks for {2 * len(docks)} AGVs")
    w, h = layout.width, layout.height
    lines = [
        f'name = "bench-{layout_name}-{agvs}"',
        f"time_limit = {sim_time}",
        "[map]",
        f'grid = """\n{layout.grid()}\n"""',
    ]
    for i in range(agvs):
        x, y = docks[i // 2]
        start, goal = ((x, y), (w - x, h - y)) if i % 2 == 0 else ((w - x, y), (x, h - y))
        lines += [
            "[[agvs]]",
            f'name = "agv{i + 1}"',
            f"start = [{start[0]}, {start[1]}]",
            f"goal = [{goal[0]}, {goal[1]}]",
            f"heading = {0 if i % 2 == 0 else 180}",
        ]
    return "\n".join(lines) + "\n"


WAREHOUSE_60X40 = (60, 40)


def warehouse_text(agvs: int, sim_time: float) -> str:
    """The 60 x 40 m warehouse of earlier rounds (3 m aisles, docks 2 m apart), which
    ``fingerprint.py`` hashes and ``cold_step.py`` steps: kept byte for byte."""
    width, height = WAREHOUSE_60X40
    rows = [["."] * width for _ in range(height)]  # rows[0] is the bottom row
    for y0 in range(5, height - 5, 5):
        for y in (y0, y0 + 1):
            for x in range(8, width - 8):
                if (x - 8) % 12 not in (9, 10, 11):  # cross aisles every 12 m
                    rows[y][x] = "#"
    grid = "\n".join("".join(r) for r in reversed(rows))
    docks = [(x + 0.5, y + 0.5) for y in range(1, height - 1, 2) for x in (1, 3, 5)]
    lines = [
        f'name = "bench-warehouse-{agvs}"',
        f"time_limit = {sim_time}",
        "[map]",
        f'grid = """\n{grid}\n"""',
    ]
    for i in range(agvs):
        x, y = docks[(i // 2) % len(docks)]
        start, goal = (
            ((x, y), (width - x, height - y)) if i % 2 == 0 else ((width - x, y), (x, height - y))
        )
        lines += [
            "[[agvs]]",
            f'name = "agv{i + 1}"',
            f"start = [{start[0]}, {start[1]}]",
            f"goal = [{goal[0]}, {goal[1]}]",
            f"heading = {0 if i % 2 == 0 else 180}",
        ]
    return "\n".join(lines) + "\n"
