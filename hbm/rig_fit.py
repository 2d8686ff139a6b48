"""A mount model fitted to rig data over frequency and amplitude (issue 28, item 4).

Two models, each with a closed-form complex stiffness ``K*(omega, X)`` (imposed
motion ``u = X sin(omega t)``, ``K*`` = fundamental force / X):

- ``rubber``: an elastic law (linear ``k1``, or the shape of a given law with its
  ``k1`` fitted or kept) + a macro-slip (Jenkins) element (``kf``, ``fs``) + a viscous
  damper ``c`` + ``n`` Maxwell branches (``maxwell<i>_k``, ``maxwell<i>_c``), in
  parallel. Under imposed motion the forces add, so
  ``K* = K_el(X) + K_J(X) + i omega c + sum_i K_M(k_i, c_i, omega)`` exactly: the
  Jenkins part is the H = 1 describing function of :func:`hbm.closed_form.
  jenkins_coefficients` (the exact fundamental of its loop), the elastic law's the
  harmonic balance of :func:`hbm.characterise.rate_independent_stiffness` (``k1``
  itself for the linear law), the Maxwell branches those of
  :func:`fmu_src.linear_branches.maxwell_complex_stiffness`.
- ``hydraulic``: the linear inertia-track (+ decoupler) mount of
  :func:`fmu_src.linear_branches.hydraulic_complex_stiffness`; amplitude
  independent. Its ``K*`` depends on the physical parameters only through
  ``K0 = kr + Ap^2/(C1+C2)``, ``Kinf - K0 = Ap^2 C2/(C1 (C1+C2))``, the passages'
  impedances times ``C1 C2/(C1+C2)`` and ``br`` (``K* - kr - i omega br = Ap^2 (1 + s
  C2 Z)/(C1 + C2 + s C1 C2 Z)``): two of them are not identified by any table, so a
  fit holds ``Ap`` and one of ``kr``, ``C1``, ``C2`` fixed (:func:`check_model`).

Data: a dynamic-stiffness table (:class:`hbm.identify.StiffnessPoint` rows; residuals
``(K*_model - K*_measured) / |K*_measured|``, real and imaginary parts) or
force-displacement loops (:class:`hbm.identify.LoopTest`; residuals the force, N,
with the model's force for the measured deflection: the elastic law and the Jenkins
element's exact periodic march (:func:`hbm.elements.jenkins_periodic`) on the samples,
the linear rate-dependent parts (``c``, Maxwell, hydraulic) applied per harmonic to
the deflection's first ``test.harmonics`` harmonics, exact for periodic motion).

The fit (:func:`fit_table`, :func:`fit_loops`) is ``scipy.optimize.least_squares``
over the logarithms of the free parameters (all positive; scale free), from several
starts computed from the data (the loop fit starts from a table fit to the loops'
fundamentals; the Maxwell branches are numbered by rising relaxation frequency).
Standard errors: ``cov(log p) = s^2 (J^T J)^-1`` with J the Jacobian
of the residuals in the log parameters at the optimum and ``s^2 = RSS / (n - p)``,
``se(p) = p se(log p)`` (first order).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares

from drymount.fmu_src.linear_branches import (HYDRAULIC_FIELDS, HydraulicParameters,
                                              hydraulic_complex_stiffness,
                                              maxwell_complex_stiffness)
from drymount.fmu_src.mount_law import AxisParameters
from drymount.hbm.characterise import rate_independent_stiffness
from drymount.hbm.closed_form import jenkins_coefficients
from drymount.hbm.elements import jenkins_periodic
from drymount.hbm.identify import (MIN_POINTS_PER_PARAMETER, DataError, Fit,
                                   FitStatus, LoopTest, StiffnessPoint,
                                   point_problems)
from drymount.hbm.laws import hbm_law

__all__ = ["MODELS", "RigModel", "RigFit", "PARAMETER_UNITS", "check_model",
           "complex_stiffness", "loop_force", "loop_fundamental", "fit_table",
           "fit_loops", "table_residuals", "loop_residuals"]

MODELS = ("rubber", "hydraulic")
_RUBBER_UNITS = {"k1": "N/m", "kf": "N/m", "fs": "N", "c": "N s/m"}
#: Unit of every parameter name (Maxwell branches: ``maxwell<i>_k`` N/m,
#: ``maxwell<i>_c`` N s/m).
PARAMETER_UNITS = {**_RUBBER_UNITS,
                   **{n: u.replace(".", " ").replace("m2", "m^2").replace("m5", "m^5")
                      .replace("m4", "m^4") for n, u, _ in HYDRAULIC_FIELDS}}
#: The hydraulic parameters a table cannot separate: Ap and one of the three.
_HYDRAULIC_GAUGE = ("kr", "C1", "C2")
#: Samples per period of the AFT of a non-linear elastic law's K_el(X).
EL_SAMPLES = 1024


def unit(name: str) -> str:
    """The unit of a parameter name."""
    if name.startswith("maxwell"):
        return "N/m" if name.endswith("_k") else "N s/m"
    return PARAMETER_UNITS[name]


@dataclass(frozen=True)
class RigModel:
    """What is fitted.

    Attributes
    ----------
    kind : str
        ``"rubber"`` or ``"hydraulic"``.
    maxwell : int
        Number of Maxwell branches (rubber).
    friction : bool
        With the Jenkins element (rubber).
    decoupler : bool
        With the decoupler passage (hydraulic).
    elastic : AxisParameters or None
        The elastic law's shape (rubber): None is the linear law ``k1 u``; otherwise
        its ``k1`` is a parameter (fitted unless fixed) and its other fields are kept.
    fixed : dict of str to float
        Parameters held at the given values (SI).
    """

    kind: str = "rubber"
    maxwell: int = 0
    friction: bool = True
    decoupler: bool = False
    elastic: AxisParameters | None = None
    fixed: dict = field(default_factory=dict)

    @property
    def names(self) -> tuple[str, ...]:
        """Every parameter of the model, in order."""
        if self.kind == "hydraulic":
            names = [n for n, _, _ in HYDRAULIC_FIELDS]
            return tuple(names if self.decoupler else names[:7])
        out = ["k1"] + (["kf", "fs"] if self.friction else []) + ["c"]
        for i in range(1, self.maxwell + 1):
            out += [f"maxwell{i}_k", f"maxwell{i}_c"]
        return tuple(out)

    @property
    def free(self) -> tuple[str, ...]:
        return tuple(n for n in self.names if n not in self.fixed)

    @property
    def label(self) -> str:
        if self.kind == "hydraulic":
            return "hydraulic" + (" with decoupler" if self.decoupler else "")
        law = "linear" if self.elastic is None else self.elastic.law
        parts = [f"{law} elastic"] + (["Jenkins"] if self.friction else []) + \
            ["damper"] + ([f"{self.maxwell} Maxwell"] if self.maxwell else [])
        return " + ".join(parts)


def check_model(model: RigModel) -> RigModel:
    """``model`` or ValueError naming what is wrong and what is allowed."""
    if model.kind not in MODELS:
        raise ValueError(f"model kind {model.kind!r}: must be one of "
                         f"{', '.join(MODELS)}")
    if not (isinstance(model.maxwell, int) and 0 <= model.maxwell <= 8):
        raise ValueError(f"maxwell = {model.maxwell!r}: the number of Maxwell branches "
                         f"must be an integer from 0 to 8")
    names = model.names
    for k, v in model.fixed.items():
        if k not in names:
            raise ValueError(f"fixed parameter {k!r} is not one of the {model.label} "
                             f"model's: {', '.join(names)}")
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
            raise ValueError(f"fixed {k} = {v!r}: must be a finite number >= 0 "
                             f"({unit(k)})")
    if model.kind == "hydraulic":
        if "Ap" not in model.fixed or not any(g in model.fixed
                                              for g in _HYDRAULIC_GAUGE):
            raise ValueError(
                "the hydraulic mount's K* depends on its parameters only through "
                "kr + Ap^2/(C1+C2), Ap^2 C2/(C1 (C1+C2)), (C1 C2/(C1+C2)) x the "
                "passages' R and I, and br: fix Ap and one of kr, C1, C2 (e.g. "
                "`--fix Ap=0.003 --fix C2=2e-9`); fixed now: "
                f"{', '.join(model.fixed) or 'none'}")
    if not model.free:
        raise ValueError("every parameter is fixed: nothing to fit")
    return model


@dataclass(frozen=True)
class RigFit(Fit):
    """A :class:`hbm.identify.Fit` of a :class:`RigModel` (``params`` holds the fixed
    parameters too, with standard error 0; ``rig`` the model; ``sigma`` the residual
    standard deviation ``sqrt(RSS / (n - p))``, in the residual's unit)."""

    rig: RigModel = None
    sigma: float = math.nan
    residual_unit: str = ""


# --------------------------------------------------------------------------------------
# The model's complex stiffness and loop force
# --------------------------------------------------------------------------------------


def _hydraulic(p: dict) -> HydraulicParameters:
    return HydraulicParameters(**{n: p.get(n, 0.0) for n, _, _ in HYDRAULIC_FIELDS})


def _maxwell(model: RigModel, p: dict, omega) -> np.ndarray:
    if not model.maxwell:
        return np.zeros(len(omega), dtype=complex)
    k = [p[f"maxwell{i}_k"] for i in range(1, model.maxwell + 1)]
    c = [p[f"maxwell{i}_c"] for i in range(1, model.maxwell + 1)]
    return np.array(maxwell_complex_stiffness(k, c, [float(w) for w in omega]))


def _elastic_stiffness(model: RigModel, k1: float, amplitudes: np.ndarray
                       ) -> np.ndarray:
    """K_el(X) of the elastic law (real for the rate-independent laws), N/m."""
    if model.elastic is None or model.elastic.law == "linear":
        return np.full(amplitudes.shape, k1, dtype=complex)
    law = replace(model.elastic, k1=k1, friction=False, c=0.0)
    uniq, inv = np.unique(amplitudes, return_inverse=True)
    vals = np.array([rate_independent_stiffness(law, float(X), 0.0, EL_SAMPLES)
                     for X in uniq])
    return vals[inv]


def _static_hydraulic(p: dict) -> float:
    """The hydraulic mount's static stiffness ``kr + Ap^2 / (C1 + C2)``, N/m."""
    return complex(hydraulic_complex_stiffness(_hydraulic(p), 0.0)).real


def _rate_part(model: RigModel, p: dict, omega) -> np.ndarray:
    """The linear frequency-dependent part of K*, zero at omega = 0, N/m."""
    omega = np.asarray(omega, dtype=float)
    if model.kind == "hydraulic":
        return (np.array(hydraulic_complex_stiffness(_hydraulic(p), omega.tolist()))
                - _static_hydraulic(p))
    return 1j * omega * p["c"] + _maxwell(model, p, omega)


def complex_stiffness(model: RigModel, params: dict, freq_hz, amplitude) -> np.ndarray:
    """K* (N/m) of the model at the pairs ``(freq_hz, amplitude)`` (broadcast)."""
    f, X = np.broadcast_arrays(np.asarray(freq_hz, float), np.asarray(amplitude, float))
    f, X = f.ravel(), X.ravel()
    K = _rate_part(model, params, 2 * np.pi * f)
    if model.kind == "hydraulic":
        K = K + _static_hydraulic(params)
    else:
        K = K + _elastic_stiffness(model, params["k1"], X)
        if model.friction:
            F_s, F_c, _, _ = jenkins_coefficients(X, params["kf"], params["fs"])
            K = K + (F_s + 1j * F_c) / X
    return K


def _harmonics(test: LoopTest) -> tuple[np.ndarray, np.ndarray]:
    """``(indices, omega)`` of the rfft bins of the test's first harmonics."""
    n = test.time.size
    duration = n * (test.time[1] - test.time[0])
    cycles = int(round(test.freq_hz * duration))
    k = np.arange(n // 2 + 1)
    keep = (k % cycles == 0) & (k <= test.harmonics * cycles) & (k > 0)
    return np.flatnonzero(keep), 2 * np.pi * k[keep] / duration


def loop_force(model: RigModel, params: dict, test: LoopTest) -> np.ndarray:
    """The model's periodic force (N) for the test's measured deflection."""
    u = test.deflection
    idx, omega = _harmonics(test)
    spec = np.fft.rfft(u)
    lin = np.zeros_like(spec)
    lin[idx] = _rate_part(model, params, omega) * spec[idx]
    F = np.fft.irfft(lin, u.size)
    if model.kind == "hydraulic":   # its static stiffness on the measured deflection
        return F + _static_hydraulic(params) * u
    k1 = params["k1"]
    F = F + k1 * u
    if model.elastic is not None and model.elastic.law != "linear":
        from drymount.hbm.characterise import axis_as_nonlinear

        ax = axis_as_nonlinear(replace(model.elastic, k1=k1, friction=False))
        rem, _ = hbm_law(ax.law[0]).remainder(u[:, None], ax, np.array([True]))
        F = F + rem[:, 0]
    if model.friction:
        F = F + jenkins_periodic(u, params["kf"], params["fs"])[0]
    return F


def loop_fundamental(test: LoopTest, force: np.ndarray | None = None) -> complex:
    """K* (N/m) of one loop: the force's fundamental over the deflection's (the
    deflection's phase as the reference)."""
    idx, _ = _harmonics(test)
    U = np.fft.rfft(test.deflection)[idx[0]]
    F = np.fft.rfft(test.force if force is None else force)[idx[0]]
    return complex(F / U)


# --------------------------------------------------------------------------------------
# Starts from the data
# --------------------------------------------------------------------------------------


def _table_arrays(points) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    f = np.array([p.freq_hz for p in points])
    X = np.array([p.amplitude for p in points])
    K = np.array([p.K for p in points])
    return f, X, K


def _rubber_starts(model: RigModel, f, X, K) -> list[dict]:
    lo, hi = f.min(), f.max()
    at_lo = np.flatnonzero(f <= lo * (1 + 1e-9))
    x_small, x_big = at_lo[np.argmin(X[at_lo])], at_lo[np.argmax(X[at_lo])]
    k1 = model.fixed.get("k1", model.elastic.k1 if model.elastic is not None
                         else 0.9 * max(K[x_big].real, 1e-6 * np.abs(K).max()))
    base = {"k1": k1}
    if model.friction:
        kf = max(K[x_small].real - K[x_big].real, 0.1 * k1)
        d_im = max(K[x_big].imag - K[x_small].imag, 1e-3 * abs(K[x_big]))
        fs = max(math.pi * d_im * X[x_big] / 4.0, 1e-3 * kf * X.min())
        base.update(kf=kf, fs=min(fs, 0.5 * kf * X[x_big]))
    small = np.flatnonzero(X <= X.min() * (1 + 1e-9))
    order = small[np.argsort(f[small])]
    rise = max(K[order[-1]].real - K[order[0]].real, 0.05 * k1)
    im_hi = max(K[order[-1]].imag, 1e-3 * abs(K[order[-1]]))
    starts = []
    spreads = [None] if not model.maxwell else \
        [np.linspace(a, b, model.maxwell) if model.maxwell > 1 else np.array([s])
         for a, b, s in ((0.25, 0.75, 0.5), (0.1, 0.5, 0.25), (0.5, 0.9, 0.75),
                         (0.0, 1.0, 0.1))]
    for spread in spreads:
        for c_frac in (0.3, 0.03):
            p = dict(base)
            w_hi = 2 * np.pi * hi
            p["c"] = c_frac * im_hi / w_hi
            if spread is not None:
                for i, s in enumerate(spread, start=1):
                    fi = lo ** (1 - s) * hi ** s
                    p[f"maxwell{i}_k"] = rise / model.maxwell
                    p[f"maxwell{i}_c"] = rise / model.maxwell / (2 * np.pi * fi)
            starts.append(p)
    return starts


def _hydraulic_starts(model: RigModel, f, K) -> list[dict]:
    """From the fluid resonance of the data: K0 (lowest frequency), the loss peak's
    frequency omega0 and height, as ``K0 + dK (d1 s + d2 s^2)/(1 + d1 s + d2 s^2)``
    (module docstring), mapped to the physical parameters with Ap and one of kr,
    C1, C2 given."""
    order = np.argsort(f)
    f, K = f[order], K[order]
    w = 2 * np.pi * f
    fx = model.fixed
    K0 = K[0].real
    starts = []
    for shift in (1.0, 0.7, 1.4):
        ip = int(np.argmax(K.imag))
        w0 = w[ip] * shift
        dK = max(np.interp(w0, w, K.real) - K0, 0.05 * K0)
        zeta = min(max(dK / (2 * max(K.imag[ip], 1e-9)), 0.02), 2.0)
        d2, d1 = 1 / w0**2, 2 * zeta / w0
        Ap = fx["Ap"]
        if "C2" in fx:
            C2 = fx["C2"]
            C1 = (-C2 + math.sqrt(C2 * C2 + 4 * Ap * Ap * C2 / dK)) / 2
        elif "C1" in fx:
            C1 = fx["C1"]
            C2 = dK * C1 * C1 / (Ap * Ap - dK * C1) if Ap * Ap > dK * C1 \
                else 100 * C1
        else:
            a = max(K0 - fx["kr"], 0.05 * K0)
            C1 = Ap * Ap / a / (1 + dK / a)
            C2 = C1 * dK / a
        kr = fx.get("kr", max(K0 - Ap * Ap / (C1 + C2), 0.3 * K0))
        g = (C1 + C2) / (C1 * C2)
        br = max((K[-1].imag - dK / (d1 * w[-1])) / w[-1], 1e-4 * K0 / w[-1])
        p = {"kr": kr, "br": br, "Ap": Ap, "C1": C1, "C2": C2, "I_i": d2 * g,
             "R_i": d1 * g}
        if model.decoupler:
            for ratio in (0.1, 0.3):
                starts.append({**p, "I_d": ratio * p["I_i"], "R_d": p["R_i"] / ratio})
        else:
            starts.append(p)
    return starts


# --------------------------------------------------------------------------------------
# The fit
# --------------------------------------------------------------------------------------


def _solve(model: RigModel, resid, starts, y, residual_unit: str,
           diff_step=None) -> RigFit:
    free = model.free
    best = None
    for p0 in starts:
        p0 = {**p0, **model.fixed}
        x0 = np.log(np.maximum([p0[n] for n in free], 1e-300))

        def r(x, p0=p0):
            return resid({**p0, **dict(zip(free, np.exp(x), strict=True))})

        res = least_squares(r, x0, method="trf", diff_step=diff_step,
                            xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=400)
        if best is None or res.cost < best[0].cost:
            best = (res, p0)
    res, p0 = best
    n, k = res.fun.size, len(free)
    rss = float(res.fun @ res.fun)
    dof = max(n - k, 1)
    x = res.x
    try:
        cov = np.linalg.inv(res.jac.T @ res.jac) * rss / dof
        se_log = np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        se_log = np.full(k, math.inf)
    vals = np.exp(x)
    params = {**p0, **dict(zip(free, vals.tolist(), strict=True))}
    params = {nm: float(params[nm]) for nm in model.names}
    stderr = {nm: 0.0 for nm in model.names}
    stderr.update(dict(zip(free, (vals * se_log).tolist(), strict=True)))
    params, stderr = _order_branches(model, params, stderr)
    yc = y - y.mean()
    tss = float(yc @ yc)
    return RigFit(model=model.label, params=params, stderr=stderr, rss=rss,
                  r2=1.0 - rss / tss if tss > 0 else math.nan,
                  aic=n * math.log(max(rss, 1e-300) / n) + 2 * k, n=n,
                  status=FitStatus.CONVERGED if res.success else
                  FitStatus.NOT_CONVERGED, message=str(res.message), rig=model,
                  sigma=math.sqrt(rss / dof), residual_unit=residual_unit)


def _order_branches(model: RigModel, params: dict, stderr: dict
                    ) -> tuple[dict, dict]:
    """The Maxwell branches numbered by rising relaxation frequency k_i / (2 pi c_i)
    (the fit's order is arbitrary: any permutation fits equally). Branches with a
    fixed parameter keep their numbers."""
    idx = range(1, model.maxwell + 1)
    if model.maxwell < 2 or any(f"maxwell{i}_{q}" in model.fixed for i in idx
                                for q in "kc"):
        return params, stderr
    order = sorted(idx, key=lambda i: params[f"maxwell{i}_k"] / params[f"maxwell{i}_c"])
    p, se = dict(params), dict(stderr)
    for new, old in zip(idx, order, strict=True):
        for q in "kc":
            p[f"maxwell{new}_{q}"] = params[f"maxwell{old}_{q}"]
            se[f"maxwell{new}_{q}"] = stderr[f"maxwell{old}_{q}"]
    return p, se


def _check_points(points, model: RigModel) -> list[StiffnessPoint]:
    points = list(points)
    problems = point_problems(points)
    need = math.ceil(MIN_POINTS_PER_PARAMETER * len(model.free) / 2)
    if len(points) < need:
        problems.append(f"the {model.label} model has {len(model.free)} free "
                        f"parameters: a table needs at least {need} rows (each gives "
                        f"K' and K''), got {len(points)}")
    if problems:
        raise DataError(problems)
    return points


def fit_table(points, model: RigModel) -> RigFit:
    """Least-squares fit of ``model`` to a dynamic-stiffness table (module docstring).

    Residuals: ``(K*_model - K*_measured) / |K*_measured|``, real and imaginary parts
    of every row (dimensionless)."""
    model = check_model(model)
    points = _check_points(points, model)
    f, X, K = _table_arrays(points)
    scale = np.abs(K)

    def resid(p):
        r = (complex_stiffness(model, p, f, X) - K) / scale
        return np.concatenate([r.real, r.imag])

    starts = (_hydraulic_starts(model, f, K) if model.kind == "hydraulic"
              else _rubber_starts(model, f, X, K))
    y = np.concatenate([(K / scale).real, (K / scale).imag])
    return _solve(model, resid, starts, y, "x |K*|")


def fit_loops(tests, model: RigModel) -> RigFit:
    """Least-squares fit of ``model`` to force-displacement loops (module docstring):
    residuals the force (N) at every sample. Starts from :func:`fit_table` on the
    loops' fundamentals."""
    model = check_model(model)
    tests = list(tests)
    if not tests:
        raise DataError(["no loop test given"])
    F = np.concatenate([t.force for t in tests])
    if F.size < MIN_POINTS_PER_PARAMETER * len(model.free):
        raise DataError([f"the loops hold {F.size} samples, need at least "
                         f"{MIN_POINTS_PER_PARAMETER * len(model.free)}"])
    pts = [_point(t) for t in tests]
    starts = []
    if 2 * len(pts) >= len(model.free):   # enough fundamentals to start from
        try:
            first = fit_table(pts, model)
            if first.status is FitStatus.CONVERGED:
                starts.append(first.params)
        except (DataError, ValueError):
            pass
    if not starts:   # too few tests, or that fit failed: starts from the data
        f, X, K = _table_arrays(pts)
        starts = (_hydraulic_starts(model, f, K) if model.kind == "hydraulic"
                  else _rubber_starts(model, f, X, K))[:2]
    starts = [s for s in starts if all(s.get(n, 1.0) > 0 for n in model.free)]

    def resid(p):
        return np.concatenate([loop_force(model, p, t) for t in tests]) - F

    return _solve(model, resid, starts, F, "N", diff_step=1e-6)


def _point(test: LoopTest) -> StiffnessPoint:
    K = loop_fundamental(test)
    return StiffnessPoint(test.freq_hz, test.amplitude, abs(K),
                          math.degrees(math.atan2(K.imag, K.real)))


# --------------------------------------------------------------------------------------
# Residual reports
# --------------------------------------------------------------------------------------


def table_residuals(fit: RigFit, points) -> list[dict]:
    """Per row: measured and fitted |K*| (N/m) and loss angle (deg), their
    differences, and the complex residual of the fit (relative)."""
    f, X, K = _table_arrays(points)
    Km = complex_stiffness(fit.rig, fit.params, f, X)
    out = []
    for i in range(f.size):
        r = (Km[i] - K[i]) / abs(K[i])
        out.append({"freq_hz": f[i], "amplitude_m": X[i],
                    "stiffness_measured": abs(K[i]), "stiffness_fitted": abs(Km[i]),
                    "stiffness_rel_error": abs(Km[i]) / abs(K[i]) - 1.0,
                    "loss_angle_measured": math.degrees(np.angle(K[i])),
                    "loss_angle_fitted": math.degrees(np.angle(Km[i])),
                    "loss_angle_error": math.degrees(np.angle(Km[i] / K[i])),
                    "residual_real": r.real, "residual_imag": r.imag})
    return out


def loop_residuals(fit: RigFit, tests) -> list[dict]:
    """Per test: its frequency and amplitude, the rms force residual (N and relative
    to the force's half range) and the measured and fitted K* of the fundamentals."""
    out = []
    for t in tests:
        Fm = loop_force(fit.rig, fit.params, t)
        rms = float(np.sqrt(np.mean((Fm - t.force) ** 2)))
        Kd, Kf = loop_fundamental(t), loop_fundamental(t, Fm)
        out.append({"test": t.label, "freq_hz": t.freq_hz, "amplitude_m": t.amplitude,
                    "rms_residual_N": rms,
                    "rms_residual_rel": rms / (0.5 * float(np.ptp(t.force))),
                    "stiffness_measured": abs(Kd), "stiffness_fitted": abs(Kf),
                    "loss_angle_measured": math.degrees(np.angle(Kd)),
                    "loss_angle_fitted": math.degrees(np.angle(Kf))})
    return out
