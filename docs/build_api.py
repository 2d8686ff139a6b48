"""Generate the API reference docs/api/ from the docstrings with pdoc (offline).

    python -m pip install -e ".[docs]"
    python docs/build_api.py            # -> docs/api/index.html
    python docs/build_api.py OUT_DIR    # elsewhere

Documents the public API (``drymount``: :mod:`drymount.api`) and the modules it
hands out: measured inputs, spectra, field paths, and the result types of the layers
below (``hbm.result.FrequencyResponse``, ``vehicle.sweep.SweepResult``,
``vehicle.results.TimeHistory``, ``vehicle.sampled``). Run from the repository root.

docs/api/ is committed and kept current: ``tests/test_api.py`` rebuilds it and
compares it page by page with the committed one (pdoc's output is deterministic: two
builds are byte-identical); after changing a docstring of these modules, run this
script and commit docs/api/ with the change. ``docs/api/renderer.json`` records the
versions of pdoc and of what it renders with (markdown2, Pygments, Jinja2,
MarkupSafe) that wrote the pages: another version may render differently (markdown2
2.5.6 broke an inline literal across a line break that 2.5.5 rendered), and where
the pages differ and so do the versions, the test skips the comparison and names
them.
"""

from __future__ import annotations

import json
import shutil
import sys
from importlib import metadata
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "docs" / "api"
MODULES = ["drymount", "drymount.api", "drymount.measured", "drymount.spectra",
           "drymount.paths", "drymount.hbm.result", "drymount.vehicle.sweep",
           "drymount.vehicle.results", "drymount.vehicle.sampled"]
#: The packages whose versions decide how the pages render (docs/api/renderer.json).
RENDERERS = ("pdoc", "markdown2", "Pygments", "Jinja2", "MarkupSafe")


def renderer_versions() -> dict[str, str]:
    """The installed version of each of :data:`RENDERERS`."""
    return {name: metadata.version(name) for name in RENDERERS}


def main(argv: list[str] | None = None) -> int:
    """Write the reference to ``argv[0]`` (default ``docs/api``), replacing it."""
    argv = sys.argv[1:] if argv is None else argv
    out = Path(argv[0]).resolve() if argv else OUT
    sys.path.insert(0, str(REPO))
    import pdoc
    import pdoc.render

    import drymount
    from drymount import api

    for name in drymount.__all__:  # the lazy names, resolved for the package page
        setattr(drymount, name, getattr(api, name))
    pdoc.render.configure(docformat="numpy", footer_text="drymount API reference",
                          search=False, show_source=False)
    tmp = out.with_name(out.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    pdoc.pdoc(*MODULES, output_directory=tmp)
    (tmp / "renderer.json").write_text(json.dumps(renderer_versions(), indent=1) + "\n",
                                       encoding="utf-8")
    shutil.rmtree(out, ignore_errors=True)
    tmp.rename(out)
    print(f"wrote {out / 'index.html'} ({len(list(out.rglob('*.html')))} pages)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
