"""The grid of a sweep: every combination of the ``--vary`` values, each a checked scenario.

A variant is made by editing the parsed TOML document of the scenario file and parsing
the edited text again through ``fleet.scenario.parse_scenario``: every check a
scenario file gets, a variant gets, and the text recorded with its run is the file as
it was run (comments kept). The whole grid is built, and so checked, before any run.

``--over`` keys are varied the same way, but their values are samples rather than
variants: the statistics of a variant are taken over its runs across them (walker
timings, random-map seeds).
"""

from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass
from pathlib import Path

import tomlkit
from tomlkit.exceptions import TOMLKitError

from fleet.scenario import Scenario, load_scenario, parse_scenario
from fleet.sweep.keys import SweepKeyError, Varied, apply
from fleet.toml_schema import ScenarioError

MAX_RUNS = 100_000
NAME_LIMIT = 80  # characters of a recording's name that describe its values


@dataclass(frozen=True)
class SweepRun:
    """One run of a sweep: its values and the scenario they make."""

    variant: dict  # the --vary keys and their values
    sample: dict  # the --over keys and their values
    scenario: Scenario

    @property
    def values(self) -> dict:
        return {**self.variant, **self.sample}

    @property
    def name(self) -> str:
        """A file name for the run's recording, the same for the same values: readable
        values and a digest of them (two values can look alike once made file-safe)."""
        text = "_".join(f"{k.split('.')[-1]}={_short(v)}" for k, v in self.values.items())
        safe = "".join(c if c.isalnum() or c in "-.=" else "_" for c in text)[:NAME_LIMIT]
        digest = hashlib.sha1(json.dumps(self.values, sort_keys=True).encode()).hexdigest()
        return f"{safe or 'run'}-{digest[:8]}"


def _short(value) -> str:
    return json.dumps(value) if not isinstance(value, str) else value


def build_grid(scenario_arg: str, vary: list[Varied], over: list[Varied]) -> list[SweepRun]:
    """Every run of the sweep, ``vary`` combinations outside, ``over`` ones inside."""
    keys = [v.key for v in (*vary, *over)]
    repeated = sorted({k for k in keys if keys.count(k) > 1})
    if repeated:
        raise SweepKeyError(f"key {repeated[0]} is varied twice")
    count = 1
    for v in (*vary, *over):
        count *= len(v.values)
    if count > MAX_RUNS:
        raise SweepKeyError(f"the grid has {count} runs (at most {MAX_RUNS})")
    base = load_scenario(scenario_arg)
    path = Path(base.path) if base.path else None
    runs = []
    for variant_values in itertools.product(*(v.values for v in vary)):
        variant = dict(zip((v.key for v in vary), variant_values, strict=True))
        for sample_values in itertools.product(*(v.values for v in over)):
            sample = dict(zip((v.key for v in over), sample_values, strict=True))
            scenario = variant_scenario(base.source, path, {**variant, **sample})
            runs.append(SweepRun(variant, sample, scenario))
    return runs


def variant_scenario(text: str, path: Path | None, values: dict) -> Scenario:
    """The scenario ``text`` with each dotted key set to its value, checked as a file is."""
    try:
        doc = tomlkit.parse(text)
    except TOMLKitError as err:  # tomllib read it already; tomlkit is stricter in places
        raise ScenarioError(f"{path}: cannot be edited for a sweep: {err}") from None
    for key, value in values.items():
        apply(doc, key, value)
    shown = ", ".join(f"{k}={_short(v)}" for k, v in values.items())
    try:
        return parse_scenario(tomlkit.dumps(doc), path)
    except ScenarioError as err:
        raise SweepKeyError(f"variant {shown}: {err}") from None
