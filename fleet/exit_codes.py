"""One exit-code convention for every ``agv-fleet`` command (the README's table)."""

from __future__ import annotations

from planner.core.errors import AgvFleetError, BadInputError, EnvironmentFailure

OK = 0
NOT_SUCCEEDED = 1  # the run did not succeed (an AGV did not arrive, a collision), or no path
BAD_INPUT = 2  # the input cannot be used; argparse's usage errors exit 2 as well
ENVIRONMENT = 3  # the machine, the bus or another process failed
INTERRUPTED = 130  # Ctrl-C or SIGTERM (128 + SIGINT, as shells report it)


def for_error(err: AgvFleetError | OSError) -> int:
    """The exit status of a command that ended with ``err``."""
    if isinstance(err, BadInputError):
        return BAD_INPUT
    if isinstance(err, EnvironmentFailure | OSError):
        return ENVIRONMENT
    return NOT_SUCCEEDED
