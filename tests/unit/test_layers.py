"""The packages of mrmp point one way: every import (even one inside a function) follows the layer table.

``ALLOWED`` is the table of the README's Layout section: for each package, the
packages it may import. The test reads every module's imports with :mod:`ast`
and fails on an import the table does not allow; the table itself must have no
cycle, so that no two packages can ever import each other.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable, Mapping
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2] / "src" / "mrmp"

ALLOWED: dict[str, frozenset[str]] = {
    "core": frozenset(),
    "search": frozenset({"core"}),
    "protocol": frozenset({"core"}),
    "io": frozenset({"core"}),
    "policies": frozenset({"core", "search"}),
    "robot": frozenset({"core", "search", "protocol", "policies"}),
    "centralized": frozenset({"core", "search", "policies"}),
    "sim": frozenset({"core", "search", "protocol", "policies", "robot"}),
    "live": frozenset({"core", "search", "protocol", "policies", "robot", "centralized", "sim", "io"}),
    "experiments": frozenset({"core", "search", "policies", "centralized", "sim", "io"}),
    "bench": frozenset({"core", "io", "experiments"}),
    "viz": frozenset({"core", "io", "bench"}),
    "cli": frozenset({"core", "search", "policies", "centralized", "sim", "live", "io", "experiments", "bench", "viz"}),
    "api": frozenset({"core", "policies", "centralized", "sim", "io", "experiments", "viz"}),
    "__main__": frozenset({"cli"}),
    "__init__": frozenset({"api"}),
}
"""Each package (or top-level module) of ``mrmp`` and the packages it may import."""

Edge = tuple[str, str, str]
"""An import: (importing package, imported package, importing module's path)."""


def package_of(module: str) -> str | None:
    """The package of ``mrmp`` a dotted module name belongs to (None outside ``mrmp``).

    >>> package_of("mrmp.sim.rounds"), package_of("mrmp"), package_of("yaml")
    ('sim', '__init__', None)
    """
    parts = module.split(".")
    if parts[0] != "mrmp":
        return None
    return parts[1] if len(parts) > 1 else "__init__"


def imported_modules(source: str) -> list[str]:
    """Every absolute module an import statement of ``source`` names, at any depth (functions included).

    >>> imported_modules("import os\\ndef f():\\n    from mrmp.sim import rounds\\n")
    ['os', 'mrmp.sim']
    """
    names: list[str] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
    return names


def package_edges(root: Path = SOURCE) -> list[Edge]:
    """Every import between two different packages of the source tree under ``root``."""
    edges: list[Edge] = []
    for path in sorted(root.rglob("*.py")):
        relative = path.relative_to(root)
        importer = relative.parts[0] if len(relative.parts) > 1 else relative.stem
        for module in imported_modules(path.read_text(encoding="utf-8")):
            imported = package_of(module)
            if imported is not None and imported != importer:
                edges.append((importer, imported, str(relative)))
    return edges


def forbidden(edges: Iterable[Edge], allowed: Mapping[str, frozenset[str]]) -> list[str]:
    """The imports among ``edges`` that ``allowed`` does not permit, one line each."""
    return [
        f"{where}: {importer} imports {imported}"
        for importer, imported, where in edges
        if imported not in allowed.get(importer, frozenset())
    ]


def cycle(allowed: Mapping[str, Iterable[str]]) -> list[str] | None:
    """A cycle of the dependency table (a list of packages, first repeated last), or None.

    >>> cycle({"a": {"b"}, "b": set()}) is None
    True
    >>> cycle({"a": {"b"}, "b": {"a"}})
    ['a', 'b', 'a']
    """
    state: dict[str, str] = {}

    def visit(node: str, trail: list[str]) -> list[str] | None:
        state[node] = "open"
        for target in sorted(allowed.get(node, ())):
            if state.get(target) == "open":
                return [*trail[trail.index(target):], target] if target in trail else [node, target]
            if target not in state:
                found = visit(target, [*trail, target])
                if found is not None:
                    return found
        state[node] = "done"
        return None

    for start in sorted(allowed):
        if start not in state:
            found = visit(start, [start])
            if found is not None:
                return found
    return None


def test_every_import_follows_the_layer_table() -> None:
    edges = package_edges()
    assert edges, "no imports found: wrong source folder?"
    assert forbidden(edges, ALLOWED) == []


def test_every_package_is_in_the_table() -> None:
    packages = {path.name for path in SOURCE.iterdir() if (path / "__init__.py").exists()}
    modules = {path.stem for path in SOURCE.glob("*.py")} - {"__init__", "__main__", "cli", "api"}
    assert packages | {"cli", "api", "__main__", "__init__"} == set(ALLOWED) and not modules


def test_the_layer_table_has_no_cycle() -> None:
    assert cycle(ALLOWED) is None


def test_the_checker_catches_a_back_edge(tmp_path: Path) -> None:
    """A synthetic tree in which io imports bench inside a function, and bench imports io."""
    for package, text in {
        "io": "def load():\n    from mrmp.bench.runner import run_bench\n",
        "bench": "from mrmp.io import load\n",
        "core": "import json\n",
    }.items():
        (tmp_path / package).mkdir()
        (tmp_path / package / "__init__.py").write_text("")
        (tmp_path / package / "module.py").write_text(text)
    edges = package_edges(tmp_path)
    assert sorted(edges) == [("bench", "io", "bench/module.py"), ("io", "bench", "io/module.py")]
    assert forbidden(edges, ALLOWED) == ["io/module.py: io imports bench"]
    with_back_edge = {**ALLOWED, "io": ALLOWED["io"] | {"bench"}}
    assert cycle(with_back_edge) is not None
