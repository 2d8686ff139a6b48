"""Measured inputs from CSV: road profiles, base displacement, engine forces.

A CSV file has one header row of column names, each with its unit in brackets
(``time [s]``, ``distance [m]``, ``elevation [mm]``, ``z [N]``, ``alpha [N m]``,
``z [m/s^2]``), then numbers. Lines starting with ``#`` are comments. A column
without a unit in the header takes it from ``units`` (a mapping column -> unit, e.g.
from a configuration); a column with neither is an error. Values are converted to SI.

Recognised units (case-sensitive): length ``m mm cm um km``; time ``s ms min``;
force ``N kN``; moment ``N m``/``Nm``/``N*m``, ``kN m``; acceleration ``m/s^2``
(``m/s2``), ``mm/s^2``, ``g`` (9.80665 m/s^2); angular acceleration ``rad/s^2``;
speed ``m/s``, ``km/h``.

Signals
-------
:func:`road_input`
    A road profile over ``distance`` (then a vehicle ``speed`` gives ``t = x / v``)
    or over ``time``, with the elevation in ``elevation`` (or ``displacement``):
    a base displacement time history (:class:`vehicle.SampledBase`).
:func:`engine_input`
    ``time`` and one column per DOF it drives, named by the DOF (``z``, ``alpha``):
    a force/moment (N, N m) or an acceleration (m/s^2, rad/s^2). Accelerations
    ``a`` of the engine DOFs become the forces ``M a`` (the structural mass matrix
    of the system; the forces that give the free engine this acceleration).

A configuration names them in ``[cosim.input]`` (``road``, ``speed``, ``engine``,
``units``; file names relative to the configuration file): :func:`configured_inputs`.

Both are resampled to the co-simulation step by a cubic spline through the samples
(:mod:`vehicle.sampled` states the method).
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["UNITS", "MeasuredInputError", "MeasuredTable", "MeasuredInputs",
           "read_measured", "road_input", "engine_input", "configured_inputs"]

#: unit -> (dimension, factor to SI).
UNITS = {
    "m": ("length", 1.0), "mm": ("length", 1e-3), "cm": ("length", 1e-2),
    "um": ("length", 1e-6), "km": ("length", 1e3),
    "s": ("time", 1.0), "ms": ("time", 1e-3), "min": ("time", 60.0),
    "N": ("force", 1.0), "kN": ("force", 1e3),
    "N m": ("moment", 1.0), "Nm": ("moment", 1.0), "N*m": ("moment", 1.0),
    "kN m": ("moment", 1e3),
    "m/s^2": ("acceleration", 1.0), "m/s2": ("acceleration", 1.0),
    "mm/s^2": ("acceleration", 1e-3), "g": ("acceleration", 9.80665),
    "rad/s^2": ("angular acceleration", 1.0), "rad/s2": ("angular acceleration", 1.0),
    "m/s": ("speed", 1.0), "km/h": ("speed", 1.0 / 3.6),
    "rad": ("angle", 1.0),
}



class MeasuredInputError(ValueError):
    """A measured input file that cannot be used: names the file, the column or row,
    and what is allowed."""


_HEADER = re.compile(r"^\s*([^\[\]]+?)\s*(?:\[([^\]]*)\])?\s*$")


@dataclass(frozen=True)
class MeasuredTable:
    """The columns of a measured CSV file in SI units.

    Attributes
    ----------
    path : str
    columns : dict
        Column name (without its unit) -> values, SI (m, s, N, N m, m/s^2, rad/s^2).
    units : dict
        Column name -> the unit it was given in.
    dimensions : dict
        Column name -> dimension (``"length"``, ``"time"``, ``"force"``, ...).
    """

    path: str
    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    dimensions: dict = field(default_factory=dict)

    def column(self, name: str, dimension: str) -> np.ndarray:
        """Values of column ``name`` (must have ``dimension``), SI."""
        if name not in self.columns:
            raise MeasuredInputError(f"{self.path}: no column `{name}` (columns: "
                                     f"{', '.join(self.columns)})")
        if self.dimensions[name] != dimension:
            raise MeasuredInputError(
                f"{self.path}: column `{name}` is in {self.units[name]!r}, a "
                f"{self.dimensions[name]}; it must be a {dimension}")
        return self.columns[name]


def _unit(path, name, unit, units) -> tuple[str, str, float]:
    unit = unit if unit else (units or {}).get(name)
    if not unit:
        raise MeasuredInputError(
            f"{path}: column `{name}` has no unit: write it in the header "
            f"(`{name} [m]`) or give units = {{{name!r}: ...}}")
    unit = " ".join(unit.split())
    if unit not in UNITS:
        raise MeasuredInputError(f"{path}: column `{name}` has unit {unit!r}; allowed: "
                                 f"{', '.join(UNITS)}")
    return (unit,) + UNITS[unit]


def read_measured(path, units=None) -> MeasuredTable:
    """Read a measured CSV file (see the module docstring) into SI columns.

    Parameters
    ----------
    path : path-like
    units : mapping, optional
        Column name -> unit, for columns whose header has no ``[unit]``.
    """
    path = Path(path)
    try:
        with open(path, encoding="utf-8") as fh:
            rows = [r for r in csv.reader(ln for ln in fh if not ln.startswith("#"))
                    if r]
    except OSError as exc:
        raise MeasuredInputError(
            f"cannot read the measured input {path}: {exc}") from None
    except UnicodeDecodeError as exc:
        raise MeasuredInputError(f"{path}: not UTF-8 text (byte "
                                 f"0x{exc.object[exc.start]:02x}); save the file as "
                                 f"UTF-8 CSV") from None
    ragged = [i for i, r in enumerate(rows[1:], start=2) if len(r) != len(rows[0])]
    if rows and ragged:
        n = ragged[0]
        raise MeasuredInputError(f"{path}: row {n} (the header is row 1; '#' and "
                                 f"empty lines not counted) has {len(rows[n - 1])} "
                                 f"values for {len(rows[0])} header columns")
    if len(rows) < 2:
        raise MeasuredInputError(f"{path}: needs a header row and data rows")
    cols, unit_of, dim_of = {}, {}, {}
    try:
        data = np.array([[float(v) for v in r] for r in rows[1:]], dtype=float)
    except ValueError as exc:
        raise MeasuredInputError(f"{path}: a data row is not numbers: {exc}") from None
    if data.shape[1] != len(rows[0]):
        raise MeasuredInputError(f"{path}: {data.shape[1]} values per row for "
                                 f"{len(rows[0])} header columns")
    for j, head in enumerate(rows[0]):
        m = _HEADER.match(head)
        if m is None:
            raise MeasuredInputError(f"{path}: header {head!r} must read `name [unit]`")
        name = m.group(1)
        unit, dim, factor = _unit(path, name, m.group(2), units)
        cols[name], unit_of[name], dim_of[name] = data[:, j] * factor, unit, dim
    return MeasuredTable(str(path), cols, unit_of, dim_of)


def _road_time(table: MeasuredTable, speed) -> np.ndarray:
    if "distance" in table.columns:
        if speed is None or not (math.isfinite(speed) and speed > 0):
            raise MeasuredInputError(
                f"{table.path}: a profile over distance needs the vehicle "
                f"`speed` in m/s (> 0), got {speed!r}")
        return table.column("distance", "length") / speed
    if "time" in table.columns:
        return table.column("time", "time")
    raise MeasuredInputError(
        f"{table.path}: a road profile needs a `distance` or a `time` "
        f"column (columns: {', '.join(table.columns)})")


def road_input(system, path, *, speed: float | None = None, units=None,
               direction=None):
    """A road profile or base-displacement time history from CSV as a model input.

    Parameters
    ----------
    system : hbm.system.System
    path : path-like
        Columns ``distance`` (m) or ``time`` (s), and ``elevation`` or
        ``displacement`` (m): any length/time units, converted.
    speed : float, optional
        Vehicle speed, m/s (needed with ``distance``; time = distance / speed).
    units : mapping, optional
        Units of columns whose header has none.
    direction : array_like, optional
        Base direction (default: the only base input, or ``chassis_z``).

    Returns
    -------
    vehicle.SampledBase
        Starting at the first sample (time shifted so that it is 0).
    """
    from drymount.vehicle import SampledBase

    table = read_measured(path, units)
    t = _road_time(table, speed)
    name = next((n for n in ("elevation", "displacement") if n in table.columns), None)
    if name is None:
        raise MeasuredInputError(
            f"{table.path}: a road profile needs an `elevation` or "
            f"`displacement` column (columns: {', '.join(table.columns)})")
    try:
        return SampledBase(system, t - t[0], table.column(name, "length"),
                           direction=direction)
    except ValueError as exc:
        raise MeasuredInputError(f"{table.path}: {exc}") from None


def engine_input(system, path, *, units=None):
    """Engine forces/moments or accelerations from CSV as a model input.

    Parameters
    ----------
    system : hbm.system.System
    path : path-like
        A ``time`` column (s) and one column per driven DOF, named by the DOF: all
        forces and moments (N, N m) or all accelerations (m/s^2, rad/s^2).
    units : mapping, optional
        Units of columns whose header has none.

    Returns
    -------
    vehicle.SampledForce
        Forces on the DOFs (accelerations ``a`` become ``M a``); time shifted so that
        the first sample is at 0.
    """
    from drymount.vehicle import SampledForce

    table = read_measured(path, units)
    t = table.column("time", "time")
    driven = [n for n in table.columns if n != "time"]
    kinds = {table.dimensions[n] for n in driven}
    if kinds <= {"force", "moment"}:
        forces = {n: table.columns[n] for n in driven}
    elif kinds <= {"acceleration", "angular acceleration"}:
        names = list(system.dof_names)
        bad = [n for n in driven if n not in names]
        if bad:
            raise MeasuredInputError(f"{table.path}: columns {bad} are not DOFs of "
                                     f"{system.name!r} (its DOFs: {names})")
        a = np.column_stack([table.columns[n] for n in driven])
        f = a @ np.asarray(system.M)[:, [names.index(n) for n in driven]].T
        forces = {d: f[:, i] for i, d in enumerate(names) if np.any(f[:, i])}
    else:
        raise MeasuredInputError(
            f"{table.path}: the DOF columns {driven} must all be forces "
            f"and moments or all accelerations, got units "
            f"{[table.units[n] for n in driven]}")
    try:
        return SampledForce(system, t - t[0], forces)
    except ValueError as exc:
        raise MeasuredInputError(f"{table.path}: {exc}") from None


@dataclass(frozen=True)
class MeasuredInputs:
    """The measured inputs a configuration's ``[cosim.input]`` names.

    Attributes
    ----------
    road, engine : pathlib.Path or None
        CSV files (resolved against the configuration file's folder).
    speed : float or None
        Vehicle speed, m/s, for a road profile over distance.
    units : dict
        Column -> unit for columns whose header has none.
    """

    road: Path | None = None
    engine: Path | None = None
    speed: float | None = None
    units: dict = field(default_factory=dict)


def configured_inputs(cfg) -> MeasuredInputs:
    """The ``[cosim.input]`` of a checked :class:`drymount.config.Config` (empty if
    it has none). Relative file names are taken from the configuration file's folder
    (the current folder for presets and text)."""
    inp = (cfg.data.get("cosim") or {}).get("input") or {}
    src = Path(str(cfg.source).split(" with --set ")[0])
    base = src.parent if src.is_file() else Path.cwd()

    def where(key):
        return (base / inp[key]) if inp.get(key) else None

    return MeasuredInputs(where("road"), where("engine"), inp.get("speed"),
                          dict(inp.get("units") or {}))
