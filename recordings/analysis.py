"""Offline analysis of a recording: per AGV and per run, and runs compared.

Definitions (all from ``recordings.series``, i.e. the world's ticks):

- run time: the sim time of the run's last tick; arrival: the time of the
  first tick an AGV reports ``arrived``.
- distance travelled: the sum of |Δposition| over every tick of the run; loops,
  how often the driven path crossed itself over the drive
  (``planner.core.path_metrics.self_crossings``).
- path: the first plan that found a path; its key nodes measured with
  ``planner.core.path_metrics`` (length, turning times, total turning angle);
  replans: plans made for the reason ``replan``.
- smoothness, over the drive (tick 0 up to the tick the AGV arrived or failed;
  parked time would dilute it): the world-frame velocity vector of each
  state is its body-frame command turned by the heading it was applied at,
  theta - omega*dt (Eq. 4 turns the command by the heading before the
  step); acceleration and jerk are finite differences over dt, reported as
  RMS of their norms; the same for the speed |v|. Angular: mean |Δω| per tick,
  the number of sign changes of ω (exact zeros skipped), and the RMS angular
  acceleration Δω/dt and angular jerk Δ²ω/dt² (the turn rate's own smoothness:
  the world-frame jerk weighs ω only by the speed it turns).
- clearance, over every tick: to obstacles (map, temporary cells shown at
  that tick, moving obstacles) and to other AGVs, separately; surface to
  surface, as the world measures it (<= 0 is a contact).
- collisions: ``collision`` events; planning time: ``plan_time_ms`` of each
  control cycle of the drive (mean, 95th percentile).
- traffic: waiting time, the ticks an AGV reports ``waiting`` (held outside a
  passage by the traffic rule) times dt; waits, the ``wait`` events naming it
  first; the run's traffic events, every ``wait``, ``go`` and ``yield`` event.
  Traffic mode "reservations": ``reservations``, the ``reserved`` events (nodes released
  to an AGV by the schedule); ``reservation_waits``, the ``waits-for`` events (an AGV
  waits for another to leave the node it needs next), also counted in each AGV's waits;
  ``reservation_searches``, the ``searched`` events (LaCAM planned a way out of a loop
  of PIBT's).
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import asdict, dataclass, replace

import numpy as np

from planner.core import path_metrics
from planner.core.motion import world_velocity
from planner.core.status import ARRIVED, COLLISION, FINISHED, RECOVERY, REPLAN, WAITING
from planner.maps.distance_field import DistanceField
from planner.nav.fusion import GLOBAL_ALGORITHM
from planner.traffic.schedule import RESERVED, SEARCHED, WAITS_FOR
from planner.traffic.zones import DECISIONS, WAIT
from recordings.reader import Recording
from recordings.series import RunSeries, extract
from recordings.task_stats import is_task_event, shift_stats


@dataclass(frozen=True)
class AgvAnalysis:
    name: str
    status: str
    arrival_time: float | None  # s
    distance: float  # m
    path_length: float | None  # m, first plan's key nodes
    turns: int | None
    turning_angle_deg: float | None
    replans: int
    rms_accel: float | None  # m/s², world-frame velocity vector
    rms_jerk: float | None  # m/s³
    rms_speed_accel: float | None  # m/s², of |v|
    rms_speed_jerk: float | None  # m/s³
    mean_abs_domega: float | None  # rad/s per tick
    omega_sign_changes: int
    min_clearance_obstacles: float | None  # m
    min_clearance_agvs: float | None  # m
    collisions: int
    plan_time_mean_ms: float | None
    plan_time_p95_ms: float | None
    waiting_time: float = 0.0  # s held outside passages
    waits: int = 0  # times it was held
    self_crossings: int = 0  # its loops: times its driven path crossed itself
    recoveries: int = 0  # recovery behaviours it started (planner/recovery.py)
    # a shift (recordings.task_stats); None in a run without tasks
    deliveries: int | None = None
    utilisation: float | None = None  # share of the shift it had a task
    distance_per_task: float | None = None  # m driven per delivery
    rms_angular_accel: float | None = None  # rad/s², of ω over the drive
    rms_angular_jerk: float | None = None  # rad/s³


@dataclass(frozen=True)
class RunAnalysis:
    path: str
    scenario: str
    algorithm: str  # the run's --algorithm, else the global planner(s) its plans name
    run_id: str
    finished: bool  # the recording has the run's result
    end_reason: str | None  # as the run reported it ("time limit", ...); None: not finished
    truncated: bool
    dt: float | None
    ticks: int
    run_time: float  # s
    arrived: int
    collisions: int
    path_length: float | None  # mean over AGVs, as are the next six
    distance: float | None
    turns: float | None
    turning_angle_deg: float | None
    rms_accel: float | None
    rms_jerk: float | None
    mean_abs_domega: float | None
    omega_sign_changes: float | None
    min_clearance_obstacles: float | None  # min over AGVs
    min_clearance_agvs: float | None
    replans: int
    plan_time_mean_ms: float | None  # over every control cycle of every AGV
    plan_time_p95_ms: float | None
    agvs: tuple[AgvAnalysis, ...]
    waiting_time: float = 0.0  # s, summed over AGVs
    traffic_events: int = 0  # wait, go and yield events
    reservations: int = 0  # "reserved" events (traffic mode "reservations")
    reservation_waits: int = 0  # "waits-for" events
    reservation_searches: int = 0  # "searched" events: LaCAM out of a loop of PIBT's
    self_crossings: int = 0  # summed over AGVs
    recoveries: int = 0  # summed over AGVs
    tasks: dict | None = None  # a shift's throughput (recordings.task_stats), else None
    rms_angular_accel: float | None = None  # mean over AGVs
    rms_angular_jerk: float | None = None

    @property
    def label(self) -> str:
        """What tells runs apart in comparisons and plot titles: scenario and algorithm."""
        name = self.scenario or self.path
        return f"{name} ({self.algorithm})" if self.algorithm else name

    def to_json(self) -> dict:
        return json_ready(asdict(self))


_VARIANT_OF_GLOBAL = {a: variant for variant, a in GLOBAL_ALGORITHM.items()}


def _algorithm(run: dict, series: RunSeries) -> str:
    """The planner variant of a run (fusion, astar-dwa, dwa), as the run facts name it or
    else as its plans tell (a run's plans name their global A*; a plan-only recording's are
    the A* variants themselves)."""
    given = run.get("algorithm")
    if given and given != "scenario's":
        return str(given)
    planners = {p.get("algorithm") for plans in series.plans.values() for p in plans}
    if run.get("mode") != "plan":
        planners = {_VARIANT_OF_GLOBAL.get(a, a) for a in planners}
    return "+".join(sorted(str(a) for a in planners if a))


def analyze(rec: Recording, series: RunSeries | None = None) -> RunAnalysis:
    """Analyse a recording (``series``: its ``extract(rec)`` if the caller has it already)."""
    series = extract(rec) if series is None else series
    dt = series.dt
    result = rec.result or {}
    statuses = {a["name"]: a.get("status") for a in result.get("agvs", [])}
    obstacle_gap, agv_gap = _clearances(series)
    collisions = [e for e in series.events if e.get("kind") == COLLISION]
    hits = Counter(n for e in collisions for n in e.get("agvs", []))
    traffic = [e for e in series.events if e.get("kind") in DECISIONS]
    waits_for = [e for e in series.events if e.get("kind") == WAITS_FOR]
    waits = Counter(
        e["agvs"][0]
        for e in [*traffic, *waits_for]
        if e.get("kind") in (WAIT, WAITS_FOR) and e.get("agvs")
    )
    recoveries = Counter(
        e["agvs"][0] for e in series.events if e.get("kind") == RECOVERY and e.get("agvs")
    )
    agvs, cycles = [], []
    for i, name in enumerate(series.agvs.names):
        clearance = (_finite(obstacle_gap[i]), _finite(agv_gap[i]))
        agv, plan_times = _agv(series, i, dt, statuses.get(name), hits[name], clearance)
        agvs.append(replace(agv, waits=waits[name], recoveries=recoveries[name]))
        cycles.append(plan_times)
    plan_times = np.concatenate(cycles) if cycles else np.zeros(0)
    run_time = float(series.time[-1]) if len(series.time) else 0.0
    shift = _shift(series.events, run_time, agvs)
    if shift is not None:
        agvs = shift[1]
    run = rec.run
    return RunAnalysis(
        path=str(rec.path),
        scenario=str(run.get("scenario", result.get("scenario", ""))),
        algorithm=_algorithm(run, series),
        run_id=str(run.get("run_id", "")),
        finished=rec.result is not None,
        end_reason=None if rec.result is None else str(result.get("end_reason", "")),
        truncated=rec.truncated,
        dt=dt,
        ticks=int(series.tick[-1]) if len(series.tick) else 0,
        run_time=run_time,
        arrived=sum(a.status == ARRIVED for a in agvs),
        collisions=len(collisions),
        path_length=_mean(a.path_length for a in agvs),
        distance=_mean(a.distance for a in agvs),
        turns=_mean(a.turns for a in agvs),
        turning_angle_deg=_mean(a.turning_angle_deg for a in agvs),
        rms_accel=_mean(a.rms_accel for a in agvs),
        rms_jerk=_mean(a.rms_jerk for a in agvs),
        mean_abs_domega=_mean(a.mean_abs_domega for a in agvs),
        omega_sign_changes=_mean(a.omega_sign_changes for a in agvs),
        min_clearance_obstacles=_least(a.min_clearance_obstacles for a in agvs),
        min_clearance_agvs=_least(a.min_clearance_agvs for a in agvs),
        replans=sum(a.replans for a in agvs),
        plan_time_mean_ms=float(plan_times.mean()) if len(plan_times) else None,
        plan_time_p95_ms=float(np.percentile(plan_times, 95)) if len(plan_times) else None,
        agvs=tuple(agvs),
        waiting_time=sum(a.waiting_time for a in agvs),
        traffic_events=len(traffic),
        reservations=sum(e.get("kind") == RESERVED for e in series.events),
        reservation_waits=len(waits_for),
        reservation_searches=sum(e.get("kind") == SEARCHED for e in series.events),
        self_crossings=sum(a.self_crossings for a in agvs),
        recoveries=sum(a.recoveries for a in agvs),
        tasks=None if shift is None else shift[0],
        rms_angular_accel=_mean(a.rms_angular_accel for a in agvs),
        rms_angular_jerk=_mean(a.rms_angular_jerk for a in agvs),
    )


def _shift(events: list[dict], run_time: float, agvs: list[AgvAnalysis]):
    """A shift's ``tasks`` block and its AGVs with their task fields; None without tasks."""
    task_events = [e for e in events if is_task_event(e)]
    if not task_events:
        return None
    stats = shift_stats(task_events, run_time)
    out = []
    for a in agvs:
        done = stats.deliveries.get(a.name, 0)
        out.append(
            replace(
                a,
                deliveries=done,
                utilisation=stats.busy.get(a.name, 0.0) / run_time if run_time else None,
                distance_per_task=a.distance / done if done else None,
            )
        )
    return stats.to_json(), out


def _agv(
    series: RunSeries, i, dt, final_status, collisions, clearance
) -> tuple[AgvAnalysis, np.ndarray]:
    """One AGV's analysis and the planning times of its control cycles."""
    col = {f: v[:, i] for f, v in series.agvs.columns.items()}
    rows = np.flatnonzero(~np.isnan(col["x"]))
    col = {f: v[rows] for f, v in col.items()}
    status = series.agvs.labels["status"][rows, i]
    time = series.time[rows]
    done = np.flatnonzero(np.isin(status, FINISHED))
    end = int(done[0]) if len(done) else len(rows) - 1
    arrived = len(done) > 0 and status[end] == ARRIVED
    drive = slice(0, end + 1)
    x, y = col["x"], col["y"]
    name = series.agvs.names[i]
    path = _first_path(series.plans.get(name, []))
    motion = _smoothness(col, drive, dt)
    plan_times = col["plan_time_ms"][1 : end + 1]
    agv = AgvAnalysis(
        name=name,
        status=final_status or (str(status[-1]) if len(status) else "unknown"),
        arrival_time=float(time[end]) if arrived else None,
        distance=float(np.hypot(np.diff(x), np.diff(y)).sum()),
        path_length=None if path is None else path_metrics.path_length(path),
        turns=None if path is None else path_metrics.turning_times(path),
        turning_angle_deg=None if path is None else path_metrics.total_turning_angle_deg(path),
        replans=sum(p.get("reason") == REPLAN for p in series.plans.get(name, [])),
        **motion,
        min_clearance_obstacles=clearance[0],
        min_clearance_agvs=clearance[1],
        collisions=collisions,
        plan_time_mean_ms=float(plan_times.mean()) if len(plan_times) else None,
        plan_time_p95_ms=float(np.percentile(plan_times, 95)) if len(plan_times) else None,
        waiting_time=float((status == WAITING).sum() * dt) if dt else 0.0,
        self_crossings=path_metrics.self_crossings(np.column_stack((x[drive], y[drive]))),
    )
    return agv, plan_times


def _first_path(plans: list[dict]):
    for plan in plans:
        if plan.get("found") and plan.get("key_nodes"):
            return plan["key_nodes"]
    return None


def _smoothness(col: dict[str, np.ndarray], drive: slice, dt: float | None) -> dict:
    omega = col["omega"][drive]
    out = {
        "mean_abs_domega": float(np.abs(np.diff(omega)).mean()) if len(omega) > 1 else None,
        "omega_sign_changes": sign_changes(omega),
        "rms_accel": None,
        "rms_jerk": None,
        "rms_speed_accel": None,
        "rms_speed_jerk": None,
        "rms_angular_accel": None,
        "rms_angular_jerk": None,
    }
    if dt is None:
        return out
    out["rms_angular_accel"], out["rms_angular_jerk"] = angular_rms(omega, dt)
    velocity = world_velocity(col["theta"][drive], col["vx"][drive], col["vy"][drive], omega, dt)
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    accel = np.diff(velocity, axis=0) / dt
    speed_accel = np.diff(speed) / dt
    out["rms_accel"] = _rms(accel)
    out["rms_jerk"] = _rms(np.diff(accel, axis=0) / dt)
    out["rms_speed_accel"] = _rms(speed_accel)
    out["rms_speed_jerk"] = _rms(np.diff(speed_accel) / dt)
    return out


def sign_changes(omega: np.ndarray) -> int:
    """How often the turn rate ``omega`` changes sign (exact zeros skipped)."""
    turning = np.sign(omega[omega != 0])
    return int(np.count_nonzero(turning[1:] != turning[:-1]))


def angular_rms(omega: np.ndarray, dt: float) -> tuple[float | None, float | None]:
    """RMS angular acceleration Δω/dt and RMS angular jerk Δ²ω/dt² of ``omega``, one
    turn rate per period ``dt`` (None: too few)."""
    accel = np.diff(omega) / dt
    return _rms(accel), _rms(np.diff(accel) / dt)


def _rms(values: np.ndarray) -> float | None:
    """Root mean square of scalars, or of vector norms (rows)."""
    if len(values) == 0:
        return None
    squares = values**2 if values.ndim == 1 else (values**2).sum(axis=1)
    return float(math.sqrt(squares.mean()))


def _clearances(series: RunSeries) -> tuple[np.ndarray, np.ndarray]:
    """Per AGV, the least clearance to obstacles and to other AGVs over the run (inf: none)."""
    xs, ys = series.agvs.columns["x"], series.agvs.columns["y"]
    radius = series.agvs.columns["radius"]
    count = len(series.agvs.names)
    obstacles = np.full(count, math.inf)
    if series.grid is not None and len(xs):
        base = DistanceField.from_grid(series.grid)
        groups: dict[tuple, list[int]] = {}
        for t, cells in enumerate(series.temporary):
            groups.setdefault(cells, []).append(t)
        for cells, rows in groups.items():
            field = base.with_blocked(list(cells)) if cells else base
            gaps = field.distance_at(xs[rows], ys[rows]) - radius[rows]
            obstacles = np.fmin(obstacles, _column_min(gaps))
    mov = series.moving.columns
    for m in range(len(series.moving.names)):
        gaps = (
            np.hypot(xs - mov["x"][:, m : m + 1], ys - mov["y"][:, m : m + 1])
            - radius
            - mov["radius"][:, m : m + 1]
        )
        obstacles = np.fmin(obstacles, _column_min(gaps))
    others = np.full(count, math.inf)
    for i in range(count - 1):
        rest = slice(i + 1, None)
        gaps = (
            np.hypot(xs[:, rest] - xs[:, i : i + 1], ys[:, rest] - ys[:, i : i + 1])
            - radius[:, rest]
            - radius[:, i : i + 1]
        )
        pair = _column_min(gaps)  # AGV i against each later AGV
        others[i] = np.fmin(others[i], pair.min(initial=math.inf))
        others[rest] = np.fmin(others[rest], pair)
    return obstacles, others


def _column_min(values: np.ndarray) -> np.ndarray:
    """Minimum of each column ignoring NaN (inf for an all-NaN column)."""
    return np.fmin.reduce(values, axis=0, initial=math.inf)


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _mean(values) -> float | None:
    kept = [v for v in values if v is not None]
    return float(np.mean(kept)) if kept else None


def _least(values) -> float | None:
    kept = [v for v in values if v is not None]
    return min(kept) if kept else None


def json_ready(value):
    """JSON-ready: numbers rounded to 6 significant decimals, NaN/inf as None."""
    if isinstance(value, dict):
        return {k: json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(v) for v in value]
    if isinstance(value, float):
        return round(value, 6) if math.isfinite(value) else None
    return value


# --- comparison ---------------------------------------------------------------------
COMPARED = (
    ("run_time", "run time", "s"),
    ("arrived", "arrived", "AGVs"),
    ("collisions", "collisions", ""),
    ("path_length", "mean path length", "m"),
    ("distance", "mean distance", "m"),
    ("turns", "mean turns", ""),
    ("turning_angle_deg", "mean turning angle", "deg"),
    ("rms_accel", "mean RMS acceleration", "m/s²"),
    ("rms_jerk", "mean RMS jerk", "m/s³"),
    ("mean_abs_domega", "mean |Δω| per tick", "rad/s"),
    ("omega_sign_changes", "mean ω sign changes", ""),
    ("rms_angular_accel", "mean RMS angular acceleration", "rad/s²"),
    ("rms_angular_jerk", "mean RMS angular jerk", "rad/s³"),
    ("min_clearance_obstacles", "min clearance obstacles", "m"),
    ("min_clearance_agvs", "min clearance AGVs", "m"),
    ("replans", "replans", ""),
    ("self_crossings", "loops (path self-crossings)", ""),
    ("waiting_time", "waiting time", "s"),
    ("traffic_events", "traffic events", ""),
    ("reservations", "node reservations", ""),
    ("reservation_waits", "waits for a reserved node", ""),
    ("reservation_searches", "searches out of a loop", ""),
    ("recoveries", "recoveries", ""),
    ("plan_time_mean_ms", "plan time mean", "ms"),
    ("plan_time_p95_ms", "plan time p95", "ms"),
)
