"""The inclined element's static working point read two ways (issue 26 item 4):
relaxed (both surfaces unloaded) and lowered onto the assembled mount, and the range
of admissible static deflections, against references written here from eq. 5.1-5.10
(thesis Ch. 5, docs/physics.md): a displacement-driven quasi-static loading march of
the element with fine steps (its own regime logic, numpy solves), and the slip-slip
regimes' equilibria in closed form.

sdof_inclined (70 kg, k1 = 45 935 N/m, 60 degrees, k = 20 kN/m, P = 200 N,
kf = kf2 = 60 kN/m, mu = 0.3): relaxed -10.86 mm with N = 376 N, lowered -5.87 mm
with N = 549 N, admissible -13.25 to -5.87 mm (the issue's numbers).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drymount.cli import main as cli_main
from drymount.config import load_preset
from drymount.config.static import vertical_dofs
from drymount.hbm.static import (admissible_range, gravity_load, lowered_equilibrium,
                                 static_equilibrium)

M, G, K1 = 70.0, 9.81, 45935.0
TH, KW, KF, KF2, MU1, MU2, P = math.radians(60.0), 2e4, 6e4, 6e4, 0.3, 0.3, 200.0
S, C = math.sin(TH), math.cos(TH)


def _forces(x, w1, w2, slip):
    """(f1, f2, N, N2) at wedge deflection x: rows stuck f_i = kf_i (d_i - w_i) or
    slipping forward f_i = mu_i N_i, with N = (c f1 + f2 + k a + P) / s and
    N2 = (f1 + c (f2 + k a + P)) / s, a = x c / s, d1 = x / s."""
    q = KW * x * C / S + P
    A = np.zeros((4, 4))
    b = np.zeros(4)
    A[2] = [-C / S, -1 / S, 1, 0]
    b[2] = q / S
    A[3] = [-1 / S, -C / S, 0, 1]
    b[3] = C * q / S
    if slip[0]:
        A[0] = [1, 0, -MU1, 0]
    else:
        A[0, 0], b[0] = 1, KF * (x / S - w1)
    if slip[1]:
        A[1] = [0, 1, 0, -MU2]
    else:
        A[1, 1], b[1] = 1, KF2 * (x * C / S - w2)
    return np.linalg.solve(A, b)


def _reference_lowering(dx=2e-6):
    """March x (into the wedge) up from 0, the element relaxed at 0; a surface that
    exceeds its limit slips forward from then on (monotonic loading). Returns the
    deflection x where k1 x + N2 = m g and N there (linear interpolation)."""
    w1 = w2 = 0.0
    slip = [False, False]
    x, prev = 0.0, None
    while True:
        while True:
            f1, f2, n1, n2 = _forces(x, w1, w2, slip)
            over = [not slip[0] and abs(f1) > MU1 * n1,
                    not slip[1] and abs(f2) > MU2 * n2]
            if not any(over):
                break
            slip = [s or o for s, o in zip(slip, over)]
        if slip[0]:
            w1 = x / S - f1 / KF
        if slip[1]:
            w2 = x * C / S - f2 / KF2
        g = K1 * x + n2 - M * G
        if g >= 0:
            t = prev[1] / (prev[1] - g)
            return prev[0] + t * dx, prev[2] + t * (n1 - prev[2])
        prev = (x, g, n1)
        x += dx


def _slip_slip_deflection(sig1, sig2):
    """k1 x + N2(x) = m g with both surfaces slipping (f_i = sig_i mu_i N_i): the
    regime's N2 is affine in x."""
    def n2(x):
        q = KW * x * C / S + P
        A = np.array([[S - sig1 * MU1 * C, -sig1 * MU1],
                      [-sig2 * MU2, S - sig2 * MU2 * C]])
        f1, f2 = np.linalg.solve(A, [sig1 * MU1 * q, sig2 * MU2 * C * q])
        return (f1 + C * f2 + C * q) / S
    a, b = n2(0.0), n2(1.0) - n2(0.0)
    return (M * G - a) / (K1 + b)


@pytest.fixture(scope="module")
def loaded():
    cfg = load_preset("sdof_inclined")
    s = cfg.system
    return s, gravity_load(s, vertical_dofs(cfg.model, list(s.dof_names)), G)


def test_relaxed_and_lowered_readings(loaded):
    system, load = loaded
    relaxed = static_equilibrium(system, load)
    x_relaxed = (M * G - C * P / S) / (K1 + KW * C * C / (S * S))
    assert -relaxed.deflection[0, 0] == pytest.approx(x_relaxed, abs=1e-12)
    lowered = lowered_equilibrium(system, load)
    x_ref, n_ref = _reference_lowering()
    assert lowered.reading == "lowered" and lowered.status.value == "converged"
    # both surfaces slip at the end, a regime without memory: the reference is
    # exact for any dx (measured difference 0 at dx = 2e-7, 1e-6, 4e-6 m); with a
    # surface still stuck its error would be O(kf dx / (k1 + k)) ~ 2e-6 m
    assert -lowered.deflection[0, 0] == pytest.approx(x_ref, abs=1e-9)
    from drymount.fmu_src.inclined import axis_normal_forces
    p = system.elements[0].params.axes[0].element_params
    n1, _ = axis_normal_forces(lowered.states[(0, 0)], p)
    assert n1 == pytest.approx(n_ref, abs=1e-6)
    assert x_ref == pytest.approx(5.87e-3, abs=5e-6) and n_ref == pytest.approx(
        548.7, abs=0.5)
    # any step count gives the same point (the deflection is monotonic in the load)
    assert lowered_equilibrium(system, load, steps=3).deflection[0, 0] == \
        pytest.approx(lowered.deflection[0, 0], abs=1e-12)


def test_admissible_range(loaded):
    system, load = loaded
    (r,) = admissible_range(system, load)
    ends = [_slip_slip_deflection(a, b) for a in (1, -1) for b in (1, -1)]
    assert -r.high == pytest.approx(min(ends), abs=1e-12)
    assert -r.low == pytest.approx(max(ends), abs=1e-12)
    assert -r.low == pytest.approx(13.25e-3, abs=5e-6)
    # both readings lie in it, the lowered one at its end
    relaxed = static_equilibrium(system, load).deflection[0, 0]
    assert r.low < relaxed < r.high
    assert lowered_equilibrium(system, load).deflection[0, 0] == pytest.approx(
        r.high, abs=1e-9)


def test_static_command_prints_both_readings(tmp_path, capsys):
    assert cli_main(["static", "sdof_inclined", "--out", str(tmp_path / "s.csv")]) == 0
    out = capsys.readouterr().out
    assert "relaxed deflection  -10.8595 mm" in out and "N = 375.73 N" in out
    assert "lowered deflection   -5.8732 mm" in out and "N = 548.71 N" in out
    assert "admissible static deflections -13.2528 to -5.8732 mm" in out
