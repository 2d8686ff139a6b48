"""Semi-active normal-force control of the mounts' friction contacts (issue 14 item 4).

A controller sets the normal force ``n`` of one mount axis's friction contact at every
communication step from the time and the axis's deflection ``u`` and rate ``v`` (the
values the master sends to the mount at that step). Both backends call it once per
step before the mount force is evaluated: in-process as the slip force
``mu * max(n, 0)``, through an FMU as its input ``n_<axis>``. The command is then
limited to ``[n_min, n_max]`` and to a rate ``|dn/dt| <= rate_max`` (:class:`Limits`).

Two laws:

* :class:`ScheduledControl` (gain scheduling): ``n = interp(x(t), x_table, n_table)``
  with ``x(t)`` a known signal, e.g. the excitation frequency of an engine run-up and
  the table the passive optimum n0 per frequency from the HBM.
* :class:`OnOffControl` (a friction "skyhook"): ``n = n_on`` while the deflection grows
  in magnitude (``u v > 0``: the contact then removes energy from the motion away from
  the rest position) and ``n = n_off`` while it returns, so the mount is soft on the
  way back and does not stick.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Limits", "ScheduledControl", "OnOffControl", "ControlLog"]


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

    def command(self, t: float, u: float, v: float) -> float:
        return float(np.interp(self.signal(t), self.x, self.n))


@dataclass(frozen=True)
class OnOffControl:
    """Friction skyhook: ``n_on`` while ``u v > 0`` (deflection growing), else
    ``n_off`` (N)."""

    n_on: float
    n_off: float = 0.0
    limits: Limits = field(default_factory=Limits)

    def __post_init__(self):
        for name in ("n_on", "n_off"):
            value = getattr(self, name)
            if not (_num(value) and math.isfinite(value) and value >= 0):
                raise ValueError(f"`{name}` must be finite and >= 0 N, got {value!r}")

    def command(self, t: float, u: float, v: float) -> float:
        return self.n_on if u * v > 0.0 else self.n_off


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
