"""Floquet multipliers of the co-simulation by shooting (vehicle/floquet.py) against
the HBM's Floquet (Hill) multipliers on six_dof_halved's resonant branch, straddling
its Neimark-Sacker point (issue 29; HBM H = 5, N = 128: 9.48612 Hz; shooting located it
at 9.48627 / 9.48607 / 9.48611 Hz with 256 / 512 / 1024 steps per period)."""

import dataclasses

import numpy as np

from drymount.config import load_preset
from drymount.hbm.bifurcation import critical_exponent
from drymount.hbm.continuation import newton
from drymount.hbm.options import HBMOptions
from drymount.hbm.problem import build_problem
from drymount.vehicle.floquet import PeriodMap, complex_pair_modulus, shoot
from drymount.vehicle.steady import orbit_start

#: |mu| by shooting (256 steps) vs HBM H = 5 (measured 2.7e-3 and 3.8e-3)
MOD_TOL = 6e-3


def test_multiplier_modulus_straddles_one_in_both_methods():
    s = load_preset("six_dof_halved").system
    prob = build_problem(s, 9.4, 9.6, 5, 128)
    st = dataclasses.replace(HBMOptions().continuation_settings(), max_newton=60)
    hb, n = prob.hb, prob.hb.n
    y = prob.linear_guess(9.47, True)   # seed: the stuck linear shape at 40 mm in z
    a1 = np.hypot(*prob.x_of(y)[0].reshape(hb.m, n)[1:3])[2]
    y[n:-1] *= 0.04 / a1
    mods = {}
    for f in (9.47, 9.48, 9.49, 9.50):   # natural continuation along the branch
        y[-1] = 2 * np.pi * f / prob.ws
        y, ok, _, _ = newton(prob, y, st, fixed=hb.size)
        assert ok
        if f in (9.47, 9.50):
            X, w = prob.x_of(y)
            J = hb.residual(X, w)[1]
            mu_hbm = np.exp(critical_exponent(hb, J, w) * 2 * np.pi / w)
            c = X.reshape(hb.m, n).T
            o = orbit_start(s, c, f, 128)
            with PeriodMap(s, f, 256) as pm:
                z = pm.settle(pm.pack(o.q, o.qd, o.qdd, np.zeros((3, 3))), 10)
                r = shoot(pm, z)
            assert r.converged
            mu = complex_pair_modulus(r.multipliers)
            assert abs(abs(mu) - abs(mu_hbm)) <= MOD_TOL, (f, abs(mu), abs(mu_hbm))
            mods[f] = abs(mu)
    assert mods[9.47] < 1.0 < mods[9.50]
