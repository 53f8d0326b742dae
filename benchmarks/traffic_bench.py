"""Traffic stress suite: many AGVs through corridors, doors, crossings and shelf aisles.

``python benchmarks/traffic_bench.py [--families corridor-2,door,...] [--seeds 5]
[--workers 1] [--zenoh N] [--json] [--write-toml DIR]`` (from the repository root)
generates the seeded cases of ``traffic_cases.py`` (see its docstring: families,
vehicle, time limits), runs each in process, and each AGV of it alone on the same
map (its solo run). Per case: arrivals, collisions, whether the run reached its
time limit, the makespan (the last arrival; only when every AGV arrived) over the
sum of the solo run times and over the longest solo run, and each AGV's waiting
time (the run summary's: held outside a passage by the traffic rule). ``--zenoh N``
also runs the first N cases of each family over Zenoh (a world process and one
process per AGV, as ``agv-fleet run`` does) and says whether the outcome (status
and arrival time of every AGV, collisions, end) equals the in-process one.
``--write-toml DIR`` writes every case as a scenario file (``agv-fleet run
DIR/corridor-2_n2_s0.toml`` to watch one) and exits.

Prints a progress line per case on stderr, then a table per family and the
targets (100 % arrival, 0 collisions, no run at its time limit) as PASS/MISS; a
MISS never makes the exit status non-zero; bad arguments exit 2 with one line.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.traffic_cases import FAMILIES, TrafficCase, cases, make_case  # noqa: E402
from fleet.runtime.inprocess import run_in_process  # noqa: E402
from fleet.runtime.summary import RunSummary  # noqa: E402
from fleet.scenario import Scenario  # noqa: E402
from planner.core.status import ARRIVED, FAILED  # noqa: E402

_SOLO_CACHE: dict[tuple[str, str], dict] = {}

DETOUR = 1.4
"""An AGV that drove more than this times the length of its first route is counted: a loop
or a detour a warehouse engineer would ask about (waiting aside adds a little)."""


def solo_run(scenario: Scenario, name: str) -> dict:
    """AGV ``name`` of ``scenario`` alone on the same map (cached per case and AGV)."""
    key = (scenario.source, name)
    if key not in _SOLO_CACHE:
        spec = scenario.agv(name)
        alone = replace(scenario, name=f"{scenario.name}-{name}-solo", agvs=(spec,))
        agv = run_in_process(alone).agvs[0]
        _SOLO_CACHE[key] = {"status": agv.status, "time": agv.arrival_time}
    return _SOLO_CACHE[key]


def outcome(summary: RunSummary) -> dict:
    """What must be equal in both run modes."""
    return {
        "end_reason": summary.end_reason,
        "sim_time": round(summary.sim_time, 6),
        "collisions": summary.collisions,
        "agvs": {
            a.name: [a.status, a.arrival_time, a.collisions, a.self_crossings, a.recoveries]
            for a in summary.agvs
        },
    }


def run_case(family: str, seed: int) -> dict:
    """One case in process, and its solo runs: the numbers of the report."""
    case = make_case(family, seed)
    t0 = time.perf_counter()
    summary = run_in_process(case.scenario)
    wall = time.perf_counter() - t0
    waits = {a.name: a.waiting_time for a in summary.agvs}
    solos = {a.name: solo_run(case.scenario, a.name) for a in case.scenario.agvs}
    arrived = sum(a.status == ARRIVED for a in summary.agvs)
    everyone = arrived == len(summary.agvs)
    solo_times = [s["time"] for s in solos.values()]
    solo_ok = all(t is not None for t in solo_times)
    makespan = max(a.arrival_time for a in summary.agvs) if everyone else None
    ratio_sum = ratio_longest = None
    if makespan is not None and solo_ok:
        ratio_sum = makespan / sum(solo_times)
        ratio_longest = makespan / max(solo_times)
    return {
        "case": case.name,
        "family": family,
        "seed": seed,
        "agvs": case.agvs,
        "mirror": case.mirror,
        "time_limit": case.scenario.time_limit,
        "arrived": arrived,
        "collisions": summary.collisions,
        "end_reason": summary.end_reason,
        "timed_out": summary.end_reason == "time limit",
        "sim_time": round(summary.sim_time, 3),
        "makespan": makespan,
        "sum_solo": round(sum(solo_times), 3) if solo_ok else None,
        "longest_solo": max(solo_times) if solo_ok else None,
        "makespan_over_sum_solo": None if ratio_sum is None else round(ratio_sum, 4),
        "makespan_over_longest_solo": None if ratio_longest is None else round(ratio_longest, 4),
        "solo_failures": sorted(n for n, s in solos.items() if s["time"] is None),
        "waiting": waits,
        "driven_over_route": {
            a.name: round(a.distance / a.route_length, 3) for a in summary.agvs if a.route_length
        },
        "statuses": {a.name: a.status for a in summary.agvs},
        "self_crossings": {a.name: a.self_crossings for a in summary.agvs if a.self_crossings},
        "recoveries": {a.name: a.recoveries for a in summary.agvs if a.recoveries},
        "failures": {a.name: a.failure for a in summary.agvs if a.failure},
        "outcome": outcome(summary),
        "wall_s": round(wall, 2),
    }


def _run_job(job: tuple[str, int]) -> dict:
    return run_case(*job)


def run_zenoh(case: TrafficCase, folder: Path) -> RunSummary:
    """``case`` over Zenoh: a world router and one process per AGV, from its TOML file."""
    from fleet.runtime.launcher import FleetOptions, run_fleet
    from fleet.scenario import load_scenario

    path = folder / case.file_name
    path.write_text(case.toml)
    return run_fleet(load_scenario(path), FleetOptions(scenario_arg=str(path)))


# --- the report ------------------------------------------------------------------------
def _median(values):
    return statistics.median(values) if values else None


def family_rows(results: list[dict]) -> list[dict]:
    rows = []
    for family in dict.fromkeys(r["family"] for r in results):
        runs = [r for r in results if r["family"] == family]
        agvs = sum(r["agvs"] for r in runs)
        waits = [w for r in runs for w in r["waiting"].values()]
        ratios = [r["makespan_over_sum_solo"] for r in runs if r["makespan_over_sum_solo"]]
        longest = [r["makespan_over_longest_solo"] for r in runs if r["makespan_over_longest_solo"]]
        detours = [d for r in runs for d in r["driven_over_route"].values()]
        limits = sorted({r["time_limit"] for r in runs})
        rows.append(
            {
                "family": family,
                "runs": len(runs),
                "agvs": agvs,
                "arrival_pct": 100.0 * sum(r["arrived"] for r in runs) / agvs,
                "runs_all_arrived": sum(r["arrived"] == r["agvs"] for r in runs),
                "failed_agvs": sum(s == FAILED for r in runs for s in r["statuses"].values()),
                "runs_with_collision": sum(r["collisions"] > 0 for r in runs),
                "runs_at_time_limit": sum(r["timed_out"] for r in runs),
                "median_makespan_over_sum_solo": _median(ratios),
                "worst_makespan_over_sum_solo": max(ratios) if ratios else None,
                "median_makespan_over_longest_solo": _median(longest),
                "mean_wait_s": statistics.fmean(waits) if waits else None,
                "max_wait_s": max(waits) if waits else None,
                "worst_driven_over_route": max(detours) if detours else None,
                "agvs_over_detour": sum(d > DETOUR for d in detours),
                "loops": sum(n for r in runs for n in r["self_crossings"].values()),
                "recoveries": sum(n for r in runs for n in r["recoveries"].values()),
                "solo_failures": sum(len(r["solo_failures"]) for r in runs),
                "time_limit_s": [limits[0], limits[-1]],
            }
        )
    return rows


def _f(value, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def print_table(rows: list[dict]) -> None:
    header = (
        f"{'family':<18} {'runs':>4} {'AGVs':>4} {'arrived':>7} {'all':>3} {'failed':>6} "
        f"{'coll':>4} "
        f"{'limit':>5} {'mk/sum med':>10} {'mk/sum max':>10} {'mk/long med':>11} "
        f"{'wait mean':>9} {'wait max':>8} {'drive max':>9} {f'>{DETOUR:g}x':>5} {'loops':>5} "
        f"{'recov':>5} {'solo fail':>9} {'time limit s':>12}"
    )
    print(header)
    print("-" * len(header))
    for r in rows:
        lo, hi = r["time_limit_s"]
        print(
            f"{r['family']:<18} {r['runs']:>4} {r['agvs']:>4} {r['arrival_pct']:>6.1f}% "
            f"{r['runs_all_arrived']:>3} {r['failed_agvs']:>6} {r['runs_with_collision']:>4} "
            f"{r['runs_at_time_limit']:>5} {_f(r['median_makespan_over_sum_solo'], '.3f'):>10} "
            f"{_f(r['worst_makespan_over_sum_solo'], '.3f'):>10} "
            f"{_f(r['median_makespan_over_longest_solo'], '.2f'):>11} "
            f"{_f(r['mean_wait_s'], '.1f'):>9} {_f(r['max_wait_s'], '.1f'):>8} "
            f"{_f(r['worst_driven_over_route'], '.2f'):>9} {r['agvs_over_detour']:>5} "
            f"{r['loops']:>5} {r['recoveries']:>5} "
            f"{r['solo_failures']:>9} {f'{lo:g}-{hi:g}':>12}"
        )
    print(
        "arrived: AGVs arrived of all; all: runs where every AGV arrived; failed: AGVs that gave\n"
        "up; coll: runs with a collision; limit: runs that reached their time limit; mk/sum,\n"
        "mk/long: makespan (last arrival) over the sum of the solo run times and over the longest\n"
        "solo run, runs where every AGV arrived only; wait: seconds per AGV held outside a\n"
        "passage by the traffic rule (status 'waiting'); drive max: the most an AGV drove over\n"
        f"the length of its first route (loops and detours show here); >{DETOUR:g}x: AGVs that\n"
        "drove more than that; loops: times the AGVs' driven paths crossed themselves\n"
        "(planner.core.path_metrics.self_crossings); recov: recovery behaviours the AGVs\n"
        "started after no progress (planner.nav.recovery); solo fail: AGVs that do not arrive\n"
        "alone."
    )


def targets(results: list[dict], zenoh: list[dict]) -> list[tuple[str, bool, str]]:
    agvs = sum(r["agvs"] for r in results)
    arrived = sum(r["arrived"] for r in results)
    collided = sum(r["collisions"] > 0 for r in results)
    limited = sum(r["timed_out"] for r in results)
    out = [
        ("100 % arrival", arrived == agvs, f"{arrived}/{agvs} AGVs, {100 * arrived / agvs:.1f} %"),
        ("0 collisions", collided == 0, f"{collided}/{len(results)} runs with a collision"),
        ("no run at its time limit", limited == 0, f"{limited}/{len(results)} runs"),
    ]
    if zenoh:
        same = sum(z["same"] for z in zenoh)
        out.append(
            ("Zenoh outcome = in process", same == len(zenoh), f"{same}/{len(zenoh)} runs equal")
        )
    return out


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit 2
        sys.stderr.write(f"traffic_bench: {message}\n")
        sys.exit(2)


def _families(text: str) -> list[str]:
    names = [f.strip() for f in text.split(",") if f.strip()]
    unknown = [f for f in names if f not in FAMILIES]
    if unknown or not names:
        raise argparse.ArgumentTypeError(
            f"unknown family {', '.join(unknown) or repr(text)}: choose from {','.join(FAMILIES)}"
        )
    return list(dict.fromkeys(names))


def _count(minimum: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = minimum - 1
        if value < minimum:
            raise argparse.ArgumentTypeError(f"expected an integer >= {minimum}, got {text!r}")
        return value

    return parse


def parse_args(argv=None) -> argparse.Namespace:
    parser = _Parser(description=__doc__.split("\n")[0])
    parser.add_argument("--families", type=_families, default=list(FAMILIES))
    parser.add_argument("--seeds", type=_count(1), default=5, help="seeds 0..N-1 per family")
    parser.add_argument("--workers", type=_count(1), default=1)
    parser.add_argument("--zenoh", type=_count(0), default=0, metavar="N",
                        help="also run the first N cases of each family over Zenoh")  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.add_argument("--write-toml", type=Path, metavar="DIR",
                        help="write every case as a scenario file into DIR and exit")  # fmt: skip
    return parser.parse_args(argv)


def main(argv=None) -> None:
    args = parse_args(argv)
    chosen = cases(args.families, args.seeds)
    if args.write_toml:
        try:
            args.write_toml.mkdir(parents=True, exist_ok=True)
            for case in chosen:
                (args.write_toml / case.file_name).write_text(case.toml)
        except OSError as err:
            sys.stderr.write(f"traffic_bench: cannot write {args.write_toml}: {err}\n")
            sys.exit(2)
        print(f"wrote {len(chosen)} scenarios to {args.write_toml}")
        return
    t0 = time.perf_counter()
    # the biggest cases first, so that two workers end together
    jobs = sorted(
        ((c.family, c.seed) for c in chosen),
        key=lambda j: -make_case(*j).agvs * make_case(*j).scenario.time_limit,
    )
    results: dict[tuple[str, int], dict] = {}

    def report(r: dict) -> None:
        results[(r["family"], r["seed"])] = r
        print(
            f"[{len(results)}/{len(jobs)}] {r['case']}: {r['arrived']}/{r['agvs']} arrived, "
            f"{r['collisions']} collisions, {r['end_reason']} at {r['sim_time']:g} s, "
            f"{r['wall_s']:.1f} s wall",
            file=sys.stderr,
            flush=True,
        )

    if args.workers > 1:
        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            for r in pool.imap_unordered(_run_job, jobs):
                report(r)
    else:
        for job in jobs:
            report(run_case(*job))
    ordered = [results[(c.family, c.seed)] for c in chosen]
    zenoh = []
    if args.zenoh:
        # the AGV processes import this checkout, installed or not
        os.environ["PYTHONPATH"] = os.pathsep.join(
            p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p
        )
        with tempfile.TemporaryDirectory(prefix="traffic-bench-") as folder:
            for family in args.families:
                for case in [c for c in chosen if c.family == family][: args.zenoh]:
                    t1 = time.perf_counter()
                    summary = run_zenoh(case, Path(folder))
                    local = results[(case.family, case.seed)]
                    same = outcome(summary) == local["outcome"]
                    zenoh.append({"case": case.name, "same": same, "outcome": outcome(summary)})
                    arrived = sum(a.status == ARRIVED for a in summary.agvs)
                    print(
                        f"zenoh {case.name}: {arrived}/{case.agvs} arrived, "
                        f"{summary.collisions} collisions, {summary.end_reason}, "
                        f"{'same as' if same else 'DIFFERENT from'} in process, "
                        f"{time.perf_counter() - t1:.1f} s wall",
                        file=sys.stderr,
                        flush=True,
                    )
    rows = family_rows(ordered)
    verdicts = targets(ordered, zenoh)
    if args.json:
        print(
            json.dumps(
                {
                    "cases": ordered,
                    "families": rows,
                    "zenoh": zenoh,
                    "targets": [{"target": t, "pass": ok, "value": v} for t, ok, v in verdicts],
                    "wall_s": round(time.perf_counter() - t0, 1),
                },
                indent=1,
            )
        )
        return
    print(
        f"traffic_bench: {len(ordered)} runs in process ({args.seeds} seeds per family), "
        f"{time.perf_counter() - t0:.0f} s wall with {args.workers} worker(s)"
    )
    print_table(rows)
    for what, ok, value in verdicts:
        print(f"{'PASS' if ok else 'MISS'}  {what} ({value})")


if __name__ == "__main__":
    main()
