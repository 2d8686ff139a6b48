"""The ``drymount`` command line.

Commands (``drymount COMMAND --help`` shows each one's options and an example)::

    presets   list | show NAME | export NAME PATH
    build-fmu build the FrictionMount FMU
    export-ssp SSP 1.0 archive of a configuration's mount FMU instances
    export-xc  FMI cross-check folder of a mount FMU
    hbm       harmonic-balance frequency response of a configuration
    cosim     time history co-simulated through the mount FMU (or in-process)
    sweep     stepped-sine sweep of co-simulated steady states
    validate  co-simulation against harmonic balance, with a report
    study     the thesis's design studies
    demo      the first-hour demo: FMU, HBM and co-simulation of a quarter car
    fit       mount-law parameters from rig data (elastic law, friction, damping)
    characterise  dynamic stiffness and loss angle of the mounts (datasheet maps)
    static    static working point under the engine's weight (knee warnings)
    explore   sample a configuration's [design] space (grid, LHS, Sobol)
    optimize  differential evolution on a configuration's [design] space
    modes     nonlinear modes (EPMC): frequency and damping against amplitude

A CONFIG argument is a TOML file (``docs/config.md``) or a preset name
(``drymount presets list``).

Exit status (docs/cli.md): 0 success; 1 a numerical failure (what was computed is
written, marked ``# partial: <reason>`` when the run stopped early); 2 bad usage or an
invalid configuration, found before any computation (every problem is listed, no
traceback); 130 interrupted by SIGINT (Ctrl-C), 143 terminated by SIGTERM (what was
computed is written, marked partial). :mod:`drymount.cli_guard` holds these rules.

Environment: ``DRYMOUNT_THREADS`` = BLAS/OpenMP threads (default 1; ``default`` keeps
the libraries' own; see :mod:`drymount.threads`), ``DRYMOUNT_TRACEBACK`` = show
tracebacks, ``DRYMOUNT_MARCH`` = Jenkins march backend of the HBM
(:mod:`hbm.friction_march`).
"""

from __future__ import annotations

import contextlib
import importlib
import os
import signal
import sys
import warnings
from pathlib import Path

from drymount.cli_guard import (
    EXIT_INTERRUPTED,
    EXIT_TERMINATED,
    UsageError,
    events_sibling,
    fmu_path,
    sibling,
    interrupted,
    outputs,
    partial_on_stop,
    signals_interrupt,
    stopped_by,
    write_with,
)
from drymount.cli_guard import check_out as _check_out
from drymount.cli_guard import check_out_dir as _check_out_dir
from drymount.cli_parser import build_parser
from drymount.cosim_report import CurveCSV as _CurveCSV
from drymount.cosim_report import missed_peak as _missed_peak
from drymount.cosim_report import plot_time_history as _plot_time_history
from drymount.hbm_report import (
    _peak_text,
    _plot_hbm,
    _print_bifurcations,
    _print_hbm_accuracy,
    _print_hbm_summary,
    _write_backbone,
)


def _stop_before_main(signum, frame):  # nothing computed or written yet
    os._exit(128 + signum)


if __name__ == "__main__" or Path(sys.argv[0]).stem == "drymount":
    # run as a program: a signal while the modules load ends the process with the
    # documented status (130/143) instead of a traceback; main() installs the
    # handlers that write what a run computed
    for _sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(_sig, _stop_before_main)

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_FAILURE", "EXIT_USAGE",
           "EXIT_INTERRUPTED", "EXIT_TERMINATED", "UsageError"]

EXIT_OK = 0
#: A numerical failure: an HBM continuation that stopped, a sweep point that did not
#: reach a steady state, an FMU error during a run.
EXIT_FAILURE = 1
#: Bad usage or an invalid configuration (argparse's own code for usage errors).
EXIT_USAGE = 2


# ======================================================================================
# Helpers
# ======================================================================================


def _err(msg: str) -> None:
    print(f"drymount: error: {msg}", file=sys.stderr)


def _info(msg: str) -> None:
    print(msg, file=sys.stderr)


def _load(spec, overrides=()):
    from drymount.paths import load_with_overrides

    cfg = load_with_overrides(spec, overrides or ())
    if "design" in cfg.data:  # part of the file: every command checks it
        from drymount.design import design_space

        design_space(cfg)
    return cfg


_write_with = write_with
_fmu_path = fmu_path


def _band(args, cfg) -> tuple[float, float]:
    fmin = args.fmin if args.fmin is not None else cfg.sweep.fmin_hz
    fmax = args.fmax if args.fmax is not None else cfg.sweep.fmax_hz
    if not fmax > fmin:
        raise UsageError(f"the frequency range must satisfy fmin < fmax, got fmin = "
                         f"{fmin:g} Hz, fmax = {fmax:g} Hz (from --fmin/--fmax or "
                         f"[sweep] of {cfg.source})")
    return fmin, fmax


# ======================================================================================
# Commands
# ======================================================================================


def cmd_presets(args) -> int:
    from drymount.config import list_presets, preset_text

    if args.action == "list":
        names = list_presets()
        width = max(len(n) for n in names)
        for n in names:
            print(f"{n:<{width}}  {_description(n)}")
        return EXIT_OK
    text = preset_text(args.name)
    if args.action == "show":
        sys.stdout.write(text)
        return EXIT_OK
    if args.path.exists() and not args.force:
        raise UsageError(f"{args.path} exists; use --force to overwrite it")
    _check_out(args.path, "PATH")
    name = args.as_name if args.as_name is not None else args.path.stem
    text = _with_name(text, name)
    if args.mount is not None:
        from drymount.config.splice import with_mount

        text = with_mount(text, args.mount)
    from drymount.io import atomic_write_text

    atomic_write_text(args.path, text)
    mount = f", [mount] from {args.mount}" if args.mount is not None else ""
    _info(f"wrote {args.path} (preset {args.name}, named {name!r}{mount})")
    return EXIT_OK


def _description(name: str) -> str:
    """A preset's description as its file states it (read without building the
    model), else the one its loaded system gives."""
    from drymount.config import preset_description

    text = preset_description(name)
    if text:
        return text
    from drymount.config import load_preset

    return load_preset(name).description


def _with_name(text: str, name: str) -> str:
    """``text`` (a preset's TOML) with its top-level ``name = ...`` set to ``name``."""
    import json
    import re

    if not name.strip():
        raise UsageError(f"`--name` must be a non-empty name, got {name!r}")
    line = f"name = {json.dumps(name)}"  # a JSON string is a TOML basic string
    head, sep, tables = text.partition("\n[")  # the top level ends at the first table
    if re.search(r"(?m)^name\s*=.*$", head):
        head = re.sub(r"(?m)^name\s*=.*$", lambda _: line, head, count=1)
    else:
        head = head.rstrip("\n") + "\n" + line + "\n"
    return head + sep + tables


def cmd_build_fmu(args) -> int:
    from drymount.io import shown_path

    if args.out is not None:
        _check_out(args.out, "--out")
        if args.out.suffix != ".fmu":
            raise UsageError(f"--out: {str(args.out)!r} must end with .fmu")
    if args.native:
        from drymount.fmu_build.native import build_native_fmu

        build = build_native_fmu(args.out, fmi=args.fmi or 2)
        _info(build.summary())
        print(shown_path(build.path))
        return EXIT_OK
    if args.fmi not in (None, 2):
        raise UsageError(f"`--fmi` {args.fmi} needs --native: the PythonFMU build is "
                         f"FMI 2.0 only")
    from drymount.fmu_build import build_fmu

    path = build_fmu(args.out) if args.out is not None else build_fmu()
    print(shown_path(path))
    return EXIT_OK


def cmd_export_ssp(args) -> int:
    from drymount.ssp import export_ssp

    from drymount.ssp import SspError, check_mount_fmu

    cfg = _load(args.config, args.overrides)
    if args.fmu is not None:
        fmu_path(args.fmu)  # exists, a zip with a modelDescription.xml
        try:
            check_mount_fmu(args.fmu)
        except SspError as exc:
            raise UsageError(str(exc)) from None
    _check_out(args.out, "--out")
    exp = export_ssp(cfg, args.out, native=args.native, fmu_path=args.fmu)
    _info(f"wrote {exp.path}: {len(exp.mounts)} mount components "
          f"({', '.join(exp.mounts)}) of {exp.fmu}, "
          f"parameter set {exp.parameter_set!r}")
    return EXIT_OK


def cmd_export_xc(args) -> int:
    from drymount.crosscheck import XcError, export_xc

    try:
        exp = export_xc(args.fmu, args.out)
    except XcError as exc:
        raise UsageError(str(exc)) from None
    _info(f"wrote {exp.folder}: {exp.model}.fmu, {exp.model}_in.csv, "
          f"{exp.model}_ref.csv ({exp.rows} rows), {exp.model}_ref.opt")
    return EXIT_OK


#: `drymount hbm`'s options by the API argument they set (to name them in messages)
_HBM_OPTIONS = {"harmonics": "--harmonics", "n_samples": "--n-samples",
                "max_harmonics": "--max-harmonics"}
_HBM_CONTROLS = ("tol", "max_harmonics", "ds_initial", "ds_min", "ds_max", "max_angle")


def cmd_hbm(args) -> int:
    cfg = _load(args.config, args.overrides)  # a bad --set: told before drymount.api
    from drymount.api import Model, hbm
    from drymount.hbm.options import CountError, OptionsError

    fmin, fmax = _band(args, cfg)
    out = outputs(args, cfg, "hbm")
    events = events_sibling(out)
    backbone = (sibling(out, "_backbone.csv", "backbone file") if args.backbone
                else None)
    controls = {k: getattr(args, k) for k in _HBM_CONTROLS}
    # --harmonics / --n-samples fix H / N; [hbm] values are where --tol starts
    try:
        with partial_on_stop(out, "points"):
            fr = hbm(Model(cfg), fmin, fmax, harmonics=args.harmonics,
                     n_samples=args.n_samples, progress=not args.quiet,
                     **controls).result
    except CountError as exc:  # checked before any work, named as the option
        raise UsageError(exc.named(_HBM_OPTIONS.get(exc.field, f"`{exc.field}`"))) \
            from None
    except OptionsError as exc:
        raise UsageError(str(exc)) from None
    _write_with(out, fr.to_csv,
                partial=None if fr.success else f"numerical failure: {fr.message}")
    _write_with(events, fr.events_to_csv)
    _info(f"wrote {out} ({len(fr.freq_hz)} points, H = {fr.harmonics}, "
          f"N = {fr.n_samples or 'closed forms'}) and {events} (folds and peaks)")
    modes = (_write_backbone(cfg, fr, cfg.hbm.options(**controls), backbone)
             if backbone else None)
    if args.plot is not None:
        _write_with(args.plot, lambda p: _plot_hbm(fr, p, args.log_freq, modes))
        _info(f"wrote {args.plot}")
    _print_hbm_accuracy(fr)
    if fr.family_summary():
        print(f"  {fr.family_summary()}")
    _print_hbm_summary(cfg.name, fr)
    if len(fr.freq_hz):
        _print_bifurcations(fr, args.config)
    if not fr.success:
        _err(f"harmonic balance did not complete: {fr.message}; the "
             f"{len(fr.freq_hz)} points computed so far are in {out}")
        return EXIT_FAILURE
    return EXIT_OK


def cmd_cosim(args) -> int:
    cfg = _load(args.config, args.overrides)  # a bad --set: told before drymount.api
    from drymount.api import Model, cosim
    from drymount.measured import MeasuredInputError, configured_inputs

    conf = configured_inputs(cfg)
    measured = any(p is not None for p in (args.road, args.engine, conf.road,
                                           conf.engine))
    freq = args.freq if args.freq is not None else cfg.cosim.freq_hz
    if freq is None and not measured:
        raise UsageError(f"give --freq, --road or --engine (the configuration "
                         f"{cfg.source} has no [cosim] freq_hz or [cosim.input])")
    backend = args.backend or cfg.cosim.backend
    out = outputs(args, cfg, "cosim")
    for path, option in ((args.spectra, "--spectra"),
                         (args.spectra_plot, "--spectra-plot")):
        if path is not None:
            _check_out(path, option)
    fmu = fmu_path(args.fmu) if backend == "fmu" else args.fmu
    try:
        with partial_on_stop(out, "time steps"):
            run = cosim(Model(cfg), args.freq, duration=args.duration,
                        backend=backend, steps_per_period=args.steps_per_period,
                        road=args.road, speed=args.speed, engine=args.engine,
                        fmu_path=fmu)
    except MeasuredInputError as exc:
        raise UsageError(str(exc)) from None
    th = run.history
    _write_with(out, th.to_csv)
    _info(f"wrote {out} ({len(th.t)} time steps, {th.t[-1]:g} s, backend {backend})")
    if args.plot is not None:
        _write_with(args.plot, lambda p: _plot_time_history(
            th, cfg, None if measured and args.freq is None else freq, p))
        _info(f"wrote {args.plot}")
    if args.spectra is not None or args.spectra_plot is not None:
        sp = run.spectra(skip=args.skip)
        for path, write in ((args.spectra, sp.to_csv),
                            (args.spectra_plot, lambda p: sp.plot(path=p))):
            if path is not None:
                write(path)
                _info(f"wrote {path} (PSDs, Welch, {sp.segment_s:.3g} s segments)")
    return EXIT_OK


def cmd_sweep(args) -> int:
    from drymount.config import SweepSettings

    cfg = _load(args.config, args.overrides)
    import numpy as np

    fmin, fmax = _band(args, cfg)
    s = SweepSettings(fmin, fmax, args.points or cfg.sweep.points,
                      args.direction or cfg.sweep.direction,
                      args.spacing or cfg.sweep.spacing)
    freqs = s.freqs_hz()
    backend = args.backend or ("inproc" if args.batch else cfg.cosim.backend)
    overlay = _CurveCSV(args.hbm) if args.hbm is not None else None
    if overlay is not None and overlay.system_name not in ("", cfg.system.name):
        raise UsageError(f"--hbm: {args.hbm} is a curve of {overlay.system_name!r} "
                         f"(its header says so), not of {cfg.system.name!r}: give the "
                         f"`drymount hbm` curve of the same configuration")
    out = outputs(args, cfg, "sweep")
    kw = {}
    spp = args.steps_per_period or cfg.cosim.steps_per_period
    if spp is not None:
        kw["steps_per_period"] = spp
    if backend == "fmu":
        kw["fmu_path"] = fmu_path(args.fmu)
    import drymount.vehicle as vehicle

    with partial_on_stop(out, "frequencies"):
        res = vehicle.sweep(cfg.system, freqs, direction=s.direction, backend=backend,
                            workers=args.workers, progress=not args.quiet,
                            batch=args.batch, refine=args.refine, hbm=overlay, **kw)
    _write_with(out, res.to_csv)
    _info(f"wrote {out} ({len(res.freq_hz)} frequencies, {s.direction}, backend "
          f"{backend})")
    if args.plot is not None:
        _write_with(args.plot, lambda p: res.plot(path=p, hbm=overlay))
        _info(f"wrote {args.plot}")
    conv = np.asarray(res.converged, dtype=bool)
    peak = _peak_text(cfg.name, res.freq_hz, res.transmissibility)
    if peak:
        print(f"{peak} ({int(conv.sum())}/{len(conv)} frequencies converged)")
    if overlay is not None and not args.refine:
        hint = _missed_peak(res.transmissibility, overlay)
        if hint:
            print(hint)
    if not np.all(conv):
        bad = ", ".join(f"{f:g}" for f in np.asarray(res.freq_hz)[~conv])
        _err(f"no steady state reached at {bad} Hz (those rows have converged = 0 in "
             f"{out})")
        return EXIT_FAILURE
    return EXIT_OK


def _lead_module(name: str):
    """Import ``drymount.<name>`` (written separately); UsageError if it is missing."""
    try:
        return importlib.import_module(f"drymount.{name}")
    except ModuleNotFoundError as exc:
        if exc.name in (f"drymount.{name}", "drymount"):
            raise UsageError(f"this installation has no drymount.{name} module; the "
                             f"`{name}` command is not available") from None
        raise


def cmd_validate(args) -> int:
    _check_out_dir(args.out, "--out")
    return _lead_module("validation").main(args)


def cmd_study(args) -> int:
    if args.out is None:
        args.out = Path(f"study-{args.name}")
    _check_out_dir(args.out, "--out")
    return _lead_module("studies").main(args)


def cmd_demo(args) -> int:
    _check_out_dir(args.out, "--out")
    return _lead_module("demo").main(args)


def cmd_fit(args) -> int:
    _check_out_dir(args.out, "--out")
    if args.kind in ("loops", "table") and _lead_module("fit_dynamic").wanted(args):
        return _lead_module("fit_dynamic").main(args)   # k1 fitted too (issue 28)
    return _lead_module("fit").main(args)


def cmd_static(args) -> int:
    if args.out is not None:  # the default <name>_static.csv: checked by static
        _check_out(args.out, "--out")
    return _lead_module("static").main(args)


def cmd_characterise(args) -> int:
    if args.fmin is not None and args.fmax is not None and not args.fmax > args.fmin:
        raise UsageError(f"the frequency range must satisfy fmin < fmax, got fmin = "
                         f"{args.fmin:g} Hz, fmax = {args.fmax:g} Hz")
    if args.out is not None:  # the default <name>_characterise: checked there
        _check_out_dir(args.out, "--out")
    return _lead_module("characterise").main(args)


def cmd_explore(args) -> int:
    from drymount.design.commands import cmd_explore as run

    return run(args, _load, UsageError)


def cmd_optimize(args) -> int:
    from drymount.design.commands import cmd_optimize as run

    return run(args, _load, UsageError)


def cmd_modes(args) -> int:
    from drymount.modes_cmd import cmd_modes as run

    return run(args, _load, UsageError)


COMMANDS = {
    "presets": cmd_presets,
    "build-fmu": cmd_build_fmu,
    "export-ssp": cmd_export_ssp,
    "export-xc": cmd_export_xc,
    "hbm": cmd_hbm,
    "cosim": cmd_cosim,
    "sweep": cmd_sweep,
    "validate": cmd_validate,
    "study": cmd_study,
    "demo": cmd_demo,
    "fit": cmd_fit,
    "characterise": cmd_characterise,
    "static": cmd_static,
    "explore": cmd_explore,
    "optimize": cmd_optimize,
    "modes": cmd_modes,
}


def main(argv: list[str] | None = None) -> int:
    """Run ``drymount`` with ``argv`` (default ``sys.argv[1:]``); return the exit code.

    Usage errors and configuration errors print a clean message (no traceback) and
    return 2; numerical failures return 1 after writing what was computed; SIGINT
    returns 130 and SIGTERM 143 after writing what was computed.
    """
    with signals_interrupt(program=argv is None):
        try:
            code = _run(argv)
        except KeyboardInterrupt:
            code = interrupted()
    if argv is None and code in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        # CPython remembers a KeyboardInterrupt that passed through exec(str) (a
        # lazy import) even when it was handled, and would end the process with
        # SIGINT (status -2) instead of this code: leave without finalisation (the
        # results are written and the workers stopped).
        _release_process_resources()
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(code)
    return code


def _release_process_resources(timeout: float = 2.0) -> None:
    """What multiprocessing releases at a normal exit (os._exit skips it): the
    semaphores of the stopped worker pools, or its resource tracker prints a
    'leaked semaphore objects' warning after the run. At most ``timeout`` s."""
    if "multiprocessing.util" not in sys.modules:
        return
    import threading
    from multiprocessing import synchronize, util

    # first the semaphores themselves, here (unlink + unregister, no lock taken that
    # another thread could hold): a timed-out thread left one registered under load
    for fin in list((util._finalizer_registry or {}).values()):
        if getattr(fin, "_callback", None) is synchronize.SemLock._cleanup:
            with contextlib.suppress(Exception):
                fin()
    t = threading.Thread(target=util._run_finalizers, daemon=True)
    t.start()
    t.join(timeout)


def _renamed_backend(args) -> None:
    """``--backend native`` (the in-process law's old name): one line on stderr, and
    the backend's name now."""
    name = getattr(args, "backend", None)
    if name == "native":
        from drymount.vehicle.backends import RENAMED_BACKENDS, renamed_backend_message

        print(f"drymount: warning: --backend {renamed_backend_message(name)}",
              file=sys.stderr)
        args.backend = RENAMED_BACKENDS[name]


_showwarning = warnings.showwarning


def _show_future_warning(message, category, filename, lineno, file=None, line=None):
    """A FutureWarning (a deprecated name the user passed) as one line on stderr;
    other warnings as Python shows them."""
    if issubclass(category, FutureWarning):
        print(f"drymount: warning: {message}", file=sys.stderr)
        return
    _showwarning(message, category, filename, lineno, file, line)


#: Commands whose ``--out`` (and ``--plot``) name files: checked before the
#: configuration loads (NumPy and the model), so that a usage error such as ``--out``
#: naming a folder costs no more than ``--help`` (issue 27 item 1).
_FILE_OUTPUT_COMMANDS = ("hbm", "cosim", "sweep", "modes")


def _check_file_outputs(args) -> None:
    """``--out`` and ``--plot`` of a :data:`_FILE_OUTPUT_COMMANDS` command, as the
    command itself checks them later (``cli_guard.outputs``); UsageError."""
    if getattr(args, "command", None) not in _FILE_OUTPUT_COMMANDS:
        return
    if getattr(args, "out", None) is not None:
        _check_out(args.out, "--out")
    if getattr(args, "plot", None) is not None:
        from drymount.cli_guard import _check_plot

        _check_plot(args.plot)


def _run(argv) -> int:
    from drymount.threads import limit_threads

    try:
        limit_threads()  # one BLAS thread unless $DRYMOUNT_THREADS says otherwise
    except ValueError as exc:
        _err(str(exc))
        return EXIT_USAGE
    from drymount.config import ConfigError

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0) or a usage error (2)
        return int(exc.code or 0)
    try:
        if isinstance(getattr(args, "config", None), str):
            from drymount.config.catalog import check_spec

            check_spec(args.config)  # a typo in CONFIG is told before NumPy loads
        _check_file_outputs(args)  # a bad --out too (before the configuration loads)
        _renamed_backend(args)
        with warnings.catch_warnings():
            # a deprecated name the user passed: told in one line, not an error
            warnings.simplefilter("default", FutureWarning)
            warnings.showwarning = _show_future_warning
            code = COMMANDS[args.command](args)
        return EXIT_OK if code is None else int(code)
    except ConfigError as exc:
        print(f"drymount: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except UsageError as exc:
        _err(str(exc))
        return EXIT_USAGE
    except Exception as exc:  # a numerical or FMU failure deep in a run
        if stopped_by() is not None:  # e.g. an FMU call that the signal broke
            return interrupted()
        if args.traceback or os.environ.get("DRYMOUNT_TRACEBACK"):
            raise
        from drymount.io import OutputError

        if isinstance(exc, OutputError):  # e.g. a full disk: the file and the reason
            _err(str(exc))
            return EXIT_FAILURE
        _err(f"{type(exc).__name__}: {exc} (run with --traceback for details)")
        return EXIT_FAILURE


if __name__ == "__main__":
    sys.exit(main())
