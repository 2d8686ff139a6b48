"""Stepped-sine sweeps: steady states at a list of frequencies, each started from the
previous one, as on a test rig.

A sweep keeps one :class:`vehicle.master.Master` alive: with the ``fmu`` backend the
mount instances are instantiated once and keep their slider states from frequency to
frequency (no re-instantiation per point). Each frequency starts from the previous
steady state (DOFs, rates and sliders) with the excitation phase restarting at zero,
which is continuous because every steady-state run ends after a whole number of
periods. On a branch that folds (hardening cubic spring, thesis Fig. 3.5/3.7) the
response therefore stays on the branch it is on until the branch ends, and jumps there:
an up sweep and a down sweep jump at different frequencies.

The first frequency starts from the linearised steady response (``linear_start``),
which shortens the transient; a down sweep of a hardening system thus starts on the
low branch, as a rig would.

Parallel sweeps (``workers > 1``): the frequency list (in sweep order) is split into
``workers`` contiguous chunks, run in separate processes (``ProcessPoolExecutor``
with the ``spawn`` context; each process builds its own backend/FMU instances). A
chunk other than the first has no previous steady state: it starts with a *warm-up*,
the ``warmup`` frequencies that precede it in the sweep order (default 3) run from the
linearised start with a loose tolerance (``WARMUP_RTOL`` = 1e-3) and discarded, so it
enters its first frequency from a neighbouring steady state. Each chunk pays a process
start and its warm-up: parallel sweeps pay off for long frequency lists on idle
cores. Inside a bistable band this is not the same history as a serial sweep
(a chunk that starts past a jump cannot know the branch the serial sweep was on): use
``workers=1`` to study jumps and hysteresis.

Results: :class:`SweepResult` (``to_csv`` with the columns of ``hbm``'s CSV minus
``stable``; ``plot`` with an optional HBM overlay).
"""

from __future__ import annotations

import multiprocessing
import sys
import time as _time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from .backends import backend_name
from .master import Master
from .results import atomic_path, dof_unit, write_csv
from .steady import (
    DEFAULT_MAX_PERIODS,
    DEFAULT_MIN_PERIODS,
    DEFAULT_RTOL,
    fourier_coefficients,
    run_steady,
)

__all__ = ["sweep", "SweepResult", "SweepPoint", "DEFAULT_WARMUP"]

#: Warm-up frequencies run (and discarded) before a parallel chunk.
DEFAULT_WARMUP = 3
#: Harmonics kept in ``SweepResult.fourier`` (a start for HBM on the same branch).
FOURIER_HARMONICS = 15
#: Tolerance of the warm-up runs (they only bring the state near the branch).
WARMUP_RTOL = 1e-3


@dataclass
class SweepResult:
    """Stepped-sine sweep (co-simulation).

    Attributes
    ----------
    freq_hz : ndarray, shape (n_points,)
        Frequencies in the order they were run (ascending for ``up``), Hz.
    amplitude : ndarray, shape (n_points, n_dof)
        Fundamental amplitude of each DOF, m or rad.
    peak : ndarray, shape (n_points, n_dof)
        Max |q| over the last period, m or rad.
    transmissibility : ndarray, shape (n_points,)
        As defined by ``system.transmissibility`` (dimensionless).
    converged : ndarray of bool, shape (n_points,)
    n_periods : ndarray of int, shape (n_points,)
        Periods run at each frequency.
    friction_energy : ndarray, shape (n_points,)
        Friction energy dissipated per cycle, J.
    dof_names : tuple of str
    phasor : ndarray, complex, shape (n_points, n_dof)
        Fundamental of each DOF, ``q(t) ~ Im(phasor exp(i omega t))``, m or rad.
    mean : ndarray, shape (n_points, n_dof)
        Mean of each DOF over the last period (the static term), m or rad.
    fourier : ndarray, shape (n_points, n_dof, 2K+1)
        Fourier coefficients of each DOF over the last period, harmonic-balance
        layout ``[static, cos1, sin1, ...]`` up to ``K = FOURIER_HARMONICS``.
    sliders : ndarray, shape (n_points, n_mounts, 3)
        Slider positions at the end of each steady state, m (axes in ``AXES`` order).
    direction : str
        ``"up"`` or ``"down"``.
    backend : str
    system_name : str
    transmissibility_kind : str
        ``"force"`` or ``"displacement"``.
    elapsed : float
        Wall-clock seconds of the sweep.
    workers : int
    """

    freq_hz: np.ndarray
    amplitude: np.ndarray
    peak: np.ndarray
    transmissibility: np.ndarray
    converged: np.ndarray
    n_periods: np.ndarray
    friction_energy: np.ndarray
    dof_names: tuple[str, ...]
    direction: str = "up"
    backend: str = "inproc"
    system_name: str = ""
    transmissibility_kind: str = ""
    elapsed: float = 0.0
    workers: int = 1
    notes: dict = field(default_factory=dict)
    phasor: np.ndarray | None = None
    sliders: np.ndarray | None = None
    mean: np.ndarray | None = None
    fourier: np.ndarray | None = None

    @property
    def success(self) -> bool:
        """Every frequency reached its steady state."""
        return bool(np.all(self.converged))

    def to_csv(self, path):
        """Write ``freq_hz``, ``<dof>_amp``, ``<dof>_peak`` per DOF,
        ``transmissibility``, ``converged`` (first line a ``# `` comment with units)."""
        units = ", ".join(f"{d} [{dof_unit(d)}]" for d in self.dof_names)
        comment = (f"drymount stepped-sine sweep ({self.direction}, {self.backend} "
                   f"backend) of {self.system_name}; units: freq_hz [Hz], {units}, "
                   f"transmissibility [-] ({self.transmissibility_kind}), "
                   "converged [0/1]")
        header = ["freq_hz"]
        cols = [self.freq_hz]
        for i, d in enumerate(self.dof_names):
            header += [f"{d}_amp", f"{d}_peak"]
            cols += [self.amplitude[:, i], self.peak[:, i]]
        header += ["transmissibility", "converged"]
        cols += [self.transmissibility, self.converged.astype(float)]
        return write_csv(path, header, cols, comment)

    def plot(self, path=None, hbm=None, ax=None):
        """Transmissibility against frequency (log axis); overlays an HBM
        ``FrequencyResponse`` when ``hbm`` is given (solid stable, dashed unstable).
        Saved atomically to ``path`` if given. Returns the matplotlib Figure."""
        from matplotlib.figure import Figure

        if ax is None:
            fig = Figure(figsize=(7.5, 4.5))
            ax = fig.add_subplot()
        else:
            fig = ax.figure
        if hbm is not None:
            f = np.asarray(hbm.freq_hz, dtype=float)
            tr = np.asarray(hbm.transmissibility, dtype=float)
            stable = np.asarray(getattr(hbm, "stable", np.ones(f.shape, bool)),
                                dtype=bool)
            ax.plot(f, np.where(stable, tr, np.nan), "-", color="C0",
                    label="harmonic balance")
            if not stable.all():
                ax.plot(f, np.where(~stable, tr, np.nan), "--", color="C0",
                        label="harmonic balance, unstable")
        ok = self.converged.astype(bool)
        ax.plot(self.freq_hz[ok], self.transmissibility[ok], "o", mfc="none",
                color="C3", label=f"co-simulation, sweep {self.direction}")
        if not ok.all():
            ax.plot(self.freq_hz[~ok], self.transmissibility[~ok], "x", color="C3",
                    label="co-simulation, not converged")
        ax.set_yscale("log")
        ax.set_xlabel("frequency [Hz]")
        kind = self.transmissibility_kind or "transmissibility"
        ax.set_ylabel(f"{kind} transmissibility [-]")
        ax.set_title(self.system_name)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        if path is not None:
            with atomic_path(path) as tmp:
                fig.savefig(tmp, dpi=120)
        return fig


@dataclass
class SweepPoint:
    """What a sweep keeps of the steady state at one frequency (picklable: parallel
    chunks send these back)."""

    freq_hz: float
    amplitude: np.ndarray
    peak: np.ndarray
    transmissibility: float
    converged: bool
    n_periods: int
    friction_energy: float
    phasor: np.ndarray
    sliders: np.ndarray
    mean: np.ndarray
    fourier: np.ndarray

    @classmethod
    def of(cls, ss) -> SweepPoint:
        return cls(ss.freq_hz, ss.amplitude, ss.peak, ss.transmissibility,
                   ss.converged, ss.n_periods, ss.friction_energy, ss.phasor,
                   np.asarray(ss.sliders, dtype=float), ss.mean,
                   fourier_coefficients(ss.q, FOURIER_HARMONICS))


def _run_chunk(system, freqs, warmup_freqs, backend, fmu_path, options, points,
               report=None):
    """Run one contiguous chunk in this process, appending a :class:`SweepPoint` to
    ``points`` for each frequency (so the caller keeps them when the run is stopped)
    and calling ``report(index, point)`` after each."""
    warm = dict(options, rtol=max(options["rtol"], WARMUP_RTOL))
    with Master(system, backend, fmu_path=fmu_path) as m:
        first = True
        for f in warmup_freqs:
            run_steady(m, f, start="linear" if first else "continue", **warm)
            first = False
        for f in freqs:
            ss = run_steady(m, f, start="linear" if first else "continue", **options)
            first = False
            points.append(SweepPoint.of(ss))
            if report is not None:
                report(len(points) - 1, points[-1])
    return points


#: The queue a worker process sends its points through (set by ``_init_worker``).
_WORKER_QUEUE = None
#: Seconds between a worker's checks that its parent is alive.
PARENT_POLL_S = 0.5


def _init_worker(queue) -> None:
    """Worker process set-up: points go to ``queue``; Ctrl-C is the parent's to
    handle (it stops the workers); the worker exits when its parent dies."""
    import os
    import signal
    import threading

    global _WORKER_QUEUE
    _WORKER_QUEUE = queue
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = os.getppid()

    def watch():
        while os.getppid() == parent:
            _time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="parent-watch").start()


def _worker_chunk(chunk, system, freqs, warmup_freqs, backend, fmu_path, options):
    """A chunk in a worker process: each point is sent as ``(chunk, index, point)``."""
    _run_chunk(system, freqs, warmup_freqs, backend, fmu_path, options, [],
               report=lambda i, point: _WORKER_QUEUE.put((chunk, i, point)))
    return len(freqs)


def _stop_pool(pool) -> None:
    """Stop a process pool now: cancel what has not started, terminate the workers
    (a running chunk can take minutes) and reap them."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    for p in procs:
        p.join(timeout=2.0)
        if p.is_alive():
            p.kill()
            p.join(timeout=1.0)


def sweep(system, freqs_hz, *, direction: str = "up", backend: str = "inproc",
          workers: int = 1, progress: bool = True, fmu_path=None,
          steps_per_period: int | None = None, rtol: float = DEFAULT_RTOL,
          min_periods: int = DEFAULT_MIN_PERIODS,
          max_periods: int = DEFAULT_MAX_PERIODS,
          warmup: int = DEFAULT_WARMUP, batch: bool = False, refine: int = 0,
          hbm=None) -> SweepResult:
    """Stepped-sine sweep of ``system`` under its harmonic excitation.

    Parameters
    ----------
    system : hbm.system.System
    freqs_hz : array_like, shape (n_points,)
        Frequencies, Hz (> 0); run ascending for ``up``, descending for
        ``down``.
    direction : {"up", "down"}
    backend : {"inproc", "fmu"}
    workers : int
        Processes; > 1 splits the list into contiguous chunks with a warm-up each
        (see the module docstring).
    progress : bool
        tqdm progress bar on stderr.
    fmu_path : path-like, optional
        FMU of the ``fmu`` backend (default: ``fmu_build.ensure_fmu()``).
    steps_per_period, rtol, min_periods, max_periods
        Steady-state options (:func:`vehicle.steady.steady_state`).
    warmup : int
        Warm-up frequencies of each parallel chunk after the first.
    batch : bool
        Step all frequencies at once as one array computation
        (:mod:`vehicle.batch`; ``inproc`` backend, one process): each frequency
        starts from the linearised response instead of the previous steady state.
    refine : int
        Extra frequencies to add where they matter (:mod:`vehicle.refine`): at the
        peak, where the response changes fastest, and first at the peak and folds
        of ``hbm``. They run after the grid, each group entered from the grid
        frequency before it (a warm-up as for a parallel chunk); the result lists
        all frequencies in sweep order.
    hbm : object with ``freq_hz`` and ``transmissibility``, optional
        A harmonic-balance curve (``hbm.FrequencyResponse``) whose peak and folds
        ``refine`` visits first.

    Returns
    -------
    SweepResult
    """
    f, backend = _sweep_arguments(freqs_hz, direction, backend, workers, warmup,
                                  batch, refine)
    options = dict(steps_per_period=steps_per_period, rtol=rtol,
                   min_periods=min_periods, max_periods=max_periods)
    if backend == "fmu" and fmu_path is None:
        from drymount.fmu_build import ensure_fmu
        fmu_path = ensure_fmu()
    from tqdm import tqdm

    t0 = _time.perf_counter()
    workers = int(min(workers, f.size))
    bar = tqdm(total=f.size, desc=f"sweep {direction} ({backend})", unit="freq",
               file=sys.stderr, disable=not progress, leave=False)
    points, received, added = [], {}, []
    try:
        if batch:
            from .batch import steady_states
            steady_states(system, f, progress=bar, **options,
                          report=lambda i, ss: received.__setitem__(
                              i, SweepPoint.of(ss)))
            points = [received[k] for k in sorted(received)]
        elif workers == 1:
            _run_chunk(system, f.tolist(), [], backend, fmu_path, options, points,
                       report=lambda i, point: bar.update(1))
        else:
            _run_parallel(system, f, workers, warmup, backend, fmu_path, options, bar,
                          received)
            points = [received[k] for k in sorted(received)]
        if refine:
            run = dict(system=system, backend=backend, fmu_path=fmu_path,
                       options=options, batch=batch, bar=bar)
            points, added = _refine(points, refine, hbm, direction, run)
    except BaseException as exc:
        # Stopped (Ctrl-C, SIGTERM, an FMU error): hand the caller what was
        # computed, in sweep order, on the exception.
        points = points or [received[k] for k in sorted(received)]
        exc.partial_result = _result(
            system, points, direction, backend, _time.perf_counter() - t0, workers,
            notes={"rtol": rtol, "warmup": warmup if workers > 1 else 0,
                   "steps_per_period": steps_per_period, "stopped": repr(exc)})
        raise
    finally:
        bar.close()
    return _result(system, points, direction, backend, _time.perf_counter() - t0,
                   workers, notes={"rtol": rtol, "warmup": warmup if workers > 1 else 0,
                                   "steps_per_period": steps_per_period,
                                   "batch": bool(batch), "refined": added})


def _sweep_arguments(freqs_hz, direction, backend, workers, warmup, batch, refine):
    """:func:`sweep`'s arguments checked: the frequencies in sweep order and the
    backend's canonical name."""
    f = np.asarray(freqs_hz, dtype=float).reshape(-1)
    if f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ValueError(f"`freqs_hz` must be a non-empty list of finite frequencies "
                         f"> 0, got {np.asarray(freqs_hz).tolist()}")
    if direction not in ("up", "down"):
        raise ValueError(f"`direction` must be 'up' or 'down', got {direction!r}")
    backend = backend_name(backend)
    if backend not in ("inproc", "fmu"):
        raise ValueError(f"`backend` must be 'inproc' or 'fmu', got {backend!r}")
    if not (isinstance(workers, (int, np.integer)) and workers >= 1):
        raise ValueError(f"`workers` must be an integer >= 1, got {workers!r}")
    if not (isinstance(warmup, (int, np.integer)) and warmup >= 0):
        raise ValueError(f"`warmup` must be an integer >= 0, got {warmup!r}")
    if batch and (backend != "inproc" or workers != 1):
        raise ValueError(f"`batch` steps the in-process law in one process: it needs "
                         f"backend 'inproc' and workers 1, got backend {backend!r}, "
                         f"workers {workers!r}")
    if not (isinstance(refine, (int, np.integer)) and refine >= 0):
        raise ValueError(f"`refine` must be an integer >= 0, got {refine!r}")
    f = np.sort(f) if direction == "up" else np.sort(f)[::-1]
    return f, backend


def _refine(points, count, hbm, direction, run):
    """Add up to ``count`` frequencies to the sweep ``points`` (vehicle.refine), in
    rounds; returns the points in sweep order and the frequencies added."""
    from .refine import MIN_STEP_FRACTION, PER_ROUND, hbm_targets, refine_targets

    freqs = [p.freq_hz for p in points]
    lo, hi = min(freqs), max(freqs)
    min_step = MIN_STEP_FRACTION * max(hi - lo, hi)
    first = [] if hbm is None else hbm_targets(hbm.freq_hz, hbm.transmissibility,
                                               lo, hi)
    added = []
    while len(added) < count:
        new = refine_targets([p.freq_hz for p in points],
                             [p.transmissibility for p in points],
                             min(PER_ROUND, count - len(added)), min_step=min_step,
                             first=first)
        if not new:
            break
        run["bar"].total += len(new)
        points = points + _run_extra(points, sorted(new, reverse=direction == "down"),
                                     direction, **run)
        added += new
    points.sort(key=lambda p: p.freq_hz, reverse=direction == "down")
    return points, added


def _run_extra(points, new, direction, *, system, backend, fmu_path, options, batch,
               bar):
    """Steady states at the frequencies ``new`` (in sweep order): batched, or one
    chunk entered from the computed frequency before the first of them."""
    if batch:
        from .batch import steady_states
        return [SweepPoint.of(ss) for ss in steady_states(system, new, progress=bar,
                                                          **options)]
    sign = 1.0 if direction == "up" else -1.0
    before = [p.freq_hz for p in points if sign * (p.freq_hz - new[0]) < 0]
    warm = [max(before, key=lambda x: sign * x)] if before else []
    return _run_chunk(system, new, warm, backend, fmu_path, options, [],
                      report=lambda i, point: bar.update(1))


def _run_parallel(system, f, workers, warmup, backend, fmu_path, options, bar,
                  received):
    """Contiguous chunks of ``f`` in ``workers`` spawned processes, each after a
    warm-up on the ``warmup`` frequencies before it; the points arrive in
    ``received`` (``(chunk, index) -> SweepPoint``) as they are computed."""
    import queue as _queue

    bounds = np.linspace(0, f.size, workers + 1).round().astype(int)
    ctx = multiprocessing.get_context("spawn")
    points_q = ctx.Queue()
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                               initializer=_init_worker, initargs=(points_q,))
    try:
        futures = []
        for c in range(workers):
            a, b = bounds[c], bounds[c + 1]
            wu = f[max(0, a - warmup):a].tolist()
            futures.append(pool.submit(_worker_chunk, c, system, f[a:b].tolist(), wu,
                                       backend, fmu_path, options))
        idle_since = None
        while len(received) < f.size:
            try:
                c, i, point = points_q.get(timeout=0.2)
            except _queue.Empty:
                for fu in futures:
                    if fu.done() and fu.exception() is not None:
                        raise fu.exception()
                if all(fu.done() for fu in futures):
                    idle_since = idle_since or _time.monotonic()
                    if _time.monotonic() - idle_since > 30.0:
                        raise RuntimeError("the sweep workers finished but "
                                           f"{f.size - len(received)} points never "
                                           "arrived") from None
                continue
            received[(c, i)] = point
            bar.update(1)
    finally:
        _stop_pool(pool)
        points_q.close()
        points_q.cancel_join_thread()


def _result(system, points, direction, backend, elapsed, workers, notes
            ) -> SweepResult:
    """Stack the points into a :class:`SweepResult`."""
    n, k = system.n_dof, len(points)

    def stack(name, dtype=float, shape=None):
        out = np.array([getattr(p, name) for p in points], dtype=dtype)
        return out if shape is None else out.reshape(shape)

    return SweepResult(
        freq_hz=stack("freq_hz"), amplitude=stack("amplitude", shape=(k, n)),
        peak=stack("peak", shape=(k, n)), transmissibility=stack("transmissibility"),
        converged=stack("converged", bool), n_periods=stack("n_periods", int),
        friction_energy=stack("friction_energy"),
        phasor=stack("phasor", complex, (k, n)),
        sliders=stack("sliders", shape=(k, len(system.elements), 3)),
        mean=stack("mean", shape=(k, n)), fourier=stack("fourier"),
        dof_names=tuple(system.dof_names), direction=direction, backend=backend,
        system_name=system.name, transmissibility_kind=system.transmissibility.kind,
        elapsed=elapsed, workers=workers, notes=notes)
