"""The inclined element of Ch. 5 as a friction kind of a mount axis: the one law
(``fmu_src.mount_law.axis_force``), the harness's backends (native and the
FrictionMount FMU), the configuration, and the refusals (batch, control).

References: ``fmu_src.inclined.inclined_update`` stepped by hand on the trajectory the
master produced (the element coordinates x = -u, axis force -N2), and the static
equilibrium written out by hand. About 20 s (FMU co-simulations of the SDOF, the
quarter car and the 6-DOF engine).
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from drymount.config import ConfigError, load_preset
from drymount.paths import override_config
from drymount.fmu_src.inclined import inclined_forces, inclined_update
from drymount.fmu_src.mount_law import (AxisParameters, MountParameters, ParameterError,
                               axis_force, initial_sliders, mean_slider,
                               normal_forces, static_force)
from drymount.hbm.static import working_point
from drymount.hbm.systems import quarter_car, sdof
from drymount.vehicle.master import Master, simulate

#: master (native / FMU) vs the hand-stepped map, N (measured 0: the same operations)
HAND_TOL = 1e-12
#: static equilibrium residual, N (measured ~1e-13)
STATIC_TOL = 1e-9
#: dynamic stiffness by AFT / time march / FMU, relative (measured below)
CHARACTERISE_TOL = 1e-9

AXIS = AxisParameters(law="linear", k1=45935.0, k2=45935.0, c=150.0, friction=True,
                      friction_kind="inclined", theta_deg=60.0, k=2e4, kf=6e4,
                      kf2=5e4, mu1=0.3, mu2=0.25, preload=200.0)
BARE = AxisParameters(law="linear", k1=45935.0, k2=45935.0, c=150.0)


def _sdof(weight=0.0):
    s = sdof(70.0, MountParameters(AXIS, BARE, BARE), "force", 150.0)
    return replace(s, static_load=np.array([-weight])) if weight else s


def _hand_march(u, p, u0=0.0, start=None):
    """Element force on the axis, stepped by hand with inclined_update, from the
    element relaxed at u0 or from the state ``start`` (w1, w2, uc)."""
    s, c = math.sin(math.radians(p.theta_deg)), math.cos(math.radians(p.theta_deg))
    w1, w2, x_old = -u0 / s, -u0 * c / s, -u0
    if start is not None:
        w1, w2, x_old = start[0], start[1], -start[2]
    out = []
    for ui in u:
        st = inclined_update(-ui, x_old, w1, w2, p.inclined)
        w1, w2, x_old = st.w1, st.w2, -ui
        out.append(-st.force)
    return np.array(out)


@pytest.mark.parametrize("backend", ["inproc", "fmu"])
def test_master_equals_the_hand_stepped_map(backend):
    th = simulate(_sdof(), 8.0, 0.5, backend=backend)
    u = th.deflections[:, 0]
    ref = _hand_march(u, AXIS)
    assert np.abs(th.friction_forces[:, 0] - ref).max() <= HAND_TOL
    # the element slipped and its normal force varied (not a trivial trajectory)
    assert np.ptp(th.friction_forces[:, 0]) > 100.0


def test_fmu_and_native_agree_under_the_weight_from_the_working_point():
    s = _sdof(70.0 * 9.81)
    a = simulate(s, 7.0, 0.4, backend="inproc")
    b = simulate(s, 7.0, 0.4, backend="fmu")
    assert np.abs(a.q - b.q).max() == 0.0
    # both start from the engine lowered onto the mount (the default reading): the
    # element's state there, sliders w1, w2 not relaxed (the FMU's w1_/w2_axial)
    start = working_point(s).states[(0, 0)]
    assert abs(start.w1 - (-start.uc) / math.sin(math.radians(60.0))) > 1e-4
    ref = _hand_march(a.deflections[:, 0], AXIS, start=start)
    assert np.abs(a.friction_forces[:, 0] - ref).max() <= HAND_TOL
    # relaxed reading: the element relaxed at its working point
    r = replace(s, static_reading="relaxed")
    a = simulate(r, 7.0, 0.4, backend="inproc")
    b = simulate(r, 7.0, 0.4, backend="fmu")
    assert np.abs(a.q - b.q).max() == 0.0
    u0 = working_point(r).deflection[0, 0]
    ref = _hand_march(a.deflections[:, 0], AXIS, u0)
    assert np.abs(a.friction_forces[:, 0] - ref).max() <= HAND_TOL


def test_static_working_point_balances_weight_with_the_relaxed_element():
    s = _sdof(70.0 * 9.81)
    u0 = working_point(s, "relaxed").deflection[0, 0]
    assert u0 < 0   # the weight compresses the mount and presses the wedge in
    f1, f2, n1, n2 = inclined_forces(-u0, *initial_sliders(AXIS, u0)[:2],
                                     AXIS.inclined)
    assert f1 == pytest.approx(0.0, abs=1e-9) and f2 == pytest.approx(0.0, abs=1e-9)
    assert abs(AXIS.k1 * u0 - n2 + 70.0 * 9.81) <= STATIC_TOL
    assert static_force(u0, AXIS)[0] == pytest.approx(AXIS.k1 * u0 - n2, abs=1e-9)


def test_axis_state_slider_value_and_normal_forces():
    w = initial_sliders(AXIS, -0.004)
    assert mean_slider(w) == -0.004
    r = axis_force(-0.006, 0.0, w, AXIS)
    assert mean_slider(r.w_new) == -0.006
    n1, n2 = normal_forces(AXIS, r.w_new)
    _, _, e1, e2 = inclined_forces(0.006, r.w_new.w1, r.w_new.w2, AXIS.inclined)
    assert (n1, n2) == (e1, e2)
    # the element pushes the sides apart; the state's stuck-regime forces reproduce
    # the slipping regime's (rounding: measured 6e-17 relative)
    assert r.friction_force == pytest.approx(-n2, rel=1e-13)


def test_parameter_checks_name_the_field():
    with pytest.raises(ParameterError, match=r"`theta_deg` must be in \(0, 90\]"):
        replace(AXIS, theta_deg=95.0)
    with pytest.raises(ParameterError, match="sliders = 1 and fs_ratio = 1"):
        replace(AXIS, sliders=4)
    with pytest.raises(ParameterError, match="friction_kind"):
        replace(AXIS, friction_kind="wedge")
    with pytest.raises(ParameterError, match="self-locks"):
        replace(AXIS, theta_deg=20.0, mu1=0.6, mu2=0.6)


def test_fmu_rejects_an_invalid_inclined_parameter_naming_it():
    with pytest.raises(Exception, match="axial_theta_deg"):
        with Master(_sdof(), "fmu",
                    fmu_start_values={"axial_theta_deg": 120.0}) as m:
            m.simulate(0.01, freq_hz=8.0)


def test_control_refuses_the_inclined_axis():
    """Its normal forces follow from its kinematics (the batched steady states run
    it: tests/test_vehicle_batch.py)."""
    with Master(_sdof(), "inproc") as m:
        with pytest.raises(ValueError, match="does not read the normal-force input"):
            m.backend.set_control({("mount", "axial"): object()})


def test_config_preset_and_set_paths():
    cfg = load_preset("sdof_inclined")
    p = cfg.system.elements[0].params.axial
    assert p.inclined is not None and p.inclined.theta_deg == 60.0
    p2 = override_config(cfg, ["mount.friction.theta_deg=75", "mount.friction.k=3e4"]
                         ).system.elements[0].params.axial
    assert (p2.theta_deg, p2.k) == (75.0, 3e4)
    with pytest.raises(ConfigError) as err:
        override_config(cfg, ["mount.friction.n0=100"])
    assert "`mount.friction.n0`" in str(err.value)
    assert "belongs to the friction element 'jenkins'" in str(err.value)
    with pytest.raises(ConfigError, match=r"`mount.friction.theta_deg` must be in"):
        override_config(cfg, ["mount.friction.theta_deg=120"])


def test_quarter_car_with_an_inclined_mount_runs_on_both_backends():
    mount = MountParameters(AXIS, BARE, BARE)
    s = quarter_car(70.0, 250.0, 40.0, 20000.0, 1000.0, 180000.0, 0.0, mount, 0.01)
    a = simulate(s, 6.0, 0.2, backend="inproc")
    b = simulate(s, 6.0, 0.2, backend="fmu")
    assert np.abs(a.q - b.q).max() == 0.0
    ref = _hand_march(a.deflections[:, 0], AXIS)
    assert np.abs(a.friction_forces[:, 0] - ref).max() <= HAND_TOL


def test_dynamic_stiffness_of_an_inclined_axis_aft_time_march_and_fmu():
    from drymount.characterise import fmu_stiffness
    from drymount.fmu_build import ensure_fmu
    from drymount.hbm.characterise import (rate_independent_stiffness,
                                           time_domain_stiffness)

    U0, X, f = -0.01, 0.003, 5.0
    k_time = time_domain_stiffness(AXIS, f, X, U0, steps_per_period=1024)
    k_aft = rate_independent_stiffness(AXIS, X, U0, n_samples=1024) \
        + 1j * AXIS.c * 2 * math.pi * f
    k_fmu = fmu_stiffness(ensure_fmu(), AXIS, f, X, U0, steps_per_period=1024)
    # the AFT march and the time march sample the same law at the same phases
    # (measured 4.7e-16 relative); the FMU is the same law (measured 0)
    assert abs(k_aft - k_time) <= CHARACTERISE_TOL * abs(k_time)
    assert abs(k_fmu - k_time) <= CHARACTERISE_TOL * abs(k_time)
    assert k_time.imag > AXIS.c * 2 * math.pi * f   # friction dissipates


def test_six_dof_engine_on_inclined_mounts_native_equals_fmu():
    import copy

    from drymount.config import config_from_dict

    data = copy.deepcopy(load_preset("six_dof_halved").data)
    table = {"kind": "inclined", "theta_deg": 60.0, "k": 2e4, "kf": 6e4, "kf2": 6e4,
             "mu1": 0.3, "mu2": 0.3, "preload": 200.0}
    for m in data["mounts"]:
        m["axial"]["friction"] = dict(table)
    data["static"] = {"gravity": True}
    data["excitation"]["amplitude"] = [0.0, 0.0, 0.001]
    s = config_from_dict(data).system
    a = simulate(s, 7.0, 0.2, backend="inproc")
    b = simulate(s, 7.0, 0.2, backend="fmu")
    assert np.abs(a.q - b.q).max() == 0.0
    col = list(a.force_names).index("mount3_axial")
    p = s.elements[2].params.axial
    # from the engine lowered onto its mounts (the default reading's states)
    ref = _hand_march(a.deflections[:, col], p, start=working_point(s).states[(2, 0)])
    assert np.abs(a.friction_forces[:, col] - ref).max() <= HAND_TOL


@pytest.mark.parametrize("build", ["python", "native"])
def test_bonded_surface_mu_inf_through_both_fmus(build, tmp_path):
    """mu1 = inf (a bonded inclined surface) is set through FMI (the one Real that may
    be infinite, docs/fmu.md 4a) and the FMU equals the hand-stepped map."""
    bonded = replace(AXIS, mu1=math.inf)
    # 40 N about the working point under the weight: the wedge keeps contact
    s = sdof(70.0, MountParameters(bonded, BARE, BARE), "force", 40.0)
    s = replace(s, static_load=np.array([-70.0 * 9.81]))
    fmu = None
    if build == "native":
        from native_helpers import build as build_native
        fmu = build_native(tmp_path, 2)
    th = simulate(s, 8.0, 0.3, backend="fmu", fmu_path=fmu)
    # from the engine lowered onto the mount (w1_/w2_axial set through FMI)
    start = working_point(s).states[(0, 0)]
    ref = _hand_march(th.deflections[:, 0], bonded, start=start)
    assert np.abs(th.friction_forces[:, 0] - ref).max() <= HAND_TOL
    assert np.ptp(th.friction_forces[:, 0]) > 100.0
