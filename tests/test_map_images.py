"""ROS maps whose image is not a PGM: PNG, BMP, colour, alpha, 16 bit, palette, as
nav2_map_server reads them (its image library: any format, colour averaged to grey,
alpha averaged in trinary mode, a not fully opaque pixel unknown in scale mode).

The AWS RoboMaker small warehouse ships its map as an RGB PNG (scenarios/maps/, source in
its README): it must plan exactly as a PGM of the same pixels. Nav2's depot and TurtleBot3
sandbox maps are also written as PNG, BMP, colour, 16-bit and palette images and read beside
their PGM originals.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from planner.core.errors import MapError
from planner.maps.map_image import read_pgm
from planner.maps.ros_map import load_ros_map, read_ros_map_info

DATA = Path(__file__).parent / "data" / "nav2"
CLI = [sys.executable, "-m", "fleet.cli"]
YAML = (
    "image: {image}\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: {negate}\n"
    "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: {mode}\n"
)


def pgm_pixels(name: str) -> np.ndarray:
    path = DATA / f"{name}.pgm"
    pixels, maxval = read_pgm(path.read_bytes(), path)
    assert maxval == 255
    return pixels.astype(np.uint8)


def twin(folder: Path, name: str, image: Image.Image, suffix: str) -> Path:
    """A copy of nav2 map ``name``'s yaml whose image is ``image`` saved as ``suffix``."""
    image.save(folder / f"{name}{suffix}")
    text = (DATA / f"{name}.yaml").read_text().replace(f"{name}.pgm", f"{name}{suffix}")
    path = folder / f"{name}-{suffix[1:]}.yaml"
    path.write_text(text)
    return path


def variants(grey: np.ndarray) -> dict[str, tuple[Image.Image, str]]:
    """The same map as grey PNG, RGB PNG and BMP, 16-bit PNG and palette PNG: each must
    read as the PGM reads."""
    rgb = np.repeat(grey[..., None], 3, axis=-1)
    return {
        "grey png": (Image.fromarray(grey, "L"), ".png"),
        "rgb png": (Image.fromarray(rgb, "RGB"), ".png"),
        "rgb bmp": (Image.fromarray(rgb, "RGB"), ".bmp"),
        "16-bit png": (Image.fromarray(grey.astype(np.uint16) * 257), ".png"),
        "palette png": (Image.fromarray(grey, "L").convert("P"), ".png"),
    }


@pytest.mark.parametrize("name", ["depot", "tb3_sandbox"])
@pytest.mark.parametrize("variant", list(variants(np.zeros((1, 1), np.uint8))))
def test_nav2_maps_read_the_same_from_any_image_format(tmp_path, name, variant):
    image, suffix = variants(pgm_pixels(name))[variant]
    pgm = load_ros_map(DATA / f"{name}.yaml")
    other = load_ros_map(twin(tmp_path, name, image, suffix))
    assert np.array_equal(other.blocked, pgm.blocked)
    assert (other.origin, other.resolution) == (pgm.origin, pgm.resolution)


def test_an_opaque_alpha_channel_counts_in_trinary_mode_as_in_map_server(tmp_path):
    """map_server averages alpha with the colour in trinary mode even when every pixel is
    opaque: the sandbox's unknown grey 205 becomes (3 * 205 + 255) / 4 = 217.5, p = 0.147,
    free. In scale mode an opaque alpha changes nothing."""
    grey = pgm_pixels("tb3_sandbox")
    rgb = np.repeat(grey[..., None], 3, axis=-1)
    opaque = Image.fromarray(np.dstack([rgb, np.full(grey.shape, 255, np.uint8)]), "RGBA")
    rgba = load_ros_map(twin(tmp_path, "tb3_sandbox", opaque, ".png"))
    pgm = load_ros_map(DATA / "tb3_sandbox.yaml", unknown="free")
    assert (grey == 205).any()
    assert np.array_equal(rgba.blocked, pgm.blocked)
    scale = tmp_path / "scale.yaml"
    scale.write_text((tmp_path / "tb3_sandbox-png.yaml").read_text() + "mode: scale\n")
    (tmp_path / "scale-pgm.yaml").write_text(
        (DATA / "tb3_sandbox.yaml")
        .read_text()
        .replace("tb3_sandbox.pgm", str(DATA / "tb3_sandbox.pgm"))
        + "mode: scale\n"
    )
    assert np.array_equal(
        load_ros_map(scale).blocked, load_ros_map(tmp_path / "scale-pgm.yaml").blocked
    )


def plan_json(map_path: Path, start=(2.0, 13.8), goal=(27.5, 14.0)) -> dict:
    args = ["--start", *map(str, start), "--goal", *map(str, goal), "--json"]
    done = subprocess.run(
        [*CLI, "plan", str(map_path), *args],
        capture_output=True,
        text=True,
        check=True,
    )
    result = json.loads(done.stdout)
    del result["map"]
    for plan in result["plans"]:
        del plan["time_ms"]
    return result


def test_a_png_map_plans_exactly_as_its_pgm_twin(tmp_path):
    png = twin(tmp_path, "depot", Image.fromarray(pgm_pixels("depot"), "L"), ".png")
    from_png, from_pgm = plan_json(png), plan_json(DATA / "depot.yaml")
    assert from_png == from_pgm
    assert all(plan["found"] for plan in from_png["plans"])


AWS = Path(__file__).parents[1] / "scenarios" / "maps" / "aws_small_warehouse.yaml"


def test_the_aws_small_warehouse_png_plans_exactly_as_its_pgm_twin(tmp_path):
    """The twin is written byte by byte as a binary PGM (P5), so it goes through the
    project's own PGM reader, not Pillow: the two readers must agree on a real RGB PNG."""
    rgb = np.asarray(Image.open(AWS.with_suffix(".png")))
    assert rgb.ndim == 3 and (rgb[..., 0] == rgb[..., 2]).all()
    height, width = rgb.shape[:2]
    pgm = tmp_path / "aws.pgm"
    pgm.write_bytes(b"P5\n%d %d\n255\n" % (width, height) + rgb[..., 0].tobytes())
    yaml = tmp_path / "aws.yaml"
    yaml.write_text(AWS.read_text().replace("aws_small_warehouse.png", "aws.pgm"))
    from_png, from_pgm = load_ros_map(AWS), load_ros_map(yaml)
    assert np.array_equal(from_png.blocked, from_pgm.blocked)
    assert from_png.blocked.any() and not from_png.blocked.all()
    plans = [plan_json(path, start=(-3.0, -9.0), goal=(3.55, -2.0)) for path in (AWS, yaml)]
    assert plans[0] == plans[1]
    assert all(plan["found"] for plan in plans[0]["plans"])


def write_map(folder: Path, image: Image.Image, mode="trinary", negate=0) -> Path:
    image.save(folder / "m.png")
    path = folder / "m.yaml"
    path.write_text(YAML.format(image="m.png", negate=negate, mode=mode))
    return path


def test_colour_is_averaged_to_grey(tmp_path):
    # shade = (r + g + b) / 3 / 255; occupancy 1 - shade against 0.65 and 0.196
    pixels = [[(255, 0, 0), (255, 255, 0), (255, 255, 255), (200, 255, 255)]]
    grid = load_ros_map(write_map(tmp_path, Image.fromarray(np.uint8(pixels), "RGB")))
    # red: p = 0.667 occupied; yellow: p = 0.333 unknown; white free; p = 0.065 free
    assert grid.to_text() == "##.."
    grid = load_ros_map(
        write_map(tmp_path, Image.fromarray(np.uint8(pixels), "RGB")), unknown="free"
    )
    assert grid.to_text() == "#..."


def test_alpha_is_averaged_in_trinary_mode_and_unknown_in_scale_mode(tmp_path):
    # white pixels of opacity 255, 128 and 0; a black opaque one
    rgba = np.uint8(
        [[(255, 255, 255, 255), (255, 255, 255, 128), (255, 255, 255, 0), (0,) * 3 + (255,)]]
    )
    path = write_map(tmp_path, Image.fromarray(rgba, "RGBA"))
    # trinary: shade = (3 * 255 + a) / 4 / 255 -> p = 0, 0.125 (free), 0.25 (unknown), 0.75
    assert load_ros_map(path, unknown="free").to_text() == "...#"
    assert load_ros_map(path).to_text() == "..##"
    # scale: any pixel not fully opaque is unknown; the rest as without alpha
    path = write_map(tmp_path, Image.fromarray(rgba, "RGBA"), mode="scale")
    assert load_ros_map(path, unknown="free").to_text() == "...#"
    assert load_ros_map(path).to_text() == ".###"


def test_grey_with_transparency_and_negate(tmp_path):
    la = np.uint8([[(0, 255), (255, 255), (0, 0)]])
    path = write_map(tmp_path, Image.fromarray(la, "LA"), negate=1)
    # negate: p = shade; trinary with alpha: shade = (3 g + a) / 4 / 255 = 0.25, 1, 0
    assert load_ros_map(path, unknown="free").to_text() == ".#."
    assert load_ros_map(path).to_text() == "##."


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        (b"this is a text file, not an image\n", r"m\.png: not an image file"),
        (b"\x89PNG\r\n\x1a\n", r"m\.png: not an image file"),
        (None, r"m\.png: cannot read the image: .*truncated"),
        ("huge", r"m\.png: a 2001 x 2001 map has 4,004,001 cells, more than the 4,000,000"),
    ],
    ids=["text", "png signature only", "truncated png", "too many cells"],
)
def test_bad_map_images_give_one_line_and_exit_2(tmp_path, content, problem):
    if content is None:  # a real PNG cut short
        Image.fromarray(np.uint8(np.random.default_rng(1).integers(0, 255, (64, 64)))).save(
            tmp_path / "full.png"
        )
        content = (tmp_path / "full.png").read_bytes()[:600]
    elif content == "huge":
        Image.new("1", (2001, 2001)).save(tmp_path / "full.png")
        content = (tmp_path / "full.png").read_bytes()
    (tmp_path / "m.png").write_bytes(content)
    path = tmp_path / "m.yaml"
    path.write_text(YAML.format(image="m.png", negate=0, mode="trinary"))
    with pytest.raises(MapError, match=problem):
        load_ros_map(path)
    done = subprocess.run(
        [*CLI, "plan", str(path), "--start", "0.5", "0.5", "--goal", "1", "1"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr


def test_a_missing_image_is_named(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(YAML.format(image="gone.png", negate=0, mode="trinary"))
    assert read_ros_map_info(path).image == tmp_path / "gone.png"
    with pytest.raises(MapError, match=r"map image not found: .*gone\.png"):
        load_ros_map(path)


def test_the_format_is_told_by_content_not_name(tmp_path):
    """GraphicsMagick reads a PNG named .pgm as PNG; so does the reader here."""
    grey = pgm_pixels("tb3_sandbox")
    Image.fromarray(grey, "L").save(tmp_path / "tb3_sandbox.png")
    shutil.move(tmp_path / "tb3_sandbox.png", tmp_path / "tb3_sandbox.pgm")
    shutil.copy(DATA / "tb3_sandbox.yaml", tmp_path / "tb3_sandbox.yaml")
    renamed = load_ros_map(tmp_path / "tb3_sandbox.yaml")
    assert np.array_equal(renamed.blocked, load_ros_map(DATA / "tb3_sandbox.yaml").blocked)
