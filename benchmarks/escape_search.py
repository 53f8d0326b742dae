"""Could any controller have avoided a nav_bench walker from a given moment on?

Runs episode ``--seed`` of ``nav_bench`` with the default fusion planner up to
``--at`` seconds, takes the AGV's position and velocity there, and searches the
sequences of accelerations the AGV could command from then on (every 0.1 s one of
the nine per-axis choices {-a, 0, +a}², the axes turned ``--rotate`` degrees from the
world's) for one that keeps its disc clear of the walls and of every walker on its
real (scripted) path for ``--horizon`` seconds. Beam search: at each step the states
are merged on a 2 cm / 2 cm/s lattice and the ``--beam`` with the most clearance so
far are kept, so "none found" is strong evidence, not a proof.

    python benchmarks/escape_search.py --seed 40 --at 24.2
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.nav_episodes import make_episode
from bridge import keys
from fleet.runtime.inprocess import run_in_process
from planner.core.motion import world_velocity
from planner.maps.distance_field import DistanceField

STEP = 0.1  # s


class _Reached(Exception):
    """Stops the run once the AGV's state at the asked time is known."""


def state_at(episode, when: float):
    """(x, y, vx, vy) of the AGV in the world frame at sim time ``when``."""
    found = {}
    scenario = episode.scenario("fusion", "default")

    def sink(key, msg):
        if key == keys.WORLD_TICK and msg.time >= when - 1e-9:
            a = msg.agvs[0]
            vx, vy = world_velocity(a.theta, a.vx, a.vy, a.omega, scenario.dt)
            found["state"] = (a.x, a.y, float(vx), float(vy), a.radius)
            raise _Reached

    try:
        run_in_process(scenario, sink)
    except _Reached:
        return found["state"]
    raise SystemExit(f"escape_search: the run ended before {when} s")


def search(episode, start, when: float, accel: float, rotate: float, horizon: float, beam: int):
    """The first time no state is clear (None: some stay clear the whole horizon) and the
    most clearance kept by the best sequence."""
    x, y, vx, vy, radius = start
    field = DistanceField.from_grid(episode.grid)
    c, s = math.cos(rotate), math.sin(rotate)
    axes = [(a * c - b * s, a * s + b * c) for a in (-accel, 0, accel) for b in (-accel, 0, accel)]
    controls = np.array(axes)
    pos, vel, kept = np.array([[x, y]]), np.array([[vx, vy]]), np.array([np.inf])
    for k in range(1, round(horizon / STEP) + 1):
        new_vel = (vel[:, None, :] + controls[None] * STEP).reshape(-1, 2)
        new_pos = np.repeat(pos, len(controls), axis=0) + new_vel * STEP
        gap = field.distance_at(new_pos[:, 0], new_pos[:, 1]) - radius
        for walker in episode.moving:
            wx, wy, _, _ = walker.state_at(when + k * STEP)
            gap = np.minimum(gap, np.hypot(new_pos[:, 0] - wx, new_pos[:, 1] - wy)
                             - walker.radius - radius)  # fmt: skip
        clear = gap > 0
        if not clear.any():
            return when + k * STEP, float(kept.max())
        pos, vel = new_pos[clear], new_vel[clear]
        kept = np.minimum(np.repeat(kept, len(controls))[clear], gap[clear])
        lattice = np.round(np.hstack([pos, vel]) / 0.02).astype(np.int64)
        _, unique = np.unique(lattice, axis=0, return_index=True)
        best = unique[np.argsort(-kept[unique])[:beam]]
        pos, vel, kept = pos[best], vel[best], kept[best]
    return None, float(kept.max())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, required=True, help="nav_bench episode seed")
    parser.add_argument("--at", type=float, required=True, help="s: search from this time")
    parser.add_argument("--accel", type=float, default=None,
                        help="m/s² per axis (default: the episode vehicle's)")  # fmt: skip
    parser.add_argument("--rotate", type=float, default=0.0, help="deg: the axes' turn")
    parser.add_argument("--horizon", type=float, default=4.0, help="s searched")
    parser.add_argument("--beam", type=int, default=4000)
    args = parser.parse_args()
    episode = make_episode(args.seed)
    if episode is None:
        raise SystemExit(f"escape_search: episode {args.seed} has no way to its goal")
    if not episode.moving:
        raise SystemExit(f"escape_search: episode {args.seed} has no walker")
    accel = args.accel
    if accel is None:
        accel = episode.scenario("fusion", "default").agvs[0].config.dwa.max_accel
    start = state_at(episode, args.at)
    turn = math.radians(args.rotate)
    contact, kept = search(episode, start, args.at, accel, turn, args.horizon, args.beam)
    where = f"from ({start[0]:.2f}, {start[1]:.2f}) at {args.at} s, a = {accel} m/s² per axis"
    if contact is None:
        print(f"escape found {where}: {kept:.2f} m kept over {args.horizon} s")
    else:
        print(f"no escape found {where}: every sequence touches by {contact:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
