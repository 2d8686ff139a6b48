"""The InclinedMount FMU (fmu_src/inclined_mount.py, built by fmu_build) through fmpy:
a valid FMU, its outputs equal to the law (fmu_src.inclined.inclined_update) on random
trajectories, FMU state save/restore, parameter errors, and the co-simulation of the
validate case's system (vehicle.inclined) against the in-process integration and HBM.
Runtime about 10 s (one FMU build, 4 x 400 steps, two co-simulated frequencies)."""

import math

import numpy as np
import pytest
import test_inclined

from fmu_build import build_fmu
from fmu_src.inclined import InclinedParameters, inclined_update
from fmu_src.inclined_mount import INCLINED_VARIABLES
from hbm.aft import FourierBasis
from hbm.inclined import InclinedSDOF, inclined_time_reference, solve_inclined_hbm
from vehicle.inclined import InclinedFMU, inclined_cosim_steady

#: FMU outputs vs the law in-process, relative to the force scale (measured 0: the FMU
#: runs the same Python function on the same floats)
FMU_VS_LAW_TOL = 1e-12
#: co-simulation through the FMU vs the same integration in-process, relative to the
#: peak-to-peak displacement (measured 0)
COSIM_VS_LAW_TOL = 1e-12
#: HBM (H = 7) vs FMU co-simulation, fundamental amplitude relative to it (the
#: acceptance bar of `drymount validate`; measured 0.30 % at 8.5 Hz)
HBM_VS_COSIM_TOL = 0.01

#: the law tests' designs plus the Jenkins limit (90 degrees, flat surface bonded)
DESIGNS = [*test_inclined.DESIGNS, InclinedParameters(theta_deg=90.0, mu2=math.inf)]


@pytest.fixture(scope="module")
def fmu_path(tmp_path_factory):
    return build_fmu(tmp_path_factory.mktemp("incl") / "InclinedMount.fmu",
                     model="InclinedMount")


def test_fmu_is_valid_with_units_and_descriptions(fmu_path):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(fmu_path)) == []
    md = read_model_description(str(fmu_path))
    names = [v.name for v in md.modelVariables]
    assert names == [v.name for v in INCLINED_VARIABLES]
    for v in md.modelVariables:
        assert v.description, v.name
        if v.type == "Real":
            assert v.unit, v.name
    assert md.coSimulation.canGetAndSetFMUstate
    units = {u.name: u for u in md.unitDefinitions}
    assert math.isclose(units["deg"].baseUnit.factor, math.pi / 180)


def _law_march(p, xs):
    w1 = w2 = x_old = energy = 0.0
    out = []
    for x in xs:
        st = inclined_update(x, x_old, w1, w2, p)
        out.append((st.force, st.n1, st.n2, st.f1, st.f2, st.tangent,
                    energy + st.dissipated, st.slip1, st.slip2))
        w1, w2, x_old, energy = st.w1, st.w2, x, energy + st.dissipated
    return out


@pytest.mark.parametrize("design", range(len(DESIGNS)))
def test_fmu_outputs_equal_the_law_on_random_trajectories(fmu_path, design):
    p = DESIGNS[design]
    rng = np.random.default_rng(design)
    # random walk with reversals, staying in contact (x > -preload / (k cot theta))
    xs = np.cumsum(rng.normal(0.0, 4e-4, 400)) * 0.5 + 0.002
    xs = np.clip(xs, -0.004, 0.012)
    ref = _law_march(p, xs)
    scale = max(abs(r[0]) for r in ref) + p.preload
    with InclinedFMU(p, 1e-3, fmu_path) as fmu:
        for i, x in enumerate(xs):
            fmu.set_inputs(0.0, 1.0)            # a trial read commits nothing ...
            fmu.outputs()
            fmu.set_inputs(float(x), 0.1)       # ... only doStep does
            o = fmu.outputs()
            got = (o.F, o.N, o.N2, o.f1, o.f2, o.kt * 1e-3, o.E_fr)
            want = (*ref[i][:5], ref[i][5] * 1e-3, ref[i][6])
            err = max(abs(a - b) for a, b in zip(got, want)) / scale
            assert err <= FMU_VS_LAW_TOL, (i, got, want)
            assert (o.slip1, o.slip2) == tuple(ref[i][7:])
            fmu.commit(i * 1e-3)
    slips = {(r[7], r[8]) for r in ref}
    assert len(slips) >= 2, slips   # the trajectory visits stick and slip


def test_fmu_state_restores_the_sliders_and_energy(fmu_path):
    p = DESIGNS[1]
    xs = 0.004 * np.sin(np.linspace(0.0, 6.0, 120)) + 0.002
    with InclinedFMU(p, 1e-3, fmu_path) as fmu:
        for i, x in enumerate(xs[:60]):
            fmu(float(x), 0.0, i * 1e-3)
        state = fmu.get_state()
        first = []
        for i, x in enumerate(xs[60:]):
            fmu.set_inputs(float(x))
            first.append(fmu.outputs())
            fmu.commit((60 + i) * 1e-3)
        fmu.set_state(state)
        for i, x in enumerate(xs[60:]):
            fmu.set_inputs(float(x))
            assert fmu.outputs() == first[i]
            fmu.commit((60 + i) * 1e-3)
        assert first[-1].E_fr > 0.0


_ERRORS_SCRIPT = """
import math, sys
import pytest
from fmu_src.inclined import InclinedParameters
from vehicle.inclined import InclinedFMU
path = sys.argv[1]
p = InclinedParameters()
object.__setattr__(p, "theta_deg", -5.0)   # bypass the dataclass's own check
with pytest.raises(ValueError, match=r"`theta_deg` must be in [(]0, 90[]].*-5"):
    InclinedFMU(p, 1e-3, path)
with InclinedFMU(InclinedParameters(), 1e-3, path) as fmu:
    with pytest.raises(RuntimeError, match="loses contact"):
        fmu(-0.05, 0.0, 0.0)   # pulled out of the wedge: N < 0
print("checked")
"""


def test_bad_parameters_and_lost_contact_are_clear_errors(fmu_path):
    """In a subprocess: both errors are fmi2Fatal (PythonFMU without the loader), and
    a fatal instance must not share the test process's heap (pythonfmu 0.7.0)."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", _ERRORS_SCRIPT, str(fmu_path)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "checked" in out.stdout, out.stderr[-2000:]


SYSTEM = InclinedSDOF(70.0, 45935.0, 150.0, InclinedParameters(theta_deg=60.0),
                      150.0, 70.0 * 9.81)


@pytest.mark.parametrize("freq_hz", [5.0, 8.5])
def test_cosimulation_through_the_fmu_matches_the_law_and_hbm(fmu_path, freq_hz):
    xt = inclined_cosim_steady(SYSTEM, freq_hz, steps=1000, fmu_path=fmu_path)
    xl = inclined_time_reference(SYSTEM, freq_hz, steps=1000)
    assert np.abs(xt - xl).max() / np.ptp(xt) <= COSIM_VS_LAW_TOL
    r = solve_inclined_hbm(SYSTEM, freq_hz, 7)
    assert r.success, r.message
    a_co = np.hypot(*(FourierBasis(7, 1000).P @ xt)[1:3])
    a_h = np.hypot(*r.X[1:3])
    assert abs(a_co - a_h) / a_co <= HBM_VS_COSIM_TOL, (a_co, a_h)
