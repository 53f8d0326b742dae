"""How fast a shift runs: the built-in ``warehouse-shift`` with N AGVs (``agvs.count``),
in process and over Zenoh side by side, as times faster than real time.

Each mode is ``agv-fleet run`` in a subprocess (``--no-record --json``): the Zenoh mode
is the world router and one process per AGV, the in-process mode the same world and AGV
step code with no bus (the baseline). Printed per mode: simulated s, wall s of the run
(its summary's ``wall_time``), x real time, tasks delivered, and the Zenoh mode's ratio
to the in-process one. Both modes must deliver the same tasks (the same decisions).

The issue's target: a one-hour shift with 16 AGVs at least 20x faster than real time
over Zenoh on 2 cores. This VM's speed drifts, and other work shares its cores: the
load average is printed before and after.

Run from the repository root:
``python benchmarks/shift_bench.py [--agvs 16] [--shift 3600] [--seed 1]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import tomlkit

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fleet.builtin import builtin_scenarios  # noqa: E402
from fleet.sweep.keys import apply  # noqa: E402

CLI = [sys.executable, "-m", "fleet.cli", "run", "--no-record", "--json", "--quiet"]


def shift_file(folder: Path, agvs: int, shift: float, seed: int) -> Path:
    doc = tomlkit.parse(builtin_scenarios()["warehouse-shift"].read_text())
    apply(doc, "agvs.count", agvs)
    apply(doc, "tasks.shift", shift)
    apply(doc, "tasks.generator.seed", seed)
    path = folder / f"warehouse-shift-{agvs}.toml"
    path.write_text(tomlkit.dumps(doc))
    return path


def run(path: Path, *mode: str) -> dict:
    out = subprocess.run([*CLI, str(path), *mode], capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise SystemExit(f"agv-fleet run {' '.join(mode)} exited {out.returncode}: {out.stderr}")
    return json.loads(out.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agvs", type=int, default=16)
    parser.add_argument("--shift", type=float, default=3600.0)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as folder:
        path = shift_file(Path(folder), args.agvs, args.shift, args.seed)
        results = {"in process": run(path, "--in-process"), "Zenoh": run(path)}
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    print(f"warehouse-shift, {args.agvs} AGVs, a shift of {args.shift:g} s, seed {args.seed}")
    print(f"{'mode':<11} {'simulated s':>11} {'wall s':>8} {'x real time':>11} {'delivered':>9}")
    for mode, r in results.items():
        speed = r["sim_time"] / r["wall_time"]
        delivered = r["tasks"]["delivered"]
        sim, wall = r["sim_time"], r["wall_time"]
        print(f"{mode:<11} {sim:>11.0f} {wall:>8.1f} {speed:>11.1f} {delivered:>9}")
    base, zenoh = results["in process"], results["Zenoh"]
    print(f"Zenoh / in process wall time: {zenoh['wall_time'] / base['wall_time']:.2f}")
    if base["tasks"] != zenoh["tasks"]:
        raise SystemExit("the two modes delivered different tasks: they must decide the same")


if __name__ == "__main__":
    main()
