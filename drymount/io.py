"""The app's file writing: the atomic writers and CSV of :mod:`hbm.io`, re-used.

They live in ``hbm`` (the lowest layer that writes files), so that ``hbm`` and
``vehicle`` results write atomically without importing the app. Output paths are
checked (:func:`check_output_path`) and partial results marked (``# partial:``) as
:mod:`hbm.io` describes.
"""

from drymount.hbm import io as _io
from drymount.hbm.io import *  # noqa: F403 - the same API

__all__ = list(_io.__all__) + ["shown_path"]


def shown_path(path) -> str:
    """``path`` as a message prints it: relative to the current folder when it lies
    inside it (``dist/FrictionMount.fmu``), else absolute."""
    from pathlib import Path

    p = Path(path).absolute()
    try:
        return str(p.relative_to(Path.cwd()))
    except ValueError:
        return str(p)
