"""Nonlinear modes by EPMC (hbm.modes) against closed forms and eigen-solutions.

References written here:
- Duffing oscillator, single-harmonic backbone ``w^2 = w0^2 + 3/4 kc X^2 / m``
  (X the displacement amplitude; the modal amplitude of one DOF is ``sqrt(m) X``);
- Jenkins element on a linear spring, its describing function (PHYSICS.md section 6,
  with a2 = arcsin(1 - 2 Fs/(kf X))): in-phase ``F_s = (kf X/pi)(pi/2 - a2 - sin a2
  cos a2)``, dissipative ``F_c = (4 Fs/pi)(1 - Fs/(kf X))``; by the energy balance
  over a period the EPMC gives ``m w^2 = k1 + F_s/X`` and ``xi = c/m + F_c/(m w X)``,
  ``D = xi / (2 w)``;
- linear systems: undamped eigen-solution of (K, M) and, for proportional damping
  ``C = alpha M + beta K``, the modal damping ratio ``(alpha/w + beta w)/2``;
- thesis Table 4.2 for the 6-DOF presets, each mode on its axis.
"""

import math

import numpy as np
import pytest

from drymount.config import load_preset
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.analysis import frequency_response
from drymount.hbm.linear import natural_frequencies
from drymount.hbm.modes import linear_modes, modes_at_amplitudes, nonlinear_modes
from drymount.hbm.options import HBMOptions
from drymount.hbm.system import Excitation, MountElement, System, Transmissibility
from drymount.hbm.systems import sdof
from drymount.paths import load_with_overrides

#: Closed-form comparisons at H = 1 use the closed forms of the laws: round-off only
#: (measured 1.6e-13 Duffing, 5e-13 Jenkins); the issue's bars.
RTOL_DUFFING_H1 = 1e-10
TOL_JENKINS_H1 = 1e-8
#: Issue 29: forced peaks at H = 7 lie on the backbone within 1e-4 relative (the
#: damping ratio 0.002 puts the peak 2e-6 off it at H = 1).
RTOL_PEAK_ON_BACKBONE = 1e-4
#: Linear modes: eigen-solution to 1e-10 (issue 29).
TOL_LINEAR = 1e-10
#: Table 4.2 within 1 % on its axis (as tests/test_presets_modes.py; measured 0.67 %).
RTOL_TABLE_4_2 = 0.01
TABLE_4_2 = {"x": 6.10, "y": 5.82, "z": 7.07, "alpha": 12.03, "beta": 11.59,
             "gamma": 14.05}

M_D, K1_D, KC_D = 1.0, 1.0e4, 1.0e10   # Duffing: kg, N/m, N/m^3


def _duffing(c=0.0, force=1.0):
    ax = AxisParameters(law="cubic", k1=K1_D, kc=KC_D, c=c)
    return sdof(M_D, MountParameters(axial=ax), excitation="force", amplitude=force)


def test_duffing_backbone_h1_equals_closed_form():
    r = nonlinear_modes(_duffing(), harmonics=1, amplitude_range=(1e-5, 3e-3))
    m = r.modes[0]
    assert m.success, m.message
    X = m.dof_amplitude[:, 0]
    np.testing.assert_allclose(m.amplitude, math.sqrt(M_D) * X, rtol=1e-12)
    w_ref = np.sqrt(K1_D / M_D + 0.75 * KC_D * X ** 2 / M_D)
    w = 2 * np.pi * m.freq_hz
    assert np.max(np.abs(w - w_ref) / w_ref) < RTOL_DUFFING_H1
    assert np.max(np.abs(m.damping_ratio)) < 1e-12   # conservative
    assert X[-1] / X[0] > 299   # the whole range, log-spaced continuation
    assert w[-1] / w[0] > 2.5   # strongly nonlinear at the top


def test_duffing_forced_peaks_lie_on_the_h7_backbone():
    c = 2 * 0.002 * math.sqrt(K1_D * M_D)
    opts = HBMOptions(tol=None, error_estimate=False, stability=False)
    for force in (0.01, 0.02, 0.04):   # N: peak amplitudes about 0.2, 0.4, 0.8 mm
        fr = frequency_response(_duffing(c, force), 12.0, 30.0, harmonics=7,
                                n_samples=64, options=opts)
        assert fr.success, fr.message
        peak = [p for p in fr.peaks if p.interior][0]
        assert peak.converged
        X1 = peak.amplitude[0]
        bb = modes_at_amplitudes(_duffing(c), [math.sqrt(M_D) * X1], harmonics=7,
                                 n_samples=64)
        f_bb = bb.modes[0].freq_hz[0]
        assert bb.modes[0].success
        assert abs(peak.freq_hz - f_bb) / f_bb < RTOL_PEAK_ON_BACKBONE, (
            force, peak.freq_hz, f_bb)
        # and the EPMC damping of a viscous SDOF is c / (2 m w) exactly
        D = bb.modes[0].damping_ratio[0]
        assert abs(D - c / (2 * M_D * 2 * np.pi * f_bb)) < 1e-10


M_J, K1_J, KF_J, FS_J = 70.0, 45935.0, 60000.0, 10.0   # sdof_halved's values


def _jenkins(c=0.0):
    ax = AxisParameters(law="linear", k1=K1_J, c=c, friction=True, kf=KF_J, mu=1.0,
                        n0=FS_J)
    return sdof(M_J, MountParameters(axial=ax), excitation="force", amplitude=1.0)


def _jenkins_reference(X, c=0.0):
    """Describing function of the Jenkins element: (omega, D) at amplitude X."""
    eps = FS_J / KF_J   # slip displacement, thesis eq. 2.13
    slip = X > eps
    a2 = np.arcsin(np.clip(1 - 2 * eps / X, -1.0, 1.0))
    f_s = np.where(slip, KF_J * X / np.pi * (np.pi / 2 - a2 - np.sin(a2) * np.cos(a2)),
                   KF_J * X)
    f_c = np.where(slip, 4 * FS_J / np.pi * (1 - eps / X), 0.0)
    w = np.sqrt((K1_J + f_s / X) / M_J)
    xi = c / M_J + f_c / (M_J * w * X)
    return w, xi / (2 * w)


@pytest.mark.parametrize("c", [0.0, 150.0])
def test_jenkins_h1_equals_describing_function(c):
    r = nonlinear_modes(_jenkins(c), harmonics=1)
    m = r.modes[0]
    assert m.success, m.message
    X = m.dof_amplitude[:, 0]
    w_ref, D_ref = _jenkins_reference(X, c)
    w = 2 * np.pi * m.freq_hz
    assert np.max(np.abs(w - w_ref) / w_ref) < TOL_JENKINS_H1
    assert np.max(np.abs(m.damping_ratio - D_ref)) < TOL_JENKINS_H1
    eps = FS_J / KF_J
    # the default range spans stuck (0.1 eps) to wide slip (10 eps)
    np.testing.assert_allclose([X[0], X[-1]], [0.1 * eps, 10 * eps], rtol=1e-9)
    # slips exactly beyond X = eps (the stuck capacity 2 eps peak to peak)
    clear = np.abs(X / eps - 1) > 1e-6
    np.testing.assert_array_equal(m.slipping[clear, 0], (X > eps)[clear])
    if c == 0.0:   # the friction's largest damping ratio, near X = 2.5 eps
        assert 0.13 < D_ref.max() < 0.14


def test_jenkins_multi_harmonic_converges_in_h():
    """Frequency and damping at fixed amplitudes for H = 1, 3, 7, 11, 15 (AFT with N
    = 1024, so that sampling does not mask truncation): the change from H to the next
    shrinks, H = 11 to 15 below 2e-4 (measured table in docs/physics.md)."""
    eps = FS_J / KF_J
    a = math.sqrt(M_J) * eps * np.array([0.5, 1.5, 3.0, 10.0])
    rows = {}
    for H in (1, 3, 7, 11, 15):
        m = modes_at_amplitudes(_jenkins(), a, harmonics=H, n_samples=1024,
                                closed_form=False).modes[0]
        assert m.success, m.message
        rows[H] = np.concatenate([m.freq_hz, m.damping_ratio])
    diffs = [np.max(np.abs(rows[h1] - rows[h0]) / np.abs(rows[15]).clip(1e-3))
             for h0, h1 in ((1, 3), (3, 7), (7, 11), (11, 15))]
    assert diffs[0] > diffs[2] > diffs[3], diffs
    assert diffs[3] < 2e-4, diffs
    np.testing.assert_allclose(rows[15][0], rows[1][0], rtol=1e-12)  # stuck: linear


def _chain(alpha, beta):
    """Three masses in a chain of linear mounts, proportional damping."""
    M = np.diag([2.0, 1.0, 1.5])
    k = (4.0e4, 3.0e4, 2.0e4)
    els, K = [], np.zeros((3, 3))
    for i, ki in enumerate(k):
        B = np.zeros((3, 3))
        B[0, i] = 1.0
        if i + 1 < 3:
            B[0, i + 1] = -1.0
        p = MountParameters(axial=AxisParameters(law="linear", k1=ki, c=beta * ki))
        els.append(MountElement(f"m{i}", p, B, np.zeros((3, 0))))
        K += ki * np.outer(B[0], B[0])
    sysm = System("chain", ("a", "b", "c"), M, alpha * M, np.zeros((3, 3)),
                  tuple(els), Excitation("force", np.zeros(3)),
                  Transmissibility("displacement", dof=0, reference=None))
    return sysm, K


@pytest.mark.parametrize("H", [1, 5])
def test_linear_modes_equal_the_eigen_solution(H):
    alpha, beta = 0.8, 2.0e-4
    sysm, K = _chain(alpha, beta)
    lam = np.linalg.eigvals(np.linalg.solve(sysm.M, K)).real
    w_ref = np.sort(np.sqrt(lam))
    D_ref = 0.5 * (alpha / w_ref + beta * w_ref)
    r = nonlinear_modes(sysm, "all", (1e-3, 1e-1), harmonics=H)
    assert len(r.modes) == 3
    for m, w, D in zip(r.modes, w_ref, D_ref, strict=True):
        assert m.success, m.message
        assert np.max(np.abs(2 * np.pi * m.freq_hz - w) / w) < TOL_LINEAR
        assert np.max(np.abs(m.damping_ratio - D)) < TOL_LINEAR
        if H > 1:   # no higher harmonics in a linear mode
            assert np.max(np.abs(m.harmonics[:, 3:])) < 1e-12 * m.amplitude.max()


@pytest.mark.parametrize("preset, overrides", [
    ("six_dof_original", ()), ("six_dof_halved", ("mounts[*].axial.c=0",))])
def test_six_dof_small_amplitude_is_table_4_2_on_each_axis(preset, overrides):
    """six_dof_original: its damping is proportional to its stiffness (c/k the same on
    every axis), so the EPMC frequencies are the undamped ones and its damping ratios
    the modal ones; six_dof_halved's stuck contacts add kf without damping (not
    proportional: the EPMC frequency is then 2.4e-4 off the undamped one, measured),
    so it is compared undamped."""
    system = load_with_overrides(preset, list(overrides)).system
    f_lin, V = natural_frequencies(system, stuck=True)
    _, C = system.linearized(stuck=True)
    r = modes_at_amplitudes(system, [1e-5], "all", harmonics=3)
    labels = {m.label for m in r.modes}
    assert labels == set(TABLE_4_2)   # one mode per axis
    for i, (m, f) in enumerate(zip(r.modes, f_lin, strict=True)):
        assert m.success, m.message
        # small amplitude: contacts stuck, below the knee: the linearised modes
        assert abs(m.freq_hz[0] - f) / f < TOL_LINEAR
        D_ref = V[:, i] @ C @ V[:, i] / (2 * 2 * np.pi * f)
        assert abs(m.damping_ratio[0] - D_ref) < TOL_LINEAR
        assert not m.slipping.any()
        if preset == "six_dof_original":
            ref = TABLE_4_2[m.label]
            assert abs(m.freq_hz[0] - ref) / ref < RTOL_TABLE_4_2, (m.label, ref)


def test_linear_mode_labels_and_bad_input():
    system = load_preset("six_dof_original").system
    lm = linear_modes(system)
    assert [m.label for m in lm] == ["y", "x", "z", "beta", "alpha", "gamma"]
    with pytest.raises(ValueError, match="`mode` must be"):
        nonlinear_modes(system, mode=7)
    with pytest.raises(ValueError, match="`amplitude_range` must satisfy"):
        nonlinear_modes(system, amplitude_range=(1e-2, 1e-3))
    r = nonlinear_modes(system, mode="z", amplitude_range=(1e-4, 1e-3), harmonics=1)
    assert [m.label for m in r.modes] == ["z"]


def test_csv_and_plot(tmp_path):
    r = nonlinear_modes(_jenkins(150.0), harmonics=3)
    out = tmp_path / "modes.csv"
    r.to_csv(out)
    lines = out.read_text().splitlines()
    assert lines[0].startswith("# drymount modes sdof: EPMC, H=3")
    head = lines[1].split(",")
    assert head[:8] == ["mode", "label", "dominant", "amplitude", "freq_hz",
                        "damping_ratio", "xi", "x_amp"]
    assert head[-1] == "mount_axial_slip"
    assert len(lines) == 2 + len(r.modes[0].amplitude)
    row = lines[-1].split(",")
    assert row[2] == "x"
    assert float(row[4]) == pytest.approx(r.modes[0].freq_hz[-1], rel=1e-11)
    r.plot(tmp_path / "modes.png")
    assert (tmp_path / "modes.png").stat().st_size > 1000


def test_static_load_mode_starts_and_its_stuck_damping_is_viscous():
    """sdof_inclined vibrates about its loaded working point: the residual carries
    the round-off of the static load, which the Newton tolerance allows for (without
    it no start at small amplitude). Stuck, the element adds no damping: the EPMC
    damping of one DOF is then exactly ``c / (2 m omega)``."""
    system = load_preset("sdof_inclined").system
    assert system.has_static_load
    r = nonlinear_modes(system, harmonics=3)
    m = r.modes[0]
    assert m.success, m.message
    _, C = system.linearized(stuck=True)
    w0 = 2 * np.pi * m.freq_hz[0]
    assert abs(m.damping_ratio[0] - C[0, 0] / (2 * system.M[0, 0] * w0)) < 1e-9
    assert m.damping_ratio.max() > 0.1   # the inclined contact slips and damps
