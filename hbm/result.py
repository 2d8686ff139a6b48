"""Result of a harmonic-balance frequency response: :class:`FrequencyResponse`."""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from drymount.hbm.continuation import Status

__all__ = ["FrequencyResponse", "MarkedPoint", "Status", "finite_max"]


def finite_max(a) -> float:
    """Largest finite value of ``a`` (NaN if none): the worst of per-point error
    estimates, some of which may be NaN (not estimated)."""
    a = np.asarray(a, float)
    a = a[np.isfinite(a)]
    return float(a.max()) if a.size else float("nan")


@dataclass(frozen=True)
class MarkedPoint:
    """A located fold or resonance peak of a curve (:mod:`hbm.folds`).

    Attributes
    ----------
    kind : ``"fold"`` or ``"peak"``
    freq_hz : float
        Frequency of the fold (extremum of the frequency along the curve) or of the
        peak (extremum of ``dof``'s fundamental amplitude along the curve), Hz,
        located to ``hbm.folds.FREQ_TOL_HZ``.
    dof : str or None
        The DOF whose amplitude peaks (None for a fold).
    index : int
        Lies between curve points ``index - 1`` and ``index``.
    amplitude, peak : ndarray, shape (n_dof,)
        Fundamental amplitudes and ``max |q(t)|`` there, m or rad.
    transmissibility : float
    converged : bool
        False when the location failed (a Newton re-solve); ``freq_hz`` is then the
        cubic-interpolation estimate (folds) or the largest curve point (peaks).
    interior : bool
        False for a peak at an end of the range (not an extremum).
    multiplier : complex or None
        For a bifurcation (``kind`` other than fold and peak): the critical Floquet
        multiplier just past it, on the unstable side (None otherwise).
    """

    kind: str
    freq_hz: float
    dof: str | None
    index: int
    amplitude: np.ndarray
    peak: np.ndarray
    transmissibility: float
    converged: bool = True
    interior: bool = True
    multiplier: complex | None = None


def _landing(f, st, amp, i: int, sgn: float):
    """``(distance, index)`` of the stable point a sweep in direction ``sgn`` lands
    on when the solution at ``i`` ends at a fold: on a stable piece of the curve
    spanning ``f[i]``, the nearest in (scaled) amplitude; None if there is none."""
    best = None
    for k in range(len(f) - 1):
        if k in (i, i - 1) or not (st[k] and st[k + 1]):
            continue
        lo, hi = sorted((f[k], f[k + 1]))
        if not lo <= f[i] <= hi or lo == hi:
            continue
        land = k + 1 if sgn * (f[k + 1] - f[k]) > 0 else k
        dist = float(np.linalg.norm(amp[land] - amp[i]))
        if land != i and (best is None or dist < best[0]):
            best = (dist, land)
    return best


@dataclass
class FrequencyResponse:
    """Steady-state frequency response computed by harmonic balance.

    Attributes
    ----------
    freq_hz : ndarray, shape (n_points,)
        Excitation frequency of each point, Hz (not monotonic through folds).
    coefficients : ndarray, shape (n_points, n_dof, 2H+1)
        Fourier coefficients of each DOF, ``[static, cos1, sin1, ..., cosH, sinH]``
        with ``q(t) = Q0 + sum_k Qck cos(k omega t) + Qsk sin(k omega t)``; m (rad for
        rotations).
    amplitude : ndarray, shape (n_points, n_dof)
        Fundamental amplitude ``hypot(Qc1, Qs1)``, m or rad.
    peak : ndarray, shape (n_points, n_dof)
        ``max |q(t)|`` over the period (``n_peak`` phases, refined by Newton on
        ``dq/dt = 0``), m or rad.
    transmissibility : ndarray, shape (n_points,)
        As defined by the system's :class:`hbm.system.Transmissibility` (fundamental
        amplitudes, thesis eq. 4.1 or 4.3), dimensionless.
    stable : ndarray of bool, shape (n_points,)
        Hill stability (True if not computed).
    turning_points : ndarray of int
        Indices of the points just past a fold (``d omega / ds`` changed sign): the
        jump frequencies are ``freq_hz[turning_points]``.
    success : bool
        Whether the curve reached ``fmax``.
    status : hbm.continuation.Status
        How the computation ended (``Status.DONE``, ``STEP_TOO_SMALL``,
        ``TOO_MANY_STEPS``, ``TURNED_BACK`` below ``fmin``, ``EVALUATION_FAILED``,
        ``NO_START``, ``RETRACED``: the branch turned back onto itself, a dead end of
        the sampled nonsmooth problem; ``NO_CONVERGENCE`` at a given frequency).
    message : str
    n_newton : int
        Newton iterations in total.
    n_steps : int
        Continuation steps tried (accepted and rejected).
    dof_names : tuple of str
    harmonics : int
    n_samples : int
        AFT samples per period (0 with closed forms).
    closed_form : bool
    floquet_max_real : ndarray, shape (n_points,)
        Largest real part of the Floquet exponents, 1/s (NaN if not computed).
    newton_per_point : ndarray of int, shape (n_points,)
    system_name : str
    turning_freq_hz : ndarray, shape (n_turning,)
        Fold (jump) frequencies, Hz: the frequency's extremum along the curve between
        the two points around each turning point, located by bisection with Newton
        re-solves to 1e-6 Hz (``folds``).
    folds, peaks : list of MarkedPoint
        The located folds (one per turning point) and each DOF's resonance peak.
    transmissibility_peak : MarkedPoint or None
        The transmissibility's maximum along the curve (``dof`` None), located like
        the DOF peaks to ``hbm.folds.FREQ_TOL_HZ`` (None if not located).
    turning_points_merged : int
        Turning points dropped as zigzags of the sampled residual (pairs that
        vanished when re-traced with more AFT samples).
    samples_per_point : ndarray of int, shape (n_points,) or (0,)
        The AFT samples each point solves the equations with: ``n_samples``, but for
        the stretches re-traced with more samples (``message`` names them); empty
        when every point uses ``n_samples``. Use :meth:`samples_of`.
    error_truncation, error_sampling : ndarray, shape (n_points,)
        Estimated errors of each point from the harmonics above H and from the N AFT
        samples, relative to the curve's peak (:mod:`hbm.error_estimate`; NaN if not
        estimated).
    error_reference : str
        How the estimates were made.
    tol_met : bool or None
        Whether the error estimate met ``HBMOptions.tol / 2`` (None: not asked).
    transmissibility_label : str
        What ``transmissibility`` is (its definition), for plots.
    bifurcations : list of MarkedPoint
        Every change of stability that is not a fold, classified from the critical
        Floquet multiplier (:mod:`hbm.bifurcation`): ``kind`` ``"period-doubling"``
        (through -1), ``"neimark-sacker"`` (a complex pair) or ``"branch-point"``
        (through +1 where the curve does not turn), located to 1e-6 Hz like the folds
        (every fold is itself the bifurcation of a multiplier through +1).
    restarts : tuple of hbm.segments.Restart
        ``(freq_hz, reason)`` of every restart (``HBMOptions.max_restarts``): the
        curve is in ``len(restarts) + 1`` segments separated by one gap row each
        (NaN values, frequency = the restart frequency); see :attr:`segments`.
    stuck : ndarray of int, shape (n_points, n_inclined)
        Per point and inclined element (thesis Ch. 5), which surfaces stick for the
        whole period (:attr:`hbm.inclined.PeriodicElement.stuck_code`): 0 both slip,
        1 the inclined surface sticks, 2 the flat surface, 3 both (0 columns without
        inclined elements). Where exactly one sticks the periodic state is a family
        and the point is one member of it (:attr:`family`).
    stuck_labels : tuple of str
        The ``<mount>_<axis>`` of each column of ``stuck``.
    """

    freq_hz: np.ndarray
    coefficients: np.ndarray
    amplitude: np.ndarray
    peak: np.ndarray
    transmissibility: np.ndarray
    stable: np.ndarray
    turning_points: np.ndarray
    success: bool
    status: Status
    message: str
    n_newton: int
    n_steps: int
    dof_names: tuple[str, ...]
    harmonics: int
    n_samples: int = 0
    closed_form: bool = False
    floquet_max_real: np.ndarray = field(default_factory=lambda: np.zeros(0))
    newton_per_point: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    system_name: str = ""
    turning_freq_hz: np.ndarray = field(default_factory=lambda: np.zeros(0))
    restarts: tuple = ()
    folds: list = field(default_factory=list)
    peaks: list = field(default_factory=list)
    transmissibility_peak: MarkedPoint | None = None
    turning_points_merged: int = 0
    samples_per_point: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    error_truncation: np.ndarray | None = None
    error_sampling: np.ndarray | None = None
    error_reference: str = ""
    tol_met: bool | None = None
    transmissibility_label: str = ""
    bifurcations: list = field(default_factory=list)
    stuck: np.ndarray | None = None
    stuck_labels: tuple = ()

    def __post_init__(self):
        if self.stuck is None:
            self.stuck = np.zeros((self.freq_hz.size, len(self.stuck_labels)), int)
        nan = np.full(self.freq_hz.size, np.nan)
        if self.error_truncation is None:
            self.error_truncation = nan.copy()
        if self.error_sampling is None:
            self.error_sampling = nan.copy()

    def set_errors(self, est) -> None:
        """Store an :class:`hbm.error_estimate.ErrorEstimate` of these points."""
        self.error_truncation = np.asarray(est.truncation, float)
        self.error_sampling = np.asarray(est.sampling, float)
        self.error_reference = est.summary()

    def error_max(self) -> float:
        """Largest estimated error (truncation + sampling) relative to peak; NaN if
        not estimated."""
        return finite_max(self.error_truncation + self.error_sampling)

    def fold_freq_at(self, i: int, j: int) -> float | None:
        """The located fold between neighbouring points i and j, Hz (None if none)."""
        k = max(i, j)
        for fo in self.folds:
            if fo.index == k:
                return fo.freq_hz
        return None

    def bifurcation_freq_at(self, i: int, j: int) -> float | None:
        """The located bifurcation between neighbouring points i and j, Hz (None if
        none)."""
        k = max(i, j)
        for b in self.bifurcations:
            if b.index == k:
                return b.freq_hz
        return None

    def transmissibility_max(self) -> tuple[float, float]:
        """``(freq_hz, transmissibility)`` of the transmissibility's peak: the
        located one (:attr:`transmissibility_peak`) if any, else the largest point
        (NaNs if none is finite). What every command prints."""
        p = self.transmissibility_peak
        if p is not None:
            return float(p.freq_hz), float(p.transmissibility)
        t = np.asarray(self.transmissibility, float)
        if not np.any(np.isfinite(t)):
            return float("nan"), float("nan")
        i = int(np.nanargmax(t))
        return float(self.freq_hz[i]), float(t[i])

    @property
    def family(self) -> np.ndarray:
        """Per point: one surface of an inclined element sticks for the whole
        period (code 1 or 2 in :attr:`stuck`), so the periodic state is a family
        (the stuck slider's position, left by the history, selects the member; the
        amplitude depends on it) and the point is the member this march reached."""
        st = np.asarray(self.stuck, int).reshape(self.freq_hz.size, -1)
        return np.any((st == 1) | (st == 2), axis=1)

    def family_bands(self) -> list[tuple[float, float]]:
        """``(fmin, fmax)`` Hz of each run of consecutive :attr:`family` points."""
        fam, out, start = self.family, [], None
        for i, on in enumerate(list(fam) + [False]):
            if on and start is None:
                start = i
            elif not on and start is not None:
                f = self.freq_hz[start:i]
                out.append((float(np.nanmin(f)), float(np.nanmax(f))))
                start = None
        return out

    def family_summary(self) -> str:
        """One sentence on the family bands ("" without inclined elements)."""
        if not self.stuck_labels:
            return ""
        bands = self.family_bands()
        if not bands:
            return ("no band where one surface of the inclined element sticks for the "
                    "whole period: the periodic states here are unique in amplitude")
        where = ", ".join(f"{a:.4g}-{b:.4g} Hz" if b > a else f"{a:.4g} Hz"
                          for a, b in bands)
        return (f"one surface of the inclined element sticks for the whole period at "
                f"{where} (column family = 1): there the periodic state is a family "
                f"and each point is the member this continuation reached, not the only "
                f"one (a start from elsewhere settles on another amplitude)")

    @property
    def n_points(self) -> int:
        return int(self.freq_hz.size)

    def samples_of(self, i: int) -> int:
        """The AFT samples point ``i`` solves the equations with."""
        if len(self.samples_per_point):
            return int(self.samples_per_point[i])
        return self.n_samples

    @property
    def segments(self) -> list[slice]:
        """Index ranges of the segments (one without restarts), gap rows excluded."""
        out, start = [], 0
        gaps = np.flatnonzero(np.isnan(self.amplitude).all(axis=1)) \
            if self.restarts else []
        for g in gaps:
            out.append(slice(start, int(g)))
            start = int(g) + 1
        out.append(slice(start, self.n_points))
        return out

    def sweep_jumps(self, direction: str = "up", min_change: float = 0.01
                    ) -> list[tuple[float, int, int]]:
        """Where a slow stepped sweep along this curve would jump.

        A quasi-static sweep follows the stable solution it is on in the direction of
        the sweep; where that solution ends at a fold it jumps to the stable solution
        on another part of the curve at that frequency, the one nearest in amplitude
        (each DOF relative to its largest amplitude on the curve), and goes on from
        there. Jumps smaller than
        ``min_change`` in that measure (the closely spaced fold pairs of a sampled
        nonsmooth problem) are followed silently.

        Parameters
        ----------
        direction : ``"up"`` (from the first point) or ``"down"`` (from the last).
        min_change : float
            Smallest amplitude change reported as a jump.

        Returns
        -------
        list of ``(freq_hz, from_index, to_index)``
            ``freq_hz`` is the located fold frequency (``folds``) where the sweep
            jumps at a fold, the located bifurcation (``bifurcations``) where it
            leaves the curve at one, else the frequency of the last point before.
            ``to_index`` is -1 where the solution loses stability away from a fold
            (a bifurcation, e.g. symmetry breaking, onto a solution the curve does not
            contain): the sweep leaves the curve there and the walk ends. The walk
            also ends where no stable solution is found beyond a fold.
        """
        if direction not in ("up", "down"):
            raise ValueError(f"`direction` must be 'up' or 'down', got {direction!r}")
        n = self.n_points
        if n < 2:
            return []
        f = self.freq_hz
        st = np.asarray(self.stable, dtype=bool)
        scale = np.nanmax(self.amplitude, axis=0)
        amp = self.amplitude / np.where(scale > 0, scale, 1.0)
        sgn = 1.0 if direction == "up" else -1.0

        def heading(k):
            """Index step along which the frequency moves with the sweep at k."""
            for d in (1, -1):
                if 0 <= k + d < n and sgn * (f[k + d] - f[k]) > 0:
                    return d
            return 0

        i = 0 if direction == "up" else n - 1
        d = heading(i)
        jumps, seen = [], set()
        while d and (i, d) not in seen:
            seen.add((i, d))
            j = i + d
            if 0 <= j < n and st[j] and sgn * (f[j] - f[i]) >= 0:
                i = j
                continue
            if not 0 <= j < n:
                break  # the end of the computed range
            near_fold = any(abs(int(t) - j) <= 2 for t in self.turning_points)
            if sgn * (f[j] - f[i]) >= 0 and not near_fold:
                # stability lost away from a fold: a bifurcation onto a solution
                # this curve does not contain; the sweep leaves the curve
                f_bif = self.bifurcation_freq_at(i, j)
                jumps.append((float(f[i]) if f_bif is None else f_bif, i, -1))
                break
            # a fold: the solution ends here; land on another stable part
            best = _landing(f, st, amp, i, sgn)
            if best is None:
                break
            if best[0] >= min_change:
                f_fold = self.fold_freq_at(i, j)
                jumps.append((float(f[i]) if f_fold is None else f_fold, i, best[1]))
            i = best[1]
            d = heading(i)
        return jumps

    def columns(self) -> list[str]:
        """CSV column names."""
        cols = ["freq_hz"]
        for d in self.dof_names:
            cols += [f"{d}_amp", f"{d}_peak"]
        cols += ["transmissibility", "stable", "err_truncation", "err_sampling"]
        return cols + self._stuck_columns()

    def _stuck_columns(self) -> list[str]:
        """``<label>_stuck`` per inclined element and ``family`` (none without)."""
        if not self.stuck_labels:
            return []
        return [f"{a}_stuck" for a in self.stuck_labels] + ["family"]

    def table(self) -> np.ndarray:
        """The CSV table as an array, shape (n_points, 2 n_dof + 5), plus the
        columns of :attr:`stuck` and :attr:`family` with inclined elements."""
        parts = [self.freq_hz[:, None]]
        for i in range(len(self.dof_names)):
            parts += [self.amplitude[:, i:i + 1], self.peak[:, i:i + 1]]
        parts += [self.transmissibility[:, None], self.stable[:, None].astype(float),
                  self.error_truncation[:, None], self.error_sampling[:, None]]
        if self.stuck_labels:
            parts += [np.asarray(self.stuck, float).reshape(self.n_points, -1),
                      self.family[:, None].astype(float)]
        return np.hstack(parts)

    def events_path(self, path: str | os.PathLike) -> str:
        """The sidecar of the CSV ``path``: ``<stem>_events.csv`` beside it."""
        root, _ = os.path.splitext(os.fspath(path))
        return root + "_events.csv"

    def events_to_csv(self, path: str | os.PathLike) -> None:
        """Write the located folds, bifurcations and peaks: ``kind``, ``dof``,
        ``freq_hz``, ``after_row``, ``converged``, ``<dof>_amp``, ``<dof>_peak``, ...,
        ``transmissibility``; ``after_row`` is the 0-based data row of the curve CSV
        the event follows.
        The transmissibility's peak is the row with ``dof`` = ``transmissibility``;
        the bifurcations (:attr:`bifurcations`) are the rows of kind
        ``period-doubling``, ``neimark-sacker`` and ``branch-point``."""
        cols = ["kind", "dof", "freq_hz", "after_row", "converged"]
        for d in self.dof_names:
            cols += [f"{d}_amp", f"{d}_peak"]
        cols.append("transmissibility")
        from drymount.hbm.io import atomic_path
        with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(f"# drymount HBM {self.system_name}: folds (extremum of the "
                     f"frequency along the curve; Floquet multiplier +1), the "
                     f"other changes of stability (period-doubling: multiplier -1; "
                     f"neimark-sacker: a complex pair; branch-point: +1 without a "
                     f"fold), each DOF's resonance peak "
                     f"(extremum of its fundamental amplitude) and the "
                     f"transmissibility's (dof = transmissibility), located to "
                     f"1e-6 Hz; "
                     f"amplitudes m or rad\n")
            fh.write(",".join(cols) + "\n")
            t_peak = [] if self.transmissibility_peak is None else [
                self.transmissibility_peak]
            events = (list(self.folds) + list(self.bifurcations) + list(self.peaks)
                      + t_peak)
            for e in events:
                dof = e.dof or ("transmissibility" if e is self.transmissibility_peak
                                else "")
                vals = [e.kind, dof, f"{e.freq_hz:.10f}", str(e.index - 1),
                        str(int(e.converged))]
                for a, p in zip(e.amplitude, e.peak, strict=True):
                    vals += [f"{a:.10g}", f"{p:.10g}"]
                vals.append(f"{e.transmissibility:.10g}")
                fh.write(",".join(vals) + "\n")

    def to_csv(self, path: str | os.PathLike) -> None:
        """Write ``freq_hz``, ``<dof>_amp``, ``<dof>_peak``, ..., ``transmissibility``,
        ``stable``, ``err_truncation``, ``err_sampling`` (the estimated errors
        relative to the peak, :mod:`hbm.error_estimate`; NaN where not estimated),
        and with inclined elements ``<mount>_<axis>_stuck``, ..., ``family``
        (:attr:`stuck`, :attr:`family`; 0/1/2/3 and 0/1).

        The first line is a ``# `` comment with units and provenance; ``stable`` is 1
        or 0; amplitudes in m (rad for rotations).
        """
        meth = "closed forms" if self.closed_form else f"AFT N={self.n_samples}"
        comment = (f"# drymount HBM {self.system_name}: H={self.harmonics} ({meth}); "
                   f"success={self.success} ({self.message}); amplitudes m or rad, "
                   f"fundamental (_amp) and max over the period (_peak); err_* "
                   f"estimated error relative to peak; stable 1/0; "
                   f"folds at Hz {np.round(self.turning_freq_hz, 6).tolist()}")
        if self.stuck_labels:
            comment += ("; *_stuck: inclined element's surfaces stuck the whole "
                        "period (0 none, 1 inclined, 2 flat, 3 both); family 1: one "
                        "surface sticks, the point is one member of a family of "
                        "periodic states (history-dependent)")
        k = len(self._stuck_columns())
        from drymount.hbm.io import atomic_path
        with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(comment + "\n")
            fh.write(",".join(self.columns()) + "\n")
            for full in self.table():
                row, extra = full[:full.size - k], full[full.size - k:]
                vals = [f"{v:.10g}" for v in row[:-3]] + [str(int(row[-3]))]
                vals += [f"{v:.3g}" for v in row[-2:]]
                vals += [str(int(v)) for v in extra]
                fh.write(",".join(vals) + "\n")

    def _plot_jumps(self, ax, y):
        for direction, color in (("up", "C1"), ("down", "C2")):
            events = self.sweep_jumps(direction)
            for f, i, k in events:
                if k < 0:
                    ax.plot([f], [y[i]], "x", color=color, ms=8)
                else:
                    ax.annotate("", xy=(f, y[k]), xytext=(f, y[i]),
                                arrowprops=dict(arrowstyle="->", ls=":", color=color))
            kinds = [("jump", any(k >= 0 for *_, k in events)),
                     ("x leaves curve", any(k < 0 for *_, k in events))]
            if events:
                ax.plot([], [], ":", color=color, label=f"sweep {direction}: "
                        + " / ".join(name for name, present in kinds if present))

    def plot(self, path: str | os.PathLike | None = None, ax=None,
             quantity: str = "transmissibility", dof: str | None = None,
             logy: bool = True, label: str | None = None, jumps: bool = True,
             logx: bool = False, **kwargs):
        """Plot the curve; unstable parts dashed, located folds marked.

        Without ``ax`` a whole figure is made (:func:`hbm.plot.plot_figure`): title
        with the system and H/N, the transmissibility with its definition and, for
        several DOFs, one panel per DOF amplitude; returns its first Axes. With
        ``ax`` one ``quantity`` is drawn there (:func:`hbm.plot.plot_curve`).

        Parameters
        ----------
        path : path, optional
            Save the figure there (PNG, ...).
        ax : matplotlib Axes, optional
        quantity : ``"transmissibility"``, ``"amplitude"`` or ``"peak"``
        dof : str, optional
            DOF name for amplitude/peak (default: the first).
        logy, logx : bool
            Logarithmic amplitude and frequency axes.
        label : str, optional
        jumps : bool
            Draw where slow sweeps up and down would jump (:meth:`sweep_jumps`):
            dotted arrows; a cross where a sweep leaves the curve.
        **kwargs
            Passed to ``Axes.plot``.

        Returns
        -------
        matplotlib Axes
        """
        from drymount.hbm.plot import plot_curve, plot_figure

        if ax is None and quantity == "transmissibility" and label is None \
                and not kwargs:
            return plot_figure(self, path, logx=logx, logy=logy).axes[0]
        if ax is None:
            from matplotlib.figure import Figure
            ax = Figure(figsize=(7, 4.5), layout="constrained").add_subplot()
        plot_curve(self, ax, quantity, dof, logy=logy, label=label, jumps=jumps,
                   logx=logx, **kwargs)
        if path is not None:
            ax.figure.savefig(path, dpi=120)
        return ax
