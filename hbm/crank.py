"""Inertia excitation of an inline four-cylinder engine (thesis Sec. 1.1.3, eq. 1.3).

One cylinder with reciprocating mass ``m_rec``, crank radius ``R`` and connecting rod
``l`` feels the vertical inertia force (eq. 1.3, the rotating masses balanced by the
counterweights)

    F_1(theta) = m_rec R w^2 (cos theta + A2 cos 2theta - A4 cos 4theta + ...),
    A2 = R / l,   A4 = R^3 / (4 l^3),   theta = w t the crank angle.

With cranks at 0, 180, 180, 0 degrees the odd orders cancel and four cylinders give

    F_z(t) = 4 m_rec R w^2 (A2 cos 2wt - A4 cos 4wt)          (vertical force)
    M(t)   = m_rec R^2 w^2 (2 sin 2wt + lambda^2 sin 4wt)      (roll moment),
    lambda = R / l, both acting on the engine block.

``M`` is the reaction on the engine block to the inertia torque
``T = -m_rec R^2 w^2 (2 sin 2theta + lambda^2 sin 4theta)`` of the four reciprocating
masses on the crankshaft. The second order dominates: at excitation frequency
``omega = 2 w`` it is an unbalance-type load ``U omega^2`` with

    U_z    = m_rec R^2 / l     (kg m),     in phase with cos(omega t),
    U_roll = m_rec R^2 / 2     (kg m^2),   in phase with sin(omega t).

The thesis prints no engine values. :data:`DEFAULT_ENGINE` is the documented default
of this project (docs/physics.md, "Crank excitation: one engine"): a 1.6 l inline four
with m_rec = 0.5 kg, R = 40.75 mm (81.5 mm stroke), l = 130 mm.

This module is the one crank model: ``vehicle.inputs.CrankInput`` (time domain) and
the six-DOF study's engine excitation (harmonic balance) both read it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CrankMechanism", "CrankOrder", "DEFAULT_ENGINE", "ORDERS"]

#: Engine orders (multiples of the crank speed) the model keeps.
ORDERS = (2, 4)


@dataclass(frozen=True)
class CrankOrder:
    """One engine order of the four-cylinder inertia load, per (crank speed)^2.

    Attributes
    ----------
    order : int
        Multiple of the crank speed w (excitation frequency ``order * w``).
    force : float
        Amplitude of the vertical force, N per (rad/s)^2 of crank speed; the force is
        ``force * w^2 * cos(order * w t)``.
    moment : float
        Amplitude of the roll moment on the block, N m per (rad/s)^2; the moment is
        ``moment * w^2 * sin(order * w t)``.
    """

    order: int
    force: float
    moment: float


def _check(name: str, value, *, positive: bool) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a number, got {value!r}") from None
    if not math.isfinite(v) or (v <= 0 if positive else v < 0):
        raise ValueError(f"`{name}` must be finite and {'>' if positive else '>='} 0, "
                         f"got {value!r}")
    return v


@dataclass(frozen=True)
class CrankMechanism:
    """The crank mechanism of an inline four-cylinder engine (thesis eq. 1.3).

    Attributes
    ----------
    m_rec : float
        Reciprocating mass per cylinder (piston, pin, rings, small end of the rod), kg
        (>= 0).
    crank_radius : float
        Crank radius R (half the stroke), m (> 0).
    rod_length : float
        Connecting-rod length l, m (> ``crank_radius``).
    """

    m_rec: float = 0.5
    crank_radius: float = 0.04075
    rod_length: float = 0.13

    def __post_init__(self):
        object.__setattr__(self, "m_rec", _check("m_rec", self.m_rec, positive=False))
        object.__setattr__(self, "crank_radius",
                           _check("crank_radius", self.crank_radius, positive=True))
        object.__setattr__(self, "rod_length",
                           _check("rod_length", self.rod_length, positive=True))
        if self.crank_radius >= self.rod_length:
            raise ValueError(f"`crank_radius` must be smaller than `rod_length`, got "
                             f"crank_radius={self.crank_radius!r}, "
                             f"rod_length={self.rod_length!r}")

    @property
    def ratio(self) -> float:
        """lambda = R / l."""
        return self.crank_radius / self.rod_length

    @property
    def a2(self) -> float:
        """Second-order coefficient A2 = R / l of eq. 1.3."""
        return self.crank_radius / self.rod_length

    @property
    def a4(self) -> float:
        """Fourth-order coefficient A4 = R^3 / (4 l^3) of eq. 1.3."""
        return self.crank_radius ** 3 / (4.0 * self.rod_length ** 3)

    def orders(self) -> tuple[CrankOrder, ...]:
        """The second and fourth orders of the four-cylinder force and moment."""
        m, R = self.m_rec, self.crank_radius
        return (CrankOrder(2, 4.0 * m * R * self.a2, 2.0 * m * R ** 2),
                CrankOrder(4, -4.0 * m * R * self.a4, m * R ** 2 * self.ratio ** 2))

    def force(self, theta, crank_speed: float) -> np.ndarray:
        """Vertical inertia force on the block, N, at crank angles ``theta`` (rad)."""
        th = np.asarray(theta, dtype=float)
        return 4.0 * self.m_rec * self.crank_radius * crank_speed ** 2 * (
            self.a2 * np.cos(2.0 * th) - self.a4 * np.cos(4.0 * th))

    def roll_moment(self, theta, crank_speed: float) -> np.ndarray:
        """Roll moment on the block, N m (minus the inertia torque on the
        crankshaft)."""
        th = np.asarray(theta, dtype=float)
        torque = self.m_rec * self.crank_radius ** 2 * crank_speed ** 2 * (
            -2.0 * np.sin(2.0 * th) - self.ratio ** 2 * np.sin(4.0 * th))
        return -torque

    @property
    def unbalance_z(self) -> float:
        """Second-order force as an unbalance at omega = 2 w: m_rec R^2 / l, kg m."""
        return self.m_rec * self.crank_radius ** 2 / self.rod_length

    @property
    def unbalance_roll(self) -> float:
        """Second-order roll moment as an unbalance at omega = 2 w: m_rec R^2 / 2,
        kg m^2."""
        return self.m_rec * self.crank_radius ** 2 / 2.0


#: The engine of the studies and of ``vehicle.inputs.CrankInput`` unless told
#: otherwise (values: docs/physics.md).
DEFAULT_ENGINE = CrankMechanism()
