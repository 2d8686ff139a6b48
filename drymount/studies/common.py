"""What the studies share: the design changes they make to a system, the metrics they
read off a curve, and the HBM curve of one design.

System edits return new systems (``hbm.system.System`` is immutable):
:func:`with_normal_force`, :func:`with_friction_of`, :func:`with_stiffness_factor`,
:func:`relocate_mount`, :func:`engine_excited`. Metrics: :func:`peak`,
:func:`value_at`, :func:`band_rms`, :func:`friction_energy`. Curves:
:func:`hbm_curve` (a :class:`Curve`: design, system, HBM response, wall time).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from types import SimpleNamespace

import numpy as np

import hbm
from fmu_src.mount_law import AXES, MountParameters, jenkins_update
from hbm.crank import DEFAULT_ENGINE, CrankMechanism
from hbm.system import Excitation, MountElement, System, Transmissibility

__all__ = [
    "StudyError", "load_system", "with_normal_force", "with_friction_of",
    "friction_template", "with_stiffness_factor", "mount_position", "relocate_mount",
    "engine_excited", "engine_unbalance", "ENGINE_EXCITATION", "friction_axes",
    "friction_energy", "FrictionWork", "Peak", "peak", "value_at", "ratio",
    "band_rms", "bands", "Curve", "hbm_curve", "PLOT_DS_MAX", "RESTART_FACTOR",
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
            _, w_new, _, slipping = jenkins_update(float(uk), w, kf, fs)
            e_sum += fs * abs(w_new - w)
            n_slip += slipping
            w = w_new
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
class Curve:
    """One HBM curve of a study with the design it belongs to.

    Attributes
    ----------
    case : dict
        The design (e.g. ``{"mount": "halved", "n0_N": 10.0, "H": 7}``).
    system : System
    fr : SegmentedResponse
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


#: When the continuation stops before ``fmax`` (a stalled step at a knee of the
#: piecewise law, a branch that turns back), the curve is restarted this factor above
#: the highest frequency reached, at most ``MAX_RESTARTS`` times. The pieces are kept
#: as separate segments (a gap in the plots) and every restart is reported.
RESTART_FACTOR = 1.02
MAX_RESTARTS = 8

#: Fields of an HBM response that the segments concatenate (point by point).
_POINT_FIELDS = ("freq_hz", "coefficients", "amplitude", "transmissibility", "stable")


@dataclass
class SegmentedResponse:
    """HBM segments of one curve, concatenated (the fields the studies use).

    Segments are separated by one row whose values are NaN (a gap in the plots); its
    frequency is the restart frequency. Fields as :class:`hbm.FrequencyResponse`:
    freq_hz (n,), coefficients (n, n_dof, 2H+1), amplitude (n, n_dof),
    transmissibility (n,), stable (n,), turning_points (indices), success (all of
    fmin..fmax covered), message, dof_names, harmonics; plus ``restarts``, one
    ``(frequency in Hz, reason)`` per restart.
    """

    freq_hz: np.ndarray
    coefficients: np.ndarray
    amplitude: np.ndarray
    transmissibility: np.ndarray
    stable: np.ndarray
    turning_points: np.ndarray
    success: bool
    message: str
    dof_names: tuple
    harmonics: int
    restarts: list


def _clip(fr, fmin: float, fmax: float):
    """The points of ``fr`` inside [fmin, fmax] Hz (a branch that turns back can
    leave the band); turning points renumbered."""
    f = np.asarray(fr.freq_hz, dtype=float)
    keep = (f >= fmin * (1 - 1e-9)) & (f <= fmax * (1 + 1e-9))
    if np.all(keep):
        return fr
    new_index = np.cumsum(keep) - 1
    tps = np.array([new_index[t] for t in fr.turning_points if keep[t]], dtype=int)
    return SimpleNamespace(
        freq_hz=f[keep], coefficients=np.asarray(fr.coefficients)[keep],
        amplitude=np.asarray(fr.amplitude)[keep],
        transmissibility=np.asarray(fr.transmissibility)[keep],
        stable=np.asarray(fr.stable, dtype=bool)[keep], turning_points=tps,
        success=fr.success, message=fr.message, dof_names=fr.dof_names,
        harmonics=fr.harmonics)


def _continue_with_restarts(system: System, band, harmonics: int, options
                            ) -> tuple[list, list]:
    """HBM pieces over ``band``: each restarted ``RESTART_FACTOR`` above the last
    frequency reached. Returns ``(pieces, restarts)``."""
    f0, fmax = float(band[0]), float(band[1])
    parts, restarts = [], []
    while True:
        fr = hbm.frequency_response(system, f0, fmax, harmonics=harmonics,
                                    options=options)
        parts.append(fr)
        top = float(np.max(fr.freq_hz)) if len(fr.freq_hz) else f0
        if fr.success or top >= fmax * (1 - 1e-9) or len(restarts) >= MAX_RESTARTS:
            break
        f_next = max(top, f0) * RESTART_FACTOR
        if f_next >= fmax:
            break
        restarts.append((f_next, fr.message))
        f0 = f_next
    return [_clip(fr, float(band[0]), fmax) for fr in parts], restarts


def _single(fr) -> SegmentedResponse:
    return SegmentedResponse(
        np.asarray(fr.freq_hz), np.asarray(fr.coefficients), np.asarray(fr.amplitude),
        np.asarray(fr.transmissibility), np.asarray(fr.stable, dtype=bool),
        np.asarray(fr.turning_points, dtype=int), bool(fr.success), fr.message,
        tuple(fr.dof_names), fr.harmonics, [])


def _gap_row(fr, f_gap: float) -> dict:
    """One NaN row (restart frequency ``f_gap``) shaped like the points of ``fr``."""
    return {"freq_hz": np.array([f_gap]),
            "coefficients": np.full((1,) + fr.coefficients.shape[1:], np.nan),
            "amplitude": np.full((1,) + fr.amplitude.shape[1:], np.nan),
            "transmissibility": np.array([np.nan]), "stable": np.array([True])}


def _join(parts, restarts, fmax: float) -> SegmentedResponse:
    """Concatenate the pieces, one gap row between neighbours."""
    cols = {k: [] for k in _POINT_FIELDS}
    tps, n = [], 0
    for i, fr in enumerate(parts):
        if i:
            for k, v in _gap_row(fr, restarts[i - 1][0]).items():
                cols[k].append(v)
            n += 1
        for k in cols:
            cols[k].append(np.asarray(getattr(fr, k)))
        tps += [n + int(t) for t in fr.turning_points]
        n += len(fr.freq_hz)
    last = parts[-1]
    reached = (float(np.max(last.freq_hz)) >= fmax * (1 - 1e-9) if len(last.freq_hz)
               else False)
    return SegmentedResponse(
        *[np.concatenate(cols[k]) for k in _POINT_FIELDS[:4]],
        np.concatenate(cols["stable"]).astype(bool), np.array(tps, dtype=int),
        bool(last.success or reached),
        f"{len(parts)} segments; " + "; ".join(
            f"restarted at {f:.4g} Hz after: {m}" for f, m in restarts),
        tuple(last.dof_names), last.harmonics, restarts)


def segmented(system: System, band, harmonics: int, options) -> SegmentedResponse:
    """HBM curve over ``band`` (Hz), restarted past points where it stalls."""
    parts, restarts = _continue_with_restarts(system, band, harmonics, options)
    if len(parts) == 1:
        return _single(parts[0])
    return _join(parts, restarts, float(band[1]))


def hbm_curve(system: System, band, harmonics: int, case: dict,
              failures: list, notes: list | None = None,
              ds_max: float | None = PLOT_DS_MAX) -> Curve:
    """An HBM curve over ``band`` (Hz), restarted past points where it stalls.

    A curve that does not reach ``band[1]`` is a failure (appended to ``failures``);
    restarts are notes.
    """
    t0 = time.perf_counter()
    options = hbm.HBMOptions() if ds_max is None else hbm.HBMOptions(ds_max=ds_max)
    fr = segmented(system, band, harmonics, options)
    dt = time.perf_counter() - t0
    if not fr.success:
        failures.append(f"{case}: {fr.message}")
    elif fr.restarts and notes is not None:
        notes.append(f"{case}: {fr.message}")
    return Curve(dict(case), system, fr, dt)
