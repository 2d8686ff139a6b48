"""Batched in-process time stepping: many frequency points stepped as one array
computation.

The in-process backend (:class:`vehicle.backends.InProcessBackend`) calls the scalar
mount law once per active axis and step, so a stepped sweep pays the Python cost of a
step once per frequency. Here the steady states of B frequencies run side by side: one
:class:`vehicle.master.Master` per frequency keeps its own row buffer, step size,
inputs and bookkeeping, but the buffers are views into one array ``(B, N + 1, width)``
and each step is

- the mount law of every axis of every frequency at once (:class:`VectorLaw`, a NumPy
  port of :func:`fmu_src.mount_law.axis_force`, tested equal to it on random
  trajectories to 1e-12; it performs the same floating-point operations, so it agrees
  bit for bit except for the friction-energy sum over the axes of a mount). A
  friction element whose fast form (``AxisParameters.fast_form``) has no vector port
  here is stepped by its own scalar step, column by column (the per-frequency
  backend's operations: equal bit for bit, at the per-frequency cost);
- one batched matrix-vector product ``rec[:, k+1] = W_b @ rec[:, k]``.

Frequencies run in lock step, so a batch holds frequencies with the same number of
steps per period (:func:`steady_states` groups them); a frequency that has converged
leaves the batch (the others go on). Each frequency runs exactly the periods of
:func:`vehicle.steady.run_steady` from the same start, so the results equal those of
one :func:`vehicle.steady.steady_state` per frequency (``start="linear"``) up to
round-off (the batched product sums in another order than ``np.dot``).

A batched *sweep* (:func:`vehicle.sweep.sweep` with ``batch=True``) therefore starts
every frequency from the linearised response instead of from the previous frequency's
steady state: outside bistable bands both reach the same steady state (to the
steady-state tolerance ``rtol``); inside one (hardening springs, folds) the batched
sweep does not follow a branch, like a parallel chunk. Use the serial sweep to study
jumps and hysteresis.
"""

from __future__ import annotations

import time as _time
from collections import defaultdict

import numpy as np

from drymount.fmu_src.mount_law import AxisParameters, axis_force

from .master import Master
from .steady import (
    DEFAULT_MAX_PERIODS,
    DEFAULT_MIN_PERIODS,
    DEFAULT_RTOL,
    SteadyState,
    _analyse,
    _begin,
    _period_change,
    check_convergence_settings,
)

__all__ = ["VectorLaw", "LawStep", "steady_states", "BATCH_SIZE"]

#: Frequencies stepped together at most (larger batches gain little per point).
BATCH_SIZE = 64


def _linear(u, a):
    return a["k1"] * u


def _cubic(u, a):
    return a["k1"] * u + a["kc"] * u * u * u


def _knees(u, a, dneg):
    # u - clip(u, -dneg, d) is exactly u - d above the knee, u + dneg below and 0
    # between, so this is the scalar law's k1 u + (k2 - k1)(u -+ delta) or k1 u
    # (np.minimum/np.maximum: np.clip's Python wrapper costs several us a call)
    excess = u - np.minimum(np.maximum(u, -dneg), a["delta"])
    return a["k1"] * u + a["dk"] * excess


def _piecewise(u, a):
    return _knees(u, a, a["delta"])


def _piecewise_asym(u, a):
    return _knees(u, a, a["delta_neg"])


#: Vectorised elastic forces, by law name (the scalar ones: fmu_src.mount_law).
VECTOR_ELASTIC = {"linear": _linear, "cubic": _cubic, "piecewise": _piecewise,
                  "piecewise_asym": _piecewise_asym}
#: The friction fast forms (``AxisParameters.fast_form``) :class:`VectorLaw` ports:
#: the symmetric return map of one slider (kf, Fs = mu n0).
VECTOR_FRICTION = ("symmetric_slider",)


def _vectorised(p) -> bool:
    """Whether :class:`VectorLaw` computes the friction of axis ``p`` itself (an
    axis with Maxwell branches or the hydraulic fluid path is stepped by the scalar
    law, whose state holds them)."""
    if p.has_branches:
        return False
    return not p.friction or p.fast_form in VECTOR_FRICTION


class LawStep:
    """Outputs of :meth:`VectorLaw.step`, arrays of shape (B, m): ``force``,
    ``friction_force``, ``w_new``, ``dissipated`` (as :class:`fmu_src.mount_law.
    AxisForce`, without the tangent)."""

    __slots__ = ("force", "friction_force", "w_new", "dissipated")

    def __init__(self, force, friction_force, w_new, dissipated):
        self.force = force
        self.friction_force = friction_force
        self.w_new = w_new
        self.dissipated = dissipated


class VectorLaw:
    """The mount law of m axes, vectorised over a leading batch axis.

    ``axes`` are the :class:`AxisParameters` of the columns. :meth:`step` takes
    deflections ``u``, rates ``v`` and committed sliders ``w`` of shape (B, m) and
    returns what :func:`fmu_src.mount_law.axis_force` returns per column, with the
    same floating-point operations in the same order. The columns listed in
    :attr:`generic` carry a friction element without a vector port: here they get
    their elastic and viscous force only (their friction and state are stepped by
    :meth:`generic_step`, one scalar step per entry).
    """

    def __init__(self, axes):
        axes = list(axes)
        bad = [i for i, p in enumerate(axes) if not isinstance(p, AxisParameters)]
        if bad:
            raise TypeError(f"`axes` must be AxisParameters, entries {bad} are not")
        #: columns whose friction element is stepped by its scalar step
        self.generic = [i for i, p in enumerate(axes) if not _vectorised(p)]
        self.axes = axes
        unknown = sorted({p.law for p in axes} - set(VECTOR_ELASTIC))
        if unknown:
            raise ValueError(f"no vectorised elastic law for {unknown}; known: "
                             f"{sorted(VECTOR_ELASTIC)}")
        self.m = len(axes)
        arr = {f: np.array([float(getattr(p, f)) for p in axes])
               for f in ("k1", "kc", "k2", "delta", "delta_neg", "c")}
        arr["dk"] = arr["k2"] - arr["k1"]
        fric = np.array([_vectorised(p) and p.friction for p in axes], dtype=bool)
        # no friction element: kf = fs = 0 gives a friction force of +-0 and an
        # unchanged slider, which leaves f_el + c v unchanged bit for bit
        self._kf = np.where(fric, [p.kf for p in axes], 0.0)
        self._fs = np.where(fric, [p.mu * p.n0 for p in axes], 0.0)
        self._neg_fs = -self._fs
        self._eps = self._fs / np.where(self._kf > 0, self._kf, 1.0)
        self._c = arr["c"]
        self._arr = arr
        laws = defaultdict(list)
        for i, p in enumerate(axes):
            laws[p.law].append(i)
        # per law: its function, its columns and their parameters (taken once)
        self._groups = [(VECTOR_ELASTIC[n], np.array(i),
                         {k: a[np.array(i)] for k, a in arr.items()})
                        for n, i in laws.items()]

    def elastic(self, u: np.ndarray) -> np.ndarray:
        """Elastic forces, shape of ``u`` (B, m), N."""
        if len(self._groups) == 1:  # one law: whole arrays, no gather/scatter
            f, _idx, a = self._groups[0]
            return f(u, a)
        out = np.empty_like(u)
        for f, idx, a in self._groups:
            out[:, idx] = f(u[:, idx], a)
        return out

    def generic_step(self, u: np.ndarray, v: np.ndarray, states: list, dt) -> tuple:
        """The scalar law (:func:`fmu_src.mount_law.axis_force`) of the
        :attr:`generic` columns: ``u``, ``v`` shape (B, m), ``states[b][c]`` the
        friction state of batch row b and generic column c, ``dt[b]`` the increment
        (s). Returns ``(force, friction_force, dissipated)`` of shape (B, g) and the
        new states (nothing committed)."""
        B, g = u.shape[0], len(self.generic)
        force, f_fr, diss = (np.empty((B, g)) for _ in range(3))
        new = []
        uu, vv = u[:, self.generic].tolist(), v[:, self.generic].tolist()
        for b in range(B):
            row = []
            for c, i in enumerate(self.generic):
                r = axis_force(uu[b][c], vv[b][c], states[b][c], self.axes[i], None,
                               dt[b])
                force[b, c], f_fr[b, c], diss[b, c] = r[0], r[1], r[5]
                row.append(r[2])
            new.append(row)
        return force, f_fr, diss, new

    def step(self, u: np.ndarray, v: np.ndarray, w: np.ndarray) -> LawStep:
        """Forces of a trial motion (nothing committed); see the class docstring."""
        force, f_fr, w_new = self.forces(u, v, w)
        return LawStep(force, f_fr, w_new, self.dissipated(w_new, w))

    def dissipated(self, w_new: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Energy the sliders dissipate from ``w`` to ``w_new``, J (Fs |dw|)."""
        return self._fs * np.abs(w_new - w)

    def forces(self, u: np.ndarray, v: np.ndarray, w: np.ndarray):
        """``(force, friction_force, w_new)`` of :meth:`step`."""
        f_el = self.elastic(u)
        fs = self._fs
        trial = self._kf * (u - w)
        # clip: fs above fs, -fs below -fs, else trial (the scalar's three branches);
        # a slip moves the slider to u - eps (trial > fs) or u + eps (trial < -fs)
        f_fr = np.minimum(np.maximum(trial, self._neg_fs), fs)
        slip = np.abs(trial) > fs
        w_new = np.where(slip, u - np.copysign(self._eps, trial), w)
        return f_el + self._c * v + f_fr, f_fr, w_new


def _slice_or_index(cols: np.ndarray):
    """A slice for consecutive column indices (a view, no copy), else the indices."""
    c = np.asarray(cols, dtype=int)
    if c.size and np.array_equal(c, np.arange(c[0], c[0] + c.size)):
        return slice(int(c[0]), int(c[0]) + c.size)
    return c


class _Batch:
    """Masters of one batch stepped together (their buffers are views of one)."""

    def __init__(self, masters):
        self.masters = list(masters)
        m0 = masters[0]
        L = m0.layout
        self.layout = L
        axes = [m0.system.elements[e].params.axes[j] for (_, e, j) in L.axes()]
        self.law = VectorLaw(axes)
        cols = {k: _slice_or_index(c) for k, c in m0._cols.items()}
        self._u, self._v = cols["u"], cols["v"]
        self._F, self._Ffr, self._E = cols["F"], cols["Ffr"], cols["E"]
        mount = np.zeros((L.m, L.n_mounts))
        for (i, e, _j) in L.axes():
            mount[i, e] = 1.0
        # one axis per mount: the energy of a mount is that of its axis
        self._mount = None if L.m == L.n_mounts else mount
        self.rebind()

    def rebind(self):
        """Stack the masters' buffers into one array and point them at its slices
        (their backends' own row views are not used: the batch steps the rows)."""
        rec = np.stack([m._rec for m in self.masters])
        self.rec = rec
        self.W = np.stack([m._Wh for m in self.masters])
        for b, m in enumerate(self.masters):
            m._rec = rec[b]

    def drop(self, keep):
        """Keep only the masters at the positions ``keep``."""
        self.masters = [self.masters[b] for b in keep]
        if self.masters:
            self.rebind()

    def _views(self, rows: int) -> list:
        """Per row k (cached until the buffer changes): the views the fast loop
        reads and writes, ``(u, v, F, Ffr, x, next)`` of row k (``u`` ... ``Ffr``
        None where the columns are not consecutive)."""
        key = (id(self.rec), rows)
        if getattr(self, "_views_key", None) != key:
            L, rec = self.layout, self.rec
            ox, nn = L.o_x, L.n_next

            def view(k, c):
                return rec[:, k, c] if isinstance(c, slice) else None
            self._views_list = [
                (view(k, self._u), view(k, self._v), view(k, self._F),
                 view(k, self._Ffr), rec[:, k, ox:, None], rec[:, k + 1, :nn, None])
                for k in range(rows)]
            self._views_key = key
        return self._views_list

    def run_rows(self, rows: int) -> None:
        """Step every master through rows 0..rows-1 (as InProcessBackend.run).

        The sliders of every step are kept; the friction energy (an output only)
        follows after the loop as the running sum of ``Fs |w_k - w_(k-1)|``, the
        scalar backend's additions in its order."""
        L, law, rec, W = self.layout, self.law, self.rec, self.W
        backends = [m.backend for m in self.masters]
        B = len(backends)
        gen = law.generic
        w0 = np.zeros((B, L.m))   # the vector columns' sliders (generic ones: 0)
        vec = [i for i in range(L.m) if i not in gen]
        for b, be in enumerate(backends):
            w0[b, vec] = [be._w[i] for i in vec]
        states = [[be._w[i] for i in gen] for be in backends]
        gdiss = np.zeros((rows, B, len(gen))) if gen else None
        E0 = np.array([be._E for be in backends], dtype=float).reshape(B, L.n_mounts)
        cu, cv, cF, cFr = self._u, self._v, self._F, self._Ffr
        ox, nn, matmul = L.o_x, L.n_next, np.matmul
        wh = np.empty((rows + 1, B, L.m))
        wh[0] = w0
        nxt = np.empty((B, nn, 1))
        t0 = _time.perf_counter()
        fast = bool(L.m) and not gen   # the inlined loop (same numbers)
        if fast:
            self._fast_rows(rows, wh)
        for k in range(0 if fast else rows):
            row = rec[:, k]
            if L.m:
                u, v = row[:, cu], row[:, cv]
                force, f_fr, w = law.forces(u, v, wh[k])
                wh[k + 1] = w
                if gen:   # as InProcessBackend.run: dt = 0 at a backend's first row
                    dt = [be._h_step if k or be.steps else 0.0 for be in backends]
                    gf, gfr, gdiss[k], states = law.generic_step(u, v, states, dt)
                    force[:, gen], f_fr[:, gen] = gf, gfr
                row[:, cF] = force
                row[:, cFr] = f_fr
            matmul(W, row[:, ox:, None], out=nxt)
            rec[:, k + 1, :nn] = nxt[:, :, 0]
        E = self._energy(wh, E0, gdiss)
        if L.n_mounts:
            rec[:, :rows, self._E] = E.transpose(1, 0, 2)
        wall = (_time.perf_counter() - t0) / B
        for b, be in enumerate(backends):
            be._w[:] = wh[rows, b].tolist()
            for c, i in enumerate(gen):
                be._w[i] = states[b][c]
            be._E[:] = E[-1, b].tolist()
            be.steps += rows
        for m in self.masters:
            m.wall_time += wall

    def _fast_rows(self, rows: int, wh: np.ndarray) -> None:
        """The loop of :meth:`run_rows` without generic columns: the operations of
        :meth:`VectorLaw.forces` and the batched product, inlined on cached views.

        Every elementwise operation runs on contiguous (B, m) arrays of the same
        shape (the law's parameters expanded to the batch, the row's ``u`` and ``v``
        copied out first) into preallocated buffers (``out=``): NumPy's fast path,
        about 0.3 us a call where a broadcast operand on a strided view costs 1 us.
        The same floating-point operations on the same operands in the same order
        as the general loop (products commuted, which IEEE leaves exact), so the
        same numbers bit for bit."""
        law, W, rec = self.law, self.W, self.rec
        B, m = wh.shape[1], wh.shape[2]
        cu, cv, cF, cFr = self._u, self._v, self._F, self._Ffr

        def full(a):
            return np.ascontiguousarray(np.broadcast_to(a, (B, m)))
        one = law._groups[0] if len(law._groups) == 1 else None
        knees = None
        if one is not None and one[0] in (_piecewise, _piecewise_asym):
            a = one[2]  # k1 u + (k2 - k1)(u - clip(u, -dneg, delta)), as _knees
            dneg = a["delta"] if one[0] is _piecewise else a["delta_neg"]
            knees = (full(-dneg), full(a["delta"]), full(a["k1"]), full(a["dk"]))
        kf, fs, neg_fs = full(law._kf), full(law._fs), full(law._neg_fs)
        eps, c = full(law._eps), full(law._c)
        U, V, T1, T2, TR, FEL, FFR = (np.empty((B, m)) for _ in range(7))
        SL = np.empty((B, m), dtype=bool)
        maximum, minimum, absolute, greater = np.maximum, np.minimum, np.abs, np.greater
        copysign, matmul, add, sub, mul = (np.copysign, np.matmul, np.add,
                                           np.subtract, np.multiply)
        putmask, elastic = np.putmask, law.elastic
        for k, (u, v, F, Ffr, x, nxt) in enumerate(self._views(rows)):
            if u is None:
                U[...] = rec[:, k, cu]
            else:
                U[...] = u
            if v is None:
                V[...] = rec[:, k, cv]
            else:
                V[...] = v
            w = wh[k]
            if knees is not None:
                nd, d, k1, dk = knees
                maximum(U, nd, out=T1)
                minimum(T1, d, out=T1)
                sub(U, T1, out=T1)
                mul(k1, U, out=FEL)
                mul(dk, T1, out=T1)
                add(FEL, T1, out=FEL)
            else:
                FEL[...] = elastic(U)
            sub(U, w, out=TR)
            mul(kf, TR, out=TR)                 # trial = kf (u - w)
            maximum(TR, neg_fs, out=FFR)
            minimum(FFR, fs, out=FFR)           # the friction force
            absolute(TR, out=T1)
            greater(T1, fs, out=SL)             # slip
            copysign(eps, TR, out=T1)
            sub(U, T1, out=T1)                  # the slider after a slip
            w1 = wh[k + 1]
            w1[...] = w
            putmask(w1, SL, T1)
            mul(c, V, out=T2)
            add(FEL, T2, out=T2)
            add(T2, FFR, out=T2)                # f_el + c v + f_fr
            if F is None:
                rec[:, k, cF] = T2
            else:
                F[...] = T2
            if Ffr is None:
                rec[:, k, cFr] = FFR
            else:
                Ffr[...] = FFR
            matmul(W, x, out=nxt)

    def _energy(self, wh: np.ndarray, E0: np.ndarray, gdiss=None) -> np.ndarray:
        """Committed friction energy per mount after each step, (rows, B, n_mounts),
        from the sliders ``wh`` (rows + 1, B, m), the generic columns' dissipation
        ``gdiss`` (rows, B, g) and the energy ``E0`` before."""
        diss = self.law.dissipated(wh[1:], wh[:-1])
        if gdiss is not None:
            diss[:, :, self.law.generic] += gdiss
        if self._mount is not None:
            diss = diss @ self._mount
        diss[0] += E0
        return np.cumsum(diss, axis=0)

def steady_states(system, freqs_hz, *, steps_per_period: int | None = None,
                  rtol: float = DEFAULT_RTOL, min_periods: int = DEFAULT_MIN_PERIODS,
                  max_periods: int = DEFAULT_MAX_PERIODS, batch_size: int = BATCH_SIZE,
                  progress=None, report=None) -> list[SteadyState]:
    """Steady states of ``system`` at every frequency of ``freqs_hz``, stepped in
    batches (in-process law; each from the linearised start, see the module docstring).

    Returns one :class:`vehicle.steady.SteadyState` per frequency, in the order of
    ``freqs_hz``; the same as ``steady_state(system, f, backend="inproc")`` per
    frequency up to round-off. ``progress`` (a tqdm bar or None) is advanced by one
    per finished frequency; ``report(index, steady_state)`` is called for each
    as it finishes (so a caller keeps what was computed if the run is stopped).
    """
    f = [float(x) for x in np.asarray(freqs_hz, dtype=float).reshape(-1)]
    if not f or not all(np.isfinite(x) and x > 0 for x in f):
        raise ValueError(f"`freqs_hz` must be a non-empty list of finite frequencies "
                         f"> 0, got {np.asarray(freqs_hz).tolist()}")
    check_convergence_settings(rtol, min_periods, max_periods)
    if not (isinstance(batch_size, int) and batch_size >= 1):
        raise ValueError(f"`batch_size` must be an integer >= 1, got {batch_size!r}")
    masters = _masters(system, len(f))
    try:
        runs = [(i, m, *_begin(m, x, steps_per_period, "linear"))
                for i, (m, x) in enumerate(zip(masters, f, strict=True))]
        groups = defaultdict(list)  # lock step needs equal steps per period
        for run in runs:
            groups[run[2]].append(run)
        out = [None] * len(f)
        for group in groups.values():
            for a in range(0, len(group), batch_size):
                for i, ss in _run_batch(group[a:a + batch_size], f, rtol,
                                        min_periods, max_periods):
                    out[i] = ss
                    if report is not None:
                        report(i, ss)
                    if progress is not None:
                        progress.update(1)
        return out
    finally:
        for m in masters:
            m.close()


def _masters(system, count: int) -> list[Master]:
    """``count`` in-process masters of ``system`` (the step limit computed once)."""
    first = Master(system, "inproc")
    out = [first]
    for _ in range(count - 1):
        m = Master(system, "inproc")
        m._dt_limit = first.dt_limit()
        out.append(m)
    return out


def _run_batch(runs, freqs, rtol, min_periods, max_periods):
    """Periods of the masters of ``runs`` (``(index, master, N, h, E_start)``) in
    lock step until each converges (as run_steady); yields ``(index, SteadyState)``."""
    batch = _Batch([r[1] for r in runs])
    state = [[i, h, E0, m.backend.steps, m.wall_time] for (i, m, _N, h, E0) in runs]
    N = runs[0][2]
    while batch.masters:
        for m in batch.masters:
            m._next_period()
        batch.run_rows(N)
        keep = []
        for b, m in enumerate(batch.masters):
            i, h, E_start, steps0, wall0 = state[b]
            period = m._finish_period()
            change = _period_change(period)
            converged = period.index >= min_periods and change <= rtol
            if converged or period.index >= max_periods:
                yield i, _analyse(m, period, freqs[i], h, E_start, change, converged,
                                  rtol, steps0, wall0)
            else:
                state[b][2] = period.energy
                keep.append(b)
        if len(keep) < len(batch.masters):
            state = [state[b] for b in keep]
            batch.drop(keep)
