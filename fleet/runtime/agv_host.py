"""Several AGV processes from one start-up: load once, then fork one process per AGV.

Starting Python, numpy, numba and the planner's compiled kernels costs about
half a second of CPU per process; for 50 AGVs on 2 cores that is 15 s before
the first tick. The host pays it once, warms every kernel, then forks one
child per AGV *before any Zenoh session exists* (forking a process that has
a session is unsafe), and each child opens its own session. The children die
with the host (PR_SET_PDEATHSIG) and the host ends them by PID on SIGTERM or
Ctrl-C, so none is ever left behind.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal

from setproctitle import setproctitle

from bridge.bus import Bus
from bridge.log import say
from bridge.session import CONNECT_TIMEOUT_S, Login, open_client
from fleet import exit_codes
from fleet.runtime.agv_node import AgvNode
from fleet.runtime.agv_process import serve_agv
from fleet.runtime.world_watch import DEFAULT_GRACE_S
from fleet.scenario import Scenario
from planner.core.errors import AgvFleetError

_PR_SET_PDEATHSIG = 1


def serve_agvs(
    scenario: Scenario,
    names: list[str],
    connect: str,
    prefix: str,
    *,
    connect_timeout: float = CONNECT_TIMEOUT_S,
    zenoh_config: str | None = None,
    logins: dict[str, Login] | None = None,
    grace: float = DEFAULT_GRACE_S,
    exits_fd: int | None = None,
) -> int:
    """Run every named AGV, each in its own process (logged in as ``logins[name]``
    when given); the worst exit status. ``exits_fd``: a pipe to the launcher, told at
    once of every AGV process that ends abnormally (see ``tell_exit``)."""
    AgvNode(scenario, names[0]).warm_up()  # also builds the map's shared layers
    logins = logins or {}
    options = (connect, prefix, connect_timeout, zenoh_config, grace)
    if len(names) == 1 and exits_fd is None:  # nobody to tell: this process is the AGV
        _set_title(process_title(names[0]))
        return _serve_one(scenario, names[0], *options, logins.get(names[0]))
    children: dict[int, str] = {}
    for name in names:
        pid = os.fork()
        if pid == 0:  # the child: no Zenoh session exists yet in this process
            code = exit_codes.NOT_SUCCEEDED
            try:
                signal.signal(signal.SIGINT, signal.SIG_DFL)
                signal.signal(signal.SIGTERM, signal.SIG_DFL)
                _prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
                _set_title(process_title(name))
                code = _serve_one(scenario, name, *options, logins.get(name))
            except BaseException as err:  # os._exit below would swallow it silently
                say(f"agv-fleet agv {name}: crashed: {err!r}")
            finally:
                os._exit(code)
        children[pid] = name
    _set_title(f"agv-fleet agv-host {scenario.name} ({len(names)} AGVs)")
    return _wait_for(children, exits_fd)


def _set_title(title: str) -> None:
    # SPT_NOENV: keep /proc/PID/environ intact (a title fits in the argv area of the
    # host's long command line); it must be set before the first setproctitle call
    os.environ.setdefault("SPT_NOENV", "1")
    setproctitle(title)


def process_title(name: str) -> str:
    """How the process of AGV ``name`` reads in ps and top (``pgrep -fx`` finds it)."""
    return f"agv-fleet agv {name}"


def _serve_one(scenario, name, connect, prefix, connect_timeout, zenoh_config, grace, login):
    try:
        with open_client(connect, connect_timeout, zenoh_config, login) as session:
            serve_agv(scenario, name, Bus(session, prefix), connect, grace)
    except AgvFleetError as err:
        say(f"agv-fleet agv {name}: {err}")
        return exit_codes.for_error(err)
    except KeyboardInterrupt:
        return exit_codes.INTERRUPTED
    return exit_codes.OK


def exit_reason(code: int) -> str:
    """How a process ended, from its exit code (negative: the signal that killed it)."""
    return f"killed by signal {-code}" if code < 0 else f"ended with status {code}"


def tell_exit(exits_fd: int | None, name: str, code: int) -> None:
    """Write "NAME<TAB>why" on the launcher's pipe (``WorldServer`` fails the AGV at once,
    rather than when its liveliness lease and the grace period have run out)."""
    if exits_fd is None:
        return
    with contextlib.suppress(OSError):  # the launcher is gone: nobody to tell
        os.write(exits_fd, f"{name}\t{exit_reason(code)}\n".encode())


def _wait_for(children: dict[int, str], exits_fd: int | None = None) -> int:
    """Wait for every child; on SIGTERM or Ctrl-C end them all by PID first."""

    ending = []

    def end_children(signum, frame):
        ending.append(signum)
        for pid in list(children):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)

    signal.signal(signal.SIGTERM, end_children)
    signal.signal(signal.SIGINT, end_children)
    worst = 0
    while children:
        try:
            pid, status = os.wait()
        except ChildProcessError:
            break
        name = children.pop(pid, None)
        code = os.waitstatus_to_exitcode(status)
        if code != 0 and not ending:
            tell_exit(exits_fd, name, code)
        if code < 0 and not ending:
            say(f"agv-fleet agv {name}: {exit_reason(code)}")
        worst = max(worst, 128 - code if code < 0 else code)
    return worst


def _prctl(option: int, value) -> None:
    # not on Linux: no prctl, and the host still ends its children itself
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(option, value, 0, 0, 0)
