"""Measured rig data from CSV files with units in the header.

A rig file is a CSV table whose header names every column with its unit, in one of
the conventions rig software writes: ``deflection [mm]``, ``deflection (mm)`` or
``deflection_mm`` (``stiffness_N_per_m``: ``_per_`` for ``/``; units match ignoring
case when that is unambiguous); lines starting with ``#`` are comments.
Values are converted to SI. Three kinds are read (``docs/design-your-own-mount.md``):

- quasi-static force-deflection curve: ``deflection``, ``force``;
- harmonic-test loops: ``test`` (a label, no unit), ``time``, ``deflection``,
  ``force`` (each test an integer number of steady-state periods);
- dynamic-stiffness table: ``frequency``, ``amplitude``, ``stiffness`` (|K*|) and
  ``loss angle``, or ``storage stiffness`` (K') and ``loss stiffness`` (K''); the CSV
  of ``drymount characterise`` is one (its rows at zero preload are read).

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
           "read_stiffness_table", "parse_header_cell", "TABLE_PAIRS"]

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
_STIFFNESS = UNITS["stiffness"]
UNITS.update({
    "storage stiffness": _STIFFNESS,     # K' = Re K*
    "loss stiffness": _STIFFNESS,        # K'' = Im K*
    "preload": UNITS["force"],           # drymount characterise's static force
})
#: Columns a dynamic-stiffness table may carry besides frequency and amplitude:
#: |K*| and the loss angle, or K' and K''; a preload column selects the unloaded rows.
TABLE_PAIRS = (("stiffness", "loss angle"), ("storage stiffness", "loss stiffness"))
#: Other spellings of the column names (lower case).
ALIASES = {"displacement": "deflection", "u": "deflection", "f": "force",
           "t": "time", "freq": "frequency", "x": "amplitude",
           "dynamic stiffness": "stiffness", "|k*|": "stiffness",
           "loss_angle": "loss angle", "delta": "loss angle", "phase": "loss angle",
           "k'": "storage stiffness", "k real": "storage stiffness",
           "storage": "storage stiffness", "k''": "loss stiffness",
           "k imag": "loss stiffness", "frequency hz": "frequency"}
#: The three header conventions of rig software: ``name [unit]``, ``name (unit)``
#: and ``name_unit`` (``stiffness_N_per_m``, ``freq_hz``: drymount's own CSVs).
_HEADER = re.compile(r"^\s*(?P<name>[^\[\]()]+?)\s*(\[(?P<unit>[^\]]*)\]|"
                     r"\((?P<unit2>[^)]*)\))?\s*$")


def _quantity(name: str) -> str:
    """The quantity a column name means (lower case, ``_`` as a space, aliases)."""
    name = " ".join(name.strip().lower().replace("_", " ").split())
    return ALIASES.get(name, name)


def _unit(unit: str, allowed: dict) -> str | None:
    """``unit`` as a key of ``allowed``: exact, with ``_per_`` as ``/``, or ignoring
    case when that is unambiguous (``hz``, ``n_per_mm``); None if none."""
    unit = unit.strip()
    for u in (unit, re.sub(r"[_ ]per[_ ]", "/", unit)):
        if u in allowed:
            return u
        same = [a for a in allowed if a.lower() == u.lower()]
        if len(same) == 1:
            return same[0]
    return None


def parse_header_cell(cell: str, known) -> tuple[str, str | None]:
    """``(quantity, unit text or None)`` of one header cell, for each convention:
    ``name [unit]``, ``name (unit)``, ``name_unit`` (the last split of the name at an
    underscore whose left part is a quantity of ``known`` and whose right part is one
    of its units; else the right part of the first split whose left part is a
    quantity, so that a wrong unit is named)."""
    m = _HEADER.match(cell)
    if m and (m["unit"] is not None or m["unit2"] is not None):
        return _quantity(m["name"]), (m["unit"] if m["unit"] is not None
                                      else m["unit2"])
    text = cell.strip()
    whole = _quantity(text)
    if whole in known:
        return whole, None
    cuts = [i for i, ch in enumerate(text) if ch == "_"]
    wrong = None
    for i in reversed(cuts):
        name, unit = _quantity(text[:i]), text[i + 1:]
        if name in known:
            if name in UNITS and _unit(unit, UNITS[name]) is not None:
                return name, unit
            wrong = wrong or (name, unit)
    return wrong or (whole, None)


@dataclass(frozen=True)
class RigTable:
    """Columns of a rig file in SI units (``labels``: the text column, if any)."""

    path: Path
    columns: dict
    labels: list | None
    lines: list  # file line number of each data row (1-based)


def _header(path: Path, cells: list[str], quantities, text_column,
            optional=()) -> dict:
    """Map each wanted quantity to ``(column index, factor to SI)`` (the ``optional``
    ones only when present)."""
    found, problems = {}, []
    known = set(quantities) | set(optional) | ({text_column} if text_column else set())
    for i, cell in enumerate(cells):
        name, unit = parse_header_cell(cell, known)
        if name == text_column:
            found[name] = (i, None)
            continue
        if name not in known or name in found:
            continue
        allowed = UNITS[name]
        key = _unit(unit, allowed) if unit else None
        if not unit or not unit.strip():
            problems.append(f"{path}: column {cell.strip()!r} has no unit; write it as "
                            f"`{name} [{next(iter(allowed))}]` (allowed units: "
                            f"{', '.join(allowed)})")
        elif key is None:
            problems.append(f"{path}: column {cell.strip()!r} has unit "
                            f"{unit.strip()!r}; allowed: {', '.join(allowed)}")
        else:
            found[name] = (i, allowed[key])
    wanted = list(quantities) + ([text_column] if text_column else [])
    for q in wanted:
        if q not in found and not any(q in p for p in problems):
            unit = f" [{next(iter(UNITS[q]))}]" if q in UNITS else ""
            problems.append(f"{path}: no column `{q}{unit}` in the header "
                            f"{','.join(cells)!r}")
    if problems:
        raise DataError(problems)
    return found


def read_table(path, quantities, text_column: str | None = None,
               optional=()) -> RigTable:
    """Read the columns ``quantities`` (keys of ``UNITS``) of a rig CSV file, in SI,
    and those of ``optional`` that it has."""
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
        table = _numeric_table(path, text, quantities, optional)
        if table is not None:
            return table
    rows = [(n, r) for n, r in enumerate(csv.reader(text.splitlines()), start=1)
            if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise DataError([f"{path}: no header line (e.g. `deflection [m],force [N]`)"])
    (_, head), body = rows[0], rows[1:]
    cols = _header(path, head, quantities, text_column, optional)
    quantities = [q for q in list(quantities) + list(optional) if q in cols]
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


def _numeric_table(path: Path, text: str, quantities,
                   optional=()) -> RigTable | None:
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
    cols = _header(path, head, quantities, None, optional)
    quantities = [q for q in list(quantities) + list(optional) if q in cols]
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
    """Rows of a dynamic-stiffness table (zero preload).

    Columns ``frequency`` and ``amplitude`` and either ``stiffness`` (|K*|) and
    ``loss angle`` or ``storage stiffness`` (K') and ``loss stiffness`` (K''), in any
    of the header conventions (``drymount characterise``'s ``freq_hz``,
    ``stiffness_N_per_m``, ... included). A ``preload`` column (characterise's
    ``preload_N``) selects the rows at zero preload: the fits model the unloaded
    mount."""
    pairs = [q for pair in TABLE_PAIRS for q in pair]
    t = read_table(path, ("frequency", "amplitude"), optional=pairs + ["preload"])
    c = t.columns
    pair = next((pr for pr in TABLE_PAIRS if all(q in c for q in pr)), None)
    if pair is None:
        raise DataError([f"{t.path}: a dynamic-stiffness table needs the columns "
                         f"`stiffness [N/m]` and `loss angle [deg]`, or "
                         f"`storage stiffness [N/m]` (K') and `loss stiffness [N/m]` "
                         f"(K''); found {', '.join(sorted(c)) or 'neither'}"])
    rows = np.arange(c["frequency"].size)
    if "preload" in c:
        rows = np.flatnonzero(c["preload"] == 0.0)
        if not rows.size:
            loads = ", ".join(f"{x:g}" for x in sorted(set(c["preload"].tolist())))
            raise DataError([f"{t.path}: `preload` is {loads} N in every row; the fit "
                             f"models the unloaded mount and needs rows at preload 0 "
                             f"(run `drymount characterise` with `--preloads 0`)"])
    if pair[0] == "stiffness":
        mag, ang = c["stiffness"], c["loss angle"]
    else:
        K = c["storage stiffness"] + 1j * c["loss stiffness"]
        mag, ang = np.abs(K), np.degrees(np.angle(K))
    return [StiffnessPoint(float(c["frequency"][i]), float(c["amplitude"][i]),
                           float(mag[i]), float(ang[i])) for i in rows]
