"""ROS map_server maps: the yaml and its image, read as map_server reads them."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from planner.core.errors import MapError
from planner.maps.grid import GridMap
from planner.maps.map_files import read_text
from planner.maps.map_image import MapImage, read_map_image

ROS_MODES = ("trinary", "scale", "raw")


@dataclass(frozen=True)
class RosMapInfo:
    """The contents of a ROS map_server YAML file, ``image`` resolved against its folder.

    ``origin`` (x, y, yaw) is the pose of the image's bottom-left pixel in the ROS ``map``
    frame; load_ros_map makes (x, y) the GridMap's origin, so world coordinates are the
    ones a ROS user reads in RViz. A non-zero yaw is refused there (see ``check_yaw``).
    """

    image: Path
    resolution: float
    origin: tuple[float, float, float]
    occupied_thresh: float
    free_thresh: float
    negate: bool
    mode: str = "trinary"


def _number(value, key: str, path: Path) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise MapError(f"{path}: '{key}' must be a number, got {value!r}")
    return float(value)


def read_ros_map_info(yaml_path: str | os.PathLike) -> RosMapInfo:
    """Parse and check a ROS map_server YAML file (the image is not read)."""
    path = Path(yaml_path)
    try:
        doc = yaml.safe_load(read_text(path))
    except yaml.YAMLError as err:
        raise MapError(f"{path}: invalid YAML: {err}") from None
    if not isinstance(doc, dict):
        raise MapError(f"{path}: expected a YAML mapping of map_server keys")
    required = ("image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate")
    missing = [key for key in required if key not in doc]
    if missing:
        raise MapError(f"{path}: missing key(s): {', '.join(missing)}")
    if not isinstance(doc["image"], str) or not doc["image"]:
        raise MapError(f"{path}: 'image' must be a file name, got {doc['image']!r}")
    resolution = _number(doc["resolution"], "resolution", path)
    if resolution <= 0:
        raise MapError(f"{path}: 'resolution' must be positive, got {resolution:g}")
    origin = doc["origin"]
    if not isinstance(origin, list) or len(origin) != 3:
        raise MapError(f"{path}: 'origin' must be a list [x, y, yaw], got {origin!r}")
    origin = tuple(_number(value, "origin", path) for value in origin)
    occupied = _number(doc["occupied_thresh"], "occupied_thresh", path)
    free = _number(doc["free_thresh"], "free_thresh", path)
    if not 0 <= free <= occupied <= 1:
        raise MapError(
            f"{path}: need 0 <= free_thresh <= occupied_thresh <= 1, "
            f"got free_thresh {free:g} and occupied_thresh {occupied:g}"
        )
    if doc["negate"] not in (0, 1):  # also accepts YAML true/false
        raise MapError(f"{path}: 'negate' must be 0 or 1, got {doc['negate']!r}")
    mode = doc.get("mode", "trinary")
    if mode not in ROS_MODES:
        raise MapError(f"{path}: 'mode' must be one of {', '.join(ROS_MODES)}, got {mode!r}")
    image = path.parent / doc["image"]  # an absolute image path stays absolute
    return RosMapInfo(image, resolution, origin, occupied, free, bool(doc["negate"]), mode)


OCC_FREE, OCC_OCCUPIED, OCC_UNKNOWN = 0, 100, -1  # nav_msgs/OccupancyGrid values


def ros_occupancy(image: MapImage, info: RosMapInfo) -> np.ndarray:
    """The nav_msgs/OccupancyGrid values map_server publishes for this image (top row
    first): 0 free, 100 occupied, -1 unknown, 1-99 partly occupied (nav2_map_server's
    ``loadMapFromFile``).

    shade = the mean of the pixel's red, green and blue, and in trinary mode of its alpha
    too when the image has one, over their maximum; occupancy p = 1 - shade (shade if
    ``negate``). trinary: p > occupied_thresh occupied, p < free_thresh free, anything
    between unknown. scale: a pixel not fully opaque is unknown; otherwise the same, but
    between the thresholds p is scaled linearly to 1-99. raw: the value is
    round(shade * 255) - the occupancy in percent, ``negate`` not applied, as map_server
    does - and above 100 unknown.
    """
    with_alpha = info.mode == "trinary" and image.alpha is not None
    if with_alpha:
        shade = (image.colour_sum + image.alpha) / 4 / image.maxval
    else:
        shade = image.colour_sum / 3 / image.maxval
    if info.mode == "raw":
        percent = np.rint(shade * 255).astype(np.int16)
        return np.where(percent <= OCC_OCCUPIED, percent, OCC_UNKNOWN).astype(np.int8)
    occ = shade if info.negate else 1.0 - shade
    out = np.full(shade.shape, OCC_UNKNOWN, dtype=np.int8)
    if info.mode == "scale":
        span = max(info.occupied_thresh - info.free_thresh, 1e-12)
        between = np.rint((occ - info.free_thresh) / span * 100.0)
        out = np.clip(between, 1, 99).astype(np.int8)
    out[occ > info.occupied_thresh] = OCC_OCCUPIED
    out[occ < info.free_thresh] = OCC_FREE
    if info.mode == "scale" and image.alpha is not None:
        out[image.alpha != image.maxval] = OCC_UNKNOWN
    return out


UNKNOWN_CHOICES = ("obstacle", "free")


def ros_blocked(occupancy: np.ndarray, info: RosMapInfo, unknown: str = "obstacle") -> np.ndarray:
    """Which OccupancyGrid cells a planner must keep out of.

    Occupied (100) always. Partly occupied (1-99), since a planner must not enter
    uncertain space: in scale mode always (the value lies between the thresholds), in
    raw mode when the percentage reaches ``free_thresh``. Unknown (-1) unless
    ``unknown == "free"``: an unexplored area is not known to be empty.
    """
    if unknown not in UNKNOWN_CHOICES:
        raise MapError(
            f"unknown cells must be one of {', '.join(UNKNOWN_CHOICES)}, got {unknown!r}"
        )
    partly = (occupancy > OCC_FREE) & (occupancy < OCC_OCCUPIED)
    if info.mode == "raw":
        partly &= occupancy.astype(np.float64) / 100.0 >= info.free_thresh
    blocked = partly | (occupancy == OCC_OCCUPIED)
    if unknown == "obstacle":
        blocked |= occupancy == OCC_UNKNOWN
    return blocked


def check_yaw(info: RosMapInfo, path: Path) -> None:
    """A rotated map (origin yaw != 0) is refused rather than silently drawn unrotated."""
    yaw = info.origin[2]
    if yaw != 0.0:
        raise MapError(
            f"{path}: origin yaw {yaw:g} rad is not supported (the map's cells must be "
            "aligned with the map frame): rotate the image and set the yaw to 0"
        )


def load_ros_map(
    yaml_path: str | os.PathLike, resolution: float | None = None, unknown: str = "obstacle"
) -> GridMap:
    """A ROS map_server map (YAML + image: PGM, PNG, ...) in its ``map`` frame: the
    YAML's origin (x, y) is the GridMap's origin, and its resolution is used unless one is
    given. ``unknown``:
    whether unknown cells are obstacles (default) or free (see :func:`ros_blocked`).
    """
    path = Path(yaml_path)
    info = read_ros_map_info(path)
    check_yaw(info, path)
    if unknown not in UNKNOWN_CHOICES:
        raise MapError(
            f"{path}: unknown cells must be one of {', '.join(UNKNOWN_CHOICES)}, got {unknown!r}"
        )
    if not info.image.is_file():
        raise MapError(f"{path}: map image not found: {info.image}")
    blocked = ros_blocked(ros_occupancy(read_map_image(info.image), info), info, unknown)
    res = info.resolution if resolution is None else resolution
    try:
        return GridMap.from_rows_top_down(blocked, res, path.stem, info.origin[:2])
    except MapError as err:
        raise MapError(f"{path}: {err}") from None
