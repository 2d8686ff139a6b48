"""Harmonic balance and co-simulation about the static working point (``[static]``).

References: the hand-computed sag of the halved single-DOF mount (its static harmonic
at a low frequency), and the co-simulation (time integration from the working point,
sliders relaxed there) against the HBM with the load in its static row. Runtime about
10 s (one FMU build).
"""

import numpy as np
import pytest

import drymount.hbm as hbm
from drymount.cli import main
from drymount.config import load_config, preset_text
from drymount.vehicle.steady import steady_state

G = 9.81
K1, K2, DELTA = 45935.0, 256900.0, 0.01225
SAG = -(DELTA + (70.0 * G - K1 * DELTA) / K2)  # -12.733 mm, past the knee
#: the engine lowered onto the mount (the default reading): the Jenkins slider slips
#: under the growing weight and carries its slip force Fs = mu n0 = 10 N of it
FS = 10.0
SAG_LOWERED = -(DELTA + (70.0 * G - FS - K1 * DELTA) / K2)  # -12.694 mm
#: HBM (H = 7) vs co-simulation (256 steps per period) where the solution is unique
#: (sliders slip at both reversals, or no friction): measured <= 5.3e-5.
RTOL_COSIM = 1e-3
#: Loaded vs unloaded where every mount stays inside its knees (linear about any
#: point): measured 0.
RTOL_SUPERPOSITION = 1e-9
#: The static harmonic at 0.5 Hz vs the hand-computed sag: measured 1.4e-16 (the
#: harmonic balance's static row is exactly the static equilibrium past the knee).
RTOL_SAG = 1e-4


def _loaded(preset: str):
    return load_config(preset_text(preset) + "\n[static]\ngravity = true\n").system


def test_config_static_section_sets_the_load():
    s = _loaded("sdof_halved")
    np.testing.assert_allclose(s.static_load, [-70.0 * G], rtol=1e-15)
    assert load_config(preset_text("sdof_halved")).system.static_load is None
    s6 = _loaded("six_dof_halved")
    np.testing.assert_allclose(s6.static_load, [0, 0, -140.6 * G, 0, 0, 0])


@pytest.mark.parametrize("reading, sag", [("lowered", SAG_LOWERED),
                                          ("relaxed", SAG)])
def test_hbm_static_harmonic_is_the_sag(reading, sag):
    from dataclasses import replace

    s = replace(_loaded("sdof_halved"), static_reading=reading)
    r = hbm.solve_frequencies(s, [0.5], harmonics=7)
    assert r.success
    static = r.coefficients[0][0, 0]
    assert abs(static - sag) / abs(sag) < RTOL_SAG, static


@pytest.mark.parametrize("preset, freqs", [("sdof_halved", (3.0, 6.0, 12.0)),
                                           ("six_dof_original", (4.0, 15.0))])
def test_hbm_about_the_working_point_matches_cosimulation(preset, freqs):
    s = _loaded(preset)
    r = hbm.solve_frequencies(s, list(freqs), harmonics=7)
    assert r.success
    unloaded = hbm.solve_frequencies(load_config(preset_text(preset)).system,
                                     list(freqs), harmonics=7)
    for k, f in enumerate(freqs):
        ss = steady_state(s, f, backend="inproc")
        assert ss.converged
        t_hbm, t_sim = r.transmissibility[k], ss.transmissibility
        assert abs(t_sim - t_hbm) / t_hbm < RTOL_COSIM, (f, t_sim, t_hbm)
    change = np.max(np.abs(r.transmissibility / unloaded.transmissibility - 1))
    if preset == "sdof_halved":  # past the knee under the weight: another answer
        assert change > 0.1
    else:  # original mounts stay inside their knees: superposition, same dynamics
        assert change < RTOL_SUPERPOSITION, change


def test_cosimulation_through_the_fmu_starts_at_the_working_point(tmp_path):
    pytest.importorskip("fmpy")
    from drymount.fmu_build import build_fmu

    fmu = build_fmu(tmp_path / "FrictionMount.fmu")
    s = _loaded("sdof_halved")
    ss = steady_state(s, 6.0, backend="fmu", fmu_path=fmu)
    r = hbm.solve_frequencies(s, [6.0], harmonics=7)
    assert ss.converged
    assert abs(ss.transmissibility - r.transmissibility[0]) / ss.transmissibility \
        < RTOL_COSIM
    assert abs(ss.mean[0] - SAG_LOWERED) < 1e-3  # about the sag, not about 0


def test_drymount_hbm_runs_about_the_working_point(tmp_path, capsys):
    cfg = tmp_path / "loaded.toml"
    cfg.write_text(preset_text("sdof_halved") + "\n[static]\ngravity = true\n")
    assert main(["hbm", str(cfg), "--out", str(tmp_path / "c.csv"), "-q"]) == 0
    out = capsys.readouterr().out
    # peak 13.3 at 6.4 Hz under the weight, against 5.36 at 4.17 Hz unloaded
    peak = float(out.split("peak transmissibility ")[1].split()[0])
    assert 12.0 < peak < 15.0
