"""A sweep's folder: its recordings and ``sweep.json``, the list of the runs it holds.

``sweep.json`` is written before the first run: which scenario, which keys and values,
and each run's values and recording name. It says which recordings of the folder
belong to the sweep (a folder swept again with other keys keeps the old recordings,
but only the new sweep's are analysed) and lets ``agv-fleet analyze DIR`` read the
folder as ``sweep`` does, a sweep cut short included.
"""

from __future__ import annotations

import json
from pathlib import Path

from fleet.sweep.grid import SweepRun
from fleet.sweep.keys import Varied
from fleet.sweep.runner import recording_path
from planner.core.errors import BadInputError
from recordings.analysis import analyze
from recordings.reader import Recording, open_recording
from recordings.sweep_report import SweepEntry

MANIFEST = "sweep.json"


class SweepFolderError(BadInputError):
    """A folder that is not a sweep's, or a ``sweep.json`` that cannot be read."""


def write_manifest(
    out: Path, scenario: str, vary: list[Varied], over: list[Varied], runs: list[SweepRun]
) -> None:
    out.mkdir(parents=True, exist_ok=True)
    manifest = {
        "scenario": scenario,
        "vary": {v.key: list(v.values) for v in vary},
        "over": {v.key: list(v.values) for v in over},
        "runs": [
            {"variant": r.variant, "sample": r.sample, "recording": recording_path(out, r).name}
            for r in runs
        ],
    }
    (out / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")


def is_sweep_folder(path: Path) -> bool:
    return path.is_dir() and (path / MANIFEST).is_file()


def read_manifest(folder: Path) -> dict:
    try:
        manifest = json.loads((folder / MANIFEST).read_text())
        if not isinstance(manifest.get("runs"), list):
            raise ValueError("no list of runs")
        return manifest
    except FileNotFoundError:
        raise SweepFolderError(f"{folder} is not a sweep folder (no {MANIFEST})") from None
    except (OSError, ValueError, AttributeError) as err:
        raise SweepFolderError(f"{folder / MANIFEST} cannot be read: {err}") from None


def sweep_entry(
    variant: dict, sample: dict, path: Path, rec: Recording, reused: bool
) -> SweepEntry:
    """A run of a sweep, measured from its recording by ``recordings.analysis``."""
    run = analyze(rec).to_json()
    run.pop("agvs")
    return SweepEntry(variant, sample, str(path), reused, run)


def folder_entries(folder: Path) -> tuple[list[SweepEntry], int, list[str]]:
    """The finished runs listed in a sweep folder's ``sweep.json`` (measured from their
    recordings), how many listed runs have no finished recording yet, and the sample keys."""
    manifest = read_manifest(folder)
    entries, missing = [], 0
    for item in manifest["runs"]:
        try:
            path = folder / str(item["recording"])
            variant, sample = dict(item["variant"]), dict(item["sample"])
        except (KeyError, TypeError, ValueError) as err:
            raise SweepFolderError(f"{folder / MANIFEST}: a run entry lacks {err}") from None
        rec = open_recording(path) if path.is_file() else None
        if rec is None or rec.result is None or rec.truncated:
            missing += 1
            continue
        entries.append(sweep_entry(variant, sample, path, rec, reused=True))
    return entries, missing, list(manifest.get("over", {}))
