"""What the studies share to show their results: figures on log axes, the long CSV of
all curves, Markdown tables, progress bars and one-line system descriptions.

matplotlib and tqdm are imported where they are used: the studies' numerics need
neither.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from drymount.io import save_figure, write_csv
from drymount.studies.common import RESTART_FACTOR, DesignResult
from drymount.hbm.system import System

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Resolution of saved plots, dots per inch (small PNGs for docs/).
DPI = 100
#: Resolution of the large six-panel figures (keeps them near 100 kB).
DPI_SIX_PANEL = 75


def new_figure(**kwargs) -> Figure:
    """A matplotlib Figure (imported here: the studies' numerics need no matplotlib)."""
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def save_fig(fig: Figure, path: Path, dpi: int = DPI) -> None:
    from drymount.hbm.plot import plain_log_ticks

    for ax in fig.axes:
        plain_log_ticks(ax)  # 5 and 0.2 on log axes, not 5x10^0
    save_figure(fig, path, dpi=dpi)


def plot_branch(ax, f, y, stable=None, **kw):
    """Plot a curve, stable parts solid and unstable parts dashed (same colour)."""
    f = np.asarray(f, dtype=float)
    y = np.asarray(y, dtype=float)
    line, = ax.plot(f, y if stable is None else np.where(stable, y, np.nan), **kw)
    if stable is not None and not np.all(stable):
        st = np.asarray(stable, dtype=bool)
        # include the neighbours so that dashed segments join the solid ones
        uns = ~st | np.r_[~st[1:], False] | np.r_[False, ~st[:-1]]
        kw2 = {k: v for k, v in kw.items()
               if k not in ("label", "linestyle", "ls", "color")}
        ax.plot(f, np.where(uns, y, np.nan), linestyle="--", color=line.get_color(),
                **kw2)
    return line


def log_axes(ax, xlabel="frequency [Hz]", ylabel="transmissibility [-]", title=None,
             ylog=True):
    """Log frequency axis with plain labels (and a log y axis unless ``ylog``)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    ax.set_xscale("log")
    if ylog:
        ax.set_yscale("log")
    # plain frequency labels at 1, 2, 5 x 10^k (log axes label 2 x 10^0 otherwise)
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)


def n0_colors(forces) -> dict:
    """Black for no friction, viridis from dark to light for increasing n0."""
    from matplotlib import colormaps

    cmap = colormaps["viridis"]
    nz = sorted(f for f in forces if f > 0)
    out = {0.0: "black"}
    for i, f in enumerate(nz):
        out[f] = cmap(0.2 + 0.7 * i / max(len(nz) - 1, 1))
    return out


def md_table(header: Sequence[str], rows) -> str:
    """A Markdown table; floats with 4 significant digits, NaN as n/a."""
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        out.append("| " + " | ".join(_md(v) for v in r) + " |")
    return "\n".join(out)


def _md(v) -> str:
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if not math.isfinite(v):
            return "n/a"
        if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
            return f"{v:.3g}"
        return f"{v:.4g}"
    return str(v)


def notes_md(r) -> list[str]:
    """Summary lines for the restarted (``r["notes"]``) and failed curves."""
    out = []
    if r.get("notes"):
        out += ["", "Curves whose continuation stalled and was restarted "
                f"{100 * (RESTART_FACTOR - 1):g} % higher in frequency (a gap in the "
                "plot; a branch beyond a fold may be missing there):", ""]
        out += [f"- {n}" for n in r["notes"]]
    if r.get("failures"):
        out += ["", "**Curves that did not complete:**", ""]
        out += [f"- {f}" for f in r["failures"]]
    return out


def write_curves(path: Path, comment: str, curves: Sequence[DesignResult]) -> None:
    """All curves in one long-format CSV: design columns, then the HBM columns."""
    case_keys = list(dict.fromkeys(k for c in curves for k in c.case))
    dof_names = list(curves[0].fr.dof_names)
    extra_keys = list(dict.fromkeys(k for c in curves for k in c.extra))
    header = (case_keys + ["freq_hz"] + [f"{d}_amp" for d in dof_names]
              + ["transmissibility", "stable"] + extra_keys)
    rows = []
    for c in curves:
        fr = c.fr
        amp = np.asarray(fr.amplitude)
        for i, f in enumerate(fr.freq_hz):
            if not np.isfinite(fr.transmissibility[i]):
                continue  # gap between segments
            rows.append([c.case.get(k, "") for k in case_keys] + [f]
                        + list(amp[i]) + [fr.transmissibility[i], bool(fr.stable[i])]
                        + [c.extra[k][i] if k in c.extra else "" for k in extra_keys])
    write_csv(path, header, rows, comment=comment)


def progress_bar(items, desc: str, progress: bool):
    """A tqdm bar over ``items`` on stderr (disabled unless ``progress``)."""
    from tqdm import tqdm

    return tqdm(items, desc=desc, unit="curve", disable=not progress, leave=False,
                file=sys.stderr)


def md_text(value) -> str:
    """``value`` as prose for a Markdown summary, not a Python repr: ``yes``/``no``
    for a bool, numbers with ``:.6g``, sequences as ``a, b`` (nested in parentheses),
    mappings as ``key: value, ...``."""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, float, np.integer, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, dict):
        return ", ".join(f"{k}: {md_text(v)}" for k, v in value.items())
    if isinstance(value, (list, tuple, np.ndarray)):
        items = [md_text(v) for v in value]
        nested = any(isinstance(v, (list, tuple, np.ndarray)) for v in value)
        return ", ".join(f"({t})" for t in items) if nested else ", ".join(items)
    return str(value)


def system_values(system: System) -> str:
    """One line with the mount values and excitation of a one-mount system (the
    friction element's values only if it has one; each law's own parameters)."""
    axes = system.elements[0].params.axes
    p = next((ax for ax in axes if ax.friction), axes[0])
    exc = system.excitation
    law = {"linear": ("k1",), "cubic": ("k1", "kc")}.get(
        p.law, ("k1", "k2", "delta") + (("delta_neg",) if p.law.endswith("asym")
                                        else ()))
    units = {"k1": "N/m", "k2": "N/m", "kc": "N/m^3", "delta": "m", "delta_neg": "m"}
    parts = [f"law {p.law}"] + [f"{k} = {getattr(p, k):.6g} {units[k]}" for k in law]
    parts.append(f"c = {p.c:.6g} N s/m")
    if p.friction:
        parts += [f"kf = {p.kf:.6g} N/m", f"mu = {p.mu:.6g}"]
    else:
        parts.append("no friction")
    return (", ".join(parts) + f"; masses {md_text(np.diag(system.M))} kg; "
            f"excitation {exc.kind} {md_text(np.asarray(exc.amplitude))}")
