"""A command in README.md or docs/ is a promise (issue 23): every ``sh`` block of
README.md and of each docs/ page marked runnable runs in a fresh temporary folder and
must exit 0.

Marks (an HTML comment line directly before a fenced block, agreed with the docs):

- ``<!-- not-runnable: reason -->`` skips the block (a Dask cluster, the test suite
  itself, ...); the reason is the skip's.
- ``<!-- slow -->`` puts the block behind the ``slow`` marker (run in the full suite,
  ``python3 -m pytest -m slow``).

A docs/ page takes part when it has a line ``<!-- runnable -->``; README.md always
does. The temporary folder holds links to the repository's ``examples/`` and
``build_fmu.py`` (the commands name them relative to the repository root), nothing
else. A leading ``python3 -m pip install ... &&`` is dropped: the test runs in the
environment that is already installed, and must not change it.
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


def _cases():
    for page in _pages():
        for line, mark, reason, script in command_blocks(page):
            marks = []
            if mark == "not-runnable":
                marks.append(pytest.mark.skip(reason=f"not runnable: {reason}"))
            elif mark == "slow":
                marks.append(pytest.mark.slow)
            name = f"{page.relative_to(ROOT)}:{line}"
            yield pytest.param(script, id=name, marks=marks)


def test_marks_are_read(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("text\n<!-- not-runnable: a Dask cluster -->\n```sh\ndask x\n```\n"
                    "<!-- slow -->\n```sh\na\nb\n```\n```sh\nc\n```\n```python\nd\n"
                    "```\n", encoding="utf-8")
    assert command_blocks(page) == [(3, "not-runnable", "a Dask cluster", "dask x"),
                                    (7, "slow", "", "a\nb"), (11, "", "", "c")]
    assert _PIP.sub("", "python3 -m pip install -e . && drymount demo") == \
        "drymount demo"


@pytest.mark.parametrize("script", list(_cases()))
def test_command_block_exits_0(script, tmp_path):
    for name in ("examples", "build_fmu.py"):
        (tmp_path / name).symlink_to(ROOT / name)
    script = "\n".join(_PIP.sub("", ln) for ln in script.splitlines())
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}:{os.environ['PATH']}")
    p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", script], cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=HANG_S)
    assert p.returncode == 0, (f"exit {p.returncode}\n{script}\n--- stderr:\n"
                               f"{p.stderr[-4000:]}")
