"""``drymount fit``: a mount law from rig data (CSV in; CSV, plot and TOML out).

Three kinds of data (units in the CSV header, see :mod:`drymount.rigdata`):

- ``elastic DATA``: quasi-static force-deflection curve -> linear, cubic, symmetric
  and asymmetric piecewise laws fitted (:func:`hbm.identify.compare_elastic`), the law
  with the lowest AIC chosen unless ``--law`` names one;
- ``loops DATA --mount M``: force-displacement loops of harmonic tests -> kf, Fs and
  c with the elastic law of ``M`` (:func:`hbm.identify.fit_loops`);
- ``table DATA --mount M``: dynamic stiffness and loss angle vs frequency and
  amplitude -> kf, Fs and c (:func:`hbm.identify.fit_dynamic_stiffness`).

Writes into ``--out``: ``fit.csv`` (every parameter with its standard error, R^2,
AIC), a plot of data and fits, and ``mount.toml``, a ``[mount]`` table that the
configuration loader accepts (paste it into a ``model = "sdof"`` or ``"quarter_car"``
configuration, or give it to ``--mount`` of the next fit).

Without ``--mount``, or with ``--maxwell``, ``--hydraulic``, ``--fix``, ``--fit-k1``
or ``--no-friction``, ``drymount fit table|loops`` runs :mod:`drymount.fit_dynamic`
instead (``drymount.cli.cmd_fit`` picks it): the elastic
stiffness fitted with friction, damper and Maxwell branches (or the hydraulic mount)
over every frequency and amplitude at once.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from drymount.io import atomic_write_text, save_figure, write_csv
from drymount.fmu_src.mount_law import AxisParameters
from drymount.hbm.identify import (FIT_LAWS, UNITS, DataError, FitStatus,
                                   compare_elastic, fit_dynamic_stiffness, fit_loops,
                                   law_force, loop_model)

__all__ = ["main", "mount_toml", "resolve_mount"]

KINDS = ("elastic", "loops", "table")


def resolve_mount(spec, need_c: bool = True) -> AxisParameters:
    """The ``[mount]`` law of a TOML file (fragment or configuration) or a preset.

    ``need_c=False`` (a fit that identifies c) accepts a table without ``c`` (the
    ``mount.toml`` of ``fit elastic`` without ``--c``) and takes c = 0 for it."""
    from drymount.config import ConfigError, list_presets, mount_from_table, preset_text
    from drymount.config.loading import parse_toml

    path = Path(spec)
    if path.is_file():
        text, source = path.read_text(encoding="utf-8"), str(path)
    elif str(spec) in list_presets():
        text, source = preset_text(str(spec)), f"preset:{spec}"
    else:
        raise ConfigError([f"--mount {spec!r} is neither a file nor a preset "
                           f"({', '.join(list_presets())})"], "--mount")
    data = parse_toml(text, source)
    if not isinstance(data.get("mount"), dict):
        raise ConfigError(["no [mount] table (a `drymount fit elastic` fragment or a "
                           "single-mount configuration is needed)"], source)
    table = data["mount"]
    if not need_c and "c" not in table:
        table = {**table, "c": 0.0}  # not used: the fit identifies c
    return mount_from_table(table, source)


def _num(x: float) -> str:
    """A TOML float (always with a decimal point or an exponent)."""
    text = f"{x:.10g}"
    return text if any(ch in text for ch in ".e") else text + ".0"


def mount_toml(axis: AxisParameters, header: str, stderr: dict,
               notes: dict | None = None, c_known: bool = True,
               maxwell: tuple = ()) -> str:
    """``[mount]`` (and ``[mount.friction]``, ``[mount.maxwell]``) TOML text of
    ``axis`` with comments; ``c_known=False`` leaves c out (a comment says it is
    unknown and how to set it). ``maxwell``: ``(k, c)`` of each Maxwell branch, their
    standard errors in ``stderr`` as ``maxwell<i>_k`` / ``maxwell<i>_c``."""
    notes = notes or {}
    used = {"linear": ("k1",), "cubic": ("k1", "kc"),
            "piecewise": ("k1", "k2", "delta"),
            "piecewise_asym": ("k1", "k2", "delta", "delta_neg")}[axis.law]

    def line(name, value, unit):
        se = stderr.get(name)
        text = f"{name} = {_num(value)}"
        note = f"  # {unit}"
        if se is not None and se > 0:
            note += f", standard error {se:.3g} ({se / abs(value):.2%})"
        if name in notes:
            note += f"; {notes[name]}"
        return f"{text:<28}{note}"

    out = [f"# {h}" for h in header.splitlines()] + ["[mount]", f'law = "{axis.law}"']
    out += [line(n, getattr(axis, n), UNITS[n]) for n in used]
    out.append(line("c", axis.c, UNITS["c"]) if c_known else
               "# c (N s/m) unknown: a quasi-static curve does not identify it; add "
               "`c = ...` here\n# (or rerun with --c) or fit it from loops (`drymount "
               "fit loops DATA --mount this file`)")
    if axis.friction:
        out += ["", "[mount.friction]",
                "# macro-slip (Jenkins) element; mu = 1 makes n0 the slip force Fs",
                line("kf", axis.kf, UNITS["kf"]), "mu = 1.0",
                f"{'n0 = ' + _num(axis.fs):<28}  # N (= Fs)"
                + (f", standard error {stderr['fs']:.3g} "
                   f"({stderr['fs'] / axis.fs:.2%})" if stderr.get("fs") else "")]
    if maxwell:
        out += ["", "[mount.maxwell]", _maxwell_line("k", maxwell, stderr, "N/m"),
                _maxwell_line("c", maxwell, stderr, "N s/m")]
    return "\n".join(out) + "\n"


def _maxwell_line(q: str, branches: tuple, stderr: dict, unit: str) -> str:
    """``k = [...]`` or ``c = [...]`` of the Maxwell branches with a comment."""
    i = 0 if q == "k" else 1
    values = ", ".join(_num(b[i]) for b in branches)
    se = [stderr.get(f"maxwell{n}_{q}") for n in range(1, len(branches) + 1)]
    note = f"  # {unit}"
    if all(s is not None and s > 0 for s in se):
        note += ", standard errors " + ", ".join(
            f"{s:.3g} ({s / abs(b[i]):.2%})" for s, b in zip(se, branches))
    return f"{q} = [{values}]{note}"


def _fits_csv(path: Path, fits, chosen, source: str) -> None:
    rows = [(f.model, "yes" if f is chosen else "no", name, value, f.stderr[name],
             UNITS[name], f.r2, f.aic, f.n, f.status.value)
            for f in fits for name, value in f.params.items()]
    write_csv(path, ["model", "chosen", "parameter", "value", "stderr", "unit", "r2",
                     "aic", "n", "status"], rows,
              comment=f"drymount fit of {source}; value and stderr in `unit`; "
                      f"aic = n ln(RSS/n) + 2 p")


def _summary(f, chosen=None) -> str:
    mark = " *" if f is chosen else "  "
    ps = ", ".join(f"{k} = {v:.6g} +- {f.stderr[k]:.2g} {UNITS[k]}"
                   for k, v in f.params.items())
    bad = "" if f.status is FitStatus.CONVERGED else f" [{f.status.value}: {f.message}]"
    return f"  {f.model:<15}{mark} AIC {f.aic:10.2f}  R^2 {f.r2:.6f}  {ps}{bad}"


def _figure(nrows=1, ncols=1, size=(7.5, 4.8)):
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    return fig, fig.subplots(nrows, ncols, squeeze=False)


def _plot_curve(path: Path, u, F, cmp, chosen, source: str) -> None:
    fig, ax = _figure()
    ax = ax[0, 0]
    ax.plot(u * 1e3, F, ".", ms=3, color="0.4", label="data")
    uu = np.linspace(u.min(), u.max(), 400)
    for f in cmp.fits:
        ax.plot(uu * 1e3, law_force(uu, f.model, f.params),
                lw=2.2 if f is chosen else 1.0,
                label=f"{f.model} (AIC {f.aic:.0f}{', chosen' if f is chosen else ''})")
    ax.set(xlabel="deflection [mm]", ylabel="force [N]",
           title=f"Elastic law fitted to {Path(source).name}")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)


def _plot_loops(path: Path, tests, elastic, fit, source: str) -> None:
    n = len(tests)
    ncols = min(n, 2)
    fig, axs = _figure((n + ncols - 1) // ncols, ncols, (8.0, 3.2 * ((n + 1) // 2)))
    p = fit.params
    for ax, t in zip(axs.ravel(), tests, strict=False):
        model = loop_model(t, elastic, p["kf"], p["fs"], p["c"])
        ax.plot(t.deflection * 1e3, t.force, ".", ms=2, color="0.5", label="data")
        order = np.r_[np.arange(t.force.size), 0]
        ax.plot(t.deflection[order] * 1e3, model[order], lw=1.2, label="fit")
        ax.set(xlabel="deflection [mm]", ylabel="force [N]",
               title=f"{t.label} ({t.freq_hz:.4g} Hz)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    for ax in axs.ravel()[n:]:
        ax.set_visible(False)
    fig.suptitle(f"Force-displacement loops of {Path(source).name}: kf = "
                 f"{p['kf']:.4g} N/m, Fs = {p['fs']:.4g} N, c = {p['c']:.4g} N s/m")
    save_figure(fig, path)


def _plot_table(path: Path, points, axis: AxisParameters, source: str) -> None:
    from drymount.hbm.characterise import dynamic_stiffness

    fig, axs = _figure(1, 2, (10.0, 4.2))
    amps = sorted({p.amplitude for p in points})
    f_all = [p.freq_hz for p in points]
    ff = np.geomspace(min(f_all), max(f_all), 60)
    m = dynamic_stiffness(axis, ff, amps)
    for j, X in enumerate(amps):
        pts = [p for p in points if p.amplitude == X]
        line, = axs[0, 0].plot(ff, m.magnitude[0, j], label=f"X = {X * 1e3:g} mm")
        axs[0, 0].plot([p.freq_hz for p in pts], [p.magnitude for p in pts], "o",
                       color=line.get_color(), ms=4)
        axs[0, 1].plot(ff, m.loss_angle_deg[0, j], color=line.get_color())
        axs[0, 1].plot([p.freq_hz for p in pts], [p.loss_angle_deg for p in pts], "o",
                       color=line.get_color(), ms=4)
    axs[0, 0].set(xscale="log", xlabel="frequency [Hz]", ylabel="|K*| [N/m]",
                  title="Dynamic stiffness (markers: data, lines: fit)")
    axs[0, 1].set(xscale="log", xlabel="frequency [Hz]", ylabel="loss angle [deg]",
                  title="Loss angle")
    for a in axs.ravel():
        a.grid(alpha=0.3, which="both")
    axs[0, 0].legend(fontsize=8)
    fig.suptitle(f"Dynamic-stiffness table {Path(source).name}")
    save_figure(fig, path)


def _elastic(args, out: Path) -> AxisParameters:
    from drymount.rigdata import read_curve

    u, F = read_curve(args.data)
    _check_curve(args.data, u, F)
    n_read = u.size
    binned = n_read > MAX_FIT_POINTS
    if binned:
        u, F = bin_means(u, F, MAX_FIT_POINTS)
        lo, hi = n_read // u.size, -(-n_read // u.size)
        print(f"{args.data}: {n_read} points binned to {u.size} means of "
              f"{lo if lo == hi else f'{lo}-{hi}'} consecutive points (more "
              f"than {MAX_FIT_POINTS}: R^2 and AIC below are of the means; the "
              f"parameters and their standard errors estimate those of all points)")
    cmp = compare_elastic(u, F, laws=_law_bar(binned))
    chosen = cmp.best if args.law == "auto" else next(f for f in cmp.fits
                                                      if f.model == args.law)
    print(f"{args.data}: {u.size} {'bin means' if binned else 'points'}, laws fitted "
          f"(* = {'lowest AIC' if args.law == 'auto' else '--law'}):")
    for f in cmp.fits:
        print(_summary(f, chosen))
    _fits_csv(out / "fit.csv", cmp.fits, chosen, str(args.data))
    if args.plot:
        _plot_curve(out / "fit.png", u, F, cmp, chosen, str(args.data))
    c_known = args.c is not None
    axis = AxisParameters(law=chosen.model, c=args.c if c_known else 0.0,
                          **chosen.params)
    why = "lowest AIC" if args.law == "auto" else "chosen with --law"
    header = (f"Fitted by `drymount fit elastic {args.data}`: law {chosen.model} "
              f"({why}), R^2 = {chosen.r2:.6f}, AIC = {chosen.aic:.2f}")
    text = mount_toml(axis, header, chosen.stderr, notes={
        "c": "not identified by a quasi-static curve (--c); fit it from loops"},
        c_known=c_known)
    atomic_write_text(out / "mount.toml", text)
    return axis


#: Most points an elastic fit uses: a longer curve is replaced by the means of
#: equal runs of consecutive points (the knee search costs points x 6400 pairs).
MAX_FIT_POINTS = 5000


def bin_means(u: np.ndarray, F: np.ndarray,
              n_bins: int) -> tuple[np.ndarray, np.ndarray]:
    """Means of ``u`` and ``F`` over ``n_bins`` runs of consecutive points whose
    lengths differ by at most one (a monotonic curve stays monotonic)."""
    starts = np.linspace(0, u.size, n_bins + 1).astype(int)
    counts = np.diff(starts)
    return (np.add.reduceat(u, starts[:-1]) / counts,
            np.add.reduceat(F, starts[:-1]) / counts)


def _law_bar(show: bool):
    """The laws to fit, through a progress bar on stderr for a large curve."""
    if not show:
        return FIT_LAWS
    from tqdm import tqdm

    return tqdm(FIT_LAWS, desc="fit elastic", unit="law", file=sys.stderr)


#: Ranges of a mount's quasi-static curve that a fit can resolve: deflections span
#: at least a micrometre and stay within a metre, forces within a meganewton.
MIN_SPAN_M, MAX_DEFLECTION_M, MAX_FORCE_N = 1e-6, 1.0, 1e6


def _check_curve(path, u, F) -> None:
    """DataError (before fitting) for a curve no law can be fitted to."""
    problems = []
    if u.size < 3:
        problems.append(f"{path}: {u.size} points; a fit needs at least 3")
    if u.size and np.ptp(u) < MIN_SPAN_M:
        problems.append(f"{path}: the deflections span {np.ptp(u):.3g} m; at least "
                        f"{MIN_SPAN_M:g} m is needed (is the unit in the header "
                        f"right?)")
    if u.size and np.ptp(F) == 0:
        problems.append(f"{path}: the force is constant ({F[0]:g} N): no stiffness "
                        f"can be fitted")
    if u.size and np.max(np.abs(u)) > MAX_DEFLECTION_M:
        problems.append(f"{path}: a deflection of {np.max(np.abs(u)):.3g} m; at most "
                        f"{MAX_DEFLECTION_M:g} m (is the unit in the header right?)")
    if u.size and np.max(np.abs(F)) > MAX_FORCE_N:
        problems.append(f"{path}: a force of {np.max(np.abs(F)):.3g} N; at most "
                        f"{MAX_FORCE_N:g} N (is the unit in the header right?)")
    if problems:
        raise DataError(problems)


def _friction(args, out: Path) -> AxisParameters:
    from drymount.rigdata import read_loops, read_stiffness_table

    elastic = resolve_mount(args.mount, need_c=args.fix_c)
    if args.kind == "loops":
        data = read_loops(args.data)
        fit = fit_loops(data, elastic, fit_c=not args.fix_c)
        n = sum(t.force.size for t in data)
        print(f"{args.data}: {len(data)} tests, {n} samples; elastic law from "
              f"{args.mount} ({elastic.law}, k1 = {elastic.k1:.6g} N/m)")
    else:
        data = read_stiffness_table(args.data)
        fit = fit_dynamic_stiffness(data, elastic, fit_c=not args.fix_c)
        print(f"{args.data}: {len(data)} rows; elastic law from {args.mount} "
              f"({elastic.law}, k1 = {elastic.k1:.6g} N/m)")
    print(_summary(fit))
    _fits_csv(out / "fit.csv", [fit], fit, str(args.data))
    p = fit.params
    axis = replace(elastic, c=p["c"], friction=True, kf=p["kf"], mu=1.0, n0=p["fs"])
    if args.plot:
        if args.kind == "loops":
            _plot_loops(out / "fit.png", data, elastic, fit, str(args.data))
        else:
            _plot_table(out / "fit.png", data, axis, str(args.data))
    header = (f"Fitted by `drymount fit {args.kind} {args.data} --mount {args.mount}`: "
              f"R^2 = {fit.r2:.6f}\nelastic law from {args.mount}"
              + ("; c kept from it (--fix-c)" if args.fix_c else ""))
    atomic_write_text(out / "mount.toml", mount_toml(axis, header, fit.stderr))
    if fit.status is not FitStatus.CONVERGED:
        print(f"drymount: error: the fit did not converge: {fit.message}",
              file=sys.stderr)
    return axis


def _usage(message: str) -> int:
    """Report bad usage or data; the exit status 2 of ``drymount.cli``."""
    print(f"drymount: error: {message}", file=sys.stderr)
    return 2


def main(args) -> int:
    """Run ``drymount fit`` (see the module docstring); return the exit status."""
    if args.kind in ("loops", "table") and args.mount is None:
        return _usage(f"`drymount fit {args.kind}` here needs --mount: the elastic law "
                      f"(without it `drymount fit` runs drymount.fit_dynamic, which "
                      f"fits k1 too)")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    try:
        (_elastic if args.kind == "elastic" else _friction)(args, out)
    except DataError as exc:
        return _usage(f"bad data: {exc}")
    print(f"wrote {out / 'fit.csv'}, {out / 'mount.toml'}"
          + (f", {out / 'fit.png'}" if args.plot else ""))
    return 0


__all__ += ["KINDS", "FIT_LAWS"]
