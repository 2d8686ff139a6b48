"""A command in README.md or docs/ is a promise (issue 23): every ``sh`` block of
README.md and of each docs/ page marked runnable runs in a fresh temporary folder and
must exit 0.

Marks (an HTML comment line directly before a fenced block, agreed with the docs):

- ``<!-- not-runnable: reason -->`` skips the block (a Dask cluster, the test suite
  itself, ...); the reason is the skip's.
- ``<!-- slow -->`` puts the block behind the ``slow`` marker (run in the full suite,
  ``python3 -m pytest -m slow``).

A docs/ page takes part when it has a line ``<!-- runnable -->``; README.md always
does. A page is read top to bottom, as a user follows it: its unmarked blocks run in
order in one fresh temporary folder (a later block may use the files of an earlier
one), one test per page; a slow block is a test of its own that first runs the
page's unmarked blocks above it in its own fresh folder. The folder holds links to
the repository's ``examples/`` and ``build_fmu.py`` (the commands name them relative
to the repository root), nothing else. A leading ``python3 -m pip
install ... &&`` is dropped: the test runs in the environment that is already
installed, and must not change it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Each README example is meant to finish within 2 minutes on 2 cores; the limit
#: here only stops a hung run (a test must not time the machine).
HANG_S = 1800
_FENCE = re.compile(r"^```(\w*)\s*$")
_MARK = re.compile(r"^<!--\s*(not-runnable|slow)\s*:?\s*(.*?)\s*-->\s*$")
_PIP = re.compile(r"^\s*python3? -m pip install [^&]*&&\s*")


def command_blocks(path: Path) -> list[tuple[int, str, str, str]]:
    """``(line, mark, reason, script)`` of every ``sh`` block of the Markdown file;
    ``mark`` is ``""``, ``"not-runnable"`` or ``"slow"`` (the comment line directly
    before the fence)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        if m.group(1) in ("sh", "bash", "console", "shell"):
            mark = _MARK.match(lines[i - 1]) if i else None
            out.append((i + 1, mark.group(1) if mark else "",
                        mark.group(2) if mark else "", "\n".join(lines[i + 1:j])))
        i = j + 1
    return out


def _pages() -> list[Path]:
    docs = sorted(p for p in (ROOT / "docs").glob("*.md")
                  if "<!-- runnable -->" in p.read_text(encoding="utf-8"))
    return [ROOT / "README.md", *docs]


def page_cases(page: Path, rel) -> list:
    """The tests of one page: ``(id, blocks, mark)`` with ``blocks`` the
    ``(line, script)`` to run in order in one folder and ``mark`` None, ``"slow"``
    or ``"skip: reason"``."""
    blocks = command_blocks(page)
    fast = [(line, script) for line, mark, _, script in blocks if not mark]
    out = [(f"{rel}:{'+'.join(str(ln) for ln, _ in fast)}", fast, None)] if fast else []
    for line, mark, reason, script in blocks:
        if mark == "not-runnable":
            out.append((f"{rel}:{line}", [], f"skip: not runnable: {reason}"))
        elif mark == "slow":
            above = [(ln, sc) for ln, sc in fast if ln < line]
            out.append((f"{rel}:{line}", above + [(line, script)], "slow"))
    return out


def _cases():
    for page in _pages():
        for name, blocks, mark in page_cases(page, page.relative_to(ROOT)):
            marks = ([pytest.mark.skip(reason=mark[6:])] if mark and mark != "slow"
                     else [pytest.mark.slow] if mark else [])
            yield pytest.param(blocks, id=name, marks=marks)


def test_marks_are_read(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("text\n<!-- not-runnable: a Dask cluster -->\n```sh\ndask x\n```\n"
                    "<!-- slow -->\n```sh\na\nb\n```\n```sh\nc\n```\n```python\nd\n"
                    "```\n", encoding="utf-8")
    assert command_blocks(page) == [(3, "not-runnable", "a Dask cluster", "dask x"),
                                    (7, "slow", "", "a\nb"), (11, "", "", "c")]
    assert _PIP.sub("", "python3 -m pip install -e . && drymount demo") == \
        "drymount demo"
    # unmarked blocks in order in one folder; a slow one after the fast ones above it
    assert page_cases(page, "p.md") == [
        ("p.md:11", [(11, "c")], None),
        ("p.md:3", [], "skip: not runnable: a Dask cluster"),
        ("p.md:7", [(7, "a\nb")], "slow")]
    page.write_text("```sh\nx\n```\n<!-- slow -->\n```sh\ny\n```\n```sh\nz\n```\n",
                    encoding="utf-8")
    assert page_cases(page, "p.md") == [("p.md:1+8", [(1, "x"), (8, "z")], None),
                                        ("p.md:5", [(1, "x"), (5, "y")], "slow")]


@pytest.mark.parametrize("blocks", list(_cases()))
def test_command_blocks_exit_0(blocks, tmp_path):
    for name in ("examples", "build_fmu.py"):
        (tmp_path / name).symlink_to(ROOT / name)
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}:{os.environ['PATH']}")
    for line, script in blocks:
        script = "\n".join(_PIP.sub("", ln) for ln in script.splitlines())
        p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", script],
                           cwd=tmp_path, env=env, capture_output=True, text=True,
                           timeout=HANG_S)
        assert p.returncode == 0, (f"the block at line {line}: exit {p.returncode}\n"
                                   f"{script}\n--- stderr:\n{p.stderr[-4000:]}")
