"""The report of ``drymount validate`` (:mod:`drymount.validation`): ``points.csv``
(every compared point), one plot per case (the validation points over the
continuous HBM curves, the family-band points) and ``validation.md`` (the table of
cases, the exact-FRF and family-band lines). Split from :mod:`drymount.validation`,
which runs the cases.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drymount.hbm.aft import default_n_samples
from drymount.io import atomic_write_text, save_figure, write_csv
from drymount.validation_cases import (_ROTATIONS, TOL_FAMILY_ORBIT, TOL_REL_PEAK,
                                       CaseResult)

__all__ = ["write_report"]


def _plot_dense(ax, res: CaseResult, i: int) -> None:
    """The continuous HBM curves of DOF ``i``: stable solid, unstable dotted."""
    for h, (f, amp, stable) in res.dense.items():
        main = h == res.case.harmonics  # drawn over the H = 1 reference
        color, style, lw, z = ("C0", "-", 1.4, 3) if main else ("C2", "--", 0.9, 2)
        a = amp[:, i]
        ax.plot(f, np.where(stable, a, np.nan), style, color=color, lw=lw, zorder=z,
                label=f"HBM H={h}, continuous")
        if not stable.all():
            ax.plot(f, np.where(stable, np.nan, a), ":", color=color, lw=lw, zorder=z,
                    label=f"HBM H={h}, unstable")


def _plot_family(ax, res: CaseResult, dof: str) -> None:
    """The family-band points of DOF ``dof``: started on the HBM orbit and at rest."""
    pts = [fp for fp in res.family if fp.dof == dof]
    if not pts:
        return
    f = [fp.freq_hz for fp in pts]
    ax.plot(f, [fp.amp_orbit for fp in pts], "^", mfc="none", color="C1", ms=8,
            label="co-simulation from the HBM orbit (family band)")
    ax.plot(f, [fp.amp_rest for fp in pts], "x", color="C4", ms=8,
            label="co-simulation from rest (family band)")


def _exact_lines(res: CaseResult) -> list[str]:
    """The report's line on the exact-FRF column ([] without)."""
    if not res.case.exact:
        return []
    return [f"Exact FRF (chamber equations, `drymount/validation_exact.py`): HBM "
            f"{100 * res.max_err_exact_hbm:.2e} % and co-simulation "
            f"{100 * res.max_err_exact_cosim:.2e} % of its peak at most (<= "
            f"{100 * TOL_REL_PEAK:g} % each); column `amp_exact` of `points.csv`.",
            ""]


def _family_lines(res: CaseResult) -> list[str]:
    """The report's table of the family-band points ([] without)."""
    if not res.family:
        return []
    lines = ["Where a surface of the inclined element sticks for the whole period "
             "the periodic state is a family: the member reached depends on the "
             "start (stuck: 1 the inclined surface, 2 the flat one). Started on the "
             f"HBM orbit the co-simulation must stay on it (<= "
             f"{100 * TOL_FAMILY_ORBIT:g} % of peak); started at rest it settles on "
             f"the member its history selects, {100 * res.max_err_rest:.2f} % of "
             "peak away at most (reported, not judged). In-process backend (the "
             "FMU's law), from rest at the engine lowered onto the mount.", "",
             "| f [Hz] | DOF | stuck | A HBM | A from orbit | error | A from rest | "
             "spread | mean HBM | mean from orbit | mean from rest |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for fp in res.family:
        lines.append(f"| {fp.freq_hz:g} | {fp.dof} | {','.join(map(str, fp.stuck))} "
                     f"| {fp.amp_hbm:.6g} | {fp.amp_orbit:.6g} | "
                     f"{100 * fp.err_orbit:.3f} % | {fp.amp_rest:.6g} | "
                     f"{100 * fp.err_rest:.2f} % | {fp.mean_hbm:.6g} | "
                     f"{fp.mean_orbit:.6g} | {fp.mean_rest:.6g} |")
    return lines + [""]


def _plot_case(res: CaseResult, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from drymount.hbm.plot import plain_log_ticks

    dofs = next(iter(res.curves.values()))["dofs"]
    ncol = min(3, len(dofs))
    nrow = -(-len(dofs) // ncol)
    size = (max(4.2 * ncol, 6.4), 3.2 * nrow + 0.6)
    fig, axes = plt.subplots(nrow, ncol, figsize=size, squeeze=False)
    dof_names = res.dof_names
    for ax, i in zip(axes.flat, dofs, strict=False):
        _plot_dense(ax, res, i)
        for k, (direction, c) in enumerate(res.curves.items()):
            mark = "o" if direction == "up" else "s"
            ax.plot(c["freq_hz"], c["hbm"][:, i], ".", color="C0", ms=4,
                    label=None if k else f"HBM H={res.case.harmonics}, compared")
            ax.plot(c["freq_hz"], c["cosim"][:, i], mark, mfc="none", color="C3",
                    label=f"co-simulation, FMU ({direction})")
        _plot_family(ax, res, dof_names[i])
        unit = "rad" if dof_names[i] in _ROTATIONS else "m"
        ax.set_title(dof_names[i])
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"fundamental amplitude [{unit}]")
        ax.set_yscale("log")
        plain_log_ticks(ax)
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(dofs):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7)
    verdict = "PASS" if res.passed else "FAIL"
    fig.suptitle(f"{res.case.name} ({res.case.preset}):\nmax error "
                 f"{100 * res.max_err:.3g} % of peak, {verdict}", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def write_report(results: list[CaseResult], out: Path, quick: bool,
                 inject: str | None) -> Path:
    """Write ``points.csv``, one PNG per case and ``validation.md``; returns the md."""
    out.mkdir(parents=True, exist_ok=True)
    header = ["system", "preset", "direction", "freq_hz", "dof", "amp_cosim",
              "amp_hbm", "amp_hbm1", "err_rel_peak", "err_rel_peak_h1", "stable",
              "compared", "amp_exact"]
    rows = [[r.case.name, r.case.preset, p["direction"], p["freq_hz"], p["dof"],
             p["amp_cosim"], p["amp_hbm"], p["amp_hbm1"], p["err"], p["err_h1"],
             p["stable"], p["compared"], p.get("amp_exact", float("nan"))]
            for r in results for p in r.rows]
    write_csv(out / "points.csv", header, rows,
              comment="freq_hz [Hz]; amp_* fundamental amplitude [m] (translations) or "
                      "[rad] (alpha, beta, gamma); err_* = |A_cosim - A_hbm| / peak "
                      "HBM amplitude of the DOF [1]; cosim = mount FMU through fmpy; "
                      "amp_exact: the exact FRF of a linear SDOF (nan: not computed)")
    lines = ["# drymount validation: co-simulation (mount FMU) vs harmonic balance", "",
             f"Mode: {'quick' if quick else 'full'}. Tolerance: largest error "
             f"<= {100 * TOL_REL_PEAK:g} % of the peak amplitude (HBM H >= 7, stable "
             "points). H = 1 (the thesis's single-harmonic method) is shown for "
             "reference and does not count.", ""]
    if inject:
        lines += [f"**Injected error**: HBM side mount parameter `{inject}`.", ""]
    lines += ["| system | preset | points | H | AFT samples | max error (H) | "
              "max error (H=1) | time [s] | result |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        n = len({(p['direction'], p['freq_hz']) for p in r.rows})
        nsamp = r.case.n_samples or default_n_samples(r.case.harmonics)
        lines.append(f"| {r.case.name} | {r.case.preset} | {n} | {r.case.harmonics} | "
                     f"{nsamp} | {100 * r.max_err:.3f} % | "
                     f"{100 * r.max_err_h1:.2f} % | {r.seconds:.1f} | "
                     f"{'PASS' if r.passed else 'FAIL'} |")
    lines.append("")
    for r in results:
        lines += [f"## {r.case.name}", ""]
        if r.message:
            lines += [f"Note: {r.message.strip()}", ""]
        lines += _exact_lines(r)
        lines += _family_lines(r)
        lines += [f"![{r.case.name}]({r.case.name}.png)", ""]
        _plot_case(r, out / f"{r.case.name}.png")
    lines += ["Every point is in `points.csv`."]
    return atomic_write_text(out / "validation.md", "\n".join(lines) + "\n")
