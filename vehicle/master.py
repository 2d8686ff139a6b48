"""Fixed-step co-simulation master of the vehicle harness.

Equations (:mod:`hbm.system`, thesis eq. 2.1-2.9), DOFs q (n), base y (n_base):

    M q'' + C q' + K q + sum_e B_e^T F_e(u_e, v_e, w_e) = f(t) + K_b y + C_b y'
    u_e = B_e q - G_e y,   v_e = B_e q' - G_e y'

The mount forces F_e come from a backend (:mod:`vehicle.backends`): the in-process
law or one FMU per mount. Exactly one mount-force evaluation (one FMU
set/get/doStep per mount) is made per step.

Coupling scheme
---------------
Explicit central difference (leapfrog) with half-step velocities and a second-order
velocity predictor for the velocity-dependent forces. State at step k:
``q_k``, ``vh_k = q'(t_k - h/2)``, ``a_{k-1}``.

    v_k  = vh_k + (h/2) a_{k-1}                        predicted q'(t_k), O(h^2)
    u, v of every active mount axis from (q_k, v_k, y(t_k), y'(t_k))
    F_k  = mount law (u_k, v_k, w_{k-1})              one FMU evaluation; commits w_k
    a_k  = M^-1 (f(t_k) + K_b y_k + C_b y'_k - K q_k - C v_k - sum B^T F_k)
    vh_{k+1} = vh_k + h a_k,   q_{k+1} = q_k + h vh_{k+1}

Why: (1) it needs the force at one instant per step, which is exactly what the FMU
protocol gives (set u, v at t_k, get F at t_k, doStep commits the slider); an
implicit scheme would need FMU iterations (get/set state) or a Jacobian the FMU
cannot provide through FMI. (2) Leapfrog is second order and non-dissipative for the
stiffness terms (|amplification| = 1 for omega h < 2), so it does not add numerical
damping to lightly damped mounts. (3) Using the lagged half-step velocity vh_k in the
damper would be first order (a phase lag of omega h / 2 in c v, i.e. a spurious
stiffness c omega^2 h / 2): measured 3.8e-3 amplitude error at 256 steps per period,
1.9e-2 at 64 (SDOF below); the predictor v_k = vh_k + (h/2) a_{k-1} restores second
order at no cost (2.5e-4 and 4.0e-3). (4) The Jenkins return map is exact for a
monotonic increment, so the friction needs no sub-stepping.

The whole linear part is one affine map: row k+1 of the row buffer
(``[u, v | q, vh, a]``) is ``W @ [q, vh, a | F, Ffr, E | r_k, g_{k+1}]`` with the input
terms precomputed per step, so the per-step Python work is one ``np.dot``.

Step size: the master uses an integer number of steps per excitation period (default
256) and never more than ``dt_limit()``: the step with omega_max h <= 0.5 (omega_max
of the system with every mount at its stiffest tangent, friction stuck) and a
spectral radius <= 1 of the linearised amplification matrix.

Measured accuracy (linear SDOF m = 70 kg, k = 91 870 N/m, c = 150 N s/m, unbalance
excitation; steady-state fundamental amplitude against the exact FRF, worst of 0.7,
0.9, 1.0, 1.1, 1.5 and 3 times the natural frequency 5.77 Hz; run from rest with
rtol = 1e-9, inproc backend):

    steps per period    16        32        64        128       256
    max rel. error      7.1e-2    1.7e-2    4.0e-3    9.9e-4    2.5e-4

Second order (error x 1/4 per halving of h, about 0.4 (2 pi / N)^2 at the flanks of
the resonance); at the default 256 steps per period the error is 2.5e-4, inside the
0.5 % target by a factor 20. ``tests/test_vehicle_linear.py`` checks the order.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from drymount.hbm.static import working_point

from .backends import Layout, backend_name, make_backend
from .inputs import HarmonicInput, Input
from .results import TimeHistory

__all__ = ["Master", "PeriodRecord", "simulate", "DEFAULT_STEPS_PER_PERIOD",
           "OMEGA_H_MAX"]

#: Default number of steps per excitation period.
DEFAULT_STEPS_PER_PERIOD = 256
#: Largest omega_max * h allowed (phase error of the stiffest mode about 1 %).
OMEGA_H_MAX = 0.5
#: Rows per block when simulating a time history.
BLOCK_ROWS = 2048


class DivergenceError(RuntimeError):
    """The time integration produced non-finite numbers."""


@dataclass
class PeriodRecord:
    """One period of :meth:`Master.run_period` (copies of the step rows).

    Rows are the steps ``t_k = k h``, k = 0..N-1, of the period (phase 0 at k = 0).

    Attributes
    ----------
    index : int
        Periods run since :meth:`Master.begin_periodic` (1 for the first).
    q, qd : ndarray, shape (N, n_dof)
        DOFs and predicted rates.
    forces, friction_forces, deflections : ndarray, shape (N, n_axes)
        Mount forces (N), friction forces (N) and deflections (m) of the active axes.
    energy : ndarray, shape (n_mounts,)
        Cumulative friction energy of each mount at the last row, J.
    q_end, qd_end : ndarray, shape (n_dof,)
        State at the end of the period (the start of the next).
    """

    index: int
    q: np.ndarray
    qd: np.ndarray
    forces: np.ndarray
    friction_forces: np.ndarray
    deflections: np.ndarray
    energy: np.ndarray
    q_end: np.ndarray
    qd_end: np.ndarray


class Master:
    """Co-simulation master for one :class:`hbm.system.System`.

    Keeps the integrator state (q, q', q'') and the backend (mount instances, slider
    states) alive between calls, so a sweep continues from the previous steady state.
    Use as a context manager (``with Master(...) as m:``) or call :meth:`close`.

    Parameters
    ----------
    system : hbm.system.System
    backend : {"inproc", "fmu"}
    fmu_path : path-like, optional
        FMU for the ``fmu`` backend (default ``fmu_build.ensure_fmu()``).
    fmu_logging : bool
        FMU debug logging (default on).
    fmu_start_values : dict, optional
        Extra FMU start values ``{name: value}`` for every instance, or
        ``{mount name: {name: value}}`` for one mount.
    omega_h_max : float
        Accuracy limit omega_max * h of the step (default 0.5).
    """

    def __init__(self, system, backend: str = "inproc", *, fmu_path=None,
                 fmu_logging: bool = True, fmu_start_values=None,
                 omega_h_max: float = OMEGA_H_MAX, control: dict | None = None):
        if not (isinstance(omega_h_max, (int, float)) and 0 < omega_h_max < 2):
            raise ValueError(f"`omega_h_max` must be in (0, 2), got {omega_h_max!r}")
        self.system = system
        self.layout = Layout.of(system)
        self.omega_h_max = float(omega_h_max)
        self._setup_matrices()
        backend = backend_name(backend, stacklevel=3)
        self.backend_name = backend
        self.backend = make_backend(backend, system, self.layout, fmu_path=fmu_path,
                                    logging_on=fmu_logging,
                                    start_values=fmu_start_values)
        if control:
            # semi-active normal forces, {(mount, axis): controller} (vehicle.control)
            self.backend.set_control(control)
        n = system.n_dof
        #: the static working point (``system.static_load``), None if unloaded; the
        #: master starts there, by default with the engine lowered onto the mount
        #: (its friction-element states; ``system.static_reading = "relaxed"``: the
        #: elements relaxed there), hbm.static.working_point
        self.static = working_point(system)
        self.q_static = np.zeros(n) if self.static is None else self.static.q.copy()
        if self.static is not None:
            self.backend.set_sliders(self.static.sliders)
            if self.static.states:   # the lowered reading: whole element states
                self.backend.set_element_states(self.static.states)
        self.q = self.q_static.copy()
        self.qd = np.zeros(n)
        self.qdd = np.zeros(n)
        self.time = 0.0          # global simulation time (FMU communication points), s
        self.wall_time = 0.0     # wall-clock seconds spent stepping
        self._dt_limit = None
        self._h = None
        self._rec = None
        self._periodic = None  # (t0, steps, periods run) of begin_periodic()

    # ------------------------------------------------------------------ matrices
    def _setup_matrices(self):
        s, L = self.system, self.layout
        n = s.n_dof
        self._Minv = np.linalg.inv(s.M)
        rows_B, rows_G = [], []
        for e, act in zip(s.elements, L.active, strict=True):
            for j in act:
                rows_B.append(e.B[j])
                rows_G.append(e.G[j])
        self._B = np.array(rows_B, dtype=float).reshape(L.m, n)
        self._G = np.array(rows_G, dtype=float).reshape(L.m, s.n_base)
        # per-mount [u rows; v rows] ordering of UV: index of the axis row for each
        # UV position and whether it is a rate
        perm, rate = [], []
        i0 = 0
        for act in L.active:
            me = len(act)
            perm += list(range(i0, i0 + me)) * 2
            rate += [False] * me + [True] * me
            i0 += me
        self._uv_axis = np.array(perm, dtype=int)
        self._uv_rate = np.array(rate, dtype=bool)
        # g = [G y ; G y'] in UV order = Gcat @ [y, y']
        nb = s.n_base
        Gcat = np.zeros((2 * L.m, 2 * nb))
        for r, (i, is_rate) in enumerate(zip(perm, rate, strict=True)):
            if is_rate:
                Gcat[r, nb:] = self._G[i]
            else:
                Gcat[r, :nb] = self._G[i]
        self._Gcat = Gcat
        cols = L.columns()
        self._cols = cols

    def _W(self, h: float) -> np.ndarray:
        """The affine one-step map for step ``h`` (see module docstring)."""
        s, L = self.system, self.layout
        n, m = s.n_dof, L.m
        eye = np.eye(n)
        Mi = self._Minv
        Lx = Mi @ np.hstack([-s.K, -s.C, -(h / 2.0) * s.C])          # (n, 3n)
        P = -Mi @ self._B.T                                           # (n, m)
        S = np.zeros((3 * n, 3 * n))
        S[:n, :n] = eye
        S[:n, n:2 * n] = h * eye
        S[n:2 * n, n:2 * n] = eye
        b = np.vstack([h * h * eye, h * eye, eye])                    # (3n, n)
        Phi = S + b @ Lx
        Cu = np.zeros((2 * m, 3 * n))
        pairs = zip(self._uv_axis, self._uv_rate, strict=True)
        for r, (i, is_rate) in enumerate(pairs):
            if is_rate:
                Cu[r, n:2 * n] = self._B[i]
                Cu[r, 2 * n:] = (h / 2.0) * self._B[i]
            else:
                Cu[r, :n] = self._B[i]
        W = np.zeros((L.n_next, L.width - L.o_x))
        # input columns: x (3n) | OUT (n_out) | r (n) | g (2m)
        W[:2 * m, :3 * n] = Cu @ Phi
        W[2 * m:, :3 * n] = Phi
        F_in = 3 * n + (self._cols["F"] - L.o_out)
        bP = b @ P
        W[:2 * m, F_in] = Cu @ bP
        W[2 * m:, F_in] = bP
        r0 = 3 * n + L.n_out
        W[:2 * m, r0:r0 + n] = Cu @ b
        W[2 * m:, r0:r0 + n] = b
        W[:2 * m, r0 + n:] = -np.eye(2 * m)
        return np.ascontiguousarray(W)

    def _linear_phi(self, h: float, stuck_max: bool = True) -> np.ndarray:
        """Amplification matrix (3n, 3n) of the scheme for the linearised system."""
        s = self.system
        n = s.n_dof
        K, C = self._stiffest()
        Mi = self._Minv
        Lx = Mi @ np.hstack([-K, -C, -(h / 2.0) * C])
        S = np.zeros((3 * n, 3 * n))
        S[:n, :n] = np.eye(n)
        S[:n, n:2 * n] = h * np.eye(n)
        S[n:2 * n, n:2 * n] = np.eye(n)
        b = np.vstack([h * h * np.eye(n), h * np.eye(n), np.eye(n)])
        return S + b @ Lx

    def _stiffest(self):
        """Total K and C with every active mount axis at its stiffest tangent (the
        law's ``stiffest``: max(k1, k2) for the piecewise laws, k1 otherwise), plus the
        friction element's stiffest tangent (``contact_stiffness``: kf, or the inclined
        element's both-stuck tangent)."""
        s = self.system
        K, C = s.K.copy(), s.C.copy()
        for e in s.elements:
            kd, cd = np.zeros(3), np.zeros(3)
            for j in e.active_axes:
                p = e.params.axes[j]
                kd[j] = p.elastic.stiffest(p) + p.contact_stiffness
                cd[j] = p.c
            K += e.B.T @ (kd[:, None] * e.B)
            C += e.B.T @ (cd[:, None] * e.B)
        return K, C

    def dt_limit(self) -> float:
        """Largest step used, s: omega_max h <= ``omega_h_max`` and a stable
        linearised amplification matrix (spectral radius <= 1)."""
        if self._dt_limit is None:
            K, _ = self._stiffest()
            lam = scipy.linalg.eigh(K, self.system.M, eigvals_only=True)
            wmax = math.sqrt(max(float(lam.max()), 0.0))
            h = self.omega_h_max / wmax if wmax > 0 else 1e-2
            for _ in range(60):
                rho = max(abs(np.linalg.eigvals(self._linear_phi(h))))
                if rho <= 1.0 + 1e-12:
                    break
                h *= 0.8
            self._dt_limit = h
        return self._dt_limit

    def steps_per_period(self, freq_hz: float,
                         minimum: int = DEFAULT_STEPS_PER_PERIOD) -> int:
        """Integer steps per period at ``freq_hz``: ``minimum``, or more if the step
        limit (:meth:`dt_limit`) demands."""
        if not (isinstance(minimum, (int, np.integer)) and minimum >= 8):
            raise ValueError(
                f"`steps_per_period` must be an integer >= 8, got {minimum!r}")
        return max(int(minimum), math.ceil(1.0 / (freq_hz * self.dt_limit()) - 1e-9))

    # ------------------------------------------------------------------ buffers
    def _prepare(self, h: float, rows: int) -> np.ndarray:
        """Allocate (or reuse) the row buffer for ``rows`` steps of size ``h``."""
        if (self._rec is None or self._rec.shape[0] != rows + 1 or self._h != h):
            self._rec = np.zeros((rows + 1, self.layout.width))
            self._h = h
            self._Wh = self._W(h)
            self.backend.bind(self._rec, self._Wh, h)
        return self._rec

    def _fill_inputs(self, rec: np.ndarray, inp: Input, t_rows: np.ndarray,
                     t_next: np.ndarray) -> None:
        """Fill the R columns of rows 0..len(t_rows)-1: r_k at ``t_rows`` and the base
        part g_{k+1} of UV at ``t_next``."""
        L, s = self.layout, self.system
        f, y, yd = inp.evaluate(t_rows)
        if s.static_load is not None:
            f = f + s.static_load
        r = (f + y @ s.Kb.T + yd @ s.Cb.T) @ self._Minv.T
        k = len(t_rows)
        rec[:k, L.o_r:L.o_r + s.n_dof] = r
        if L.m:
            _, y1, yd1 = inp.evaluate(t_next)
            rec[:k, L.o_r + s.n_dof:] = np.hstack([y1, yd1]) @ self._Gcat.T

    def _base_uv(self, inp: Input, t: float) -> np.ndarray:
        _, y, yd = inp.evaluate(np.array([t]))
        return (np.hstack([y, yd]) @ self._Gcat.T)[0]

    def _set_row0(self, rec, inp: Input, t_local: float) -> None:
        """Row 0 from the master's state (q, q', q'') at local input time t_local."""
        L, n, h = self.layout, self.system.n_dof, self._h
        x = np.concatenate([self.q, self.qd - 0.5 * h * self.qdd, self.qdd])
        rec[0, L.o_x:L.o_x + 3 * n] = x
        q, vp = self.q, self.qd
        uv = np.where(self._uv_rate, (self._B @ vp)[self._uv_axis],
                      (self._B @ q)[self._uv_axis]) if L.m else np.zeros(0)
        rec[0, :2 * L.m] = uv - self._base_uv(inp, t_local)

    def _state_of_row(self, row: np.ndarray):
        """(q, q', q'') of a row: q' is the predicted velocity vh + h/2 a."""
        L, n, h = self.layout, self.system.n_dof, self._h
        x = row[L.o_x:L.o_x + 3 * n]
        q, vh, a = x[:n], x[n:2 * n], x[2 * n:]
        return q.copy(), vh + 0.5 * h * a, a.copy()

    def set_state(self, q=None, qd=None, qdd=None, sliders=None,
                  elements=None) -> None:
        """Set the integrator state (DOFs in m/rad) and optionally slider positions
        (shape (n_mounts, 3), m) and whole friction-element states ``elements`` =
        ``{(mount index, axis index): state}`` (set after the sliders; the in-process
        backend only, :meth:`vehicle.backends.NativeBackend.set_element_states`)."""
        n = self.system.n_dof
        for name, val in (("q", q), ("qd", qd), ("qdd", qdd)):
            if val is not None:
                a = np.asarray(val, dtype=float)
                if a.shape != (n,) or not np.all(np.isfinite(a)):
                    raise ValueError(f"`{name}` must be {n} finite values, got "
                                     f"{np.asarray(val).tolist()}")
                setattr(self, name, a.copy())
        if sliders is not None:
            self.backend.set_sliders(np.asarray(sliders, dtype=float).reshape(
                self.layout.n_mounts, 3))
        if elements:
            self.backend.set_element_states(elements)

    def sliders(self) -> np.ndarray:
        """Slider positions (n_mounts, 3), m."""
        return self.backend.sliders()

    def _run_rows(self, rows: int, t_global0: float, step0: int) -> None:
        """Run rows 0..rows-1 of the buffer; global time of row k is
        ``t_global0 + (step0 + k) h``."""
        times = (t_global0 + (step0 + np.arange(rows)) * self._h).tolist()
        w0 = _time.perf_counter()
        self.backend.run(0, rows, times)
        self.wall_time += _time.perf_counter() - w0

    def _check_finite(self, row, t: float) -> None:
        L = self.layout
        if not np.all(np.isfinite(row[:L.n_next])):
            raise DivergenceError(
                f"the co-simulation of {self.system.name!r} diverged before "
                f"t = {t:.6g} s (step {self._h:.3g} s); use more steps per period "
                "or a smaller `omega_h_max`")

    # ------------------------------------------------------------------ time history
    def simulate(self, duration: float, *, dt: float | None = None,
                 inputs: Input | None = None, freq_hz: float | None = None
                 ) -> TimeHistory:
        """Time history from the current state over ``duration`` s.

        ``inputs`` (an :mod:`vehicle.inputs` object) or, if None, the system's
        harmonic excitation at ``freq_hz``. ``dt`` defaults to one period /
        ``DEFAULT_STEPS_PER_PERIOD`` (limited by :meth:`dt_limit`) with ``freq_hz``,
        else to ``min(dt_limit()/4, 1e-3)``, then shortened so that the grid ends at
        ``duration``. Rows t = k dt, k = 0..n, with n = ceil(duration / dt) for the
        default step and n = round(duration / dt) for a given ``dt``.
        """
        if duration is None or not (np.isfinite(duration) and duration > 0):
            raise ValueError(f"`duration` must be finite and > 0, got {duration!r}")
        inputs = self._inputs_for(inputs, freq_hz)
        dt, n_steps = self._time_grid(duration, dt, freq_hz)
        total = n_steps + 1
        L, n = self.layout, self.system.n_dof
        rows = min(BLOCK_ROWS, total)
        rec = self._prepare(dt, rows)
        cols = self._cols
        out_q = np.empty((total, n))
        out_qd = np.empty((total, n))
        out_F = np.empty((total, L.m))
        out_Ffr = np.empty((total, L.m))
        out_u = np.empty((total, L.m))
        out_E = np.empty((total, L.n_mounts))
        self._set_row0(rec, inputs, 0.0)
        t0 = self.time
        done = 0

        def history(rows_done: int) -> TimeHistory:
            sl = slice(0, rows_done)
            return TimeHistory(
                t=np.arange(rows_done) * dt, q=out_q[sl], qd=out_qd[sl],
                forces=out_F[sl], friction_forces=out_Ffr[sl],
                deflections=out_u[sl], friction_energy=out_E[sl].sum(1),
                dof_names=tuple(self.system.dof_names),
                force_names=tuple(self.system.axis_labels()), dt=dt,
                backend=self.backend_name, system_name=self.system.name)

        try:
            while done < total:
                b = min(rows, total - done)
                k = done + np.arange(b)
                self._fill_inputs(rec, inputs, k * dt, (k + 1) * dt)
                self._run_rows(b, t0, done)
                self._check_finite(rec[b], t0 + (done + b) * dt)
                x = rec[:b, L.o_x:L.o_x + 3 * n]
                out_q[done:done + b] = x[:, :n]
                out_qd[done:done + b] = x[:, n:2 * n] + 0.5 * dt * x[:, 2 * n:]
                out_F[done:done + b] = rec[:b, cols["F"]]
                out_Ffr[done:done + b] = rec[:b, cols["Ffr"]]
                out_u[done:done + b] = rec[:b, cols["u"]]
                out_E[done:done + b] = rec[:b, cols["E"]]
                done += b
                rec[0, :L.n_next] = rec[b, :L.n_next]
        except BaseException as exc:
            # stopped (interrupt, FMU error, divergence): the rows completed so far
            exc.partial_result = history(done)
            raise
        self.q, self.qd, self.qdd = self._state_of_row(rec[0])
        self.time = t0 + total * dt
        return history(total)

    def _inputs_for(self, inputs: Input | None, freq_hz: float | None) -> Input:
        """``inputs`` checked against the system, or the system's harmonic
        excitation at ``freq_hz`` (:meth:`simulate`)."""
        if inputs is None:
            if freq_hz is None:
                raise ValueError("give `freq_hz` (harmonic excitation of the system) "
                                 "or `inputs`")
            return HarmonicInput(self.system, freq_hz)
        if (inputs.n_dof, inputs.n_base) != (self.system.n_dof, self.system.n_base):
            raise ValueError("`inputs` was made for another system: (n_dof, n_base) "
                             f"{(inputs.n_dof, inputs.n_base)} != "
                             f"{(self.system.n_dof, self.system.n_base)}")
        return inputs

    def _time_grid(self, duration: float, dt: float | None, freq_hz: float | None
                   ) -> tuple[float, int]:
        """The step and the number of steps of :meth:`simulate` over ``duration``
        (finite and > 0)."""
        if dt is None:
            if freq_hz is not None:
                dt0 = 1.0 / (freq_hz * self.steps_per_period(freq_hz))
            else:
                dt0 = min(self.dt_limit() / 4.0, 1e-3)
            n_steps = max(1, math.ceil(duration / dt0 - 1e-9))
            return duration / n_steps, n_steps
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"`dt` must be finite and > 0, got {dt!r}")
        if dt > self.dt_limit() * (1 + 1e-9):
            raise ValueError(f"`dt` = {dt:.4g} s exceeds the step limit "
                             f"{self.dt_limit():.4g} s of this system")
        return dt, max(1, int(round(duration / dt)))

    # ------------------------------------------------------------------ periods
    def begin_periodic(self, inputs: Input, steps: int, h: float) -> None:
        """Prepare runs of whole periods of ``steps`` steps of ``h`` s under the
        periodic ``inputs`` (period ``steps * h``), phase 0 at the current state.

        Then call :meth:`run_period` once per period; the master's state, sliders and
        ``time`` follow every period, so a later run continues from them.
        """
        if not (isinstance(steps, (int, np.integer)) and steps >= 1):
            raise ValueError(f"`steps` must be an integer >= 1, got {steps!r}")
        rec = self._prepare(h, int(steps))
        k = np.arange(steps)
        self._fill_inputs(rec, inputs, k * h, ((k + 1) % steps) * h)
        self._set_row0(rec, inputs, 0.0)
        self._periodic = [self.time, int(steps), 0]

    def run_period(self) -> PeriodRecord:
        """Run the next period of :meth:`begin_periodic`; returns its rows."""
        t0, N, done = self._next_period()
        self._run_rows(N, t0, done * N)
        return self._finish_period()

    def _next_period(self):
        """Row 0 of the next period (row N of the last one); ``(t0, N, done)``.
        :meth:`run_period` and :mod:`vehicle.batch` run the rows in between."""
        if self._periodic is None:
            raise RuntimeError("call begin_periodic() before run_period()")
        t0, N, done = self._periodic
        if done:
            L = self.layout  # the next period starts at row N
            self._rec[0, :L.n_next] = self._rec[N, :L.n_next]
        return t0, N, done

    def _finish_period(self) -> PeriodRecord:
        """Bookkeeping after the rows of a period ran: its :class:`PeriodRecord`."""
        t0, N, done = self._periodic
        rec, L, n, h = self._rec, self.layout, self.system.n_dof, self._h
        cols = self._cols
        self._check_finite(rec[N], t0 + (done + 1) * N * h)
        done += 1
        self._periodic[2] = done
        ox = L.o_x
        q_end, qd_end, qdd_end = self._state_of_row(rec[N])
        self.q, self.qd, self.qdd = q_end, qd_end, qdd_end
        self.time = t0 + done * N * h
        return PeriodRecord(
            index=done, q=rec[:N, ox:ox + n].copy(),
            qd=rec[:N, ox + n:ox + 2 * n] + 0.5 * h * rec[:N, ox + 2 * n:ox + 3 * n],
            forces=rec[:N, cols["F"]].copy(),
            friction_forces=rec[:N, cols["Ffr"]].copy(),
            deflections=rec[:N, cols["u"]].copy(), energy=rec[N - 1, cols["E"]].copy(),
            q_end=q_end.copy(), qd_end=qd_end.copy())

    # ------------------------------------------------------------------ cleanup
    def close(self) -> None:
        """Terminate and free the backend's instances (safe to call twice)."""
        self.backend.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def simulate(system, freq_hz: float | None = None, duration: float = 1.0, *,
             backend: str = "fmu", dt: float | None = None, inputs: Input | None = None,
             fmu_path=None, fmu_start_values=None, control: dict | None = None
             ) -> TimeHistory:
    """Time histories of ``system`` from rest.

    Parameters
    ----------
    system : hbm.system.System
    freq_hz : float, optional
        Frequency of the system's own harmonic excitation (used when ``inputs`` is
        None; also sets the default step: one period / 256).
    duration : float
        Simulated time, s.
    backend : {"fmu", "inproc"}
    dt : float, optional
        Step, s (default: see :meth:`Master.simulate`).
    inputs : vehicle.inputs.Input, optional
        Engine/road input (crank excitation, road profiles, ...).
    fmu_path : path-like, optional
    control : dict, optional
        ``{(mount name, axis): controller}`` (:mod:`vehicle.control`): semi-active
        normal forces applied every step.

    Returns
    -------
    vehicle.results.TimeHistory

    Examples
    --------
    >>> from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    >>> from drymount.hbm.systems import sdof
    >>> s = sdof(70.0, MountParameters.from_axial(AxisParameters(law="linear")),
    ...          "unbalance", 0.01)
    >>> th = simulate(s, 10.0, 0.5, backend="inproc")
    >>> th.q.shape
    (1281, 1)
    """
    with Master(system, backend, fmu_path=fmu_path,
                fmu_start_values=fmu_start_values, control=control) as m:
        return m.simulate(duration, dt=dt, inputs=inputs, freq_hz=freq_hz)
