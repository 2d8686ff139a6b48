"""Bifurcations classified and located on a forced branch (issue 29, item 3).

The reference is written here: shooting on the equation of motion with its variational
equations (scipy's DOP853 at rtol 1e-11), the Floquet multipliers as the eigenvalues of
the monodromy matrix, and the frequency where the spectral radius crosses 1 found by
Brent's method. The system is the thesis's cubic mount fit (k1 = 34 770 N/m,
kc = 5.708e8 N/m^3, c = 150 N s/m, 70 kg, as ``sdof_cubic``) under the engine's weight:
about its static working point the cubic spring has a quadratic part, so near twice the
linearised natural frequency (7.8 Hz) a large unbalance (0.08 kg m) pumps the
principal parametric resonance and the period-1 solution loses stability through a
multiplier -1 (period doubling) at about 14.36 Hz and regains it at about 16.39 Hz.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import drymount
from drymount.hbm.bifurcation import BifurcationKind, classify

M, C, K1, KC, F0, G = 70.0, 150.0, 34770.0, 5.708e8, 0.08, 9.81

CONFIG = f"""
model = "sdof"
name = "sdof_cubic_pd"
[sdof]
mass = {M}
[mount]
law = "cubic"
k1 = {K1}
kc = {KC}
c = {C}
[excitation]
kind = "unbalance"
amplitude = {F0}
[sweep]
fmin_hz = 10.0
fmax_hz = 20.0
[hbm]
harmonics = 8
[static]
gravity = true
g = {G}
"""

#: HBM at H = 8 against the shooting reference (measured: 1.0e-6 and 1.1e-6 Hz).
FREQ_TOL_HZ = 1e-3


def _rhs(t, y, w):
    x, v = y[0], y[1]
    phi = y[2:].reshape(2, 2)
    a = (-C * v - K1 * x - KC * x**3 - M * G + F0 * w * w * np.sin(w * t)) / M
    A = np.array([[0.0, 1.0], [-(K1 + 3 * KC * x * x) / M, -C / M]])
    return np.concatenate([[v, a], (A @ phi).ravel()])


def _period_map(y0, w):
    s = solve_ivp(_rhs, (0.0, 2 * np.pi / w), np.concatenate([y0, np.eye(2).ravel()]),
                  args=(w,), method="DOP853", rtol=1e-11, atol=1e-13)
    return s.y[:2, -1], s.y[2:, -1].reshape(2, 2)


class _Shooting:
    """Periodic orbits by Newton shooting, continued in frequency (warm starts)."""

    def __init__(self):
        x_static = brentq(lambda x: K1 * x + KC * x**3 + M * G, -0.1, 0.1)
        self.y0 = np.array([x_static, 0.0])

    def multipliers(self, f_hz: float) -> np.ndarray:
        w = 2 * np.pi * f_hz
        for _ in range(30):
            yT, phi = _period_map(self.y0, w)
            step = np.linalg.solve(phi - np.eye(2), self.y0 - yT)
            self.y0 = self.y0 + step
            if np.linalg.norm(step) < 1e-12:
                break
        return np.linalg.eigvals(_period_map(self.y0, w)[1])


@pytest.fixture(scope="module")
def reference():
    """The two period-doubling frequencies and the multipliers just inside."""
    sh = _Shooting()
    sh.multipliers(14.0)
    out = {}
    for lo, hi in ((14.25, 14.5), (16.25, 16.5)):
        f = brentq(lambda f: np.max(np.abs(sh.multipliers(f))) - 1.0, lo, hi,
                   xtol=1e-7)
        out[f] = sh.multipliers(f + (1e-3 if lo < 15 else -1e-3))
    return out


@pytest.fixture(scope="module")
def curve(tmp_path_factory):
    path = tmp_path_factory.mktemp("pd") / "pd.toml"
    path.write_text(CONFIG, encoding="utf-8")
    return drymount.hbm(drymount.load(str(path)), progress=False).result


def test_the_reference_crosses_at_minus_one(reference):
    for mu in reference.values():
        assert np.all(np.abs(mu.imag) < 1e-9)
        assert np.min(mu.real) < -1.0  # a real multiplier beyond -1: period doubling


def test_period_doublings_located_against_shooting(curve, reference):
    found = [b for b in curve.bifurcations if b.kind == "period-doubling"]
    assert len(found) == 2, curve.bifurcations
    for b, f_ref in zip(sorted(found, key=lambda b: b.freq_hz), sorted(reference),
                        strict=True):
        assert b.converged
        assert abs(b.freq_hz - f_ref) < FREQ_TOL_HZ, (b.freq_hz, f_ref)
        assert b.multiplier.real < -1.0 and abs(b.multiplier.imag) < 1e-6
    # the stability verdict follows: unstable exactly between the two
    lo, hi = sorted(b.freq_hz for b in found)
    inside = (curve.freq_hz > lo) & (curve.freq_hz < hi)
    assert inside.any() and not curve.stable[inside].any()
    assert curve.stable[~inside].all()


def test_events_csv_and_sweep_jumps_carry_them(curve, tmp_path):
    path = tmp_path / "pd_events.csv"
    curve.events_to_csv(path)
    rows = [r.split(",") for r in path.read_text().splitlines()[2:]]
    pd_rows = [r for r in rows if r[0] == "period-doubling"]
    assert [float(r[2]) for r in pd_rows] == pytest.approx(
        sorted(b.freq_hz for b in curve.bifurcations), abs=1e-9)
    up = curve.sweep_jumps("up")
    assert up and up[0][2] == -1
    assert up[0][0] == pytest.approx(min(b.freq_hz for b in curve.bifurcations),
                                     abs=1e-12)


@pytest.mark.parametrize(("imag", "at_fold", "kind"), [
    (0.0, True, BifurcationKind.FOLD),
    (0.0, False, BifurcationKind.BRANCH_POINT),
    (0.5, False, BifurcationKind.PERIOD_DOUBLING),
    (-0.5, False, BifurcationKind.PERIOD_DOUBLING),
    (1.5, False, BifurcationKind.PERIOD_DOUBLING),  # a copy one strip up
    (1.0, False, BifurcationKind.BRANCH_POINT),  # a copy of a real exponent
    (0.31, False, BifurcationKind.NEIMARK_SACKER),
    (0.69, False, BifurcationKind.NEIMARK_SACKER),
])
def test_classify_by_where_the_multiplier_crosses(imag, at_fold, kind):
    omega = 2 * np.pi * 7.0
    assert classify(complex(0.01, imag * omega), omega, at_fold) is kind
    mu = np.exp(complex(0.0, imag * omega) * 2 * np.pi / omega)
    expected = {BifurcationKind.FOLD: 1, BifurcationKind.BRANCH_POINT: 1,
                BifurcationKind.PERIOD_DOUBLING: -1}.get(kind)
    if expected is not None:
        assert mu.real == pytest.approx(expected, abs=1e-12)
    else:
        assert abs(mu.imag) > 0.1


def test_the_cli_summary_says_the_steady_state_is_not_periodic(tmp_path, capsys):
    from drymount.cli import main

    cfg = tmp_path / "pd.toml"
    cfg.write_text(CONFIG, encoding="utf-8")
    assert main(["hbm", str(cfg), "--out", str(tmp_path / "pd.csv")]) == 0
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if "period doubling" in ln]
    assert len(lines) == 2, out
    assert all("not this periodic solution" in ln and "drymount cosim" in ln
               for ln in lines)


@pytest.mark.slow
def test_the_six_dof_neimark_sacker_leaves_the_periodic_branch_in_cosimulation(
        tmp_path):
    """six_dof_halved: HBM says the resonant branch loses stability through a complex
    pair at 9.49 Hz; a stepped co-simulation sweep up that branch is periodic at 9.4 Hz
    and not periodic (not converged) at 9.5-9.8 Hz."""
    from drymount.cli import main

    out = tmp_path / "sweep.csv"
    main(["sweep", "six_dof_halved", "--fmin", "5", "--fmax", "9.8", "--points", "49",
          "--direction", "up", "--backend", "inproc", "--quiet", "--out", str(out)])
    lines = out.read_text(encoding="utf-8").splitlines()
    cols = lines[1].split(",")
    rows = {round(float(r.split(",")[0]), 6): r.split(",") for r in lines[2:]
            if not r.startswith("#")}
    conv = cols.index("converged")
    assert all(rows[round(f, 6)][conv] == "1" for f in np.arange(9.0, 9.41, 0.1))
    assert all(rows[round(f, 6)][conv] == "0" for f in np.arange(9.5, 9.81, 0.1))
    fr = drymount.hbm("six_dof_halved", 2.0, 10.5, harmonics=5, n_samples=128,
                      progress=False).result
    ns = [b.freq_hz for b in fr.bifurcations if b.kind == "neimark-sacker"]
    assert len(ns) == 1 and 9.4 < ns[0] < 9.5, fr.bifurcations
