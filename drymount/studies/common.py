"""What the studies share: the design changes they make to a system, the metrics they
read off a curve, and the HBM curve of one design.

System edits return new systems (``hbm.system.System`` is immutable):
:func:`with_normal_force`, :func:`with_friction_of`, :func:`with_stiffness_factor`,
:func:`relocate_mount`, :func:`engine_excited`. Metrics: :func:`peak`,
:func:`value_at`, :func:`band_rms`, :func:`friction_energy`. Curves:
:func:`hbm_curve` (a :class:`DesignResult`: design, system, HBM response, wall time).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

import drymount.hbm as hbm
from drymount.fmu_src.mount_law import AXES, MountParameters, jenkins_update
from drymount.hbm.crank import DEFAULT_ENGINE, CrankMechanism
from drymount.hbm.system import Excitation, MountElement, System, Transmissibility

__all__ = [
    "StudyError", "load_system", "with_normal_force", "with_friction_of",
    "friction_template", "with_stiffness_factor", "mount_position", "relocate_mount",
    "engine_excited", "engine_unbalance", "ENGINE_EXCITATION", "friction_axes",
    "friction_energy", "FrictionWork", "Peak", "peak", "value_at", "ratio",
    "band_rms", "bands", "DesignResult", "hbm_curve", "PLOT_DS_MAX", "RESTART_FACTOR",
    "MAX_RESTARTS",
]


class StudyError(ValueError):
    """Bad input to a study (unknown name, invalid option)."""


# ======================================================================================
# Systems: presets and the design changes the studies make
# ======================================================================================


def load_system(name: str) -> System:
    """The :class:`hbm.system.System` of preset ``name`` (``drymount.config``).

    Parameters
    ----------
    name : str
        A preset name, e.g. ``"sdof_original"``, ``"quarter_car_halved"``.
    """
    from drymount.config import load_preset

    return load_preset(name).system


def _map_friction_axes(system: System, fn: Callable) -> System:
    params = []
    for e in system.elements:
        axes = {name: fn(p) if p.friction else p for name, p in zip(AXES, e.params.axes,
                                                                       strict=True)}
        params.append(MountParameters(**axes))
    return system.with_mount_params(params)


def with_normal_force(system: System, n0: float) -> System:
    """A copy of ``system`` with normal force ``n0`` (N) on every friction element.

    ``n0 = 0`` removes the friction elements (with ``Fs = mu * n0 = 0`` a Jenkins
    element carries no force, thesis eq. 2.12), which gives the HBM the smooth,
    non-hysteretic mount. Axes without a friction element are unchanged.
    """
    if not (np.isfinite(n0) and n0 >= 0):
        raise StudyError(f"`n0` must be finite and >= 0, got {n0!r}")
    if n0 == 0:
        return _map_friction_axes(system, lambda p: replace(p, n0=0.0, friction=False))
    return _map_friction_axes(system, lambda p: replace(p, n0=float(n0)))


def with_friction_of(system: System, template: System) -> System:
    """A copy of ``system`` with the friction elements of ``template``.

    Every axis that has a friction element in ``template`` (same mount index, same
    axis) gets that element (``kf``, ``mu``, ``n0``) in ``system``; the elastic law and
    damping of ``system`` are kept. This puts the friction element of a preset such as
    ``sdof_halved`` onto the original mount (thesis Fig. 4.1: the original mount with
    friction for several n0).
    """
    if len(system.elements) != len(template.elements):
        raise StudyError(f"`template` must have {len(system.elements)} mounts, got "
                         f"{len(template.elements)}")
    if not template.is_hysteretic:
        raise StudyError(f"`template` {template.name!r} has no friction element")
    params = []
    for e, t in zip(system.elements, template.elements, strict=True):
        axes = [replace(p, friction=True, kf=q.kf, mu=q.mu, n0=q.n0) if q.friction
                else p for p, q in zip(e.params.axes, t.params.axes, strict=True)]
        params.append(MountParameters(*axes))
    return system.with_mount_params(params)


def friction_template(systems) -> System:
    """The first system of ``systems`` that has a friction element."""
    for s in systems:
        if s.is_hysteretic:
            return s
    raise StudyError("none of the presets has a friction element: "
                     + ", ".join(s.name for s in systems))


def with_stiffness_factor(system: System, factor: float) -> System:
    """A copy with every mount's elastic stiffness (k1, kc, k2) times ``factor``.

    Damping ``c`` and the friction contact stiffness ``kf`` are unchanged: the thesis
    halves "the stiffness of the original mount" (Sec. 4.2) to offset the stiffening of
    the stuck friction element.
    """
    if not (np.isfinite(factor) and factor > 0):
        raise StudyError(f"`factor` must be finite and > 0, got {factor!r}")
    params = []
    for e in system.elements:
        params.append(MountParameters(*[
            replace(p, k1=p.k1 * factor, kc=p.kc * factor, k2=p.k2 * factor)
            for p in e.params.axes]))
    return system.with_mount_params(params)


def mount_position(element: MountElement) -> np.ndarray:
    """Position (3,) in m of a 6-DOF mount, from ``B = R [I, -S(a)]`` (eq. 2.9)."""
    B = np.asarray(element.B)
    if B.shape != (3, 6):
        raise StudyError(f"mount {element.name!r} is not a 6-DOF mount (B has shape "
                         f"{B.shape}, expected (3, 6))")
    R = B[:, :3]
    S = -R.T @ B[:, 3:]
    return np.array([S[2, 1], S[0, 2], S[1, 0]])


def _skew(a) -> np.ndarray:
    ax, ay, az = a
    return np.array([[0.0, -az, ay], [az, 0.0, -ax], [-ay, ax, 0.0]])


def relocate_mount(system: System, index: int, position: Sequence[float]) -> System:
    """A copy of a 6-DOF system with mount ``index`` moved to ``position`` (m).

    The mount keeps its orientation ``R`` (rows: local axes in body axes) and law; only
    its deflection map changes: ``B = R [I, -S(a)]`` (thesis eq. 2.9).
    """
    e = system.elements[index]
    a = np.asarray(position, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise StudyError(
            f"`position` must be three finite values in m, got {position!r}")
    R = np.asarray(e.B)[:, :3]
    B = R @ np.hstack([np.eye(3), -_skew(a)])
    els = list(system.elements)
    els[index] = MountElement(e.name, e.params, B, e.G)
    return System(system.name, system.dof_names, system.M, system.C, system.K,
                  tuple(els), system.excitation, system.transmissibility, system.Kb,
                  system.Cb, system.base_names, system.description, dict(system.notes))


#: Engine of the six-dof study: the project's one crank model and default engine
#: (:data:`hbm.crank.DEFAULT_ENGINE`, values in docs/physics.md).
ENGINE_EXCITATION = DEFAULT_ENGINE


def engine_unbalance(engine: CrankMechanism = ENGINE_EXCITATION) -> np.ndarray:
    """6-vector U (x, y, z, alpha, beta, gamma) of the engine's second order as an
    unbalance ``U omega^2``: vertical force along z and roll moment about y.

    The shared ``Excitation`` carries one phase for all DOFs, so both are applied in
    phase (``sin(omega t)``); the real 90 degree shift between them (``hbm.crank``)
    changes the coupled response only where the z and beta modes overlap.
    """
    return np.array([0.0, 0.0, engine.unbalance_z, 0.0, engine.unbalance_roll, 0.0])


def engine_excited(system: System, engine: CrankMechanism = ENGINE_EXCITATION
                   ) -> System:
    """The 6-DOF ``system`` with the chassis fixed and the engine's own excitation.

    Transmissibility: sum of the mounts' axial (vertical) forces over the excitation
    amplitude (``hbm.system.Transmissibility`` kind ``force``).
    """
    if system.n_dof != 6:
        raise StudyError(f"engine excitation needs a 6-DOF system, got {system.n_dof} "
                         f"DOFs")
    els = tuple(MountElement(e.name, e.params, e.B, np.zeros((3, 0)))
                for e in system.elements)
    axial_forces = tuple((i, 0) for i in range(len(els)))
    return System(system.name + "_engine", system.dof_names, system.M, system.C,
                  system.K, els, Excitation("unbalance", engine_unbalance(engine)),
                  Transmissibility("force", forces=axial_forces),
                  description=system.description + ", engine excitation",
                  notes=dict(system.notes))


def friction_axes(system: System) -> list[tuple[int, int]]:
    """(mount index, local axis index) of every active friction element."""
    return [(i, j) for i, e in enumerate(system.elements) for j in e.active_axes
            if e.params.axes[j].friction]


# ======================================================================================
# Metrics of HBM curves
# ======================================================================================


def _deflection(system: System, fr, point: int, element: int, axis: int,
                n_samples: int) -> np.ndarray:
    """Local deflection u(t) (n_samples,) in m of one mount axis over one period at an
    HBM point, at t_k = k T / n_samples."""
    coeffs = np.asarray(fr.coefficients[point])  # (n_dof, 2H + 1)
    H = (coeffs.shape[1] - 1) // 2
    theta = 2.0 * math.pi * np.arange(n_samples) / n_samples
    basis = [np.ones(n_samples)]
    for k in range(1, H + 1):
        basis += [np.cos(k * theta), np.sin(k * theta)]
    q = coeffs @ np.array(basis)  # (n_dof, n_samples)
    e = system.elements[element]
    u = np.asarray(e.B)[axis] @ q
    if system.excitation.kind == "base" and system.n_base:
        y = np.outer(np.asarray(system.excitation.amplitude), np.sin(theta))
        u = u - np.asarray(e.G)[axis] @ y
    return u


@dataclass(frozen=True)
class FrictionWork:
    """Work of one friction element along a curve (one value per curve point).

    Attributes
    ----------
    energy : ndarray, shape (n_points,)
        Dissipated energy per cycle, J (NaN at the gap rows of a restarted curve)
        (``Fs * sum |w_new - w|``, thesis Sec. 3.1.3; for u = X sin(omega t) with
        X > eps it is 4 Fs (X - eps)).
    slip_fraction : ndarray, shape (n_points,)
        Fraction of the period during which the slider slips (Fig. 4.44).
    """

    energy: np.ndarray
    slip_fraction: np.ndarray


def _cycle_work(u: np.ndarray, kf: float, fs: float) -> tuple[float, int]:
    """Energy and slipping samples of the second period of the Jenkins element
    marched from ``w = 0`` over two periods of the samples ``u``."""
    w = 0.0
    for period in range(2):
        e_sum, n_slip = 0.0, 0
        for uk in u:
            step = jenkins_update(float(uk), w, kf, fs)
            e_sum += fs * abs(step.w_new - w)
            n_slip += step.slipping
            w = step.w_new
    return e_sum, n_slip


def friction_energy(system: System, fr, element: int, axis: int,
                    n_samples: int = 512) -> FrictionWork:
    """Energy dissipated per cycle by one friction element along an HBM curve.

    The element's deflection is rebuilt from the harmonic coefficients and the exact
    return map of the Jenkins element (``fmu_src.mount_law.jenkins_update``) is marched
    over two periods from ``w = 0`` (the HBM convention, PHYSICS.md section 1); the
    second period is kept.

    Parameters
    ----------
    system : System
        The system the curve ``fr`` belongs to.
    fr : hbm.FrequencyResponse
    element, axis : int
        Mount index and local axis index (order of ``AXES``).
    n_samples : int
        Samples per period.
    """
    p = system.elements[element].params.axes[axis]
    n_points = len(fr.freq_hz)
    energy = np.zeros(n_points)
    slip = np.zeros(n_points)
    if not p.friction or p.fs == 0.0:
        return FrictionWork(energy, slip)
    for i in range(n_points):
        u = _deflection(system, fr, i, element, axis, n_samples)
        if not np.all(np.isfinite(u)):  # gap between segments
            energy[i] = slip[i] = np.nan
            continue
        e_sum, n_slip = _cycle_work(u, p.kf, p.fs)
        energy[i] = e_sum
        slip[i] = n_slip / n_samples
    return FrictionWork(energy, slip)


@dataclass(frozen=True)
class Peak:
    """Largest value of a curve and its frequency (NaN for an empty curve)."""

    value: float
    freq_hz: float


def peak(freq_hz, values) -> Peak:
    """The :class:`Peak` of a curve, ignoring NaN."""
    values = np.asarray(values, dtype=float)
    if values.size == 0 or not np.any(np.isfinite(values)):
        return Peak(float("nan"), float("nan"))
    i = int(np.nanargmax(values))
    return Peak(float(values[i]), float(np.asarray(freq_hz)[i]))


def value_at(freq_hz, values, f) -> float:
    """Curve value at frequency ``f``, linear interpolation on the points sorted by
    frequency (meant for single-valued parts of a curve, away from folds)."""
    freq_hz = np.asarray(freq_hz, dtype=float)
    values = np.asarray(values, dtype=float)
    ok = np.isfinite(values)
    freq_hz, values = freq_hz[ok], values[ok]
    order = np.argsort(freq_hz, kind="stable")
    return float(np.interp(f, freq_hz[order], values[order]))


def ratio(a: float, b: float) -> float:
    """a / b, NaN when b is zero or tiny (a DOF the input does not excite)."""
    return float(a / b) if abs(b) > 1e-15 else float("nan")


def band_rms(freq_hz, values, band) -> float:
    """RMS over ``band`` (Hz) with equal weight per Hz (trapezoid rule)."""
    f = np.asarray(freq_hz, dtype=float)
    v = np.asarray(values, dtype=float)
    m = (f >= band[0] - 1e-9) & (f <= band[1] + 1e-9)
    f, v = f[m], v[m]
    if f.size < 2:
        raise StudyError(f"band {band} Hz holds fewer than 2 curve points")
    return float(math.sqrt(np.trapezoid(v**2, f) / (f[-1] - f[0])))


def bands(f, mask) -> list[tuple[float, float]]:
    """Frequency intervals (Hz) where ``mask`` holds."""
    out, start, prev = [], None, None
    for fi, m in zip(f, mask, strict=True):
        if m and start is None:
            start = fi
        if not m and start is not None:
            out.append((round(float(start), 3), round(float(prev), 3)))
            start = None
        prev = fi
    if start is not None:
        out.append((round(float(start), 3), round(float(f[-1]), 3)))
    return out


# ======================================================================================
# Curves: one HBM curve per design, restarted where the continuation stalls
# ======================================================================================


@dataclass
class DesignResult:
    """One design of a study and its HBM curve (the curve itself is the one
    ``hbm.FrequencyResponse`` type; this record adds the design, wall time and extra
    per-point columns).

    Attributes
    ----------
    case : dict
        The design (e.g. ``{"mount": "halved", "n0_N": 10.0, "H": 7}``).
    system : System
    fr : hbm.FrequencyResponse
        With a gap row between restarted segments (``fr.restarts``).
    seconds : float
        Wall time of the HBM run, s.
    extra : dict of str -> ndarray (n_points,)
        Extra per-point columns (e.g. friction energy per cycle).
    """

    case: dict
    system: System
    fr: object
    seconds: float
    extra: dict = field(default_factory=dict)


#: Largest continuation step (scaled units of hbm.HBMOptions) for plotted curves:
#: finer than the default so that curves look smooth on a log frequency axis.
PLOT_DS_MAX = 0.01


#: The studies' curves restart the continuation where it stalls before ``fmax`` (a
#: stalled step at a knee of the piecewise law, a branch that turns back): at most
#: ``MAX_RESTARTS`` times, ``RESTART_FACTOR`` above the highest frequency reached
#: (``hbm.HBMOptions.max_restarts``, ``restart_factor``). The pieces are separate
#: segments of one ``hbm.FrequencyResponse`` (a gap row, NaN, in the plots) and every
#: restart is reported.
RESTART_FACTOR = 1.02
MAX_RESTARTS = 8


def hbm_curve(system: System, band, harmonics: int, case: dict,
              failures: list, notes: list | None = None,
              ds_max: float | None = PLOT_DS_MAX) -> DesignResult:
    """An HBM curve over ``band`` (Hz), restarted past points where it stalls.

    A curve that does not reach ``band[1]`` is a failure (appended to ``failures``);
    restarts are notes.
    """
    t0 = time.perf_counter()
    restart = {"max_restarts": MAX_RESTARTS, "restart_factor": RESTART_FACTOR}
    options = (hbm.HBMOptions(**restart) if ds_max is None
               else hbm.HBMOptions(ds_max=ds_max, **restart))
    fr = hbm.frequency_response(system, float(band[0]), float(band[1]),
                                harmonics=harmonics, options=options)
    dt = time.perf_counter() - t0
    if not fr.success:
        failures.append(f"{case}: {fr.message}")
    elif fr.restarts and notes is not None:
        notes.append(f"{case}: {fr.message}")
    return DesignResult(dict(case), system, fr, dt)
