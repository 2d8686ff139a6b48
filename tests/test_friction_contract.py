"""The friction-element contract (fmu_src.friction) and its registry: every
registered element keeps the contract, and the consumers' tables follow from the
declarations."""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np
import pytest

from drymount.fmu_src import interface
from drymount.fmu_src.friction import (FRICTION_ELEMENTS, ElementStep,
                                       element_fields)
from drymount.fmu_src.mount_law import (AxisParameters, axis_force, conform_state,
                                        initial_sliders, slider_position)

#: One axis per element (and variant) with friction on.
AXES_BY_KIND = {
    "jenkins": AxisParameters(friction=True, n0=20.0),
    "jenkins non-symmetric": AxisParameters(friction=True, n0=20.0, fs_ratio=0.6),
    "jenkins micro-slip": AxisParameters(friction=True, n0=20.0, sliders=5,
                                         spread=0.5, fs_ratio=0.8),
    "inclined": AxisParameters(friction=True, friction_kind="inclined"),
    "dahl": AxisParameters(friction=True, friction_kind="dahl", n0=20.0),
    "lugre": AxisParameters(friction=True, friction_kind="lugre", n0=20.0,
                            sigma1=300.0, sigma2=5.0, stribeck_ratio=1.5,
                            v_stribeck=0.05),
    "berg": AxisParameters(friction=True, friction_kind="berg", n0=20.0),
}


def test_every_registered_element_has_an_axis_here():
    assert {p.friction_kind for p in AXES_BY_KIND.values()} == set(FRICTION_ELEMENTS)


def test_axis_fields_are_the_registered_fields():
    names = [f.name for f in fields(AxisParameters)]
    assert names[:8] == ["law", "k1", "kc", "k2", "delta", "delta_neg", "c",
                         "friction"]
    maxwell = {name for name, *_ in interface.MAXWELL_PARAMETER_FIELDS}
    # the hydraulic fluid path's axis fields are FMU parameters too
    from drymount.fmu_src.mount_law import HYDRAULIC_AXIS_FIELDS
    hyd = set(HYDRAULIC_AXIS_FIELDS)
    assert {name for name, *_ in interface.HYDRAULIC_PARAMETER_FIELDS} == hyd
    assert set(names[8:]) == ({"friction_kind"} | {f.name for f in element_fields()}
                              | maxwell | hyd)
    rows = {name for name, *_ in interface.ALL_PARAMETER_FIELDS}
    assert rows == set(names)
    for f in element_fields():   # the FMU's row carries the declared unit and text
        var = interface.variable(f"axial_{f.name}")
        assert (var.type, var.unit) == (f.type, f.unit)
        assert f.description in var.description


@pytest.mark.parametrize("kind", list(AXES_BY_KIND))
def test_step_keeps_the_contract(kind):
    """start/position round trip, state size, a random walk: the step's force and
    tangent against axis_force, finite-difference dF/du on stuck steps, energy >= 0,
    a flat copy of every state restores it (the FMU's saved state)."""
    p = AXES_BY_KIND[kind]
    el = p.element
    w = el.start(p, 1e-4)
    assert slider_position(p, w) == 1e-4
    flat = (w,) if isinstance(w, float) else tuple(w)
    assert len(flat) == el.state_size(p)
    rng = np.random.default_rng(7)
    u = np.cumsum(rng.normal(0.0, 2e-4, 300)) - 2e-3
    state = initial_sliders(p, float(u[0]))
    compared = 0
    for x in u[1:].tolist():
        r = p.friction_step(state, x, 0.0, p.n0, 1e-3)
        assert isinstance(r, ElementStep) and r.dissipated >= 0.0
        assert math.isfinite(r.force) and math.isfinite(r.df_du)
        ref = axis_force(x, 0.0, state, p, None, 1e-3)
        assert ref.friction_force == r.force and ref.dissipated == r.dissipated
        # dF/du by central differences where the step does not change regime
        h = 1e-9
        hi = p.friction_step(state, x + h, 0.0, p.n0, 1e-3)
        lo = p.friction_step(state, x - h, 0.0, p.n0, 1e-3)
        if hi.slipping == lo.slipping == r.slipping and (
                not r.slipping or p.fast_form is None):
            compared += 1
            assert (hi.force - lo.force) / (2 * h) == pytest.approx(r.df_du, rel=1e-5)
        state = r.state
        flat = [state] if isinstance(state, float) else list(state)
        assert conform_state(p, flat) == state
    assert compared > 0


def test_lost_contact_and_normal_input():
    """Elements that read n: n < 0 means Fs = 0; the others ignore n."""
    for p in AXES_BY_KIND.values():
        w = initial_sliders(p)
        r_neg = axis_force(0.002, 0.0, w, p, -5.0)
        r_n0 = axis_force(0.002, 0.0, w, p)
        if p.element.uses_normal_input:
            assert r_neg.friction_force == 0.0 and r_n0.friction_force != 0.0
        else:
            assert r_neg == r_n0


#: Generic march vs fast forms: the same return maps, so the forces agree to
#: round-off (measured ~1e-16 of the peak); the central-difference Jacobian against
#: the fast forms' analytic one: a slip event inside a difference step leaves
#: O(step) errors (measured < 1e-5 of the largest entry).
RTOL_GENERIC_F = 1e-12
RTOL_GENERIC_JAC = 1e-4


@pytest.mark.parametrize("kind", [k for k, p in AXES_BY_KIND.items() if p.fast_form])
def test_generic_march_equals_the_fast_forms(kind):
    """Every registered element through hbm.generic_march (its own step over the
    sampled period) against the HBM's fast form of it, H = 5, N = 128, a static
    offset plus three harmonics."""
    from dataclasses import replace as dc_replace

    from drymount.hbm.aft import FourierBasis, aft_forces
    from drymount.hbm.characterise import axis_as_nonlinear

    p = AXES_BY_KIND[kind]
    basis = FourierBasis(5, 128)
    U = np.zeros((11, 1))
    U[0, 0], U[2, 0], U[3, 0], U[6, 0] = -4e-4, 1.5e-3, 3e-4, -2e-4
    fast = axis_as_nonlinear(p)
    assert not fast.generic
    generic = dc_replace(fast, kf=np.zeros(1), fs=np.zeros(1), banks=((),),
                         inclined=(), generic=((0, p),))
    F1, J1 = aft_forces(U, fast, basis)
    F2, J2 = aft_forces(U, generic, basis)
    scale = float(np.max(np.abs(F1)))
    assert float(np.max(np.abs(F2 - F1))) <= RTOL_GENERIC_F * scale
    jscale = float(np.max(np.abs(J1)))
    assert float(np.max(np.abs(J2 - J1))) <= RTOL_GENERIC_JAC * jscale


@pytest.mark.parametrize("kind", list(AXES_BY_KIND))
def test_axis_pickles_and_copies_by_its_fields(kind):
    """Process pools pickle the system: an axis travels as its fields and comes back
    with its element's step bound again (a closure is not picklable)."""
    import copy
    import pickle

    p = AXES_BY_KIND[kind]
    for q in (pickle.loads(pickle.dumps(p)), copy.deepcopy(p), copy.copy(p)):
        assert q == p and q.friction_step is not None
        w = initial_sliders(q, 1e-4)
        assert axis_force(2e-3, 0.1, w, q) == axis_force(2e-3, 0.1, w, p)
