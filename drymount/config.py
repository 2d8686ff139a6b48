"""Configuration files: TOML -> a checked :class:`Config` holding a model System.

A configuration describes one of the thesis's three systems (``model = "sdof"``,
``"quarter_car"`` or ``"rigid_engine"``), its mount law(s), its harmonic excitation, and
the settings of the runs (frequency sweep, harmonic balance, co-simulation). The field
names are those of :class:`fmu_src.mount_law.AxisParameters` and of the builders of
:mod:`vehicle.models`; units are SI. ``docs/config.md`` documents every field.

Example (the single DOF of the thesis, Sec. 2.1.1, with a friction element)::

    model = "sdof"
    name = "my_mount"

    [sdof]
    mass = 70.0                 # kg

    [mount]
    law = "piecewise"           # thesis eq. 2.16-2.20, 3.30
    k1 = 45935.0                # N/m
    k2 = 256900.0               # N/m
    delta = 0.01225             # m
    c = 150.0                   # N s/m

    [mount.friction]            # macro-slip (Jenkins) element, thesis Sec. 2.2
    kf = 60000.0                # N/m
    mu = 1.0
    n0 = 10.0                   # N

    [excitation]
    kind = "unbalance"          # f = f0 omega^2 sin(omega t), thesis eq. 4.2
    amplitude = 0.0305          # f0, kg m

Every problem of a file is collected and raised together as one :class:`ConfigError`
whose ``problems`` name the field path (``mounts[2].axial.friction.kf``, indices from
0), the value and what is allowed. Unknown keys get the closest valid key as a hint.

Public functions: :func:`load_config`, :func:`config_from_dict`, :func:`load_preset`,
:func:`list_presets`, :func:`preset_text`, :func:`resolve_config`.
"""

from __future__ import annotations

import difflib
import math
import sys
import warnings
from dataclasses import dataclass, field, fields, replace
from importlib import resources
from pathlib import Path

import numpy as np

from fmu_src.mount_law import AXES, LAWS, AxisParameters, MountParameters
from hbm.system import System

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "MODELS",
    "Config",
    "ConfigError",
    "SweepSettings",
    "HBMSettings",
    "CosimSettings",
    "load_config",
    "config_from_dict",
    "load_preset",
    "list_presets",
    "preset_text",
    "resolve_config",
    "ALLOWED_KEYS",
]

#: Values of the top-level ``model`` key.
MODELS = ("sdof", "quarter_car", "rigid_engine")
#: Excitation kinds allowed per model (``hbm.system.Excitation``).
EXCITATION_KINDS = {
    "sdof": ("unbalance", "force", "base"),
    "quarter_car": ("base",),
    "rigid_engine": ("base", "unbalance", "force"),
}
BACKENDS = ("fmu", "native")
DIRECTIONS = ("up", "down")
SPACINGS = ("linear", "log")
#: Largest number of harmonics accepted (a sanity bound: H = 7 already converges the
#: friction systems to 1e-3; 50 harmonics cost ~50x more per Newton step).
MAX_HARMONICS = 50
#: Relative size below which the smallest eigenvalue of the linearised (stuck)
#: stiffness counts as zero: the mounts leave a rigid-body motion free.
SINGULAR_RTOL = 1e-10

_AXIS_LAW_KEYS = ("law", "k1", "kc", "k2", "delta", "delta_neg", "c")
_FRICTION_KEYS = ("kf", "mu", "n0")

#: Allowed keys of every table, by the path pattern used in messages and in
#: docs/config.md (``[]`` stands for an index of ``[[mounts]]``).
ALLOWED_KEYS: dict[str, tuple[str, ...]] = {
    "": ("model", "name", "description", "sdof", "quarter_car", "rigid_engine",
         "mount", "mounts", "excitation", "sweep", "hbm", "cosim"),
    "sdof": ("mass",),
    "quarter_car": ("m_e", "m_s", "m_us", "k_s", "c_s", "k_t", "c_t"),
    "rigid_engine": ("mass", "inertia"),
    "mount": (*_AXIS_LAW_KEYS, "friction"),
    "mount.friction": _FRICTION_KEYS,
    "mounts[]": ("name", "position", "orientation", "lambda", *AXES),
    "mounts[].<axis>": (*_AXIS_LAW_KEYS, "friction"),
    "mounts[].<axis>.friction": _FRICTION_KEYS,
    "excitation": ("kind", "amplitude"),
    "sweep": ("fmin_hz", "fmax_hz", "points", "direction", "spacing"),
    "hbm": ("harmonics", "n_samples", "tol", "max_harmonics", "ds_initial", "ds_min",
            "ds_max", "max_angle"),
    "cosim": ("backend", "freq_hz", "duration", "steps_per_period"),
}

#: The model-specific tables: which model each belongs to.
_MODEL_TABLES = {"sdof": "sdof", "quarter_car": "quarter_car",
                 "rigid_engine": "rigid_engine", "mount": ("sdof", "quarter_car"),
                 "mounts": ("rigid_engine",)}


class ConfigError(ValueError):
    """An invalid configuration. ``problems`` lists every problem found.

    Each problem names the field path (``mounts[2].axial.friction.kf``; indices of
    ``[[mounts]]`` count from 0), the value found and what is allowed. ``str()`` gives
    a message with one problem per line, meant to be printed as is.
    """

    def __init__(self, problems: list[str], source: str | None = None):
        self.problems = list(problems)
        self.source = source
        super().__init__(self._message())

    def _message(self) -> str:
        n = len(self.problems)
        where = f" {self.source}" if self.source else ""
        head = f"invalid configuration{where}: {n} problem{'s' if n != 1 else ''}"
        return "\n".join([head + ":"] + [f"  - {p}" for p in self.problems])


# ======================================================================================
# Result objects
# ======================================================================================


@dataclass(frozen=True)
class SweepSettings:
    """Frequency band of ``drymount hbm`` and ``drymount sweep``.

    Attributes
    ----------
    fmin_hz, fmax_hz : float
        Band in Hz, 0 < fmin_hz < fmax_hz.
    points : int
        Number of frequencies of a stepped-sine sweep (>= 2). The HBM continuation
        chooses its own steps between fmin_hz and fmax_hz.
    direction : str
        ``"up"`` or ``"down"``: order of the stepped sweep.
    spacing : str
        ``"linear"`` or ``"log"``: spacing of the sweep frequencies.
    """

    fmin_hz: float = 1.0
    fmax_hz: float = 50.0
    points: int = 50
    direction: str = "up"
    spacing: str = "linear"

    def freqs_hz(self) -> np.ndarray:
        """The sweep frequencies in Hz, shape (points,), ascending."""
        if self.spacing == "log":
            return np.geomspace(self.fmin_hz, self.fmax_hz, self.points)
        return np.linspace(self.fmin_hz, self.fmax_hz, self.points)


@dataclass(frozen=True)
class HBMSettings:
    """Harmonic balance settings (``hbm.frequency_response``).

    Attributes
    ----------
    harmonics : int
        Number of harmonics H (1..MAX_HARMONICS); 1 is the thesis's single harmonic.
    n_samples : int or None
        AFT time samples per period (>= 2H + 1); None lets ``hbm`` choose.
    tol : float or None
        Wanted accuracy relative to the peak (``hbm.HBMOptions.tol``); None: its
        default (1e-3).
    max_harmonics : int or None
        Cap on H when ``tol`` raises it (``hbm.HBMOptions.max_harmonics``).
    ds_initial, ds_min, ds_max, max_angle : float or None
        Continuation step controls (scaled arc length, rad); None: the defaults of
        ``hbm.HBMOptions``.
    """

    harmonics: int = 7
    n_samples: int | None = None
    tol: float | None = None
    max_harmonics: int | None = None
    ds_initial: float | None = None
    ds_min: float | None = None
    ds_max: float | None = None
    max_angle: float | None = None

    def options(self, **overrides):
        """``hbm.HBMOptions`` with these settings (None: hbm's default), H as the
        starting number of harmonics; ``overrides`` (not None) win."""
        import hbm

        kw = {"harmonics": self.harmonics}
        for k in ("n_samples", "tol", "max_harmonics", "ds_initial", "ds_min", "ds_max",
                  "max_angle"):
            v = overrides.get(k)
            v = getattr(self, k) if v is None else v
            if v is not None:
                kw[k] = v
        return hbm.HBMOptions(**kw)


@dataclass(frozen=True)
class CosimSettings:
    """Co-simulation settings (``vehicle.simulate``, ``vehicle.sweep``).

    Attributes
    ----------
    backend : str
        ``"fmu"`` (one FMU instance per mount through fmpy) or ``"native"`` (the same
        mount law called in-process, for long sweeps).
    freq_hz : float or None
        Default excitation frequency of ``drymount cosim``, Hz.
    duration : float or None
        Default simulated time of ``drymount cosim``, s (None: the harness default).
    steps_per_period : int or None
        Fixed steps per excitation period (dt = 1 / (freq_hz * steps_per_period));
        None: the harness default.
    """

    backend: str = "fmu"
    freq_hz: float | None = None
    duration: float | None = None
    steps_per_period: int | None = None

    def dt(self, freq_hz: float) -> float | None:
        """Step size in s at ``freq_hz`` (None when ``steps_per_period`` is unset)."""
        if self.steps_per_period is None:
            return None
        return 1.0 / (float(freq_hz) * self.steps_per_period)


@dataclass(frozen=True, eq=False)
class Config:
    """A checked configuration.

    Attributes
    ----------
    name : str
        ``name`` of the file, else the preset name or the file stem.
    description : str
    model : str
        One of ``MODELS``.
    system : hbm.system.System
        The model with its mounts and excitation, ready for ``hbm`` and ``vehicle``;
        its ``name`` and ``description`` are the configuration's, ``system.notes``
        holds ``config_name``, ``model`` and ``source``.
    sweep : SweepSettings
    hbm : HBMSettings
    cosim : CosimSettings
    source : str
        Where it came from: a file path, ``preset:<name>`` or ``<text>``.
    data : dict
        The parsed TOML document.
    """

    name: str
    description: str
    model: str
    system: System
    sweep: SweepSettings
    hbm: HBMSettings
    cosim: CosimSettings
    source: str
    data: dict = field(repr=False, default_factory=dict)


# ======================================================================================
# Checking
# ======================================================================================


def _join(path: str, key) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else str(key)


def _type_name(v) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, int):
        return "an integer"
    if isinstance(v, float):
        return "a float"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return "an array"
    return f"a {type(v).__name__}"


def _show(v) -> str:
    """Short display of a value for a message."""
    if isinstance(v, dict):
        return "{" + ", ".join(str(k) for k in list(v)[:6]) + (
            ", ...}" if len(v) > 6 else "}")
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _as_float(v) -> float | None:
    """``float(v)`` for a TOML number, None for anything else or a too large int."""
    if not _is_number(v):
        return None
    try:
        return float(v)
    except OverflowError:
        return None


_RULES = {
    ">0": (lambda x: x > 0, "> 0"),
    ">=0": (lambda x: x >= 0, ">= 0"),
    "any": (lambda x: True, ""),
}


class _Checker:
    """Collects problems while reading a parsed TOML document."""

    def __init__(self):
        self.problems: list[str] = []

    def add(self, msg: str) -> None:
        self.problems.append(msg)

    # -- tables and keys --------------------------------------------------------------

    def table(self, data: dict, key: str, path: str, required: bool = True,
              what: str = "") -> dict | None:
        """``data[key]`` if it is a table; None (with a problem if required) else."""
        p = _join(path, key)
        if key not in data:
            if required:
                self.add(f"`{p}` is missing: a table {what}is required")
            return None
        v = data[key]
        if not isinstance(v, dict):
            self.add(f"`{p}` must be a table ([{p}] ...), got {_type_name(v)} "
                     f"{_show(v)}")
            return None
        return v

    def keys(self, data: dict, path: str, allowed, hints: dict | None = None) -> None:
        """Report each key of ``data`` that is not in ``allowed``, with a suggestion."""
        allowed = tuple(allowed)
        for k in data:
            if k in allowed:
                continue
            p = _join(path, k)
            hint = (hints or {}).get(k)
            if hint is None:
                close = difflib.get_close_matches(str(k), allowed, n=1, cutoff=0.6)
                hint = f"did you mean `{close[0]}`?" if close else ""
            msg = f"unknown key `{p}` (value {_show(data[k])})"
            if hint:
                msg += f": {hint}"
            msg += f"; allowed here: {', '.join(allowed)}"
            self.add(msg)

    # -- scalars ----------------------------------------------------------------------

    def number(self, data: dict, key: str, path: str, rule: str = ">=0", unit: str = "",
               required: bool = True, default=None, finite: bool = True):
        """A float satisfying ``rule``; ``default`` if absent and not required.

        Returns None after recording a problem. With ``finite=False`` NaN/inf pass
        through (left to a later check that reports them with its own rule).
        """
        p = _join(path, key)
        unit_txt = f" in {unit}" if unit else ""
        test, rule_txt = _RULES[rule]
        what = f"a number{unit_txt}" + (f" {rule_txt}" if rule_txt else "")
        if key not in data:
            if required:
                self.add(f"`{p}` is missing: {what} is required")
            return default
        v = data[key]
        x = _as_float(v)
        if x is None:
            self.add(f"`{p}` must be {what}, got {_type_name(v)} {_show(v)}")
            return None
        if not finite:
            return x
        if not math.isfinite(x) or not test(x):
            self.add(f"`{p}` must be finite and {rule_txt or 'real'}{unit_txt}, "
                     f"got {_show(v)}")
            return None
        return x

    def integer(self, data: dict, key: str, path: str, minimum: int,
                maximum: int | None = None, required: bool = False, default=None):
        p = _join(path, key)
        rng = f">= {minimum}" if maximum is None else f"in {minimum}..{maximum}"
        if key not in data:
            if required:
                self.add(f"`{p}` is missing: an integer {rng} is required")
            return default
        v = data[key]
        if not isinstance(v, int) or isinstance(v, bool):
            self.add(f"`{p}` must be an integer {rng}, got {_type_name(v)} {_show(v)}")
            return None
        if v < minimum or (maximum is not None and v > maximum):
            self.add(f"`{p}` must be an integer {rng}, got {v}")
            return None
        return v

    def choice(self, data: dict, key: str, path: str, choices, required: bool = True,
               default=None, extra: str = ""):
        p = _join(path, key)
        allowed = ", ".join(f'"{c}"' for c in choices)
        if key not in data:
            if required:
                self.add(f"`{p}` is missing: one of {allowed} is required{extra}")
            return default
        v = data[key]
        if not isinstance(v, str) or v not in choices:
            close = (difflib.get_close_matches(v, choices, n=1, cutoff=0.6)
                     if isinstance(v, str) else [])
            hint = f" (did you mean \"{close[0]}\"?)" if close else ""
            self.add(f"`{p}` must be one of {allowed}, got {_show(v)}{hint}{extra}")
            return None
        return v

    def string(self, data: dict, key: str, path: str, default: str = "") -> str:
        p = _join(path, key)
        if key not in data:
            return default
        v = data[key]
        if not isinstance(v, str):
            self.add(f"`{p}` must be a string, got {_type_name(v)} {_show(v)}")
            return default
        return v

    def vector(self, data: dict, key: str, path: str, length: int, unit: str = "",
               rule: str = "any", required: bool = True, default=None):
        """A list of ``length`` finite numbers satisfying ``rule`` each."""
        p = _join(path, key)
        test, rule_txt = _RULES[rule]
        unit_txt = f" in {unit}" if unit else ""
        each = f", each finite{(' and ' + rule_txt) if rule_txt else ''}"
        what = f"an array of {length} numbers{unit_txt}{each}"
        if key not in data:
            if required:
                self.add(f"`{p}` is missing: {what} is required")
            return default
        v = data[key]
        if not isinstance(v, list) or len(v) != length:
            n = f" of length {len(v)}" if isinstance(v, list) else ""
            self.add(f"`{p}` must be {what}, got {_type_name(v)}{n} {_show(v)}")
            return None
        out = []
        ok = True
        for i, item in enumerate(v):
            x = _as_float(item)
            if x is None or not math.isfinite(x) or not test(x):
                self.add(f"`{p}[{i}]` must be a finite number{unit_txt}"
                         f"{(' ' + rule_txt) if rule_txt else ''}, got "
                         f"{_type_name(item)} {_show(item)}")
                ok = False
            else:
                out.append(x)
        return out if ok else None


# -- mount law ------------------------------------------------------------


def _unchecked_axis(**kw) -> AxisParameters:
    """An AxisParameters without its ``__post_init__`` check (to call ``problems``)."""
    obj = object.__new__(AxisParameters)
    defaults = AxisParameters.__dataclass_fields__
    for f in fields(AxisParameters):
        object.__setattr__(obj, f.name, kw.get(f.name, defaults[f.name].default))
    return obj


def _law_problems(axis: AxisParameters, path: str) -> list[str]:
    """``AxisParameters.problems``, friction fields under ``<path>.friction``."""
    prefix = path + "."
    out = []
    for msg in axis.problems(prefix):
        for name in _FRICTION_KEYS:
            msg = msg.replace(f"`{prefix}{name}`", f"`{prefix}friction.{name}`")
        out.append(msg)
    return out


def _friction(ck: _Checker, data: dict, path: str) -> dict | None:
    """The friction sub-table of an axis -> AxisParameters keywords, or None (off)."""
    if "friction" not in data:
        return {"friction": False}
    p = _join(path, "friction")
    fr = data["friction"]
    if not isinstance(fr, dict):
        ck.add(f"`{p}` must be a table with kf [N/m], mu [-] and n0 [N] (remove it "
               f"for a mount without friction), got {_type_name(fr)} {_show(fr)}")
        return None
    ck.keys(fr, p, _FRICTION_KEYS, hints={
        "normal_force": "the normal force is `n0`", "N": "the normal force is `n0`",
        "fs": "give the normal force `n0` and `mu` (Fs = mu * n0)",
        "enabled": "the table's presence switches friction on; remove the table "
                   "to switch it off"})
    kw = {"friction": True}
    ok = True
    if "n0" not in fr:
        ck.add(f"`{p}.n0` is missing: a friction element needs its normal force n0, "
               f"a number in N > 0 (remove the [{p}] table for a mount without "
               f"friction)")
        ok = False
    if "kf" not in fr:
        ck.add(f"`{p}.kf` is missing: the contact stiffness of the friction element, "
               f"a number in N/m > 0, is required (the thesis does not print it; the "
               f"presets use 60000)")
        ok = False
    for name, default in (("kf", None), ("mu", 1.0), ("n0", None)):
        if name in fr:
            x = _as_float(fr[name])
            if x is None:
                unit = {"kf": "N/m", "mu": "[-]", "n0": "N"}[name]
                ck.add(f"`{p}.{name}` must be a number ({unit}), got "
                       f"{_type_name(fr[name])} {_show(fr[name])}")
                ok = False
            else:
                kw[name] = x
        elif default is not None:
            kw[name] = default
    if not ok:
        return None
    # with Fs = mu * n0 = 0 the element carries no force: almost surely a mistake
    for name, unit in (("n0", "N"), ("mu", "[-]")):
        x = kw[name]
        if math.isfinite(x) and x == 0:
            ck.add(f"`{p}.{name}` must be > 0 in a friction table ({unit}), got "
                   f"{_show(fr[name])}: with mu * n0 = 0 the element does nothing; "
                   f"remove the [{p}] table instead")
    return kw


def _axis(ck: _Checker, data, path: str) -> AxisParameters | None:
    """One full axis table (law fields + optional friction) -> AxisParameters."""
    if not isinstance(data, dict):
        ck.add(f"`{path}` must be a table of mount-law fields, got {_type_name(data)} "
               f"{_show(data)}")
        return None
    n_before = len(ck.problems)
    ck.keys(data, path, ALLOWED_KEYS["mount"], hints={
        "kf": "friction fields go in the sub-table "
              f"[{path}.friction]", "mu": f"friction fields go in [{path}.friction]",
        "n0": f"friction fields go in [{path}.friction]",
        "k": "the small-deflection stiffness is `k1`",
        "stiffness": "the small-deflection stiffness is `k1`",
        "damping": "the viscous damping is `c`"})
    law = ck.choice(data, "law", path, LAWS)
    needed = {"k1", "c"}
    if law == "cubic":
        needed |= {"kc"}
    elif law in ("piecewise", "piecewise_asym"):
        needed |= {"k2", "delta"}
    if law == "piecewise_asym":
        needed |= {"delta_neg"}
    units = {"k1": "N/m", "kc": "N/m^3", "k2": "N/m", "delta": "m", "delta_neg": "m",
             "c": "N s/m"}
    kw = {}
    for name in ("k1", "kc", "k2", "delta", "delta_neg", "c"):
        if name in data:
            x = ck.number(data, name, path, rule="any", unit=units[name], finite=False)
            if x is not None:
                kw[name] = x
        elif name in needed:
            why = f" (law \"{law}\")" if name not in ("k1", "c") else ""
            typo = [k for k in data if k not in ALLOWED_KEYS["mount"]
                    and difflib.get_close_matches(str(k), [name], n=1, cutoff=0.6)]
            if typo:
                why += f"; is `{typo[0]}` a misspelling of it?"
            ck.add(f"`{_join(path, name)}` is missing: a number in {units[name]} is "
                   f"required{why}")
    fr = _friction(ck, data, path)
    if len(ck.problems) > n_before or law is None or fr is None:
        return None
    # fields the law does not use get neutral values (kept for the FMU's parameters)
    kw.setdefault("kc", 0.0)
    kw.setdefault("k2", kw["k1"])
    kw.setdefault("delta", AxisParameters.delta)
    kw.setdefault("delta_neg", kw["delta"])
    kw.update(fr)
    axis = _unchecked_axis(law=law, **kw)
    problems = _law_problems(axis, path)
    if problems:
        ck.problems.extend(problems)
        return None
    return AxisParameters(**axis.to_dict())


def _single_mount(ck: _Checker, data: dict) -> MountParameters | None:
    """``[mount]`` of the sdof and quarter-car models (its axial axis is used)."""
    tbl = ck.table(data, "mount", "", what="with the mount law (law, k1, c, ...) ")
    if tbl is None:
        return None
    axis = _axis(ck, tbl, "mount")
    if axis is None:
        return None
    # only the axial axis deflects in these models; the unused radial axes carry the
    # same elastic law without a friction element (so that nothing reports friction
    # on an axis that never moves)
    radial = replace(axis, friction=False)
    return MountParameters(axis, radial, radial)


def _rigid_mount(ck: _Checker, m, i: int):
    """One ``[[mounts]]`` entry -> (name, position, orientation, MountParameters)."""
    path = f"mounts[{i}]"
    if not isinstance(m, dict):
        ck.add(f"`{path}` must be a table ([[mounts]] ...), got {_type_name(m)} "
               f"{_show(m)}")
        return None
    n_before = len(ck.problems)
    ck.keys(m, path, ALLOWED_KEYS["mounts[]"], hints={
        "x": "give `position = [x, y, z]`", "pos": "the key is `position`",
        "lam": "the key is `lambda`", "law": f"law fields go in [{path}.axial]",
        "k1": f"law fields go in [{path}.axial]",
        "friction": f"friction goes in the table of its axis, e.g. "
                    f"[{path}.radial1.friction]"})
    name = ck.string(m, "name", path, default=f"mount{i + 1}")
    position = ck.vector(m, "position", path, 3, unit="m")
    orientation = None
    if "orientation" in m:
        o = m["orientation"]
        rows = o if isinstance(o, list) and len(o) == 3 else None
        if rows is None:
            ck.add(f"`{path}.orientation` must be 3 rows of 3 numbers (the axial, "
                   f"radial1 and radial2 unit vectors in body axes), got "
                   f"{_type_name(o)} {_show(o)}")
        else:
            R = [ck.vector({"r": r}, "r", f"{path}.orientation[{j}]", 3)
                 for j, r in enumerate(rows)]
            if all(r is not None for r in R):
                R = np.array(R)
                if not np.allclose(R @ R.T, np.eye(3), atol=1e-6):
                    ck.add(f"`{path}.orientation` must be a rotation: orthonormal rows "
                           f"(axial, radial1, radial2 unit vectors), got "
                           f"{R.tolist()}")
                elif np.linalg.det(R) < 0:
                    ck.add(f"`{path}.orientation` must be a right-handed rotation "
                           f"(determinant +1), got determinant -1: swap radial1 and "
                           f"radial2")
                else:
                    # re-orthonormalise the rounding of hand-typed values
                    u, _, vt = np.linalg.svd(R)
                    orientation = u @ vt
    lam = None
    if "lambda" in m:
        lam = ck.number(m, "lambda", path, rule=">0", unit="")
    axial = None
    if "axial" not in m:
        ck.add(f"`{path}.axial` is missing: a table with the mount law (law, k1, c, "
               f"...) is required")
    else:
        axial = _axis(ck, m["axial"], f"{path}.axial")
    axes = {"axial": axial}
    for name_ax in ("radial1", "radial2"):
        p = f"{path}.{name_ax}"
        if "lambda" in m:
            r = m.get(name_ax, {})
            if not isinstance(r, dict):
                ck.add(f"`{p}` must be a table, got {_type_name(r)} {_show(r)}")
                continue
            law_keys = [k for k in r if k != "friction"]
            for k in law_keys:
                if k in _AXIS_LAW_KEYS:
                    ck.add(f"`{p}.{k}` conflicts with `{path}.lambda`: with lambda "
                           f"the radial law is lambda times the axial one (thesis "
                           f"eq. 4.4); "
                           f"remove `{p}.{k}`, or remove `lambda` and give the whole "
                           f"[{p}] table")
                else:
                    ck.keys({k: r[k]}, p, ("friction",))
            fr = _friction(ck, r, p)
            if axial is not None and lam is not None and fr is not None:
                base = axial.scaled(lam).to_dict()
                base.update(friction=False)
                base.update(fr)
                ax = _unchecked_axis(**base)
                probs = _law_problems(ax, p)
                if probs:
                    ck.problems.extend(probs)
                else:
                    axes[name_ax] = AxisParameters(**ax.to_dict())
        elif name_ax not in m:
            ck.add(f"`{p}` is missing: give the [{p}] table, or `lambda` in "
                   f"[[mounts]] to derive it from the axial law (radial = lambda * "
                   f"axial, thesis eq. 4.4)")
        else:
            axes[name_ax] = _axis(ck, m[name_ax], p)
    if len(ck.problems) > n_before or any(axes.get(a) is None for a in AXES):
        return None
    return name, position, orientation, MountParameters(**axes)


# -- model tables ------------------------------------------------------------


def _excitation(ck: _Checker, data: dict, model: str, n_vec: dict):
    tbl = ck.table(data, "excitation", "", what="(kind, amplitude) ")
    if tbl is None:
        return None
    ck.keys(tbl, "excitation", ALLOWED_KEYS["excitation"])
    kinds = EXCITATION_KINDS[model]
    kind = ck.choice(tbl, "kind", "excitation", kinds,
                     extra=f" for model \"{model}\"")
    units = {"unbalance": "kg m (f0 of f = f0 omega^2 sin(omega t))",
             "force": "N", "base": "m"}
    if kind is None:
        if "amplitude" not in tbl:
            ck.add("`excitation.amplitude` is missing")
        return None
    if model == "rigid_engine":
        n = n_vec[kind]
        unit = {"base": "m (chassis x, y, z)",
                "unbalance": "kg m / kg m^2 (x, y, z, alpha, beta, gamma)",
                "force": "N / N m (x, y, z, alpha, beta, gamma)"}[kind]
        amp = ck.vector(tbl, "amplitude", "excitation", n, unit=unit)
        if amp is not None and not any(a != 0 for a in amp):
            ck.add(f"`excitation.amplitude` must not be all zero (the "
                   f"transmissibility divides by it), got {amp}")
            return None
        return (kind, amp) if amp is not None else None
    amp = ck.number(tbl, "amplitude", "excitation", rule=">0", unit=units[kind])
    return (kind, amp) if amp is not None else None


def _settings(ck: _Checker, data: dict):
    sw = ck.table(data, "sweep", "", required=False) or {}
    ck.keys(sw, "sweep", ALLOWED_KEYS["sweep"])
    d = SweepSettings()
    fmin = ck.number(sw, "fmin_hz", "sweep", rule=">0", unit="Hz", required=False,
                     default=d.fmin_hz)
    fmax = ck.number(sw, "fmax_hz", "sweep", rule=">0", unit="Hz", required=False,
                     default=d.fmax_hz)
    if fmin is not None and fmax is not None and not fmax > fmin:
        what = "empty" if fmax == fmin else "reversed"
        ck.add(f"`sweep.fmax_hz` must be > `sweep.fmin_hz` = {fmin:g} Hz, got "
               f"{fmax:g} Hz: the frequency range is {what}")
    points = ck.integer(sw, "points", "sweep", minimum=2, default=d.points)
    direction = ck.choice(sw, "direction", "sweep", DIRECTIONS, required=False,
                          default=d.direction)
    spacing = ck.choice(sw, "spacing", "sweep", SPACINGS, required=False,
                        default=d.spacing)
    hb = ck.table(data, "hbm", "", required=False) or {}
    ck.keys(hb, "hbm", ALLOWED_KEYS["hbm"])
    harmonics = ck.integer(hb, "harmonics", "hbm", minimum=1, maximum=MAX_HARMONICS,
                           default=HBMSettings.harmonics)
    n_samples = None
    if harmonics is not None:
        n_samples = ck.integer(hb, "n_samples", "hbm", minimum=2 * harmonics + 1)
    hbm_extra = {k: ck.number(hb, k, "hbm", rule=">0", required=False)
                 for k in ("tol", "ds_initial", "ds_min", "ds_max", "max_angle")}
    if hbm_extra["tol"] is not None and not hbm_extra["tol"] < 0.5:
        ck.add(f"`hbm.tol` must be a number > 0 and < 0.5 (relative to the peak), "
               f"got {hbm_extra['tol']}")
    hbm_extra["max_harmonics"] = ck.integer(hb, "max_harmonics", "hbm", minimum=1,
                                            maximum=MAX_HARMONICS)
    cs = ck.table(data, "cosim", "", required=False) or {}
    ck.keys(cs, "cosim", ALLOWED_KEYS["cosim"])
    backend = ck.choice(cs, "backend", "cosim", BACKENDS, required=False,
                        default=CosimSettings.backend)
    freq = ck.number(cs, "freq_hz", "cosim", rule=">0", unit="Hz", required=False)
    duration = ck.number(cs, "duration", "cosim", rule=">0", unit="s", required=False)
    spp = ck.integer(cs, "steps_per_period", "cosim", minimum=8)
    if None in (fmin, fmax, points, direction, spacing, harmonics, backend):
        return None
    return (SweepSettings(fmin, fmax, points, direction, spacing),
            HBMSettings(harmonics, n_samples, **hbm_extra),
            CosimSettings(backend, freq, duration, spp))


def _check_support(ck: _Checker, system: System) -> None:
    """The mounts (with stuck friction) must hold every DOF: K positive definite."""
    K, _ = system.linearized(stuck=True)
    if not np.all(np.isfinite(K)):
        ck.add("the linearised stiffness is not finite: stiffness values are too large")
        return
    Mi = np.diag(1.0 / np.sqrt(np.diag(system.M)))
    ev = np.linalg.eigvalsh(Mi @ K @ Mi)
    if ev[0] <= SINGULAR_RTOL * max(abs(ev[-1]), 1e-300):
        mode = np.linalg.eigh(Mi @ K @ Mi)[1][:, 0]
        dof = system.dof_names[int(np.argmax(abs(mode)))]
        ck.add(f"the mounts do not hold the system: the linearised stiffness (k1 of "
               f"each axis, plus kf where friction sticks) is singular, a motion "
               f"mostly "
               f"along `{dof}` meets no spring; check the stiffnesses and, for "
               f"rigid_engine, that the mount positions are not collinear")


def _build(ck: _Checker, data: dict, model: str):
    from vehicle import models  # late import: vehicle imports hbm, both are heavy

    if model == "sdof":
        t = ck.table(data, "sdof", "", what="(mass) ")
        mass = None
        if t is not None:
            ck.keys(t, "sdof", ALLOWED_KEYS["sdof"], hints={
                "m": "the key is `mass`", "m_e": "the key is `mass`"})
            mass = ck.number(t, "mass", "sdof", rule=">0", unit="kg")
        mount = _single_mount(ck, data)
        exc = _excitation(ck, data, model, {})
        if ck.problems:
            return None
        return lambda: models.sdof(mass, mount, excitation=exc[0], amplitude=exc[1])
    if model == "quarter_car":
        t = ck.table(data, "quarter_car", "",
                     what="(m_e, m_s, m_us, k_s, c_s, k_t, c_t) ")
        vals = {}
        if t is not None:
            ck.keys(t, "quarter_car", ALLOWED_KEYS["quarter_car"], hints={
                "mass": "the masses are `m_e`, `m_s`, `m_us`"})
            for name, rule, unit in (("m_e", ">0", "kg"), ("m_s", ">0", "kg"),
                                     ("m_us", ">0", "kg"), ("k_s", ">=0", "N/m"),
                                     ("c_s", ">=0", "N s/m"), ("k_t", ">0", "N/m"),
                                     ("c_t", ">=0", "N s/m")):
                vals[name] = ck.number(t, name, "quarter_car", rule=rule, unit=unit)
        mount = _single_mount(ck, data)
        exc = _excitation(ck, data, model, {})
        if ck.problems:
            return None
        return lambda: models.quarter_car(mount=mount, road_amplitude=exc[1], **vals)
    # rigid_engine
    t = ck.table(data, "rigid_engine", "", what="(mass, inertia) ")
    mass = inertia = None
    if t is not None:
        ck.keys(t, "rigid_engine", ALLOWED_KEYS["rigid_engine"], hints={
            "Ixx": "give `inertia = [Ixx, Iyy, Izz]`", "m": "the key is `mass`"})
        mass = ck.number(t, "mass", "rigid_engine", rule=">0", unit="kg")
        inertia = ck.vector(t, "inertia", "rigid_engine", 3, unit="kg m^2", rule=">0")
    mounts = []
    if "mounts" not in data:
        ck.add("`mounts` is missing: model \"rigid_engine\" needs at least 3 "
               "[[mounts]] tables")
    elif not isinstance(data["mounts"], list):
        ck.add(f"`mounts` must be an array of tables ([[mounts]] ...), got "
               f"{_type_name(data['mounts'])} {_show(data['mounts'])}")
    else:
        if len(data["mounts"]) < 3:
            ck.add(f"`mounts` must hold at least 3 mounts (a rigid engine on fewer is "
                   f"not held in 6 DOF), got {len(data['mounts'])}")
        for i, m in enumerate(data["mounts"]):
            mounts.append(_rigid_mount(ck, m, i))
        names = [m[0] for m in mounts if m is not None]
        for n in sorted({n for n in names if names.count(n) > 1}):
            ck.add(f"`mounts[].name` must be unique, got {n!r} {names.count(n)} times")
    exc = _excitation(ck, data, model, {"base": 3, "unbalance": 6, "force": 6})
    if ck.problems:
        return None
    orients = [m[2] if m[2] is not None else models.DEFAULT_ORIENTATION for m in mounts]
    return lambda: models.rigid_engine(
        mass, inertia, [m[1] for m in mounts], [m[3] for m in mounts],
        names=[m[0] for m in mounts], orientations=orients, excitation=exc[0],
        amplitude=exc[1])


def config_from_dict(data, source: str = "<dict>", name: str | None = None) -> Config:
    """Check a parsed TOML document and build its :class:`Config`.

    Parameters
    ----------
    data : dict
        The document, as :func:`tomllib.loads` returns it.
    source : str
        Shown in error messages and kept in ``Config.source``.
    name : str, optional
        Name used when the document has no ``name`` key.

    Raises
    ------
    ConfigError
        Listing every problem found (never another exception for bad input).
    """
    ck = _Checker()
    if not isinstance(data, dict):
        raise ConfigError(
            [f"the document must be a TOML table, got {_type_name(data)}"], source)
    model = ck.choice(data, "model", "", MODELS)
    hints = {}
    if model is not None:
        for key, owner in _MODEL_TABLES.items():
            owners = owner if isinstance(owner, tuple) else (owner,)
            if model not in owners:
                use = {"sdof": "[sdof]", "quarter_car": "[quarter_car]",
                       "rigid_engine": "[rigid_engine]"}[model]
                alt = "[[mounts]]" if model == "rigid_engine" else "[mount]"
                hints[key] = (f"[{key}] belongs to model "
                              f"{' or '.join(repr(o) for o in owners)}; model "
                              f"{model!r} uses {use} and {alt}")
        allowed = [k for k in ALLOWED_KEYS[""] if k not in hints]
    else:
        allowed = ALLOWED_KEYS[""]
    ck.keys(data, "", allowed, hints=hints)
    cfg_name = ck.string(data, "name", "", default=name or "config")
    description = ck.string(data, "description", "", default="")
    build = _build(ck, data, model) if model is not None else None
    settings = _settings(ck, data)
    if ck.problems or build is None or settings is None:
        raise ConfigError(ck.problems or ["invalid configuration"], source)
    try:
        with np.errstate(all="raise"), warnings.catch_warnings():
            warnings.simplefilter("error")
            system = build()
            _check_support(ck, system)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError, RuntimeWarning) as exc:
        ck.add(f"the model cannot be built from these values: {exc}")
    if ck.problems:
        raise ConfigError(ck.problems, source)
    # labels of CSV provenance lines and plot titles: the configuration's name
    system = replace(system, name=cfg_name,
                     description=description or system.description,
                     notes={"config_name": cfg_name, "model": model, "source": source})
    sweep, hbm_settings, cosim = settings
    return Config(cfg_name, description, model, system, sweep, hbm_settings, cosim,
                  source, data)


def load_config(path_or_text, name: str | None = None) -> Config:
    """Load a configuration from a TOML file or from TOML text.

    Parameters
    ----------
    path_or_text : str or Path
        A :class:`~pathlib.Path`, or a string: TOML text if it contains a newline or
        ``=``, else a file name.
    name : str, optional
        Name used when the document has no ``name`` key (default: the file stem).

    Returns
    -------
    Config

    Raises
    ------
    ConfigError
        For a missing or unreadable file, a TOML syntax error, or any invalid field;
        lists every problem found.

    Examples
    --------
    >>> cfg = load_config('''
    ... model = "sdof"
    ... [sdof]
    ... mass = 70.0
    ... [mount]
    ... law = "linear"
    ... k1 = 91870.0
    ... c = 150.0
    ... [excitation]
    ... kind = "force"
    ... amplitude = 40.0
    ... ''')
    >>> cfg.system.dof_names
    ('x',)
    """
    if isinstance(path_or_text, Path) or (
            isinstance(path_or_text, str) and "\n" not in path_or_text
            and "=" not in path_or_text):
        path = Path(path_or_text)
        source = str(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise ConfigError([f"no such file: {source}"], source) from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError([f"cannot read the file: {exc}"], source) from None
        name = name or path.stem
    elif isinstance(path_or_text, str):
        text, source = path_or_text, "<text>"
    else:
        raise ConfigError([f"expected a file path or TOML text, got "
                           f"{_type_name(path_or_text)}"], "<input>")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError([f"TOML syntax error: {exc}"], source) from None
    return config_from_dict(data, source=source, name=name)


# ======================================================================================
# Presets
# ======================================================================================


def list_presets() -> list[str]:
    """Names of the presets shipped in ``drymount/presets`` (sorted)."""
    root = resources.files("drymount.presets")
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def preset_text(name: str) -> str:
    """The TOML text of preset ``name`` (with its comments)."""
    names = list_presets()
    if name not in names:
        close = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
        hint = f" (did you mean `{close[0]}`?)" if close else ""
        raise ConfigError(
            [f"unknown preset `{name}`{hint}; presets: {', '.join(names)}"],
            f"preset:{name}")
    return resources.files("drymount.presets").joinpath(f"{name}.toml").read_text(
        encoding="utf-8")


def load_preset(name: str) -> Config:
    """The :class:`Config` of preset ``name`` (see :func:`list_presets`)."""
    text = preset_text(name)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:  # a broken package file
        raise ConfigError([f"TOML syntax error: {exc}"], f"preset:{name}") from None
    return config_from_dict(data, source=f"preset:{name}", name=name)


def resolve_config(spec) -> Config:
    """A configuration from a file path or a preset name (the CLI's CONFIG argument).

    An existing file wins; else a preset of that name; else a :class:`ConfigError`
    that suggests the closest preset.
    """
    spec = str(spec)
    path = Path(spec)
    if path.is_file():
        return load_config(path)
    if spec in list_presets():
        return load_preset(spec)
    names = list_presets()
    close = difflib.get_close_matches(spec, names, n=1, cutoff=0.5)
    hint = f"; did you mean preset `{close[0]}`?" if close else ""
    raise ConfigError([f"`{spec}` is neither a file nor a preset{hint} (presets: "
                       f"{', '.join(names)})"], spec)
