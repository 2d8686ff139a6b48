"""The inclined two-surface element (fmu_src/inclined.py) vs independent references.

* Fine-step reference: the same kinematics (eq. 5.1-5.10 as corrected in
  docs/physics.md) written here as one 4x4 linear system in (f1, f2, N, N2), marched
  in tiny increments, each increment settled at its end point only (trial stick, else
  the slipping regimes of the trial signs). Where no surface re-sticks inside an
  increment this end-point march is exact, so the exact event map must agree to
  rounding.
* The 90-degree limit with a bonded second surface equals the Jenkins element.
* Energy: the slip energy of a closed cycle equals the loop area.
"""

import math

import numpy as np
import pytest

from drymount.fmu_src.inclined import ContactLost, InclinedParameters, inclined_update
from drymount.fmu_src.mount_law import jenkins_update

#: exact map vs fine-step reference, relative to the peak force (measured 2.2e-16)
FINE_STEP_TOL = 1e-9
#: 90-degree limit vs Jenkins, relative to the slip force (measured 0, exact)
JENKINS_TOL = 1e-12
#: slip energy of a cycle vs loop area (trapezoid, 2e4 steps), relative (measured 2e-8)
ENERGY_TOL = 1e-6

DESIGNS = [
    InclinedParameters(),
    InclinedParameters(theta_deg=45.0, k=5e4, kf=8e4, kf2=3e4, mu1=0.2, mu2=0.4,
                       preload=300.0),
    InclinedParameters(theta_deg=75.0, k=1e4, kf=4e4, kf2=1e5, mu1=0.5, mu2=0.1,
                       preload=600.0),
]


def _reference_regime(x, w1, w2, p, reg):
    """(f1, f2, N, N2) from the free-body equations as one 4x4 system."""
    t = math.radians(p.theta_deg)
    s, c = math.sin(t), math.cos(t)
    a = x * c / s
    A = np.zeros((4, 4))
    b = np.zeros(4)
    # wedge horizontal (5.3 with preload): N s - f1 c - f2 = k a + P
    A[0] = [-c, -1.0, s, 0.0]
    b[0] = p.k * a + p.preload
    # wedge vertical (5.2): N2 - f1 s - N c = 0
    A[1] = [-s, 0.0, -c, 1.0]
    if reg[0] == 0:
        A[2] = [1.0, 0.0, 0.0, 0.0]
        b[2] = p.kf * (x / s - w1)
    else:
        A[2] = [1.0, 0.0, -reg[0] * p.mu1, 0.0]
    if reg[1] == 0:
        A[3] = [0.0, 1.0, 0.0, 0.0]
        b[3] = p.kf2 * (a - w2)
    else:
        A[3] = [0.0, 1.0, 0.0, -reg[1] * p.mu2]
    return np.linalg.solve(A, b), s, c, a


def _reference_step(x, w1, w2, p):
    """End-point settlement of one tiny increment; returns (F, w1, w2).

    The admissible regime with the fewest slipping surfaces: stuck surfaces inside
    their friction cone, slipping ones at the limit with the slider moved in the
    direction of their force.
    """
    regimes = sorted(((a, b) for a in (0, 1, -1) for b in (0, 1, -1)),
                     key=lambda r: abs(r[0]) + abs(r[1]))
    for reg in regimes:
        (f1, f2, n1, n2), s, c, a = _reference_regime(x, w1, w2, p, reg)
        nw1 = x / s - f1 / p.kf if reg[0] else w1
        nw2 = a - f2 / p.kf2 if reg[1] else w2
        ok1 = (abs(f1) <= p.mu1 * n1 * (1 + 1e-12) if reg[0] == 0
               else reg[0] * (nw1 - w1) >= 0)
        ok2 = (abs(f2) <= p.mu2 * n2 * (1 + 1e-12) if reg[1] == 0
               else reg[1] * (nw2 - w2) >= 0)
        if ok1 and ok2:
            return n2, nw1, nw2
    raise AssertionError(f"reference found no regime at x = {x}")


def _path(rng, n_turns=6, scale=0.006):
    """Random turning points of a monotone-piecewise trajectory, m."""
    return np.concatenate([[0.0], rng.uniform(-0.2, 1.0, n_turns) * scale])


@pytest.mark.parametrize("p", DESIGNS)
def test_exact_map_matches_fine_step_reference(p):
    rng = np.random.default_rng(14)
    turns = _path(rng)
    w1 = w2 = r1 = r2 = 0.0
    worst, peak = 0.0, 0.0
    for x0, x1 in zip(turns[:-1], turns[1:]):
        step = inclined_update(x1, x0, w1, w2, p)   # one call per monotone branch
        w1, w2 = step.w1, step.w2
        for x in np.linspace(x0, x1, 4001)[1:]:
            F_ref, r1, r2 = _reference_step(x, r1, r2, p)
        peak = max(peak, abs(F_ref))
        worst = max(worst, abs(step.force - F_ref), abs(step.w1 - r1) * p.kf,
                    abs(step.w2 - r2) * p.kf2)
    assert worst <= FINE_STEP_TOL * peak, (worst, peak)


def test_ninety_degrees_with_bonded_second_surface_is_jenkins():
    p = InclinedParameters(theta_deg=90.0, mu2=math.inf, mu1=0.4, preload=250.0,
                           kf=7e4, k=3e4)
    fs = p.mu1 * p.preload
    rng = np.random.default_rng(5)
    xs = np.cumsum(rng.normal(0, 0.002, 300))
    w1 = w2 = wj = 0.0
    xo = 0.0
    for x in xs:
        st = inclined_update(x, xo, w1, w2, p)
        fj, wj, kt, slip = jenkins_update(x, wj, p.kf, fs)
        assert abs(st.force - fj) <= JENKINS_TOL * fs
        assert abs(st.n1 - p.preload) <= JENKINS_TOL * fs
        assert st.slip1 == slip
        w1, w2, xo = st.w1, st.w2, x


@pytest.mark.parametrize("p", DESIGNS)
def test_cycle_energy_equals_loop_area(p):
    n = 20000
    x = 0.005 * np.sin(np.linspace(0, 4 * np.pi, 2 * n + 1)) + 0.002
    w1 = w2 = 0.0
    F = np.empty_like(x)
    E = np.empty_like(x)
    xo, e = 0.0, 0.0
    for i, xi in enumerate(x):
        st = inclined_update(xi, xo, w1, w2, p)
        w1, w2, xo = st.w1, st.w2, xi
        e += st.dissipated
        F[i], E[i] = st.force, e
    area = np.trapezoid(F[n:], x[n:])     # second cycle, closed
    diss = E[-1] - E[n]
    assert diss > 0
    assert abs(area - diss) <= ENERGY_TOL * diss, (area, diss)


def test_parameter_checks_name_field_and_value():
    with pytest.raises(ValueError, match="theta_deg.*got 95"):
        InclinedParameters(theta_deg=95)
    with pytest.raises(ValueError, match="self-locks"):
        InclinedParameters(theta_deg=10, mu1=0.5)
    with pytest.raises(ValueError, match="`kf2` must be finite and > 0, got 0"):
        InclinedParameters(kf2=0)


def test_lost_contact_is_reported():
    p = InclinedParameters(preload=10.0, k=5e4)
    with pytest.raises(ContactLost, match="N"):
        inclined_update(-0.01, 0.0, 0.0, 0.0, p)


def test_surface_at_its_limit_with_a_vanishing_normal_force_slips():
    """Regression (study incline, 75 degrees): N2 = 0.005 N, the flat surface at its
    limit within the rounding of the 100 N forces around it; the walk used to stop at
    the start for ever ("more than 64 stick/slip events")."""
    p = InclinedParameters(theta_deg=75.0, k=5000.0, kf=6e4, kf2=6e4, mu1=0.3, mu2=0.3,
                           preload=100.0)
    x_old, x = 0.013761253808459595, 0.013760826624516402
    w1, w2 = 0.014757511768119893, 0.003687340007461514
    # the flat surface slips (its limit is reached at once) and then opens: N2 < 0
    # by x (measured -0.021 N), an honest ContactLost, not the event-count guard
    with pytest.raises(ContactLost, match="loses contact at x"):
        inclined_update(x, x_old, w1, w2, p)


def _loop_energy(kf: float, X: float = 3e-3, n: int = 256) -> float:
    """Energy dissipated in the third period of x = X sin(2 pi i / n) (J)."""
    p = InclinedParameters(theta_deg=60.0, k=20000.0, kf=kf, kf2=kf, mu1=0.3,
                           mu2=0.3, preload=200.0)
    w1 = w2 = x_old = 0.0
    energy = []
    for i in range(1, 3 * n + 1):
        x = X * math.sin(2 * math.pi * i / n)
        st = inclined_update(x, x_old, w1, w2, p)
        w1, w2, x_old = st.w1, st.w2, x
        energy.append(st.dissipated)
    return sum(energy[2 * n:])


#: kf = kf2 = 1e9 N/m against the rigid-contact limit (issue 26 item 5)
RTOL_RIGID = 1e-4


def test_stiff_contacts_run_and_converge_to_the_rigid_loop_energy():
    # the at-limit test was 1e-12 relative, below a contact force's rounding kf ulp(x)
    # at kf = 1e9: "more than 64 stick/slip events" (X = 3 mm, 256 steps a period).
    # Rigid limit: the error of the contact compliance is O(1/kf) (measured: the
    # energy changes 3.9e-4 J from 1e8 to 1e9 and 3.9e-5 J from 1e9 to 1e10), so
    # Richardson from 1e10 and 1e11 gives it to O(1e-11 relative)
    e9, e10, e11 = (_loop_energy(kf) for kf in (1e9, 1e10, 1e11))
    rigid = e11 + (e11 - e10) / 9.0
    assert abs(e10 - rigid) < abs(e9 - rigid) / 5  # converging, O(1/kf)
    assert abs(e9 - rigid) <= RTOL_RIGID * rigid
