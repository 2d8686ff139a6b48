"""Semi-active normal-force control in the co-simulation (vehicle.control)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.systems import sdof
from drymount.vehicle.control import Limits, GrowthControl, ScheduledControl
from drymount.vehicle.master import Master

#: the FMU evaluates the same law with the same inputs: measured 0 (bit-identical)
RTOL_FMU = 1e-12
#: rate limit: floating-point slack of n_prev + rate h, N
RATE_SLACK = 1e-9


def _system(n0=10.0):
    p = AxisParameters(law="piecewise", k1=45935.0, k2=256900.0, friction=True,
                       kf=60000.0, n0=n0)
    return sdof(70.0, MountParameters(axial=p), "unbalance", 0.030478)


def _run(system, control, backend="inproc", duration=0.6):
    with Master(system, backend, control=control) as m:
        th = m.simulate(duration, freq_hz=6.0)
        log = m.backend.control_log
    return th, log


def test_constant_schedule_equals_the_passive_mount_with_that_n0():
    table = ScheduledControl((1.0, 10.0), (25.0, 25.0), signal=lambda t: 6.0)
    th, log = _run(_system(10.0), {("mount", "axial"): table})
    ref, _ = _run(_system(25.0), None)
    # n starts at n0 = 10 N: one step at 25 N (no rate limit) then constant
    assert np.array_equal(th.q, ref.q) and np.array_equal(th.forces, ref.forces)
    t, n = log.arrays()
    assert np.all(n == 25.0) and len(t) == len(th.t)


def test_on_off_with_limits_fmu_equals_in_process():
    lim = Limits(n_min=2.0, n_max=40.0, rate_max=2.0e4)
    ctl = {("mount", "axial"): GrowthControl(n_on=60.0, n_off=0.0, limits=lim)}
    a, log_a = _run(_system(), ctl, "inproc")
    b, log_b = _run(_system(), ctl, "fmu")
    np.testing.assert_allclose(b.q, a.q, rtol=RTOL_FMU, atol=0)
    t, n = log_a.arrays()
    assert np.array_equal(n, log_b.arrays()[1])
    # limits hold: range, rate, and both states were used
    assert n.min() >= 2.0 and n.max() <= 40.0
    h = t[1] - t[0]
    assert np.max(np.abs(np.diff(n[:, 0]))) <= lim.rate_max * h + RATE_SLACK
    assert np.any(n == 40.0) and np.any(n == 2.0)
    # the on/off rule itself: with no limit, n = n_on exactly where u v > 0
    free = {("mount", "axial"): GrowthControl(n_on=60.0, n_off=5.0)}
    th, log = _run(_system(), free)
    _, n = log.arrays()
    u = th.deflections[:, 0]
    v = th.qd[:, 0]
    # n_on where u v > 0 at the step and its neighbours, n_off where it is <= 0
    # there; at a switch the step's command lies between (located in the step)
    on = u * v > 0.0
    inner_on = on[1:-1] & on[:-2] & on[2:]
    inner_off = ~(on[1:-1] | on[:-2] | on[2:])
    n = n[1:-1, 0]
    assert np.all(n[inner_on] == 60.0) and np.all(n[inner_off] == 5.0)
    assert np.all((n >= 5.0) & (n <= 60.0)) and inner_on.sum() > 100


def test_bad_control_is_refused_with_a_clear_message():
    with pytest.raises(ValueError, match="no active mount axis"):
        _run(_system(), {("mount", "radial1"): GrowthControl(10.0)})
    with pytest.raises(ValueError, match="`rate_max` must be > 0"):
        Limits(rate_max=0.0)
    with pytest.raises(ValueError, match="strictly increasing"):
        ScheduledControl((2.0, 1.0), (1.0, 2.0), signal=math.sin)
    with pytest.raises(ValueError, match="`n_on` must be finite and >= 0"):
        GrowthControl(-1.0)


CONTROL_TOML = """
model = "sdof"
name = "controlled"
[sdof]
mass = 70.0
[mount]
law = "linear"
k1 = 45935.0
c = 150.0
[mount.friction]
kf = 60000.0
n0 = 10.0
[excitation]
kind = "unbalance"
amplitude = 0.03
[control]
"""


def test_control_table_builds_controllers_and_checks_values():
    from drymount.config import ConfigError, load_config

    cfg = load_config(CONTROL_TOML + 'kind = "scheduled"\nschedule_hz = [2.0, 8.0]\n'
                      'schedule_n = [20.0, 4.0]\nn_max = 50.0\nrate_max = 1e4\n')
    ctl = cfg.control.controllers(cfg.system, lambda t: 5.0)
    c = ctl[("mount", "axial")]
    assert c.command(0.0, 0.0, 0.0) == pytest.approx(12.0)
    assert c.limits == Limits(0.0, 50.0, 1e4)
    cfg = load_config(CONTROL_TOML + 'kind = "growth"\nn_on = 30.0\n')
    c = cfg.control.controllers(cfg.system)[("mount", "axial")]
    assert (c.command(0, 1e-3, 1.0), c.command(0, 1e-3, -1.0)) == (30.0, 0.0)
    with pytest.raises(ConfigError) as err:
        load_config(CONTROL_TOML + 'kind = "scheduled"\nschedule_hz = [8.0, 2.0]\n'
                    'schedule_n = [1.0]\nn_min = 5.0\nn_max = 1.0\n'
                    'axes = ["mount.bogus"]\n')
    text = "\n".join(err.value.problems)
    assert "`control.schedule_hz` must be a non-empty array of finite strictly " \
           "increasing frequencies" in text
    assert "`control.n_max` must be >= control.n_min = 5.0 N, got 1.0" in text
    assert "`control.axes` must be a non-empty array of \"<mount>.<axis>\"" in text
    with pytest.raises(ConfigError, match="`control.n_on` is missing"):
        load_config(CONTROL_TOML + 'kind = "growth"\n')
    with pytest.raises(ConfigError, match="not friction axes"):
        load_config(CONTROL_TOML + 'kind = "growth"\nn_on = 3.0\n'
                    'axes = ["engine.axial"]\n')


def test_control_kinds_build_their_laws_and_onoff_names_its_new_name():
    from drymount.config import ConfigError, load_config
    from drymount.vehicle import control as vc

    for kind, law in (("balance", vc.BalanceControl), ("skyhook", vc.SkyhookControl),
                      ("growth", vc.GrowthControl)):
        cfg = load_config(CONTROL_TOML + f'kind = "{kind}"\nn_on = 30.0\n')
        c = cfg.control.controllers(cfg.system)[("mount", "axial")]
        assert type(c) is law and c.contact == (60000.0, 1.0)
        # the point law (h = 0): u > 0 and v < 0 is the returning deflection
        row = np.zeros(16)
        row[2 + 1] = -1.0  # vh of DOF x: the engine velocity -1 m/s
        on = c.command(0.0, 1e-3, -1.0, row, 0.0)
        assert on == (30.0 if kind in ("balance", "skyhook") else 0.0)
    with pytest.raises(ConfigError, match='"onoff" is now "growth"'):
        load_config(CONTROL_TOML + 'kind = "onoff"\nn_on = 3.0\n')
