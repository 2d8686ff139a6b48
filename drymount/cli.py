"""The ``drymount`` command line.

Commands (``drymount COMMAND --help`` shows each one's options and an example)::

    presets   list | show NAME | export NAME PATH
    build-fmu build the FrictionMount FMU
    hbm       harmonic-balance frequency response of a configuration
    cosim     time history co-simulated through the mount FMU (or in-process)
    sweep     stepped-sine sweep of co-simulated steady states
    validate  co-simulation against harmonic balance, with a report
    study     the thesis's design studies
    demo      the first-hour demo: FMU, HBM and co-simulation of a quarter car

A CONFIG argument is a TOML file (``docs/config.md``) or a preset name
(``drymount presets list``).

Exit status: 0 success; 2 bad usage or an invalid configuration (every problem is
listed, no traceback); 1 a numerical failure (what was computed is still written);
130 interrupted.
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import sys
import textwrap
from pathlib import Path

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_FAILURE", "EXIT_USAGE"]

EXIT_OK = 0
#: A numerical failure: an HBM continuation that stopped, a sweep point that did not
#: reach a steady state, an FMU error during a run.
EXIT_FAILURE = 1
#: Bad usage or an invalid configuration (argparse's own code for usage errors).
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

STUDY_NAMES = ("normal-force", "optimize-n0", "quarter-car", "six-dof", "jump")


class UsageError(Exception):
    """Bad command-line values found after parsing (exit status 2)."""


# ======================================================================================
# Argument types
# ======================================================================================


def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be a number > 0, got {text!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return x


def _int_at_least(minimum: int):
    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"must be an integer >= {minimum}, got {text!r}") from None
        if n < minimum:
            raise argparse.ArgumentTypeError(
                f"must be an integer >= {minimum}, got {n}")
        return n

    parse.__name__ = f"integer >= {minimum}"
    return parse


# ======================================================================================
# Parser
# ======================================================================================


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Keeps the layout of descriptions and examples; shows defaults."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("%(default)" not in text and action.default not in (None, False,
                                                                 argparse.SUPPRESS)
                and action.option_strings):
            text += " (default: %(default)s)"
        return text


def _examples(*lines: str) -> str:
    return "examples:\n" + "\n".join(f"  {line}" for line in lines)


def _add(sub, name: str, help_: str, description: str, examples: list[str]):
    return sub.add_parser(name, help=help_, description=textwrap.dedent(description),
                          epilog=_examples(*examples), formatter_class=_Formatter)


def _harness_args(p, kind: str) -> None:
    """Options shared by ``cosim`` and ``sweep``: step, FMU, output files."""
    p.add_argument("--steps-per-period", type=_int_at_least(8), default=None,
                   help="fixed steps per excitation period (default: [cosim] "
                        "steps_per_period, else the harness default)")
    p.add_argument("--fmu", type=Path, default=None,
                   help="FMU to use (default: dist/FrictionMount.fmu, built if "
                        "missing)")
    p.add_argument("--out", type=Path, default=None,
                   help=f"CSV file to write (default: <name>_{kind}.csv)")
    p.add_argument("--plot", type=Path, default=None, help="plot file to write")


def _config_arg(p):
    p.add_argument("config", metavar="CONFIG",
                   help="TOML configuration file (docs/config.md) or preset name "
                        "(drymount presets list)")


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("drymount")
    except PackageNotFoundError:  # running from a source tree without install
        return "(not installed)"


def build_parser() -> argparse.ArgumentParser:
    """The ``drymount`` argument parser (subcommands in ``args.command``)."""
    parser = argparse.ArgumentParser(
        prog="drymount",
        description=textwrap.dedent("""\
            drymount: friction-damped engine mounts. An FMI 2.0 mount FMU, a vehicle
            co-simulation harness and harmonic balance, for the systems of the thesis
            "Design of an engine mount with dry friction damping".

            CONFIG is a TOML file (docs/config.md) or a preset name."""),
        epilog=_examples(
            "drymount demo --out demo                # first look: report in demo/",
            "drymount presets list",
            "drymount hbm sdof_halved --out curve.csv --plot curve.png",
            "drymount sweep sdof_halved --points 20 --backend native --hbm curve.csv "
            "--plot sweep.png",
            "drymount build-fmu --out FrictionMount.fmu",
        ) + "\n\nexit status: 0 success, 1 numerical failure (results so far are "
            "written), 2 bad usage or configuration",
        formatter_class=_Formatter)
    parser.add_argument("--version", action="version",
                        version=f"drymount {_version()}")
    parser.add_argument("--traceback", action="store_true",
                        help="show the Python traceback of an unexpected error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    # presets ------------------------------------------------------------------
    p = _add(sub, "presets", "list, show or export the shipped presets",
             """\
             The presets are the thesis's systems as TOML configurations. Every
             value the thesis does not give is stated in a comment with its reason.
             Export one to start your own configuration.""",
             ["drymount presets list", "drymount presets show sdof_halved",
              "drymount presets export six_dof_halved my_engine.toml"])
    psub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    psub.add_parser("list", help="names and descriptions of the presets",
                    description="Print each preset's name and description.",
                    epilog=_examples("drymount presets list"),
                    formatter_class=_Formatter)
    q = psub.add_parser("show", help="print a preset's TOML text",
                        description="Print the TOML text of a preset, with its "
                                    "comments.",
                        epilog=_examples("drymount presets show quarter_car_halved"),
                        formatter_class=_Formatter)
    q.add_argument("name", metavar="NAME", help="preset name")
    q = psub.add_parser("export", help="write a preset's TOML to a file",
                        description="Write the TOML text of a preset to PATH, to edit "
                                    "it into your own configuration.",
                        epilog=_examples(
                            "drymount presets export sdof_halved mine.toml",
                            "drymount hbm mine.toml"),
                        formatter_class=_Formatter)
    q.add_argument("name", metavar="NAME", help="preset name")
    q.add_argument("path", metavar="PATH", type=Path, help="file to write")
    q.add_argument("--force", action="store_true", help="overwrite PATH if it exists")

    # build-fmu ----------------------------------------------------------------
    p = _add(sub, "build-fmu", "build the FrictionMount FMU (FMI 2.0 co-simulation)",
             """\
             Build FrictionMount.fmu, the mount law as an FMI 2.0 co-simulation FMU
             (pythonfmu). The importer needs a Python 3 with the pythonfmu runtime on
             the host; docs/fmu.md describes its variables.""",
             ["drymount build-fmu", "drymount build-fmu --out /tmp/FrictionMount.fmu"])
    p.add_argument("--out", type=Path, default=None,
                   help="FMU file to write (default: dist/FrictionMount.fmu under the "
                        "current folder)")

    # hbm ----------------------------------------------------------------------
    p = _add(sub, "hbm", "harmonic-balance frequency response (continuation)",
             """\
             Multi-harmonic balance with alternating frequency-time evaluation and
             arc-length continuation from fmin to fmax (thesis Chapter 3,
             eq. 3.51-3.66), following folds and marking unstable points. Writes a
             CSV (freq_hz, for each DOF <dof>_amp and <dof>_peak, transmissibility,
             stable) and optionally a plot. H = 1 is the thesis's single-harmonic
             method.""",
             ["drymount hbm sdof_halved --out curve.csv --plot curve.png",
              "drymount hbm sdof_cubic --harmonics 1 --fmin 2 --fmax 14 --out h1.csv",
              "drymount hbm my_engine.toml --harmonics 9"])
    _config_arg(p)
    p.add_argument("--harmonics", "-H", type=_int_at_least(1), default=None,
                   help="number of harmonics H (default: [hbm] harmonics of CONFIG, 7)")
    p.add_argument("--n-samples", type=_int_at_least(3), default=None,
                   help="AFT samples per period (default: [hbm] n_samples, else auto)")
    p.add_argument("--fmin", type=_positive_float, default=None,
                   help="lowest frequency in Hz (default: [sweep] fmin_hz)")
    p.add_argument("--fmax", type=_positive_float, default=None,
                   help="highest frequency in Hz (default: [sweep] fmax_hz)")
    p.add_argument("--out", type=Path, default=None,
                   help="CSV file to write (default: <name>_hbm.csv)")
    p.add_argument("--plot", type=Path, default=None,
                   help="plot file to write (.png, .pdf, .svg)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    _hbm_accuracy_args(p)

    # cosim --------------------------------------------------------------------
    p = _add(sub, "cosim", "time history co-simulated through the mount FMU",
             """\
             Fixed-step co-simulation of the bodies with one mount FMU instance per
             mount (backend fmu, through fmpy) or the same mount law in-process
             (backend native). Writes the time histories: time, every DOF and every
             mount force.""",
             ["drymount cosim sdof_halved --freq 5 --duration 4 --out run.csv",
              "drymount cosim six_dof_halved --freq 7 --duration 3 --backend native "
              "--out run.csv --plot run.png"])
    _config_arg(p)
    p.add_argument("--freq", type=_positive_float, default=None,
                   help="excitation frequency in Hz (default: [cosim] freq_hz)")
    p.add_argument("--duration", type=_positive_float, default=None,
                   help="simulated time in s (default: [cosim] duration, else the "
                        "harness default)")
    p.add_argument("--backend", choices=("fmu", "native"), default=None,
                   help="fmu: FMU instances through fmpy; native: in-process law "
                        "(default: [cosim] backend)")
    _harness_args(p, "cosim")

    # sweep --------------------------------------------------------------------
    p = _add(sub, "sweep", "stepped-sine sweep of co-simulated steady states",
             """\
             At each frequency, run until the period-to-period change is below the
             tolerance, starting from the previous frequency's steady state (so jumps
             show as on a test rig), and extract each DOF's fundamental amplitude and
             peak and the transmissibility. Same CSV columns as `drymount hbm` (without
             `stable`) plus `converged`. --hbm overlays a curve written by `drymount
             hbm` on the plot.""",
             ["drymount sweep sdof_halved --fmin 2 --fmax 14 --points 25 --backend "
              "native --workers 2 --out sweep.csv --plot sweep.png",
              "drymount hbm sdof_cubic --out curve.csv && drymount sweep sdof_cubic "
              "--direction down --hbm curve.csv --plot down.png"])
    _config_arg(p)
    p.add_argument("--fmin", type=_positive_float, default=None,
                   help="lowest frequency in Hz (default: [sweep] fmin_hz)")
    p.add_argument("--fmax", type=_positive_float, default=None,
                   help="highest frequency in Hz (default: [sweep] fmax_hz)")
    p.add_argument("--points", type=_int_at_least(2), default=None,
                   help="number of frequencies (default: [sweep] points)")
    p.add_argument("--spacing", choices=("linear", "log"), default=None,
                   help="frequency spacing (default: [sweep] spacing)")
    p.add_argument("--direction", choices=("up", "down"), default=None,
                   help="sweep order (default: [sweep] direction)")
    p.add_argument("--backend", choices=("fmu", "native"), default=None,
                   help="default: [cosim] backend")
    p.add_argument("--workers", type=_int_at_least(1), default=1,
                   help="parallel processes")
    _harness_args(p, "sweep")
    p.add_argument("--hbm", type=Path, default=None, metavar="CURVE_CSV",
                   help="HBM curve (CSV of `drymount hbm`) to overlay on the plot")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")

    # validate -----------------------------------------------------------------
    p = _add(sub, "validate", "co-simulation through the FMU against harmonic balance",
             """\
             For the single-DOF, quarter-car and 6-DOF presets with friction and the
             cubic single DOF: a stepped sweep co-simulated through the FMU against
             multi-harmonic HBM at the same frequencies. Writes validation.md (report
             with plots) and points.csv; exit status 1 if a system fails its
             tolerance.""",
             ["drymount validate --quick --out validation",
              "drymount validate --systems sdof_friction --inject n0=1.5  # fails"])
    p.add_argument("--quick", action="store_true",
                   help="fewer frequencies (still real runs), for CI")
    p.add_argument("--out", type=Path, default=Path("validation"),
                   help="report folder")
    p.add_argument("--systems", nargs="+", default=None, metavar="NAME",
                   help="only these systems (sdof_friction, quarter_car_friction, "
                        "six_dof_friction, sdof_cubic)")
    p.add_argument("--inject", default=None, metavar="FIELD=FACTOR",
                   help="scale a mount-law field on the HBM side only "
                        "(proves that the check can fail), e.g. n0=1.5")

    # study --------------------------------------------------------------------
    p = _add(sub, "study", "the thesis's design studies (Chapter 4)",
             """\
             normal-force  single DOF, transmissibility for a range of n0
                           (Figs. 4.1-4.4)
             optimize-n0   the n0 minimising peak or RMS transmissibility (Sec. 4.2)
             quarter-car   quarter car for a range of n0 (Figs. 4.6-4.9)
             six-dof       6-DOF responses, lambda 1 and 1.2, relocated mount
                           (Figs. 4.11-4.44)
             jump          cubic single DOF: unstable branch and the jump (Fig. 3.7)
             Each writes CSV files, plots and summary.md into --out.""",
             ["drymount study normal-force --out study-nf",
              "drymount study jump --out jump --quick"])
    p.add_argument("name", metavar="NAME", choices=STUDY_NAMES,
                   help="one of " + ", ".join(STUDY_NAMES))
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: study-NAME)")
    p.add_argument("--quick", action="store_true",
                   help="fewer designs and coarser curves (seconds instead of minutes)")

    # demo ---------------------------------------------------------------------
    p = _add(sub, "demo", "the first-hour demo: FMU, HBM, co-simulation, report",
             """\
             Builds the FMU, computes the HBM curve of the friction-damped quarter car
             against the original mount, co-simulates a few frequencies through the FMU
             and writes demo.md with plots and CSV files. A couple of minutes on 2
             cores.""",
             ["drymount demo", "drymount demo --out /tmp/demo"])
    p.add_argument("--out", type=Path, default=Path("demo"), help="report folder")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress output")
    return parser


# ======================================================================================
# Helpers
# ======================================================================================


def _err(msg: str) -> None:
    print(f"drymount: error: {msg}", file=sys.stderr)


def _info(msg: str) -> None:
    print(msg, file=sys.stderr)


def _load(spec):
    from drymount.config import resolve_config

    return resolve_config(spec)


def _hbm_accuracy_args(p) -> None:
    """Accuracy and step controls of `drymount hbm` (default: [hbm] of CONFIG)."""
    g = p.add_argument_group("accuracy and steps (default: [hbm] of CONFIG, else hbm's)")
    g.add_argument("--tol", type=_positive_float, default=None,
                   help="wanted accuracy relative to the peak (default 1e-3): H and N "
                        "are raised until the error estimate is below tol/2 (unless "
                        "--harmonics/--n-samples fix them), and the step until reading "
                        "between CSV rows stays within tol/2")
    g.add_argument("--max-harmonics", type=_int_at_least(1), default=None,
                   help="cap on H when --tol raises it (default 25)")
    for flag, what in (("--ds-initial", "first"), ("--ds-min", "smallest"),
                       ("--ds-max", "largest")):
        g.add_argument(flag, type=_positive_float, default=None,
                       help=f"{what} arc-length step (scaled: a sweep spans about 1)")
    g.add_argument("--max-angle", type=_positive_float, default=None,
                   help="largest angle between successive tangents, rad (default 0.15)")
    g.add_argument("--log-freq", action="store_true", help="log frequency axis in --plot")


def _write_with(path: Path, writer) -> Path:
    """Call ``writer(tmp_path)`` and move the file to ``path`` atomically."""
    from drymount.io import atomic_path

    with atomic_path(path) as tmp:
        writer(tmp)
    return path


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
    from drymount.config import list_presets, load_preset, preset_text
    from drymount.io import atomic_write_text

    if args.action == "list":
        names = list_presets()
        width = max(len(n) for n in names)
        for n in names:
            print(f"{n:<{width}}  {load_preset(n).description}")
        return EXIT_OK
    text = preset_text(args.name)
    if args.action == "show":
        sys.stdout.write(text)
        return EXIT_OK
    if args.path.exists() and not args.force:
        raise UsageError(f"{args.path} exists; use --force to overwrite it")
    atomic_write_text(args.path, text)
    _info(f"wrote {args.path} (preset {args.name})")
    return EXIT_OK


def cmd_build_fmu(args) -> int:
    from drymount.fmu_build import build_fmu

    path = build_fmu(args.out) if args.out is not None else build_fmu()
    print(path)
    return EXIT_OK


def cmd_hbm(args) -> int:
    cfg = _load(args.config)
    fmin, fmax = _band(args, cfg)
    H = args.harmonics if args.harmonics is not None else cfg.hbm.harmonics
    n_samples = args.n_samples if args.n_samples is not None else cfg.hbm.n_samples
    if n_samples is not None and n_samples < 2 * H + 1:
        raise UsageError(f"--n-samples must be >= 2H + 1 = {2 * H + 1} for H = {H}, "
                         f"got {n_samples}")
    out = args.out or Path(f"{cfg.name}_hbm.csv")
    import hbm

    try:
        opts = cfg.hbm.options(**{k: getattr(args, k) for k in (
            "tol", "max_harmonics", "ds_initial", "ds_min", "ds_max", "max_angle")})
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    fr = hbm.frequency_response(cfg.system, fmin, fmax, harmonics=args.harmonics,
                                n_samples=args.n_samples, options=opts,
                                progress=not args.quiet)
    _write_with(out, fr.to_csv)
    events = Path(fr.events_path(out))
    _write_with(events, fr.events_to_csv)
    _info(f"wrote {out} ({len(fr.freq_hz)} points, H = {fr.harmonics}, "
          f"N = {fr.n_samples or 'closed forms'}) and {events} (folds and peaks)")
    if args.plot is not None:
        _write_with(args.plot, lambda p: fr.plot(path=p, logx=args.log_freq))
        _info(f"wrote {args.plot}")
    _print_hbm_accuracy(fr)
    if len(fr.freq_hz):
        import numpy as np

        t = np.asarray(fr.transmissibility, dtype=float)
        if np.any(np.isfinite(t)):
            i = int(np.nanargmax(t))
            print(f"{cfg.name}: peak transmissibility {t[i]:.4g} at "
                  f"{fr.freq_hz[i]:.4g} Hz; {len(fr.turning_points)} turning point(s); "
                  f"{int(np.sum(~np.asarray(fr.stable, bool)))} unstable point(s)")
            for direction in ("up", "down"):
                events = [f"jumps at {f:.4g} Hz" if k >= 0 else
                          f"leaves the curve at {f:.4g} Hz (stability lost "
                          f"without a fold)" for f, _, k in fr.sweep_jumps(direction)]
                if events:
                    print(f"  a slow sweep {direction} " + "; then ".join(events))
    if not fr.success:
        _err(f"harmonic balance did not complete: {fr.message}; the "
             f"{len(fr.freq_hz)} points computed so far are in {out}")
        return EXIT_FAILURE
    return EXIT_OK


def _print_hbm_accuracy(fr) -> None:
    """Error estimate, merged turning points, folds and peaks of an HBM curve."""
    e = fr.error_max()
    if e == e:
        verdict = {True: "meets", False: "misses", None: "vs"}[fr.tol_met]
        print(f"  error estimate {e:.2g} of peak ({fr.error_reference}); {verdict} "
              f"the tolerance")
    if fr.turning_points_merged:
        print(f"  {fr.turning_points_merged} turning point(s) merged as zigzags of the "
              f"sampled residual (gone with more AFT samples)")
    for ev in fr.folds:
        print(f"  fold at {ev.freq_hz:.6f} Hz" + ("" if ev.converged else
                                                  " (not converged)"))
    for ev in fr.peaks:
        if ev.interior:
            print(f"  peak of {ev.dof}: {ev.amplitude[fr.dof_names.index(ev.dof)]:.6g}"
                  f" at {ev.freq_hz:.6f} Hz")


def cmd_cosim(args) -> int:
    cfg = _load(args.config)
    freq = args.freq if args.freq is not None else cfg.cosim.freq_hz
    if freq is None:
        raise UsageError(f"give --freq (the configuration {cfg.source} has no "
                         f"[cosim] freq_hz)")
    backend = args.backend or cfg.cosim.backend
    spp = args.steps_per_period or cfg.cosim.steps_per_period
    duration = args.duration if args.duration is not None else cfg.cosim.duration
    kw = {"backend": backend}
    if spp is not None:
        kw["dt"] = 1.0 / (freq * spp)
    if duration is not None:
        kw["duration"] = duration
    if backend == "fmu":
        kw["fmu_path"] = _fmu_path(args.fmu)
    out = args.out or Path(f"{cfg.name}_cosim.csv")
    import vehicle

    th = vehicle.simulate(cfg.system, freq, **kw)
    _write_with(out, th.to_csv)
    _info(f"wrote {out} ({len(th.t)} time steps, {th.t[-1]:g} s, backend {backend})")
    if args.plot is not None:
        _write_with(args.plot, lambda p: _plot_time_history(th, cfg, freq, p))
        _info(f"wrote {args.plot}")
    return EXIT_OK


def _fmu_path(path):
    from drymount.fmu_build import ensure_fmu

    return ensure_fmu(path)


def _plot_time_history(th, cfg, freq, path) -> None:
    import numpy as np
    from matplotlib.figure import Figure

    q = np.asarray(th.q)
    names = cfg.system.dof_names
    fig = Figure(figsize=(8, 2.2 * len(names) if len(names) <= 3 else 9))
    for j, name in enumerate(names):
        ax = fig.add_subplot(len(names), 1, j + 1)
        ax.plot(th.t, q[:, j], lw=0.8)
        unit = "rad" if name in ("alpha", "beta", "gamma") else "m"
        ax.set_ylabel(f"{name} [{unit}]")
        ax.grid(True, alpha=0.3)
        if j == 0:
            ax.set_title(f"{cfg.name}: co-simulation at {freq:g} Hz", fontsize=10)
    ax.set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


class _CurveCSV:
    """An HBM curve read back from the CSV of ``drymount hbm``, for the sweep plot.

    Carries the attributes a plot needs: ``freq_hz``, ``amplitude`` (n, n_dof),
    ``peak``, ``transmissibility``, ``stable``, ``dof_names``, ``harmonics`` (None).
    """

    def __init__(self, path: Path):
        import csv

        import numpy as np

        try:
            with open(path, encoding="utf-8") as fh:
                lines = [ln for ln in fh if not ln.startswith("#")]
        except OSError as exc:
            raise UsageError(f"--hbm: cannot read {path}: {exc}") from None
        rows = list(csv.reader(lines))
        if len(rows) < 2 or "freq_hz" not in rows[0]:
            raise UsageError(f"--hbm: {path} is not a curve CSV of `drymount hbm` "
                             f"(needs a header with freq_hz and data rows)")
        header = rows[0]
        try:
            data = np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)
        except ValueError as exc:
            raise UsageError(f"--hbm: {path}: {exc}") from None
        col = {h: data[:, i] for i, h in enumerate(header)}
        self.freq_hz = col["freq_hz"]
        self.dof_names = tuple(h[:-4] for h in header if h.endswith("_amp"))
        self.amplitude = np.column_stack([col[f"{d}_amp"] for d in self.dof_names])
        self.peak = np.column_stack([col.get(f"{d}_peak", col[f"{d}_amp"])
                                     for d in self.dof_names])
        n = len(self.freq_hz)
        self.transmissibility = col.get("transmissibility", np.full(n, np.nan))
        self.stable = (col["stable"].astype(bool) if "stable" in col
                       else np.ones(n, bool))
        self.harmonics = None
        self.turning_points = ()
        self.success = True


def cmd_sweep(args) -> int:
    import numpy as np

    from drymount.config import SweepSettings

    cfg = _load(args.config)
    fmin, fmax = _band(args, cfg)
    s = SweepSettings(fmin, fmax, args.points or cfg.sweep.points,
                      args.direction or cfg.sweep.direction,
                      args.spacing or cfg.sweep.spacing)
    freqs = s.freqs_hz()
    backend = args.backend or cfg.cosim.backend
    overlay = _CurveCSV(args.hbm) if args.hbm is not None else None
    out = args.out or Path(f"{cfg.name}_sweep.csv")
    kw = {}
    spp = args.steps_per_period or cfg.cosim.steps_per_period
    if spp is not None:
        kw["steps_per_period"] = spp
    if backend == "fmu":
        kw["fmu_path"] = _fmu_path(args.fmu)
    import vehicle

    res = vehicle.sweep(cfg.system, freqs, direction=s.direction, backend=backend,
                        workers=args.workers, progress=not args.quiet, **kw)
    _write_with(out, res.to_csv)
    _info(f"wrote {out} ({len(res.freq_hz)} frequencies, {s.direction}, backend "
          f"{backend})")
    if args.plot is not None:
        _write_with(args.plot, lambda p: res.plot(path=p, hbm=overlay))
        _info(f"wrote {args.plot}")
    conv = np.asarray(res.converged, dtype=bool)
    t = np.asarray(res.transmissibility, dtype=float)
    if np.any(np.isfinite(t)):
        i = int(np.nanargmax(t))
        print(f"{cfg.name}: peak transmissibility {t[i]:.4g} at "
              f"{res.freq_hz[i]:.4g} Hz ({int(conv.sum())}/{len(conv)} frequencies "
              f"converged)")
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
    return _lead_module("validation").main(args)


def cmd_study(args) -> int:
    if args.out is None:
        args.out = Path(f"study-{args.name}")
    return _lead_module("studies").main(args)


def cmd_demo(args) -> int:
    return _lead_module("demo").main(args)


COMMANDS = {
    "presets": cmd_presets,
    "build-fmu": cmd_build_fmu,
    "hbm": cmd_hbm,
    "cosim": cmd_cosim,
    "sweep": cmd_sweep,
    "validate": cmd_validate,
    "study": cmd_study,
    "demo": cmd_demo,
}


def main(argv: list[str] | None = None) -> int:
    """Run ``drymount`` with ``argv`` (default ``sys.argv[1:]``); return the exit code.

    Usage errors and configuration errors print a clean message (no traceback) and
    return 2; numerical failures return 1 after writing what was computed.
    """
    from drymount.config import ConfigError

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0) or a usage error (2)
        return int(exc.code or 0)
    try:
        code = COMMANDS[args.command](args)
        return EXIT_OK if code is None else int(code)
    except ConfigError as exc:
        print(f"drymount: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except UsageError as exc:
        _err(str(exc))
        return EXIT_USAGE
    except KeyboardInterrupt:
        _err("interrupted")
        return EXIT_INTERRUPTED
    except Exception as exc:  # a numerical or FMU failure deep in a run
        if args.traceback or os.environ.get("DRYMOUNT_TRACEBACK"):
            raise
        _err(f"{type(exc).__name__}: {exc} (run with --traceback for details)")
        return EXIT_FAILURE


if __name__ == "__main__":
    sys.exit(main())
