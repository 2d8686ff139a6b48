"""Switching control laws in the co-simulation against an event-exact reference.

The reference is written here from the equations (not drymount's stepping): the
single-DOF engine ``m x'' + c x' + k x + F_fr = f0 w^2 sin(w t)`` on a linear mount
with a macro-slip contact (stick: ``F_fr = kf (x - w)``; slip: ``F_fr = mu n sign``),
classical RK4 at a fine fixed step (1/16 of drymount's) with every event located to
round-off by bisection inside the step: the law's switching surfaces (``x = 0``,
``v = 0``), stick to slip (``|kf (x - w)| = mu n``) and slip to stick (``v = 0``).
At an event the contact follows the return map at fixed ``x``: a force above the new
slip force drops to it; a contact moving along its force slips, else it sticks.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.systems import sdof
from drymount.vehicle import control as vc
from drymount.vehicle.master import Master

M, K, C, KF, MU, F0 = 70.0, 45935.0, 150.0, 60000.0, 1.0, 0.030478
FREQ, PERIODS, N_ON, N0 = 4.2, 34, 30.0, 10.0
#: issue 26: the co-simulation within 0.2 % of peak of the reference at the
#: default step (measured 3.2e-4 balance, 3.1e-4 growth, 1.4e-4 scheduled and
#: skyhook; growth without the located stick point was 4.3e-2)
RTOL_PEAK = 2e-3
#: steps of the reference per drymount step
FINE = 16

LAWS = {  # predicate of (x, v): contact on
    "balance": lambda x, v: x * v < 0.0,
    "growth": lambda x, v: x * v > 0.0,
    # chassis fixed: va = v, on but at isolated instants (and at the start from
    # rest, where the first motion is along the contact's force)
    "skyhook": lambda x, v: v * v >= 0.0,
    "scheduled": lambda x, v: True,            # a table constant at FREQ
}


def _system():
    p = AxisParameters(law="linear", k1=K, c=C, friction=True, kf=KF, mu=MU, n0=N0)
    return sdof(M, MountParameters(axial=p), "unbalance", F0)


class _Reference:
    """State ``x, v``, contact ``stuck`` at ``w`` or slipping along ``sgn``."""

    def __init__(self, on):
        self.on_rule, self.om = on, 2 * math.pi * FREQ
        self.x = self.v = 0.0
        self.on = on(0.0, 0.0)
        self.stuck, self.w, self.sgn = self.fs() > 0, 0.0, 1.0

    def fs(self, on=None):
        return MU * (N_ON if (self.on if on is None else on) else 0.0)

    def friction(self, x):
        return KF * (x - self.w) if self.stuck else self.sgn * self.fs()

    def acc(self, t, x, v):
        f = F0 * self.om ** 2 * math.sin(self.om * t)
        return (f - K * x - C * v - self.friction(x)) / M

    def rk4(self, t, x, v, h):
        a1 = self.acc(t, x, v)
        a2 = self.acc(t + h / 2, x + h / 2 * v, v + h / 2 * a1)
        a3 = self.acc(t + h / 2, x + h / 2 * (v + h / 2 * a1), v + h / 2 * a2)
        a4 = self.acc(t + h, x + h * (v + h / 2 * a2), v + h * a3)
        x4 = x + h * v + h * h / 6 * (a1 + a2 + a3)
        return x4, v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)

    def events(self, x, v):
        g = [x, v]
        if self.stuck and self.fs() > 0:
            g += [KF * (x - self.w) - self.fs(), KF * (x - self.w) + self.fs()]
        return g

    def step(self, t, h):
        """Advance by ``h``, splitting at every event."""
        end = t + h
        while end - t > 1e-15:
            g0 = self.events(self.x, self.v)
            x1, v1 = self.rk4(t, self.x, self.v, end - t)
            g1 = self.events(x1, v1)
            hit = [i for i, (a, b) in enumerate(zip(g0, g1)) if a != 0 and a * b <= 0]
            if not hit:
                self.x, self.v, t = x1, v1, end
                continue
            lo, hi = 0.0, end - t
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                xm, vm = self.rk4(t, self.x, self.v, mid)
                gm = self.events(xm, vm)
                if any(g0[i] * gm[i] <= 0 for i in hit):
                    hi = mid
                else:
                    lo = mid
            self.x, self.v = self.rk4(t, self.x, self.v, hi)
            t += hi
            self.event(t)

    def event(self, t):
        """Law and contact at an event (the return map at fixed x)."""
        tiny = 1e-9
        a = self.acc(t, self.x, self.v)
        xa, va = self.x + tiny * self.v, self.v + tiny * a  # just after
        f = self.friction(self.x)  # with the law before the event
        self.on = self.on_rule(xa, va)
        fs = self.fs()
        f = max(-fs, min(fs, f))
        d = math.copysign(1.0, va)
        if fs == 0.0 or (abs(f) >= fs * (1 - 1e-12) and d * f > 0):
            self.stuck, self.sgn = False, d
        else:
            self.stuck, self.w = True, self.x - f / KF


def _controller(name, system):
    contact = vc.macro_slip_contact(system, "mount", "axial")
    if name == "balance":
        return vc.BalanceControl(N_ON, 0.0, contact=contact)
    if name == "growth":
        return vc.GrowthControl(N_ON, 0.0, contact=contact)
    if name == "skyhook":
        velocity = vc.engine_velocity(system, "mount", "axial")
        return vc.SkyhookControl(N_ON, 0.0, contact=contact, velocity=velocity)
    return vc.ScheduledControl((1.0, 10.0), (N_ON, N_ON), signal=lambda t: FREQ)


@pytest.mark.parametrize("law", sorted(LAWS))
def test_switching_law_equals_the_event_exact_reference(law):
    system = _system()
    with Master(system, "inproc", control={("mount", "axial"): _controller(
            law, system)}) as m:
        th = m.simulate(PERIODS / FREQ, freq_hz=FREQ)
    n = m.steps_per_period(FREQ)
    h = th.t[1] - th.t[0]
    ref = _Reference(LAWS[law])
    xr = [0.0]
    for k in range(len(th.t) - 1):
        for j in range(FINE):
            ref.step(th.t[k] + j * h / FINE, h / FINE)
        xr.append(ref.x)
    xr = np.array(xr)[-n:]
    x = th.q[-n:, 0]
    peak = np.max(np.abs(xr))
    assert np.max(np.abs(x - xr)) <= RTOL_PEAK * peak
