"""Options of the harmonic-balance solver: the one source of their defaults.

The continuation's settings (:class:`hbm.continuation.ContinuationSettings`) have no
defaults of their own and are built from these; the app's configuration
(``drymount.config``) takes its ``[hbm]`` defaults from here too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported where used: the configuration's checks need no solver
    from drymount.hbm.continuation import ContinuationSettings

__all__ = ["HBMOptions", "MAX_HARMONICS", "MAX_N_SAMPLES", "ADAPTIVE_MAX_HARMONICS",
           "MULTI_DOF_MAX_HARMONICS", "OptionsError", "CountError", "check_harmonics",
           "check_samples"]

#: Largest number of harmonics accepted anywhere (a sanity bound: H = 7 already
#: converges the friction systems to 1e-3; 50 harmonics cost ~50x more per Newton
#: step). :func:`check_harmonics` is the one check against it.
MAX_HARMONICS = 50
#: Largest number of AFT samples per period accepted (64..1024 are used; 8192
#: resolves the sharpest kink of the friction law at H = 50 many times over).
MAX_N_SAMPLES = 8192
#: Default cap on H of the ``tol`` adaptation (systems of up to MULTI_DOF DOF).
ADAPTIVE_MAX_HARMONICS = 25
#: Default cap on H for systems of more than MULTI_DOF DOF (the 6-DOF presets).
MULTI_DOF_MAX_HARMONICS = 13
MULTI_DOF = 3


class OptionsError(ValueError):
    """An invalid option of the harmonic balance (the message names the field, its
    value and what is allowed); raised before any work."""


class CountError(OptionsError):
    """A harmonic or sample count out of its range. ``str()`` names the field in
    backticks; :meth:`named` names it as the caller does (``--harmonics``)."""

    def __init__(self, field: str, value, allowed: str):
        self.field, self.value, self.allowed = field, value, allowed
        super().__init__(self.named(f"`{field}`"))

    @property
    def requirement(self) -> str:
        """The message without the field (argparse names the option itself)."""
        return f"must be {self.allowed}, got {self.value!r}"

    def named(self, name: str) -> str:
        return f"{name} {self.requirement}"


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def check_harmonics(value, field: str = "harmonics") -> int:
    """``value`` if it is a harmonic count H in 1..MAX_HARMONICS, else
    :class:`CountError` naming ``field``. The one check of H: the configuration, the
    API, the CLI's parser and :class:`HBMOptions` call it; the layers below trust
    them."""
    if not _is_int(value) or not 1 <= value <= MAX_HARMONICS:
        raise CountError(field, value, f"an integer in 1..{MAX_HARMONICS}")
    return value


def check_samples(value, harmonics: int, field: str = "n_samples") -> int:
    """``value`` if it is an AFT sample count N in 2H + 1..MAX_N_SAMPLES for
    ``harmonics`` = H, else :class:`CountError` naming ``field``."""
    low = 2 * harmonics + 1
    if not _is_int(value) or not low <= value <= MAX_N_SAMPLES:
        raise CountError(field, value, f"an integer in {low}..{MAX_N_SAMPLES} "
                                       f"(>= 2H + 1 = {low} for H = {harmonics})")
    return value


@dataclass(frozen=True)
class HBMOptions:
    """Options of :func:`hbm.frequency_response` and :func:`hbm.solve_frequencies`.

    Step sizes are in scaled units: the unknowns are divided by the largest linear
    (free-slider) response of each DOF over the range, the angular frequency by
    ``2 pi (fmax - fmin)`` (NLvib's ``Dscale``), so a full sweep spans about 1.

    Attributes
    ----------
    harmonics : int
        Number of harmonics H (default 7).
    n_samples : int or None
        AFT samples per period; None: ``max(64, 8H)`` rounded up to a power of 2
        (the ``tol`` adaptation's first curve of a system of more than 3 DOF:
        ``max(64, 16H)``, :func:`hbm.resolution.first_samples`).
    ds_initial, ds_min, ds_max : float
        Initial, smallest and largest arc-length step (scaled units). ``ds_max`` =
        0.1 is what every shipped result used (``hbm.continuation`` once had its own,
        unused default of 0.15).
    n_norm : int
        Desired Newton iterations per step (thesis eq. 3.66).
    max_newton : int
        Newton iterations before a step is rejected and halved.
    tol_residual : float
        Convergence: residual norm / excitation norm.
    tol_step : float
        Convergence: size of the last Newton step (scaled units).
    max_steps : int
        Continuation steps before giving up (``success=False``).
    max_growth : float
        Largest step growth factor per step.
    max_angle : float
        Largest angle (rad) between successive unit tangents (scaled units) before
        the next step is shrunk: resolves resonance peaks and folds.
    stability : bool
        Compute the Hill stability of the points.
    stability_stride : int
        Solve Hill's eigenvalue problem at every ``stability_stride``-th point, at
        the ends, on both sides of every sign change of ``det(dR/dX)``, and between
        two such points where the verdicts differ (bisection) or where the points
        are close to the stability boundary for their distance
        (:mod:`hbm.stability_schedule`); elsewhere the verdict is carried over
        (1: every point). The eigenvalues nearest the origin come from shift-invert
        Arnoldi on the LU of ``dR/dX`` (:mod:`hbm.hill_arnoldi`, dense when unsure).
        ``floquet_max_real`` is NaN at the points not evaluated.
    n_peak : int
        Phases per period used for the peak ``max |q(t)|``.
    refine_samples : int
        How often :func:`hbm.frequency_response` may double the AFT sample count and
        trace the curve again when the continuation stalls or dead-ends at a kink of
        the sampled nonsmooth residual (0: never). The result's ``n_samples`` and
        ``message`` say when it did.
    max_restarts : int
        When the curve still stops before ``fmax`` (a stall at a knee, a branch that
        turns back), :func:`hbm.frequency_response` starts a new segment
        ``restart_factor`` above the highest frequency reached, at most this many
        times (0: never). Segments are clipped to the band and joined with a gap row;
        see ``FrequencyResponse.restarts``.
    restart_factor : float
        Where a restarted segment starts, relative to the highest frequency reached
        (> 1).
    tol : float or None
        Wanted accuracy of the curve relative to its peak (default 1e-3): half of it
        for the harmonic-balance error (:mod:`hbm.error_estimate`; H and N are raised
        until the estimate is below ``tol / 2``, up to ``max_harmonics`` and
        ``max_samples``, unless the caller fixed them) and half for reading the curve
        between consecutive points (the step is shrunk until the straight chord stays
        within ``tol / 2`` of the curve in every DOF's amplitude). None: neither
        (fixed H and N, steps by ``max_angle`` only).
    error_estimate : bool
        Estimate the truncation and sampling errors of the points (always on when
        ``tol`` is set).
    max_harmonics : int or None
        Largest H the ``tol`` adaptation may use. None (default): 25 for systems
        of up to 3 DOF, ``MULTI_DOF_MAX_HARMONICS`` (13) for more (a 6-DOF curve at
        H = 19, N = 1024 takes minutes where one at H = 13 takes seconds); the result
        says when the tolerance was not reached at the cap, and what was.
    max_samples : int
        Largest N the ``tol`` adaptation may use.
    zigzag_refine : int
        Factor on N for re-tracing a cluster of closely spaced turning points (then
        its square); the cluster keeps only the turning points that persist
        (1: keep every turning point).
    zigzag_span : float
        Largest frequency extent between two turning points of a cluster, relative
        to ``fmax - fmin``.
    """

    harmonics: int = 7
    n_samples: int | None = None
    ds_initial: float = 0.02
    ds_min: float = 1e-6
    ds_max: float = 0.1
    n_norm: int = 4
    max_newton: int = 12
    tol_residual: float = 1e-10
    tol_step: float = 1e-6
    max_steps: int = 20000
    max_growth: float = 2.0
    max_angle: float = 0.15
    stability: bool = True
    stability_stride: int = 64
    n_peak: int = 256
    refine_samples: int = 2
    max_restarts: int = 0
    restart_factor: float = 1.02
    tol: float | None = 1e-3
    error_estimate: bool = True
    max_harmonics: int | None = None
    max_samples: int = 2048
    zigzag_refine: int = 4
    zigzag_span: float = 0.05

    def __post_init__(self):
        problems = []
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in ("harmonics", "max_harmonics", "n_samples"):
                problems += self._count_problem(f.name, v)
                continue
            if f.name in ("stability", "error_estimate"):
                if not isinstance(v, bool):
                    problems.append(f"`{f.name}` must be true or false, got {v!r}")
                continue
            if f.name == "tol" and v is None:
                continue
            if f.name in ("refine_samples", "max_restarts"):
                if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                    problems.append(f"`{f.name}` must be an integer >= 0, got {v!r}")
                continue
            if f.name in ("n_norm", "max_newton", "max_steps", "n_peak",
                          "stability_stride", "max_samples", "zigzag_refine"):
                if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                    problems.append(f"`{f.name}` must be an integer >= 1, got {v!r}")
            elif not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                problems.append(f"`{f.name}` must be finite and > 0, got {v!r}")
        if not problems and self.ds_min > self.ds_max:
            problems.append(f"`ds_min` must be <= `ds_max` = {self.ds_max}, "
                            f"got {self.ds_min}")
        if not problems and self.max_growth < 1:
            problems.append(f"`max_growth` must be >= 1, got {self.max_growth}")
        if not problems and self.tol is not None and not self.tol < 0.5:
            problems.append(f"`tol` must be < 0.5 (relative to peak), got {self.tol}")
        if not problems and self.restart_factor <= 1:
            problems.append(f"`restart_factor` must be > 1, got {self.restart_factor}")
        if problems:
            raise OptionsError("invalid HBMOptions: " + "; ".join(problems))

    def _count_problem(self, name: str, value) -> list[str]:
        if value is None and name != "harmonics":
            return []
        try:
            if name == "n_samples":
                if _is_int(self.harmonics):  # else harmonics' own problem says it
                    check_samples(value, self.harmonics, name)
            else:
                check_harmonics(value, name)
        except CountError as exc:
            return [str(exc)]
        return []

    def harmonics_cap(self, n_dof: int) -> int:
        """The cap on H of the ``tol`` adaptation for a system of ``n_dof`` DOF."""
        if self.max_harmonics is not None:
            return self.max_harmonics
        return ADAPTIVE_MAX_HARMONICS if n_dof <= MULTI_DOF else MULTI_DOF_MAX_HARMONICS

    def continuation_settings(self) -> ContinuationSettings:
        from drymount.hbm.continuation import ContinuationSettings

        return ContinuationSettings(
            ds_initial=min(max(self.ds_initial, self.ds_min), self.ds_max),
            ds_min=self.ds_min, ds_max=self.ds_max, n_norm=self.n_norm,
            max_newton=self.max_newton, tol_residual=self.tol_residual,
            tol_step=self.tol_step, max_steps=self.max_steps,
            max_growth=self.max_growth, max_angle=self.max_angle)
