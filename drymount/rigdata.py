"""Measured rig data from CSV files with units in the header.

A rig file is a CSV table whose header names every column with its unit in square
brackets, e.g. ``deflection [mm],force [kN]``; lines starting with ``#`` are comments.
Values are converted to SI. Three kinds are read (``docs/design-your-own-mount.md``):

- quasi-static force-deflection curve: ``deflection``, ``force``;
- harmonic-test loops: ``test`` (a label, no unit), ``time``, ``deflection``,
  ``force`` (each test an integer number of steady-state periods);
- dynamic-stiffness table: ``frequency``, ``amplitude``, ``stiffness`` (|K*|),
  ``loss angle``.

Every problem (missing column or unit, unknown unit, a cell that is not a number, a
NaN) raises :class:`hbm.identify.DataError` naming the file, the line and the value.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drymount.hbm.identify import DataError, LoopTest, StiffnessPoint

__all__ = ["UNITS", "RigTable", "read_table", "read_curve", "read_loops",
           "read_stiffness_table"]

_LENGTH = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6}
#: Accepted units of each quantity and their factor to SI.
UNITS = {
    "deflection": _LENGTH,
    "amplitude": _LENGTH,
    "force": {"N": 1.0, "kN": 1e3},
    "time": {"s": 1.0, "ms": 1e-3},
    "frequency": {"Hz": 1.0},
    "stiffness": {"N/m": 1.0, "N/mm": 1e3, "kN/m": 1e3, "kN/mm": 1e6},
    "loss angle": {"deg": 1.0, "rad": 180.0 / math.pi},
}
#: Other spellings of the column names (lower case).
ALIASES = {"displacement": "deflection", "u": "deflection", "f": "force",
           "t": "time", "freq": "frequency", "x": "amplitude",
           "dynamic stiffness": "stiffness", "|k*|": "stiffness",
           "loss_angle": "loss angle", "delta": "loss angle", "phase": "loss angle"}
_HEADER = re.compile(r"^\s*(?P<name>[^\[\]]+?)\s*(\[(?P<unit>[^\]]*)\])?\s*$")


@dataclass(frozen=True)
class RigTable:
    """Columns of a rig file in SI units (``labels``: the text column, if any)."""

    path: Path
    columns: dict
    labels: list | None
    lines: list  # file line number of each data row (1-based)


def _header(path: Path, cells: list[str], quantities, text_column) -> dict:
    """Map each wanted quantity to ``(column index, factor to SI)``."""
    found, problems = {}, []
    for i, cell in enumerate(cells):
        m = _HEADER.match(cell)
        if not m:
            continue
        name = m["name"].strip().lower()
        name = ALIASES.get(name, name)
        if name == text_column:
            found[name] = (i, None)
            continue
        if name not in quantities:
            continue
        allowed = UNITS[name]
        unit = (m["unit"] or "").strip()
        if not unit:
            problems.append(f"{path}: column {cell.strip()!r} has no unit; write it as "
                            f"`{name} [{next(iter(allowed))}]` (allowed units: "
                            f"{', '.join(allowed)})")
        elif unit not in allowed:
            problems.append(f"{path}: column {cell.strip()!r} has unit {unit!r}; "
                            f"allowed: {', '.join(allowed)}")
        else:
            found[name] = (i, allowed[unit])
    wanted = list(quantities) + ([text_column] if text_column else [])
    for q in wanted:
        if q not in found and not any(q in p for p in problems):
            unit = f" [{next(iter(UNITS[q]))}]" if q in UNITS else ""
            problems.append(f"{path}: no column `{q}{unit}` in the header "
                            f"{','.join(cells)!r}")
    if problems:
        raise DataError(problems)
    return found


def read_table(path, quantities, text_column: str | None = None) -> RigTable:
    """Read the columns ``quantities`` (keys of ``UNITS``) of a rig CSV file, in SI."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise DataError([f"cannot read {path}: {exc.strerror or exc}"]) from None
    except UnicodeDecodeError as exc:
        line = exc.object[:exc.start].count(b"\n") + 1
        raise DataError([f"{path}, line {line}: not UTF-8 text (byte "
                         f"0x{exc.object[exc.start]:02x}); save the file as UTF-8 "
                         f"CSV"]) from None
    if text_column is None:  # numbers only: parsed in C (1e6 rows in about a second)
        table = _numeric_table(path, text, quantities)
        if table is not None:
            return table
    rows = [(n, r) for n, r in enumerate(csv.reader(text.splitlines()), start=1)
            if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise DataError([f"{path}: no header line (e.g. `deflection [m],force [N]`)"])
    (_, head), body = rows[0], rows[1:]
    cols = _header(path, head, quantities, text_column)
    values = {q: [] for q in quantities}
    labels = [] if text_column else None
    problems = []
    for line, r in body:
        if len(r) != len(head):  # a short or a ragged long row
            problems.append(f"{path}, line {line}: {len(r)} cells, the header has "
                            f"{len(head)}")
            continue
        for q in quantities:
            i, factor = cols[q]
            try:
                x = float(r[i])
            except ValueError:
                x = None
            if x is None or not math.isfinite(x):
                problems.append(f"{path}, line {line}: `{q}` must be a finite number, "
                                f"got {r[i].strip()!r}")
                x = math.nan
            values[q].append(x * factor)
        if text_column:
            labels.append(r[cols[text_column][0]].strip())
    if problems:
        raise DataError(problems[:10] + ([f"... and {len(problems) - 10} more"]
                                         if len(problems) > 10 else []))
    return RigTable(path, {q: np.array(v) for q, v in values.items()}, labels,
                    [line for line, _ in body])


def _numeric_table(path: Path, text: str, quantities) -> RigTable | None:
    """The table of a file of plain numbers (comment lines only before the header,
    no quotes, no blank lines), read by numpy; None when anything is unusual, and the
    line-by-line reader, which names the line of each problem, reads it instead."""
    pos, first = 0, 1  # skip the leading comment and blank lines
    while pos < len(text):
        end = text.find("\n", pos)
        end = len(text) if end < 0 else end
        line = text[pos:end]
        if line.strip() and not line.lstrip().startswith("#"):
            break
        pos, first = end + 1, first + 1
    end = text.find("\n", pos)
    if end < 0:
        return None
    header, body = text[pos:end].rstrip("\r"), text[end + 1:]
    if any(ch in text[pos:] for ch in '"#\r') or "\n\n" in body or not body.strip():
        return None
    head = next(csv.reader([header]))
    cols = _header(path, head, quantities, None)
    try:
        arr = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2, comments=None,
                         dtype=float)
    except ValueError:
        return None
    n = body.count("\n") + (not body.endswith("\n"))
    if arr.shape != (n, len(head)) or not np.isfinite(arr).all():
        return None
    columns = {q: arr[:, cols[q][0]] * cols[q][1] for q in quantities}
    return RigTable(path, columns, None, list(range(first + 1, first + 1 + n)))


def read_curve(path) -> tuple[np.ndarray, np.ndarray]:
    """Deflection (m) and force (N) of a quasi-static force-deflection curve."""
    t = read_table(path, ("deflection", "force"))
    return t.columns["deflection"], t.columns["force"]


def read_loops(path) -> list[LoopTest]:
    """The harmonic tests of a loop file, one :class:`LoopTest` per ``test`` label."""
    t = read_table(path, ("time", "deflection", "force"), text_column="test")
    order = list(dict.fromkeys(t.labels))
    lab = np.array(t.labels)
    tests = []
    for name in order:
        sel = lab == name
        tests.append(LoopTest(name, t.columns["time"][sel],
                              t.columns["deflection"][sel], t.columns["force"][sel]))
    return tests


def read_stiffness_table(path) -> list[StiffnessPoint]:
    """Rows of a dynamic-stiffness table (zero preload)."""
    t = read_table(path, ("frequency", "amplitude", "stiffness", "loss angle"))
    c = t.columns
    return [StiffnessPoint(float(f), float(a), float(k), float(d)) for f, a, k, d in
            zip(c["frequency"], c["amplitude"], c["stiffness"], c["loss angle"],
                strict=True)]
