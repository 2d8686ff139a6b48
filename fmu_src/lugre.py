"""The LuGre friction element (``friction_kind = "lugre"``): the bristle model of
Canudas de Wit, Olsson, Astrom & Lischinsky (1995), docs/physics.md "LuGre friction".

The mean bristle deflection z (m) follows the sliding velocity v (m/s) through

    dz/dt = v - sigma0 |v| z / g(v),   g(v) = Fc + (Fs - Fc) exp(-(v / vs)^2)

and the friction force is ``F = sigma0 z + sigma1 dz/dt + sigma2 v``: sigma0 = ``kf``
the bristle stiffness (N/m), sigma1 the bristle damping and sigma2 the viscous
friction (N s/m), Fc = mu n the Coulomb force, Fs = ``stribeck_ratio`` * Fc the
static (breakaway) force and vs = ``v_stribeck`` the Stribeck velocity.

One increment from the committed state (z0, uc) to the deflection u over dt seconds
is integrated exactly for a constant rate r = (u - uc) / dt (u linear in time over
the step, as the FMU's inputs are): with q = |u - uc|, s = sign(u - uc) and
g = g(r) (g = Fc at dt = 0: an instantaneous jump),

    z = s g / sigma0 + (z0 - s g / sigma0) exp(-sigma0 q / g)

(an exponential integrator: stable for any step, exact for rate-independent g).
The force is evaluated at the end of the increment with the input rate ``v``:
dz/dt = v - sigma0 |v| z / g(v). The tangents dF/du and dF/dv are exact
derivatives of that map (dF/du = 1 * (sigma0 - sigma1 sigma0 |v| / g(v)) at a step
without motion). The dissipated energy is the bristle's exact part over the
increment, ``int sigma0 z du - sigma0 (z^2 - z0^2) / 2`` (>= 0), plus
``(sigma1 dz/dt + sigma2 v) v dt`` of the damping terms at the end of the step;
their sum is clamped at 0 (sigma1 dz/dt v < 0 where the bristle unloads faster than
the contact moves: the model is passive only for a small enough sigma1, Olsson 1996).
A lost contact (n <= 0) drops the force and releases the bristle energy. With
sigma1 = sigma2 = 0 and stribeck_ratio = 1 the element is the Dahl element. The
state is :class:`LuGreState`. Standard library only.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .friction import ElementStep, Field, FrictionElement, finite_rule
from .jenkins import JENKINS, contact_normal_forces

__all__ = ["LUGRE", "LuGreState"]

_new = tuple.__new__


class LuGreState(NamedTuple):
    """Committed state: the bristle deflection ``z`` (m) and deflection ``uc`` (m)."""

    z: float
    uc: float


def _stribeck(v: float, fc: float, dfs: float, vs: float) -> tuple[float, float]:
    """g(v) (N) and dg/dv (N s/m) of the Stribeck curve, dfs = Fs - Fc."""
    x = v / vs
    e = math.exp(-(x * x))
    if e == 0.0:
        return fc, 0.0
    return fc + dfs * e, dfs * e * (-2.0 * x / vs)


def _bristle(z0, du, dt, p, fc, dfs):
    """``(z, dz/du, dissipated)`` of the bristle over the increment du (m)."""
    if du == 0.0:
        return z0, 1.0, 0.0
    s0 = p.kf
    if dt > 0.0:
        g, gr = _stribeck(du / dt, fc, dfs, p.v_stribeck)
        gu = gr / dt
    else:   # an instantaneous jump: the Coulomb level
        g, gu = fc, 0.0
    s = 1.0 if du > 0.0 else -1.0
    q = abs(du)
    zss = s * g / s0
    e = math.exp(-s0 * q / g)
    z1 = zss + (z0 - zss) * e
    de = e * (s0 * q * gu / (g * g) - s0 * s / g)
    dz = s * gu / s0 * (1.0 - e) + (z0 - zss) * de
    work = s * (s0 * zss * q + (z0 - zss) * g * (1.0 - e))
    return z1, dz, work - s0 * (z1 * z1 - z0 * z0) / 2.0


def _bind(p):
    kf, mu, sg1, sg2 = p.kf, p.mu, p.sigma1, p.sigma2
    ratio, vs = p.stribeck_ratio, p.v_stribeck

    def step(state, u, v, n, dt):
        z0, uc = state
        fc = mu * n if n > 0.0 else 0.0
        du = u - uc
        if fc <= 0.0:   # lost contact: no force, the bristle energy is released
            return _new(ElementStep, (0.0, _new(LuGreState, (0.0, u)), 0.0, 0.0,
                                      du != 0.0, kf * z0 * z0 / 2.0))
        dfs = ratio * fc - fc
        z1, dz, diss = _bristle(z0, du, dt, p, fc, dfs)
        gv, gvp = _stribeck(v, fc, dfs, vs)
        av = abs(v)
        zdot = v - kf * av * z1 / gv
        force = kf * z1 + sg1 * zdot + sg2 * v
        sv = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
        df_du = (kf - sg1 * kf * av / gv) * dz
        df_dv = sg1 * (1.0 - kf * z1 * (sv / gv - av * gvp / (gv * gv))) + sg2
        diss += (sg1 * zdot + sg2 * v) * v * dt
        return _new(ElementStep, (force, _new(LuGreState, (z1, u)), df_du, df_dv,
                                  du != 0.0, diss if diss > 0.0 else 0.0))
    return step


_FIELDS = (
    Field("sigma1", "Real", "N.s/m", 0.0, "finite and >= 0", finite_rule(">= 0"),
          "LuGre element: bristle damping sigma1, >= 0"),
    Field("sigma2", "Real", "N.s/m", 0.0, "finite and >= 0", finite_rule(">= 0"),
          "LuGre element: viscous friction sigma2, >= 0 (in parallel with c)"),
    Field("stribeck_ratio", "Real", "1", 1.0, "finite and > 0", finite_rule("> 0"),
          "LuGre element: static over Coulomb friction force Fs / Fc, > 0 (1: no "
          "Stribeck effect)"),
    Field("v_stribeck", "Real", "m/s", 0.01, "finite and > 0", finite_rule("> 0"),
          "LuGre element: Stribeck velocity vs, > 0"),
)


LUGRE = FrictionElement(
    name="lugre",
    summary="LuGre element (Canudas de Wit 1995): bristle dz/dt = v - kf |v| z / g(v), "
            "F = kf z + sigma1 dz/dt + sigma2 v, Stribeck curve g(v) from Fs to "
            "Fc = mu n",
    fields=tuple(f for f in JENKINS.fields if f.name in ("kf", "mu", "n0")) + _FIELDS,
    bind=_bind,
    state_size=lambda p: 2,
    start=lambda p, w=0.0: LuGreState(0.0, float(w)),
    position=lambda state: state.uc,
    stuck_stiffness=lambda p: p.kf,
    normal_forces=contact_normal_forces,
    rate_dependent=True,
    c_port="ml_lugre",
)
