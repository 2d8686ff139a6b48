"""The design studies (drymount.studies): quick mode of each study writes its files,
and its key numbers satisfy the claims of PHYSICS.md section 4 that must hold for our
presets. Helpers are checked against independent references (closed-form Jenkins
energy, Table 4.1 positions, the crank-mechanism formulas).

Each study runs once per module (fixtures) in quick mode: coarse, but real HBM.
"""

from __future__ import annotations

import argparse
import csv
import math
from types import SimpleNamespace

import numpy as np
import pytest

import drymount.hbm as hbm
from drymount import studies
from drymount.studies import (
    ENGINE_EXCITATION,
    StudyError,
    engine_excited,
    friction_energy,
    load_system,
    mount_position,
    relocate_mount,
    with_friction_of,
    with_normal_force,
    with_stiffness_factor,
)

# ---- tolerances (named, with their reason)
#: Energy of the Jenkins loop for a sampled pure sine: the return map is exact at the
#: samples and the extremes of sin are sampled when n_samples % 4 == 0, so only
#: rounding remains.
RTOL_ENERGY = 1e-9
#: A resonance "shifts up" if its frequency rises by more than this fraction: the
#: continuation places points about 1 % apart near the peak, so smaller shifts are
#: not resolved.
MIN_FREQ_SHIFT = 0.02
#: A design is "lower" or "higher" if it differs by more than this fraction of the
#: reference: far above the HBM convergence error in quick mode (H = 3 against H = 7
#: differ by well under 1 % at the peaks of these systems).
MIN_EFFECT = 0.02
#: Local optimality of the optimum n0: steps of this size on each side (N) must not
#: lower the objective by more than REL_OPT (quick mode stops at xatol = 0.5 N).
OPT_PROBE_N = 2.0
REL_OPT = 1e-3
#: A stepped time-domain sweep leaves the upper branch of a hardening fold before
#: the HBM turning point once the branch's basin is narrower than the frequency step:
#: measured 8 % below the fold with the quick study's 0.2 Hz steps (2 % at 0.1 Hz).
JUMP_EARLY_RTOL = 0.15
#: Relocating mount 3 must let friction cut the beta peak by at least this fraction
#: (measured 0.58 with H = 3, n0 = 2 N; at Table 4.1 the change is 0.06).
MIN_BETA_REDUCTION = 0.2
#: FFT of the sampled crank input against its closed-form orders: exact for a
#: trigonometric polynomial sampled above its Nyquist rate, rounding only (measured
#: 9e-16).
RTOL_FFT = 1e-12

TABLE_4_1 = [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)]


def _csv_header(path):
    with open(path, newline="") as fh:
        first = fh.readline()
        assert first.startswith("# "), f"{path.name}: first line must be a # comment"
        return next(csv.reader(fh))


def _check_files(out, result, expected):
    names = set(result["files"])
    for name in expected:
        assert name in names, f"{name} not written"
        path = out / name
        assert path.stat().st_size > 0
        if name.endswith(".png"):
            assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    summary = (out / "summary.md").read_text()
    for name in expected:
        if name.endswith(".png"):
            assert f"({name})" in summary, f"summary.md does not show {name}"
    assert not [n for n in names if n.endswith(".tmp")], "temporary files left"


# ---- fixtures: each study once, quick mode

@pytest.fixture(scope="module")
def normal_force(tmp_path_factory):
    out = tmp_path_factory.mktemp("normal_force")
    return out, studies.run_normal_force(out, quick=True, progress=False)


@pytest.fixture(scope="module")
def quarter_car(tmp_path_factory):
    out = tmp_path_factory.mktemp("quarter_car")
    return out, studies.run_quarter_car(out, quick=True, progress=False)


@pytest.fixture(scope="module")
def optimize(tmp_path_factory):
    out = tmp_path_factory.mktemp("optimize")
    return out, studies.run_optimize_n0(out, quick=True, progress=False)


@pytest.fixture(scope="module")
def six_dof(tmp_path_factory):
    out = tmp_path_factory.mktemp("six_dof")
    return out, studies.run_six_dof(out, quick=True, progress=False)


@pytest.fixture(scope="module")
def jump(tmp_path_factory):
    out = tmp_path_factory.mktemp("jump")
    return out, studies.run_jump(out, quick=True, progress=False)


def _case(cases, **kw):
    found = [c for c in cases if all(c[k] == v for k, v in kw.items())]
    assert len(found) == 1, f"{len(found)} cases match {kw}"
    return found[0]


# ---- helpers against independent references

def test_friction_energy_equals_jenkins_loop_area():
    """Pure sine u = X sin(theta): energy per cycle 4 Fs (X - eps) (PHYSICS.md sec. 1),
    zero while the element sticks (X <= eps)."""
    system = with_normal_force(load_system("sdof_halved"), 20.0)
    p = system.elements[0].params.axial
    assert p.friction
    eps = p.fs / p.kf
    amps = np.array([0.5 * eps, 0.99 * eps, 1.5 * eps, 10 * eps, 100 * eps])
    n = len(amps)
    coeffs = np.zeros((n, 1, 3))
    coeffs[:, 0, 2] = amps  # sine coefficient of the first harmonic
    coeffs[:, 0, 0] = 1e-3  # a static offset must not change the loop
    fr = SimpleNamespace(freq_hz=np.full(n, 5.0), coefficients=coeffs)
    work = friction_energy(system, fr, 0, 0, n_samples=512)
    energy, slip = work.energy, work.slip_fraction
    expected = np.where(amps > eps, 4 * p.fs * (amps - eps), 0.0)
    np.testing.assert_allclose(energy, expected, rtol=RTOL_ENERGY, atol=1e-15)
    assert slip[0] == 0.0 and slip[-1] > 0.9


def test_mount_positions_and_relocation():
    s = load_system("six_dof_original")
    for e, a in zip(s.elements, TABLE_4_1, strict=True):
        np.testing.assert_allclose(mount_position(e), a, atol=1e-12)
    moved = relocate_mount(s, 2, (0.4, -0.25, -0.5))
    np.testing.assert_allclose(mount_position(moved.elements[2]), (0.4, -0.25, -0.5),
                               atol=1e-12)
    # a rotation beta moves the new point along z by -beta * a_x (t + theta x a)
    q = np.array([0.0, 0.0, 0.0, 0.0, 1e-3, 0.0])
    axial = [j for j in range(3) if np.allclose(s.elements[2].B[j, :3], [0, 0, 1])][0]
    assert abs(s.elements[2].B[axial] @ q) < 1e-15
    assert moved.elements[2].B[axial] @ q == pytest.approx(-0.4e-3, rel=1e-12)
    with pytest.raises(StudyError, match="position"):
        relocate_mount(s, 2, (0.4, 0.0))


@pytest.mark.parametrize("original,halved", [("sdof_original", "sdof_halved"),
                                             ("quarter_car_original",
                                              "quarter_car_halved"),
                                             ("six_dof_original", "six_dof_halved")])
def test_halved_presets_are_half_the_stiffness(original, halved):
    """The studies derive the lambda = 1.2 halved 6-DOF mounts with
    with_stiffness_factor(0.5): it must give exactly the shipped halved presets."""
    mine = with_stiffness_factor(load_system(original), 0.5)
    ref = load_system(halved)
    for a, b in zip(mine.elements, ref.elements, strict=True):
        for pa, pb in zip(a.params.axes, b.params.axes, strict=True):
            assert pa.law == pb.law
            for f in ("k1", "kc", "k2", "c", "delta", "delta_neg"):
                assert getattr(pa, f) == pytest.approx(getattr(pb, f), rel=1e-12), f


def test_with_normal_force():
    s = load_system("six_dof_halved")
    assert s.is_hysteretic
    s0 = with_normal_force(s, 0.0)
    assert not s0.is_hysteretic
    s1 = with_normal_force(s, 123.0)
    fr_axes = [p for e in s1.elements for p in e.params.axes if p.friction]
    assert len(fr_axes) == 3 and all(p.n0 == 123.0 for p in fr_axes)
    with pytest.raises(StudyError, match="`n0` must be finite and >= 0, got -1"):
        with_normal_force(s, -1.0)
    # the original mounts get the halved preset's friction elements (Fig. 4.1)
    orig = load_system("six_dof_original")
    assert not orig.is_hysteretic
    both = with_friction_of(orig, s)
    for e, t, o in zip(both.elements, s.elements, orig.elements, strict=True):
        for pb, pt, po in zip(e.params.axes, t.params.axes, o.params.axes,
                              strict=True):
            if pt.friction:
                assert (pb.friction, pb.kf, pb.mu, pb.n0) == (True, pt.kf, pt.mu,
                                                              pt.n0)
                assert (pb.k1, pb.k2, pb.c) == (po.k1, po.k2, po.c)
            else:
                assert pb == po


def test_engine_excitation_is_the_crank_mechanism():
    """Second-order inline-four inertia force and roll torque (thesis eq. 1.3): the
    force amplitude is 4 m_rec R omega_c^2 (R / L) with omega_c = omega / 2."""
    ex = ENGINE_EXCITATION
    omega = 2 * math.pi * 100.0
    omega_c = omega / 2
    r_over_l = ex.crank_radius / ex.rod_length
    force = 4 * ex.m_rec * ex.crank_radius * omega_c**2 * r_over_l
    torque = 2 * ex.m_rec * ex.crank_radius**2 * omega_c**2
    s = engine_excited(load_system("six_dof_original"))
    f = s.excitation.force_amplitude(omega)
    np.testing.assert_allclose(f, [0, 0, force, 0, torque, 0], rtol=1e-12)
    assert s.n_base == 0 and s.excitation.kind == "unbalance"


def test_one_crank_model_for_time_domain_and_hbm():
    """The harness's crank input and the studies' engine excitation are one model
    (hbm.crank): the second-order Fourier coefficients of the time-domain force and
    moment equal the HBM unbalance excitation at omega = 2 w (force: cosine, moment:
    sine; the HBM applies both as one amplitude vector)."""
    from drymount.vehicle.inputs import CrankInput

    s = engine_excited(load_system("six_dof_original"))
    inp = CrankInput(s, 3000.0)
    assert inp.engine == ENGINE_EXCITATION
    omega = 2 * inp.omega
    n = 256
    t = np.arange(n) / n * (2 * math.pi / inp.omega)  # one crank revolution
    spec = np.fft.rfft(inp.force(t), axis=0) * 2 / n
    z, beta = s.dof_names.index("z"), s.dof_names.index("beta")
    f = s.excitation.force_amplitude(omega)
    assert spec[2, z].real == pytest.approx(f[z], rel=RTOL_FFT)
    assert -spec[2, beta].imag == pytest.approx(f[beta], rel=RTOL_FFT)
    # the fourth order as hbm.crank states it
    o4 = ENGINE_EXCITATION.orders()[1]
    assert spec[4, z].real == pytest.approx(o4.force * inp.omega**2, rel=RTOL_FFT)
    assert -spec[4, beta].imag == pytest.approx(o4.moment * inp.omega**2, rel=RTOL_FFT)
    with pytest.raises(ValueError, match="`crank_radius` must be smaller than"):
        CrankInput(s, 3000.0, R=0.2, l=0.1)


def test_main_dispatch(monkeypatch, tmp_path, capsys):
    assert studies.main(argparse.Namespace(name="nope", out=str(tmp_path))) == 2
    assert "unknown study 'nope'" in capsys.readouterr().err
    calls = []

    def fake(out, quick=False):
        calls.append((out, quick))
        return {"files": ["summary.md"], "failures": ["curve 3 stalled"]}

    monkeypatch.setitem(studies.STUDIES, "jump", fake)
    args = argparse.Namespace(name="jump", out=str(tmp_path), quick=True)
    assert studies.main(args) == 1  # a numerical failure: exit 1, files kept
    assert calls == [(tmp_path, True)]
    assert "curve 3 stalled" in capsys.readouterr().err


# ---- normal-force (Figs. 4.1-4.4)

def test_normal_force_files(normal_force):
    out, r = normal_force
    _check_files(out, r, ["normal_force_curves.csv", "normal_force_peaks.csv",
                          "normal_force_original.png", "normal_force_halved.png",
                          "normal_force_best.png", "summary.md"])
    header = _csv_header(out / "normal_force_curves.csv")
    assert header[:6] == ["mount", "n0_N", "H", "freq_hz", "x_amp", "transmissibility"]
    assert not r["failures"]


def test_normal_force_claims(normal_force):
    """PHYSICS.md section 4, single DOF."""
    _, r = normal_force
    H = r["harmonics"]
    cs = r["cases"]
    forces = sorted(f for f in r["normal_forces_N"] if f > 0)
    ref = _case(cs, mount="original", n0_N=0.0, H=H)
    low = _case(cs, mount="original", n0_N=forces[0], H=H)
    high = _case(cs, mount="original", n0_N=forces[-1], H=H)
    # raising n0 lowers the peak near the original resonance
    assert low["peak"] < (1 - MIN_EFFECT) * ref["peak"]
    # ... and shifts the resonance up
    assert high["peak_freq_hz"] > (1 + MIN_FREQ_SHIFT) * ref["peak_freq_hz"]
    # a high n0 worsens isolation at high frequency (stuck element adds stiffness)
    assert high["t_high"] > (1 + MIN_EFFECT) * ref["t_high"]
    # halved mount + a good n0: lower peak than the original mount
    assert r["best_halved"]["peak"] < (1 - MIN_EFFECT) * ref["peak"]
    # friction dissipates, never creates energy; with n0 > 0 it works somewhere
    assert r["e_fr_min_J"] >= 0.0
    assert low["e_fr_max_J"] > 0.0


# ---- optimize-n0

def test_optimize_files(optimize):
    out, r = optimize
    _check_files(out, r, ["optimize_n0_evaluations.csv", "optimize_n0_optima.csv",
                          "optimize_n0_objectives.png", "optimize_n0_curves.png",
                          "summary.md"])
    assert not r["failures"]


def test_optimize_optimum_is_a_local_minimum(optimize):
    """Independent check: HBM at n0_opt +- OPT_PROBE_N is not better than the optimum
    (same harmonics as the study), and the optimum beats no friction."""
    _, r = optimize
    o = _case(r["optima"], mount="halved", objective="peak")
    assert o["n0_opt_N"] > 0.0, "friction should help the halved mount's peak"
    assert o["improvement_vs_no_friction"] > MIN_EFFECT
    assert o["improvement_vs_reference"] > MIN_EFFECT
    system = load_system("sdof_halved")
    band = studies.OPT_PEAK_BAND_HZ
    for n0 in (o["n0_opt_N"] - OPT_PROBE_N, o["n0_opt_N"] + OPT_PROBE_N):
        if n0 <= 0:
            continue
        fr = hbm.frequency_response(with_normal_force(system, n0), *band,
                                    harmonics=r["harmonics"])
        assert np.max(fr.transmissibility) >= o["value"] * (1 - REL_OPT)


# ---- quarter-car (Figs. 4.6-4.9)

def test_quarter_car(quarter_car):
    out, r = quarter_car
    _check_files(out, r, ["quarter_car_curves.csv", "quarter_car_peaks.csv",
                          "quarter_car_original.png", "quarter_car_halved.png",
                          "quarter_car_best.png", "summary.md"])
    assert _csv_header(out / "quarter_car_curves.csv")[4:7] == [
        "engine_amp", "sprung_amp", "unsprung_amp"]
    assert not r["failures"]
    H = r["harmonics"]
    cs = r["cases"]
    ref = _case(cs, mount="original", n0_N=0.0, H=H)
    high = _case(cs, mount="original", n0_N=max(r["normal_forces_N"]), H=H)
    assert high["peak_freq_hz"] > (1 + MIN_FREQ_SHIFT) * ref["peak_freq_hz"]
    assert high["t_high"] > (1 + MIN_EFFECT) * ref["t_high"]
    assert r["best_halved"]["peak"] < (1 - MIN_EFFECT) * ref["peak"]
    assert r["e_fr_min_J"] >= 0.0


# ---- six-dof (Figs. 4.11-4.44)

def test_six_dof_files(six_dof):
    out, r = six_dof
    _check_files(out, r, ["six_dof_curves.csv", "six_dof_peaks.csv",
                          "six_dof_base_lambda10_original.png",
                          "six_dof_base_lambda10_halved.png",
                          "six_dof_engine_original.png", "six_dof_engine_halved.png",
                          "six_dof_relocation.png", "summary.md"])
    assert not r["failures"]


def test_six_dof_relocation_lets_mount3_work(six_dof):
    """Thesis Sec. 4.5: at Table 4.1 no friction element sees beta, so beta barely
    changes with friction; with mount 3 moved along x, its element dissipates and
    beta drops."""
    _, r = six_dof
    red = r["beta_reduction"]
    assert red["relocated"] > MIN_BETA_REDUCTION
    assert red["relocated"] > 2 * abs(red["table_4_1"])
    assert r["mount3_energy_max_J"]["relocated"] > 0.0
    assert r["e_fr_min_J"] >= 0.0


def test_six_dof_good_design_lowers_responses(six_dof):
    """Thesis Sec. 4.5: halved mounts with 250 N lower all six responses (mount
    deflection input)."""
    _, r = six_dof
    for lam, ratios in r["good_design_ratio"].items():
        for dof, ratio in ratios.items():
            assert ratio < 1 - MIN_EFFECT, (lam, dof, ratio)


# ---- jump (Figs. 3.5, 3.7)

def test_jump(jump):
    out, r = jump
    _check_files(out, r, ["jump_hbm.csv", "jump_sweeps.csv", "jump.png",
                          "summary.md"])
    assert len(r["turning_points_hz"]) == 2
    assert r["hbm_unstable_points"] > 0
    f_lo, f_hi = sorted(r["turning_points_hz"])
    up, dn = r["jump_up"], r["jump_down"]
    up_before, up_after, up_change = up.f_before_hz, up.f_after_hz, up.change_m
    dn_before, dn_after, dn_change = dn.f_before_hz, dn.f_after_hz, dn.change_m
    assert up_change < 0 < dn_change
    # the up sweep jumps down near the upper fold (not past it: there is no upper
    # branch beyond), the down sweep jumps up where the lower branch ends
    assert (1 - JUMP_EARLY_RTOL) * f_hi <= up_after and up_before <= f_hi
    assert dn_after <= f_lo <= dn_before + r["sweep_step_hz"]
    assert all(h > 0 for h in r["hysteresis_m"])
    # Fig. 3.7: stepping the frequency past the fold drops the amplitude to the lower
    # branch (measured 18.4 mm -> 0.96 mm in quick mode)
    step = r["frequency_step"]
    assert step["amp_after_m"] < 0.25 * step["amp_before_m"]
