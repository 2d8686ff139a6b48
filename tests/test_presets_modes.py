"""The 6-DOF presets put each natural frequency of thesis Table 4.2 on its axis.

A mode is labelled by the DOF that holds the largest share of its kinetic energy
(``M_jj phi_j^2 / sum_k M_kk phi_k^2``; the mass matrix is diagonal in the principal
axes at the centre of mass). Reference: Table 4.2 (x 6.10, y 5.82, z 7.07, alpha
12.03, beta 11.59, gamma 14.05 Hz) for k = 91 870 N/m in every direction, lambda = 1
(six_dof_original); the halved mounts scale every frequency by 1/sqrt(2) exactly.
PHYSICS.md section 3 (issue 13: the earlier inertias put 14.05 Hz on beta).
"""

import numpy as np
import pytest

from drymount.config import load_preset
from drymount.hbm.linear import natural_frequencies

#: Table 4.2, Hz, by axis.
TABLE_4_2 = {"x": 6.10, "y": 5.82, "z": 7.07, "alpha": 12.03, "beta": 11.59,
             "gamma": 14.05}
#: Issue 13: every mode on its axis within 1 %; measured 0.67 % (x: 6.141 Hz).
RTOL_LABELLED = 0.01
#: A mode must be clearly dominated: measured smallest share 0.68 (the y mode).
MIN_SHARE = 0.6
ENGINE = (140.6, (7.90, 13.00, 8.64))
SIX_DOF = ("six_dof_original", "six_dof_halved", "six_dof_lambda12", "six_dof_4mount")


def _labelled_modes(system) -> dict[str, tuple[float, float]]:
    """Axis name -> (frequency in Hz, kinetic-energy share) of its dominant mode."""
    f, V = natural_frequencies(system)
    M = np.diag(system.M)
    assert np.allclose(system.M, np.diag(M))
    share = M[:, None] * V**2
    share /= share.sum(axis=0)
    out = {}
    for i in range(len(f)):
        j = int(np.argmax(share[:, i]))
        name = system.dof_names[j]
        assert name not in out, f"two modes dominated by {name}"
        out[name] = (float(f[i]), float(share[j, i]))
    return out


@pytest.mark.parametrize("preset, scale", [("six_dof_original", 1.0),
                                           ("six_dof_halved", 2 ** -0.5)])
def test_each_mode_on_its_table_4_2_axis(preset, scale):
    modes = _labelled_modes(load_preset(preset).system)
    for axis, ref in TABLE_4_2.items():
        f, share = modes[axis]
        assert abs(f - scale * ref) / (scale * ref) < RTOL_LABELLED, (axis, f, ref)
        assert share > MIN_SHARE, (axis, share)


@pytest.mark.parametrize("preset", SIX_DOF)
def test_every_six_dof_preset_uses_the_label_preserving_engine(preset):
    system = load_preset(preset).system
    M = np.diag(system.M)
    np.testing.assert_allclose(M[:3], ENGINE[0], rtol=1e-12)
    np.testing.assert_allclose(M[3:], ENGINE[1], rtol=1e-12)
    # every preset's modes are still one per axis
    assert len(_labelled_modes(system)) == 6
