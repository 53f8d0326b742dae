"""Map readers on the public data sets and on files written here, including bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.core.errors import MapError
from planner.maps.loaders import load_map
from planner.maps.movingai import load_movingai, load_movingai_scenarios
from planner.maps.ros_map import load_ros_map, read_ros_map_info
from planner.maps.text_maps import load_matrix_text, parse_text_grid

# Obstacle counts stated in data/grid20/README.md.
GRID20_OBSTACLES = {
    "map20_classic_aco_xuedidi.txt": 118,
    "map20_improved_ant_winsleo.txt": 112,
    "map20_winsleo_commented.txt": 51,
    "map20_jsntjyz_graduation.txt": 51,
    "map20_IAstar_LOS_unknownrepo.txt": 125,
}
# (width, height, obstacles): sizes from the headers, obstacles counted with grep.
MOVINGAI_MAPS = {
    "arena.map": (49, 49, 347),
    "maze-32-32-2.map": (32, 32, 356),
    "random-32-32-20.map": (32, 32, 205),
}
SCENARIOS = {"random-32-32-20-random-1.scen": 409, "arena.map.scen": 130}


# --- text grids ------------------------------------------------------------------------
def test_text_grid_first_printed_row_is_the_top_row():
    grid = parse_text_grid("#..\n...\n", resolution=0.5, name="t")
    assert (grid.width, grid.height, grid.resolution, grid.name) == (3, 2, 0.5, "t")
    assert grid.blocked[1, 0] and grid.blocked.sum() == 1


def test_text_grid_ignores_outer_blank_lines_and_trailing_whitespace():
    grid = parse_text_grid("\n  \n.#  \n#.\t\n\n")
    assert grid.to_text() == ".#\n#."


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("...\n..\n...", r"line 2 has 2 cells, expected 3"),
        ("...\n\n...", r"line 2 has 0 cells, expected 3"),
        ("..\n.x", r"unknown character 'x' at line 2, column 2"),
        (" ..", r"unknown character ' '"),
        ("\n \n", r"no grid rows"),
    ],
)
def test_bad_text_grid(text, problem):
    with pytest.raises(MapError, match=problem):
        parse_text_grid(text, name="bad")


# --- 0/1 matrices (data/grid20) ----------------------------------------------------------
@pytest.mark.parametrize("name", sorted(GRID20_OBSTACLES))
def test_grid20_maps_load_top_row_first(public_data, name):
    path = public_data / "grid20" / name
    as_printed = np.loadtxt(path, comments="#", encoding="utf-8").astype(bool)
    for grid in (load_matrix_text(path, resolution=0.5), load_map(path, resolution=0.5)):
        assert (grid.width, grid.height, grid.resolution) == (20, 20, 0.5)
        assert grid.name == path.stem
        assert grid.blocked.sum() == GRID20_OBSTACLES[name]
        assert np.array_equal(grid.blocked[::-1], as_printed)


def test_grid20_known_cells(public_data):
    # First printed row "0 0 0 0 0 0 1 1 1 0 ...",
    # last printed row "0 0 0 0 0 0 0 0 0 0 1 1 0 ...".
    grid = load_map(public_data / "grid20" / "map20_classic_aco_xuedidi.txt")
    assert grid.blocked[19, 6] and not grid.blocked[19, 5] and not grid.blocked[0, 6]
    assert grid.blocked[0, 10] and not grid.blocked[19, 10]
    assert grid.is_free((0, 19)) and grid.is_free((19, 0))  # the README's start and goal


def test_matrix_errors_name_the_line(tmp_path):
    path = tmp_path / "m.txt"
    path.write_text("# comment\n0 1 0\n0 2 0\n")
    with pytest.raises(MapError, match=r"m\.txt: line 3: expected 0 or 1, got '2'"):
        load_matrix_text(path)
    path.write_text("# comment\n0 1 0\n0 1\n")
    with pytest.raises(MapError, match=r"line 3 has 2 values, expected 3 like line 2"):
        load_map(path)
    path.write_text("# only a comment\n")
    with pytest.raises(MapError, match=r"m\.txt: no grid rows"):
        load_map(path)


def test_load_map_tells_text_grids_from_matrices(tmp_path):
    grid_file = tmp_path / "g.grid"
    grid_file.write_text("#.#\n...\n")  # a first row starting with '#' is not a comment
    assert load_map(grid_file).to_text() == "#.#\n..."
    matrix_file = tmp_path / "m.grid"
    matrix_file.write_text("# 1 = obstacle\n1 0 1\n0 0 0\n")
    assert load_map(matrix_file).to_text() == "#.#\n..."
    bad = tmp_path / "bad.txt"
    bad.write_text("..\n.o\n")
    with pytest.raises(MapError, match=r"bad\.txt: unknown character 'o' at line 2"):
        load_map(bad)


# --- MovingAI ------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(MOVINGAI_MAPS))
def test_movingai_maps(public_data, name):
    path = public_data / "movingai" / name
    rows = path.read_text().splitlines()[4:]
    as_printed = np.array([[c in "@OTW" for c in row] for row in rows])
    grid = load_map(path)
    assert (grid.width, grid.height, grid.blocked.sum()) == MOVINGAI_MAPS[name]
    assert grid.name == path.stem
    assert np.array_equal(grid.blocked[::-1], as_printed)


def test_movingai_known_cells(public_data):
    # maze-32-32-2: first grid line all '@', second "@..@..@....", last "@.....@.....".
    grid = load_movingai(public_data / "movingai" / "maze-32-32-2.map")
    assert grid.blocked[31].all()
    assert [grid.blocked[30, c] for c in range(4)] == [True, False, False, True]
    assert [grid.blocked[0, c] for c in (0, 1, 6)] == [True, False, True]
    # random-32-32-20 has a single 'T' (tree) among its '@': grid line 18, index 30.
    grid = load_movingai(public_data / "movingai" / "random-32-32-20.map")
    assert grid.blocked[31 - 17, 30]


def test_movingai_crlf_and_other_terrain(tmp_path):
    path = tmp_path / "crlf.map"
    path.write_bytes(b"type octile\r\nheight 2\r\nwidth 3\r\nmap\r\nGOT\r\nSW.\r\n")
    grid = load_movingai(path, resolution=2.0)
    assert grid.to_text() == ".##\n.#."
    assert grid.resolution == 2.0


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        (
            "type octile\nheight x\nwidth 2\nmap\n..\n",
            r"header: height 'x' is not a positive integer",
        ),
        ("type octile\nwidth 2\nmap\n..\n", r"header: no 'height' line"),
        ("type octile\nheight 1\nwidth 2\n..\n", r"header at line 4: '\.\.'"),
        ("type hex\nheight 1\nwidth 2\nmap\n..\n", r"unsupported MovingAI map type 'hex'"),
        ("type octile\nheight 2\nwidth 2\nmap\n..\n", r"header says height 2 but the map has 1"),
        ("type octile\nheight 1\nwidth 3\nmap\n..\n", r"line 5 has 2 cells but .* width 3"),
        ("type octile\nheight 1\nwidth 2\nmap\n.X\n", r"unknown map character 'X' at line 5"),
    ],
)
def test_bad_movingai_map(tmp_path, content, problem):
    path = tmp_path / "bad.map"
    path.write_text(content)
    with pytest.raises(MapError, match=r"bad\.map: (bad MovingAI )?" + problem):
        load_map(path)


def test_movingai_scenarios_in_the_world_frame(public_data):
    total = 0
    for scen_name, count in SCENARIOS.items():
        entries = load_movingai_scenarios(public_data / "movingai" / scen_name)
        assert len(entries) == count
        total += len(entries)
        grid = load_movingai(public_data / "movingai" / entries[0].map_name)
        for e in entries:
            assert (e.width, e.height) == (grid.width, grid.height)
            # Flipped rows would put many starts and goals inside obstacles.
            assert grid.is_free(e.start) and grid.is_free(e.goal), e
    assert total == 539
    # First entry: "7 random-32-32-20.map 32 32 5 16 31 24 31.31370850" (CRLF file).
    first = load_movingai_scenarios(public_data / "movingai" / "random-32-32-20-random-1.scen")[0]
    assert (first.bucket, first.map_name) == (7, "random-32-32-20.map")
    assert (first.start, first.goal) == ((5, 31 - 16), (31, 31 - 24))
    assert first.optimal_length == pytest.approx(31.3137085)


@pytest.mark.parametrize(
    ("line", "problem"),
    [
        ("0\tm.map\t4\t4\t0\t0\t1\n", r"line 2: expected 9 fields, got 7"),
        ("0\tm.map\t4\t4\t0\t0\t1\tx\t1.0\n", r"line 2: expected integers"),
        ("0\tm.map\t4\t4\t0\t4\t1\t1\t1.0\n", r"line 2: start \(0, 4\) is outside the 4x4 map"),
        ("0\tm.map\t4\t4\t0\t0\t1\t1\tnan\n", r"line 2: optimal length 'nan'"),
    ],
)
def test_bad_scenario_line(tmp_path, line, problem):
    path = tmp_path / "bad.scen"
    path.write_text("version 1\n" + line)
    with pytest.raises(MapError, match=r"bad\.scen: " + problem):
        load_movingai_scenarios(path)


# --- ROS map_server ----------------------------------------------------------------------
FREE, OCCUPIED, UNKNOWN = 254, 0, 205  # map_saver's shades
# As printed (top row first); a cell is blocked unless its pixel is FREE.
IMAGE = np.array(
    [
        [OCCUPIED, FREE, FREE, FREE],
        [FREE, UNKNOWN, FREE, 230],  # p(230) = 0.098: free
        [FREE, FREE, 180, FREE],  # p(180) = 0.294: between the thresholds
    ]
)
BLOCKED_TEXT = "#...\n.#..\n..#."


def write_pgm(path, pixels, maxval=255, plain=False, comment=True):
    height, width = pixels.shape
    header = "P2" if plain else "P5"
    header += "\n# CREATOR: test\n" if comment else "\n"
    header += f"{width} {height}\n{maxval}\n"
    if plain:
        body = "\n".join(" ".join(str(v) for v in row) for row in pixels).encode()
    else:
        body = pixels.astype(">u2" if maxval > 255 else "u1").tobytes()
    path.write_bytes(header.encode() + body)


def write_yaml(path, image="map.pgm", negate=0, extra=""):
    path.write_text(
        f"image: {image}\nresolution: 0.05\norigin: [-10.0, -5.5, 0.0]\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: {negate}\n{extra}"
    )
    return path


@pytest.mark.parametrize("plain", [False, True])
def test_ros_map_8_bit(tmp_path, plain):
    write_pgm(tmp_path / "map.pgm", IMAGE, plain=plain)
    grid = load_map(write_yaml(tmp_path / "office.yaml"))
    assert grid.to_text() == BLOCKED_TEXT
    assert (grid.resolution, grid.name) == (0.05, "office")


def test_ros_map_negate_and_16_bit(tmp_path):
    write_pgm(tmp_path / "map.pgm", 255 - IMAGE, comment=False)
    assert load_ros_map(write_yaml(tmp_path / "neg.yaml", negate=1)).to_text() == BLOCKED_TEXT
    write_pgm(tmp_path / "deep.pgm", IMAGE * 256, maxval=65535)  # big-endian samples
    grid = load_ros_map(write_yaml(tmp_path / "deep.yaml", image="deep.pgm"))
    assert grid.to_text() == BLOCKED_TEXT


def test_ros_map_modes(tmp_path):
    write_pgm(tmp_path / "map.pgm", IMAGE)
    scale = write_yaml(tmp_path / "scale.yaml", extra="mode: scale\n")
    assert load_ros_map(scale).to_text() == BLOCKED_TEXT
    # raw: pixels are occupancy percentages (free below 19.6), above 100 unknown.
    write_pgm(tmp_path / "raw.pgm", np.array([[0, 10, 19, 30, 100, 255]]))
    raw = write_yaml(tmp_path / "raw.yaml", image="raw.pgm", extra="mode: raw\n")
    assert load_ros_map(raw).to_text() == "...###"


def test_ros_map_resolution_and_info(tmp_path):
    write_pgm(tmp_path / "map.pgm", IMAGE)
    yaml_path = write_yaml(tmp_path / "m.yml")
    assert load_map(yaml_path, resolution=0.1).resolution == 0.1
    info = read_ros_map_info(yaml_path)
    assert info.image == tmp_path / "map.pgm"
    assert info.origin == (-10.0, -5.5, 0.0)
    assert (info.resolution, info.free_thresh, info.negate, info.mode) == (
        0.05,
        0.196,
        False,
        "trinary",
    )


def test_ros_map_image_path_may_be_absolute(tmp_path):
    (tmp_path / "images").mkdir()
    write_pgm(tmp_path / "images" / "map.pgm", IMAGE)
    yaml_path = write_yaml(tmp_path / "m.yaml", image=tmp_path / "images" / "map.pgm")
    assert load_map(yaml_path).to_text() == BLOCKED_TEXT


@pytest.mark.parametrize(
    ("pgm", "problem"),
    [
        (b"P5\n4 3\n255\n" + bytes(11), r"truncated PGM: 11 of 12 pixels present"),
        (b"P5\n4 3\n65535\n" + bytes(23), r"truncated PGM: 11 of 12 pixels present"),
        (b"P2\n4 3\n255\n" + b"0 " * 11, r"truncated PGM: 11 of 12 pixels present"),
        (b"P2\n2 1\n255\n0 x", r"plain PGM pixels must be non-negative integers"),
        (b"P2\n2 1\n100\n0 101", r"pixel value 101 exceeds maxval 100"),
        (b"P5\n4 x\n255\n" + bytes(12), r"bad PGM header"),
        (b"P5\n0 3\n255\n", r"bad PGM header: size 0x3"),
    ],
)
def test_bad_pgm(tmp_path, pgm, problem):
    (tmp_path / "map.pgm").write_bytes(pgm)
    with pytest.raises(MapError, match=r"map\.pgm: " + problem):
        load_map(write_yaml(tmp_path / "m.yaml"))


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        ("image: map.pgm\nresolution: 0.05\n", r"missing key\(s\): origin, occupied_thresh"),
        ("image: [map.pgm\n", r"invalid YAML"),
        ("- a list\n", r"expected a YAML mapping"),
        (
            "image: map.pgm\nresolution: -1\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.2\nnegate: 0\n",
            r"'resolution' must be positive",
        ),
        (
            "image: map.pgm\nresolution: 1\norigin: [0, 0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.2\nnegate: 0\n",
            r"'origin' must be a list \[x, y, yaw\]",
        ),
        (
            "image: map.pgm\nresolution: 1\norigin: [0, 0, 0]\noccupied_thresh: 0.1\n"
            "free_thresh: 0.2\nnegate: 0\n",
            r"need 0 <= free_thresh <= occupied_thresh",
        ),
        (
            "image: map.pgm\nresolution: 1\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.2\nnegate: 2\n",
            r"'negate' must be 0 or 1",
        ),
        (
            "image: map.pgm\nresolution: 1\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.2\nnegate: 0\nmode: fuzzy\n",
            r"'mode' must be one of",
        ),
        (
            "image: map.pgm\nresolution: fine\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.2\nnegate: 0\n",
            r"'resolution' must be a number, got 'fine'",
        ),
        (
            "image: other.pgm\nresolution: 1\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
            "free_thresh: 0.2\nnegate: 0\n",
            r"map image not found: .*other\.pgm",
        ),
    ],
)
def test_bad_ros_yaml(tmp_path, content, problem):
    write_pgm(tmp_path / "map.pgm", IMAGE)
    (tmp_path / "bad.yaml").write_text(content)
    with pytest.raises(MapError, match=r"bad\.yaml: " + problem):
        load_map(tmp_path / "bad.yaml")


# --- load_map in general -------------------------------------------------------------------
def test_missing_file(tmp_path):
    with pytest.raises(MapError, match=r"map file not found: .*nowhere\.map"):
        load_map(tmp_path / "nowhere.map")
    with pytest.raises(MapError, match=r"map file not found: .*nowhere\.txt"):
        load_matrix_text(tmp_path / "nowhere.txt")


def test_unknown_extension_and_binary_text(tmp_path):
    path = tmp_path / "map.png"
    path.write_bytes(b"\x89PNG")
    with pytest.raises(MapError, match=r"map\.png: unknown map file extension '\.png'"):
        load_map(path)
    path = tmp_path / "map.txt"
    path.write_bytes(b"\xff\xfe0 1\n")
    with pytest.raises(MapError, match=r"map\.txt: not a UTF-8 text file"):
        load_map(path)


def test_bad_resolution_names_the_file(public_data):
    path = public_data / "movingai" / "arena.map"
    with pytest.raises(MapError, match=r"arena\.map: map resolution must be a positive number"):
        load_map(path, resolution=-1.0)
    assert load_map(path, resolution=0.25).size_m == (49 * 0.25, 49 * 0.25)
    assert math.isclose(load_map(path).resolution, 1.0)
