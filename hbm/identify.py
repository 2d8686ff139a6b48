"""Mount-law parameters from rig data (thesis Sec. 2.3-2.4, Figs. 2.5-2.6).

Two identifications, both nonlinear least squares (``scipy.optimize.least_squares``)
with the model evaluated by the mount law of ``fmu_src.mount_law`` (one source of
truth):

1. **Elastic law** from a quasi-static force-deflection curve: linear, cubic,
   symmetric and asymmetric piecewise (:func:`fit_elastic`, :func:`compare_elastic`).
   The piecewise laws are linear in (k1, k2) once the knees are fixed, so the knees are
   first located by a grid search over the measured deflections (each candidate an
   exact linear least-squares solve) and then refined with the stiffnesses.
2. **Friction and damping** (kf, Fs, optionally c) with the elastic law given:
   from force-displacement loops of harmonic tests (:func:`fit_loops`; the model is the
   law's exact periodic march, :func:`hbm.elements.jenkins_periodic`), or from a
   dynamic-stiffness / loss-angle table (:func:`fit_dynamic_stiffness`; the model is
   the harmonic balance of :mod:`hbm.characterise`).

Every fit reports its parameters with standard errors from the Jacobian at the optimum
(``cov = s^2 (J^T J)^-1``, ``s^2 = RSS / (n - p)``), R^2 and Akaike's information
criterion ``AIC = n ln(RSS / n) + 2 p`` (Gaussian residuals); the law with the lowest
AIC is preferred. Bad data raise :class:`DataError` naming the row, the value and what
is allowed. A fit that does not converge returns what it reached with the reason in
``message`` and a non-converged ``status``.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares

from drymount.fmu_src.mount_law import AxisParameters, elastic_force
from drymount.hbm.characterise import DEFAULT_SAMPLES, rate_independent_stiffness
from drymount.hbm.elements import jenkins_periodic

__all__ = ["FIT_LAWS", "PARAMETERS", "UNITS", "MIN_POINTS", "DataError",
           "FitStatus", "Fit", "ElasticComparison", "LoopTest", "StiffnessPoint",
           "check_curve", "law_force", "fit_elastic", "compare_elastic",
           "loop_model", "fit_loops", "fit_dynamic_stiffness", "point_problems"]

#: The elastic laws a force-deflection curve is fitted with.
FIT_LAWS = ("linear", "cubic", "piecewise", "piecewise_asym")
#: Fitted parameters of each elastic law, in order.
PARAMETERS = {"linear": ("k1",), "cubic": ("k1", "kc"),
              "piecewise": ("k1", "k2", "delta"),
              "piecewise_asym": ("k1", "k2", "delta", "delta_neg")}
UNITS = {"k1": "N/m", "kc": "N/m^3", "k2": "N/m", "delta": "m", "delta_neg": "m",
         "kf": "N/m", "fs": "N", "c": "N s/m"}
#: Fewest data points per fitted parameter (fewer gives no honest standard errors).
MIN_POINTS_PER_PARAMETER = 3
#: Fewest points of a force-deflection curve (the asymmetric law has 4 parameters).
MIN_POINTS = 4 * MIN_POINTS_PER_PARAMETER
#: Fewest measured deflections beyond a knee candidate in the grid search.
MIN_BEYOND_KNEE = 2


class DataError(ValueError):
    """Unusable measured data. ``problems`` lists every problem found."""

    def __init__(self, problems: list[str]):
        self.problems = list(problems)
        super().__init__("; ".join(self.problems))


class FitStatus(enum.Enum):
    CONVERGED = "converged"
    NOT_CONVERGED = "not converged"


@dataclass(frozen=True)
class Fit:
    """Result of one least-squares fit.

    Attributes
    ----------
    model : str
        The elastic law fitted, or ``"friction"``.
    params, stderr : dict of str to float
        Estimates and their standard errors (units in ``UNITS``).
    rss : float
        Residual sum of squares (in the residual's unit squared).
    r2 : float
        Coefficient of determination of the fitted quantity.
    aic : float
        ``n ln(RSS/n) + 2 p``.
    n : int
        Number of residuals.
    status : FitStatus
    message : str
        The optimizer's reason for stopping.
    """

    model: str
    params: dict
    stderr: dict
    rss: float
    r2: float
    aic: float
    n: int
    status: FitStatus
    message: str

    @property
    def n_params(self) -> int:
        return len(self.params)

    def relative_stderr(self, name: str) -> float:
        return self.stderr[name] / abs(self.params[name])


@dataclass(frozen=True)
class ElasticComparison:
    """Every elastic law fitted to one curve, and the one AIC prefers."""

    fits: tuple[Fit, ...]
    best: Fit


# --------------------------------------------------------------------------------------
# Data checks
# --------------------------------------------------------------------------------------


def _finite_problems(arr: np.ndarray, name: str, unit: str) -> list[str]:
    bad = np.flatnonzero(~np.isfinite(arr))
    if not bad.size:
        return []
    rows = ", ".join(f"row {i + 1} = {float(arr[i])!r}" for i in bad[:5])
    more = f" and {bad.size - 5} more" if bad.size > 5 else ""
    return [f"`{name}` ({unit}) must be finite: {rows}{more}"]


def check_curve(u, F) -> tuple[np.ndarray, np.ndarray]:
    """Checked deflections (m) and forces (N) of a force-deflection curve.

    Requires at least ``MIN_POINTS`` points, finite values and strictly monotonic
    deflections (a quasi-static loading curve; a hysteresis loop is for
    :func:`fit_loops`). Returned sorted by increasing deflection.
    """
    u = np.asarray(u, dtype=float).ravel()
    F = np.asarray(F, dtype=float).ravel()
    problems = []
    if u.size != F.size:
        problems.append(f"`deflection` and `force` must have the same length, got "
                        f"{u.size} and {F.size}")
    elif u.size < MIN_POINTS:
        problems.append(f"a force-deflection curve needs at least {MIN_POINTS} points "
                        f"({MIN_POINTS_PER_PARAMETER} per parameter of the richest "
                        f"law), got {u.size}")
    problems += _finite_problems(u, "deflection", "m")
    problems += _finite_problems(F, "force", "N")
    if not problems:
        du = np.diff(u)
        sign = 1.0 if u[-1] > u[0] else -1.0
        bad = np.flatnonzero(sign * du <= 0)
        if bad.size:
            i = bad[0]
            problems.append(
                f"`deflection` must be strictly monotonic (one quasi-static loading "
                f"curve; use the loop fit for cyclic data): row {i + 2} = "
                f"{float(u[i + 1])!r} m follows row {i + 1} = {float(u[i])!r} m")
    if problems:
        raise DataError(problems)
    order = np.argsort(u)
    return u[order], F[order]


# --------------------------------------------------------------------------------------
# Elastic law
# --------------------------------------------------------------------------------------


def _axis(law: str, params: dict) -> AxisParameters:
    k1 = params["k1"]
    delta = params.get("delta", AxisParameters.delta)
    return AxisParameters(law=law, k1=k1, kc=params.get("kc", 0.0),
                          k2=params.get("k2", k1), delta=delta,
                          delta_neg=params.get("delta_neg", delta), c=0.0)


def _elastic(u: np.ndarray, axis: AxisParameters) -> np.ndarray:
    """:func:`fmu_src.mount_law.elastic_force` sample by sample, N."""
    return np.array([elastic_force(x, axis)[0] for x in u.tolist()])


def law_force(u, law: str, params: dict) -> np.ndarray:
    """Elastic force (N) of ``law`` with ``params`` at the deflections ``u`` (m)."""
    return _elastic(np.asarray(u, dtype=float), _axis(law, params))


def _gap(u: np.ndarray, d_pos: float, d_neg: float) -> np.ndarray:
    """Deflection beyond the knees (the gap spring's stretch), m."""
    return np.maximum(u - d_pos, 0.0) + np.minimum(u + d_neg, 0.0)


def _knee_candidates(u: np.ndarray, side: float, max_n: int = 80) -> np.ndarray:
    """Knee positions between measured |u| on one side, leaving points beyond."""
    a = np.sort(np.abs(u[side * u > 0]))
    if a.size < MIN_BEYOND_KNEE + 2:
        return np.array([])
    mids = 0.5 * (a[1:-MIN_BEYOND_KNEE] + a[2:a.size - MIN_BEYOND_KNEE + 1])
    if mids.size > max_n:
        mids = mids[np.linspace(0, mids.size - 1, max_n).astype(int)]
    return mids


def _linear_ls(columns: list[np.ndarray], F: np.ndarray) -> tuple[np.ndarray, float]:
    A = np.column_stack(columns)
    coef, *_ = np.linalg.lstsq(A, F, rcond=None)
    r = A @ coef - F
    return coef, float(r @ r)


def _initial_guess(u: np.ndarray, F: np.ndarray, law: str) -> np.ndarray:
    """Start values: exact linear least squares, knees by grid search."""
    if law == "linear":
        return _linear_ls([u], F)[0]
    if law == "cubic":
        return np.maximum(_linear_ls([u, u**3], F)[0], 0.0)
    pos = _knee_candidates(u, 1.0)
    neg = _knee_candidates(u, -1.0)
    if law == "piecewise":
        cands = np.union1d(pos, neg)
        pairs = [(d, d) for d in cands]
    else:
        pairs = [(dp, dn) for dp in pos for dn in neg]
    if not pairs:
        raise DataError([f"law {law!r} needs at least {MIN_BEYOND_KNEE + 2} points on "
                         f"each side of zero deflection to place a knee"])
    best = None
    for dp, dn in pairs:
        (k1, dk), rss = _linear_ls([u, _gap(u, dp, dn)], F)
        if best is None or rss < best[0]:
            best = (rss, k1, dk, dp, dn)
    _, k1, dk, dp, dn = best
    x = [k1, k1 + dk, dp] + ([dn] if law == "piecewise_asym" else [])
    return np.array(x)


def _elastic_jacobian(x: np.ndarray, u: np.ndarray, law: str) -> np.ndarray:
    """d(force)/d(parameters); the force itself comes from the law (``law_force``)."""
    if law == "linear":
        return u[:, None].copy()
    if law == "cubic":
        return np.column_stack([u, u**3])
    k1, k2, dp = x[:3]
    dn = x[3] if law == "piecewise_asym" else dp
    g = _gap(u, dp, dn)
    hi, lo = (u > dp).astype(float), (u < -dn).astype(float)
    cols = [u - g, g]
    if law == "piecewise":
        cols.append(-(k2 - k1) * (hi - lo))
    else:
        cols += [-(k2 - k1) * hi, (k2 - k1) * lo]
    return np.column_stack(cols)


def _summarise(model: str, names, res, y: np.ndarray, scale: np.ndarray | None = None
               ) -> Fit:
    """A :class:`Fit` from a ``least_squares`` result (``y``: the fitted data)."""
    n, p = res.fun.size, len(names)
    rss = float(res.fun @ res.fun)
    # d(residual)/d(parameter) = d(residual)/d(scaled parameter) / scale
    J = res.jac if scale is None else res.jac / scale
    dof = max(n - p, 1)
    try:
        cov = np.linalg.inv(J.T @ J) * rss / dof
        se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        se = np.full(p, math.inf)
    x = res.x if scale is None else res.x * scale
    yc = y - y.mean()
    tss = float(yc @ yc)
    return Fit(model=model,
               params={k: float(v) for k, v in zip(names, x, strict=True)},
               stderr={k: float(v) for k, v in zip(names, se, strict=True)},
               rss=rss, r2=1.0 - rss / tss if tss > 0 else math.nan,
               aic=n * math.log(max(rss, 1e-300) / n) + 2 * p, n=n,
               status=FitStatus.CONVERGED if res.success else FitStatus.NOT_CONVERGED,
               message=str(res.message))


def fit_elastic(u, F, law: str) -> Fit:
    """Least-squares fit of one elastic law to a force-deflection curve.

    Parameters
    ----------
    u, F : array_like
        Deflections (m, strictly monotonic) and forces (N).
    law : str
        One of ``ELASTIC_LAWS``.
    """
    if law not in PARAMETERS:
        raise ValueError(f"`law` must be one of {', '.join(FIT_LAWS)}, got {law!r}")
    u, F = check_curve(u, F)
    names = PARAMETERS[law]
    x0 = _initial_guess(u, F, law)
    umax = float(np.max(np.abs(u)))
    lo = np.zeros(len(names))
    hi = np.full(len(names), np.inf)
    if law.startswith("piecewise"):
        lo[2:] = umax * 1e-6
        hi[2:] = umax
    x0 = np.clip(x0, lo + 1e-12 * np.abs(x0), np.where(np.isfinite(hi), hi, x0 + 1))
    # parameters differ by orders of magnitude (N/m, N/m^3, m): scale by the start
    scale = np.where(np.abs(x0) > 0, np.abs(x0), 1.0)

    def resid(z):
        return law_force(u, law, dict(zip(names, z * scale, strict=True))) - F

    def jac(z):
        return _elastic_jacobian(z * scale, u, law) * scale

    res = least_squares(resid, x0 / scale, jac=jac, bounds=(lo / scale, hi / scale),
                        method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    return _summarise(law, names, res, F, scale)


def compare_elastic(u, F, laws=FIT_LAWS) -> ElasticComparison:
    """Fit every law of ``laws``; the best is the lowest AIC among converged fits."""
    fits = tuple(fit_elastic(u, F, law) for law in laws)
    ok = [f for f in fits if f.status is FitStatus.CONVERGED] or list(fits)
    return ElasticComparison(fits, min(ok, key=lambda f: f.aic))


# --------------------------------------------------------------------------------------
# Friction and damping from loops
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LoopTest:
    """One harmonic test: an integer number of periods of steady-state response.

    Attributes
    ----------
    label : str
    time : ndarray, shape (N,)
        Equidistant sample times, s.
    deflection, force : ndarray, shape (N,)
        Measured deflection (m) and force (N).
    freq_hz : float
        Test frequency (estimated from the deflection if not given), Hz.
    velocity : ndarray, shape (N,)
        Deflection rate from the deflection's first ``harmonics`` harmonics, m/s.
    """

    label: str
    time: np.ndarray
    deflection: np.ndarray
    force: np.ndarray
    freq_hz: float = 0.0
    velocity: np.ndarray = field(default=None, repr=False)
    harmonics: int = 5

    def __post_init__(self):
        t = np.asarray(self.time, float)
        u = np.asarray(self.deflection, float)
        F = np.asarray(self.force, float)
        where = f"test {self.label!r}: "
        problems = []
        if not (t.size == u.size == F.size):
            problems.append(f"{where}time, deflection and force must have the same "
                            f"length, got {t.size}, {u.size}, {F.size}")
        elif t.size < 16:
            problems.append(f"{where}a loop needs at least 16 samples, got {t.size}")
        for arr, name, unit in ((t, "time", "s"), (u, "deflection", "m"),
                                (F, "force", "N")):
            problems += [where + p for p in _finite_problems(arr, name, unit)]
        if not problems:
            dt = np.diff(t)
            if np.any(dt <= 0) or np.ptp(dt) > 1e-6 * dt.mean():
                problems.append(f"{where}`time` must increase in equal steps "
                                f"(steps from {float(dt.min())!r} to "
                                f"{float(dt.max())!r} s)")
        if problems:
            raise DataError(problems)
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "deflection", u)
        object.__setattr__(self, "force", F)
        n = t.size
        spec = np.fft.rfft(u - u.mean())
        cycles = int(np.argmax(np.abs(spec[1:]))) + 1
        duration = n * (t[1] - t[0])
        if self.freq_hz:
            if abs(self.freq_hz * duration - round(self.freq_hz * duration)) > 1e-3:
                raise DataError([f"{where}the record ({duration:g} s) must hold an "
                                 f"integer number of periods of {self.freq_hz:g} Hz"])
            cycles = int(round(self.freq_hz * duration))
        object.__setattr__(self, "freq_hz", cycles / duration if not self.freq_hz
                           else float(self.freq_hz))
        # periodic spectral derivative of the deflection, first `harmonics` harmonics
        k = np.arange(spec.size)
        keep = (k % cycles == 0) & (k <= self.harmonics * cycles) & (k > 0)
        dspec = np.where(keep, 2j * np.pi * k / duration * np.fft.rfft(u), 0.0)
        object.__setattr__(self, "velocity", np.fft.irfft(dspec, n))

    @property
    def amplitude(self) -> float:
        return 0.5 * float(np.ptp(self.deflection))


def loop_model(test: LoopTest, elastic: AxisParameters, kf: float, fs: float,
               c: float) -> np.ndarray:
    """Force (N) of the law for the test's measured motion, periodic steady state.

    ``F_el(u) + c v + F_fr`` with the friction force from the exact periodic march
    (:func:`hbm.elements.jenkins_periodic`) of the measured deflection.
    """
    u = test.deflection
    f = _elastic(u, elastic)
    f += c * test.velocity
    if kf > 0 and fs > 0:
        f += jenkins_periodic(u, kf, fs)[0]
    return f


def _friction_start(tests, elastic: AxisParameters, with_c: bool) -> list[np.ndarray]:
    """Start values from the loop energies: 4 Fs X per cycle (c = 0, kf large)."""
    big = max(tests, key=lambda t: t.amplitude)
    u, F = big.deflection, big.force
    du = np.roll(u, -1) - u
    energy = abs(float(np.sum(0.5 * (F + np.roll(F, -1)) * du)))
    cycles = big.freq_hz * big.time.size * (big.time[1] - big.time[0])
    fs0 = max(energy / cycles / (4.0 * big.amplitude), 1e-9)
    starts = []
    for kf_factor in (0.3, 1.0, 3.0):
        kf0 = kf_factor * max(elastic.k1, fs0 / big.amplitude)
        starts.append(np.array([kf0, 0.5 * fs0] + ([0.0] if with_c else [])))
    return starts


def fit_loops(tests, elastic: AxisParameters, fit_c: bool = True) -> Fit:
    """Fit kf, Fs (and c) to force-displacement loops with the elastic law given.

    Parameters
    ----------
    tests : sequence of LoopTest
        Harmonic tests, each an integer number of steady-state periods.
    elastic : AxisParameters
        The elastic law (``law``, ``k1``, ...) and, if ``fit_c`` is false, ``c``.
    fit_c : bool
        Fit the viscous damping too (else keep ``elastic.c``).

    Returns
    -------
    Fit
        ``model = "friction"``, parameters ``kf`` (N/m), ``fs`` (N) and ``c`` (N s/m).
    """
    tests = list(tests)
    if not tests:
        raise DataError(["no loop test given"])
    names = ("kf", "fs", "c") if fit_c else ("kf", "fs")
    F = np.concatenate([t.force for t in tests])
    if F.size < MIN_POINTS_PER_PARAMETER * len(names):
        raise DataError([f"the loops hold {F.size} samples, need at least "
                         f"{MIN_POINTS_PER_PARAMETER * len(names)}"])

    def model(x):
        c = x[2] if fit_c else elastic.c
        return np.concatenate([loop_model(t, elastic, x[0], x[1], c) for t in tests])

    best = None
    for x0 in _friction_start(tests, elastic, fit_c):
        scale = np.where(x0 > 0, x0, np.array([1.0, 1.0, 100.0])[:x0.size])
        res = least_squares(lambda z: model(z * scale) - F, x0 / scale,
                            bounds=(0.0, np.inf), x_scale="jac", diff_step=1e-6,
                            xtol=1e-10, ftol=1e-12)
        if best is None or res.cost < best[0].cost:
            best = (res, scale)
    res, scale = best
    fit = _summarise("friction", names, res, F, scale)
    if not fit_c:
        fit = replace(fit, params={**fit.params, "c": elastic.c},
                      stderr={**fit.stderr, "c": 0.0})
    return fit


# --------------------------------------------------------------------------------------
# Friction and damping from a dynamic-stiffness table
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class StiffnessPoint:
    """One row of a dynamic-stiffness table (zero preload)."""

    freq_hz: float
    amplitude: float    # m
    magnitude: float    # |K*|, N/m
    loss_angle_deg: float

    @property
    def K(self) -> complex:
        return self.magnitude * complex(math.cos(math.radians(self.loss_angle_deg)),
                                        math.sin(math.radians(self.loss_angle_deg)))


def point_problems(points) -> list[str]:
    """What is wrong with each row of a dynamic-stiffness table (empty: nothing):
    frequency, amplitude and |K*| finite and > 0, the loss angle finite."""
    problems = []
    for i, p in enumerate(points):
        vals = (p.freq_hz, p.amplitude, p.magnitude, p.loss_angle_deg)
        if not all(math.isfinite(v) for v in vals) or min(vals[:3]) <= 0:
            problems.append(f"row {i + 1}: frequency, amplitude and |K*| must be "
                            f"finite and > 0 and the loss angle finite, got {vals}")
    return problems


def fit_dynamic_stiffness(points, elastic: AxisParameters, fit_c: bool = True,
                          n_samples: int = DEFAULT_SAMPLES // 4) -> Fit:
    """Fit kf, Fs (and c) to measured |K*| and loss angles, the elastic law given.

    The model is :func:`hbm.characterise.rate_independent_stiffness` plus
    ``i omega c``; the residuals are ``(K*_model - K*_measured) / |K*_measured|``
    (real and imaginary parts, dimensionless).
    """
    points = list(points)
    names = ("kf", "fs", "c") if fit_c else ("kf", "fs")
    problems = point_problems(points)
    if len(points) < MIN_POINTS_PER_PARAMETER * len(names):
        problems.append(f"a dynamic-stiffness table needs at least "
                        f"{MIN_POINTS_PER_PARAMETER * len(names)} rows, got "
                        f"{len(points)}")
    if problems:
        raise DataError(problems)
    Km = np.array([p.K for p in points])
    w = 2 * np.pi * np.array([p.freq_hz for p in points])
    amps = sorted({p.amplitude for p in points})
    idx = [amps.index(p.amplitude) for p in points]

    def resid(z):
        kf, fs = z[0], z[1]
        c = z[2] if fit_c else elastic.c
        ax = replace(elastic, friction=bool(kf > 0 and fs > 0), kf=max(kf, 0.0), mu=1.0,
                     n0=max(fs, 0.0))
        k_ri = np.array([rate_independent_stiffness(ax, X, 0.0, n_samples)
                         for X in amps])
        r = (k_ri[idx] + 1j * w * c - Km) / np.abs(Km)
        return np.concatenate([r.real, r.imag])

    # start: the slip force from the largest loss at the largest amplitude
    X = max(amps)
    k_im = max(p.K.imag for p in points if p.amplitude == X)
    fs0 = max(np.pi * k_im * X / 4.0, 1e-6)
    x0 = np.array([elastic.k1, fs0] + ([0.0] if fit_c else []))
    scale = np.where(x0 > 0, x0, 100.0)
    res = least_squares(lambda z: resid(z * scale), x0 / scale, bounds=(0.0, np.inf),
                        x_scale="jac", diff_step=1e-6, xtol=1e-10, ftol=1e-12)
    y = np.concatenate([(Km / np.abs(Km)).real, (Km / np.abs(Km)).imag])
    fit = _summarise("friction", names, res, y, scale)
    if not fit_c:
        fit = replace(fit, params={**fit.params, "c": elastic.c},
                      stderr={**fit.stderr, "c": 0.0})
    return fit
