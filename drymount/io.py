"""The app's file writing: the atomic writers and CSV of :mod:`hbm.io`, re-used.

They live in ``hbm`` (the lowest layer that writes files), so that ``hbm`` and
``vehicle`` results write atomically without importing the app. Output paths are
checked (:func:`check_output_path`) and partial results marked (``# partial:``) as
:mod:`hbm.io` describes.
"""

from hbm.io import (
    PARTIAL_PREFIX,
    OutputPathError,
    atomic_path,
    atomic_write_bytes,
    atomic_write_text,
    check_output_path,
    format_value,
    mark_partial,
    save_figure,
    write_csv,
)

__all__ = [
    "OutputPathError",
    "check_output_path",
    "mark_partial",
    "PARTIAL_PREFIX",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "write_csv",
    "save_figure",
    "format_value",
]
