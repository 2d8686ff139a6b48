"""The ``[control]`` table: semi-active normal-force control in co-simulation.

    [control]
    kind = "balance"              # "balance", "skyhook", "scheduled" or "growth"
    axes = ["mount.axial"]   # optional: "<mount>.<axis>"; default every friction axis
    n_min = 0.0                   # N
    n_max = 400.0                 # N (default: no upper limit)
    rate_max = 20000.0            # N/s (default: no rate limit)
    schedule_hz = [20, 60, 200]   # scheduled: excitation frequency, Hz, increasing
    schedule_n = [40, 15, 5]      # scheduled: normal force at each frequency, N
    n_on = 60.0                   # balance/skyhook/growth: normal force while on, N
    n_off = 0.0                   # balance/skyhook/growth: while off, N (default 0)

Laws (:mod:`vehicle.control`): ``balance`` on while the friction force opposes the
elastic force (``u v < 0``); ``skyhook`` on while the friction force opposes the
engine's absolute velocity (``v va > 0``); ``scheduled`` a table of the excitation
frequency; ``growth`` on while the deflection grows (``u v > 0``, the former
``onoff``: it adds to the transmitted force, kept as a reference).

:meth:`ControlSettings.controllers` turns it into the ``vehicle.control`` objects of
every controlled axis (``Master(control=...)``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from drymount.fmu_src.mount_law import AXES
from drymount.config.checks import _Checker, _show, _type_name

__all__ = ["ControlSettings", "CONTROL_KINDS", "parse_control"]

CONTROL_KINDS = ("balance", "skyhook", "scheduled", "growth")
#: the laws with two states, n_on and n_off
SWITCHING_KINDS = ("balance", "skyhook", "growth")


@dataclass(frozen=True)
class ControlSettings:
    """A checked ``[control]`` table (see the module docstring for the keys)."""

    kind: str
    axes: tuple[str, ...] | None = None
    n_min: float = 0.0
    n_max: float = math.inf
    rate_max: float = math.inf
    schedule_hz: tuple[float, ...] = ()
    schedule_n: tuple[float, ...] = ()
    n_on: float = 0.0
    n_off: float = 0.0

    def targets(self, system) -> list[tuple[str, str]]:
        """``(mount name, axis)`` of the controlled axes of ``system`` (friction
        axes whose element reads the normal-force input, ``uses_normal_input``)."""
        friction = [(e.name, AXES[j]) for e in system.elements for j in e.active_axes
                    if e.params.axes[j].friction
                    and e.params.axes[j].element.uses_normal_input]
        if self.axes is None:
            return friction
        out = [tuple(a.split(".", 1)) for a in self.axes]
        bad = [a for a, key in zip(self.axes, out) if key not in friction]
        if bad:
            raise ValueError(
                f"`control.axes` entries {bad} are not friction axes (with a "
                f"normal-force input) of "
                f"{system.name!r}; allowed: "
                f"{', '.join(f'{m}.{a}' for m, a in friction) or 'none'}")
        return out

    def controllers(self, system, frequency: Callable[[float], float] | None = None
                    ) -> dict:
        """``{(mount, axis): controller}`` for ``Master(control=...)``.

        ``frequency(t)``: the excitation frequency (Hz) at time ``t`` that a
        ``scheduled`` table is looked up with (required for that kind).
        """
        from drymount.vehicle import control as vc

        limits = vc.Limits(self.n_min, self.n_max, self.rate_max)
        if self.kind == "scheduled":
            if frequency is None:
                raise ValueError("a scheduled control needs the excitation frequency "
                                 "as a function of time (`frequency`)")
            table = vc.ScheduledControl(self.schedule_hz, self.schedule_n, frequency,
                                        limits)
            return {key: table for key in self.targets(system)}
        # one instance per axis: a switching law keeps its last step
        out = {}
        for key in self.targets(system):
            contact = vc.macro_slip_contact(system, *key)
            if self.kind == "skyhook":
                out[key] = vc.SkyhookControl(self.n_on, self.n_off, limits, contact,
                                             velocity=vc.engine_velocity(system, *key))
            else:
                law = vc.BalanceControl if self.kind == "balance" else vc.GrowthControl
                out[key] = law(self.n_on, self.n_off, limits, contact)
        return out


def _list(ck: _Checker, data: dict, key: str, unit: str, rule: str) -> tuple | None:
    p = f"control.{key}"
    v = data.get(key)
    ok = (isinstance(v, list) and len(v) >= 1
          and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                  and math.isfinite(x) for x in v))
    if ok and rule == ">=0":
        ok = all(x >= 0 for x in v)
    if ok and rule == "increasing":
        ok = all(x > 0 for x in v) and all(b > a for a, b in zip(v, v[1:]))
    if not ok:
        what = ("strictly increasing frequencies > 0" if rule == "increasing"
                else "normal forces >= 0")
        ck.add(f"`{p}` must be a non-empty array of finite {what} ({unit}), got "
               f"{_type_name(v)} {_show(v)}")
        return None
    return tuple(float(x) for x in v)


def parse_control(ck: _Checker, data: dict) -> ControlSettings | None:
    """The ``[control]`` table of a document (None if absent or invalid; problems
    go to ``ck``)."""
    from drymount.config.schema import ALLOWED_KEYS

    c = ck.table(data, "control", "", required=False)
    if not c:
        return None
    ck.keys(c, "control", ALLOWED_KEYS["control"])
    renamed = (" (\"onoff\" is now \"growth\": on while the deflection grows, which "
               "adds to the transmitted force; \"balance\" is the reverse)"
               if c.get("kind") == "onoff" else "")
    kind = ck.choice(c, "kind", "control", CONTROL_KINDS, extra=renamed)
    kw = {}
    for key, rule, unit in (("n_min", ">=0", "N"), ("rate_max", ">0", "N/s")):
        x = ck.number(c, key, "control", rule=rule, unit=unit, required=False)
        if x is not None:
            kw[key] = x
    n_max = ck.number(c, "n_max", "control", rule=">0", unit="N", required=False)
    if n_max is not None:
        if n_max < kw.get("n_min", 0.0):
            ck.add(f"`control.n_max` must be >= control.n_min = {kw['n_min']} N, "
                   f"got {_show(c['n_max'])}")
        kw["n_max"] = n_max
    if "axes" in c:
        axes = c["axes"]
        if not (isinstance(axes, list) and axes and all(
                isinstance(a, str) and a.count(".") == 1
                and a.split(".")[1] in AXES for a in axes)):
            ck.add(f"`control.axes` must be a non-empty array of \"<mount>.<axis>\" "
                   f"(axis one of {', '.join(AXES)}), got {_show(axes)}")
        else:
            kw["axes"] = tuple(axes)
    if kind == "scheduled":
        hz = _list(ck, c, "schedule_hz", "Hz", "increasing")
        n = _list(ck, c, "schedule_n", "N", ">=0")
        if hz is not None and n is not None and len(hz) != len(n):
            ck.add(f"`control.schedule_n` must have one normal force per "
                   f"`control.schedule_hz` entry ({len(hz)}), got {len(n)}")
        kw.update(schedule_hz=hz or (), schedule_n=n or ())
    elif kind in SWITCHING_KINDS:
        kw["n_on"] = ck.number(c, "n_on", "control", rule=">=0", unit="N")
        kw["n_off"] = ck.number(c, "n_off", "control", rule=">=0", unit="N",
                                required=False, default=0.0)
    if kind is None or None in kw.values():
        return None
    return ControlSettings(kind, **kw)
