"""The package's import structure, read from the sources with ``ast`` (nothing is imported):

(a) no import cycle between the modules of ``acld_gym/``, ``baselines/`` and ``train/``;
(b) no import upward across the layers of :data:`LAYERS` (physics -> design -> envs ->
    baselines -> train, lowest first);
(c) no module over :data:`MAX_LINES` lines in ``acld_gym/``, ``baselines/`` and ``train/``.

An import inside a function is an edge like one at the top of a module: it runs later, but
the modules still depend on each other. An edge goes to the module imported:
``from a.b import c`` to ``a.b.c`` where that is a module, else to ``a.b``; the packages
a name passes through (``a`` and ``a.b`` for ``import a.b.c``) are not counted.

There are no exceptions: :data:`KNOWN_UPWARD` is empty, and exact both ways (a new upward
import fails, and so does a listed one that is gone).
"""

from __future__ import annotations

import ast
from collections import deque
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("acld_gym", "baselines", "train")
MAX_LINES = 400

#: The layers, lowest first: a module may import modules of its own layer and of the layers
#: below it, never above. An entry names a package and everything in it, except
#: ``"acld_gym"``, which names only the package's ``__init__`` (it registers the envs).
#: The order, read from the code: util imports nothing of the project; physics only util;
#: design physics and util; envs design, physics and util; the pieces over the envs
#: (``acld_gym/__init__.py`` registers the presets; wrappers wrap the envs and read
#: envs.step; benchmark holds the test sets, plain data over the env ids; thesis reproduces
#: the thesis from design and physics) import envs and below; baselines all of acld_gym;
#: train everything.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("acld_gym.util",),
    ("acld_gym.physics",),
    ("acld_gym.design",),
    ("acld_gym.envs",),
    (
        "acld_gym",
        "acld_gym.wrappers",
        "acld_gym.test_sets",
        "acld_gym.thesis",
    ),
    ("baselines",),
    ("train",),
)

#: Upward imports allowed, with the reason.
KNOWN_UPWARD: dict[tuple[str, str], str] = {}


@dataclass(frozen=True)
class Edge:
    source: str
    target: str
    line: int
    in_function: bool

    def __str__(self) -> str:
        where = "in a function" if self.in_function else "at module level"
        return f"{self.source} -> {self.target} (line {self.line}, {where})"


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def modules() -> dict[str, Path]:
    """Every module of the three packages by dotted name."""
    return {module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


def _known(name: str) -> str:
    """``name`` if it is a module of the project, else its nearest enclosing one (a compiled
    extension such as ``acld_gym.envs._stepcore`` has no source: its package stands in)."""
    mods = modules()
    parts = name.split(".")
    while parts and ".".join(parts) not in mods:
        parts.pop()
    return ".".join(parts) if parts else name


def _targets(module: str, is_package: bool, node: ast.Import | ast.ImportFrom) -> list[str]:
    """The project modules one import statement imports."""
    if isinstance(node, ast.Import):
        return [_known(a.name) for a in node.names if a.name.split(".")[0] in PACKAGES]
    if node.level:
        base = module.split(".") if is_package else module.split(".")[:-1]
        base = base[: len(base) - (node.level - 1)]
        source = ".".join(base + ([node.module] if node.module else []))
    else:
        source = node.module or ""
    if source.split(".")[0] not in PACKAGES:
        return []
    mods = modules()
    return [
        f"{source}.{a.name}" if f"{source}.{a.name}" in mods else _known(source) for a in node.names
    ]


def _function_nodes(tree: ast.Module) -> set[int]:
    """The ids of every node inside a function (or a lambda) of ``tree``."""
    inside: set[int] = set()
    for f in ast.walk(tree):
        if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            inside |= {id(n) for n in ast.walk(f) if n is not f}
    return inside


@cache
def edges() -> tuple[Edge, ...]:
    """Every import of a project module by a project module (self-imports left out)."""
    out = []
    for name, path in modules().items():
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        inside = _function_nodes(tree)
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for target in _targets(name, path.name == "__init__.py", node):
                    if target != name:
                        out.append(Edge(name, target, node.lineno, id(node) in inside))
    return tuple(sorted(out, key=lambda e: (e.source, e.target, e.line)))


def graph(es) -> dict[str, set[str]]:
    g: dict[str, set[str]] = {}
    for e in es:
        g.setdefault(e.source, set()).add(e.target)
        g.setdefault(e.target, set())
    return g


def cycles(g: dict[str, set[str]]) -> list[frozenset[str]]:
    """The strongly connected components of ``g`` with more than one node (Tarjan's
    algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out = []
    for root in sorted(g):
        if root in index:
            continue
        work = [(root, iter(sorted(g[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(g[w]))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = set()
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.add(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(frozenset(comp))
    return out


def one_cycle(component: frozenset[str], es) -> list[Edge]:
    """A shortest cycle through the first module of ``component``, as its edges."""
    by_pair = {}
    for e in es:
        if e.source in component and e.target in component:
            by_pair.setdefault((e.source, e.target), e)
    start = min(component)
    previous: dict[str, str] = {}
    queue = deque([start])
    while queue:
        v = queue.popleft()
        for a, b in sorted(by_pair):
            if a != v:
                continue
            if b == start:
                path = [by_pair[(v, start)]]
                while v != start:
                    path.append(by_pair[(previous[v], v)])
                    v = previous[v]
                return path[::-1]
            if b not in previous:
                previous[b] = v
                queue.append(b)
    raise AssertionError(f"no cycle through {start}")  # a component always has one


def layer(module: str) -> int:
    """The index in :data:`LAYERS` of the layer holding ``module``."""
    best = None
    for i, names in enumerate(LAYERS):
        for prefix in names:
            if module == prefix or (prefix != "acld_gym" and module.startswith(prefix + ".")):
                if best is None or len(prefix) > len(best[1]):
                    best = (i, prefix)
    if best is None:
        raise KeyError(f"{module} is in no layer: add its package to LAYERS")
    return best[0]


# --- the checker itself ----------------------------------------------------------------------
def test_the_reader_sees_imports_at_the_top_and_inside_functions():
    top = {(e.source, e.target) for e in edges() if not e.in_function}
    inner = {(e.source, e.target) for e in edges() if e.in_function}
    assert ("acld_gym.thesis.cli", "acld_gym.thesis.plots") in inner - top  # matplotlib's
    assert not any(t.startswith(("matplotlib", "scipy", "torch")) for _, t in top | inner)
    assert ("baselines.policies", "baselines.policy_base") in top  # from .policy_base import
    assert ("baselines.policies", "baselines.arguments") in top  # from . import arguments
    assert ("acld_gym", "acld_gym.envs.registration") in top  # absolute, in a package's __init__
    assert ("acld_gym.physics.loads", "acld_gym.physics.load_cases") in top
    assert len(modules()) > 100 and len(edges()) > 500


def test_cycles_are_found_and_shown():
    toy = [Edge("a", "b", 1, False), Edge("b", "c", 2, True), Edge("c", "a", 3, False)]
    toy += [Edge("c", "d", 4, False), Edge("d", "e", 5, False)]
    assert cycles(graph(toy)) == [frozenset("abc")]
    assert [str(e) for e in one_cycle(frozenset("abc"), toy)] == [
        "a -> b (line 1, at module level)",
        "b -> c (line 2, in a function)",
        "c -> a (line 3, at module level)",
    ]
    assert cycles(graph(toy[:2])) == []


def test_every_module_has_a_layer():
    assert layer("acld_gym") == layer("acld_gym.wrappers.single") == 4
    assert layer("acld_gym.envs.presets") == 3 and layer("train.core.report") == 6
    with pytest.raises(KeyError, match="acld_gym.newthing is in no layer"):
        layer("acld_gym.newthing")
    for name in modules():
        layer(name)


# --- (a) no cycles ---------------------------------------------------------------------------
def test_no_import_cycles():
    """None in any of the three packages: a module that two others share goes below both
    (e.g. :mod:`train.agent_program` under ``train.agent`` and ``train.sb3_export``)."""
    es = edges()
    found = cycles(graph(es))
    shown = "\n".join(
        "cycle among " + ", ".join(sorted(c)) + ":\n  " + "\n  ".join(map(str, one_cycle(c, es)))
        for c in found
    )
    assert not found, f"import cycles:\n{shown}"


# --- (b) no upward imports -------------------------------------------------------------------
def test_no_upward_imports():
    up = [e for e in edges() if layer(e.target) > layer(e.source)]
    new = [str(e) for e in up if (e.source, e.target) not in KNOWN_UPWARD]
    assert not new, "imports of a higher layer:\n" + "\n".join(new)
    gone = set(KNOWN_UPWARD) - {(e.source, e.target) for e in up}
    assert not gone, f"KNOWN_UPWARD lists imports that are gone: {sorted(gone)}"


def test_the_allowed_upward_import_is_inside_a_function():
    """The one reach upward runs only when called (an agent directory to read), never when
    baselines is imported."""
    for e in edges():
        if (e.source, e.target) in KNOWN_UPWARD:
            assert e.in_function, str(e)


# --- (c) module length -----------------------------------------------------------------------
def _lines(path: Path) -> int:
    return len(path.read_text(encoding="utf-8").splitlines())


@pytest.mark.parametrize("package", PACKAGES)
def test_no_module_over_400_lines(package):
    long = {
        str(p.relative_to(ROOT)): _lines(p)
        for p in sorted((ROOT / package).rglob("*.py"))
        if _lines(p) > MAX_LINES
    }
    assert not long, f"modules over {MAX_LINES} lines (split them by job): {long}"
