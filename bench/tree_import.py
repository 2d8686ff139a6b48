"""Run ``drymount`` from another checkout's source tree, with this interpreter.

Benchmarks compare a change against main measured in the same run: ``python
bench/tree_import.py TREE ARGS...`` runs ``drymount ARGS...`` with the packages
``drymount``, ``drymount.hbm``, ``drymount.vehicle``, ``drymount.fmu_src`` and
``drymount.fmu_build`` imported from the folders of TREE (a checkout or ``git archive``
of another commit; the layout of pyproject's ``package-dir``), whatever drymount this
interpreter has installed. The dependencies are this interpreter's.

Use a copy of the other tree (``git archive main | tar -x -C /tmp/main_tree``): Python
and numba write their caches beside the sources.
"""

from __future__ import annotations

import importlib.abc
import importlib.util
import sys
from pathlib import Path

#: package -> folder of the tree (pyproject's ``[tool.setuptools.package-dir]``)
LAYOUT = {
    "drymount": "drymount",
    "drymount.fmu_src": "fmu_src",
    "drymount.fmu_build": "fmu_build",
    "drymount.hbm": "hbm",
    "drymount.vehicle": "vehicle",
}


class _TreeFinder(importlib.abc.MetaPathFinder):
    """Finds the packages of :data:`LAYOUT` in one tree; the rest by their parent."""

    def __init__(self, tree: Path):
        self.tree = tree

    def find_spec(self, fullname, path=None, target=None):
        folder = LAYOUT.get(fullname)
        if folder is None:
            return None
        init = self.tree / folder / "__init__.py"
        return importlib.util.spec_from_file_location(
            fullname, init, submodule_search_locations=[str(init.parent)])


def use_tree(tree: str | Path) -> Path:
    """Import drymount from ``tree`` from now on (call before importing it)."""
    root = Path(tree).resolve()
    if not (root / "drymount" / "__init__.py").is_file():
        raise SystemExit(f"tree = {str(tree)!r}: no drymount/__init__.py there; "
                         "expected a drymount checkout (e.g. git archive main)")
    if any(name == "drymount" or name.startswith("drymount.") for name in sys.modules):
        raise RuntimeError("drymount is already imported: call use_tree first")
    sys.meta_path.insert(0, _TreeFinder(root))
    return root


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args:
        raise SystemExit("usage: python bench/tree_import.py TREE [drymount ARGS...]")
    use_tree(args[0])
    from drymount.cli import main as cli_main

    sys.argv = ["drymount", *args[1:]]
    return cli_main()


if __name__ == "__main__":
    raise SystemExit(main())
