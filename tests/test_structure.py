"""The structure of ``fepost/``: no import cycles, no upward imports across the documented
layers, no imports of another module's private names, short functions, no raw Sphinx roles.

The layers are read from ``docs/architecture.md`` (its table "Layers"), so the page and the
code cannot drift apart. Every import counts: at the top of a module, inside a function, and
under ``if TYPE_CHECKING:``.
"""

from __future__ import annotations

import ast
import functools
import re
from collections import defaultdict
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "fepost"
#: Longest function allowed in fepost/ (the aim is a screen: under 100 lines).
MAX_FUNCTION_LINES = 110
ROLE = re.compile(r":(func|class|meth|data|attr|mod|exc|obj):`")


def _modules() -> dict[str, Path]:
    mods = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        name = ".".join(path.relative_to(REPO).with_suffix("").parts)
        mods[name.removesuffix(".__init__")] = path
    return mods


MODULES = _modules()


@functools.cache
def _trees() -> dict[str, ast.Module]:
    """Every module's syntax tree, parsed when a test first asks (not at collection: under
    pytest-xdist every worker collects this file, one runs it)."""
    return {name: ast.parse(path.read_text(encoding="utf-8"), str(path)) for name, path in MODULES.items()}


def _is_face(name: str) -> bool:
    return MODULES[name].name == "__init__.py"


def _target(current: str, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = current.split(".") if _is_face(current) else current.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


@functools.cache
def _imports() -> list[tuple[str, str, str]]:
    """(importing module, imported module, name) for every import of fepost code; name is
    the imported name for ``from X import name`` where X is a module, else ""."""
    out = []
    for name, tree in _trees().items():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _target(name, node)
                if not target.startswith("fepost"):
                    continue
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    if full in MODULES:
                        out.append((name, full, ""))
                    elif target in MODULES:
                        out.append((name, target, alias.name))
            elif isinstance(node, ast.Import):
                out += [(name, a.name, "") for a in node.names if a.name in MODULES]
    return [(a, b, n) for a, b, n in out if a != b]


def _layers() -> dict[str, int]:
    """{top-level module or package: layer number} from docs/architecture.md."""
    text = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.split("## Layers", 1)[1].split("\n## ", 1)[0]
    layers = {}
    for number, mods in re.findall(r"^\|\s*(\d+)\s*\|[^|]*\|([^|]*)\|\s*$", section, re.M):
        for mod in re.findall(r"`([^`]+)`", mods):
            assert mod not in layers, f"{mod} is listed twice in docs/architecture.md"
            layers[mod] = int(number)
    return layers


LAYERS = _layers()


def _top(module: str) -> str | None:
    """The top-level module or package of ``module`` (None for the root face ``fepost``)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_the_layer_table_is_read():
    assert len(set(LAYERS.values())) >= 10 and LAYERS["errors"] == 1 and LAYERS["cli"] == max(LAYERS.values())


def test_every_module_has_a_layer():
    tops = {_top(m) for m in MODULES} - {None}
    missing = sorted(tops - set(LAYERS))
    assert not missing, f"give these modules a layer in docs/architecture.md: {missing}"
    stale = sorted(set(LAYERS) - tops)
    assert not stale, f"docs/architecture.md lists modules that do not exist: {stale}"


def _upward(imports) -> list[str]:
    upward = []
    for src, dst, name in imports:
        if _top(src) is None:
            continue  # the root face re-exports the API
        if _top(dst) is None:
            if name and not (name.startswith("__") and name.endswith("__")):
                upward.append(f"{src} imports {name} from the root face fepost")
            continue
        if LAYERS[_top(dst)] > LAYERS[_top(src)]:
            upward.append(f"{src} (layer {LAYERS[_top(src)]}) imports {dst} (layer {LAYERS[_top(dst)]})")
    return upward


def test_no_upward_imports():
    upward = _upward(_imports())
    assert not upward, "\n".join(upward)


def test_upward_finder_finds_an_upward_import():
    """The check can fail: the friction models importing the pipeline is upward, a face's
    ``__version__`` is not."""
    edges = [
        ("fepost.friction.summary", "fepost.analysis", ""),
        ("fepost.sweep.engine", "fepost", "__version__"),
    ]
    assert _upward(edges) == ["fepost.friction.summary (layer 5) imports fepost.analysis (layer 7)"]


def _cycles(imports) -> list[list[str]]:
    graph = defaultdict(set)
    for src, dst, _ in imports:
        graph[src].add(dst)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []

    def strong(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            # a cycle through a package face alone (an __init__ re-exporting its modules) is no cycle
            if sum(not _is_face(m) for m in comp) > 1:
                found.append(sorted(comp))

    for v in MODULES:
        if v not in index:
            strong(v)
    return found


def test_no_import_cycles():
    cycles = _cycles(_imports())
    assert not cycles, "\n".join(" <-> ".join(c) for c in cycles)


def test_cycle_finder_finds_a_cycle():
    """The check can fail: two modules importing each other are a cycle; a package face
    importing its own module that imports the face back is not."""
    assert any(
        {"fepost.errors", "fepost.polar"} <= set(c)
        for c in _cycles([*_imports(), ("fepost.errors", "fepost.polar", "")])
    )
    face = [("fepost.figures", "fepost.figures.curves", ""), ("fepost.figures.curves", "fepost.figures", "")]
    assert not any("fepost.figures.curves" in c for c in _cycles(face))


def test_no_private_cross_module_imports():
    private = [
        f"{src} takes {dst}.{name}"
        for src, dst, name in _imports()
        if name.startswith("_") and not (name.startswith("__") and name.endswith("__"))
    ]
    assert not private, "\n".join(private)


def test_functions_are_short():
    long = []
    for name, tree in _trees().items():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long.append(f"{name}.{node.name}: {n} lines")
    assert not long, "\n".join(long)


def test_no_sphinx_roles_in_docstrings():
    raw = sorted(name for name, path in MODULES.items() if ROLE.search(path.read_text(encoding="utf-8")))
    assert not raw, f"raw Sphinx roles (rendered raw by MkDocs) in: {raw}"
