"""Sampled (measured) inputs: a base displacement or DOF forces given as samples.

A measured signal comes at its own sample times; the master asks an input for values
on its step grid ``t0 + k dt``. These inputs **resample with a cubic spline**
(``scipy.interpolate.CubicSpline``, not-a-knot ends) through the samples: the spline
passes exactly through every sample, and the base velocity ``y'`` the equations of
motion need is the spline's derivative (twice continuously differentiable, so no
steps in velocity where a linear interpolant would have them). When the step is
shorter than the sample spacing this upsamples; when it is longer, the spline is
evaluated at the step times (no low-pass filter: content above the step's Nyquist
frequency ``1 / (2 dt)`` folds down, so sample the data at least as finely as the
step or filter it first). Outside the sampled time span the inputs hold the first or
last value (velocity 0): a run longer than the record raises ``ValueError`` instead
(``check_span``).

Public: :class:`SampledBase`, :class:`SampledForce`.
"""

from __future__ import annotations

import numpy as np

from .inputs import Input, _direction

__all__ = ["SampledBase", "SampledForce"]


def _spline_of(t, values, name: str):
    from scipy.interpolate import CubicSpline

    t = np.asarray(t, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise ValueError(f"`{name}` needs at least 4 samples (a cubic spline), got "
                         f"{t.size}")
    if v.shape[0] != t.size:
        raise ValueError(f"`{name}`: {v.shape[0]} values for {t.size} sample times")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
        raise ValueError(f"`{name}`: sample times and values must be finite")
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise ValueError(f"`{name}`: sample times must increase strictly; t[{k + 1}] "
                         f"= {t[k + 1]!r} s follows t[{k}] = {t[k]!r} s")
    return CubicSpline(t, v, axis=0, bc_type="not-a-knot", extrapolate=False)


class _Sampled:
    """The spline of one signal and its time span."""

    def __init__(self, t, values, name):
        self.spline = _spline_of(t, values, name)
        self.t_first = float(np.asarray(t, float)[0])
        self.t_last = float(np.asarray(t, float)[-1])
        self.name = name

    def check_span(self, t_end: float) -> None:
        """ValueError if a run to ``t_end`` s would leave the sampled span."""
        if self.t_first > 0 or t_end > self.t_last * (1 + 1e-12):
            raise ValueError(f"`{self.name}` covers {self.t_first:g}-{self.t_last:g} "
                             f"s; a run over 0-{t_end:g} s needs samples over all "
                             f"of it")

    def values(self, t, nu: int = 0) -> np.ndarray:
        tc = np.clip(t, self.t_first, self.t_last)
        out = self.spline(tc, nu)
        if nu:
            out = np.where(((t < self.t_first) | (t > self.t_last))
                           .reshape((-1,) + (1,) * (out.ndim - 1)), 0.0, out)
        return out


class SampledBase(Input):
    """Base (road or chassis) displacement from samples, along a base ``direction``.

    Parameters
    ----------
    system : hbm.system.System
    t : array_like, shape (n,)
        Sample times, s, strictly increasing (a road measured over distance ``x`` at
        speed ``v`` has ``t = x / v``).
    displacement : array_like, shape (n,)
        Base displacement (road elevation) at ``t``, m.
    direction : array_like, optional
        Base direction (default: the only base input, or ``chassis_z``).
    """

    def __init__(self, system, t, displacement, *, direction=None):
        super().__init__(system)
        self.direction = _direction(system, direction)
        self.signal = _Sampled(t, displacement, "displacement")
        self.span = (self.signal.t_first, self.signal.t_last)

    def check_span(self, t_end: float) -> None:
        """ValueError if the samples do not cover 0-``t_end`` s."""
        self.signal.check_span(t_end)

    def _base(self, t):
        r = self.signal.values(t)
        rd = self.signal.values(t, 1)
        d = self.direction[None, :]
        return r[:, None] * d, rd[:, None] * d


class SampledForce(Input):
    """Generalised forces on named DOFs from samples (engine forces and moments).

    Parameters
    ----------
    system : hbm.system.System
    t : array_like, shape (n,)
        Sample times, s, strictly increasing.
    forces : mapping
        DOF name -> samples at ``t`` (shape (n,)), N on a translation, N m on a
        rotation. DOFs not named get no force.
    """

    def __init__(self, system, t, forces):
        super().__init__(system)
        names = list(system.dof_names)
        if not forces:
            raise ValueError("`forces` must name at least one DOF")
        unknown = [k for k in forces if k not in names]
        if unknown:
            raise ValueError(f"`forces`: {unknown} are not DOFs of {system.name!r} "
                             f"(its DOFs: {names})")
        self.dofs = list(forces)
        self.index = [names.index(k) for k in self.dofs]
        values = np.column_stack([np.asarray(forces[k], float) for k in self.dofs])
        self.signal = _Sampled(t, values, "forces")
        self.span = (self.signal.t_first, self.signal.t_last)

    def check_span(self, t_end: float) -> None:
        """ValueError if the samples do not cover 0-``t_end`` s."""
        self.signal.check_span(t_end)

    def _force(self, t):
        out = np.zeros((t.size, self.n_dof))
        out[:, self.index] = self.signal.values(t)
        return out
