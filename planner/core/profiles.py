"""Planner profiles: the paper exactly, or the default built on it.

``paper`` is Guo et al. 2023 as DESIGN.md makes it precise (safety distance to
obstacle-cell centres, no inflation, free heading, brake when nothing is
admissible): the paper reproduction runs it. ``default`` is the same fusion
planner made footprint-safe, robust and fleet-aware; the README lists every
difference with its measured effect.
"""

from __future__ import annotations

DEFAULT = "default"
PAPER = "paper"
PROFILES = (DEFAULT, PAPER)


def check_profile(profile: str) -> str:
    """``profile`` if it is one of ``PROFILES``; a ValueError naming the choices otherwise."""
    if profile not in PROFILES:
        raise ValueError(
            f"unknown planner profile {profile!r}: choose one of {', '.join(PROFILES)}"
        )
    return profile
