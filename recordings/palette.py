"""The colour of each AGV, the same in every viewer: tab10, then it repeats."""

from __future__ import annotations

PALETTE = (
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)


def agv_color(index: int) -> tuple[int, int, int]:
    """The colour of the ``index``-th AGV met (0-based), as 0-255 RGB."""
    return PALETTE[index % len(PALETTE)]
