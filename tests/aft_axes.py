"""Random :class:`hbm.elements.NonlinearAxes` for the AFT tests (one independent
axis per law, friction where ``kf`` > 0)."""

from __future__ import annotations

import numpy as np

from drymount.hbm.elements import NonlinearAxes


def random_axes(laws, kf, rng) -> NonlinearAxes:
    n = len(laws)
    k1 = rng.uniform(5e4, 1e5, n)
    return NonlinearAxes(
        labels=tuple(f"a{i}" for i in range(n)), index=tuple((0, i) for i in range(n)),
        B=np.eye(n), G=np.zeros((n, 1)), law=tuple(laws), k1=k1,
        kc=rng.uniform(1e8, 1e10, n), k2=k1 * rng.uniform(2, 6, n),
        delta=rng.uniform(2e-4, 1e-3, n), delta_neg=rng.uniform(2e-4, 1e-3, n),
        kf=np.asarray(kf, float), fs=rng.uniform(5, 50, n) * (np.asarray(kf) > 0))
