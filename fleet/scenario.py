"""Scenario files (TOML): the public format of a run. See scenarios/README.md.

``load_scenario`` turns a file (or a built-in scenario's name) into a
validated ``Scenario``; anything wrong becomes one ``ScenarioError`` whose
message names the key or the AGV.
"""

from __future__ import annotations

import functools
import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

from fleet.builtin import builtin_scenarios
from fleet.missions.format import AGV_TASK_KEYS, parse_missions
from fleet.missions.spec import Missions
from fleet.moving_obstacle import MODES, MovingObstacle
from fleet.placement import check_room
from fleet.toml_schema import (
    MAX_TIME_LIMIT,
    ScenarioError,
    as_cell,
    as_point,
    check_keys,
    get_int,
    get_list,
    get_number,
    get_str,
    get_table,
)
from planner.core.errors import MapError
from planner.core.limits import read_input_file
from planner.core.motion import CONTROL_PERIOD
from planner.core.profiles import DEFAULT, PROFILES
from planner.local.config import DwaConfig
from planner.maps.clearance import ClearanceError, clearance_for
from planner.maps.grid import GridMap
from planner.maps.loaders import load_map
from planner.maps.random_map import random_map
from planner.maps.ros_map import UNKNOWN_CHOICES
from planner.maps.text_maps import parse_text_grid
from planner.nav.fusion import VARIANTS, FusionConfig
from planner.traffic.mode_choice import suits_reservations

TOP_KEYS = (
    "name", "description", "dt", "time_limit", "sensing_radius", "profile",
    "map", "planner", "agv_defaults", "agvs", "obstacles", "traffic", "stations", "tasks",
)  # fmt: skip
ZONES, RESERVATIONS, AUTO = "zones", "reservations", "auto"
TRAFFIC_MODES = (AUTO, ZONES, RESERVATIONS)
"""How AGVs share space: the zone rule (``planner.traffic.zones``: one direction holds a
passage), node reservations in time (``planner.traffic.schedule``: PIBT steps), or the
one of the two that suits the map and the fleet (``planner.traffic.mode_choice``)."""
TRAFFIC_KEYS = ("mode",)
# the control period (s; the longest run: toml_schema.MAX_TIME_LIMIT): no
# run whose clock never reaches its end (a dt of 1e-9 was accepted)
DT_RANGE = (0.01, 1.0)
MAP_KEYS = ("resolution", "grid", "file", "random", "unknown")
RANDOM_KEYS = ("width", "height", "obstacle_ratio", "seed")
# [planner]: TOML key -> (FusionConfig or DwaConfig field, scale to internal units)
PLANNER_KEYS = {
    "alpha": ("alpha", 1.0),
    "beta": ("beta", 1.0),
    "gamma": ("gamma", 1.0),
    "predict_time": ("predict_time", 1.0),
    "velocity_resolution": ("v_resolution", 1.0),
    "omega_resolution": ("omega_resolution", math.pi / 180),
}
FUSION_KEYS = (
    "safety_distance", "switch_distance", "goal_tolerance", "progress_window", "progress_distance",
)  # fmt: skip
# [planner] margin (m): safety_distance = radius + margin (planner.maps.clearance); one of the two
CLEARANCE_KEYS = ("margin",)
# [agv_defaults] and per-AGV keys: TOML key (user units) -> (DwaConfig field, scale)
VEHICLE_KEYS = {
    "radius": ("radius", 1.0),
    "max_speed": ("max_speed", 1.0),
    "max_accel": ("max_accel", 1.0),
    "max_omega": ("max_omega", math.pi / 180),  # deg/s
    "max_alpha": ("max_alpha", math.pi / 180),  # deg/s²
}
AGV_KEYS = ("name", "start", "goal", "heading", "profile", "planner", *VEHICLE_KEYS, *AGV_TASK_KEYS)
TEMPORARY_KEYS = ("type", "name", "cells", "appear_at")
MOVING_KEYS = ("type", "name", "radius", "waypoints", "speed", "mode", "start_at")


@dataclass(frozen=True)
class AgvSpec:
    name: str
    start: tuple[float, float]
    goal: tuple[float, float]
    heading_deg: float
    config: FusionConfig

    @property
    def radius(self) -> float:
        return self.config.dwa.radius


@dataclass(frozen=True)
class TemporaryObstacle:
    """Obstacle cells unknown to the global planner, present from ``appear_at`` on."""

    name: str
    cells: tuple[tuple[int, int], ...]
    appear_at: float


@dataclass(frozen=True)
class Scenario:
    name: str
    description: str
    dt: float
    time_limit: float
    sensing_radius: float
    grid: GridMap
    agvs: tuple[AgvSpec, ...]
    temporary: tuple[TemporaryObstacle, ...]
    moving: tuple[MovingObstacle, ...]
    source: str
    path: str
    traffic: str = AUTO  # TRAFFIC_MODES, as the scenario or --traffic chose

    @functools.cached_property
    def traffic_mode(self) -> str:
        """The mode the run uses: ``traffic``, with ``auto`` decided by
        ``planner.traffic.mode_choice`` (the same in every process of a run)."""
        if self.traffic != AUTO:
            return self.traffic
        clearances = [a.config.clearance for a in self.agvs]
        agents = [(a.name, a.start, a.goal) for a in self.agvs]
        fits = suits_reservations(self.grid, clearances, agents)
        return RESERVATIONS if fits else ZONES

    missions: Missions | None = None  # a shift of transport tasks (fleet.missions)

    def __post_init__(self) -> None:
        # dt is the run's one control period: the world steps by it, each AGV's DWA plans
        # and checks its window with its own copy, and the two must be the same number
        for a in self.agvs:
            if a.config.dwa.dt != self.dt:
                raise ScenarioError(
                    f"AGV {a.name!r} plans with a control period of {a.config.dwa.dt:g} s, "
                    f"but the run steps by dt = {self.dt:g} s: they must be equal"
                )

    def agv(self, name: str) -> AgvSpec:
        spec = self._agvs_by_name.get(name)
        if spec is None:
            raise ScenarioError(f"no AGV named {name!r} in scenario {self.name!r}")
        return spec

    @functools.cached_property
    def _agvs_by_name(self) -> dict[str, AgvSpec]:
        # the world looks up every AGV's spec at every tick: a search of 50 was 1250 steps
        return {a.name: a for a in self.agvs}


def resolve_scenario(name_or_path: str) -> Path:
    """A scenario file path as given, or the built-in scenario of that name."""
    path = Path(name_or_path)
    if path.is_file():
        return path
    builtin = builtin_scenarios()
    if name_or_path in builtin:
        return builtin[name_or_path]
    raise ScenarioError(
        f"scenario {name_or_path!r} is neither a file nor a built-in scenario "
        f"(built-in: {', '.join(builtin)})"
    )


def load_scenario(name_or_path: str | Path) -> Scenario:
    path = resolve_scenario(str(name_or_path))
    try:
        text = read_input_file(path, "scenario").decode("utf-8")
    except MapError as err:
        raise ScenarioError(str(err)) from None
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError(f"cannot read scenario {path}: {err}") from None
    return parse_scenario(text, path)


def parse_scenario(text: str, path: Path | None = None) -> Scenario:
    where = str(path) if path else "<scenario>"
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ScenarioError(f"{where}: not valid TOML: {err}") from None
    check_keys(doc, TOP_KEYS, "")
    name = get_str(doc, "name", "", default=path.stem if path else "scenario")
    dt = get_number(doc, "dt", "", default=CONTROL_PERIOD, minimum=DT_RANGE[0], maximum=DT_RANGE[1])
    profile = get_str(doc, "profile", "", default=DEFAULT, choices=PROFILES)
    grid = _parse_map(get_table(doc, "map", "", required=True), path, name, doc)
    planner_defaults = get_table(doc, "planner", "")
    vehicle_defaults = get_table(doc, "agv_defaults", "")
    check_keys(vehicle_defaults, VEHICLE_KEYS, "agv_defaults")
    _parse_config(planner_defaults, "planner", vehicle_defaults, "agv_defaults", dt, profile)
    shift = "tasks" in doc
    agvs = _parse_agvs(doc, grid, dt, planner_defaults, vehicle_defaults, profile, shift)
    missions = parse_missions(doc, grid, agvs)
    shift_end = missions.shift if missions else 300.0  # time_limit's default
    temporary, moving = _parse_obstacles(get_list(doc, "obstacles", "", default=[]), grid)
    traffic = get_table(doc, "traffic", "")
    check_keys(traffic, TRAFFIC_KEYS, "traffic")
    return Scenario(
        name=name,
        description=get_str(doc, "description", "", default=""),
        dt=dt,
        time_limit=get_number(
            doc, "time_limit", "", default=shift_end, positive=True, maximum=MAX_TIME_LIMIT
        ),
        sensing_radius=get_number(doc, "sensing_radius", "", default=5.0, minimum=0.0),
        grid=grid,
        agvs=agvs,
        temporary=temporary,
        moving=moving,
        source=text,
        path=str(path) if path else "",
        traffic=get_str(traffic, "mode", "traffic", default=AUTO, choices=TRAFFIC_MODES),
        missions=missions,
    )


def _parse_map(table: dict, path: Path | None, name: str, doc: dict) -> GridMap:
    check_keys(table, MAP_KEYS, "map")
    sources = [k for k in ("grid", "file", "random") if k in table]
    if len(sources) != 1:
        raise ScenarioError("[map] needs exactly one of: grid, file, random")
    resolution = (
        get_number(table, "resolution", "map", positive=True) if "resolution" in table else None
    )
    unknown = get_str(table, "unknown", "map", default="obstacle", choices=UNKNOWN_CHOICES)
    try:
        if "grid" in table:
            return parse_text_grid(get_str(table, "grid", "map"), resolution or 1.0, name)
        if "file" in table:
            base = path.parent if path else Path.cwd()
            file = base / get_str(table, "file", "map")
            return load_map(file, resolution=resolution, unknown=unknown)
    except MapError as err:
        raise ScenarioError(f"map: {err}") from None
    spec = get_table(table, "random", "map")
    check_keys(spec, RANDOM_KEYS, "map.random")
    width = get_int(spec, "width", "map.random", minimum=1)
    height = get_int(spec, "height", "map.random", minimum=1)
    ratio = get_number(spec, "obstacle_ratio", "map.random", minimum=0.0)
    if ratio >= 1:
        raise ScenarioError(f"map.random.obstacle_ratio must be < 1, got {ratio}")
    res = resolution or 1.0
    keep = []
    for i, agv in enumerate(doc.get("agvs", []) if isinstance(doc.get("agvs"), list) else []):
        for key in ("start", "goal"):
            if isinstance(agv, dict) and key in agv:
                x, y = as_point(agv[key], f"agvs[{i}].{key}")
                keep.append((math.floor(x / res), math.floor(y / res)))
    seed = get_int(spec, "seed", "map.random", default=0)
    try:
        return random_map(width, height, ratio, seed, keep, res)
    except MapError as err:
        raise ScenarioError(f"map: {err}") from None


def _parse_config(
    planner: dict,
    planner_where: str,
    vehicle: dict,
    vehicle_where: str,
    dt: float,
    profile: str = DEFAULT,
) -> FusionConfig:
    """A FusionConfig from a [planner] table and vehicle keys (user units).

    The safety distance comes from planner.maps.clearance: ``safety_distance`` or ``margin``
    (not both), else radius + the default margin; below the radius it is an error."""
    dwa_args: dict = {"dt": dt}
    fusion_args: dict = {"profile": profile}
    check_keys(planner, ("algorithm", *PLANNER_KEYS, *FUSION_KEYS, *CLEARANCE_KEYS), planner_where)
    margin = None
    for key in planner:
        if key == "algorithm":
            fusion_args[key] = get_str(planner, key, planner_where, choices=VARIANTS)
        elif key == "profile":
            fusion_args[key] = get_str(planner, key, planner_where, choices=PROFILES)
        elif key in PLANNER_KEYS:
            field_name, scale = PLANNER_KEYS[key]
            dwa_args[field_name] = get_number(planner, key, planner_where, positive=True) * scale
        elif key == "margin":
            margin = get_number(planner, key, planner_where, minimum=0.0)
        else:
            fusion_args[key] = get_number(planner, key, planner_where, positive=True)
    for key in vehicle:
        field_name, scale = VEHICLE_KEYS[key]
        dwa_args[field_name] = get_number(vehicle, key, vehicle_where, positive=True) * scale
    try:
        dwa = DwaConfig(**dwa_args)
        if margin is not None and "safety_distance" in fusion_args:
            raise ClearanceError(
                "give safety_distance or margin, not both (safety_distance = radius + margin)"
            )
        clearance = clearance_for(
            dwa.radius, margin=margin, safety_distance=fusion_args.get("safety_distance")
        )
        fusion_args["safety_distance"] = clearance.safety_distance
        return FusionConfig(dwa=dwa, **fusion_args)
    except ValueError as err:
        raise ScenarioError(f"{planner_where}: {err}") from None


def _parse_agvs(
    doc, grid, dt, planner_defaults, vehicle_defaults, profile=DEFAULT, shift=False
) -> tuple[AgvSpec, ...]:
    """The [[agvs]]; in a shift (``shift``) an AGV may omit its goal (its start then)."""
    raw = get_list(doc, "agvs", "")
    if not raw:
        raise ScenarioError("a scenario needs at least one [[agvs]] entry")
    seen: set[str] = set()
    agvs = []
    for i, entry in enumerate(raw):
        where = f"agvs[{i}]"
        if not isinstance(entry, dict):
            raise ScenarioError(f"{where} must be a table")
        check_keys(entry, AGV_KEYS, where)
        name = get_str(entry, "name", where)
        if not name or "/" in name or "*" in name or "$" in name or "#" in name or "?" in name:
            raise ScenarioError(f"{where}.name {name!r} must be non-empty without / * $ # ?")
        if name in seen:
            raise ScenarioError(f"duplicate AGV name {name!r} ({where})")
        seen.add(name)
        who = f"AGV {name!r}"
        vehicle = {**vehicle_defaults, **{k: entry[k] for k in VEHICLE_KEYS if k in entry}}
        own_planner = get_table(entry, "planner", where)
        defaults = dict(planner_defaults)
        if "margin" in own_planner or "safety_distance" in own_planner:
            # the AGV's own clearance replaces the run's, whichever way it is given
            defaults.pop("margin", None)
            defaults.pop("safety_distance", None)
        planner = {**defaults, **own_planner}
        own_profile = get_str(entry, "profile", where, default=profile, choices=PROFILES)
        config = _parse_config(planner, f"{where}.planner", vehicle, where, dt, own_profile)
        start = as_point(get_list(entry, "start", where), f"{where}.start")
        if "goal" not in entry and shift:  # an AGV of a shift: its goals are its tasks'
            goal = start
        else:
            goal = as_point(get_list(entry, "goal", where), f"{where}.goal")
        for what, point in (("start", start), ("goal", goal)):
            check_room(grid, point, config.dwa.radius, who, what)
        heading = get_number(entry, "heading", where, default=0.0)
        agvs.append(AgvSpec(name, start, goal, heading, config))
    return tuple(agvs)


def _parse_obstacles(raw: list, grid: GridMap):
    temporary, moving = [], []
    for i, entry in enumerate(raw):
        where = f"obstacles[{i}]"
        if not isinstance(entry, dict):
            raise ScenarioError(f"{where} must be a table")
        kind = get_str(entry, "type", where, choices=("temporary", "moving"))
        name = get_str(entry, "name", where, default=f"{kind}{i}")
        if kind == "temporary":
            check_keys(entry, TEMPORARY_KEYS, where)
            cells = tuple(
                as_cell(c, f"{where}.cells[{j}]")
                for j, c in enumerate(get_list(entry, "cells", where))
            )
            for j, cell in enumerate(cells):
                if not grid.contains_cell(cell):
                    raise ScenarioError(f"{where}.cells[{j}] {list(cell)} is outside the map")
            appear = get_number(entry, "appear_at", where, default=0.0, minimum=0.0)
            temporary.append(TemporaryObstacle(name, cells, appear))
        else:
            check_keys(entry, MOVING_KEYS, where)
            points = tuple(
                as_point(p, f"{where}.waypoints[{j}]")
                for j, p in enumerate(get_list(entry, "waypoints", where))
            )
            if not points:
                raise ScenarioError(f"{where}.waypoints needs at least one point")
            for j, p in enumerate(points):
                if not grid.contains_point(p):
                    raise ScenarioError(f"{where}.waypoints[{j}] {list(p)} is outside the map")
            moving.append(
                MovingObstacle(
                    name=name,
                    radius=get_number(entry, "radius", where, positive=True),
                    waypoints=points,
                    speed=get_number(entry, "speed", where, minimum=0.0),
                    mode=get_str(entry, "mode", where, default="bounce", choices=MODES),
                    start_at=get_number(entry, "start_at", where, default=0.0, minimum=0.0),
                )
            )
    return tuple(temporary), tuple(moving)


def with_profile(scenario: Scenario, profile: str) -> Scenario:
    """The same scenario with every AGV planning with planner profile ``profile``."""
    if profile not in PROFILES:
        raise ScenarioError(f"unknown profile {profile!r}: choose one of {', '.join(PROFILES)}")
    agvs = tuple(replace(a, config=replace(a.config, profile=profile)) for a in scenario.agvs)
    return replace(scenario, agvs=agvs)


def with_traffic(scenario: Scenario, mode: str) -> Scenario:
    """The same scenario with traffic mode ``mode`` (``TRAFFIC_MODES``)."""
    if mode not in TRAFFIC_MODES:
        raise ScenarioError(
            f"unknown traffic mode {mode!r}: choose one of {', '.join(TRAFFIC_MODES)}"
        )
    return replace(scenario, traffic=mode)


def with_algorithm(scenario: Scenario, algorithm: str) -> Scenario:
    """The same scenario with every AGV planning with ``algorithm`` (for comparisons)."""
    if algorithm not in VARIANTS:
        raise ScenarioError(f"unknown algorithm {algorithm!r}: choose one of {', '.join(VARIANTS)}")
    agvs = tuple(replace(a, config=replace(a.config, algorithm=algorithm)) for a in scenario.agvs)
    return replace(scenario, agvs=agvs)
