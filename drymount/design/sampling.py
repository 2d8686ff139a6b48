"""Samples of a design space: full grid, Latin hypercube or Sobol (scipy.stats.qmc).

The sample depends only on the space (method, size, seed, variables): design ``i`` has
the same values on every backend and in a resumed run.
"""

from __future__ import annotations

import inspect
import itertools

import numpy as np
from scipy.stats import qmc

from drymount.design.space import DesignSpace, Method

__all__ = ["sample"]


def _seed(seed: int) -> dict:
    """The seed keyword of this scipy (``rng`` since 1.15, ``seed`` before)."""
    if "rng" in inspect.signature(qmc.LatinHypercube).parameters:
        return {"rng": np.random.default_rng(seed)}
    return {"seed": np.random.default_rng(seed)}


def sample(space: DesignSpace) -> np.ndarray:
    """The designs of ``space``: array (n_designs, n_variables) of variable values.

    ``grid``: every combination of each variable's grid (``points`` values between the
    bounds, or its list), the first variable varying slowest. ``lhs``: scrambled
    Latin hypercube (``scipy.stats.qmc.LatinHypercube``). ``sobol``: scrambled Sobol
    sequence (``qmc.Sobol``, ``random_base2``). Both with ``seed``; a list variable
    takes item ``floor(u n)`` of its list for the unit coordinate u.
    """
    if space.method is Method.GRID:
        grids = [v.grid() for v in space.variables]
        return np.array(list(itertools.product(*grids)), dtype=float).reshape(
            -1, len(grids))
    d = len(space.variables)
    if space.method is Method.LHS:
        u = qmc.LatinHypercube(d=d, **_seed(space.seed)).random(space.samples)
    else:
        m = int(round(np.log2(space.samples)))
        u = qmc.Sobol(d=d, **_seed(space.seed)).random_base2(m)
    return np.array([[v.from_unit(ui) for v, ui in zip(space.variables, row,
                                                       strict=True)]
                     for row in u], dtype=float)
