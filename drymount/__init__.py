"""drymount: friction-damped engine mounts, scriptable.

The public API (documented in :mod:`drymount.api`, units SI)::

    import drymount

    model = drymount.load("sdof_halved")                # preset name or TOML file
    model = model.replace("mount.friction.n0", 40.0)    # N
    curve = drymount.hbm(model, 1.0, 30.0)              # Hz
    print(curve.peak())                                 # peak transmissibility

- :func:`load` -> :class:`Model` (``replace``, ``with_``);
- :func:`hbm`, :func:`sweep` -> :class:`Curve` (``freq_hz``, ``transmissibility``,
  ``peak(dof)``, ``to_csv``, ``plot``);
- :func:`cosim` -> :class:`CosimResult` (measured road/engine inputs, ``spectra``,
  ``to_csv``, ``plot``); :class:`Peak`;
- :func:`modes` -> nonlinear modes (EPMC): frequency and damping against amplitude.

The names are imported on first use: ``import drymount`` loads neither NumPy nor SciPy.
The command line loads the solvers only when it computes: ``--help``, ``--version``,
``presets list`` and the usage errors load no NumPy, SciPy, Matplotlib or numba
(``tests/test_startup.py``); a configuration's checks load NumPy, not the solvers
(0.05-0.14 s CPU in all, ``bench/bench_startup.py``).
"""

import types as _types

__all__ = ["Model", "Peak", "Curve", "CosimResult", "load", "hbm", "sweep", "cosim",
           "modes"]


class _HarmonicBalance(_types.ModuleType):
    """``drymount.hbm`` is two things: the harmonic-balance package (the folder
    ``hbm/``, installed as ``drymount.hbm``) and, called, the API function
    :func:`drymount.api.hbm`. Importing the package binds its name on ``drymount``,
    so the package's module is made callable rather than the function shadowed."""

    def __call__(self, *args, **kwargs):
        from drymount.api import hbm as frequency_response

        return frequency_response(*args, **kwargs)


def _source_tree_layers() -> None:
    """In a source checkout that is not installed, find ``drymount.hbm`` (and the
    other lower layers) in the folders beside ``drymount/``, as the build backend's
    package-dir mapping does once installed. Appended last: an installed copy wins."""
    import importlib.util
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    layers = {f"drymount.{name}": root / name
              for name in ("fmu_src", "fmu_build", "hbm", "vehicle")}
    if not all((folder / "__init__.py").is_file() for folder in layers.values()):
        return  # an installed wheel: the layers are inside drymount/

    class _Layers:
        @staticmethod
        def find_spec(fullname, path=None, target=None):
            folder = layers.get(fullname)
            if folder is None:
                return None
            return importlib.util.spec_from_file_location(
                fullname, folder / "__init__.py",
                submodule_search_locations=[str(folder)])

    sys.meta_path.append(_Layers)


def _callable_hbm_package():
    import importlib

    package = importlib.import_module("drymount.hbm")  # its face imports lazily
    package.__class__ = _HarmonicBalance
    return package


_source_tree_layers()
hbm = _callable_hbm_package()


def __getattr__(name):
    if name in __all__:
        from drymount import api

        return getattr(api, name)
    raise AttributeError(f"module 'drymount' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
