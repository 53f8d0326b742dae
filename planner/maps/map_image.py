"""A map image's pixels as ROS map_server's image library hands them to it.

nav2_map_server reads its image with GraphicsMagick, so any format that library reads
is a map: PGM (what map_saver writes), PNG, BMP, JPEG, GIF, TIFF, ... For every pixel it
takes the red, green and blue values (a grey image has the three equal) and, in some
modes, the alpha channel. :class:`MapImage` keeps exactly those, as integers with their
maximum, so that the occupancy rule (``ros_map.ros_occupancy``) sees what map_server sees.

PGM is read by the exact reader below (8 and 16 bit, binary and plain, any maxval), so a
PGM reads bit for bit as it always has and its errors name what is wrong in the header;
every other format through Pillow, which reads all the raster formats map_server users
ship (16-bit colour is reduced to 8 bits per channel by Pillow; a map's shades do not
need more). A file's format is told by its content, as GraphicsMagick tells it.
"""

from __future__ import annotations

import io
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from planner.core.errors import MapError
from planner.core.limits import check_map_cells
from planner.maps.map_files import read_bytes


@dataclass(frozen=True)
class MapImage:
    """Pixels top row first: ``colour_sum`` (H, W) the sum of red, green and blue (three
    times the grey of a grey image), ``alpha`` (H, W) the opacity (``maxval`` opaque) or
    None when the image has no alpha channel, both in units of ``maxval``."""

    colour_sum: np.ndarray
    alpha: np.ndarray | None
    maxval: int


def read_map_image(path: Path) -> MapImage:
    """The pixels of the map image at ``path``: MapError with one line if it cannot be
    read, is not an image, or has more cells than a map may have."""
    data = read_bytes(path, "map image")
    if data[:2] in (b"P2", b"P5"):
        grey, maxval = read_pgm(data, path)
        return MapImage(3 * grey.astype(np.int64), None, maxval)
    return _read_with_pillow(data, path)


_PGM_SEP = rb"(?:\s|#[^\r\n]*[\r\n])+"  # whitespace and '#' comments between header fields
_PGM_HEADER = re.compile(
    rb"(P[25])" + _PGM_SEP + rb"(\d+)" + _PGM_SEP + rb"(\d+)" + _PGM_SEP + rb"(\d+)\s"
)


def read_pgm(data: bytes, path: Path) -> tuple[np.ndarray, int]:
    """(pixels, maxval) of a binary (P5, 8 or 16 bit) or plain (P2) PGM; top row first."""
    match = _PGM_HEADER.match(data)
    if match is None:
        raise MapError(f"{path}: bad PGM header")
    magic, width, height, maxval = match[1], int(match[2]), int(match[3]), int(match[4])
    if width == 0 or height == 0 or not 0 < maxval < 65536:
        raise MapError(f"{path}: bad PGM header: size {width}x{height}, maxval {maxval}")
    check_map_cells(width, height, str(path))
    count = width * height
    if magic == b"P5":
        dtype = np.dtype("u1" if maxval < 256 else ">u2")
        available = (len(data) - match.end()) // dtype.itemsize
        if available < count:
            raise MapError(f"{path}: truncated PGM: {available} of {count} pixels present")
        pixels = np.frombuffer(data, dtype, count, match.end())
    else:
        tokens = data[match.end() :].split()
        if len(tokens) < count:
            raise MapError(f"{path}: truncated PGM: {len(tokens)} of {count} pixels present")
        if not all(token.isdigit() for token in tokens[:count]):
            raise MapError(f"{path}: plain PGM pixels must be non-negative integers")
        pixels = np.array([int(token) for token in tokens[:count]], dtype=np.int64)
    if pixels.max() > maxval:
        raise MapError(f"{path}: pixel value {pixels.max()} exceeds maxval {maxval}")
    return pixels.reshape(height, width), maxval


_GREY_16 = ("I;16", "I;16B", "I;16L", "I;16N", "I")
"""Pillow's modes of a 16-bit grey image (older Pillows open a 16-bit PNG as "I")."""


def _read_with_pillow(data: bytes, path: Path) -> MapImage:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            image = Image.open(io.BytesIO(data))
            check_map_cells(image.width, image.height, str(path))
            image.load()
    except UnidentifiedImageError:
        raise MapError(
            f"{path}: not an image file (map images may be PGM, PNG, BMP, JPEG, GIF, TIFF, ...)"
        ) from None
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as err:
        raise MapError(f"{path}: image too large: {err}") from None
    except (OSError, ValueError, SyntaxError, EOFError) as err:
        raise MapError(f"{path}: cannot read the image: {err}") from None
    return _pixels(image, path)


def _pixels(image: Image.Image, path: Path) -> MapImage:
    """Pillow's image as map_server's colour channels and alpha."""
    mode = image.mode
    if mode in _GREY_16:
        grey = np.asarray(image).astype(np.int64)
        if grey.min() < 0 or grey.max() > 65535:
            raise MapError(f"{path}: 32-bit integer images are not supported (at most 16 bits)")
        return MapImage(3 * grey, None, 65535)
    if mode == "F":
        raise MapError(f"{path}: floating-point images are not supported (use 8 or 16 bits)")
    has_alpha = mode in ("LA", "La", "PA", "RGBA", "RGBa") or (
        mode in ("P", "L", "RGB") and "transparency" in image.info
    )
    rgba = np.asarray(image.convert("RGBA" if has_alpha else "RGB")).astype(np.int64)
    alpha = rgba[..., 3] if has_alpha else None
    return MapImage(rgba[..., :3].sum(axis=-1), alpha, 255)
