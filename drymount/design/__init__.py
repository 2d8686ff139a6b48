"""Design-space exploration and optimisation of a configuration (``[design]``).

- :func:`design_space` - the checked ``[design]`` section (:mod:`.space`,
  :mod:`.check`);
- :func:`explore` - a grid / Latin hypercube / Sobol sample, one HBM curve per design,
  a streamed CSV table, a Pareto plot and a summary (:mod:`.explore`);
- :func:`optimize` - differential evolution with a local polish (:mod:`.optimize`);
- :func:`parse_backend` - serial, local processes or Dask (:mod:`.backends`).

This package belongs to the app: it reads configurations; nothing in ``hbm``,
``vehicle`` or ``fmu_src`` imports it.
"""

from drymount.design.backends import BackendSpec, parse_backend
from drymount.design.check import design_space
from drymount.design.evaluate import DesignResult, DesignStatus, evaluate_design
from drymount.design.explore import ExploreResult, explore
from drymount.design.space import DesignSpace

__all__ = ["design_space", "explore", "evaluate_design", "parse_backend",
           "BackendSpec", "DesignSpace", "DesignResult", "DesignStatus",
           "ExploreResult"]
