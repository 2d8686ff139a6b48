"""What keeps a ``drymount`` run from losing or overwriting results (issue 11).

* Output paths are checked before any computation (:func:`outputs`): a directory,
  device, FIFO, an unwritable folder, a plot extension that names no format -> a
  :class:`UsageError` (exit status 2) at once.
* SIGINT and SIGTERM raise KeyboardInterrupt in the main thread
  (:func:`signals_interrupt`), so every run stops the same way; a run that stops
  hands its computed points over on the exception (``partial_result``) and
  :func:`partial_on_stop` writes them with a first line ``# partial: <reason>``.
  Exit status 128 + the signal (:func:`interrupted`).
* A user's ``--fmu`` is used as it is, never rebuilt (:func:`fmu_path`).

docs/cli.md states the rules for users.
"""

from __future__ import annotations

import contextlib
import re
import signal
import sys
from pathlib import Path

__all__ = ["UsageError", "EXIT_INTERRUPTED", "EXIT_TERMINATED", "signals_interrupt",
           "interrupted", "partial_on_stop", "write_with", "outputs", "check_out",
           "check_out_dir", "events_sibling",
           "fmu_path", "stopped_by", "stop_reason"]

#: Interrupted by SIGINT (128 + 2); SIGTERM gives 128 + 15 = 143.
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143


class UsageError(Exception):
    """Bad command-line values found after parsing (exit status 2)."""


def _err(msg: str) -> None:
    print(f"drymount: error: {msg}", file=sys.stderr)


def _info(msg: str) -> None:
    print(msg, file=sys.stderr)


def write_with(path: Path, writer, partial: str | None = None) -> Path:
    """Call ``writer(tmp_path)`` and move the file to ``path`` atomically; with
    ``partial`` (the reason the run stopped early) the first line is
    ``# partial: <partial>``."""
    from drymount.io import PARTIAL_PREFIX, atomic_path

    with atomic_path(path) as tmp:
        writer(tmp)
        if partial is not None:
            text = tmp.read_text(encoding="utf-8")
            reason = " ".join(partial.split())
            tmp.write_text(f"{PARTIAL_PREFIX}{reason}\n{text}", encoding="utf-8")
    return path


# --------------------------------------------------------------------- signals

#: The signal that stopped the run (SIGINT or SIGTERM), set by the handler.
_stopped_by: int | None = None


def stopped_by() -> int | None:
    """The signal that stopped the current run, or None."""
    return _stopped_by


@contextlib.contextmanager
def signals_interrupt(program: bool = False):
    """SIGINT and SIGTERM raise KeyboardInterrupt in the main thread (so every run
    stops the same way and writes what it computed); the signal is remembered for the
    exit status. Restores the previous handlers afterwards; as a ``program`` (the
    process ends after main, its results are written) they are ignored instead:
    Python's finalisation would otherwise die of a late SIGINT (status -2)."""
    global _stopped_by
    _stopped_by = None

    def handler(signum, frame):
        global _stopped_by
        if _stopped_by is None:
            _stopped_by = signum
        if _cannot_raise_in(frame):
            _redeliver_soon()
            return
        raise KeyboardInterrupt(signal.Signals(signum).name)

    def late(signum, frame):
        """SIGALRM of :func:`_redeliver_soon`: the deferred interrupt."""
        if _stopped_by is not None:
            handler(_stopped_by, frame)

    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    saved_alarm = signal.signal(signal.SIGALRM, late)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, saved_alarm)
        for s, h in saved.items():
            signal.signal(s, signal.SIG_IGN if program else h)


#: Delay of a deferred interrupt (:func:`_redeliver_soon`), s.
REDELIVER_S = 0.005


def _cannot_raise_in(frame) -> bool:
    """Whether an exception raised in ``frame`` would be swallowed: the signal
    arrived inside a weak-reference callback of importlib's module locks (``cb``),
    where Python prints "Exception ignored" with a traceback and carries on."""
    code = getattr(frame, "f_code", None)
    return (code is not None and code.co_name == "cb"
            and code.co_filename.startswith("<frozen importlib"))


def _redeliver_soon() -> None:
    """Raise the interrupt a moment later, outside the callback (SIGALRM)."""
    signal.setitimer(signal.ITIMER_REAL, REDELIVER_S)


def stop_reason(exc: BaseException) -> str:
    """Why a run stopped, for a ``# partial:`` line: the signal, or the error."""
    if _stopped_by is not None:
        return f"interrupted by {signal.Signals(_stopped_by).name}"
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted"
    return f"{type(exc).__name__}: {exc}"


@contextlib.contextmanager
def partial_on_stop(out: Path, what: str):
    """On any exception carrying a ``partial_result`` (the points computed before a
    run stopped), write it to ``out`` marked partial, then re-raise."""
    try:
        yield
    except BaseException as exc:
        res = getattr(exc, "partial_result", None)
        n = len(getattr(res, "freq_hz", getattr(res, "t", ())))
        if res is not None and n:
            reason = f"{stop_reason(exc)}; {n} {what} computed before the run stopped"
            write_with(out, res.to_csv, partial=reason)
            _info(f"wrote {out} (partial: {n} {what})")
        raise


def interrupted() -> int:
    """Exit status after SIGINT (130) or SIGTERM (143)."""
    if _stopped_by == signal.SIGTERM:
        _err("terminated (SIGTERM)")
        return EXIT_TERMINATED
    _err("interrupted")
    return EXIT_INTERRUPTED



# ------------------------------------------------------------- output paths

_PLOT_FORMATS = ("png", "pdf", "svg", "svgz", "eps", "ps", "jpg", "jpeg", "tif",
                 "tiff", "webp", "pgf", "raw", "rgba")


def check_out(path, option: str) -> Path:
    """``path`` checked as an output file (hbm.io.check_output_path);
    UsageError naming ``option`` otherwise."""
    from drymount.io import OutputPathError, check_output_path

    try:
        check_output_path(path, option)
    except OutputPathError as exc:
        raise UsageError(str(exc)) from None
    return Path(path)


def check_out_dir(path, option: str) -> Path:
    """``path`` checked as an output folder (it may exist as a folder, or be
    creatable in a writable folder); UsageError naming ``option`` otherwise."""
    import os

    text = os.fspath(path) if path is not None else ""
    if not str(text).strip():
        raise UsageError(f"{option}: the folder name is empty")
    target = Path(os.path.realpath(text))
    if target.exists() and not target.is_dir():
        raise UsageError(f"{option}: {str(text)!r} exists and is not a folder")
    from drymount.io import OutputPathError, check_creatable_in

    try:
        check_creatable_in(target, option, repr(str(text)))
    except OutputPathError as exc:
        raise UsageError(str(exc)) from None
    return Path(path)


def _check_plot(path) -> Path | None:
    if path is None:
        return None
    fmt = Path(path).suffix.lstrip(".").lower()
    if fmt not in _PLOT_FORMATS:
        raise UsageError(f"--plot: {str(path)!r} has the extension {fmt!r}, which "
                         f"names no plot format; use one of "
                         f"{', '.join(_PLOT_FORMATS)}")
    return check_out(path, "--plot")


def _default_out(cfg, kind: str) -> Path:
    """``<name>_<kind>.csv`` in the working directory, whatever the configuration's
    name holds (path separators, ``..``, odd characters become ``_``)."""
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", cfg.name).strip("._") or "config"
    return Path(f"{name}_{kind}.csv")


#: first-line prefixes of the files drymount writes (results and partial results)
_OWN_PREFIXES = ("# drymount ", "# partial: ")


def _written_by_drymount(path: Path) -> bool:
    try:
        with open(path, "rb") as fh:
            head = fh.read(64).decode("utf-8", "replace")
    except OSError:
        return False
    return head.startswith(_OWN_PREFIXES)


def _check_default_out(path: Path) -> Path:
    """The default output name was not chosen by the user: replace only an earlier
    drymount result there (saying so), never a file of the user's."""
    if path.exists() and not _written_by_drymount(path):
        raise UsageError(f"--out not given: the default output {str(path)!r} exists "
                         f"and was not written by drymount (its first line does not "
                         f"start with '# drymount'); name the output with --out, or "
                         f"move the file")
    if path.exists():
        _info(f"replacing {path} (an earlier drymount result)")
    return path


def events_sibling(out: Path) -> Path:
    """``<out stem>_events.csv`` beside ``hbm``'s CSV (FrequencyResponse.events_path),
    checked before computing (:func:`sibling`)."""
    return sibling(out, "_events.csv", "folds-and-peaks file")


def sibling(out: Path, suffix: str, what: str) -> Path:
    """``<out stem><suffix>`` beside ``out``, checked before computing. The user did
    not name it: like a default output, an existing file there is replaced only when
    drymount wrote it."""
    import os

    root, _ = os.path.splitext(os.fspath(out))
    path = check_out(Path(root + suffix), "--out")
    if path.exists() and not _written_by_drymount(path):
        raise UsageError(f"--out: the {what} {str(path)!r} written "
                         f"beside "
                         f"{str(out)!r} exists and was not written by drymount (its "
                         f"first line does not start with '# drymount'); choose "
                         f"another --out, or move the file")
    return path


def outputs(args, cfg, kind: str) -> Path:
    """Check ``--out`` (or the default name) and ``--plot`` before any work."""
    if args.out is not None:
        out = check_out(args.out, "--out")
    else:
        out = _check_default_out(check_out(_default_out(cfg, kind), "--out"))
    _check_plot(args.plot)
    return out


def fmu_path(path) -> Path:
    """The FMU a run uses. A user's ``--fmu`` is used as it is (never rebuilt):
    UsageError if it is missing or not an FMU. The default FMU is built, or rebuilt
    when older than drymount's sources, saying so."""
    import zipfile

    from drymount.fmu_build import default_fmu_path, ensure_fmu

    if path is None:
        return ensure_fmu(default_fmu_path(),
                          notify=lambda why: _info(f"building the default FMU "
                                                   f"{default_fmu_path()} ({why})"))
    path = Path(path)
    if not path.exists():
        raise UsageError(f"--fmu: {str(path)!r} does not exist (leave --fmu out to "
                         f"use the default FMU, built when needed)")
    if not path.is_file() or not zipfile.is_zipfile(path):
        raise UsageError(f"--fmu: {str(path)!r} is not an FMU (not a zip file)")
    try:
        with zipfile.ZipFile(path) as z:
            has_md = "modelDescription.xml" in z.namelist()
    except (OSError, zipfile.BadZipFile) as exc:
        raise UsageError(f"--fmu: {str(path)!r} cannot be read: {exc}") from None
    if not has_md:
        raise UsageError(f"--fmu: {str(path)!r} is not an FMU (no "
                         f"modelDescription.xml in the zip)")
    _check_fmu_binary(path)
    return path.resolve()


def _check_fmu_binary(path: Path) -> None:
    """UsageError naming ``--fmu`` when the FMU has no co-simulation binary for this
    platform (e.g. its binaries were deleted): found before the run, not reported
    later against the folder it was unzipped to."""
    import zipfile

    import fmpy
    from fmpy import read_model_description

    try:
        md = read_model_description(str(path))
    except Exception as exc:  # noqa: BLE001 - any unreadable description
        raise UsageError(f"--fmu: {str(path)!r} has an invalid modelDescription.xml "
                         f"({exc})") from None
    if md.coSimulation is None:
        raise UsageError(f"--fmu: {str(path)!r} is not a co-simulation FMU")
    folder = fmpy.platform_tuple if md.fmiVersion.startswith("3") else fmpy.platform
    binary = (f"binaries/{folder}/{md.coSimulation.modelIdentifier}"
              f"{fmpy.sharedLibraryExtension}")
    with zipfile.ZipFile(path) as z:
        if binary not in z.namelist():
            raise UsageError(f"--fmu: {str(path)!r} has no binary for this platform "
                             f"({binary} is not in the zip)")


