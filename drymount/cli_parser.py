"""The argument parser of the ``drymount`` command line (a table of commands and
options; :mod:`drymount.cli` runs them)."""

from __future__ import annotations

import argparse
import math
import sys
import textwrap
from pathlib import Path

__all__ = ["build_parser", "STUDY_NAMES"]

STUDY_NAMES = ("normal-force", "optimize-n0", "quarter-car", "six-dof", "jump", "laws",
               "six-dof-75", "incline", "semi-active", "hydraulic")


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


def _finite_float(minimum: float | None = None, maximum: float | None = None,
                  above: float | None = None):
    """A finite number >= minimum (or > above) and <= maximum (each optional)."""
    parts = ([f">= {minimum:g}"] if minimum is not None else []) + (
        [f"> {above:g}"] if above is not None else []) + (
        [f"<= {maximum:g}"] if maximum is not None else [])
    rng = "a finite number" + (" " + " and ".join(parts) if parts else "")

    def parse(text: str) -> float:
        try:
            x = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {rng}, got {text!r}") from None
        if not (math.isfinite(x) and (minimum is None or x >= minimum)
                and (above is None or x > above)
                and (maximum is None or x <= maximum)):
            raise argparse.ArgumentTypeError(f"must be {rng}, got {text!r}")
        return x

    parse.__name__ = rng
    return parse


#: Limits of options the configuration does not bound (each a run that would not
#: fit in memory or finish beyond them): steps per period, simulated seconds,
#: differential-evolution generations and population per variable.
MAX_STEPS_PER_PERIOD = 65_536
MAX_DURATION_S = 3_600.0


def _int_at_least(minimum: int, maximum: int | None = None):
    rng = f">= {minimum}" if maximum is None else f"in {minimum}..{maximum}"

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"must be an integer {rng}, got {text!r}") from None
        if n < minimum or (maximum is not None and n > maximum):
            raise argparse.ArgumentTypeError(f"must be an integer {rng}, got {n}")
        return n

    parse.__name__ = f"integer {rng}"
    return parse


def _harmonics_arg(text: str) -> int:
    """A harmonic count, by hbm.options' one check of H (argparse names the option)."""
    from drymount.hbm.options import CountError, check_harmonics

    try:
        n = int(text)
    except ValueError:
        n = text  # not an integer: the check says so
    try:
        return check_harmonics(n)
    except CountError as exc:
        raise argparse.ArgumentTypeError(exc.requirement) from None


_harmonics_arg.__name__ = "harmonic count"


def _path(text: str) -> Path:
    if not text.strip():
        raise argparse.ArgumentTypeError("the file name is empty")
    return Path(text)


_path.__name__ = "path"


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
    p.add_argument("--steps-per-period",
                   type=_int_at_least(8, MAX_STEPS_PER_PERIOD), default=None,
                   help=f"fixed steps per excitation period, 8..{MAX_STEPS_PER_PERIOD} "
                        f"(default: [cosim] steps_per_period, else the harness "
                        f"default)")
    p.add_argument("--fmu", type=_path, default=None,
                   help="FMU to use, never modified (default: dist/FrictionMount.fmu, "
                        "built or rebuilt when missing or older than drymount's "
                        "sources; or a native build, dist/FrictionMountNative.fmu or "
                        "dist/FrictionMountNative3.fmu)")
    p.add_argument("--out", type=_path, default=None,
                   help=f"CSV file to write (default: <name>_{kind}.csv)")
    p.add_argument("--plot", type=_path, default=None, help="plot file to write")


def _hbm_accuracy_args(p) -> None:
    """Accuracy and step controls of `drymount hbm` (default: [hbm] of CONFIG)."""
    g = p.add_argument_group(
        "accuracy and steps (default: [hbm] of CONFIG, else hbm's)")
    g.add_argument("--tol", type=_positive_float, default=None,
                   help="wanted accuracy relative to the peak (default 1e-3): H and N "
                        "are raised until the error estimate is below tol/2 (unless "
                        "--harmonics/--n-samples fix them), and the step until reading "
                        "between CSV rows stays within tol/2")
    from drymount.config import MAX_HARMONICS

    g.add_argument("--max-harmonics", type=_harmonics_arg,
                   default=None,
                   help=f"cap on H when --tol raises it, 1..{MAX_HARMONICS} (default "
                        f"25; 13 for systems of more than 3 DOF, the 6-DOF presets)")
    for flag, what in (("--ds-initial", "first"), ("--ds-min", "smallest"),
                       ("--ds-max", "largest")):
        g.add_argument(flag, type=_positive_float, default=None,
                       help=f"{what} arc-length step (scaled: a sweep spans about 1)")
    g.add_argument("--max-angle", type=_positive_float, default=None,
                   help="largest angle between successive tangents, rad (default 0.15)")
    g.add_argument("--log-freq", action="store_true",
                   help="log frequency axis in --plot")


#: --backend: the in-process law and the FMU; "native" is the in-process law's old
#: name (deprecated: the word means only the C FMU now), told by drymount.cli.
_BACKENDS = ("fmu", "inproc", "native")


def _config_arg(p):
    p.add_argument("config", metavar="CONFIG",
                   help="TOML configuration file (docs/config.md) or preset name "
                        "(drymount presets list)")
    p.add_argument("--set", action="append", default=None, metavar="PATH=VALUE",
                   dest="overrides",
                   help="override a field of CONFIG, checked like the file; "
                        "repeatable, e.g. --set mount.friction.n0=12 --set "
                        "'mounts[*].axial.c=200'")


class _VersionAction(argparse.Action):
    """``--version``: the installed version, looked up only when asked
    (``importlib.metadata`` costs 0.1 s of every start-up, issue 27)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS,
                 default=argparse.SUPPRESS,
                 help="show program's version number and exit"):
        super().__init__(option_strings=option_strings, dest=dest,
                         default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        parser._print_message(f"drymount {_version()}\n", sys.stdout)
        parser.exit()


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("drymount")
    except PackageNotFoundError:  # running from a source tree without install
        return "(not installed)"


def _cmd_presets(sub) -> None:
    """``drymount presets``."""
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
                            "drymount presets export sdof_halved mine.toml --mount "
                            "fit/mount.toml",
                            "drymount hbm mine.toml"),
                        formatter_class=_Formatter)
    q.add_argument("name", metavar="NAME", help="preset name")
    q.add_argument("path", metavar="PATH", type=_path, help="file to write")
    q.add_argument("--name", dest="as_name", default=None,
                   help="the configuration's `name` (output files start with it); "
                        "default: the stem of PATH")
    q.add_argument("--force", action="store_true", help="overwrite PATH if it exists")
    q.add_argument("--mount", type=_path, default=None, metavar="FILE",
                   help="replace the preset's [mount] tables by those of FILE (the "
                        "mount.toml of `drymount fit`); single-mount presets only")


def _cmd_build_fmu(sub) -> None:
    """``drymount build-fmu``."""
    p = _add(sub, "build-fmu", "build the FrictionMount FMU (FMI 2.0 co-simulation)",
             """\
             Build FrictionMount.fmu, the mount law as an FMI 2.0 co-simulation FMU
             (pythonfmu). The importer needs a Python 3 with the pythonfmu runtime on
             the host; docs/fmu.md describes its variables.""",
             ["drymount build-fmu", "drymount build-fmu --out /tmp/FrictionMount.fmu",
              "drymount build-fmu --native --fmi 3  # dist/FrictionMountNative3.fmu"])
    p.add_argument("--out", type=_path, default=None,
                   help="FMU file to write (default: dist/FrictionMount.fmu under the "
                        "current folder; with --native dist/FrictionMountNative.fmu or "
                        "dist/FrictionMountNative3.fmu)")
    p.add_argument("--native", action="store_true",
                   help="the native build (C, no Python needed by the importer; "
                        "docs/fmu.md, 'Which FMU')")
    p.add_argument("--fmi", type=int, choices=(2, 3), default=None,
                   help="FMI version of the native build (default 2; the PythonFMU "
                        "build is FMI 2.0 only)")


def _cmd_export_xc(sub) -> None:
    """``drymount export-xc``."""
    p = _add(sub, "export-xc", "FMI cross-check folder of a mount FMU",
             """\
             Write the FMI cross-check folder of a FrictionMount FMU:
             DIR/<fmiVersion>/cs/<platform>/drymount/<version>/<Model>/ with the FMU,
             <Model>_in.csv (sine deflections of two axes), <Model>_ref.csv (the forces
             by the mount law, outputs read after doStep), <Model>_ref.opt and
             ReadMe.txt (docs/fmu.md, 'Cross-check').""",
             ["drymount export-xc dist/FrictionMountNative.fmu --out xc"])
    p.add_argument("fmu", type=_path, metavar="FMU",
                   help="a FrictionMount co-simulation FMU (FMI 2.0 or 3.0)")
    p.add_argument("--out", type=_path, required=True,
                   help="folder under which the cross-check tree is written")


def _cmd_export_ssp(sub) -> None:
    """``drymount export-ssp``."""
    p = _add(sub, "export-ssp", "SSP 1.0 archive of a configuration's mount FMUs",
             """\
             Write an SSP 1.0 archive: SystemStructure.ssd with one FMU component per
             mount of the configuration (connectors u, v, n in; F, Ffr, E_fr out), one
             parameter set per mount (resources/<mount>.ssv, the configuration's values
             and units) and documentation/README.txt saying what the host connects (the
             vehicle body is not an FMU).""",
             ["drymount export-ssp six_dof_halved --out six_dof.ssp --native"])
    _config_arg(p)
    p.add_argument("--out", type=_path, required=True, help="SSP file to write")
    p.add_argument("--native", action="store_true",
                   help="pack the native FMU (FrictionMountNative.fmu, FMI 2.0) "
                        "instead of the PythonFMU build")
    p.add_argument("--fmu", type=_path, default=None, help="pack this FMU instead")


def _cmd_hbm(sub) -> None:
    """``drymount hbm``."""
    from drymount.config import MAX_HARMONICS, MAX_N_SAMPLES

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
    p.add_argument("--harmonics", "-H", type=_harmonics_arg,
                   default=None,
                   help=f"number of harmonics H, 1..{MAX_HARMONICS} (default: [hbm] "
                        f"harmonics of CONFIG, 7)")
    p.add_argument("--n-samples", type=_int_at_least(3, MAX_N_SAMPLES), default=None,
                   help=f"AFT samples per period, 2H+1..{MAX_N_SAMPLES} (default: "
                        f"[hbm] n_samples, else auto)")
    p.add_argument("--fmin", type=_positive_float, default=None,
                   help="lowest frequency in Hz (default: [sweep] fmin_hz)")
    p.add_argument("--fmax", type=_positive_float, default=None,
                   help="highest frequency in Hz (default: [sweep] fmax_hz)")
    p.add_argument("--out", type=_path, default=None,
                   help="CSV file to write (default: <name>_hbm.csv)")
    p.add_argument("--plot", type=_path, default=None,
                   help="plot file to write (.png, .pdf, .svg)")
    p.add_argument("--backbone", action="store_true",
                   help="also trace the nonlinear modes near the band (EPMC, as "
                        "drymount modes) over the curve's amplitudes: written to "
                        "<out stem>_backbone.csv and drawn on the DOF amplitude "
                        "panels of --plot; the peaks of forced curves lie on them")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    _hbm_accuracy_args(p)


def _cmd_cosim(sub) -> None:
    """``drymount cosim``."""
    p = _add(sub, "cosim", "time history co-simulated through the mount FMU",
             """\
             Fixed-step co-simulation of the bodies with one mount FMU instance per
             mount (backend fmu, through fmpy) or the same mount law in-process
             (backend inproc). Writes the time histories: time, every DOF and every
             mount force.""",
             ["drymount cosim sdof_halved --freq 5 --duration 4 --out run.csv",
              "drymount cosim six_dof_halved --freq 7 --duration 3 --backend inproc "
              "--out run.csv --plot run.png",
              "drymount cosim six_dof_halved --road examples/data/road_profile.csv "
              "--speed 20 --backend inproc --spectra psd.csv --spectra-plot psd.png "
              "--skip 0.5"])
    _config_arg(p)
    p.add_argument("--freq", type=_positive_float, default=None,
                   help="excitation frequency in Hz (default: [cosim] freq_hz)")
    p.add_argument("--duration", type=_finite_float(above=0.0, maximum=MAX_DURATION_S),
                   default=None,
                   help=f"simulated time in s, at most {MAX_DURATION_S:g} (default: "
                        f"[cosim] duration, else the harness default)")
    p.add_argument("--backend", choices=_BACKENDS, default=None, metavar="{fmu,inproc}",
                   help="fmu: FMU instances through fmpy; inproc: in-process law "
                        "(`native`, its old name, still works; default: [cosim] "
                        "backend)")
    p.add_argument("--road", type=_path, default=None, metavar="CSV",
                   help="measured road profile or base displacement: distance [m] or "
                        "time [s], elevation [mm|m] (default: [cosim.input] road)")
    p.add_argument("--speed", type=_positive_float, default=None,
                   help="vehicle speed in m/s for a road over distance (default: "
                        "[cosim.input] speed)")
    p.add_argument("--engine", type=_path, default=None, metavar="CSV",
                   help="measured engine forces/moments or accelerations: time [s] "
                        "and one column per DOF (default: [cosim.input] engine)")
    p.add_argument("--spectra", type=_path, default=None, metavar="CSV",
                   help="write the PSDs of the mount forces and DOF accelerations")
    p.add_argument("--spectra-plot", type=_path, default=None, metavar="PNG",
                   help="plot the PSDs")
    p.add_argument("--skip", type=_finite_float(0.0), default=0.0, metavar="SECONDS",
                   help="start-up transient left out of the spectra (default 0 s)")
    _harness_args(p, "cosim")


def _cmd_sweep(sub) -> None:
    """``drymount sweep``."""
    from drymount.config import MAX_POINTS

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
    p.add_argument("--points", type=_int_at_least(2, MAX_POINTS), default=None,
                   help=f"number of frequencies, 2..{MAX_POINTS} (default: [sweep] "
                        f"points)")
    p.add_argument("--spacing", choices=("linear", "log"), default=None,
                   help="frequency spacing (default: [sweep] spacing)")
    p.add_argument("--direction", choices=("up", "down"), default=None,
                   help="sweep order (default: [sweep] direction)")
    p.add_argument("--backend", choices=_BACKENDS, default=None, metavar="{fmu,inproc}",
                   help="fmu: FMU instances through fmpy; inproc: in-process law "
                        "(`native`, its old name, still works; default: [cosim] "
                        "backend)")
    p.add_argument("--workers", type=_int_at_least(1), default=1,
                   help="parallel processes")
    p.add_argument("--batch", action="store_true",
                   help="inproc backend: step all frequencies at once as one array "
                        "computation (each from the linearised response, not from "
                        "the previous frequency; docs/performance.md)")
    p.add_argument("--refine", type=_int_at_least(0, MAX_POINTS), default=0,
                   metavar="N",
                   help="add N frequencies where they matter: at the peak and where "
                        "the response changes fastest, first at the peak and folds "
                        "of the --hbm curve if given (default 0)")
    _harness_args(p, "sweep")
    p.add_argument("--hbm", type=_path, default=None, metavar="CURVE_CSV",
                   help="HBM curve (CSV of `drymount hbm`) to overlay on the plot "
                        "(and to guide --refine)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")


def _cmd_validate(sub) -> None:
    """``drymount validate``."""
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
    p.add_argument("--fmu", type=_path, default=None,
                   help="FMU to validate (default: dist/FrictionMount.fmu, built if "
                        "missing; any build, e.g. dist/FrictionMountNative.fmu)")
    p.add_argument("--out", type=_path, default=Path("validation"),
                   help="report folder")
    p.add_argument("--systems", nargs="+", default=None, metavar="NAME",
                   help="only these systems (sdof_friction, quarter_car_friction, "
                        "six_dof_friction, sdof_cubic)")
    p.add_argument("--inject", default=None, metavar="FIELD=FACTOR",
                   help="scale a mount-law field on the HBM side only "
                        "(proves that the check can fail), e.g. n0=1.5")


def _cmd_study(sub) -> None:
    """``drymount study``."""
    p = _add(sub, "study", "the thesis's design studies (Chapter 4)",
             """\
             normal-force  single DOF, transmissibility for a range of n0
                           (Figs. 4.1-4.4)
             optimize-n0   the n0 minimising peak or RMS transmissibility (Sec. 4.2)
             quarter-car   quarter car for a range of n0 (Figs. 4.6-4.9)
             six-dof       6-DOF responses, lambda 1 and 1.2, relocated mount
                           (Figs. 4.11-4.44)
             jump          cubic single DOF: unstable branch and the jump (Fig. 3.7)
             laws          single DOF with the thesis's linear, cubic and piecewise
                           fits at one excitation (Fig. 4.5)
             six-dof-75    6-DOF original mounts at 75 % with friction
                           (Figs. 4.45-4.50)
             incline       inclined friction surfaces (Ch. 5): theta, k, preload;
                           transmissibility and static deflection under the weight
             semi-active   passive vs controlled normal force (balance, skyhook,
                           scheduled, growth): unbalance, engine run-up and ISO
                           8608 road; single-DOF, quarter car, 6-DOF (co-simulation)
             hydraulic     original elastomer vs halved friction mount (best n0)
                           vs a linear hydraulic mount: transmissibility, |K*|,
                           loss angle and static sag in single-DOF, quarter car, 6-DOF
             Each writes CSV files, plots and summary.md into --out.""",
             ["drymount study normal-force --out study-nf",
              "drymount study jump --out jump --quick"])
    p.add_argument("name", metavar="NAME", choices=STUDY_NAMES,
                   help="one of " + ", ".join(STUDY_NAMES))
    p.add_argument("--out", type=_path, default=None,
                   help="output folder (default: study-NAME)")
    p.add_argument("--quick", action="store_true",
                   help="fewer designs and coarser curves (seconds instead of minutes)")


def _cmd_fit(sub) -> None:
    """``drymount fit``."""
    p = _add(sub, "fit", "mount-law parameters from rig data (CSV with units)",
             """\
             elastic  quasi-static force-deflection curve: fits linear, cubic,
                      symmetric and asymmetric piecewise laws, picks the lowest AIC
             loops    force-displacement loops of harmonic tests: kf, Fs and c
                      with the elastic law of --mount
             table    dynamic stiffness and loss angle vs frequency and amplitude:
                      kf, Fs and c with the elastic law of --mount
             Without --mount (or with --maxwell, --hydraulic, --fix, --fit-k1,
             --no-friction) a table or loop fit fits k1 too, with Maxwell branches
             or the hydraulic mount, and writes residuals.csv as well.
             Writes fit.csv (parameters, standard errors, R^2, AIC), fit.png and
             mount.toml (a [mount] table for a configuration) into --out. The CSV
             header gives every column's unit, e.g. `deflection [mm],force [N]`
             (docs/design-your-own-mount.md).""",
             ["drymount fit elastic examples/data/rig_piecewise.csv --out fit-el",
              "drymount fit loops examples/data/rig_loops.csv --mount sdof_halved"])
    p.add_argument("kind", metavar="KIND", choices=("elastic", "loops", "table"),
                   help="elastic, loops or table")
    p.add_argument("data", metavar="DATA", type=_path, help="the rig data (CSV)")
    p.add_argument("--law", default="auto",
                   choices=("auto", "linear", "cubic", "piecewise", "piecewise_asym"),
                   help="elastic: the law to write (default: lowest AIC)")
    p.add_argument("--c", type=_finite_float(0.0), default=None, metavar="N_S_PER_M",
                   help="elastic: viscous damping to write into mount.toml (a "
                        "quasi-static curve does not identify it; without --c it is "
                        "left out, marked unknown)")
    p.add_argument("--mount", default=None, metavar="TOML_OR_PRESET",
                   help="loops/table: the elastic law, from the [mount] table of a "
                        "file (e.g. the mount.toml of `fit elastic`) or a preset")
    p.add_argument("--fix-c", action="store_true",
                   help="loops/table: keep c of --mount instead of fitting it")
    # the frequency-dependent model (drymount/fit_dynamic.py); issue 28
    p.add_argument("--maxwell", type=int, default=0, metavar="N",
                   help="loops/table: N Maxwell branches (spring + damper in series) "
                        "in parallel, the rubber's frequency dependence")
    p.add_argument("--hydraulic", action="store_true",
                   help="loops/table: fit the hydraulic (inertia-track) mount; needs "
                        "--fix Ap=... and one of kr, C1, C2 fixed")
    p.add_argument("--decoupler", action="store_true",
                   help="with --hydraulic: the decoupler passage too")
    p.add_argument("--no-friction", dest="friction", action="store_false",
                   help="loops/table: no friction element in the model")
    p.add_argument("--fix", action="append", default=[], metavar="NAME=VALUE",
                   help="loops/table: hold a parameter (SI units), e.g. c=0; repeat")
    p.add_argument("--fit-k1", action="store_true",
                   help="loops/table: fit k1 of the --mount law too (without --mount "
                        "a linear law's k1 is always fitted)")
    p.add_argument("--out", type=_path, default=Path("fit"), help="output folder")
    p.add_argument("--no-plot", dest="plot", action="store_false",
                   help="do not draw fit.png")


def _cmd_characterise(sub) -> None:
    """``drymount characterise``."""
    p = _add(sub, "characterise", "dynamic stiffness and loss angle of the mounts",
             """\
             For every mount axis the model deflects: |K*| and loss angle vs
             frequency at several displacement amplitudes and static preloads,
             from harmonic balance with an imposed harmonic deflection (fundamental
             force / displacement amplitude), cross-checked at a few points in the
             time domain (through the FMU if fmpy is installed). Writes
             <mount>_<axis>.csv/.png and crosscheck.csv into --out; exit status 1
             if the cross-check fails.""",
             ["drymount characterise sdof_halved --preloads 0 686.7",
              "drymount characterise six_dof_halved --amplitudes-mm 0.2 1 3"])
    _config_arg(p)
    p.add_argument("--amplitudes-mm", type=_positive_float, nargs="+",
                   default=[0.1, 0.5, 1.0, 2.0], metavar="MM",
                   help="displacement amplitudes in mm")
    p.add_argument("--preloads", type=_finite_float(), nargs="+", default=[0.0],
                   metavar="N",
                   help="static preloads in N (e.g. the engine weight on the mount)")
    p.add_argument("--fmin", type=_positive_float, default=None,
                   help="lowest frequency, Hz (default: [sweep] fmin_hz)")
    p.add_argument("--fmax", type=_positive_float, default=None,
                   help="highest frequency, Hz (default: [sweep] fmax_hz)")
    from drymount.config import MAX_POINTS

    p.add_argument("--points", type=_int_at_least(2, MAX_POINTS), default=40,
                   help=f"frequencies, evenly spaced, 2..{MAX_POINTS}")
    p.add_argument("--check", choices=("auto", "fmu", "law"), default="auto",
                   help="time-domain cross-check: through the FMU (auto: if fmpy is "
                        "installed) or by marching the law")
    p.add_argument("--fmu", type=_path, default=None,
                   help="FMU for the cross-check (default: dist/FrictionMount.fmu, "
                        "built if missing)")
    p.add_argument("--out", type=_path, default=None,
                   help="output folder (default: <name>_characterise)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")


def _cmd_static(sub) -> None:
    """``drymount static``."""
    p = _add(sub, "static", "static working point under the engine's weight",
             """\
             Equilibrium of the configuration under gravity (and the [static]
             loads and --load) with the nonlinear elastic laws, friction sliders
             relaxed. Prints and writes the static deflection and force of every
             mount axis (CSV) and warns when an axis works past a knee of its law
             or beyond --travel-mm. With [static] gravity = true in the
             configuration, hbm, cosim and sweep run about this point.""",
             ["drymount static sdof_halved",
              "drymount static six_dof_halved --load beta=40 --travel-mm 15"])
    _config_arg(p)
    p.add_argument("--g", type=_positive_float, default=None,
                   help="gravitational acceleration, m/s^2, at most 1000 (default: "
                        "[static] g, else 9.81)")
    p.add_argument("--no-gravity", action="store_true", help="only the --load terms")
    p.add_argument("--load", action="append", default=None, metavar="DOF=VALUE",
                   help="static generalised load on a DOF, N or N m, within +-1e9 "
                        "(repeatable)")
    p.add_argument("--travel-mm", type=_positive_float, default=None,
                   help="warn when a mount axis deflects more than this, mm")
    p.add_argument("--out", type=_path, default=None,
                   help="CSV file (default: <name>_static.csv)")


def _cmd_demo(sub) -> None:
    """``drymount demo``."""
    p = _add(sub, "demo", "the first-hour demo: FMU, HBM, co-simulation, report",
             """\
             Builds the FMU, computes the HBM curve of the friction-damped quarter car
             against the original mount, co-simulates a few frequencies through the FMU
             and writes demo.md with plots and CSV files. About 10 s on 2 cores
             (8-10 s measured on an idle machine, the FMU build included; up to
             30 s on a loaded one).""",
             ["drymount demo", "drymount demo --out /tmp/demo"])
    p.add_argument("--out", type=_path, default=Path("demo"), help="report folder")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress output")


#: The subcommands in the order of ``drymount --help`` (explore and optimize follow,
#: from drymount.design.commands).
_COMMANDS = (_cmd_presets, _cmd_build_fmu, _cmd_export_ssp, _cmd_export_xc, _cmd_hbm,
             _cmd_cosim, _cmd_sweep, _cmd_validate, _cmd_study, _cmd_fit,
             _cmd_characterise, _cmd_static, _cmd_demo)


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
            "drymount sweep sdof_halved --points 20 --backend inproc --hbm curve.csv "
            "--plot sweep.png",
            "drymount build-fmu --out FrictionMount.fmu",
        ) + "\n\nexit status: 0 success, 1 numerical failure, 2 bad usage or "
            "configuration (before computing), 130 Ctrl-C, 143 SIGTERM; after 1, 130 "
            "or 143 what was computed is written, first line '# partial: <reason>' "
            "(docs/cli.md)",
        formatter_class=_Formatter)
    parser.add_argument("--version", action=_VersionAction)
    parser.add_argument("--traceback", action="store_true",
                        help="show the Python traceback of an unexpected error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in _COMMANDS:
        add(sub)
    # explore, optimize (drymount.design)
    from drymount.design.commands import add_commands

    add_commands(sub, _add, _config_arg, _int_at_least)
    # modes (drymount.modes_cmd)
    from drymount.modes_cmd import add_command as add_modes

    add_modes(sub, _add, _config_arg, _int_at_least, _positive_float, _path,
              harmonics_arg=_harmonics_arg)
    return parser
