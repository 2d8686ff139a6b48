"""Semi-active normal-force control of the mounts' friction contacts (issue 14 item 4).

A controller sets the normal force ``n`` of one mount axis's friction contact at every
communication step from the time, the axis's deflection ``u`` and rate ``v`` (the
values the master sends to the mount at that step), the master's row of the step
and the step ``h``: ``command(t, u, v, row, h)``. Both backends call it once per
step before the mount force is evaluated: in-process as the slip force
``mu * max(n, 0)``, through an FMU as its input ``n_<axis>``. The command is then
limited to ``[n_min, n_max]`` and to a rate ``|dn/dt| <= rate_max`` (:class:`Limits`).

Sign convention: ``u`` is engine minus chassis, the mount force on the chassis is
``F = F_el(u) + c v + F_fr`` with ``F_el`` of the sign of ``u`` and a slipping
friction force ``F_fr = mu n sign(v)``.

The laws:

* :class:`BalanceControl` (balance logic): ``n_on`` while the friction force
  opposes the elastic force (``u v < 0``), else ``n_off``.
* :class:`SkyhookControl`: ``n_on`` while the friction force on the engine opposes
  the engine's absolute velocity ``va`` (``v va > 0``), else ``n_off``.
* :class:`ScheduledControl` (gain scheduling): ``n = interp(x(t), x_table, n_table)``
  with ``x(t)`` a known signal, e.g. the excitation frequency of an engine run-up and
  the table the passive optimum n0 per frequency from the HBM.
* :class:`GrowthControl`: ``n_on`` while the deflection grows (``u v > 0``), the
  reverse of the balance logic: it adds to the transmitted force (kept as the
  reference of a wrong law; it was called ``onoff``).

The two-state laws locate their switch inside the step (:class:`SwitchingControl`):
the co-simulation stays second order in the step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Limits", "ScheduledControl", "SwitchingControl", "BalanceControl",
           "GrowthControl", "SkyhookControl", "engine_velocity", "macro_slip_contact",
           "ENGINE_DOFS",
           "ControlLog"]


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and not math.isnan(x)


@dataclass(frozen=True)
class Limits:
    """Actuator limits: ``n_min <= n <= n_max`` (N), ``|dn/dt| <= rate_max`` (N/s)."""

    n_min: float = 0.0
    n_max: float = math.inf
    rate_max: float = math.inf

    def __post_init__(self):
        problems = []
        if not (_num(self.n_min) and math.isfinite(self.n_min) and self.n_min >= 0):
            problems.append(f"`n_min` must be finite and >= 0 N, got {self.n_min!r}")
        if not (_num(self.n_max) and self.n_max >= (self.n_min if _num(self.n_min)
                                                     else 0.0)):
            problems.append(f"`n_max` must be a number >= n_min = {self.n_min!r} N, "
                            f"got {self.n_max!r}")
        if not (_num(self.rate_max) and self.rate_max > 0):
            problems.append(f"`rate_max` must be > 0 N/s (inf: no limit), got "
                            f"{self.rate_max!r}")
        if problems:
            raise ValueError("invalid control limits: " + "; ".join(problems))

    def apply(self, n: float, n_prev: float, h: float) -> float:
        """``n`` clipped to the range and to a change of ``rate_max h`` from
        ``n_prev``."""
        step = self.rate_max * h
        if n > n_prev + step:
            n = n_prev + step
        elif n < n_prev - step:
            n = n_prev - step
        return min(max(n, self.n_min), self.n_max)


@dataclass(frozen=True)
class ScheduledControl:
    """Gain scheduling: ``n = interp(signal(t), x, n)`` (constant beyond the table).

    Attributes
    ----------
    x : tuple of float
        Strictly increasing scheduling variable (e.g. excitation frequency, Hz).
    n : tuple of float
        Normal force at each ``x``, N (>= 0).
    signal : callable
        ``signal(t) -> x`` at time ``t`` (s), e.g. a run-up's instantaneous
        frequency.
    limits : Limits
    """

    x: tuple[float, ...]
    n: tuple[float, ...]
    signal: Callable[[float], float]
    limits: Limits = field(default_factory=Limits)

    def __post_init__(self):
        x, n = tuple(self.x), tuple(self.n)
        if len(x) < 1 or len(x) != len(n):
            raise ValueError(f"`x` and `n` must have the same length >= 1, got "
                             f"{len(x)} and {len(n)}")
        if not all(_num(v) and math.isfinite(v) for v in x) or any(
                b <= a for a, b in zip(x, x[1:])):
            raise ValueError(f"`x` must be finite and strictly increasing, got {x}")
        if not all(_num(v) and math.isfinite(v) and v >= 0 for v in n):
            raise ValueError(f"`n` must be finite and >= 0 N, got {n}")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "n", n)

    def command(self, t: float, u: float, v: float, row=None, h: float = 0.0
                ) -> float:
        return float(np.interp(self.signal(t), self.x, self.n))


class SwitchingControl:
    """A two-state law: ``n_on`` while the law's predicate on two signals holds,
    else ``n_off`` (N), the switch located inside the step.

    Subclasses give :meth:`signals` (two values and their rates at the step) and
    :meth:`predicate` (on/off from the two values). The master's force sample at
    ``t_k`` stands for the cell ``[t_k - h/2, t_k + h/2]`` (leapfrog): a switch
    inside that cell applied at the whole cell would move an impulse ``jump * O(h)``
    and make the scheme first order. The command is therefore the cell average
    ``n = n_off + theta (n_on - n_off)`` with ``theta`` the fraction of the cell in
    which the predicate holds, the signals linear in the cell (value and rate at
    ``t_k``; a rate not known from the state is the difference quotient of the
    last two steps). The friction force of a slipping contact is ``mu n``, so the
    cell's impulse is right to O(h^2). That holds for an off-switch (the force
    steps down to ``mu n_off``; the released contact forgets its slider). An
    on-switch keeps the force continuous but sets where the contact sticks: with
    ``contact = (kf, mu)`` of a macro-slip axis, the first step after it commands
    the normal force whose return map puts the slider where it stuck at the switch
    (:meth:`_anchor`); otherwise the stick point lags by ``v h`` (first order).
    Both together: second order, as the passive mount (docs/physics.md). A rate
    limit starts its ramp at the step, not at the switch.

    The controller keeps the last step's signals (it is stateful: one instance per
    controlled axis and per run).
    """

    kind = ""

    def __init__(self, n_on: float, n_off: float = 0.0, limits: Limits | None = None,
                 contact: tuple[float, float] | None = None):
        for name, value in (("n_on", n_on), ("n_off", n_off)):
            if not (_num(value) and math.isfinite(value) and value >= 0):
                raise ValueError(f"`{name}` must be finite and >= 0 N, got {value!r}")
        self.n_on, self.n_off = float(n_on), float(n_off)
        self.limits = Limits() if limits is None else limits
        #: (kf, mu) of a macro-slip contact: locates the stick point of an on-switch
        self.contact = None if contact is None else (float(contact[0]),
                                                     float(contact[1]))
        self._last = None  # (t, a, b, u, v, on) of the previous step

    def __repr__(self):
        return (f"{type(self).__name__}(n_on={self.n_on!r}, n_off={self.n_off!r}, "
                f"limits={self.limits!r})")

    def signals(self, u: float, v: float, row, h: float
                ) -> tuple[float, float, float | None, float | None]:
        """``(a, b, da/dt, db/dt)`` at the step; a rate None: from the history."""
        raise NotImplementedError

    def predicate(self, a: float, b: float) -> bool:
        raise NotImplementedError

    def command(self, t: float, u: float, v: float, row=None, h: float = 0.0
                ) -> float:
        a, b, ra, rb = self.signals(u, v, row, h)
        last, on_now = self._last, self.predicate(a, b)
        self._last = (t, a, b, u, v, on_now)
        ok = last is not None and h > 0 and abs(t - last[0] - h) <= 1e-9 * h
        if ra is None or rb is None:
            ra = ra if ra is not None else ((a - last[1]) / h if ok else 0.0)
            rb = rb if rb is not None else ((b - last[2]) / h if ok else 0.0)
        if ok and on_now and not last[5] and self.contact is not None:
            return self._anchor(a, b, ra, rb, u, v, last[4], h)
        theta = self.on_fraction(a, b, ra, rb, h)
        return self.n_off + theta * (self.n_on - self.n_off)

    def _anchor(self, a, b, ra, rb, u, v, v_prev, h) -> float:
        """Normal force at the first step after an on-switch at ``t_s`` in
        ``(t_k - h, t_k]``: the one whose return map leaves the slider where the
        contact stuck at ``t_s`` (a slipping force ``mu n_off sign(v_prev)`` plus
        ``kf (u_k - u(t_s))``); ``n_on`` if that exceeds it."""
        kf, mu = self.contact
        s = -h
        for x, r in ((a, ra), (b, rb)):
            if r != 0.0 and -h <= -x / r <= 0.0:
                s = max(s, -x / r)
        force = math.copysign(mu * self.n_off, v_prev) + kf * (-v * s)
        return min(self.n_on, abs(force) / mu)

    def on_fraction(self, a, b, ra, rb, h) -> float:
        """Fraction of ``[-h/2, h/2]`` in which the predicate of ``a + ra s``,
        ``b + rb s`` holds if the contact switches off in that cell; else the
        predicate at ``s = 0`` (``h = 0``: the predicate at the point)."""
        now = 1.0 if self.predicate(a, b) else 0.0
        if h <= 0.0:
            return now
        half = 0.5 * h
        cuts = [-half, half]
        for x, r in ((a, ra), (b, rb)):
            if r != 0.0 and abs(x) < half * abs(r):
                cuts.append(-x / r)
        cuts.sort()
        on, states = 0.0, []
        for s0, s1 in zip(cuts, cuts[1:]):
            if s1 > s0:
                states.append(self.predicate(a + ra * (0.5 * (s0 + s1)),
                                             b + rb * (0.5 * (s0 + s1))))
                on += (s1 - s0) * states[-1]
        off_switch = any(x and not y for x, y in zip(states, states[1:]))
        return on / h if off_switch else now


class BalanceControl(SwitchingControl):
    """Balance logic: ``n_on`` while the friction force opposes the elastic force.

    The mount force on the chassis is ``F = F_el(u) + c v + F_fr`` with ``F_el``
    of the sign of ``u`` and a slipping ``F_fr = Fs sign(v)``: they oppose while
    ``u v < 0`` (the deflection returns towards rest). The contact then brakes the
    spring's return, and is off while the deflection grows so that it does not add
    to the spring force (the balance logic of semi-active dampers, Rakheja and
    Sankar 1985). Switches on at ``v = 0`` (where a released contact carries no
    force: continuous) and off at ``u = 0`` (a force step ``mu (n_on - n_off)``).
    """

    kind = "balance"

    def signals(self, u, v, row, h):
        return u, v, v, None

    def predicate(self, a, b):
        return a * b < 0.0


class GrowthControl(SwitchingControl):
    """``n_on`` while the deflection grows in magnitude (``u v > 0``), else ``n_off``.

    The former ``onoff`` law. The contact is on exactly while a slipping friction
    force has the sign of the elastic force, so it adds to the transmitted force
    by construction (the reverse of :class:`BalanceControl`): kept as a reference
    of what not to do.
    """

    kind = "growth"

    def signals(self, u, v, row, h):
        return u, v, v, None

    def predicate(self, a, b):
        return a * b > 0.0


class SkyhookControl(SwitchingControl):
    """Skyhook on the engine's absolute velocity: ``n_on`` while ``v va > 0``.

    ``va`` is the engine's absolute velocity at the mount along the axis (the engine
    DOFs' part of ``B q'``). The engine feels ``-F_fr``, of sign ``-sign(v)`` while
    slipping: that opposes the engine's absolute motion (an ideal skyhook damper's
    force ``-c_sky va``) exactly while ``v va > 0``. With the chassis fixed
    ``va = v`` and the law is the passive mount at ``n_on``.

    Parameters
    ----------
    velocity : callable
        ``velocity(row, h) -> va`` (m/s) from the master's row of the step and
        the step h (:func:`engine_velocity`).
    """

    kind = "skyhook"

    def __init__(self, n_on, n_off=0.0, limits=None, contact=None, *,
                 velocity: Callable):
        super().__init__(n_on, n_off, limits, contact)
        self.velocity = velocity

    def signals(self, u, v, row, h):
        return v, self.velocity(row, h), None, None

    def predicate(self, a, b):
        return a * b > 0.0


#: DOF names of the engine (the rest of a system is chassis, suspension, wheels).
ENGINE_DOFS = ("x", "engine", "y", "z", "alpha", "beta", "gamma")


def engine_velocity(system, mount: str, axis: str) -> Callable:
    """``velocity(row, h)``: the engine's absolute velocity at ``mount`` along
    ``axis`` (m/s) from a row of the master's buffer (:class:`vehicle.backends.
    Layout`): ``b . (vh_k + (h/2) a_{k-1})``, the predicted ``q'_k`` of the
    master, with ``b`` the row of ``B`` restricted to the engine DOFs
    (:data:`ENGINE_DOFS`).
    """
    from drymount.fmu_src.mount_law import AXES

    e = next((el for el in system.elements if el.name == mount), None)
    if e is None:
        raise ValueError(f"skyhook: no mount {mount!r} in {system.name!r}")
    b = np.array(e.B[AXES.index(axis)], dtype=float)
    b[[name not in ENGINE_DOFS for name in system.dof_names]] = 0.0
    if not np.any(b):
        raise ValueError(f"skyhook: mount {mount!r} axis {axis!r} does not move "
                         f"with an engine DOF ({', '.join(ENGINE_DOFS)})")
    # the row starts with u, v of every active axis (Layout.o_x = 2 m)
    n, o = system.n_dof, 2 * sum(len(el.active_axes) for el in system.elements)

    def velocity(row, h: float) -> float:
        acc = b @ row[o + 2 * n:o + 3 * n]
        return float(b @ row[o + n:o + 2 * n] + 0.5 * h * acc)

    return velocity


def macro_slip_contact(system, mount: str, axis: str) -> tuple[float, float] | None:
    """``(kf, mu)`` of ``mount``'s ``axis`` if it is a macro-slip (Jenkins) contact,
    else None (micro-slip, non-symmetric: :class:`SwitchingControl` then does not
    locate the stick point of an on-switch)."""
    from drymount.fmu_src.mount_law import AXES

    e = next((el for el in system.elements if el.name == mount), None)
    p = None if e is None else e.params.axes[AXES.index(axis)]
    if p is None or not p.friction or p.general_friction:
        return None
    return p.kf, p.mu


class ControlLog:
    """The normal forces the controllers applied, per controlled axis and step."""

    def __init__(self, labels: tuple[str, ...]):
        self.labels = labels
        self.t: list[float] = []
        self.n: list[list[float]] = []

    def add(self, t: float, n: list[float]) -> None:
        self.t.append(t)
        self.n.append(list(n))

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``(t, n)``: times (s) and normal forces (steps x axes, N)."""
        return np.asarray(self.t), np.asarray(self.n).reshape(len(self.t),
                                                             len(self.labels))
