"""Figures of a :class:`hbm.result.FrequencyResponse` that explain themselves.

:func:`plot_curve` draws one quantity on one set of axes (unstable parts dashed,
located folds marked, predicted sweep jumps as arrows); :func:`plot_figure` makes the
figure of ``drymount hbm --plot``: titled with the system and H/N, the
transmissibility (its definition in the y label) and, for a multi-DOF system, one
panel per DOF with its fundamental amplitude (as the thesis's Figs. 4.11-4.16).
Where a surface of an inclined element sticks for the whole period the band is
shaded grey (:func:`shade_family`): the curve there is one member of a family.
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["plot_curve", "plot_figure", "dof_unit", "title", "plain_log_ticks",
           "shade_family"]

#: DOF names measured in rad (rotations of the rigid engine); the others in m.
ROTATIONS = ("alpha", "beta", "gamma", "phi", "theta", "psi")


def dof_unit(name: str) -> str:
    return "rad" if name in ROTATIONS else "m"


def plain_log_ticks(ax) -> None:
    """Plain tick labels (``6``, ``0.02``, ``1e-05``) on the log axes of ``ax``, not
    Matplotlib's ``6x10^0``: labels at 1, 2, 5 x 10^k where the axis spans at most
    three decades, at the decades otherwise (call it after the data are drawn)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    for axis, scale, (lo, hi) in ((ax.xaxis, ax.get_xscale(), ax.get_xlim()),
                                  (ax.yaxis, ax.get_yscale(), ax.get_ylim())):
        if scale != "log" or not (0 < lo < hi):
            continue
        subs = (1.0, 2.0, 5.0) if np.log10(hi / lo) <= 3.0 else (1.0,)
        axis.set_major_locator(LogLocator(base=10, subs=subs))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(NullFormatter())


def title(fr) -> str:
    """``<system>: HBM H = .., N = ..`` (or closed forms)."""
    meth = "closed forms" if fr.closed_form else f"N = {fr.n_samples}"
    name = fr.system_name or "system"
    return f"{name}: harmonic balance, H = {fr.harmonics}, {meth}"


def _ylabel(fr, quantity: str, name: str | None) -> str:
    if quantity == "transmissibility":
        return fr.transmissibility_label or "transmissibility [-]"
    what = ("fundamental amplitude" if quantity == "amplitude"
            else "max |q(t)| over the period")
    return f"{name} {what} [{dof_unit(name)}]"


def _values(fr, quantity: str, name: str | None):
    """Curve values and the values at the located folds."""
    return _curve_values(fr, quantity, name), _event_values(fr.folds, quantity, fr,
                                                            name)


def _curve_values(fr, quantity: str, name: str | None) -> np.ndarray:
    if quantity == "transmissibility":
        return fr.transmissibility
    arr = fr.amplitude if quantity == "amplitude" else fr.peak
    return arr[:, fr.dof_names.index(name)]


def _event_values(events, quantity: str, fr, name: str | None) -> list:
    if quantity == "transmissibility":
        return [e.transmissibility for e in events]
    j = fr.dof_names.index(name)
    return [getattr(e, quantity)[j] for e in events]


#: Marker and legend text of each bifurcation kind (hbm.bifurcation).
BIFURCATION_MARKERS = {"period-doubling": ("s", "period doubling"),
                       "neimark-sacker": ("D", "Neimark-Sacker"),
                       "branch-point": ("^", "branch point")}


def _plot_bifurcations(fr, ax, quantity: str, name: str | None, color) -> None:
    """Mark each located bifurcation that is not a fold, one legend entry per kind."""
    for kind, (marker, text) in BIFURCATION_MARKERS.items():
        events = [e for e in getattr(fr, "bifurcations", []) if e.kind == kind]
        if events:
            ax.plot([e.freq_hz for e in events],
                    _event_values(events, quantity, fr, name), marker, ms=7,
                    mfc="none", mew=1.5, color=color,
                    label=f"{text} (located to 1e-6 Hz)", ls="none")


def plot_curve(fr, ax, quantity: str = "transmissibility", dof: str | None = None,
               logy: bool = True, label: str | None = None, jumps: bool = True,
               logx: bool = False, **kwargs):
    """Draw ``quantity`` of ``fr`` on ``ax``; returns ``ax``."""
    if quantity not in ("transmissibility", "amplitude", "peak"):
        raise ValueError(f"`quantity` must be transmissibility, amplitude or peak, "
                         f"got {quantity!r}")
    name = None
    if quantity != "transmissibility":
        name = dof if dof is not None else fr.dof_names[0]
        if name not in fr.dof_names:
            raise ValueError(f"`dof` must be one of {fr.dof_names}, got {name!r}")
    y, y_fold = _values(fr, quantity, name)
    label = label or f"HBM H={fr.harmonics}"
    st = fr.stable.astype(bool)
    line, = ax.plot(fr.freq_hz, np.where(st, y, np.nan), "-", label=label, **kwargs)
    if not np.all(st):
        # unstable parts dashed (include neighbours so the dashes join the curve)
        un = ~st
        un_ext = un | np.r_[un[1:], False] | np.r_[False, un[:-1]]
        ax.plot(fr.freq_hz, np.where(un_ext, y, np.nan), "--",
                color=line.get_color(), label=f"{label} (unstable)")
    if fr.folds:
        ax.plot([e.freq_hz for e in fr.folds], y_fold, "o", mfc="none", ms=7,
                color=line.get_color(), label="folds (located to 1e-6 Hz)")
    _plot_bifurcations(fr, ax, quantity, name, line.get_color())
    if jumps:
        fr._plot_jumps(ax, y)
    shade_family(fr, ax)
    if logy and np.all(y[np.isfinite(y)] > 0):
        ax.set_yscale("log")
    if logx:
        ax.set_xscale("log")
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel(_ylabel(fr, quantity, name))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    plain_log_ticks(ax)
    return ax


def plot_backbones(ax, modes, dof: str, fmin_hz: float, fmax_hz: float) -> None:
    """Draw each nonlinear mode's backbone (:class:`hbm.modes.NonlinearModes`): the
    fundamental amplitude of ``dof`` against the mode's frequency, within the band."""
    j = modes.dof_names.index(dof)
    for k, mode in enumerate(modes.modes):
        f, a = mode.freq_hz, mode.dof_amplitude[:, j]
        inside = (f >= fmin_hz) & (f <= fmax_hz)
        if np.any(inside):
            ax.plot(np.where(inside, f, np.nan), a, "-.", lw=1.2, color=f"C{k + 3}",
                    label=f"backbone, mode {mode.index} ({mode.label})")
    ax.legend(fontsize="small")


def shade_family(fr, ax) -> None:
    """Shade the frequencies where a surface of an inclined element sticks for the
    whole period (:attr:`hbm.result.FrequencyResponse.family`): there the curve is
    one member of a family of periodic states (edges half-way to the neighbours)."""
    fam = np.asarray(fr.family, bool) if getattr(fr, "stuck_labels", ()) else ()
    if not np.any(fam):
        return
    f = np.asarray(fr.freq_hz, float)
    label = "one surface stuck: one member of a family"
    i, n = 0, f.size
    while i < n:
        if not fam[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and fam[j + 1]:
            j += 1
        lo = f[i] if i == 0 else 0.5 * (f[i - 1] + f[i])
        hi = f[j] if j == n - 1 else 0.5 * (f[j] + f[j + 1])
        ax.axvspan(min(lo, hi), max(lo, hi), color="0.85", zorder=0, label=label)
        label = None
        i = j + 1


def plot_figure(fr, path: str | os.PathLike | None = None, logx: bool = False,
                logy: bool = True, backbones=None):
    """The transmissibility and, for several DOFs, each DOF's amplitude in its own
    panel; titled with the system and H/N. Saved to ``path`` if given. Returns the
    figure. ``backbones`` (:class:`hbm.modes.NonlinearModes`): drawn on every DOF's
    amplitude panel (a single DOF then gets one too, :func:`plot_backbones`)."""
    from matplotlib.figure import Figure

    n = len(fr.dof_names)
    panels = 1 if n == 1 and backbones is None else n + 1
    cols = 1 if panels == 1 else 2
    rows = (panels + cols - 1) // cols
    fig = Figure(figsize=(7 * cols, 4.2 * rows), layout="constrained")
    axes = [fig.add_subplot(rows, cols, k + 1) for k in range(panels)]
    plot_curve(fr, axes[0], "transmissibility", logy=logy, logx=logx)
    axes[0].set_title("transmissibility")
    for k, name in enumerate(fr.dof_names if panels > 1 else ()):
        plot_curve(fr, axes[k + 1], "amplitude", dof=name, logy=logy, logx=logx,
                   jumps=False)
        if backbones is not None:
            f = fr.freq_hz[np.isfinite(fr.freq_hz)]
            plot_backbones(axes[k + 1], backbones, name, float(f.min()),
                           float(f.max()))
        axes[k + 1].set_title(f"DOF {name}")
    fig.suptitle(title(fr))
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig
