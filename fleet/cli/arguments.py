"""Argument types and checks shared by the commands."""

from __future__ import annotations

import argparse

from planner.core.errors import BadInputError


class UsageError(BadInputError):
    """Options that cannot go together, found after parsing."""


def positive_int(text: str) -> int:
    """A whole number >= 1 (a count of workers, maps, runs)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text}")
    return value


def positive_float(text: str) -> float:
    """An argparse type: a number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def non_negative_float(text: str) -> float:
    """An argparse type: a finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (0 <= value < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text}")
    return value


FOXGLOVE_PORT = 8765
"""Foxglove's default WebSocket port: ``--foxglove`` without a number."""


def tcp_port(text: str) -> int:
    """An argparse type: a TCP port, 0 for one the OS picks."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a port number: {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"not a TCP port: {text}")
    return value


def add_foxglove_options(parser: argparse.ArgumentParser, what: str) -> None:
    """``--foxglove [PORT]`` and ``--foxglove-host``, for ``run`` and ``replay``."""
    parser.add_argument(
        "--foxglove",
        nargs="?",
        type=tcp_port,
        const=FOXGLOVE_PORT,
        metavar="PORT",
        help=(
            f"serve {what} over the Foxglove WebSocket protocol (foxglove.websocket.v1) on "
            f"PORT (default {FOXGLOVE_PORT}; 0: a free port), kept up after it until Ctrl-C"
        ),
    )
    parser.add_argument(
        "--foxglove-host",
        default="127.0.0.1",
        metavar="HOST",
        help="with --foxglove: the address to listen on (default 127.0.0.1)",
    )
