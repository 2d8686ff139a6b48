"""Vehicle harness sweeps: jumps of the cubic spring, CSV/plot output, parallel
chunks."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import drymount.vehicle as vehicle
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.systems import sdof

# Cubic-spring SDOF (thesis fit k1 = 34 770 N/m, kc = 5.708e8 N/m^3, Sec. 2.4) with
# c = 150 N s/m and an unbalance f0 = 0.05 kg m: large enough for the response to
# fold over between about 4.2 and 6.3 Hz.
M, K1, KC, C, F0 = 70.0, 34770.0, 5.708e8, 150.0, 0.05
#: Jumps happen within one frequency step of the single-harmonic folds (the third
#: harmonic of a cubic spring shifts them slightly; a stepped sweep leaves the
#: branch a little before its fold): one step of margin on each side.
STEP_HZ = 0.25
#: Linear system, unique steady state: parallel chunks and a serial sweep differ
#: only by what rtol leaves of the transient (measured 2e-5).
RTOL_PARALLEL = 1e-3


def cubic_sdof():
    ax = AxisParameters(law="cubic", k1=K1, kc=KC, c=C)
    return sdof(M, MountParameters.from_axial(ax), "unbalance", F0)


def hbm1_folds():
    """Frequencies (Hz) bounding the band with three single-harmonic solutions of
    X^2 [(k1 - m w^2 + 3/4 kc X^2)^2 + (c w)^2] = (f0 w^2)^2 (thesis eq. 3.17-3.18)."""
    def n_solutions(f):
        w = 2 * math.pi * f
        a, b = (0.75 * KC) ** 2, 2 * (K1 - M * w * w) * 0.75 * KC
        c = (K1 - M * w * w) ** 2 + (C * w) ** 2
        r = np.roots([a, b, c, -(F0 * w * w) ** 2])
        z = r[np.abs(r.imag) <= 1e-12 * np.abs(r)].real
        return int(np.sum(z > 0))
    fs = np.arange(3.0, 9.0, 1e-3)
    three = fs[[n_solutions(f) == 3 for f in fs]]
    return float(three[0]), float(three[-1])


def jump(sw) -> tuple[float, float, float]:
    """(f_before, f_after, log ratio) of the largest amplitude change of a sweep."""
    a = np.log(sw.amplitude[:, 0])
    i = int(np.argmax(np.abs(np.diff(a))))
    return float(sw.freq_hz[i]), float(sw.freq_hz[i + 1]), float(a[i + 1] - a[i])


def test_cubic_spring_up_and_down_sweeps_jump_at_different_frequencies():
    system = cubic_sdof()
    f_low, f_high = hbm1_folds()  # about 4.22 and 6.28 Hz
    freqs = np.arange(3.5, 7.01, STEP_HZ)
    up = vehicle.sweep(system, freqs, direction="up", progress=False, rtol=1e-4)
    down = vehicle.sweep(system, freqs, direction="down", progress=False, rtol=1e-4)
    assert up.success and down.success
    assert np.all(np.diff(up.freq_hz) > 0) and np.all(np.diff(down.freq_hz) < 0)
    u0, u1, du = jump(up)
    d0, d1, dd = jump(down)
    # a drop (x0.09 measured) going up, a rise (x1.9 measured) coming down
    assert du < -math.log(5) and dd > math.log(1.5)
    assert f_high - 2 * STEP_HZ <= u0 < u1 <= f_high + STEP_HZ, (u0, u1, f_high)
    assert f_low - STEP_HZ <= d1 < d0 <= f_low + 2 * STEP_HZ, (d0, d1, f_low)
    assert u0 - d0 > 1.0
    # hysteresis: in between, the up sweep rides the upper branch
    between = (up.freq_hz > d0 + 1e-9) & (up.freq_hz < u1 - 1e-9)
    a_dn = np.interp(up.freq_hz[between], down.freq_hz[::-1], down.amplitude[::-1, 0])
    assert np.all(up.amplitude[between, 0] > 3 * a_dn)


def test_sweep_csv_and_plot(tmp_path):
    system = cubic_sdof()
    sw = vehicle.sweep(system, [3.0, 4.0, 5.0], progress=False)
    path = sw.to_csv(tmp_path / "out" / "sweep.csv")
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# ") and "freq_hz [Hz]" in lines[0]
    assert lines[1] == "freq_hz,x_amp,x_peak,transmissibility,converged"
    data = np.loadtxt(path, delimiter=",", skiprows=2)
    np.testing.assert_allclose(data[:, 0], [3.0, 4.0, 5.0])
    np.testing.assert_allclose(data[:, 1], sw.amplitude[:, 0], rtol=1e-9)
    np.testing.assert_allclose(data[:, 3], sw.transmissibility, rtol=1e-9)
    hbm = SimpleNamespace(freq_hz=np.linspace(3, 5, 20),
                          transmissibility=np.linspace(1, 2, 20),
                          stable=np.arange(20) < 15)
    fig = sw.plot(tmp_path / "sweep.png", hbm=hbm)
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    assert "Hz" in ax.get_xlabel() and "transmissibility" in ax.get_ylabel()
    assert len(ax.lines) == 3  # HBM stable, HBM unstable, co-simulation
    assert (tmp_path / "sweep.png").stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "sweep.png"]
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["sweep.csv"]


def test_time_history_csv(tmp_path):
    th = vehicle.simulate(cubic_sdof(), 4.0, 0.05, backend="inproc")
    path = th.to_csv(tmp_path / "run.csv")
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# ") and "time [s]" in lines[0] and "x [m]" in lines[0]
    assert lines[1] == "time,x,F_mount_axial"
    data = np.loadtxt(path, delimiter=",", skiprows=2)
    assert data.shape == (len(th.t), 3)
    assert data[-1, 0] == pytest.approx(0.05)


def test_parallel_chunks_equal_serial_sweep_for_a_linear_system():
    mount = MountParameters.from_axial(AxisParameters(law="linear", c=1500.0))
    system = sdof(70.0, mount, "force", 100.0)
    f = np.linspace(2.0, 12.0, 6)
    serial = vehicle.sweep(system, f, progress=False)
    par = vehicle.sweep(system, f, workers=2, progress=False)
    assert par.workers == 2 and par.success
    np.testing.assert_allclose(par.freq_hz, serial.freq_hz)
    np.testing.assert_allclose(par.amplitude, serial.amplitude, rtol=RTOL_PARALLEL)


def test_sweep_rejects_bad_input():
    s = cubic_sdof()
    with pytest.raises(ValueError, match="`direction` must be 'up' or 'down'"):
        vehicle.sweep(s, [1.0], direction="sideways")
    with pytest.raises(ValueError, match="`freqs_hz` must be"):
        vehicle.sweep(s, [1.0, -2.0])
    with pytest.raises(ValueError, match="`workers` must be an integer >= 1"):
        vehicle.sweep(s, [1.0], workers=0)


@pytest.mark.slow
def test_cubic_jump_through_the_fmu_with_fine_steps(tmp_path):
    """The same hysteresis through FrictionMount.fmu with 0.1 Hz steps."""
    from drymount.fmu_build import build_fmu

    fmu = build_fmu(tmp_path / "FrictionMount.fmu")
    system = cubic_sdof()
    f_low, f_high = hbm1_folds()
    freqs = np.arange(3.8, 6.61, 0.1)
    up = vehicle.sweep(system, freqs, direction="up", backend="fmu", fmu_path=fmu,
                       progress=False)
    down = vehicle.sweep(system, freqs, direction="down", backend="fmu", fmu_path=fmu,
                         progress=False)
    u0, u1, _ = jump(up)
    d0, d1, _ = jump(down)
    # the single-harmonic folds are approximate: the third harmonic moves the upper
    # fold up by about 0.1 Hz (measured: jump between 6.3 and 6.4 Hz, HBM1 6.28 Hz)
    assert f_high - 0.3 <= u0 < u1 <= f_high + 0.2, (u0, u1, f_high)
    assert f_low - 0.2 <= d1 < d0 <= f_low + 0.3, (d0, d1, f_low)
