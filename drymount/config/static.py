"""``[static]``: the constant loads a configuration's system vibrates about.

    [static]
    gravity = true              # the bodies' weight (default false: unloaded)
    g = 9.81                    # m/s^2
    loads = { beta = 40.0 }     # generalised static loads by DOF name, N or N m
    travel = 0.015              # m: warn when a mount axis deflects more (optional)
    reading = "lowered"         # the working point the HBM and cosim start from:
                                # "lowered" (default) or "relaxed" (hbm.static)

Gravity acts downwards on the vertical translation DOFs of the model
(:data:`VERTICAL`). The resulting generalised load becomes ``System.static_load``:
harmonic balance and co-simulation then run about the static working point of
:mod:`hbm.static` (friction sliders relaxed there). Without ``[static]`` (or with
``gravity = false`` and no loads) nothing changes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drymount.config.checks import _Checker, _join, _show, _type_name
from drymount.hbm.static import gravity_load
from drymount.hbm.system import STATIC_READINGS, System

__all__ = ["VERTICAL", "StaticSettings", "vertical_dofs", "static_settings",
           "static_load"]

#: The DOFs that a unit upward translation of every body moves, per model.
VERTICAL = {"sdof": ("x",), "quarter_car": ("engine", "sprung", "unsprung"),
            "rigid_engine": ("z",)}
KEYS = ("gravity", "g", "loads", "travel", "reading")


@dataclass(frozen=True)
class StaticSettings:
    """The ``[static]`` table (defaults: no static load)."""

    gravity: bool = False
    g: float = 9.81
    loads: dict = field(default_factory=dict)
    travel: float | None = None
    #: ``System.static_reading``: "lowered" (the engine lowered onto the assembled
    #: mount) or "relaxed" (every friction element unloaded there)
    reading: str = "lowered"

    @property
    def active(self) -> bool:
        return self.gravity or any(v != 0.0 for v in self.loads.values())


def vertical_dofs(model: str, dof_names) -> np.ndarray:
    """1 on the vertical translation DOFs of ``model``, 0 elsewhere."""
    up = VERTICAL[model]
    return np.array([1.0 if n in up else 0.0 for n in dof_names])


def _loads(ck: _Checker, tbl: dict, dof_names) -> dict:
    if "loads" not in tbl:
        return {}
    v = tbl["loads"]
    if not isinstance(v, dict):
        ck.add(f"`static.loads` must be a table of DOF = value (N or N m), e.g. "
               f"{{ {dof_names[-1]} = 40.0 }}, got {_type_name(v)} {_show(v)}")
        return {}
    out = {}
    for name in v:
        if name not in dof_names:
            ck.add(f"`static.loads.{name}`: no DOF {name!r} in this model; DOFs: "
                   f"{', '.join(dof_names)}")
            continue
        x = ck.number(v, name, "static.loads", rule="any", unit="N or N m")
        if x is not None:
            out[name] = x
    return out


def static_settings(ck: _Checker, data: dict, dof_names) -> StaticSettings | None:
    """Check ``[static]`` (absent: the defaults); None after recording a problem."""
    tbl = ck.table(data, "static", "", required=False) or {}
    ck.keys(tbl, "static", KEYS)
    n_before = len(ck.problems)
    gravity = tbl.get("gravity", False)
    if not isinstance(gravity, bool):
        ck.add(f"`{_join('static', 'gravity')}` must be true or false, got "
               f"{_type_name(gravity)} {_show(gravity)}")
    g = ck.number(tbl, "g", "static", rule=">0", unit="m/s^2", required=False,
                  default=StaticSettings.g)
    travel = ck.number(tbl, "travel", "static", rule=">0", unit="m", required=False)
    loads = _loads(ck, tbl, list(dof_names))
    reading = tbl.get("reading", StaticSettings.reading)
    if reading not in STATIC_READINGS:
        ck.add(f"`{_join('static', 'reading')}` must be one of "
               f"{', '.join(repr(r) for r in STATIC_READINGS)}, got "
               f"{_type_name(reading)} {_show(reading)}")
    if len(ck.problems) > n_before:
        return None
    return StaticSettings(gravity, g, loads, travel, reading)


def static_load(settings: StaticSettings, model: str, system: System
                ) -> np.ndarray | None:
    """The generalised static load of ``settings`` (None when there is none)."""
    if not settings.active:
        return None
    names = list(system.dof_names)
    f = np.zeros(len(names))
    for name, x in settings.loads.items():
        f[names.index(name)] += x
    if settings.gravity:
        f += gravity_load(system, vertical_dofs(model, names), settings.g)
    return f
