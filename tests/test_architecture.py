"""The layers point one way and no module imports itself back (docs/architecture.md).

Every import of every module of the five packages is read with ``ast``, including
imports inside functions (lazy imports) and relative imports (resolved against the
module's package), and mapped to its layer:

    fmu_src  <-  fmu_build  <-  hbm  <-  vehicle  <-  drymount

An edge outside ``ALLOWED`` fails, as does any cycle of modules. ``fmu_src`` ships
inside the FMU, so it may import only the standard library and pythonfmu. The last
tests inject a forbidden edge and a cycle into synthetic sources and show that the
checker reports them.
"""

from __future__ import annotations

import ast
import functools
import re
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
#: The layers, lowest first.
LAYERS = ("fmu_src", "fmu_build", "hbm", "vehicle", "drymount")
#: Which layers each layer may import (itself included).
ALLOWED = {
    "fmu_src": {"fmu_src"},
    "fmu_build": {"fmu_build", "fmu_src"},
    "hbm": {"hbm", "fmu_src"},
    "vehicle": {"vehicle", "hbm", "fmu_src", "fmu_build"},
    "drymount": set(LAYERS),
}
#: What fmu_src may import besides itself (it runs inside the FMU's host Python).
FMU_SRC_EXTERNAL = {"pythonfmu"}


def project_sources(root: Path = REPO) -> dict[str, str]:
    """``{module name: source}`` of every module of the five packages."""
    return dict(_read_sources(root))


@functools.cache
def _read_sources(root: Path) -> tuple[tuple[str, str], ...]:
    out = {}
    for pkg in LAYERS:
        for path in sorted((root / pkg).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = path.read_text(encoding="utf-8")
    return tuple(out.items())


@functools.cache
def _imports(source: str, name: str) -> tuple:
    """``(level, module, [alias names] or None, line)`` of every import statement."""
    out = []
    for node in ast.walk(ast.parse(source, filename=name)):
        if isinstance(node, ast.Import):
            out += [(0, alias.name, None, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            out.append((node.level, node.module, tuple(a.name for a in node.names),
                        node.lineno))
    return tuple(out)


#: The lower layers are installed under the ``drymount`` namespace
#: (``drymount.hbm`` is the folder ``hbm/``); sources are named here by folder.
_INSTALLED = re.compile(r"^drymount\.(fmu_src|fmu_build|hbm|vehicle)(\.|$)")


def _canon(module: str) -> str:
    """``drymount.hbm.result`` -> ``hbm.result`` (the folder name of the module)."""
    return _INSTALLED.sub(r"\1\2", module)


def _is_package(name: str, sources: dict[str, str]) -> bool:
    return any(m.startswith(name + ".") for m in sources)


def imports_of(name: str, source: str, sources: dict[str, str]
               ) -> list[tuple[str, int]]:
    """``(imported module, line)`` for every import statement of module ``name``,
    wherever it is (module level, functions, ``try`` blocks). Relative imports are
    resolved; ``from pkg import sub`` points at ``pkg.sub`` when that is a module and
    also at ``pkg`` itself when it is a package: the statement runs the package's
    ``__init__`` (a package face) and reads ``sub`` from it, so a cycle through an
    ``__init__`` is a cycle (``import pkg.sub`` reads the submodule only)."""
    package = name if _is_package(name, sources) else name.rpartition(".")[0]
    out = []
    for level, module, names, line in _imports(source, name):
        if names is None:  # import a.b.c
            out.append((_canon(module), line))
            continue
        if level:
            base = package.split(".")
            base = base[:len(base) - (level - 1)]
            target = ".".join(base + ([module] if module else []))
        else:
            target = module
        face = _canon(target)
        for alias in names:
            sub = _canon(f"{target}.{alias}")
            out.append((sub if sub in sources else face, line))
        if face in sources and _is_package(face, sources) and face != name:
            out.append((face, line))
    return out


def project_edges(sources: dict[str, str]) -> list[tuple[str, str, int]]:
    """``(importer, imported, line)`` for imports of project modules."""
    edges = []
    for name, src in sources.items():
        for target, line in imports_of(name, src, sources):
            if target.split(".")[0] in LAYERS:
                while target not in sources and "." in target:
                    target = target.rpartition(".")[0]  # a name inside a module
                edges.append((name, target, line))
    return edges


def layer_violations(sources: dict[str, str]) -> list[str]:
    """Every import that goes against the layers, and every non-standard import of
    ``fmu_src``."""
    bad = []
    for name, target, line in project_edges(sources):
        src_layer, dst_layer = name.split(".")[0], target.split(".")[0]
        if dst_layer not in ALLOWED[src_layer]:
            bad.append(f"{name}:{line} imports {target} ({src_layer} -> {dst_layer})")
    for name, src in sources.items():
        if name.split(".")[0] != "fmu_src":
            continue
        for target, line in imports_of(name, src, sources):
            top = target.split(".")[0]
            if top not in sys.stdlib_module_names and top not in FMU_SRC_EXTERNAL \
                    and top != "fmu_src":
                bad.append(f"{name}:{line} imports {target} (fmu_src: standard "
                           f"library and pythonfmu only)")
    return bad


def module_cycles(sources: dict[str, str]) -> list[list[str]]:
    """The strongly connected components with more than one module (or a module
    importing itself): Tarjan's algorithm on the module graph."""
    graph = {name: set() for name in sources}
    for name, target, _ in project_edges(sources):
        graph[name].add(target)
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph[v]:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


# ---------------------------------------------------------------------- the real tree


def test_every_package_is_read():
    sources = project_sources()
    for pkg in LAYERS:
        assert pkg in sources, pkg
    assert "vehicle.master" in sources and "drymount.config.loading" in sources
    edges = project_edges(sources)
    # lazy imports are seen: fmu_build.builder imports fmu_src inside a function
    assert ("fmu_build.builder", "fmu_src", ) in {(a, b) for a, b, _ in edges}


def test_layers_point_one_way():
    assert layer_violations(project_sources()) == []


def test_no_module_cycles():
    assert module_cycles(project_sources()) == []


def bare_layer_imports(sources: dict[str, str], root: Path = REPO) -> list[str]:
    """Absolute imports of a lower layer by its folder name (``import hbm``): the
    installed name is ``drymount.hbm``, and ``hbm`` on PyPI is another project."""
    bad = []
    lower = set(LAYERS) - {"drymount"}
    files = {n: s for n, s in sources.items()}
    for extra in ("tests", "bench", "examples", "docs"):
        for path in sorted((root / extra).rglob("*.py")):
            files[str(path.relative_to(root))] = path.read_text(encoding="utf-8")
    files["build_fmu.py"] = (root / "build_fmu.py").read_text(encoding="utf-8")
    for name, src in files.items():
        for level, module, _, line in _imports(src, name):
            if level == 0 and module and module.split(".")[0] in lower:
                bad.append(f"{name}:{line} imports {module} (use drymount.{module})")
    return bad


def test_lower_layers_are_imported_by_their_installed_name():
    assert bare_layer_imports(project_sources()) == []
    srcs = _synthetic(**{"vehicle.x": "import hbm.result\n"})
    assert bare_layer_imports(srcs) == [
        "vehicle.x:1 imports hbm.result (use drymount.hbm.result)"]


# ---------------------------------------------------------------------- the checker


def _synthetic(**overrides) -> dict[str, str]:
    """The real sources with some modules replaced or added."""
    sources = project_sources()
    sources.update(overrides)
    return sources


def test_checker_reports_an_injected_forbidden_edge():
    """hbm importing the app inside a function (the lazy import the refactor
    removed from hbm/result.py) is an error."""
    lazy = "def to_csv(path):\n    from drymount.io import atomic_path\n"
    bad = layer_violations(_synthetic(**{"hbm.result": lazy}))
    assert bad == ["hbm.result:2 imports drymount.io (hbm -> drymount)"]


def test_checker_resolves_relative_imports():
    """``from ..drymount import cli`` two levels up from vehicle/sub/x.py is
    drymount.cli; ``from . import master`` in vehicle/sub is vehicle.sub.master."""
    srcs = _synthetic(**{"vehicle.sub": "", "vehicle.sub.master": "",
                         "vehicle.sub.x": "from ...drymount import cli\n"
                                          "from . import master\n"})
    assert ("drymount.cli", 1) in imports_of("vehicle.sub.x", srcs["vehicle.sub.x"],
                                            srcs)
    assert ("vehicle.sub.master", 2) in imports_of("vehicle.sub.x",
                                                   srcs["vehicle.sub.x"], srcs)
    assert layer_violations(srcs) == [
        "vehicle.sub.x:1 imports drymount.cli (vehicle -> drymount)",
        "vehicle.sub.x:1 imports drymount (vehicle -> drymount)"]  # its face too


def test_checker_reports_a_cycle_and_non_standard_imports_of_fmu_src():
    steady = "from .master import Master\n"
    master = "def steady_state():\n    from .steady import run_steady\n"
    cycles = module_cycles(_synthetic(**{"vehicle.steady": steady,
                                         "vehicle.master": master}))
    assert ["vehicle.master", "vehicle.steady"] in cycles
    bad = layer_violations(_synthetic(**{"fmu_src.mount_law": "import numpy\n"}))
    assert bad == ["fmu_src.mount_law:1 imports numpy (fmu_src: standard library "
                   "and pythonfmu only)"]


@pytest.mark.parametrize("layer", LAYERS)
def test_allowed_edges_point_down(layer):
    """The allowed set itself: no layer may import a layer above it."""
    above = set(LAYERS[LAYERS.index(layer) + 1:])
    assert not ALLOWED[layer] & above


def test_checker_sees_a_cycle_through_a_package_face():
    """``from drymount.vehicle import fmi_logging`` inside vehicle.backends (the lazy
    import this branch removed) runs vehicle/__init__, which imports backends: a
    cycle the checker used to miss (it mapped the statement to the submodule only)."""
    real = project_sources()["vehicle.backends"]
    lazy = real + "\n\ndef _f():\n    from drymount.vehicle import fmi_logging\n"
    cycles = module_cycles(_synthetic(**{"vehicle.backends": lazy}))
    assert any("vehicle" in c and "vehicle.backends" in c for c in cycles)
    line = lazy.count("\n")
    assert ("vehicle", line) in imports_of("vehicle.backends", lazy,
                                           project_sources())
    # importing the submodule by its full name reads no package face
    direct = real + "\n\ndef _f():\n    import drymount.vehicle.fmi_logging as m\n"
    assert module_cycles(_synthetic(**{"vehicle.backends": direct})) == []
