"""``drymount fit table|loops`` with a frequency-dependent model (issue 28, item 4).

The model (:mod:`hbm.rig_fit`): elastic + macro-slip (Jenkins) + damper + ``--maxwell
N`` Maxwell branches, or ``--hydraulic`` (the inertia-track mount, ``--decoupler``),
fitted over the whole table or every loop at once, with the elastic stiffness k1
fitted too (``--mount`` gives the law's shape and, without ``--fit-k1``, its k1).
``--fix NAME=VALUE`` holds parameters; ``--no-friction`` leaves the Jenkins element
out. ``drymount.cli.cmd_fit`` sends a table or loop fit here when any of these is asked
for, or when ``--mount`` is not given.

Writes into ``--out``: ``fit.csv`` (every parameter, standard error, unit, fixed or
fitted, R^2, AIC), ``residuals.csv`` (per row of the table, or per loop: measured and
fitted |K*| and loss angle, the residuals), ``fit.png`` (measured and fitted |K*|
and loss angle over frequency, one line per amplitude) and, for a model the
configuration has (up to three Maxwell branches, not hydraulic), ``mount.toml``.
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from drymount.hbm.identify import DataError, FitStatus
from drymount.hbm.rig_fit import (RigModel, check_model, complex_stiffness,
                                  fit_loops, fit_table, loop_fundamental,
                                  loop_residuals, table_residuals, unit)
from drymount.io import atomic_write_text, save_figure, write_csv

#: The configuration's ``[mount.maxwell]`` holds at most this many branches (the FMU
#: has three per axis).
MAX_CONFIG_BRANCHES = 3

__all__ = ["wanted", "parse_fixed", "build_model", "main"]


def wanted(args) -> bool:
    """Whether a table or loop fit asks for this module's model."""
    return (getattr(args, "mount", None) is None or getattr(args, "maxwell", 0) > 0
            or getattr(args, "hydraulic", False) or bool(getattr(args, "fix", None))
            or getattr(args, "fit_k1", False) or not getattr(args, "friction", True)
            or getattr(args, "decoupler", False))


def parse_fixed(items) -> dict:
    """``{name: value}`` of ``--fix NAME=VALUE`` items (ValueError naming the item)."""
    out = {}
    for item in items or ():
        name, sep, text = str(item).partition("=")
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not sep or not name.strip() or not math.isfinite(value):
            raise ValueError(f"--fix {item!r}: must be NAME=VALUE with a finite number "
                             f"in SI units, e.g. --fix c=0 or --fix Ap=0.003")
        out[name.strip()] = value
    return out


def build_model(args) -> RigModel:
    """The :class:`hbm.rig_fit.RigModel` the arguments ask for (ValueError if bad)."""
    fixed = parse_fixed(getattr(args, "fix", None))
    elastic = None
    if args.hydraulic:
        if args.maxwell or args.mount is not None or args.fit_k1:
            raise ValueError("--hydraulic is a model of its own: --maxwell, --mount "
                             "and --fit-k1 are for the elastomer (rubber) model")
    elif args.decoupler:
        raise ValueError("--decoupler needs --hydraulic")
    if args.mount is not None and not args.hydraulic:
        from drymount.fit import resolve_mount

        elastic = resolve_mount(args.mount, need_c=args.fix_c)
        if not args.fit_k1:
            fixed.setdefault("k1", elastic.k1)
        if args.fix_c:
            fixed.setdefault("c", elastic.c)
    elif args.fix_c:
        raise ValueError("--fix-c keeps c of --mount; without --mount write "
                         "--fix c=VALUE")
    elif args.fit_k1:
        raise ValueError("--fit-k1 refits k1 of the --mount law; without --mount k1 is "
                         "always fitted (the linear law)")
    return check_model(RigModel(kind="hydraulic" if args.hydraulic else "rubber",
                                maxwell=int(args.maxwell), friction=args.friction,
                                decoupler=args.decoupler, elastic=elastic,
                                fixed=fixed))


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def _print_fit(fit, source: str, what: str) -> None:
    print(f"{source}: {what}; model {fit.rig.label}")
    for name, v in fit.params.items():
        if name in fit.rig.fixed:
            print(f"  {name:<12} = {_fmt(v):>12} {unit(name):<8} (fixed)")
        else:
            se = fit.stderr[name]
            rel = f"{se / abs(v):.2%}" if v else "-"
            print(f"  {name:<12} = {_fmt(v):>12} {unit(name):<8} +- {se:.3g} ({rel})")
    print(f"  R^2 {fit.r2:.6f}, AIC {fit.aic:.2f}, residual sd {fit.sigma:.3g} "
          f"{fit.residual_unit}, {fit.n} residuals, {fit.status.value}")


def _fit_csv(path: Path, fit, source: str) -> None:
    rows = [(fit.rig.label, name, v, fit.stderr[name], unit(name),
             "fixed" if name in fit.rig.fixed else "fitted", fit.r2, fit.aic, fit.n,
             fit.sigma, fit.status.value) for name, v in fit.params.items()]
    write_csv(path, ["model", "parameter", "value", "stderr", "unit", "how", "r2",
                     "aic", "n", "residual_sd", "status"], rows,
              comment=f"drymount fit of {source}; value and stderr in `unit` (stderr "
                      f"from the Jacobian at the optimum scaled by the residual "
                      f"variance); residual_sd in {fit.residual_unit}")


def _residual_csv(path: Path, rows: list[dict], source: str, loops: bool) -> None:
    units = {"freq_hz": "Hz", "amplitude_m": "m", "stiffness_measured": "N/m",
             "stiffness_fitted": "N/m", "stiffness_rel_error": "1",
             "loss_angle_measured": "deg", "loss_angle_fitted": "deg",
             "loss_angle_error": "deg", "residual_real": "1", "residual_imag": "1",
             "rms_residual_N": "N", "rms_residual_rel": "1"}
    head = list(rows[0])
    write_csv(path, head, [[r[h] for h in head] for r in rows],
              comment=f"residuals of the fit of {source} per "
                      f"{'loop (fundamentals of the force)' if loops else 'row'}: "
                      + ", ".join(f"{h} [{units[h]}]" for h in head if h in units))


def _plot(path: Path, fit, freq, amp, K, source: str, loops: bool) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 4.4), layout="constrained")
    ax_k, ax_d = fig.subplots(1, 2)
    ff = np.geomspace(freq.min(), freq.max(), 200)
    # measured amplitudes (loops) scatter: one line per amplitude to 2 digits
    nominal = np.array([float(f"{x:.2g}") for x in amp])
    for j, Xn in enumerate(sorted(set(nominal.tolist()))):
        sel = nominal == Xn
        X = float(np.mean(amp[sel]))
        Kf = complex_stiffness(fit.rig, fit.params, ff, X)
        line, = ax_k.plot(ff, np.abs(Kf), color=f"C{j % 10}",
                          label=f"X = {Xn * 1e3:g} mm")
        ax_d.plot(ff, np.degrees(np.angle(Kf)), color=line.get_color())
        ax_k.plot(freq[sel], np.abs(K[sel]), "o", ms=4, color=line.get_color())
        ax_d.plot(freq[sel], np.degrees(np.angle(K[sel])), "o", ms=4,
                  color=line.get_color())
    what = "loop fundamentals" if loops else "data"
    ax_k.set(xscale="log", yscale="log", xlabel="frequency [Hz]",
             ylabel="dynamic stiffness |K*| [N/m]",
             title=f"|K*|: markers {what}, lines fit")
    ax_d.set(xscale="log", xlabel="frequency [Hz]", ylabel="loss angle [deg]",
             title=f"Loss angle: markers {what}, lines fit")
    for a in (ax_k, ax_d):
        a.grid(alpha=0.3, which="both")
    ax_k.legend(fontsize=8)
    fig.suptitle(f"{fit.rig.label} fitted to {Path(source).name} (R^2 = {fit.r2:.5f})")
    save_figure(fig, path)


def _mount_toml(fit, args) -> str | None:
    """The ``[mount]`` TOML of a fit the configuration can hold, else None."""
    rig = fit.rig
    if rig.kind != "rubber" or rig.maxwell > MAX_CONFIG_BRANCHES:
        return None
    from drymount.fit import mount_toml
    from drymount.fmu_src.mount_law import AxisParameters

    p = fit.params
    base = rig.elastic if rig.elastic is not None else AxisParameters(law="linear")
    axis = replace(base, k1=p["k1"], c=p["c"], friction=rig.friction,
                   **({"kf": p["kf"], "mu": 1.0, "n0": p["fs"]} if rig.friction
                      else {}))
    header = (f"Fitted by `drymount fit {args.kind} {args.data}`: model {rig.label}, "
              f"R^2 = {fit.r2:.6f}")
    branches = tuple((p[f"maxwell{i}_k"], p[f"maxwell{i}_c"])
                     for i in range(1, rig.maxwell + 1))
    return mount_toml(axis, header, {k: v for k, v in fit.stderr.items() if v > 0},
                      maxwell=branches)


def main(args) -> int:
    """Run the fit (arguments of ``drymount fit``); the exit status."""
    from drymount.rigdata import read_loops, read_stiffness_table

    try:
        model = build_model(args)
    except ValueError as exc:
        print(f"drymount: error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    src = str(args.data)
    try:
        if args.kind == "loops":
            data = read_loops(args.data)
            fit = fit_loops(data, model)
            freq = np.array([t.freq_hz for t in data])
            amp = np.array([t.amplitude for t in data])
            K = np.array([loop_fundamental(t) for t in data])
            rows = loop_residuals(fit, data)
            what = (f"{len(data)} loops, {sum(t.force.size for t in data)} samples, "
                    f"{freq.min():.4g}-{freq.max():.4g} Hz")
        else:
            data = read_stiffness_table(args.data)
            fit = fit_table(data, model)
            freq = np.array([p.freq_hz for p in data])
            amp = np.array([p.amplitude for p in data])
            K = np.array([p.K for p in data])
            rows = table_residuals(fit, data)
            n_amp = len(set(amp.tolist()))
            what = (f"{len(data)} rows, {freq.min():.4g}-{freq.max():.4g} Hz, "
                    f"{n_amp} amplitude{'' if n_amp == 1 else 's'}")
    except DataError as exc:
        print(f"drymount: error: bad data: {exc}", file=sys.stderr)
        return 2
    _print_fit(fit, src, what)
    _fit_csv(out / "fit.csv", fit, src)
    _residual_csv(out / "residuals.csv", rows, src, args.kind == "loops")
    written = [out / "fit.csv", out / "residuals.csv"]
    if args.plot:
        _plot(out / "fit.png", fit, freq, amp, K, src, args.kind == "loops")
        written.append(out / "fit.png")
    text = _mount_toml(fit, args)
    if text is not None:
        atomic_write_text(out / "mount.toml", text)
        written.append(out / "mount.toml")
    print("wrote " + ", ".join(str(p) for p in written))
    if text is None:
        print("  (no mount.toml: the configuration has "
              + ("no hydraulic mount in this build" if model.kind == "hydraulic" else
                 f"at most {MAX_CONFIG_BRANCHES} Maxwell branches per axis")
              + "; the parameters are in fit.csv)")
    if fit.status is not FitStatus.CONVERGED:
        print(f"drymount: error: the fit did not converge: {fit.message}",
              file=sys.stderr)
        return 1
    return 0
