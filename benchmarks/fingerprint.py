"""The behaviour of the planner as one hash per run: proof that a refactor changed nothing.

``python benchmarks/fingerprint.py [--workers 2] [--quick] [--out FILE] [--compare FILE]``
(from the repository root) runs, in process, the built-in scenarios, a 50-AGV
warehouse (``fleet_bench``'s), nav_bench episodes (held-out 211 and 282 among them, in
every variant) and traffic_bench cases, and prints for each the sha256 of every AGV
command, world tick and event it produced (``repr`` of the messages, so every float bit
counts; the measured planning time left out) with the run's outcome. ``--out`` writes
the hashes as JSON; ``--compare FILE`` prints which runs differ from that file and exits
1 if any does. ``--quick`` runs a
third of the set (the built-ins, two episodes, two traffic cases) for a quick check.

A restructure keeps every hash; a deliberate behaviour change names the runs it changes.
``benchmarks/fingerprint-facd495.json`` holds the hashes of commit facd495 (before the
planner was split into sub-packages); every commit since that meant to keep behaviour
keeps them, until a deliberate change (then write a new file named after its commit).
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import multiprocessing
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.fleet_maps import warehouse_text  # noqa: E402
from benchmarks.nav_episodes import make_episode  # noqa: E402
from benchmarks.traffic_cases import make_case  # noqa: E402
from fleet.builtin import builtin_scenarios  # noqa: E402
from fleet.runtime.inprocess import run_in_process  # noqa: E402
from fleet.scenario import Scenario, load_scenario, parse_scenario  # noqa: E402
from planner.core.status import ARRIVED  # noqa: E402

NAV_SEEDS = (3, 8, 12, 40, 42, 211, 282)
NAV_VARIANTS = (("fusion", "default"), ("fusion", "paper"), ("astar-dwa", "paper"))
TRAFFIC = (("corridor-2", 0), ("door", 1), ("crossing", 0), ("warehouse-10", 0))
TRAFFIC += (("corridor-3-mirror", 2),)


def jobs(quick: bool) -> list[tuple[str, str, tuple]]:
    """(label, kind, arguments) of every run of the fingerprint."""
    out = [(f"builtin:{name}", "builtin", (name,)) for name in builtin_scenarios()]
    nav = NAV_SEEDS[-2:] if quick else NAV_SEEDS
    out += [
        (f"nav:{seed}:{alg}:{prof}", "nav", (seed, alg, prof))
        for seed in nav
        for alg, prof in NAV_VARIANTS
    ]
    traffic = TRAFFIC[:2] if quick else TRAFFIC
    out += [(f"traffic:{fam}:{seed}", "traffic", (fam, seed)) for fam, seed in traffic]
    if not quick:
        out.append(("warehouse-50", "warehouse", (50, 20.0)))
    return out


def scenario_of(kind: str, args: tuple) -> Scenario:
    if kind == "builtin":
        return load_scenario(builtin_scenarios()[args[0]])
    if kind == "nav":
        seed, algorithm, profile = args
        return make_episode(seed).scenario(algorithm, profile)
    if kind == "traffic":
        return make_case(*args).scenario
    return parse_scenario(warehouse_text(*args))


def fingerprint(job: tuple[str, str, tuple]) -> tuple[str, dict]:
    label, kind, args = job
    digest = hashlib.sha256()

    def outbox(key: str, msg: object) -> None:
        if key.endswith("/command"):
            msg = dataclasses.replace(msg, plan_time_ms=0.0)  # measured, not decided
        elif key == "world/tick":
            agvs = [dataclasses.replace(a, plan_time_ms=0.0) for a in msg.agvs]
            msg = dataclasses.replace(msg, agvs=agvs)
        if key in ("world/tick", "world/event") or key.endswith("/command"):
            digest.update(key.encode())
            # a tick of the zone rule carries no reservations: hashed as before the field
            digest.update(repr(msg).replace(", reservations=[])", ")").encode())

    t0 = time.perf_counter()
    summary = run_in_process(scenario_of(kind, args), outbox)
    outcome = {
        "sha256": digest.hexdigest(),
        "end": summary.end_reason,
        "arrived": sum(a.status == ARRIVED for a in summary.agvs),
        "agvs": len(summary.agvs),
        "collisions": summary.collisions,
        "sim_time": round(summary.sim_time, 3),
        "wall_s": round(time.perf_counter() - t0, 2),
    }
    return label, outcome


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", type=Path)
    parser.add_argument("--compare", type=Path)
    args = parser.parse_args()
    todo = jobs(args.quick)
    results = {}
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        for i, (label, outcome) in enumerate(pool.imap_unordered(fingerprint, todo), 1):
            results[label] = outcome
            print(
                f"[{i}/{len(todo)}] {label}: {outcome['sha256'][:16]} "
                f"{outcome['arrived']}/{outcome['agvs']} arrived, "
                f"{outcome['collisions']} collisions, {outcome['wall_s']} s",
                file=sys.stderr,
            )
    results = dict(sorted(results.items()))
    if args.out:
        args.out.write_text(json.dumps(results, indent=1) + "\n")
    if not args.compare:
        for label, outcome in results.items():
            print(f"{outcome['sha256']}  {label}")
        return 0
    before = json.loads(args.compare.read_text())
    changed = [k for k in results if k in before and before[k]["sha256"] != results[k]["sha256"]]
    for label in changed:
        print(f"CHANGED {label}: {before[label]} -> {results[label]}")
    same = sum(1 for k in results if k in before) - len(changed)
    print(
        f"{same} runs identical, {len(changed)} changed, "
        f"{sum(k not in before for k in results)} not in {args.compare}"
    )
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
