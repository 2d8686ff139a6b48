"""What the harmonic balance needs of each elastic law, looked up by the law's name.

The laws themselves (parameters, checks, scalar force and tangent) are defined once in
:data:`fmu_src.mount_law.ELASTIC_LAWS`. The HBM splits each law into ``k1 u`` (handled
exactly in the frequency domain) and a remainder ``F_el(u) - k1 u``; for every law this
module registers

- ``remainder(u, ax, mask)``: the remainder and its tangent, vectorised over samples
  ``u`` (N, n) of the axes ``mask`` of a :class:`hbm.elements.NonlinearAxes`
  (``tests/test_hbm_elements.py`` proves it equal to the scalar law);
- ``closed_form(a, ax, u0, uc, us, x, d)``: the single-harmonic (H = 1) terms of axis
  ``a`` for ``u = u0 + uc cos + us sin``, ``x = hypot(uc, us)`` (PHYSICS.md section 6,
  checked against quadrature in ``tests/test_hbm_closed_form.py``); it adds the parts of
  the Jacobian rows that are not of the equivalent-stiffness form into ``d`` (3 x 3)
  and returns :class:`ClosedFormTerms`. None: the law has no closed form.

A new law: register it in ``fmu_src/mount_law.py`` and add its entry to ``HBM_LAWS``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from drymount.fmu_src.mount_law import ELASTIC_LAWS

__all__ = ["HBMLaw", "HBM_LAWS", "ClosedFormTerms", "hbm_law"]


class ClosedFormTerms(NamedTuple):
    """H = 1 terms of one axis (see :func:`hbm.closed_form.closed_form_forces`).

    ``f0``: static force beyond ``k0 u0`` (N); ``gs``, ``dgs``: equivalent stiffness of
    the fundamental (N/m) and d/dX; ``k0``, ``dk0``: static tangent at the mean (N/m)
    and d/dX.
    """

    f0: float = 0.0
    gs: float = 0.0
    dgs: float = 0.0
    k0: float = 0.0
    dk0: float = 0.0


@dataclass(frozen=True)
class HBMLaw:
    """The harmonic-balance forms of one law of ``fmu_src.mount_law.ELASTIC_LAWS``."""

    remainder: Callable | None
    closed_form: Callable | None


_NO_TERMS = ClosedFormTerms()


def _linear_closed_form(a, ax, u0, uc, us, x, d) -> ClosedFormTerms:
    return _NO_TERMS


def _cubic_remainder(u, ax, m):
    kc = ax.kc[m]
    return kc * u * u * u, 3.0 * kc * u * u


def _cubic_closed_form(a, ax, u0, uc, us, x, d) -> ClosedFormTerms:
    """Exact H = 1 projection of kc (U0 + Uc cos + Us sin)^3 (eq. 3.17-3.18)."""
    kc = ax.kc_list[a]
    d[0][0] += kc * (3 * u0 * u0 + 1.5 * x * x)
    d[0][1] += kc * 3 * u0 * uc
    d[0][2] += kc * 3 * u0 * us
    # the u0-dependence of g_s enters the harmonic rows directly
    d[1][0] += kc * 6 * u0 * uc
    d[2][0] += kc * 6 * u0 * us
    return ClosedFormTerms(f0=kc * (u0**3 + 1.5 * u0 * x * x),
                           gs=kc * (3 * u0 * u0 + 0.75 * x * x), dgs=kc * 1.5 * x)


def _gap_remainder(u, dk, delta, dneg):
    hi = u > delta
    lo = u < -dneg
    f = dk * (np.where(hi, u - delta, 0.0) + np.where(lo, u + dneg, 0.0))
    return f, dk * (hi | lo)


def _piecewise_remainder(u, ax, m):
    return _gap_remainder(u, (ax.k2 - ax.k1)[m], ax.delta[m], ax.delta[m])


def _piecewise_asym_remainder(u, ax, m):
    return _gap_remainder(u, (ax.k2 - ax.k1)[m], ax.delta[m], ax.delta_neg[m])


def _piecewise_closed_form(a, ax, u0, uc, us, x, d) -> ClosedFormTerms:
    """Corrected thesis eq. 3.32 (symmetric knees, zero-mean form; PHYSICS.md 6)."""
    dl = ax.delta_list[a]
    if not x > dl:
        return _NO_TERMS
    dk = ax.dk_list[a]
    pi = math.pi
    a1 = math.asin(dl / x)
    ca1 = math.cos(a1)
    return ClosedFormTerms(gs=dk * (pi - 2 * a1 - math.sin(2 * a1)) / pi,
                           dgs=4 * dk * ca1 * dl / (pi * x * x),
                           k0=dk * (1.0 - 2 * a1 / pi),
                           dk0=2 * dk * dl / (pi * x * x * ca1))


#: The HBM forms of every law, by the law's name.
HBM_LAWS: dict[str, HBMLaw] = {
    "linear": HBMLaw(None, _linear_closed_form),
    "cubic": HBMLaw(_cubic_remainder, _cubic_closed_form),
    "piecewise": HBMLaw(_piecewise_remainder, _piecewise_closed_form),
    "piecewise_asym": HBMLaw(_piecewise_asym_remainder, None),
}


def hbm_law(name: str) -> HBMLaw:
    """The HBM forms of the law ``name`` (a clear error for a law without them)."""
    try:
        return HBM_LAWS[name]
    except KeyError:
        known = "registered in fmu_src" if name in ELASTIC_LAWS else "unknown"
        raise KeyError(f"elastic law {name!r} ({known}) has no harmonic-balance forms: "
                       f"add it to hbm.laws.HBM_LAWS") from None
