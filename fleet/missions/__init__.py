"""Shifts of transport work: stations, requests, and the rule that gives them to AGVs.

``spec`` holds what a scenario says (stations, the generator, per-AGV task lists),
``format`` reads it from the scenario file, ``requests`` makes the requests of a shift,
``dispatch`` is the assignment rule. All of it is pure and deterministic: the world
runs it (``fleet.runtime.missions``) in both run modes. docs/missions.md has the rules.
"""
