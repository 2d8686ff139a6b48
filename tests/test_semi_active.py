"""Study semi-active (drymount.studies.semi_active) and the run-up input."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from drymount.studies import semi_active as sa
from drymount.studies.common import load_system
from drymount.vehicle import CrankInput, CrankRunUp

#: same formula, arrays vs the constant-speed input: measured 0
EXACT = 1e-12
#: crank angle by the closed-form integral vs a fine trapezoid of the speed:
#: measured 3e-12 of the force scale
PHASE = 1e-9


def test_run_up_is_the_crank_load_at_the_integrated_angle():
    system = load_system("quarter_car_halved")
    t = np.linspace(0.0, 3.0, 300001)
    const = CrankRunUp(system, 1500.0, 1500.0, 2.0)
    ref = CrankInput(system, 1500.0)
    scale = np.abs(ref.force(t)).max()
    assert np.max(np.abs(const.force(t) - ref.force(t))) <= EXACT * scale
    ru = CrankRunUp(system, 600.0, 6000.0, 2.0)
    w = 2 * math.pi * ru.speed(t) / 60.0
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    f = ru.engine.force(theta, w)
    got = ru.force(t)[:, list(system.dof_names).index("engine")]
    assert np.max(np.abs(got - f)) <= PHASE * np.abs(f).max()
    assert ru.second_order(0.0) == pytest.approx(20.0)
    assert ru.second_order(5.0) == pytest.approx(200.0)


@pytest.fixture
def small(monkeypatch):
    """The study cut to the quarter car, two frequencies, two n0 and short runs."""
    monkeypatch.setattr(sa, "MODELS", sa.MODELS[1:2])
    monkeypatch.setattr(sa, "N0_FACTORS", (0.3, 1.0))
    monkeypatch.setattr(sa, "SCHEDULE_HZ", (20.0, 120.0))
    monkeypatch.setattr(sa, "RUNUP_S", (8.0, 0.3))
    monkeypatch.setattr(sa, "ROAD_S", (8.0, 0.4))


def test_study_outputs_and_passive_choice(small, tmp_path):
    out = sa.run_semi_active(tmp_path, quick=True, progress=False)
    text = (tmp_path / "semi_active.csv").read_text().splitlines()
    rows = list(csv.DictReader(line for line in text if not line.startswith("#")))
    designs = {(r["scenario"], r["design"]) for r in rows}
    laws = ("balance", "skyhook", "growth")
    assert designs == ({("run-up", "passive original"), ("run-up", "passive best n0"),
                        ("run-up", "scheduled"), ("road", "passive original"),
                        ("road", "passive best n0")}
                       | {(s, law) for s in ("run-up", "road") for law in laws})
    n0 = 30.0  # quarter_car_halved
    for scenario in ("run-up", "road"):
        by = {r["design"]: r for r in rows if r["scenario"] == scenario}
        assert float(by["passive original"]["n0_N"]) == n0
        assert float(by["passive best n0"]["n0_N"]) in (0.3 * n0, n0)
        assert float(by["passive best n0"]["rms_force_N"]) <= float(
            by["passive original"]["rms_force_N"])
        for r in by.values():
            assert 0 < float(r["rms_force_N"]) <= float(r["peak_force_N"])
    assert out["rms_force"]["quarter car/road/balance"] > 0 and not out["failures"]
    md = (tmp_path / "summary.md").read_text()
    assert "| quarter car | road | balance |" in md and "HBM schedule" in md
    assert (tmp_path / "semi_active_quarter.png").stat().st_size > 10_000


def test_hbm_schedule_picks_the_smallest_transmissibility():
    import drymount.hbm as hbm

    system = load_system("quarter_car_halved")
    grid = (3.0, 30.0)
    f, n = sa.hbm_schedule(system, grid, freqs=(20.0, 60.0))
    for k, fk in enumerate(f):
        tr = [hbm.solve_frequencies(sa._crank_system(sa._scaled_n0(system, g)), [fk],
                                    harmonics=3).transmissibility[0] for g in grid]
        assert n[k] == grid[int(np.argmin(tr))]


@pytest.mark.slow
def test_quick_study_runs(tmp_path):
    out = sa.run_semi_active(tmp_path, quick=True, progress=False)
    assert len(out["rms_force"]) == 42 and len(out["files"]) == 5


def test_suspended_road_is_the_quarter_car_body_response():
    from drymount.vehicle.inputs import RandomRoad, SuspendedRoad

    system = load_system("six_dof_halved")
    raw = RandomRoad(system, "C", 20.0, seed=1)
    body = SuspendedRoad(system, "C", 20.0, seed=1)
    # state space of the 2-DOF suspension (body zs, wheel zu), road r as input:
    # H = C (i w - A)^-1 B
    ms, mu, ks, cs, kt = 300.0, 30.0, 15000.0, 1000.0, 200000.0
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-ks / ms, ks / ms, -cs / ms, cs / ms],
                  [ks / mu, -(ks + kt) / mu, cs / mu, -cs / mu]])
    B = np.array([0, 0, 0, kt / mu])
    w = 2 * np.pi * raw.n * raw.speed
    h = np.array([np.linalg.solve(1j * wi * np.eye(4) - A, B)[0] for wi in w])
    np.testing.assert_allclose(body.amplitudes, raw.amplitudes * np.abs(h), rtol=1e-9)
    dphi = np.angle(np.exp(1j * (body.phases - raw.phases - np.angle(h))))
    assert np.max(np.abs(dphi)) < 1e-9
