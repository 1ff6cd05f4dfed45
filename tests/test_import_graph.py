"""The import graph of ``src/gaitopt`` keeps the layering of docs/architecture.md.

Every module is parsed with :mod:`ast` (nothing is imported), and every ``import`` of a
gaitopt module is an edge: at module level, in a class body, inside a function (a *lazy*
import) and under ``if TYPE_CHECKING:``. The rules:

* **Layering.** Each package imports only itself and the packages above it in the table of
  docs/architecture.md (``robot`` < ``dynamics`` < ``ocp`` < ``gait`` < ``analysis`` <
  ``study`` < ``viz`` < ``cli``); the top-level helpers (``fileio``, ``units``, ``codegen``,
  ``process_memory``) are below them all and import no gaitopt module. The front door
  (``gaitopt/__init__.py``, ``gaitopt/__main__.py``) is outside the layering: it re-exports
  from every package. ``TYPE_CHECKING`` imports count here too: an annotation that names a
  lower layer's type is a dependency on that layer's concept all the same.
* **The bottom of gait/.** Its sub-packages are concepts (docs/architecture.md, "gait/ by
  concept"); the two at the bottom, the gait record (numpy only) and the contact sequences,
  import no other module of ``gait/``.
* **Lazy imports** (inside a function) are allowed only in ``viz/`` and ``cli/``, where they
  keep ``gaitopt solve`` from loading the figures or the study, and they follow the layering
  like any other.
* **No cycles** among modules, lazy imports included: a module never imports, directly or
  through others, a module that imports it. Imports under ``if TYPE_CHECKING:`` are left out
  of this one rule: they never run, and they are how an annotation names a type of a module
  that imports this one (inside one package; across packages the layering already forbids
  them).
* **No private names across modules**: no ``from x import _name`` and no ``module._name``
  on an imported gaitopt module (a dunder such as ``__version__`` is public).

Each assertion message names the file and line of every offence, and a cycle as a path.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "src"
PACKAGE = "gaitopt"

#: The packages from the top of docs/architecture.md's table down: each may import only
#: itself and the ones before it.
LAYERS: tuple[str, ...] = ("robot", "dynamics", "ocp", "gait", "analysis", "study", "viz",
                           "cli")
#: Top-level helper modules, below every package; they import no gaitopt module.
HELPERS: frozenset[str] = frozenset({"fileio", "units", "codegen", "interrupts", "process_memory",
                                   "views"})
#: The front door: re-exports from everywhere, outside the layering.
FRONT_DOOR: frozenset[str] = frozenset({"gaitopt", "gaitopt.__main__"})
#: The sub-packages at the bottom of gait/: they import no other module of gait/.
GAIT_BOTTOM: frozenset[str] = frozenset({"gaitopt.gait.record", "gaitopt.gait.sequence"})
#: Packages whose modules may import lazily (inside a function).
LAZY_ALLOWED: frozenset[str] = frozenset({"viz", "cli"})
#: Names any module may import from the root: constants it defines before any import.
ROOT_CONSTANTS: frozenset[str] = frozenset({"__version__"})
#: The imports inside functions below viz/ and cli/ that stay there, each with its reason:
#: each keeps a heavy third-party library out of a process that does not need it (they
#: follow the layering and close no cycle all the same).
DEFERRED: dict[tuple[str, str], str] = {
    ("gaitopt.gait.options.gait_options", "gaitopt.gait.sequence.contact_sequence"):
        "``from gaitopt import GaitOptions`` loads no CasADi (gaitopt.dynamics' package does)",
}


@dataclass(frozen=True)
class Edge:
    """One import of a gaitopt module by another."""

    importer: str
    target: str
    path: Path
    line: int
    lazy: bool  # inside a function
    type_checking: bool  # under ``if TYPE_CHECKING:``
    name: str = ""  # the name imported from ``target`` (``from target import name``)

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT.parent)}:{self.line}"


@dataclass(frozen=True)
class PrivateUse:
    """A private name of one gaitopt module used by another."""

    importer: str
    target: str
    name: str
    path: Path
    line: int

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT.parent)}:{self.line}"


def module_files() -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its ``__init__``)."""
    files = {}
    for path in sorted((ROOT / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        files[".".join(parts)] = path
    return files


MODULES = module_files()


def is_package(module: str) -> bool:
    return MODULES[module].name == "__init__.py"


def is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


class ImportVisitor(ast.NodeVisitor):
    """Collects the gaitopt imports of one module, and the private attributes it reads on
    the gaitopt modules it imported."""

    def __init__(self, module: str, path: Path) -> None:
        self.module = module
        self.path = path
        self.edges: list[Edge] = []
        self.private: list[PrivateUse] = []
        self.depth = 0  # functions entered
        self.type_checking = 0  # ``if TYPE_CHECKING:`` blocks entered
        self.module_aliases: dict[str, str] = {}  # local name -> gaitopt module it binds

    def edge(self, target: str, node: ast.stmt, name: str = "") -> None:
        self.edges.append(Edge(self.module, target, self.path, node.lineno, self.depth > 0,
                               self.type_checking > 0, name))

    def visit_FunctionDef(self, node: ast.FunctionDef) -> None:
        self.depth += 1
        self.generic_visit(node)
        self.depth -= 1

    visit_AsyncFunctionDef = visit_FunctionDef  # type: ignore[assignment]

    def visit_Lambda(self, node: ast.Lambda) -> None:
        self.depth += 1
        self.generic_visit(node)
        self.depth -= 1

    def visit_If(self, node: ast.If) -> None:
        if is_type_checking(node.test):
            self.type_checking += 1
            for stmt in node.body:
                self.visit(stmt)
            self.type_checking -= 1
            for stmt in node.orelse:
                self.visit(stmt)
        else:
            self.generic_visit(node)

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            if alias.name.split(".")[0] != PACKAGE:
                continue
            self.edge(alias.name, node)
            if alias.asname:
                self.module_aliases[alias.asname] = alias.name

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        base = node.module or ""
        if node.level:  # relative: resolve against this module's package
            package = self.module if is_package(self.module) else self.module.rpartition(".")[0]
            for _ in range(node.level - 1):
                package = package.rpartition(".")[0]
            base = f"{package}.{base}" if base else package
        if base.split(".")[0] != PACKAGE:
            return
        for alias in node.names:
            submodule = f"{base}.{alias.name}"
            if submodule in MODULES:  # ``from package import module``
                self.edge(submodule, node)
                self.module_aliases[alias.asname or alias.name] = submodule
                if is_private(alias.name):
                    self.private.append(PrivateUse(self.module, base, alias.name, self.path,
                                                   node.lineno))
            else:
                self.edge(base, node, alias.name)
                if is_private(alias.name):
                    self.private.append(PrivateUse(self.module, base, alias.name, self.path,
                                                   node.lineno))

    def visit_Attribute(self, node: ast.Attribute) -> None:
        target = None
        if isinstance(node.value, ast.Name):
            target = self.module_aliases.get(node.value.id)
        if target is not None and target != self.module and is_private(node.attr):
            self.private.append(PrivateUse(self.module, target, node.attr, self.path,
                                           node.lineno))
        self.generic_visit(node)


@dataclass(frozen=True)
class Graph:
    edges: tuple[Edge, ...]
    private: tuple[PrivateUse, ...]


def build_graph() -> Graph:
    edges: list[Edge] = []
    private: list[PrivateUse] = []
    for module, path in MODULES.items():
        visitor = ImportVisitor(module, path)
        visitor.visit(ast.parse(path.read_text(), filename=str(path)))
        edges.extend(visitor.edges)
        private.extend(visitor.private)
    return Graph(tuple(edges), tuple(private))


GRAPH = build_graph()


def layer_of(module: str) -> int | None:
    """The rank of a module's package in :data:`LAYERS` (-1 for a helper), or ``None`` for
    the front door."""
    if module in FRONT_DOOR:
        return None
    part = module.split(".")[1]
    if part in HELPERS:
        return -1
    return LAYERS.index(part)


def package_name(module: str) -> str:
    return module.split(".")[1] if "." in module else module


def reads_a_root_constant(edge: Edge) -> bool:
    """``from gaitopt import __version__``: a constant the root defines before any import."""
    return edge.target == PACKAGE and edge.name in ROOT_CONSTANTS


def cycles(edges: list[Edge]) -> list[list[Edge]]:
    """One cycle (as the edges along it) in each strongly connected component of more than
    one module, the largest component first; empty for an acyclic graph."""
    out: dict[str, list[Edge]] = {}
    for edge in edges:
        if edge.importer != edge.target:
            out.setdefault(edge.importer, []).append(edge)
    components = strongly_connected(out)
    found = []
    for component in sorted(components, key=len, reverse=True):
        if len(component) > 1:
            found.append(cycle_in(min(component), out, component))
    return found


def strongly_connected(out: dict[str, list[Edge]]) -> list[set[str]]:
    """Tarjan's algorithm, iterative."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[set[str]] = []
    for root in sorted(out):
        if root in index:
            continue
        work: list[tuple[str, Iterator[Edge]]] = [(root, iter(out.get(root, [])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            edge = next(children, None)
            if edge is not None:
                child = edge.target
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(out.get(child, []))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                components.append(component)
    return components


def cycle_in(start: str, out: dict[str, list[Edge]], component: set[str]) -> list[Edge]:
    """A shortest cycle through ``start`` inside its component (breadth first)."""
    previous: dict[str, Edge] = {}
    frontier = [start]
    while frontier:
        next_frontier = []
        for node in frontier:
            for edge in out.get(node, []):
                if edge.target not in component:
                    continue
                if edge.target == start:
                    path = [edge]
                    while path[0].importer != start:
                        path.insert(0, previous[path[0].importer])
                    return path
                if edge.target not in previous:
                    previous[edge.target] = edge
                    next_frontier.append(edge.target)
        frontier = next_frontier
    raise AssertionError(f"{start} is on no cycle of its component")


def describe_cycles(found: list[list[Edge]]) -> str:
    lines = []
    for cycle in found:
        lines.append(f"a {len(cycle)}-module import cycle:")
        for edge in cycle:
            kind = " (inside a function)" if edge.lazy else ""
            lines.append(f"  {edge.importer} -> {edge.target}{kind}   [{edge.where}]")
    return "\n".join(lines)


def offences_text(offences: list[str]) -> str:
    return "\n".join(dict.fromkeys(offences))  # one line per import statement


def test_the_graph_sees_every_package() -> None:
    """The parser finds imports in every layer (a guard against a test that checks nothing)."""
    importers = {package_name(e.importer) for e in GRAPH.edges}
    assert set(LAYERS) <= importers
    assert any(e.lazy for e in GRAPH.edges) and any(e.type_checking for e in GRAPH.edges)


def test_helpers_import_no_gaitopt_module() -> None:
    offences = [f"{e.where}: {e.importer} imports {e.target}" for e in GRAPH.edges
                if layer_of(e.importer) == -1 and not e.type_checking]
    assert not offences, offences_text(offences)


def test_each_package_imports_only_the_packages_above_it() -> None:
    offences = []
    for edge in GRAPH.edges:
        importer, target = layer_of(edge.importer), layer_of(edge.target)
        if importer is None or reads_a_root_constant(edge):
            continue
        if target is None or target > importer:
            offences.append(f"{edge.where}: {edge.importer} ({package_name(edge.importer)}/) "
                            f"imports {edge.target}, which is below it")
    assert not offences, ("imports against the layering of docs/architecture.md:\n"
                          + offences_text(offences))


def test_the_bottom_of_gait_imports_nothing_else_of_gait() -> None:
    def subpackage(module: str) -> str:
        return ".".join(module.split(".")[:3])

    assert all(package in MODULES for package in GAIT_BOTTOM)
    offences = [f"{e.where}: {e.importer} imports {e.target}" for e in GRAPH.edges
                if subpackage(e.importer) in GAIT_BOTTOM
                and (e.target + ".").startswith("gaitopt.gait.")
                and subpackage(e.target) != subpackage(e.importer)]
    assert not offences, ("gait/record/ and gait/sequence/ import another part of gait/:\n"
                          + offences_text(offences))


def test_the_two_formulations_do_not_import_each_other() -> None:
    # What both share lives beside them in gait/formulations/ (step_parameters, shared_rows,
    # cost, record_points); only select.py imports both.
    def formulation(module: str) -> str | None:
        parts = module.split(".")
        if parts[:3] == ["gaitopt", "gait", "formulations"] and len(parts) > 3:
            return parts[3] if parts[3] in ("reduced", "full") else None
        return None

    offences = [f"{e.where}: {e.importer} imports {e.target}" for e in GRAPH.edges
                if formulation(e.importer) is not None and formulation(e.target) is not None
                and formulation(e.importer) != formulation(e.target)]
    assert not offences, ("one formulation imports the other:\n" + offences_text(offences))


def test_only_viz_and_cli_import_inside_functions() -> None:
    offences = [f"{e.where}: {e.importer} imports {e.target} inside a function"
                for e in GRAPH.edges
                if e.lazy and e.importer not in FRONT_DOOR
                and package_name(e.importer) not in LAZY_ALLOWED
                and (e.importer, e.target) not in DEFERRED]
    assert not offences, ("imports inside functions outside viz/ and cli/ (import at the "
                          "top, or move the code to the layer it needs):\n"
                          + offences_text(offences))


def test_every_deferred_import_is_still_there() -> None:
    """:data:`DEFERRED` lists no import that has gone (or moved to the top)."""
    lazy = {(e.importer, e.target) for e in GRAPH.edges if e.lazy}
    assert not set(DEFERRED) - lazy, sorted(set(DEFERRED) - lazy)


def test_no_import_cycles() -> None:
    found = cycles([e for e in GRAPH.edges if not e.type_checking])
    assert not found, describe_cycles(found)


def test_no_module_uses_another_modules_private_names() -> None:
    offences = [f"{p.where}: {p.importer} uses {p.target}.{p.name}" for p in GRAPH.private
                if p.importer != p.target]
    assert not offences, "private names used across modules:\n" + offences_text(offences)


@pytest.mark.parametrize(("edges", "cyclic"), [
    ([("a", "b"), ("b", "c")], []),
    ([("a", "b"), ("b", "c"), ("c", "a")], [3]),
    ([("a", "b"), ("a", "c"), ("c", "b")], []),
    ([("x", "y"), ("y", "z"), ("z", "y"), ("a", "b"), ("b", "a"), ("b", "c"), ("c", "b")],
     [2, 2]),
    ([("a", "b"), ("b", "c"), ("c", "d"), ("d", "a"), ("b", "a")], [2]),
])
def test_cycles_on_small_graphs(edges: list[tuple[str, str]], cyclic: list[int]) -> None:
    """Each component of several modules gives one closed path, a shortest one."""
    path = Path(__file__)
    found = cycles([Edge(a, b, path, 1, False, False) for a, b in edges])
    assert [len(c) for c in found] == cyclic
    for cycle in found:
        assert cycle[0].importer == cycle[-1].target
        assert all(e.target == f.importer for e, f in zip(cycle, cycle[1:], strict=False))
