"""Independent reference: time integration to the periodic steady state (scipy).

Integrates the equations of motion of :mod:`hbm.system` with
:func:`scipy.integrate.solve_ivp` (DOP853) and event-exact stick-slip for the Jenkins
elements, independently of the harmonic-balance code (it uses only the scalar mount law
of :mod:`fmu_src.mount_law` and the structure matrices):

- each friction element is in one phase: stuck (``F_fr = kf (u - w)``, ``w`` fixed) or
  slipping with sign s (``F_fr = s Fs``); inside a phase the equations are smooth;
- a stuck element starts to slip when ``kf (u - w)`` reaches ``+-Fs`` (event); a
  slipping element sticks when its slip velocity ``du/dt`` changes sign (event), with
  ``w = u - s Fs / kf`` (thesis eq. 2.10-2.13);
- the knees of the piecewise laws (``u = delta``, ``u = -delta_neg``) are events too,
  so that no step straddles a kink;
- every event stops the integrator, switches the phase and restarts it, so the
  switching times are located to the integrator's event tolerance (about machine
  precision in time), not to a step.

The integration runs period by period until the state at the period boundary repeats
(with a geometric extrapolation of the remaining transient), then samples the last
period uniformly and takes its Fourier coefficients by FFT.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp

from drymount.fmu_src.mount_law import AXES, elastic_force
from drymount.hbm.linear import linear_frf
from drymount.hbm.system import System

__all__ = ["ReferenceResult", "periodic_response"]


@dataclass
class ReferenceResult:
    """Periodic steady state from time integration.

    Attributes
    ----------
    freq_hz : float
    t : ndarray, shape (n_out,)
        Times of the samples of the last period, s.
    q : ndarray, shape (n_out, n_dof)
        DOFs at ``t``, m or rad.
    coefficients : ndarray, shape (n_dof, 2H+1)
        ``[static, cos1, sin1, ...]`` with phase ``omega t`` (same convention as HBM).
    amplitude : ndarray, shape (n_dof,)
        Fundamental amplitude, m or rad.
    peak : ndarray, shape (n_dof,)
        ``max |q|`` over the last period.
    periods : int
        Periods integrated.
    converged : bool
        Whether the period-to-period change (extrapolated) fell below ``tol``.
    change : float
        Last relative period-to-period change of the state.
    n_events : int
        Phase switches and knee crossings in the whole run.
    """

    freq_hz: float
    t: np.ndarray
    q: np.ndarray
    coefficients: np.ndarray
    amplitude: np.ndarray
    peak: np.ndarray
    periods: int
    converged: bool
    change: float
    n_events: int


class _Model:
    def __init__(self, system: System, omega: float):
        self.n = system.n_dof
        self.omega = omega
        self.Minv = np.linalg.inv(system.M)
        self.K, self.C = system.K, system.C
        self.Kb, self.Cb = system.Kb, system.Cb
        exc = system.excitation
        self.kind = exc.kind
        self.amp = np.asarray(exc.amplitude, dtype=float)
        rows = []
        for e in system.elements:
            for j in e.active_axes:
                rows.append((e.B[j], e.G[j], e.params.axes[j]))
        self.B = np.array([r[0] for r in rows]).reshape(len(rows), self.n)
        self.G = np.array([r[1] for r in rows]).reshape(len(rows), system.n_base)
        self.p = [r[2] for r in rows]
        general = [f"{e.name} {AXES[j]}" for e in system.elements
                   for j in e.active_axes if e.params.axes[j].friction
                   and e.params.axes[j].general_friction]
        if general:
            raise ValueError(
                f"the event-exact reference integrates the symmetric macro-slip "
                f"element only; axes {', '.join(general)} have sliders > 1, "
                f"fs_ratio != 1 or the inclined element (use the co-simulation, "
                f"vehicle.steady_state)")
        self.friction = [p.friction for p in self.p]
        # kinks of each law (the registry's knees: +-delta for the symmetric
        # piecewise law, +delta and -delta_neg for the asymmetric one)
        self.knees = [p.elastic.knees(p) if p.elastic.nonlinear(p) else ()
                      for p in self.p]
        self.n_ax = len(rows)
        # discrete state
        self.mode = [0] * self.n_ax   # 0 stuck, +-1 slipping
        self.w = [0.0] * self.n_ax
        self.side = [[0] * len(k) for k in self.knees]  # knee sides (+1 above)

    def base(self, t):
        if self.kind != "base":
            return None, None
        s, c = math.sin(self.omega * t), math.cos(self.omega * t)
        return self.amp * s, self.amp * (self.omega * c)

    def uv(self, t, z):
        q, qd = z[: self.n], z[self.n:]
        u = self.B @ q
        v = self.B @ qd
        y, yd = self.base(t)
        if y is not None:
            u = u - self.G @ y
            v = v - self.G @ yd
        return u, v, y, yd

    def axis_forces(self, u, v):
        F = np.empty(self.n_ax)
        for a in range(self.n_ax):
            p = self.p[a]
            f, _ = elastic_force(float(u[a]), p)
            f += p.c * float(v[a])
            if self.friction[a]:
                if self.mode[a] == 0:
                    f += p.kf * (float(u[a]) - self.w[a])
                else:
                    f += self.mode[a] * p.fs
            F[a] = f
        return F

    def rhs(self, t, z):
        q, qd = z[: self.n], z[self.n:]
        u, v, y, yd = self.uv(t, z)
        rhs = -(self.K @ q) - (self.C @ qd) - self.B.T @ self.axis_forces(u, v)
        s = math.sin(self.omega * t)
        if self.kind == "force":
            rhs += self.amp * s
        elif self.kind == "unbalance":
            rhs += (self.omega ** 2) * self.amp * s
        else:
            rhs += self.Kb @ y + self.Cb @ yd
        return np.concatenate([qd, self.Minv @ rhs])

    def init_discrete(self, t, z):
        u, v, _, _ = self.uv(t, z)
        for a, p in enumerate(self.p):
            if self.friction[a]:
                trial = p.kf * float(u[a])
                if abs(trial) > p.fs:
                    s = 1 if trial > 0 else -1
                    self.w[a] = float(u[a]) - s * p.fs / p.kf
                    self.mode[a] = s if float(v[a]) * s > 0 else 0
                else:
                    self.w[a], self.mode[a] = 0.0, 0
            self.side[a] = [1 if u[a] > level else -1 for level in self.knees[a]]

    def events(self):
        """Event functions of the current phase, with their meaning."""
        evs, meta = [], []
        for a, p in enumerate(self.p):
            if self.friction[a]:
                if self.mode[a] == 0:
                    for s in (1, -1):
                        def g(t, z, a=a, s=s, p=p):
                            u = self.uv(t, z)[0][a]
                            return p.kf * (u - self.w[a]) - s * p.fs
                        g.terminal, g.direction = True, s
                        evs.append(g)
                        meta.append(("slip", a, s))
                else:
                    s = self.mode[a]

                    def g(t, z, a=a):
                        return self.uv(t, z)[1][a]
                    g.terminal, g.direction = True, -s
                    evs.append(g)
                    meta.append(("stick", a, s))
            for k, level in enumerate(self.knees[a]):
                def g(t, z, a=a, level=level):
                    return self.uv(t, z)[0][a] - level
                g.terminal, g.direction = True, -self.side[a][k]
                evs.append(g)
                meta.append(("knee", a, k))
        return evs, meta

    def switch(self, meta, t, z):
        kind, a, s = meta
        p = self.p[a]
        if kind == "slip":
            self.mode[a] = s
        elif kind == "stick":
            u = self.uv(t, z)[0][a]
            self.w[a] = float(u) - s * p.fs / p.kf
            self.mode[a] = 0
        else:
            self.side[a][s] = -self.side[a][s]


class _Run(NamedTuple):
    """Periods integrated: the dense segments of the last one, convergence."""

    periods: int
    segments: list
    converged: bool
    change: float
    n_events: int


def _period(model: _Model, z: np.ndarray, t: float, t_end: float, T: float,
            options: dict):
    """Integrate one period from ``t`` to ``t_end``, stopping at every event to switch
    the phase; returns ``(z at t_end, dense segments, events)``."""
    segments = []
    events = 0
    guard = 0
    while t < t_end - 1e-14 * T:
        evs, meta = model.events()
        sol = solve_ivp(model.rhs, (t, t_end), z, events=evs or None, **options)
        segments.append((sol.t[0], sol.t[-1], sol.sol))
        z = sol.y[:, -1].copy()
        t = float(sol.t[-1])
        if sol.status == 1:
            hits = [i for i, te in enumerate(sol.t_events) if len(te)]
            for i in hits:
                if abs(sol.t_events[i][0] - t) <= 1e-12 * T:
                    model.switch(meta[i], t, z)
                    events += 1
            guard += 1
            if guard > 10000:
                raise RuntimeError("event chattering: more than 10000 events in "
                                   "one period")
        elif sol.status < 0:
            raise RuntimeError(f"integration failed: {sol.message}")
    return z, segments, events


def _integrate(model: _Model, z0: np.ndarray, T: float, scale_q: float, omega: float,
               max_periods: int, tol: float, options: dict) -> _Run:
    """Periods until the state at the period boundary repeats (with a geometric
    extrapolation of the remaining transient) or ``max_periods``."""
    n = model.n
    z = z0.copy()
    prev_end = None
    prev_change = None
    n_events = 0
    converged = False
    change = np.inf
    k = 0
    segments = []
    for k in range(1, max_periods + 1):
        z, segments, events = _period(model, z, (k - 1) * T, k * T, T, options)
        n_events += events
        state = np.concatenate([z[:n] / scale_q, z[n:] / (omega * scale_q)])
        if prev_end is not None:
            change = float(np.abs(state - prev_end).max())
            rho = change / prev_change if prev_change else 1.0
            remaining = change * rho / (1.0 - rho) if rho < 0.95 else np.inf
            if change < tol and (remaining < tol or change < 1e-3 * tol):
                converged = True
                break
            prev_change = change
        prev_end = state
    return _Run(k, segments, converged, change, n_events)


def periodic_response(system: System, freq_hz: float, *, harmonics: int = 15,
                      initial="linear", max_periods: int = 2000, tol: float = 1e-8,
                      rtol: float = 1e-10, atol: float | None = None,
                      n_out: int = 1024) -> ReferenceResult:
    """Periodic steady state at ``freq_hz`` by event-exact time integration.

    Parameters
    ----------
    system : System
    freq_hz : float
        Excitation frequency, Hz (> 0).
    harmonics : int
        Harmonics kept in ``coefficients``.
    initial : ``"linear"``, ``"rest"`` or (q0, qd0)
        Initial state: the free-slider linear steady state at t = 0 (default), rest, or
        given arrays. Sliders start at ``w = 0`` (slipping at once if the initial
        deflection exceeds Fs/kf).
    max_periods : int
        Give up (``converged=False``) after this many periods.
    tol : float
        Relative period-to-period change of the state (extrapolated to the end of the
        transient) that counts as periodic.
    rtol, atol : float
        Integrator tolerances (atol default: 1e-12 times the linear response scale).
    n_out : int
        Samples of the last period.

    Returns
    -------
    ReferenceResult
    """
    if not (isinstance(freq_hz, (int, float, np.floating)) and math.isfinite(freq_hz)
            and freq_hz > 0):
        raise ValueError(f"`freq_hz` must be a finite frequency > 0, got {freq_hz!r}")
    omega = 2.0 * math.pi * float(freq_hz)
    T = 1.0 / float(freq_hz)
    n = system.n_dof
    Q = linear_frf(system, [freq_hz])[0]
    scale_q = max(float(np.abs(Q).max()), 1e-12)
    if isinstance(initial, str):
        if initial == "linear":
            z0 = np.concatenate([Q.imag, omega * Q.real])
        elif initial == "rest":
            z0 = np.zeros(2 * n)
        else:
            raise ValueError(f"`initial` must be 'linear', 'rest' or (q0, qd0), "
                             f"got {initial!r}")
    else:
        z0 = np.concatenate([np.asarray(initial[0], float), np.asarray(initial[1],
                                                                       float)])
        if z0.shape != (2 * n,):
            raise ValueError(f"`initial` must hold two arrays of length {n}")
    if atol is None:
        atol = 1e-12 * scale_q
    atol_v = np.concatenate([np.full(n, atol), np.full(n, atol * omega)])
    model = _Model(system, omega)
    model.init_discrete(0.0, z0)
    run = _integrate(model, z0, T, scale_q, omega, max_periods, tol,
                     dict(method="DOP853", rtol=rtol, atol=atol_v, dense_output=True))
    k, segments = run.periods, run.segments
    converged, change, n_events = run.converged, run.change, run.n_events
    t0 = (k - 1) * T
    ts = t0 + T * np.arange(n_out) / n_out
    q = np.empty((n_out, n))
    for a, b, f in segments:
        sel = (ts >= a) & (ts <= b)
        if np.any(sel):
            q[sel] = f(ts[sel])[:n].T
    c = np.fft.rfft(q, axis=0) / n_out
    H = min(harmonics, n_out // 2 - 1)
    coef = np.empty((n, 2 * H + 1))
    coef[:, 0] = c[0].real
    coef[:, 1::2] = 2 * c[1:H + 1].real.T
    coef[:, 2::2] = -2 * c[1:H + 1].imag.T
    return ReferenceResult(freq_hz=float(freq_hz), t=ts, q=q, coefficients=coef,
                           amplitude=np.hypot(coef[:, 1], coef[:, 2]),
                           peak=np.abs(q).max(axis=0), periods=k, converged=converged,
                           change=change, n_events=n_events)
