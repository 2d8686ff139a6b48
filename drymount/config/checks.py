"""Checking a parsed TOML document field by field: every problem is collected with
the field path, the value found and what is allowed."""

from __future__ import annotations

import difflib
import math

#: Masses accepted, kg: from a 1 g test body to a 1000 t machine. Outside, the
#: mass matrix spans more than the double precision the stability and support
#: checks rely on (1e-300 kg or 1e30 kg read as "the mounts do not hold the system").
MASS_RANGE_KG = (1e-3, 1e6)
#: Principal moments of inertia accepted, kg m^2 (same reasoning).
INERTIA_RANGE_KGM2 = (1e-6, 1e6)


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
    "mass": (lambda x: MASS_RANGE_KG[0] <= x <= MASS_RANGE_KG[1],
             f"in {MASS_RANGE_KG[0]:g}..{MASS_RANGE_KG[1]:g}"),
    "inertia": (lambda x: INERTIA_RANGE_KGM2[0] <= x <= INERTIA_RANGE_KGM2[1],
                f"in {INERTIA_RANGE_KGM2[0]:g}..{INERTIA_RANGE_KGM2[1]:g}"),
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
