"""The AGV node's warm-up loads every compiled kernel a run's control cycles use.

An AGV host warms one node, then forks its AGV processes: a kernel (or a signature of
one) the warm-up misses is loaded by every process on its first use, mid-run. With 50
AGVs on 2 cores that cost more than the kernels it was written to save.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

# the world's kernels, not a control cycle's: its end-of-run summary (the loop count) and
# its AGV-to-AGV contact check; the world process loads them once
WORLD_ONLY = {
    "planner.core.path_metrics._crossings",
    "fleet.runtime.agv_gaps.agv_gaps",
    "fleet.runtime.world.agv_gaps",
}

PROBE = textwrap.dedent(
    """
    import json, sys
    from numba.core.registry import CPUDispatcher
    from fleet.runtime.agv_node import AgvNode
    from fleet.runtime.inprocess import run_in_process
    from fleet.scenario import load_scenario

    def signatures():
        return {
            f"{module}.{attr}": len(obj.overloads)
            for module, loaded in list(sys.modules.items())
            if module.startswith(("planner", "fleet", "bridge"))
            for attr, obj in list(vars(loaded).items())
            if isinstance(obj, CPUDispatcher)
        }

    scenario = load_scenario(sys.argv[1])
    AgvNode(scenario, scenario.agvs[0].name).warm_up()
    before = signatures()
    run_in_process(scenario)
    after = signatures()
    print(json.dumps(sorted(k for k, n in after.items() if n != before.get(k, 0))))
    """
)


# crossing: traffic rules and tight corners; nav2-depot: a real map, replans, centring
@pytest.mark.parametrize("scenario", ["crossing", "nav2-depot"])
def test_a_run_loads_no_kernel_the_warm_up_did_not(scenario):
    out = subprocess.run(
        [sys.executable, "-c", PROBE, scenario],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    loaded_later = set(json.loads(out.stdout.strip().splitlines()[-1]))
    assert loaded_later - WORLD_ONLY == set()
