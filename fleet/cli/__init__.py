"""The ``agv-fleet`` command line: one module per command, errors as one line."""

from fleet.cli.main import main

__all__ = ["main"]
