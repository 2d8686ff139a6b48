"""Measured inputs (CSV with units -> cubic-spline inputs -> cosim) and their spectra.

References: the built-in generators (ISO 8608 random road, harmonic force), the cubic
spline's derivative error bound, M a for accelerations, Parseval for the PSDs.
Runtime about 3 s."""

import math

import numpy as np
import pytest

import drymount.vehicle as vehicle
from drymount import cosim, load
from drymount.measured import engine_input, read_measured, road_input
from drymount.spectra import spectra

#: Measured input read back = the generator it was written from, when the samples
#: sit on the step times: the spline passes through them, `repr` round-trips the
#: floats, and mm -> m and t = x / v are single roundings. Measured: 1.2e-14 (ISO
#: road, relative to the largest response), 0 (harmonic force).
ROUND_TRIP_RTOL = 1e-12
#: Not-a-knot cubic spline through samples of a sine, interior: |s' - f'| <= h^3
#: max|f''''| / 24 (the clamped spline's bound; measured 1.0e-7 m/s against a bound
#: of 5.3e-7 m/s at h = 1 ms, 8 Hz, 2 mm).
SPLINE_BOUND = 1.0
#: 6-DOF response to a sine base sampled at the step vs. the analytic sine: only the
#: base velocity differs (above); measured 1.0e-8 relative.
SINE_RESPONSE_RTOL = 1e-6
#: Parseval through Welch (Hann, 50 % overlap, a bin-centred sine): the integral of
#: the PSD is the mean square; measured 8.9e-16 (force) and 2.4e-10 (acceleration:
#: np.gradient's one-sided differences at the record's two ends).
PARSEVAL_RTOL = 1e-8


def _write(path, header, columns, comment="# measured"):
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(comment + "\n" + ",".join(header) + "\n")
        for row in zip(*columns, strict=True):
            fh.write(",".join(repr(float(v)) for v in row) + "\n")
    return path


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def test_iso8608_road_written_and_read_back_gives_the_same_response(tmp_path):
    """An ISO 8608 class C road (seed 3, 20 m/s) written as elevation [mm] over
    distance [m] at the step spacing and read back by ``cosim(road=...)``."""
    m = load("quarter_car_halved")
    assert not np.any(m.system.Cb)  # tyre without damping: y' does not enter
    road = vehicle.RandomRoad(m.system, "C", speed=20.0, seed=3)
    dt, T = 1e-3, 2.0
    ref = vehicle.simulate(m.system, None, T, backend="inproc", dt=dt, inputs=road)
    ts = np.arange(round(T / dt) + 5) * dt
    csv = _write(tmp_path / "road.csv", ["distance [m]", "elevation [mm]"],
                 [20.0 * ts, 1e3 * road.base(ts)[:, 0]])
    run = cosim(m, road=csv, speed=20.0, duration=T, dt=dt, backend="inproc")
    assert np.ptp(ref.q[:, 2]) > 5e-3  # the road moves the wheel by millimetres
    assert _rel(run.q, ref.q) < ROUND_TRIP_RTOL
    assert _rel(run.forces, ref.forces) < ROUND_TRIP_RTOL
    # the default duration is the record's span (2.004 s here)
    assert cosim(m, road=csv, speed=20.0, dt=dt, backend="inproc").t[-1] == \
        pytest.approx(ts[-1])


def test_sampled_base_velocity_and_6dof_response_against_the_analytic_sine():
    m = load("six_dof_halved")
    A, f, h = 0.002, 8.0, 1e-3
    w = 2 * math.pi * f
    ts = np.arange(1100) * h
    sampled = vehicle.SampledBase(m.system, ts, A * np.sin(w * ts))
    tt = np.linspace(0.01, 1.0, 777)
    k = int(np.argmax(sampled.direction))
    err = np.max(np.abs(sampled.base_velocity(tt)[:, k] - A * w * np.cos(w * tt)))
    assert err <= SPLINE_BOUND * h ** 3 * A * w ** 4 / 24
    sine = vehicle.SineRoad(m.system, A, f)
    ref = vehicle.simulate(m.system, None, 1.0, backend="inproc", dt=h, inputs=sine)
    run = vehicle.simulate(m.system, None, 1.0, backend="inproc", dt=h,
                           inputs=sampled)
    assert _rel(run.q, ref.q) < SINE_RESPONSE_RTOL


def test_engine_force_in_kn_over_ms_gives_the_harmonic_response(tmp_path):
    """The unbalance force f0 omega^2 sin(omega t) of sdof_halved as a measured
    ``x [kN]`` over ``time [ms]`` = the model's own harmonic excitation."""
    m = load("sdof_halved")
    f, dt, T = 5.0, 1e-3, 1.0
    w = 2 * math.pi * f
    ts = np.arange(round(T / dt) + 3) * dt
    force = m.system.excitation.amplitude[0] * w ** 2 * np.sin(w * ts)
    csv = _write(tmp_path / "bench.csv", ["time [ms]", "x [kN]"],
                 [1e3 * ts, 1e-3 * force])
    run = cosim(m, engine=csv, duration=T, dt=dt, backend="inproc")
    ref = vehicle.simulate(m.system, f, T, backend="inproc", dt=dt)
    assert _rel(run.q, ref.q) < ROUND_TRIP_RTOL


def test_engine_accelerations_become_m_a(tmp_path):
    m = load("six_dof_halved")
    ts = np.linspace(0.0, 0.1, 11)
    az_g, aa = np.sin(30 * ts), 5.0 * np.cos(20 * ts)
    csv = _write(tmp_path / "acc.csv", ["time [s]", "z [g]", "alpha"], [ts, az_g, aa])
    inp = engine_input(m.system, csv, units={"alpha": "rad/s^2"})
    names = list(m.system.dof_names)
    a = np.zeros((ts.size, len(names)))
    a[:, names.index("z")] = 9.80665 * az_g
    a[:, names.index("alpha")] = aa
    np.testing.assert_allclose(inp.force(ts), a @ np.asarray(m.system.M).T,
                               rtol=1e-13, atol=1e-12)


@pytest.mark.parametrize("header, rows, kw, match", [
    (["time", "elevation [mm]"], [[0, 1]] * 5, {}, "column `time` has no unit"),
    (["time [s]", "elevation [furlong]"], [[0, 1]] * 5, {}, "unit 'furlong'; allowed"),
    (["distance [m]", "elevation [m]"], [[i, 0] for i in range(5)], {},
     "needs the vehicle `speed`"),
    (["time [s]", "height [m]"], [[i, 0] for i in range(5)], {},
     "`elevation` or `displacement` column"),
    (["time [s]", "elevation [m]"], [[0, 0], [1, 0], [1, 0], [2, 0], [3, 0]], {},
     r"must increase strictly; t\[2\]"),
    (["time [s]", "elevation [N]"], [[i, 0] for i in range(5)], {},
     "must be a length"),
])
def test_bad_road_files_name_the_problem(tmp_path, header, rows, kw, match):
    m = load("quarter_car_halved")
    csv = _write(tmp_path / "r.csv", header, list(zip(*rows)))
    with pytest.raises(ValueError, match=match):
        road_input(m.system, csv, **kw)


def test_bad_engine_files_name_the_problem(tmp_path):
    m = load("six_dof_halved")
    ts = [0.0, 0.1, 0.2, 0.3]
    bad = _write(tmp_path / "e.csv", ["time [s]", "q [N]"], [ts, ts])
    with pytest.raises(ValueError, match=r"\['q'\] are not DOFs"):
        engine_input(m.system, bad)
    mixed = _write(tmp_path / "m.csv", ["time [s]", "z [N]", "x [g]"], [ts, ts, ts])
    with pytest.raises(ValueError, match="all be forces"):
        engine_input(m.system, mixed)
    table = read_measured(mixed)
    assert table.units == {"time": "s", "z": "N", "x": "g"}


def test_spectra_parseval_and_files(tmp_path):
    """A bin-centred sine force of amplitude F and velocity amplitude V: the PSD
    integrals are F^2 / 2 and, for the acceleration (central difference of the
    velocity), (V sin(omega dt) / dt)^2 / 2."""
    dt, n, nper = 1e-3, 4096, 1024
    f0 = 40 / (nper * dt)  # on a Welch bin
    w = 2 * math.pi * f0
    t = np.arange(n) * dt
    F, V = 120.0, 0.01
    th = vehicle.TimeHistory(
        t=t, q=np.zeros((n, 1)), qd=V * np.sin(w * t)[:, None],
        forces=F * np.sin(w * t)[:, None], friction_forces=np.zeros((n, 1)),
        deflections=np.zeros((n, 1)), friction_energy=np.zeros(n), dof_names=("x",),
        force_names=("mount_axial",), dt=dt, system_name="sine")
    sp = spectra(th, segment_s=nper * dt)
    df = sp.freq_hz[1] - sp.freq_hz[0]
    assert np.sum(sp.force_psd[:, 0]) * df == pytest.approx(F ** 2 / 2,
                                                            rel=PARSEVAL_RTOL)
    # the central difference of V sin(w t) has amplitude V sin(w dt) / dt
    assert np.sum(sp.acceleration_psd[:, 0]) * df == pytest.approx(
        (V * math.sin(w * dt) / dt) ** 2 / 2, rel=PARSEVAL_RTOL)
    assert sp.freq_hz[np.argmax(sp.force_psd[:, 0])] == pytest.approx(f0)
    sp.to_csv(tmp_path / "s.csv")
    head = (tmp_path / "s.csv").read_text().splitlines()[:2]
    assert "N^2/Hz" in head[0] and head[1] == "freq_hz,F_mount_axial_psd,x_acc_psd"
    fig = sp.plot(tmp_path / "s.png")
    assert (tmp_path / "s.png").stat().st_size > 1000
    titles = [ax.get_title() for ax in fig.axes]
    assert all(titles) and "N^2/Hz" in fig.axes[0].get_ylabel()
    assert fig.axes[1].get_xlabel() == "frequency [Hz]"
    with pytest.raises(ValueError, match="`skip`"):
        spectra(th, skip=5.0)


def _road_csv(path, system, T=1.0, dt=1e-3):
    road = vehicle.RandomRoad(system, "C", speed=20.0, seed=3)
    ts = np.arange(round(T / dt) + 5) * dt
    return _write(path, ["distance [m]", "elevation"],
                  [20.0 * ts, 1e3 * road.base(ts)[:, 0]]), road


def test_config_cosim_input_and_the_cli(tmp_path, capsys):
    """``[cosim.input]`` (file relative to the configuration, units from the file)
    and ``drymount cosim --road`` give the API's run; spectra are written."""
    from drymount.cli import main
    from drymount.config import load_config, preset_text

    m = load("quarter_car_halved")
    (tmp_path / "data").mkdir()
    _road_csv(tmp_path / "data" / "road.csv", m.system)
    text = preset_text("quarter_car_halved") + (
        '\n[cosim.input]\nroad = "data/road.csv"\nspeed = 20.0\n'
        '[cosim.input.units]\nelevation = "mm"\n')
    (tmp_path / "qc.toml").write_text(text)
    ref = cosim(load(tmp_path / "qc.toml"), backend="inproc", dt=1e-3)
    direct = cosim(m, road=tmp_path / "data" / "road.csv", speed=20.0,
                   units={"elevation": "mm"}, backend="inproc", dt=1e-3)
    assert np.array_equal(ref.q, direct.q)
    out, psd = tmp_path / "run.csv", tmp_path / "psd.csv"
    code = main(["cosim", str(tmp_path / "qc.toml"), "--backend", "inproc",
                 "--out", str(out), "--spectra", str(psd), "--spectra-plot",
                 str(tmp_path / "psd.png"), "--skip", "0.2"])
    assert code == 0
    rows = out.read_text().splitlines()
    assert len(rows) == 2 + len(ref.t)
    assert "N^2/Hz" in psd.read_text().splitlines()[0]
    # a unit that does not exist is a configuration problem with its field path
    bad = text.replace('elevation = "mm"', 'elevation = "furlong"')
    (tmp_path / "bad.toml").write_text(bad)
    from drymount.config import ConfigError

    with pytest.raises(ConfigError, match=r"`cosim.input.units.elevation` must be "
                                          r"one of m, mm"):
        load_config(tmp_path / "bad.toml")
    # a file problem exits with 2 and names the file
    capsys.readouterr()
    code = main(["cosim", "quarter_car_halved", "--road",
                 str(tmp_path / "data" / "road.csv"), "--backend", "inproc"])
    assert code == 2
    assert "column `elevation` has no unit" in capsys.readouterr().err
