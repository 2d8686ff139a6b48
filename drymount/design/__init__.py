"""Design-space exploration and optimisation of a configuration (``[design]``).

- :func:`design_space` - the checked ``[design]`` section (:mod:`.space`,
  :mod:`.check`);
- :func:`explore` - a grid / Latin hypercube / Sobol sample, one HBM curve per design,
  a streamed CSV table, a Pareto plot and a summary (:mod:`.exploration`: not
  ``explore``, whose import would bind the package's ``explore`` to the module);
- :func:`optimize` - differential evolution with a local polish (:mod:`.optimize`);
- :func:`parse_backend` - serial, local processes or Dask (:mod:`.backends`).

This package belongs to the app: it reads configurations; nothing in ``hbm``,
``vehicle`` or ``fmu_src`` imports it.
"""

import importlib

#: Public name -> the submodule defining it. Imported on first use (PEP 562):
#: every ``drymount`` command registers ``explore``/``optimize`` through
#: :mod:`drymount.design.commands`, and :mod:`.exploration` imports scipy.stats (seconds
#: on a loaded machine), which a usage error must not wait for (issue 11: exit 2
#: within a second).
_WHERE = {
    "BackendSpec": "backends", "parse_backend": "backends",
    "design_space": "check",
    "DesignResult": "evaluate", "DesignStatus": "evaluate",
    "evaluate_design": "evaluate",
    "ExploreResult": "exploration", "explore": "exploration",
    "DesignSpace": "space",
}

__all__ = ["design_space", "explore", "evaluate_design", "parse_backend",
           "BackendSpec", "DesignSpace", "DesignResult", "DesignStatus",
           "ExploreResult"]


def __getattr__(name: str):
    if name in _WHERE:
        value = getattr(importlib.import_module(f"drymount.design.{_WHERE[name]}"),
                        name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'drymount.design' has no attribute {name!r}")
