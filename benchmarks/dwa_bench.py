"""Time one DWA control cycle against a straightforward loop implementation.

The set-up: a 50 x 50 map (1 m cells, ~20 % random obstacles,
numpy default_rng(0)), the paper's sampling (Table 1: 5 x 5 x 11 = 275
samples per cycle), 10 moving discs around the AGV, 200 random situations
(pose, current command, local target, discs). ``planner.local.dwa.DwaPlanner`` is
timed over 2000 cycles after a warm-up; the reference, written here in the
PythonRobotics style (Python loops over samples and horizon steps, Eq. (4)
stepped one period at a time, the same window, clearance, admissibility and
scoring), once per situation. Both must choose the same command, or one
with the same score.

Run from the repository root: ``python benchmarks/dwa_bench.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from planner.local.config import DwaConfig
from planner.local.dwa import DwaPlanner
from planner.maps.distance_field import DistanceField
from planner.maps.grid import GridMap

MAP_SIZE = 50
OBSTACLE_RATIO = 0.2
DISCS = 10
SITUATIONS = 200
CALLS = 2000


# --- the reference: plain Python loops ---------------------------------------------------
def loop_axis(current, lowest, highest, reach, step):
    lo, hi = max(lowest, current - reach), min(highest, current + reach)
    centre = min(max(current, lo), hi)
    nearest = round(centre / step)
    on_grid = abs(centre / step - nearest) < 1e-6
    values = []
    k = -math.floor((centre - lo) / step + 1e-9)
    while k <= math.floor((hi - centre) / step + 1e-9):
        values.append((nearest + k) * step if on_grid else centre + k * step)
        k += 1
    return values


def loop_lookup(rows, inv_spacing, x, y):
    u = min(max(x * inv_spacing, 0.0), len(rows[0]) - 1.0)
    w = min(max(y * inv_spacing, 0.0), len(rows) - 1.0)
    i, j = min(int(u), len(rows[0]) - 2), min(int(w), len(rows) - 2)
    fu, fw = u - i, w - j
    bottom = rows[j][i] * (1 - fu) + rows[j][i + 1] * fu
    top = rows[j + 1][i] * (1 - fu) + rows[j + 1][i + 1] * fu
    return bottom * (1 - fw) + top * fw


def loop_dwa(cfg, rows, inv_spacing, pose, command, target, discs):
    """[(command, score)] of every admissible sample, in window order (empty: braking)."""
    dv, dw = cfg.max_accel * cfg.dt, cfg.max_alpha * cfg.dt
    candidates = []
    for vx in loop_axis(command[0], cfg.min_vx, cfg.max_speed, dv, cfg.v_resolution):
        for vy in loop_axis(command[1], -cfg.max_speed, cfg.max_speed, dv, cfg.v_resolution):
            if math.hypot(vx, vy) > cfg.max_speed + 1e-9:
                continue
            for omega in loop_axis(
                command[2], -cfg.max_omega, cfg.max_omega, dw, cfg.omega_resolution
            ):
                x, y, theta = pose
                clearance = math.inf
                for k in range(1, cfg.steps + 1):
                    x, y, theta = (
                        x + (vx * math.cos(theta) - vy * math.sin(theta)) * cfg.dt,
                        y + (vx * math.sin(theta) + vy * math.cos(theta)) * cfg.dt,
                        theta + omega * cfg.dt,
                    )
                    c = loop_lookup(rows, inv_spacing, x, y) - cfg.radius
                    for ox, oy, ovx, ovy, r in discs:
                        t = k * cfg.dt
                        gap = math.hypot(x - (ox + ovx * t), y - (oy + ovy * t)) - r - cfg.radius
                        c = min(c, gap)
                    clearance = min(clearance, c)
                    if clearance <= 0:
                        break
                if clearance <= 0:
                    continue
                room = clearance
                if math.hypot(vx, vy) > math.sqrt(2 * room * cfg.max_accel) + 1e-9:
                    continue
                if abs(omega) > math.sqrt(2 * room * cfg.max_alpha) + 1e-9:
                    continue
                bearing = math.atan2(target[1] - y, target[0] - x)
                travel = theta + (math.atan2(vy, vx) if math.hypot(vx, vy) > 1e-9 else 0.0)
                error = abs(math.remainder(bearing - travel, math.tau))
                candidates.append(
                    (
                        (vx, vy, omega),
                        math.pi - error,
                        min(clearance, cfg.clearance_cap),
                        math.hypot(vx, vy),
                    )
                )
    sums = [sum(c[i] for c in candidates) for i in (1, 2, 3)]
    weights = (cfg.alpha, cfg.beta, cfg.gamma)
    return [
        (
            cmd,
            sum(w * t / s if s > 0 else 0.0 for w, t, s in zip(weights, terms, sums, strict=True)),
        )
        for cmd, *terms in candidates
    ]


def loop_choice(scored):
    """The first best-scored command (None when nothing is admissible) and its score."""
    best, best_score = None, -math.inf
    for cmd, score in scored:
        if score > best_score:
            best, best_score = cmd, score
    return best, best_score


# --- the set-up ---------------------------------------------------------------------------
def situations(rng, grid, field, cfg):
    free = np.argwhere(~grid.blocked)  # (row, col)
    out = []
    while len(out) < SITUATIONS:
        row, col = free[rng.integers(len(free))]
        x, y = col + rng.random(), row + rng.random()
        if field.distance_at(x, y) < cfg.radius + 0.2:
            continue
        pose = (x, y, rng.uniform(-math.pi, math.pi))
        command = (
            rng.uniform(0.05, 0.4),
            rng.uniform(-0.1, 0.1),
            math.radians(rng.uniform(-15, 15)),
        )
        angle, reach = rng.uniform(-math.pi, math.pi), rng.uniform(2, 8)
        target = (x + reach * math.cos(angle), y + reach * math.sin(angle))
        bearings, ranges = rng.uniform(-math.pi, math.pi, DISCS), rng.uniform(2, 8, DISCS)
        discs = np.column_stack(
            (
                x + ranges * np.cos(bearings),
                y + ranges * np.sin(bearings),
                rng.uniform(-1, 1, (DISCS, 2)),
                np.full(DISCS, 0.3),
            )
        )
        out.append((pose, command, target, discs))
    return out


def compare(ours, scored) -> str:
    """'same', 'tied' (another command of equal score) or 'differ'."""
    theirs, best = loop_choice(scored)
    if ours is None or theirs is None:
        return "same" if ours is theirs else "differ"
    if np.allclose(ours, theirs, rtol=0, atol=1e-9):
        return "same"
    mine = [s for cmd, s in scored if np.allclose(cmd, ours, rtol=0, atol=1e-9)]
    return "tied" if mine and abs(mine[0] - best) <= 1e-9 else "differ"


def main() -> None:
    rng = np.random.default_rng(0)
    grid = GridMap(rng.random((MAP_SIZE, MAP_SIZE)) < OBSTACLE_RATIO, 1.0, "random50")
    cfg = DwaConfig()
    field = DistanceField.from_grid(grid)
    planner = DwaPlanner(cfg, field)
    cases = situations(rng, grid, field, cfg)
    print(
        f"map {MAP_SIZE}x{MAP_SIZE}, obstacles {grid.obstacle_ratio:.1%}, {DISCS} moving discs, "
        f"horizon {cfg.predict_time} s ({cfg.steps} steps), {SITUATIONS} situations"
    )

    for pose, command, target, discs in cases[:20]:  # warm-up (numba)
        planner.plan(pose, command, target, discs)
    times, results = [], []
    for n in range(CALLS):
        pose, command, target, discs = cases[n % SITUATIONS]
        t0 = time.perf_counter()
        result = planner.plan(pose, command, target, discs)
        times.append(time.perf_counter() - t0)
        if n < SITUATIONS:
            results.append(result)
    samples = {r.samples for r in results}
    admissible = sum(r.admissible for r in results)
    print(
        f"samples per cycle {sorted(samples)}, situations with an admissible command {admissible}"
    )

    rows = field.samples.astype(float).tolist()
    inv = 1 / field.spacing
    loop_times, outcomes, shown = [], [], None
    for (pose, command, target, discs), result in zip(cases, results, strict=True):
        t0 = time.perf_counter()
        scored = loop_dwa(cfg, rows, inv, pose, command, target, discs.tolist())
        loop_times.append(time.perf_counter() - t0)
        outcomes.append(compare(result.command if result.admissible else None, scored))
        if shown is None and result.admissible:
            shown = (result, loop_choice(scored))

    med, p95 = np.median(times) * 1e3, np.percentile(times, 95) * 1e3
    slow = [t for n, t in enumerate(times) if results[n % SITUATIONS].admissible]
    loop_med, loop_p95 = np.median(loop_times) * 1e3, np.percentile(loop_times, 95) * 1e3
    print(f"DwaPlanner.plan : median {med:.3f} ms, p95 {p95:.3f} ms over {CALLS} calls")
    print(
        f"  (cycles with an admissible command only: median {np.median(slow) * 1e3:.3f} ms, "
        f"p95 {np.percentile(slow, 95) * 1e3:.3f} ms)"
    )
    print(f"loop reference  : median {loop_med:.2f} ms, p95 {loop_p95:.2f} ms over {SITUATIONS}")
    print(f"speed-up (median): {loop_med / med:.0f}x")
    if shown is not None:
        result, (loop_cmd, loop_score) = shown
        print(
            f"first admissible situation: DwaPlanner chose {_fmt(result.command)}, "
            f"loop chose {_fmt(loop_cmd)} (score {loop_score:.6f})"
        )
    print(
        f"agreement over {SITUATIONS} situations: {outcomes.count('same')} same command, "
        f"{outcomes.count('tied')} another command of equal score, "
        f"{outcomes.count('differ')} differ"
    )


def _fmt(command) -> str:
    if command is None:
        return "nothing (braking)"
    vx, vy, omega = command
    return f"(vx {vx:.2f} m/s, vy {vy:.2f} m/s, omega {math.degrees(omega):.0f} deg/s)"


if __name__ == "__main__":
    main()
