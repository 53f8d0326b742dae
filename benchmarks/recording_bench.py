"""Recorder throughput, its cost on a run, and analysis time on a large recording.

1. Writing: ``RecordingWriter.write`` of typical ``AgvState`` messages (encode +
   MCAP) and ``write_payload`` of the same messages pre-encoded (what a bus
   recorder does), messages/s.
2. A run: the in-process ``warehouse`` scenario without and with recording
   (ticks/s and the ratio).
3. Reading and analysing: a synthetic recording of AGVS x TICKS AGV states
   plus one ``world/tick`` per tick carrying every AGV (as the world sends it),
   on a 100 x 100 map: ``open_recording`` and ``analyze`` times against the
   target (< 10 s for 1 M messages).

Prints, never asserts. Run from the repository root:
``python benchmarks/recording_bench.py [--agvs 50] [--ticks 20000]``.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from pathlib import Path

from bridge import keys
from bridge.messages import AgvState, MapMsg, Tick, to_dict
from fleet.runtime.inprocess import run_in_process
from fleet.scenario import load_scenario
from recordings.analysis import analyze
from recordings.reader import open_recording
from recordings.writer import RecordingWriter, record_sink

WRITE_MESSAGES = 200_000
ANALYZE_TARGET_S = 10.0


def agv_state(i: int, k: int) -> AgvState:
    """A typical state: AGV i circling at tick k, full-precision floats."""
    angle = 0.01 * k + i
    return AgvState(
        name=f"agv{i}",
        tick=k,
        x=50 + 20 * math.cos(angle),
        y=50 + 20 * math.sin(angle),
        theta=math.remainder(angle + math.pi / 2, math.tau),
        vx=0.2,
        vy=0.0,
        omega=0.01,
        radius=0.3,
        target=[50 + 20 * math.cos(angle + 0.3), 50 + 20 * math.sin(angle + 0.3)],
        plan_time_ms=0.4 + 0.1 * math.sin(k),
    )


def writer(path: Path) -> RecordingWriter:
    return RecordingWriter(path, scenario_name="bench", scenario_text="", run_facts={})


def bench_write(folder: Path) -> None:
    states = [agv_state(k % 50, k // 50) for k in range(WRITE_MESSAGES)]
    payloads = [json.dumps(to_dict(s), separators=(",", ":")).encode() for s in states]
    for label, write_all in (
        ("write(msg)", lambda w: [w.write(keys.agv_state(s.name), s, s.tick) for s in states]),
        (
            "write_payload",
            lambda w: [
                w.write_payload(keys.agv_state(s.name), p, s.tick)
                for s, p in zip(states, payloads, strict=True)
            ],
        ),
    ):
        path = folder / "write.mcap"
        t0 = time.perf_counter()
        with writer(path) as w:
            write_all(w)
        seconds = time.perf_counter() - t0
        print(
            f"  {label:<14} {WRITE_MESSAGES / seconds:>10,.0f} msgs/s  "
            f"({path.stat().st_size / WRITE_MESSAGES:.0f} B/msg on disk)"
        )


def bench_run(folder: Path) -> None:
    scenario = load_scenario("warehouse")
    run_in_process(scenario)  # warm-up: numba kernels and caches
    t0 = time.perf_counter()
    plain = run_in_process(scenario)
    bare = plain.ticks / (time.perf_counter() - t0)
    path = folder / "warehouse.mcap"
    t0 = time.perf_counter()
    with writer(path) as w:
        summary = run_in_process(scenario, outbox=record_sink(w, scenario.dt))
        w.finish(summary.to_json())
    recorded = summary.ticks / (time.perf_counter() - t0)
    messages = len(open_recording(path).records)
    print(f"  without recording  {bare:8.1f} ticks/s")
    print(f"  with recording     {recorded:8.1f} ticks/s  ({messages} messages)")
    print(f"  ratio              {recorded / bare:8.2f}")


def synthetic(path: Path, agvs: int, ticks: int) -> int:
    rows = ["." * 100 for _ in range(100)]
    rows[50] = "." * 40 + "#" * 20 + "." * 40
    count = 0
    with writer(path) as w:
        w.write(keys.WORLD_MAP, MapMsg("bench", 100, 100, 1.0, rows), 0)
        for k in range(ticks):
            states = [agv_state(i, k) for i in range(agvs)]
            w.write(keys.WORLD_TICK, Tick(k, round(k * 0.1, 9), states), k * 100_000_000)
            for s in states:
                w.write(keys.agv_state(s.name), s, k * 100_000_000)
            count += 1 + agvs
        w.finish({"scenario": "bench"})
    return count + 1


def bench_analyze(folder: Path, agvs: int, ticks: int) -> None:
    path = folder / "large.mcap"
    t0 = time.perf_counter()
    count = synthetic(path, agvs, ticks)
    print(
        f"  wrote {count:,} messages ({agvs} AGVs x {ticks} ticks + ticks) in "
        f"{time.perf_counter() - t0:.1f} s, {path.stat().st_size / 1e6:.0f} MB"
    )
    t0 = time.perf_counter()
    rec = open_recording(path)
    read = time.perf_counter() - t0
    run = analyze(rec)
    total = time.perf_counter() - t0
    verdict = "PASS" if total < ANALYZE_TARGET_S else "MISS"
    print(f"  open_recording     {read:6.2f} s  ({len(rec.records) / read:,.0f} msgs/s)")
    print(f"  analyze            {total - read:6.2f} s  (decodes world/tick only)")
    print(f"  total              {total:6.2f} s  target < {ANALYZE_TARGET_S:.0f} s: {verdict}")
    print(f"  ({len(run.agvs)} AGVs analysed, run time {run.run_time:.0f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agvs", type=int, default=50)
    parser.add_argument("--ticks", type=int, default=20_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        print(f"recorder throughput ({WRITE_MESSAGES:,} AgvState messages):")
        bench_write(folder)
        print("in-process warehouse run:")
        bench_run(folder)
        print("analysis of a large recording:")
        bench_analyze(folder, args.agvs, args.ticks)


if __name__ == "__main__":
    main()
