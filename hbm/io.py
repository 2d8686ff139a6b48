"""Output files that never end up half-written: atomic writes and CSV with units.

Every file drymount writes goes through this module (standard library only; it sits in
the lowest layer that writes files, ``hbm``, and ``vehicle`` and the app's
:mod:`drymount.io` re-use it). A file is first written to a
temporary file in the same folder and then renamed over the target with
:func:`os.replace`, which is atomic on POSIX and Windows: an interrupted run leaves
either the old file or the new one, never a truncated one.

CSV files open in a spreadsheet: one comment line starting with ``# `` (units and
provenance), then a header row, then the data, comma separated, ``.`` as decimal point.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path

__all__ = [
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "write_csv",
    "save_figure",
    "format_value",
]


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None) -> Iterator[Path]:
    """Context manager giving a temporary path that replaces ``path`` on success.

    For writers that insist on a file name (``Figure.savefig``, NumPy, an FMU builder).
    The temporary file lives in the folder of ``path`` (created if needed) so that the
    final :func:`os.replace` is a rename on one file system. On an exception the
    temporary file is removed and ``path`` is left untouched.

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
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.",
                               suffix=path.suffix if suffix is None else suffix)
    os.close(fd)
    try:
        yield Path(tmp)
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
