"""The results table of an exploration: CSV rows written as designs finish.

One comment line (what produced the table, a fingerprint of the configuration and the
design space, units), a header, then one row per design: ``design``, ``status``,
``feasible``, every variable, every objective, every constraint margin (>= 0
satisfied), ``n_points`` and ``message``. Floats are written with ``repr`` so that a
table read back gives the same numbers. Rows are appended and flushed as results
arrive (an interrupted run keeps them); :func:`read_table` reads them back for a
resume, and :meth:`ResultsTable.finish` rewrites the file ordered by design number.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
from pathlib import Path

from drymount.design.evaluate import DesignResult, DesignStatus
from drymount.design.space import DesignSpace
from drymount.io import atomic_write_text, writing

__all__ = ["ResultsTable", "fingerprint", "read_table", "parse_row", "columns",
           "TableError",
           "table_row"]


class TableError(ValueError):
    """A table that cannot be resumed (another exploration's, or not a table)."""


def fingerprint(doc: dict, space: DesignSpace) -> str:
    """A short hash of the document and the space: a resumed table must match it."""
    text = json.dumps(doc, sort_keys=True, default=str) + repr(space)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def columns(space: DesignSpace) -> list[str]:
    n = space.names
    return ["design", "status", "feasible", *n["variables"], *n["objectives"],
            *n["constraints"], "n_points", "message"]


def _fmt(x: float) -> str:
    return repr(float(x)) if math.isfinite(x) else "nan"


def table_row(r: DesignResult) -> list:
    return [r.index, r.status.value, int(r.feasible), *map(_fmt, r.values),
            *map(_fmt, r.objectives), *map(_fmt, r.margins), r.n_points, r.message]


def _comment(space: DesignSpace, source: str, fp: str) -> str:
    units = ", ".join(f"{o.name} [{o.unit}]" for o in space.objectives)
    margins = ", ".join(f"{c.name} [{c.unit}]" for c in space.constraints)
    return (f"# drymount explore of {source}; fingerprint {fp}; objectives: {units}; "
            f"constraint margins (>= 0 satisfied): {margins or 'none'}; HBM H = "
            f"{space.harmonics} over {space.band_hz[0]:g}-{space.band_hz[1]:g} Hz\n")


def _text(comment: str, space: DesignSpace, results) -> str:
    import io

    buf = io.StringIO()
    buf.write(comment)
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns(space))
    for r in sorted(results, key=lambda r: r.index):
        w.writerow(table_row(r))
    return buf.getvalue()


def read_table(path: Path, space: DesignSpace, fp: str) -> list[DesignResult]:
    """The complete rows of a table written for the same ``space`` (fingerprint
    ``fp``); TableError if it belongs to another exploration."""
    lines = Path(path).read_text(encoding="utf-8").splitlines(keepends=True)
    if not lines or f"fingerprint {fp};" not in lines[0]:
        raise TableError(f"{path} is not a table of this exploration (another "
                         f"configuration or [design], or not written by drymount "
                         f"explore); choose another --out folder")
    complete = [ln for ln in lines[1:] if ln.endswith("\n")]
    rows = list(csv.reader(complete))
    if not rows or rows[0] != columns(space):
        raise TableError(f"{path}: its columns differ from this design space's")
    return [parse_row(space, row) for row in rows[1:]
            if len(row) == len(rows[0])]  # not a row cut by an interruption


def parse_row(space: DesignSpace, row: list) -> DesignResult:
    """The :class:`DesignResult` of a row written by :func:`table_row`."""
    nv, no = len(space.variables), len(space.objectives)
    nc = len(space.constraints)
    nums = [float(x) for x in row[3:3 + nv + no + nc]]
    return DesignResult(int(row[0]), tuple(nums[:nv]), tuple(nums[nv:nv + no]),
                        tuple(nums[nv + no:]), DesignStatus(row[1]), row[-1],
                        int(row[-2]))


class ResultsTable:
    """Appends rows to ``path`` as results arrive (see the module docstring)."""

    def __init__(self, path: Path, space: DesignSpace, source: str, fp: str,
                 done=()):
        self.path, self.space = Path(path), space
        self.comment = _comment(space, source, fp)
        self.results = {r.index: r for r in done}
        atomic_write_text(self.path, _text(self.comment, space, self.results.values()))
        with writing(self.path):
            self._fh = open(self.path, "a", encoding="utf-8", newline="")
        self._w = csv.writer(self._fh, lineterminator="\n")

    def add(self, results) -> None:
        """Append rows (a full disk: OutputError naming the file; the rows before
        stay, and a rerun resumes from them)."""
        with writing(self.path):
            for r in results:
                self.results[r.index] = r
                self._w.writerow(table_row(r))
            self._fh.flush()

    def close(self) -> None:
        if not self._fh.closed:
            self._fh.close()

    def finish(self) -> list[DesignResult]:
        """Close and rewrite the file ordered by design number; the results."""
        self.close()
        atomic_write_text(self.path, _text(self.comment, self.space,
                                           self.results.values()))
        return sorted(self.results.values(), key=lambda r: r.index)
