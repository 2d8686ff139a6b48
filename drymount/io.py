"""The app's file writing: the atomic writers and CSV of :mod:`hbm.io`, re-used.

They live in ``hbm`` (the lowest layer that writes files), so that ``hbm`` and
``vehicle`` results write atomically without importing the app. Output paths are
checked (:func:`check_output_path`) and partial results marked (``# partial:``) as
:mod:`hbm.io` describes.

Here every writer names its file when the writing fails: an ``OSError`` while writing
(a full disk, ``ENOSPC``; a file-size limit; an I/O error) becomes an
:class:`OutputError` reading ``cannot write results/x.csv: No space left on device``
(the CLI's exit status 1). The file it would have replaced is left as it was.
"""

import contextlib
import functools

from drymount.hbm import io as _io
from drymount.hbm.io import *  # noqa: F403 - the same API

__all__ = list(_io.__all__) + ["shown_path", "OutputError", "writing"]


def shown_path(path) -> str:
    """``path`` as a message prints it: relative to the current folder when it lies
    inside it (``dist/FrictionMount.fmu``), else absolute."""
    from pathlib import Path

    p = Path(path).absolute()
    try:
        return str(p.relative_to(Path.cwd()))
    except ValueError:
        return str(p)


class OutputError(OSError):
    """Writing ``path`` failed; ``str()`` names the file and the reason."""

    def __init__(self, path, exc: OSError):
        super().__init__(exc.errno, exc.strerror or str(exc))
        self.filename = str(path)

    def __str__(self) -> str:
        return f"cannot write {shown_path(self.filename)}: {self.strerror}"


@contextlib.contextmanager
def writing(path):
    """An ``OSError`` raised inside the block becomes an :class:`OutputError`
    naming ``path``."""
    try:
        yield
    except OutputError:
        raise
    except OSError as exc:
        raise OutputError(path, exc) from exc


def _named(writer, arg: int = 0):
    """``writer`` whose ``OSError`` names the file (its argument ``arg``)."""
    @functools.wraps(writer)
    def wrapped(*args, **kwargs):
        with writing(args[arg] if len(args) > arg else kwargs.get("path")):
            return writer(*args, **kwargs)
    return wrapped


@contextlib.contextmanager
def atomic_path(path, suffix=None):  # noqa: F811 - hbm.io's, naming its file
    with writing(path), _io.atomic_path(path, suffix) as tmp:
        yield tmp


atomic_path.__doc__ = _io.atomic_path.__doc__
atomic_write_bytes = _named(_io.atomic_write_bytes)  # noqa: F811
atomic_write_text = _named(_io.atomic_write_text)  # noqa: F811
write_csv = _named(_io.write_csv)  # noqa: F811
mark_partial = _named(_io.mark_partial)  # noqa: F811
save_figure = _named(_io.save_figure, arg=1)  # noqa: F811
