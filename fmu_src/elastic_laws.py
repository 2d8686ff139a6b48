"""The elastic laws of a mount axis (thesis eq. 2.15-2.20): the law registry.

Each elastic law is defined once here (:class:`ElasticLaw`: the fields it reads, its
scalar force and tangent, its knees, its stiffest tangent) and looked up by name
everywhere else (:data:`ELASTIC_LAWS`; ``AxisParameters.law``). The FMU's integer
parameter ``<axis>_law`` is the position of the law in the registry
(:func:`law_code` / :func:`law_name` are the one place that maps the two); append new
laws at the end. Standard library only: this module ships inside the FMU.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

__all__ = ["AxisFields", "ElasticLaw", "ELASTIC_LAWS", "LAWS", "register_law",
           "law_code", "law_name"]


class AxisFields(Protocol):
    """The fields of an axis the elastic laws read
    (:class:`fmu_src.mount_law.AxisParameters` has them): stiffnesses in N/m (``kc``
    in N/m^3), knee deflections in m."""

    k1: float
    kc: float
    k2: float
    delta: float
    delta_neg: float


@dataclass(frozen=True)
class ElasticLaw:
    """One elastic law of a mount axis (thesis eq. 2.15-2.20).

    Attributes
    ----------
    name : str
        The value of ``AxisParameters.law``.
    summary : str
        One line for documentation and error messages.
    uses : tuple of str
        ``AxisParameters`` fields the law reads besides ``k1`` and ``c`` (a
        configuration must give them).
    force : callable
        ``force(u, p) -> (F_el, dF_el/du)`` for a deflection ``u`` (m) and the axis
        parameters ``p``.
    knees : callable
        ``knees(p) -> tuple of deflections (m)`` where the law has a kink (events
        of an event-exact integrator); empty for smooth laws.
    nonlinear : callable
        ``nonlinear(p) -> bool``: whether ``F_el - k1 u`` is not identically zero.
    stiffest : callable
        ``stiffest(p) -> float``: the largest tangent stiffness of the piecewise-
        linear part, N/m (``k1`` for smooth laws; a step-size bound, not a bound of
        the cubic's growing tangent).
    """

    name: str
    summary: str
    uses: tuple[str, ...]
    force: Callable[[float, AxisFields], tuple[float, float]]
    knees: Callable[[AxisFields], tuple[float, ...]]
    nonlinear: Callable[[AxisFields], bool]
    stiffest: Callable[[AxisFields], float]


#: The registered elastic laws by name, in FMU code order.
ELASTIC_LAWS: dict[str, ElasticLaw] = {}
#: Names of the elastic laws, in FMU code order.
LAWS: tuple[str, ...] = ()


def register_law(law: ElasticLaw) -> ElasticLaw:
    """Add ``law`` to :data:`ELASTIC_LAWS` (its FMU code is the next integer)."""
    global LAWS
    if law.name in ELASTIC_LAWS:
        raise ValueError(f"elastic law {law.name!r} is registered already")
    ELASTIC_LAWS[law.name] = law
    LAWS = tuple(ELASTIC_LAWS)
    return law


def law_code(name: str) -> int:
    """The FMU's integer ``<axis>_law`` of the law ``name``."""
    return LAWS.index(name)


def law_name(code) -> str | None:
    """The law of the FMU's integer ``<axis>_law`` = ``code``; None if invalid."""
    if isinstance(code, int) and not isinstance(code, bool) and 0 <= code < len(LAWS):
        return LAWS[code]
    return None


def _linear(u: float, p: AxisFields) -> tuple[float, float]:
    k1 = p.k1
    return k1 * u, k1


def _cubic(u: float, p: AxisFields) -> tuple[float, float]:
    k1, kc = p.k1, p.kc
    return k1 * u + kc * u * u * u, k1 + 3.0 * kc * u * u


def _piecewise(u: float, p: AxisFields) -> tuple[float, float]:
    """A linear spring plus a spring (k2 - k1) behind gaps at +-delta (eq. 3.30)."""
    return _knee_spring(u, p, p.delta)


def _piecewise_asym(u: float, p: AxisFields) -> tuple[float, float]:
    """As :func:`_piecewise` with the negative gap at -delta_neg."""
    return _knee_spring(u, p, p.delta_neg)


def _knee_spring(u: float, p: AxisFields, dneg: float) -> tuple[float, float]:
    k1 = p.k1
    if u > p.delta:
        k2 = p.k2
        return k1 * u + (k2 - k1) * (u - p.delta), k2
    if u < -dneg:
        k2 = p.k2
        return k1 * u + (k2 - k1) * (u + dneg), k2
    return k1 * u, k1


def _no_knees(p: AxisFields) -> tuple[float, ...]:
    return ()


def _k1(p: AxisFields) -> float:
    return p.k1


def _stiffer(p: AxisFields) -> float:
    return max(p.k1, p.k2)


def _gap(p: AxisFields) -> bool:
    return p.k2 != p.k1


register_law(ElasticLaw(
    "linear", "k1 u", (), _linear, _no_knees, lambda p: False, _k1))
register_law(ElasticLaw(
    "cubic", "k1 u + kc u^3 (eq. 2.15)", ("kc",), _cubic, _no_knees,
    lambda p: p.kc != 0.0, _k1))
register_law(ElasticLaw(
    "piecewise", "k1 u, k2 beyond |u| > delta (symmetric, eq. 3.30)",
    ("k2", "delta"), _piecewise, lambda p: (p.delta, -p.delta), _gap, _stiffer))
register_law(ElasticLaw(
    "piecewise_asym", "as piecewise, knee at +delta for u > 0, -delta_neg for u < 0",
    ("k2", "delta", "delta_neg"), _piecewise_asym,
    lambda p: (p.delta, -p.delta_neg), _gap, _stiffer))
