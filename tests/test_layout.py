"""The layers of DESIGN.md, checked on the source: imports only run downwards, no import
circle, no private name used across modules, and modules small enough to read.

Every import statement counts, wherever it stands (in a function, under TYPE_CHECKING):
a circle that only type checking closes is still a circle for the reader.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("planner", "bridge", "recordings", "fleet")
# a package may import those left of it, never those right of it
PACKAGE_ORDER = ("planner", "bridge", "recordings", "fleet")
# planner's sub-packages, lowest first: each imports only itself and those before it
PLANNER_ORDER = ("core", "maps", "route", "local", "traffic", "nav")
MAX_LINES = 450
MAX_PLANNER_TOP_MODULES = 8


def modules() -> dict[str, Path]:
    out = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            out[name] = path
    return out


MODULES = modules()


def imports(path: Path) -> list[tuple[str, list[str], int]]:
    """(module, imported names, line) of every import of one of ours in ``path``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(a.name, [], node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.append((node.module, [a.name for a in node.names], node.lineno))
    return [(m, names, line) for m, names, line in found if m.split(".")[0] in PACKAGES]


def target(module: str, name: str) -> str:
    """The module an ``from module import name`` reaches: a sub-module or ``module``."""
    return f"{module}.{name}" if f"{module}.{name}" in MODULES else module


def edges() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for name, path in MODULES.items():
        for module, names, _ in imports(path):
            for reached in [target(module, n) for n in names] or [module]:
                if reached in MODULES and reached != name:
                    graph[name].add(reached)
    return graph


def rank(module: str) -> tuple[int, int]:
    parts = module.split(".")
    outer = PACKAGE_ORDER.index(parts[0])
    if parts[0] == "planner" and len(parts) > 1 and parts[1] in PLANNER_ORDER:
        return outer, PLANNER_ORDER.index(parts[1]) + 1
    return outer, 0


def test_imports_only_run_downwards():
    wrong = []
    for name, path in MODULES.items():
        for module, _, line in imports(path):
            if module not in MODULES and module.rsplit(".", 1)[0] not in MODULES:
                continue
            mine, theirs = rank(name), rank(module)
            upward = theirs[0] > mine[0] or (theirs[0] == mine[0] == 0 and theirs[1] > mine[1])
            if upward:
                wrong.append(f"{path.relative_to(ROOT)}:{line} imports {module}")
    assert not wrong, "imports that run upwards:\n" + "\n".join(wrong)


def test_no_import_circle():
    graph = edges()
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    circles = []

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                circles.append(" -> ".join([*stack[stack.index(nxt) :], nxt]))
            elif nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])
    assert not circles, "import circles:\n" + "\n".join(circles)


def test_no_private_name_across_modules():
    wrong = [
        f"{path.relative_to(ROOT)}:{line} imports {n} from {module}"
        for name, path in MODULES.items()
        for module, names, line in imports(path)
        for n in names
        if n.startswith("_") and target(module, n) != name
    ]
    assert not wrong, "private names imported across modules:\n" + "\n".join(wrong)


@pytest.mark.parametrize("package", PACKAGES)
def test_modules_are_small(package):
    long = {
        str(p.relative_to(ROOT)): n
        for name, p in MODULES.items()
        if name.split(".")[0] == package and (n := len(p.read_text().splitlines())) > MAX_LINES
    }
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_planner_is_sub_packages():
    top = [p.name for p in (ROOT / "planner").glob("*.py")]
    assert len(top) <= MAX_PLANNER_TOP_MODULES, top
    assert {
        p.name for p in (ROOT / "planner").iterdir() if p.is_dir() and p.name != "__pycache__"
    } == set(PLANNER_ORDER)


def test_the_checks_see_a_violation(tmp_path):
    """The rules above find what they look for: a made-up upward import is upward."""
    assert rank("planner.core.errors") < rank("planner.maps.grid") < rank("planner.nav.fusion")
    assert rank("planner.nav.fusion") < rank("bridge.messages") < rank("fleet.cli.main")
    assert "planner.maps.grid" in edges()["planner.maps.costmap"]


def test_every_package_is_installed():
    """pyproject.toml lists the packages a plain ``pip install .`` ships: a sub-package
    missing there works in a checkout and the editable install, and fails installed."""
    import tomllib

    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    found = {name for name, path in MODULES.items() if path.name == "__init__.py"}
    assert found - listed == set(), "packages pyproject.toml does not install"
