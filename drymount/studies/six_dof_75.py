"""Study ``six-dof-75``: the 6-DOF engine on the original mounts at 75 % stiffness with
friction (thesis Sec. 4.5, Figs. 4.45-4.50).

The thesis found that friction on the original mounts raises the x and z responses at
high frequency (a stuck contact adds stiffness) and cut the mounts' stiffness to 75 %:
"the issue about displacement in x and z directions at high frequencies is solved with
this modification; however, problems regarding displacement in y direction emerged".
Here: Table 4.1 layout, lambda = 1, the six-dof study's input (chassis moved 1 mm along
x, y and z in phase) and friction elements (x on mount 1, y on mount 2, z on mount 3,
n0 = 250 N, the thesis's value); designs: original without friction, original with
friction, 75 % with friction. HBM with H = 3 over 2-40 Hz.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drymount.studies.common import (
    friction_template,
    hbm_curve,
    load_system,
    peak,
    ratio,
    value_at,
    with_friction_of,
    with_normal_force,
    with_stiffness_factor,
)
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
from drymount.hbm.system import Excitation

__all__ = ["DESIGNS", "run_six_dof_75"]

#: (label, stiffness factor, n0 in N)
DESIGNS = (("original, no friction", 1.0, 0.0), ("original, 250 N", 1.0, 250.0),
           ("75 %, 250 N", 0.75, 250.0))
BAND_HZ = (2.0, 40.0)
HIGH_HZ = 30.0
BASE_AMPLITUDE = (0.001, 0.001, 0.001)  # m, as the six-dof study


def _systems():
    original = load_system("six_dof_original")
    template = friction_template([load_system("six_dof_halved"), original])
    exc = Excitation("base", np.array(BASE_AMPLITUDE))
    base = with_friction_of(original, template).with_excitation(exc)
    return [(label, with_normal_force(with_stiffness_factor(base, factor)
                                      if factor != 1.0 else base, n0))
            for label, factor, n0 in DESIGNS]


def _plot(curves, dofs, out: Path) -> str:
    fig = new_figure(figsize=(11.0, 6.2), layout="constrained")
    axs = fig.subplots(2, 3)
    for ax, (j, dof) in zip(axs.ravel(), enumerate(dofs), strict=True):
        for c in curves:
            amp = np.asarray(c.fr.amplitude)[:, j]
            plot_branch(ax, c.fr.freq_hz, amp, c.fr.stable, label=c.case["design"])
        unit = "rad" if dof in ("alpha", "beta", "gamma") else "m"
        log_axes(ax, ylabel=f"{dof} amplitude [{unit}]", title=dof)
    axs[0, 0].legend(fontsize=7)
    fig.suptitle("6 DOF, mount deflection input, lambda = 1: mounts at 75 % with "
                 "friction (cf. thesis Figs. 4.45-4.50)")
    path = out / "six_dof_75.png"
    save_fig(fig, path)
    return path.name


def _cases(curves, dofs) -> list[dict]:
    out = []
    for c in curves:
        amp = np.asarray(c.fr.amplitude)
        row = {"design": c.case["design"], "success": bool(c.fr.success)}
        for j, d in enumerate(dofs):
            row[f"{d}_peak"] = peak(c.fr.freq_hz, amp[:, j]).value
            row[f"{d}_high"] = value_at(c.fr.freq_hz, amp[:, j], HIGH_HZ)
        out.append(row)
    return out


def run_six_dof_75(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """Original vs 75 % mounts with friction (Figs. 4.45-4.50).

    Returns ``cases`` (per design: peak and value at ``HIGH_HZ`` of every DOF),
    ``peak_ratio`` and ``high_ratio`` ({design: {dof: value / original without
    friction}}), ``failures``, ``notes``, ``files``. Quick mode: H = 1.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    H = 1 if quick else 3
    failures, notes, curves = [], [], []
    for label, system in progress_bar(_systems(), "six-dof-75", progress):
        curves.append(hbm_curve(system, BAND_HZ, H, {"design": label, "H": H},
                                failures, notes, ds_max=None))
    dofs = list(curves[0].fr.dof_names)
    cases = _cases(curves, dofs)
    ref = cases[0]
    peak_ratio = {c["design"]: {d: ratio(c[f"{d}_peak"], ref[f"{d}_peak"])
                                for d in dofs} for c in cases[1:]}
    high_ratio = {c["design"]: {d: ratio(c[f"{d}_high"], ref[f"{d}_high"])
                                for d in dofs} for c in cases[1:]}
    write_curves(out / "six_dof_75_curves.csv", "6 DOF, mount deflection input 1 mm "
                 "per axis; amplitudes in m or rad", curves)
    files = ["six_dof_75_curves.csv", _plot(curves, dofs, out)]
    r = {"cases": cases, "peak_ratio": peak_ratio, "high_ratio": high_ratio,
         "failures": failures, "notes": notes, "files": files, "harmonics": H}
    (out / "summary.md").write_text(_summary(r, dofs))
    files.append("summary.md")
    return r


def _summary(r, dofs) -> str:
    head = ["design", *dofs]
    lines = ["# Study six-dof-75: original mounts at 75 % with friction "
             "(Figs. 4.45-4.50)", "",
             f"Table 4.1 layout, lambda = 1, chassis moved {BASE_AMPLITUDE} m "
             f"(x, y, z) in phase, friction x on mount 1, y on mount 2, z on mount "
             f"3; HBM H = {r['harmonics']}.", "",
             "Peak over the original mounts without friction:", "",
             md_table(head, [[k, *v.values()] for k, v in r["peak_ratio"].items()]), "",
             f"Amplitude at {HIGH_HZ:g} Hz over the original mounts without friction:",
             "", md_table(head, [[k, *v.values()] for k, v in r["high_ratio"].items()]),
             "", "![six_dof_75](six_dof_75.png)"]
    return "\n".join(lines + notes_md(r)) + "\n"
