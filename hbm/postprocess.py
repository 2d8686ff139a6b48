"""From a traced branch to a :class:`hbm.result.FrequencyResponse`: per-point
quantities, stability, exact folds and peaks as marked points, the transmissibility's
label."""

from __future__ import annotations

import numpy as np

from drymount.hbm.bifurcation import Bifurcation, locate_bifurcations
from drymount.hbm.continuation import Branch
from drymount.hbm.folds import CurveEvent, locate_folds, locate_maximum, locate_peaks
from drymount.hbm.inclined import stuck_codes
from drymount.hbm.options import HBMOptions
from drymount.hbm.problem import _amplitude_fn, _point_quantities, _Problem, _to_hz
from drymount.hbm.result import FrequencyResponse, MarkedPoint
from drymount.hbm.stability_schedule import _stability
from drymount.hbm.system import System

__all__ = ["postprocess"]


def _marked(prob: _Problem, ev: CurveEvent, n_peak: int) -> MarkedPoint:
    f, Xr, amp, trans = _point_quantities(prob, ev.y)
    peak = prob.hb.peak_abs(Xr.ravel(), n_peak)
    dof = None if ev.dof is None else prob.hb.system.dof_names[ev.dof]
    return MarkedPoint(ev.kind.value, float(ev.freq_hz), dof, ev.index, amp, peak,
                       float(trans), ev.converged, ev.interior)


def _events(prob: _Problem, br: Branch, opts: HBMOptions, turning, located):
    """Located folds and per-DOF peaks (empty without tangents); ``located``: folds
    already located on a finer re-trace, by turning-point index."""
    if not br.tangent or len(br.tangent) != len(br.y):
        return [], [], None
    settings = opts.continuation_settings()
    folds = []
    if len(turning):
        todo = Branch(y=br.y, tangent=br.tangent,
                      turning_points=[i for i in turning if i not in located])
        found = {e.index: e for e in locate_folds(prob, todo, settings, _to_hz(prob))}
        folds = [located.get(i) or found[i] for i in turning]
    peaks = locate_peaks(prob, br, settings, _to_hz(prob), _amplitude_fn(prob),
                         prob.hb.n)
    return ([_marked(prob, e, opts.n_peak) for e in folds],
            [_marked(prob, e, opts.n_peak) for e in peaks],
            _transmissibility_peak(prob, br, settings, opts.n_peak))


def _bifurcations(prob: _Problem, br: Branch, opts: HBMOptions, stable, turning
                  ) -> list[MarkedPoint]:
    """The changes of stability that are not folds, classified and located
    (:mod:`hbm.bifurcation`), as marked points; none without tangents."""
    if not br.tangent or len(br.tangent) != len(br.y) or len(stable) != len(br.y):
        return []
    found = locate_bifurcations(prob, br, stable, turning,
                                opts.continuation_settings())
    return [_marked_bifurcation(prob, b, opts.n_peak) for b in found]


def _marked_bifurcation(prob: _Problem, b: Bifurcation, n_peak: int) -> MarkedPoint:
    f, Xr, amp, trans = _point_quantities(prob, b.y)
    return MarkedPoint(b.kind.value, float(f), None, b.index,
                       amp, prob.hb.peak_abs(Xr.ravel(), n_peak), float(trans),
                       b.converged, True, b.multiplier)


#: Step along the unit tangent (scaled unknowns) of the central difference that gives
#: the transmissibility's slope (a ratio of fundamentals, smooth along the branch).
SLOPE_STEP = 1e-6


def _transmissibility_peak(prob: _Problem, br: Branch, settings, n_peak: int):
    """The transmissibility's maximum along the branch, located like a DOF's peak
    (to ``hbm.folds.FREQ_TOL_HZ``); None where it is not finite anywhere."""
    def value(y):
        return float(_point_quantities(prob, y)[3])

    values = np.array([value(y) for y in br.y])
    if not np.any(np.isfinite(values)):
        return None

    def slope(y, t):
        return (value(y + SLOPE_STEP * t) - value(y - SLOPE_STEP * t)) / (
            2 * SLOPE_STEP)

    ev = locate_maximum(prob, br, settings, _to_hz(prob), values, slope, value)
    return _marked(prob, ev, n_peak)


def postprocess(prob: _Problem, ys, opts: HBMOptions, br: Branch,
                turning, located=None, events: bool = True) -> FrequencyResponse:
    """The :class:`FrequencyResponse` of the scaled points ``ys`` of ``prob``, with
    its folds (``located``: those already located on a finer re-trace) and peaks
    (``events`` False: neither located, for a curve only traced to estimate its
    error)."""
    hb = prob.hb
    sysm = hb.system
    n, m, H = hb.n, hb.m, hb.H
    npts = len(ys)
    freq = np.empty(npts)
    coef = np.empty((npts, n, m))
    amp = np.empty((npts, n))
    peak = np.empty((npts, n))
    trans = np.empty(npts)
    stable = np.ones(npts, dtype=bool)
    fmr = np.full(npts, np.nan)
    for i, y in enumerate(ys):
        freq[i], Xr, amp[i], trans[i] = _point_quantities(prob, y)
        coef[i] = Xr.T
    if npts:
        peak[:] = hb.peak_abs(coef.transpose(0, 2, 1).reshape(npts, m * n),
                              opts.n_peak)
    if opts.stability and npts:
        stable[:], fmr[:] = _stability(prob, ys, br, opts.stability_stride)
    folds, peaks, t_peak = (_events(prob, br, opts, turning, located or {})
                            if events else ([], [], None))
    bifurcations = (_bifurcations(prob, br, opts, stable, turning)
                    if events and opts.stability else [])
    # which surfaces of each inclined element stick for the whole period (a family)
    stuck = stuck_codes(hb, coef) if events else None
    return FrequencyResponse(
        turning_freq_hz=np.array([e.freq_hz for e in folds], dtype=float),
        freq_hz=freq, coefficients=coef, amplitude=amp, peak=peak,
        transmissibility=trans, stable=stable,
        turning_points=np.asarray(turning, dtype=int), success=br.success,
        status=br.status, message=br.message, n_newton=br.n_newton,
        n_steps=br.n_steps, dof_names=tuple(sysm.dof_names), harmonics=H,
        n_samples=0 if hb.closed_form else hb.n_samples, closed_form=hb.closed_form,
        floquet_max_real=fmr, newton_per_point=np.asarray(br.n_iter, dtype=int),
        system_name=sysm.name, folds=folds, peaks=peaks, transmissibility_peak=t_peak,
        bifurcations=bifurcations,
        transmissibility_label=_transmissibility_label(sysm),
        stuck=stuck, stuck_labels=tuple(hb.axes.labels[a] for a, _ in
                                        hb.axes.inclined))


def _transmissibility_label(sysm: System) -> str:
    """The transmissibility's definition (thesis eq. 4.1, 4.3) for a y label."""
    tr = sysm.transmissibility
    if tr.kind == "force":
        return ("force transmissibility [-]\n|F_mounts| / |F_exc| (fundamentals, "
                "eq. 4.1)")
    num = sysm.dof_names[tr.dof]
    den = (sysm.dof_names[tr.reference] if tr.reference is not None
           else "base input")
    return (f"displacement transmissibility [-]\n|{num}| / |{den}| (fundamentals, "
            f"eq. 4.3)")


