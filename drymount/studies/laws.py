"""Study ``laws``: the single DOF with the thesis's three fitted elastic laws at one
excitation (thesis Sec. 4.2, Fig. 4.5, "Displacement of engine for different stiffness
models").

The thesis fitted linear, cubic and piecewise-linear laws to one measured
force-deflection curve (Sec. 2.3-2.4) and compared the engine's displacement for the
same excitation amplitude. The three fits (PHYSICS.md section 1) go into the engine of
``sdof_original`` (70 kg, c = 150 N s/m, rotating unbalance f0 = 0.030478 kg m, all
CHOSEN there) without friction; HBM with H = 7 over 1-30 Hz.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from drymount.studies.common import hbm_curve, load_system, peak, value_at
from drymount.studies.output import (
    log_axes,
    md_table,
    new_figure,
    notes_md,
    plot_branch,
    progress_bar,
    save_fig,
    write_curves,
)
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.system import System

__all__ = ["THESIS_FITS", "run_laws"]

#: The thesis's fits of one measured curve (Sec. 2.4; PHYSICS.md section 1), SI.
THESIS_FITS = {
    "linear": {"k1": 133000.0},
    "cubic": {"k1": 34770.0, "kc": 5.708e8},
    "piecewise": {"k1": 91870.0, "k2": 513800.0, "delta": 0.01225},
}
BAND_HZ = (1.0, 30.0)
HIGH_HZ = 20.0


def _system(law: str) -> System:
    """``sdof_original`` with the thesis's fit of ``law`` (no friction)."""
    base = load_system("sdof_original")
    old = base.elements[0].params.axial
    axis = AxisParameters(law=law, c=old.c, **THESIS_FITS[law])
    mount = MountParameters(axis, replace(axis), replace(axis))
    el = replace(base.elements[0], params=mount)
    return replace(base, elements=(el,), name=f"sdof_{law}_fit")


def _plot(curves, out: Path) -> str:
    fig = new_figure(figsize=(7.5, 4.6))
    ax = fig.subplots()
    for c in curves:
        fr = c.fr
        amp = np.asarray(fr.amplitude)[:, 0]
        plot_branch(ax, fr.freq_hz, amp * 1e3, fr.stable, label=c.case["law"])
    log_axes(ax, ylabel="engine displacement amplitude [mm]",
             title="Single DOF, thesis's three fitted laws, same unbalance "
                   "(cf. thesis Fig. 4.5)")
    ax.legend()
    path = out / "laws.png"
    save_fig(fig, path)
    return path.name


def run_laws(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """The three fitted laws of the thesis at one excitation (Fig. 4.5).

    Returns ``cases`` (one dict per law: law, peak_mm, peak_freq_hz, x_high_mm at
    ``HIGH_HZ``, turning points, success), ``failures``, ``notes``, ``files``.
    Quick mode: H = 3.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    H = 3 if quick else 7
    failures, notes, curves = [], [], []
    for law in progress_bar(list(THESIS_FITS), "laws", progress):
        curves.append(hbm_curve(_system(law), BAND_HZ, H, {"law": law, "H": H},
                                failures, notes))
    cases = []
    for c in curves:
        fr = c.fr
        x = np.asarray(fr.amplitude)[:, 0]
        pk = peak(fr.freq_hz, x)
        cases.append({"law": c.case["law"], "peak_mm": pk.value * 1e3,
                      "peak_freq_hz": pk.freq_hz,
                      "x_high_mm": value_at(fr.freq_hz, x, HIGH_HZ) * 1e3,
                      "turning_points": len(fr.turning_points),
                      "success": bool(fr.success)})
    write_curves(out / "laws_curves.csv",
                 "single DOF (sdof_original engine) with the thesis's three fitted "
                 "laws; amplitudes in m", curves)
    files = ["laws_curves.csv", _plot(curves, out)]
    r = {"cases": cases, "failures": failures, "notes": notes, "files": files,
         "harmonics": H}
    (out / "summary.md").write_text(_summary(r))
    files.append("summary.md")
    return r


def _summary(r) -> str:
    rows = [[c["law"], c["peak_mm"], c["peak_freq_hz"], c["x_high_mm"],
             c["turning_points"]] for c in r["cases"]]
    fits = "; ".join(f"{law}: " + ", ".join(f"{k} = {v:g}" for k, v in p.items())
                     for law, p in THESIS_FITS.items())
    lines = ["# Study laws: the thesis's three fitted elastic laws (Fig. 4.5)", "",
             f"Engine of sdof_original (70 kg, c = 150 N s/m, unbalance "
             f"0.030478 kg m), no friction, HBM H = {r['harmonics']}. Fits (SI): "
             f"{fits}.", "",
             md_table(["law", "peak [mm]", "at [Hz]", f"x at {HIGH_HZ:g} Hz [mm]",
                       "turning points"], rows), "", "![laws](laws.png)"]
    return "\n".join(lines + notes_md(r)) + "\n"
