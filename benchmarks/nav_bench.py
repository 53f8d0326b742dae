"""Single-AGV navigation episodes: the local planner of each variant side by side.

``python benchmarks/nav_bench.py [--episodes 100] [--workers 2]`` (from the
repository root) generates the seeded episodes of ``nav_episodes.py`` (each
has a way the body fits through) and runs each in process with ``fusion``
(default profile), ``fusion`` (paper profile), ``astar-dwa`` and ``dwa``
(both, as the paper's baselines, with the paper profile). Per variant:
success (arrived, no collision) out of the episodes that leave a way once
every walker has stopped (``Episode.way_at_rest``), episodes with a collision, median distance
driven / shortest path the body fits through (successful episodes), median
arrival time, median RMS jerk per vehicle (world-frame, over the drive, as
``recordings.analysis`` defines it), median ω sign changes and RMS angular jerk (rad/s³)
and the wall time. Then the default
fusion's targets: 100 % success, 0 collisions, median driven/shortest <=
1.15, RMS jerk <= 0.6 m/s³ at Table-1 limits; a MISS never fails the run.

``--first-seed 200`` generates the episodes from seed 200 on: a held-out set, for
episodes the planner was not tuned on. ``--seeds 8,40,42`` runs just those episodes and
prints one line for each (status, arrival, collisions, driven/shortest), to iterate on
them. ``--write-toml DIR`` writes the chosen episodes as scenario files and exits: ``agv-fleet
run DIR/nav-282.toml --rerun`` shows one in Rerun (``--algorithm``, ``--profile`` for the
other variants), and ``agv-fleet analyze`` plots its recording.
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.nav_episodes import Episode, episodes, make_episode
from fleet.runtime.inprocess import run_in_process
from planner.core.status import ARRIVED, FINISHED
from recordings.analysis import angular_rms, sign_changes, world_velocity

VARIANTS = (
    ("fusion (default)", "fusion", "default"),
    ("fusion (paper)", "fusion", "paper"),
    ("astar-dwa (paper)", "astar-dwa", "paper"),
    ("dwa (paper)", "dwa", "paper"),
)


def smoothness(states, dt: float) -> dict:
    """Over the drive (up to arrival or failure), as ``recordings.analysis`` defines them:
    the RMS world-frame jerk, ω's sign changes and its RMS angular acceleration and jerk."""
    end = next((i for i, s in enumerate(states) if s.status in FINISHED), len(states))
    drive = states[: end + 1]
    col = {k: np.array([getattr(s, k) for s in drive]) for k in ("theta", "vx", "vy", "omega")}
    accel, angular_jerk = angular_rms(col["omega"], dt)
    out = {
        "jerk": 0.0,
        "omega_signs": sign_changes(col["omega"]),
        "angular_accel": accel or 0.0,
        "angular_jerk": angular_jerk or 0.0,
    }
    if len(drive) >= 3:
        velocity = world_velocity(col["theta"], col["vx"], col["vy"], col["omega"], dt)
        jerk = np.diff(velocity, n=2, axis=0) / dt**2
        out["jerk"] = float(np.sqrt((jerk**2).sum(axis=1).mean()))
    return out


def run_one(job: tuple[Episode, str, str, str]) -> dict:
    episode, label, algorithm, profile = job
    scenario = episode.scenario(algorithm, profile)
    states = []
    summary = run_in_process(
        scenario, lambda key, msg: states.extend(msg.agvs) if key == "world/tick" else None
    )
    agv = summary.agvs[0]
    return {
        "seed": episode.seed,
        "way": episode.way_at_rest,
        "vehicle": episode.vehicle,
        "kind": f"{episode.goal_kind}:{episode.events}",
        "variant": label,
        "status": agv.status,
        "failure": agv.failure,
        "collisions": agv.collisions,
        "ratio": agv.distance / episode.shortest,
        "arrival": agv.arrival_time,
        **smoothness(states, scenario.dt),
        "wall": summary.wall_time,
    }


def _median(values) -> str:
    values = list(values)
    return f"{statistics.median(values):.2f}" if values else "-"


def successes(rs: list[dict]) -> tuple[list[dict], int]:
    """The runs that arrived without a collision, and how many runs had a way to arrive by
    (``Episode.way_at_rest``: success is counted where a path exists)."""
    ok = [r for r in rs if r["way"] and r["status"] == ARRIVED and r["collisions"] == 0]
    return ok, sum(r["way"] for r in rs)


def table(results: list[dict]) -> str:
    by = defaultdict(list)
    for r in results:
        by[r["variant"]].append(r)
    header = ("variant", "success", "collided", "driven/shortest", "arrival s",
              "jerk T1", "jerk real", "ω signs", "ω jerk", "wall s")  # fmt: skip
    rows = [header]
    for label in (v[0] for v in VARIANTS if v[0] in by):
        rs = by[label]
        ok, count = successes(rs)
        rows.append(
            (
                label,
                f"{len(ok)}/{count}",
                str(sum(r["collisions"] > 0 for r in rs)),
                _median(r["ratio"] for r in ok),
                _median(r["arrival"] for r in ok),
                _median(r["jerk"] for r in ok if r["vehicle"] == "table1"),
                _median(r["jerk"] for r in ok if r["vehicle"] == "realistic"),
                _median(r["omega_signs"] for r in ok),
                _median(r["angular_jerk"] for r in ok),
                f"{sum(r['wall'] for r in rs):.0f}",
            )
        )
    widths = [max(len(r[i]) for r in rows) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)) for r in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def targets(results: list[dict]) -> list[str]:
    rs = [r for r in results if r["variant"] == VARIANTS[0][0]]
    ok, count = successes(rs)
    ratio = statistics.median(r["ratio"] for r in ok) if ok else float("inf")
    jerks = [r["jerk"] for r in ok if r["vehicle"] == "table1"]
    jerk = statistics.median(jerks) if jerks else float("inf")
    collided = sum(r["collisions"] > 0 for r in rs)
    checks = (
        (f"success {len(ok)}/{count} = 100 %", len(ok) == count),
        (f"collisions {collided} = 0", collided == 0),
        (f"median driven/shortest {ratio:.2f} <= 1.15", ratio <= 1.15),
        (f"median RMS jerk at Table-1 limits {jerk:.2f} <= 0.6 m/s³", jerk <= 0.6),
    )
    return [f"{'PASS' if good else 'MISS'} fusion (default): {text}" for text, good in checks]


def selected(seeds: str) -> list[Episode]:
    """The episodes of the comma-separated ``seeds``; a seed without one is an error."""
    out = []
    for seed in (int(s) for s in seeds.split(",")):
        episode = make_episode(seed)
        if episode is None:
            raise SystemExit(f"seed {seed} has no episode: its map leaves the body no way")
        out.append(episode)
    return out


def write_toml(eps: list[Episode], folder: Path) -> None:
    """Each episode as ``folder/nav-SEED.toml`` (the default fusion; ``agv-fleet run``'s
    ``--algorithm`` and ``--profile`` run it as another variant)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for e in eps:
            (folder / f"nav-{e.seed}.toml").write_text(e.toml())
    except OSError as err:
        sys.stderr.write(f"nav_bench: cannot write {folder}: {err}\n")
        sys.exit(2)
    print(f"wrote {len(eps)} episodes to {folder}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument(
        "--first-seed", type=int, default=0,
        help="generate the episodes from this seed on (200: a set the planner was not tuned on)",
    )  # fmt: skip
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--variants", default="all", help="'all' or a comma list of labels")
    parser.add_argument("--seeds", help="a comma list of episode seeds, in place of --episodes")
    parser.add_argument("--write-toml", type=Path, metavar="DIR",
                        help="write the episodes as scenario files nav-SEED.toml into DIR and "
                        "exit (agv-fleet run reads them)")  # fmt: skip
    args = parser.parse_args()
    chosen = [v for v in VARIANTS if args.variants == "all" or v[0] in args.variants.split(",")]
    eps = selected(args.seeds) if args.seeds else episodes(args.episodes, args.first_seed)
    if args.write_toml:
        write_toml(eps, args.write_toml)
        return
    jobs = [(e, *v) for e in eps for v in chosen]
    t0 = time.perf_counter()
    with multiprocessing.get_context("spawn").Pool(max(1, min(args.workers, 2))) as pool:
        results = pool.map(run_one, jobs, chunksize=4)
    kinds = defaultdict(int)
    for e in eps:
        kinds[e.goal_kind] += 1
    print(
        f"{len(eps)} episodes (seeds {eps[0].seed}-{eps[-1].seed}; goals: "
        + ", ".join(f"{k} {n}" for k, n in sorted(kinds.items()))
        + f"; {sum('crossing' in e.events for e in eps)} crossing walkers, "
        f"{sum('head-on' in e.events for e in eps)} head-on, "
        f"{sum('wall-early' in e.events for e in eps)} early and "
        f"{sum('wall-late' in e.events for e in eps)} late walls), "
        f"run in {time.perf_counter() - t0:.0f} s"
    )
    print(table(results))
    for line in targets(results):
        print(line)
    for e in eps:
        if not e.way_at_rest:
            print(f"  seed {e.seed}: no way left once its walkers stopped (not in 'success')")
    shown = [r for r in results if args.seeds or r["variant"] == VARIANTS[0][0]]
    if not args.seeds:  # the whole benchmark: only the default fusion's failures
        shown = [r for r in shown if r["status"] != ARRIVED or r["collisions"]]
    for r in shown:
        arrival = f" at {r['arrival']:.1f} s" if r["status"] == ARRIVED else ""
        print(
            f"  {r['variant']} seed {r['seed']} ({r['vehicle']}, {r['kind']}): {r['status']}"
            f"{arrival}{' ' + r['failure'] if r['failure'] else ''}, "
            f"{r['collisions']} collision(s), driven/shortest {r['ratio']:.2f}"
        )


if __name__ == "__main__":
    main()
