"""Bifurcations of a forced branch: each change of stability classified and located.

Hill's method (:mod:`hbm.stability`) gives the Floquet exponents ``lambda`` of a
periodic solution; the Floquet multipliers are ``mu = exp(lambda T)``. Stability changes
where a multiplier leaves the unit circle, and *where* it leaves says what kind of
bifurcation it is:

- through +1 (a real exponent through 0): a **fold** where the branch turns (every
  located fold of :mod:`hbm.folds` is one), a **branch point** where it does not (a
  symmetry-breaking pitchfork: another periodic branch crosses this one);
- through -1 (an exponent through 0 with imaginary part omega / 2): a **period
  doubling**: the periodic solution of period T gives way to one of period 2 T;
- as a complex pair elsewhere on the circle (imaginary part strictly between 0 and
  omega / 2): a **Neimark-Sacker** bifurcation: a quasi-periodic motion (a torus) is
  born, with a second frequency ``Im(lambda) / 2 pi`` beside the excitation.

Past a period doubling or a Neimark-Sacker bifurcation the steady state is not periodic
with the excitation's period; harmonic balance cannot represent it, a time simulation
(``drymount cosim``) shows it.

The exponents are those of the stability verdict
(:func:`hbm.stability.floquet_exponents`, which keeps both copies of an exponent at the
strip's edge ``|Im lambda| = omega / 2``, as a period doubling has them); the critical
one is that of largest real part. Each change is located on the arc between the two
curve points around it by bisection of that real part against the threshold of
:data:`hbm.stability.RTOL` (Newton re-solves on the arc, as folds are located), to
``hbm.folds.FREQ_TOL_HZ``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from drymount.hbm.continuation import Branch, ContinuationSettings
from drymount.hbm.folds import ARC_TOL, _locate
from drymount.hbm.problem import _to_hz
from drymount.hbm.hill_arnoldi import central_eigenvalues
from drymount.hbm.stability import RTOL, _selected, floquet_exponents

__all__ = ["BifurcationKind", "Bifurcation", "classify", "critical_exponent",
           "locate_bifurcations", "IMAG_TOL"]

#: An exponent is real (multiplier +1 side) when its imaginary part, folded into
#: [0, omega / 2], is below IMAG_TOL * omega, and on the -1 side when it is within
#: IMAG_TOL * omega of omega / 2; otherwise it is one of a complex pair.
IMAG_TOL = 1e-3


class BifurcationKind(enum.Enum):
    """Where the critical Floquet multiplier crosses the unit circle."""

    FOLD = "fold"  # +1, at a turning point of the branch
    BRANCH_POINT = "branch-point"  # +1, the branch goes on (symmetry breaking)
    PERIOD_DOUBLING = "period-doubling"  # -1
    NEIMARK_SACKER = "neimark-sacker"  # a complex pair

    @property
    def leaves_periodic(self) -> bool:
        """Whether the steady state beyond it is not T-periodic."""
        return self in (BifurcationKind.PERIOD_DOUBLING, BifurcationKind.NEIMARK_SACKER)


@dataclass(frozen=True)
class Bifurcation:
    """A classified change of stability along a branch.

    Attributes
    ----------
    kind : BifurcationKind
    index : int
        Between branch points ``index - 1`` and ``index``.
    y : ndarray
        The located solution (scaled unknowns; the unstable side's point when the
        location failed).
    exponent : complex
        The critical Floquet exponent at the unstable side's point, 1/s.
    omega : float
        The excitation's angular frequency there, rad/s.
    converged : bool
        Whether the location reached ``hbm.folds.FREQ_TOL_HZ``.
    """

    kind: BifurcationKind
    index: int
    y: np.ndarray
    exponent: complex
    omega: float
    converged: bool

    @property
    def multiplier(self) -> complex:
        """The critical Floquet multiplier ``exp(lambda T)``, ``T = 2 pi / omega``."""
        return complex(np.exp(self.exponent * 2 * np.pi / self.omega))


def critical_exponent(hb, J: np.ndarray, omega: float) -> complex:
    """The Floquet exponent of largest real part (1/s), of those
    :func:`hbm.stability.floquet_exponents` selects (the verdict's)."""
    lam = central_eigenvalues(hb, J, omega)  # cheaper where Hill's matrix is large
    lam = (floquet_exponents(hb, J, omega) if lam is None
           else _selected(lam, hb.n, omega))
    return complex(lam[int(np.argmax(lam.real))])


def classify(exponent: complex, omega: float, at_fold: bool) -> BifurcationKind:
    """The kind of a stability change whose critical exponent (unstable side) is
    ``exponent``; ``at_fold``: the branch turns there."""
    theta = abs(exponent.imag) % omega
    theta = min(theta, omega - theta)
    if theta < IMAG_TOL * omega:
        return BifurcationKind.FOLD if at_fold else BifurcationKind.BRANCH_POINT
    if 0.5 * omega - theta < IMAG_TOL * omega:
        return BifurcationKind.PERIOD_DOUBLING
    return BifurcationKind.NEIMARK_SACKER


def _jacobian(prob, y):
    X, w = prob.x_of(y)
    return prob.hb.residual(X, w)[1], w


def _unstable_side(br: Branch, i: int, stable) -> np.ndarray:
    return br.y[i] if not stable[i] else br.y[i - 1]


def locate_bifurcations(prob, br: Branch, stable: np.ndarray, turning,
                        settings: ContinuationSettings) -> list[Bifurcation]:
    """Every change of ``stable`` between consecutive points of ``br`` that is not a
    turning point's fold, classified and located (folds are located by
    :func:`hbm.folds.locate_folds`; a +1 crossing at a turning point is left to it)."""
    stable = np.asarray(stable, dtype=bool)
    near_fold = {int(t) + d for t in turning for d in (-1, 0, 1)}
    out = []
    for i in np.nonzero(stable[1:] != stable[:-1])[0] + 1:
        i = int(i)
        y_u = _unstable_side(br, i, stable)
        J, w = _jacobian(prob, y_u)
        exponent = critical_exponent(prob.hb, J, w)
        kind = classify(exponent, w, i in near_fold)
        if kind is BifurcationKind.FOLD:
            continue
        y, ok = _locate(prob, br, i, _margin(prob), _to_hz(prob), settings, ARC_TOL)
        if y is None:
            y, ok = y_u, False
        out.append(Bifurcation(kind, i, y, exponent, w, ok))
    return out


def _margin(prob):
    """``g(y, t)``: the critical exponent's real part minus the stability threshold
    (the sign of the verdict, continuous along the branch)."""
    def g(y, t):
        J, w = _jacobian(prob, y)
        return critical_exponent(prob.hb, J, w).real - RTOL * w
    return g
