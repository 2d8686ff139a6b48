"""Floquet multipliers of the co-simulation's periodic steady state, by shooting.

The harness (:class:`vehicle.master.Master`, in-process backend: the mount law of
``fmu_src``) over one excitation period is a map ``z -> P(z)`` of the integrator
state and the friction elements' sliders,

    z = (q, q', q'', w)        q', q'': the master's predicted rate and acceleration,
                               w: the sliders of the friction axes (their states)

(the leapfrog with a velocity predictor carries the acceleration from step to step,
so it is part of the state). A periodic steady state is a fixed point ``P(z*) = z*``,
found here by Newton's method on ``P(z) - z`` (shooting), with the Jacobian of the
map, the monodromy matrix, by finite differences of ``P`` (the map is piecewise
smooth: a slipping slider's return map forgets its committed position, so its column
is zero; a stuck one's carries it). Its eigenvalues are the Floquet multipliers of
the discrete-time orbit: they converge to the time-continuous ones as the step
shrinks (leapfrog, second order; a stick-slip switch lands on a step). A complex pair
crossing the unit circle is a Neimark-Sacker bifurcation of the periodic branch
(:func:`neimark_sacker`: secant/bisection on the largest modulus of the complex
pairs), the time-domain check of :mod:`hbm.bifurcation`'s Floquet (Hill) analysis.

Only friction elements whose state is their position (the macro-slip Jenkins
element: ``w_<axis>``) are supported, which is what the presets' 6-DOF engines have.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drymount.vehicle.inputs import HarmonicInput
from drymount.vehicle.master import DEFAULT_STEPS_PER_PERIOD, Master

__all__ = ["PeriodMap", "ShootingResult", "shoot", "complex_pair_modulus",
           "NeimarkSacker", "neimark_sacker"]

#: relative finite-difference step of the monodromy (times each component's scale)
FD_STEP = 1e-7
#: Newton stops when |P(z) - z| <= TOL times the state's scale (per component class)
TOL = 1e-11
MAX_NEWTON = 12
#: a multiplier counts as complex when |Im| exceeds this (0 < angle)
IMAG_MIN = 1e-6


class PeriodMap:
    """One period of the in-process harness at ``freq_hz`` with ``steps`` steps, as
    a map of the flat state ``z`` (:meth:`pack`/:meth:`unpack`).

    ``scale``: the typical size of each component (m, m/s, m/s^2, m) the finite
    differences and the convergence test are relative to.
    """

    def __init__(self, system, freq_hz: float, steps: int = DEFAULT_STEPS_PER_PERIOD):
        if not (isinstance(steps, (int, np.integer)) and steps >= 8):
            raise ValueError(f"`steps` must be an integer >= 8, got {steps!r}")
        if not (math.isfinite(freq_hz) and freq_hz > 0):
            raise ValueError(f"`freq_hz` must be a finite frequency > 0 Hz, got "
                             f"{freq_hz!r}")
        self.system = system
        self.freq_hz = float(freq_hz)
        self.steps = int(steps)
        self.h = 1.0 / (self.freq_hz * self.steps)
        self.master = Master(system, "inproc")
        self.inputs = HarmonicInput(system, self.freq_hz)
        self.friction = []
        for e, el in enumerate(system.elements):
            for j in el.active_axes:
                p = el.params.axes[j]
                if not p.friction:
                    continue
                if p.element.state_size(p) != 1 or p.element.name != "jenkins":
                    raise ValueError(
                        f"{el.name} axis {j}: the shooting map holds friction states "
                        f"that are one slider (the macro-slip Jenkins element); "
                        f"{p.friction_kind!r} with {p.element.state_size(p)} floats "
                        f"is not supported")
                self.friction.append((e, j))
        self.n = system.n_dof
        omega = 2 * math.pi * self.freq_hz
        self.scale = None
        self._omega = omega
        self.evaluations = 0

    def pack(self, q, qd, qdd, sliders) -> np.ndarray:
        """``z`` of a state (``sliders`` (n_mounts, 3), m)."""
        w = [float(sliders[e, j]) for e, j in self.friction]
        return np.concatenate([q, qd, qdd, w])

    def unpack(self, z):
        n = self.n
        W = np.zeros((len(self.system.elements), 3))
        for (e, j), x in zip(self.friction, z[3 * n:]):
            W[e, j] = x
        return z[:n], z[n:2 * n], z[2 * n:3 * n], W

    def set_scale(self, z) -> None:
        """Per-component scales from a state on (or near) the orbit: its DOFs'
        size for q and w, times omega and omega^2 for the rates."""
        n = self.n
        a = max(float(np.max(np.abs(z[:n]))), 1e-12)
        w = self._omega
        self.scale = np.concatenate([np.full(n, a), np.full(n, a * w),
                                     np.full(n, a * w * w),
                                     np.full(len(self.friction), a)])

    def __call__(self, z) -> np.ndarray:
        m = self.master
        q, qd, qdd, W = self.unpack(np.asarray(z, dtype=float))
        m.set_state(q, qd, qdd, sliders=W)
        m.begin_periodic(self.inputs, self.steps, self.h)
        m.run_period()
        self.evaluations += 1
        return self.pack(m.q, m.qd, m.qdd, m.sliders())

    def settle(self, z, periods: int) -> np.ndarray:
        """``periods`` applications of the map from ``z``."""
        for _ in range(periods):
            z = self(z)
        return z

    def monodromy(self, z, Pz=None) -> np.ndarray:
        """``dP/dz`` at ``z`` by central differences (steps ``FD_STEP * scale``)."""
        if self.scale is None:
            self.set_scale(z)
        J = np.empty((z.size, z.size))
        for i in range(z.size):
            d = FD_STEP * self.scale[i]
            zp, zm = z.copy(), z.copy()
            zp[i] += d
            zm[i] -= d
            J[:, i] = (self(zp) - self(zm)) / (2 * d)
        return J

    def close(self) -> None:
        self.master.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


@dataclass(frozen=True)
class ShootingResult:
    """A fixed point of the period map: the state ``z`` (see :class:`PeriodMap`),
    the monodromy matrix at it, its eigenvalues (the Floquet multipliers), the
    Newton iterations, the final defect ``|P(z) - z|`` relative to the scales and
    whether it met ``TOL``."""

    z: np.ndarray
    monodromy: np.ndarray
    multipliers: np.ndarray
    iterations: int
    defect: float
    converged: bool


def shoot(pm: PeriodMap, z0, tol: float = TOL, max_newton: int = MAX_NEWTON
          ) -> ShootingResult:
    """Newton's method on ``P(z) - z = 0`` from ``z0`` (the monodromy by finite
    differences at every iterate; a step that does not lower the defect is halved)."""
    z = np.asarray(z0, dtype=float).copy()
    if pm.scale is None:
        pm.set_scale(z)
    Pz = pm(z)
    defect = float(np.max(np.abs(Pz - z) / pm.scale))
    it = 0
    J = pm.monodromy(z)
    while defect > tol and it < max_newton:
        it += 1
        # least squares: a slider stuck for the whole period is a neutral direction
        # (multiplier 1, its offset a family of orbits), so J - I may be singular
        A = (J - np.eye(z.size)) * pm.scale
        dz = pm.scale * np.linalg.lstsq(A / pm.scale[:, None], -(Pz - z) / pm.scale,
                                        rcond=1e-12)[0]
        lam = 1.0
        while True:
            zn = z + lam * dz
            Pn = pm(zn)
            dn = float(np.max(np.abs(Pn - zn) / pm.scale))
            if dn < defect or lam < 1e-3:
                break
            lam *= 0.5
        z, Pz, defect = zn, Pn, dn
        J = pm.monodromy(z)
    mult = np.linalg.eigvals(J)
    return ShootingResult(z, J, mult, it, defect, defect <= tol)


def complex_pair_modulus(multipliers) -> complex:
    """The complex multiplier (Im > 0) of largest modulus: the pair whose crossing
    of the unit circle is a Neimark-Sacker bifurcation."""
    mu = np.asarray(multipliers)
    cands = mu[mu.imag > IMAG_MIN]
    if cands.size == 0:
        raise ValueError("no complex pair of multipliers")
    return complex(cands[int(np.argmax(np.abs(cands)))])


@dataclass(frozen=True)
class NeimarkSacker:
    """Where the complex pair crosses the unit circle: ``freq_hz`` (bracketed by
    ``bracket`` to ``tol_hz``), the critical multiplier there and the shootings
    ``{freq: ShootingResult}`` it took."""

    freq_hz: float
    bracket: tuple[float, float]
    multiplier: complex
    shots: dict


def neimark_sacker(system, f_lo: float, f_hi: float, z_lo, *,
                   steps: int = DEFAULT_STEPS_PER_PERIOD, tol_hz: float = 1e-4,
                   max_iter: int = 30) -> NeimarkSacker:
    """Locate the frequency in ``[f_lo, f_hi]`` where the largest complex pair of
    Floquet multipliers of the periodic branch through ``z_lo`` (a state on it at
    ``f_lo``) reaches modulus 1: shooting at each frequency from the nearest
    shot's orbit (natural continuation), secant on ``|mu| - 1`` safeguarded by
    bisection of the bracket until it is narrower than ``tol_hz``."""
    shots = {}

    def g(f, z_start):
        with PeriodMap(system, f, steps) as pm:
            r = shoot(pm, z_start)
        if not r.converged:
            raise RuntimeError(f"shooting at {f:.6f} Hz did not converge (defect "
                               f"{r.defect:.3g})")
        shots[f] = r
        return abs(complex_pair_modulus(r.multipliers)) - 1.0

    def nearest(f):
        return shots[min(shots, key=lambda x: abs(x - f))].z

    a, b = float(f_lo), float(f_hi)
    ga = g(a, z_lo)
    gb = g(b, nearest(b))
    if ga * gb > 0:
        raise ValueError(f"no crossing of the unit circle between {a} and {b} Hz "
                         f"(|mu| - 1 = {ga:.3g}, {gb:.3g})")
    for _ in range(max_iter):
        if b - a <= tol_hz:
            break
        f = b - gb * (b - a) / (gb - ga)      # secant (regula falsi) ...
        if not (a + 0.1 * (b - a) < f < b - 0.1 * (b - a)):
            f = 0.5 * (a + b)                 # ... kept off the ends by bisection
        gf = g(f, nearest(f))
        if gf * ga > 0:
            a, ga = f, gf
        else:
            b, gb = f, gf
        if abs(gf) < 1e-12:
            a = b = f
            break
    f = a - ga * (b - a) / (gb - ga) if b > a else a
    mu = complex_pair_modulus(shots[min(shots, key=lambda x: abs(x - f))].multipliers)
    return NeimarkSacker(float(f), (a, b), mu, shots)
