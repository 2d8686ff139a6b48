"""The ``auto`` march (hbm.march_choice): NumPy until numba's start has paid, the same
numbers either way, numba loaded only then, a cold cache warmed in the background."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import drymount.hbm.friction_march as fm
from drymount.hbm import march_choice
from drymount.hbm.march_choice import AutoMarch

ROOT = Path(__file__).resolve().parents[1]
needs_numba = pytest.mark.skipif(
    not fm._HAVE_NUMBA, reason="numba not installed: pip install 'drymount[fast]'")


def test_without_numba_always_numpy():
    a = AutoMarch(have_numba=False, warm_start_s=0.0)
    a.spent(10.0)
    assert a.choose() == "numpy" and a.warming is None


def test_switches_once_the_numpy_marches_cost_the_start(monkeypatch):
    monkeypatch.setattr(march_choice, "cache_is_warm", lambda: True)
    monkeypatch.delitem(sys.modules, march_choice._MODULE, raising=False)
    a = AutoMarch(have_numba=True, warm_start_s=1.0, warmup_after_s=0.25,
                  scale_by_start=False)
    for _ in range(7):  # 0.125 s each: exact sums
        a.spent(0.125)
        assert a.choose() == "numpy"
    a.spent(0.125)
    assert a.choose() == "numba" and a.choose() == "numba"
    assert a.warming is None  # a warm cache is not compiled again


def test_cold_cache_is_warmed_in_the_background_and_waited_for(monkeypatch):
    started = []

    class Running:
        done = False

        def poll(self):
            return 0 if self.done else None

    proc = Running()
    monkeypatch.setattr(march_choice, "cache_is_warm", lambda: proc.done)
    monkeypatch.setattr(march_choice, "start_warmup",
                        lambda: started.append(1) or proc)
    monkeypatch.delitem(sys.modules, march_choice._MODULE, raising=False)
    a = AutoMarch(have_numba=True, warm_start_s=1.0, warmup_after_s=0.25,
                  scale_by_start=False)
    a.spent(0.2)
    assert started == []
    a.spent(0.1)
    assert started == [1]  # one warm-up, however long the run
    a.spent(2.0)
    assert a.choose() == "numpy"  # still compiling: go on with NumPy
    a.spent(1.0)
    assert started == [1]
    proc.done = True
    a.spent(1.0)
    assert a.choose() == "numba"


@needs_numba
def test_the_threshold_scales_with_the_start_up(monkeypatch):
    monkeypatch.delitem(sys.modules, march_choice._MODULE, raising=False)
    monkeypatch.setattr(AutoMarch, "clock", staticmethod(lambda: 2.0))
    a = AutoMarch(have_numba=True, warm_start_s=1.0)
    assert a.choose() == "numpy"
    assert a.warm_start_s == pytest.approx(march_choice.START_RATIO * 2.0)
    monkeypatch.setattr(AutoMarch, "clock", staticmethod(lambda: 100.0))
    b = AutoMarch(have_numba=True, warm_start_s=1.0)
    b.choose()
    assert b.warm_start_s == march_choice.MAX_START_S


@needs_numba
def test_auto_gives_the_numbers_of_both_backends():
    rng = np.random.default_rng(3)
    N, C = 64, 2
    th = 2 * np.pi * np.arange(N) / N
    u = (rng.normal(size=(3, 1, C)) * 1e-3 * np.sin(th)[None, :, None]
         + rng.normal(size=(3, 1, C)) * 4e-4 * np.sin(3 * th + 1)[None, :, None])
    kf, fs, w0 = np.array([6e4, 3e4]), np.array([20.0, 5.0]), np.zeros(C)
    E = rng.normal(size=(N, 7))
    P = np.linalg.pinv(E)
    ref = {b: fm.jenkins_aft(u, kf, fs, w0, E, P, backend=b)
           for b in ("numpy", "numba")}
    got = fm.jenkins_aft(u, kf, fs, w0, E, P, backend="auto")
    for b in ref:
        np.testing.assert_allclose(got[0], ref[b][0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(got[1], ref[b][1], rtol=0,
                                   atol=1e-12 * np.abs(ref[b][1]).max())


_SMALL_CURVE = """
import json, sys
import drymount
curve = drymount.hbm(drymount.load("sdof_halved"), 4.0, 12.0, harmonics=3,
                     n_samples=64, progress=False)
import drymount.hbm.friction_march as fm
print(json.dumps({"numba": "numba" in sys.modules, "spent": fm.AUTO.spent_s,
                  "limit": fm.AUTO.warm_start_s,
                  "peak": float(max(curve.transmissibility))}))
"""


@needs_numba
def test_a_small_curve_does_not_load_numba():
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    env.pop("DRYMOUNT_MARCH", None)
    p = subprocess.run([sys.executable, "-c", _SMALL_CURVE], env=env,
                       capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout.splitlines()[-1])
    assert r["spent"] < r["limit"]
    assert not r["numba"]
