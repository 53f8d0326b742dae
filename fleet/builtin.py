"""Where the built-in scenarios and bundled maps are, installed or in a checkout."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

MAP_SUFFIXES = (".txt", ".map", ".yaml", ".yml")


def _data_dir() -> Path:
    """The installed data package, or the repository's scenarios/ in a plain checkout."""
    try:
        return Path(str(resources.files("fleet.builtin_scenarios")))
    except ModuleNotFoundError:
        return Path(__file__).resolve().parents[1] / "scenarios"


def bundled_maps() -> dict[str, Path]:
    """Bundled map files by name (file stem)."""
    folder = _data_dir() / "maps"
    return {p.stem: p for p in sorted(folder.iterdir()) if p.suffix in MAP_SUFFIXES}


def resolve_map(name_or_path: str) -> Path:
    """A map file path as given, or else the bundled map of that name."""
    path = Path(name_or_path)
    if path.exists():
        return path
    return bundled_maps().get(name_or_path, path)


def builtin_scenarios() -> dict[str, Path]:
    """Built-in scenario files by name (file stem)."""
    return {p.stem: p for p in sorted(_data_dir().glob("*.toml"))}
