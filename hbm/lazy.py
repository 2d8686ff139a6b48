"""Package faces whose names are imported on first use (PEP 562).

``drymount.hbm``, ``drymount.vehicle`` and ``drymount.config`` bind their public names
lazily, so that importing a package (the command line's parser, ``drymount --help``)
loads none of NumPy, SciPy or the solvers (issue 27)::

    __getattr__, __dir__ = lazy_face(__name__, {"Name": "submodule", ...}, __all__)
"""

from __future__ import annotations

import importlib
import sys

__all__ = ["lazy_face"]


def lazy_face(package: str, where: dict[str, str], public):
    """The module ``__getattr__`` and ``__dir__`` of ``package``: a name of ``where``
    is read from ``package.<where[name]>`` when first asked for."""

    def __getattr__(name):
        if name in where:
            return getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(public))

    return __getattr__, __dir__
