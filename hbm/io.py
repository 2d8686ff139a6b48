"""Output files that never end up half-written: atomic writes and CSV with units.

Every file drymount writes goes through this module (standard library only; it sits in
the lowest layer that writes files, ``hbm``, and ``vehicle`` and the app's
:mod:`drymount.io` re-use it). A file is first written to a
temporary file in the same folder and then renamed over the target with
:func:`os.replace`, which is atomic on POSIX and Windows: an interrupted run leaves
either the old file or the new one, never a truncated one.

CSV files open in a spreadsheet: one comment line starting with ``# `` (units and
provenance), then a header row, then the data, comma separated, ``.`` as decimal point.

Output paths (:func:`check_output_path`, used by the CLI before any computation):

* a regular file is replaced atomically; a new file gets the mode a plain ``open()``
  would give under the current umask (``0o666 & ~umask``), an existing one keeps its
  mode (the temporary file of :func:`tempfile.mkstemp` is ``0o600``: it is changed
  before the rename);
* a symbolic link is followed: its target is replaced, the link stays;
* a directory, device, FIFO or socket is refused (:class:`OutputPathError`): an
  atomic rename would replace it by a regular file, and writing through it would give
  up atomicity. Write to a file and copy it if you need to;
* a missing parent folder is created; a parent that cannot be created (a path under a
  file) or written to is refused.

A run that stops early (interrupt, numerical failure) writes what it computed with a
first line ``# partial: <reason>`` (:func:`mark_partial`), in the same format
otherwise.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import stat
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path

__all__ = [
    "OutputPathError",
    "check_output_path",
    "check_creatable_in",
    "mark_partial",
    "PARTIAL_PREFIX",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "write_csv",
    "save_figure",
    "format_value",
]


#: First line of a file written by a run that stopped early.
PARTIAL_PREFIX = "# partial: "


class OutputPathError(ValueError):
    """An output path that cannot be written (see :func:`check_output_path`)."""


def _umask() -> int:
    """The process umask (read from /proc where possible, which changes nothing)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _target(path) -> Path:
    """``path`` with symbolic links followed (the file a write must replace)."""
    return Path(os.path.realpath(os.fspath(path)))


def check_output_path(path, what: str = "output") -> Path:
    """Check that ``path`` can be written as an output file; return the real target.

    Creates nothing. Raises :class:`OutputPathError` (naming ``what``, the path and
    the reason) for an empty path, an existing directory, device, FIFO or socket, a
    parent that is a file or not writable.

    Parameters
    ----------
    path : str or Path
    what : str
        How the message names the path, e.g. ``"--out"``.
    """
    text = os.fspath(path) if path is not None else ""
    if not str(text).strip():
        raise OutputPathError(f"{what}: the file name is empty")
    target = _target(text)
    shown = repr(str(text)) if str(target) == os.path.abspath(text) else \
        f"{str(text)!r} (a link to {str(target)!r})"
    if os.path.lexists(target):
        mode = os.stat(target).st_mode
        if stat.S_ISDIR(mode):
            raise OutputPathError(f"{what}: {shown} is a directory; give a file name")
        if not stat.S_ISREG(mode):
            kind = ("a FIFO" if stat.S_ISFIFO(mode) else "a socket" if
                    stat.S_ISSOCK(mode) else "a device")
            raise OutputPathError(f"{what}: {shown} is {kind}, not a regular file; "
                                  f"drymount writes results to regular files only")
    check_creatable_in(target.parent, what, shown)
    return target


def check_creatable_in(folder: Path, what: str, shown: str) -> None:
    """OutputPathError unless the nearest existing ancestor of ``folder`` (itself
    included) is a writable directory, so that ``shown`` can be created below it."""
    parent = Path(folder)
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise OutputPathError(f"{what}: cannot create {shown}: {str(parent)!r} is "
                              f"not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputPathError(f"{what}: cannot write {shown}: the folder "
                              f"{str(parent)!r} is not writable")


def mark_partial(path, reason: str) -> Path:
    """Rewrite the text file ``path`` (atomically) with a first line
    ``# partial: <reason>``: the run that wrote it stopped early."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    reason = " ".join(str(reason).split()) or "stopped early"
    return atomic_write_text(path, f"{PARTIAL_PREFIX}{reason}\n{text}")


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None) -> Iterator[Path]:
    """Context manager giving a temporary path that replaces ``path`` on success.

    For writers that insist on a file name (``Figure.savefig``, NumPy, an FMU builder).
    The temporary file lives in the folder of ``path`` (created if needed) so that the
    final :func:`os.replace` is a rename on one file system. On an exception the
    temporary file is removed and ``path`` is left untouched. A symbolic link is
    followed (its target is replaced); a directory, device or FIFO at ``path`` raises
    :class:`OutputPathError` before anything is written. The file gets the mode of
    the file it replaces, else ``0o666 & ~umask``.

    Parameters
    ----------
    path : str or Path
        Final file name.
    suffix : str, optional
        Suffix of the temporary file (default: that of ``path``, so that writers which
        pick a format from the extension still do).

    Examples
    --------
    >>> with atomic_path("plot.png") as tmp:          # doctest: +SKIP
    ...     fig.savefig(tmp)
    """
    path = check_output_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.",
                               suffix=path.suffix if suffix is None else suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        try:
            mode = stat.S_IMODE(os.stat(path).st_mode)
        except FileNotFoundError:
            mode = 0o666 & ~_umask()
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns ``path`` as a :class:`Path`."""
    path = Path(path)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return path


def atomic_write_text(path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (UTF-8, ``\\n`` line ends)."""
    return atomic_write_bytes(path, text.encode(encoding))


def format_value(v) -> str:
    """A CSV cell: booleans as 0/1, floats to 10 significant digits, NaN as ``nan``."""
    if isinstance(v, bool) or type(v).__name__ == "bool_":
        return str(int(v))
    if isinstance(v, float) or type(v).__name__.startswith("float"):
        x = float(v)
        if math.isnan(x):
            return "nan"
        return f"{x:.10g}"
    return str(v)


def write_csv(path, header: Sequence[str], rows: Iterable[Sequence],
              comment: str | None = None) -> Path:
    """Write a CSV file atomically.

    Parameters
    ----------
    path : str or Path
        Target file.
    header : sequence of str
        Column names, e.g. ``["freq_hz", "x_amp", "transmissibility"]``.
    rows : iterable of sequences
        One sequence per row, ``len(header)`` values each (numbers, booleans, strings;
        NumPy scalars are fine).
    comment : str, optional
        Text of the first line, written after ``# ``: the units of the columns and
        where the numbers come from, e.g.
        ``"freq_hz [Hz], x_amp [m]; HBM H=7, preset sdof_original"``. Newlines in it
        start further ``# `` lines.

    Returns
    -------
    Path
    """
    buf = io.StringIO()
    if comment:
        for line in str(comment).splitlines() or [""]:
            buf.write(f"# {line}\n")
    w = csv.writer(buf, lineterminator="\n")
    header = list(header)
    w.writerow(header)
    for i, row in enumerate(rows):
        row = list(row)
        if len(row) != len(header):
            raise ValueError(f"CSV row {i} has {len(row)} values, the header has "
                             f"{len(header)} columns")
        w.writerow([format_value(v) for v in row])
    return atomic_write_text(path, buf.getvalue())


def save_figure(fig, path, dpi: int = 120) -> Path:
    """Save a Matplotlib figure atomically (format from the extension of ``path``)."""
    path = Path(path)
    fmt = path.suffix.lstrip(".") or "png"
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi)
    return atomic_write_bytes(path, buf.getvalue())
