"""The app's file writing: the atomic writers and CSV of :mod:`hbm.io`, re-used.

They live in ``hbm`` (the lowest layer that writes files), so that ``hbm`` and
``vehicle`` results write atomically without importing the app.
"""

from hbm.io import (
    atomic_path,
    atomic_write_bytes,
    atomic_write_text,
    format_value,
    save_figure,
    write_csv,
)

__all__ = [
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "write_csv",
    "save_figure",
    "format_value",
]
