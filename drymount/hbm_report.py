"""What ``drymount hbm`` prints and draws beside its curve: the located peak, sweep
jumps and bifurcations of the summary, the error estimate, the backbone file and plot
(split from :mod:`drymount.cli`, which parses and dispatches)."""

from __future__ import annotations

from drymount.cli_guard import _info, partial_on_stop, write_with

_write_with = write_with


def _peak_text(name: str, freq_hz, transmissibility) -> str:
    """``"<name>: peak transmissibility T at F Hz"`` ("" without a finite value) of
    the largest row (a stepped sweep's)."""
    import numpy as np

    t = np.asarray(transmissibility, dtype=float)
    if not np.any(np.isfinite(t)):
        return ""
    i = int(np.nanargmax(t))
    return _peak_line(name, float(freq_hz[i]), float(t[i]))


def _peak_line(name: str, freq_hz: float, value: float) -> str:
    """The one format every command prints a peak transmissibility in."""
    return f"{name}: peak transmissibility {value:.4g} at {freq_hz:.4g} Hz"


def _write_backbone(cfg, fr, opts, path):
    """The backbones of the modes near the band (:mod:`drymount.backbone`), written
    to ``path``; None (with a note) when there is none to trace."""
    from drymount.backbone import backbones

    try:
        with partial_on_stop(path, "backbone points"):
            modes = backbones(cfg.system, fr, opts)
    except ValueError as exc:
        _info(f"no backbone: {exc}")
        return None
    _write_with(path, modes.to_csv)
    _info(f"wrote {path} (backbones of mode(s) "
          f"{', '.join(f'{m.index} ({m.label})' for m in modes.modes)})")
    return modes


def _plot_hbm(fr, path, logx: bool, modes) -> None:
    if modes is None:
        fr.plot(path=path, logx=logx)
        return
    from drymount.hbm.plot import plot_figure

    plot_figure(fr, path, logx=logx, backbones=modes)


#: What each bifurcation kind (hbm.bifurcation) means for the steady state.
_BIFURCATION_TEXT = {
    "period-doubling": ("period doubling (a Floquet multiplier through -1)",
                        "a motion of twice the period (or a cascade towards chaos)"),
    "neimark-sacker": ("Neimark-Sacker bifurcation (a complex pair of Floquet "
                       "multipliers through the unit circle)",
                       "a quasi-periodic motion with a second frequency"),
    "branch-point": ("branch point (a Floquet multiplier through +1 where the curve "
                     "does not turn)", "another periodic solution, which this curve "
                     "does not contain"),
}


def _print_bifurcations(fr, config: str) -> None:
    """One line per located bifurcation that is not a fold, with what it means and
    where the co-simulation shows the steady state the HBM cannot."""
    for e in getattr(fr, "bifurcations", []):
        what, instead = _BIFURCATION_TEXT[e.kind]
        mu = "" if e.multiplier is None else f", multiplier {_complex(e.multiplier)}"
        near = _unstable_frequency(fr, e)
        print(f"  {what} at {e.freq_hz:.6f} Hz{mu}: on the unstable side the steady "
              f"state is not this periodic solution but {instead}; `drymount cosim "
              f"{config} --freq {near:.4g}` shows what happens instead")


def _complex(z: complex) -> str:
    return f"{z.real:.3g}" if abs(z.imag) < 1e-9 * abs(z) else \
        f"{z.real:.3g}{z.imag:+.3g}i"


def _unstable_frequency(fr, e) -> float:
    """A curve frequency on the unstable side of the bifurcation ``e``."""
    import numpy as np

    st = np.asarray(fr.stable, bool)
    i = min(max(e.index, 1), len(st) - 1)
    return float(fr.freq_hz[i] if not st[i] else fr.freq_hz[i - 1])


def _print_hbm_summary(name: str, fr) -> None:
    """The located transmissibility peak, turning and unstable points, sweep jumps."""
    if not len(fr.freq_hz):
        return
    import numpy as np

    f_peak, t_peak = fr.transmissibility_max()  # located, as the DOF peaks
    if t_peak != t_peak:
        return
    print(f"{_peak_line(name, f_peak, t_peak)}; {len(fr.turning_points)} turning "
          f"point(s); {int(np.sum(~np.asarray(fr.stable, bool)))} unstable point(s)")
    for direction in ("up", "down"):
        jumps = [f"jumps at {f:.4g} Hz" if k >= 0 else
                 f"leaves the curve at {f:.4g} Hz (stability lost "
                 f"without a fold)" for f, _, k in fr.sweep_jumps(direction)]
        if jumps:
            print(f"  a slow sweep {direction} " + "; then ".join(jumps))


def _print_hbm_accuracy(fr) -> None:
    """Error estimate, merged turning points, folds and peaks of an HBM curve."""
    e = fr.error_max()
    if e == e:
        verdict = {True: "meets", False: "misses", None: "vs"}[fr.tol_met]
        print(f"  error estimate {e:.2g} of peak ({fr.error_reference}); {verdict} "
              f"the tolerance")
    if fr.tol_met is False:
        _info(f"drymount: warning: the tolerance is not met: {fr.message}")
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
