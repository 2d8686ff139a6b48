"""The n0 family studies (single DOF, quarter car): HBM curves of the original and
the halved mount for a range of normal forces, the best halved design, files.

:class:`FamilySpec` holds what distinguishes the two studies
(``drymount.studies.normal_force``, ``drymount.studies.quarter_car``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drymount.io import atomic_write_text, write_csv
from drymount.studies.common import (
    PLOT_DS_MAX,
    DesignResult,
    bands,
    friction_energy,
    friction_template,
    hbm_curve,
    load_system,
    peak,
    value_at,
    with_friction_of,
    with_normal_force,
)
from drymount.studies.output import (
    log_axes,
    md_table,
    n0_colors,
    new_figure,
    notes_md,
    plot_branch,
    progress_bar,
    save_fig,
    system_values,
    write_curves,
)

#: Points of the common log grid on which "lower at every frequency" is judged.
COMPARISON_GRID_POINTS = 300

#: Columns of ``<study>_peaks.csv`` (keys of a case).
PEAK_KEYS = ["mount", "n0_N", "H", "peak", "peak_freq_hz", "t_high", "e_fr_min_J",
             "e_fr_max_J", "success", "seconds", "n_points"]


@dataclass(frozen=True)
class FamilySpec:
    """What distinguishes the single-DOF and quarter-car n0 studies."""

    study: str
    presets: tuple[tuple[str, str], ...]  # (mount label, preset name)
    band_hz: tuple[float, float]
    high_hz: float
    forces: tuple[float, ...]
    forces_quick: tuple[float, ...]
    harmonics: tuple[int, ...]  # first = main curves; others dotted
    harmonics_quick: tuple[int, ...]
    ylabel: str
    title: str
    description: str
    figs: tuple[str, str, str]  # thesis figures: original, halved, comparison

    @property
    def stem(self) -> str:
        """File name stem, e.g. ``normal_force``."""
        return self.study.replace("-", "_")


def _find(curves: list[DesignResult], mount: str, n0: float, H: int) -> DesignResult:
    return next(c for c in curves if c.case == {"mount": mount, "n0_N": n0, "H": H})


def _systems(spec: FamilySpec) -> dict:
    """mount label -> preset system with the friction element of the first preset
    that has one."""
    systems = {m: load_system(p) for m, p in spec.presets}
    template = friction_template(systems.values())
    return {m: with_friction_of(s, template) for m, s in systems.items()}


def _curves(spec: FamilySpec, systems: dict, forces, hs, quick: bool,
            progress: bool, failures: list, notes: list) -> list[DesignResult]:
    """One HBM curve per (mount, n0, H), with the friction energy per cycle."""
    designs = [(m, n0, H) for m in systems for n0 in forces for H in hs]
    curves = []
    for mount, n0, H in progress_bar(designs, spec.study, progress):
        sys_ = with_normal_force(systems[mount], n0)
        c = hbm_curve(sys_, spec.band_hz, H, {"mount": mount, "n0_N": n0, "H": H},
                      failures, notes, ds_max=None if quick else PLOT_DS_MAX)
        c.extra["e_fr_J"] = friction_energy(sys_, c.fr, 0, 0).energy
        curves.append(c)
    return curves


def _case(spec: FamilySpec, c: DesignResult) -> dict:
    """The key numbers of one curve."""
    pk = peak(c.fr.freq_hz, c.fr.transmissibility)
    e = c.extra["e_fr_J"]
    return {**c.case, "peak": pk.value, "peak_freq_hz": pk.freq_hz,
            "t_high": value_at(c.fr.freq_hz, c.fr.transmissibility, spec.high_hz),
            "e_fr_min_J": float(np.nanmin(e)), "e_fr_max_J": float(np.nanmax(e)),
            "success": bool(c.fr.success), "seconds": c.seconds,
            "n_points": len(c.fr.freq_hz)}


def _best_halved(cases: list[dict], ref: dict, H_hi: int) -> dict:
    """The good halved design: the lowest peak among those that keep the isolation at
    high_hz at least as good as the reference (the thesis's "performance increase at
    all frequencies"); the lowest peak overall if none does."""
    halved = [x for x in cases if x["mount"] == "halved" and x["H"] == H_hi
              and x["n0_N"] > 0]
    isolating = [x for x in halved if x["t_high"] <= ref["t_high"]]
    return min(isolating or halved, key=lambda x: x["peak"])


def _lower_on_grid(spec: FamilySpec, cref: DesignResult, cbest: DesignResult):
    """(grid, best < reference per grid point) on a common log grid."""
    f_grid = np.geomspace(spec.band_hz[0], spec.band_hz[1], COMPARISON_GRID_POINTS)
    t_ref = np.array([value_at(cref.fr.freq_hz, cref.fr.transmissibility, f)
                      for f in f_grid])
    t_best = np.array([value_at(cbest.fr.freq_hz, cbest.fr.transmissibility, f)
                       for f in f_grid])
    return f_grid, t_best < t_ref


def _write_tables(spec: FamilySpec, curves: list[DesignResult], cases: list[dict],
                  out: Path) -> None:
    write_curves(out / f"{spec.stem}_curves.csv",
                 f"{spec.description} from HBM; n0 in N, freq in Hz, <dof>_amp in m "
                 "(fundamental amplitude), e_fr_J: friction energy per cycle in J",
                 curves)
    write_csv(out / f"{spec.stem}_peaks.csv", PEAK_KEYS,
              [[x[k] for k in PEAK_KEYS] for x in cases],
              comment=f"peak transmissibility and its frequency (Hz) per design; "
                      f"t_high = transmissibility at {spec.high_hz:g} Hz; energies in "
                      "J; seconds = HBM wall time")


def family_study(spec: FamilySpec, out_dir, quick: bool, progress: bool) -> dict:
    """Run the n0 family study ``spec`` into ``out_dir`` (see
    :func:`drymount.studies.run_normal_force` for the returned keys)."""
    out = Path(out_dir)
    systems = _systems(spec)
    forces = spec.forces_quick if quick else spec.forces
    hs = spec.harmonics_quick if quick else spec.harmonics
    H_hi = hs[0]
    failures: list[str] = []
    notes: list[str] = []
    curves = _curves(spec, systems, forces, hs, quick, progress, failures, notes)
    cases = [_case(spec, c) for c in curves]
    ref = next(x for x in cases
               if (x["mount"], x["n0_N"], x["H"]) == ("original", 0.0, H_hi))
    best = _best_halved(cases, ref, H_hi)
    f_grid, lower = _lower_on_grid(spec, _find(curves, "original", 0.0, H_hi),
                                   _find(curves, "halved", best["n0_N"], H_hi))
    result = {
        "study": spec.study,
        "band_hz": spec.band_hz,
        "high_hz": spec.high_hz,
        "harmonics": H_hi,
        "normal_forces_N": list(forces),
        "cases": cases,
        "reference": ref,
        "best_halved": best,
        "best_halved_peak_reduction": 1.0 - best["peak"] / ref["peak"],
        "best_halved_lower_fraction": float(np.mean(lower)),
        "best_halved_higher_hz": bands(f_grid, ~lower),
        "e_fr_min_J": min(x["e_fr_min_J"] for x in cases),
        "failures": failures, "notes": notes,
        "systems": {m: system_values(s) for m, s in systems.items()},
    }
    _write_tables(spec, curves, cases, out)
    figs = _plot_family(spec, curves, forces, hs, best, out)
    atomic_write_text(out / "summary.md", _summary_family(spec, result, figs))
    result["files"] = sorted(p.name for p in out.iterdir())
    return result


def _plot_mount(spec: FamilySpec, curves, colors, hs, mount: str, fig_no: str,
                out: Path) -> str:
    """Curves of one mount for every n0 (thesis Figs. 4.1/4.2, 4.6/4.7)."""
    H_hi = hs[0]
    fig = new_figure(figsize=(7, 4.5))
    ax = fig.add_subplot()
    if mount == "halved":
        cref = _find(curves, "original", 0.0, H_hi)
        ax.plot(cref.fr.freq_hz, cref.fr.transmissibility, color="0.6", lw=3,
                alpha=0.7, label="original mount, no friction")
    for c in curves:
        if c.case["mount"] != mount:
            continue
        n0, H = c.case["n0_N"], c.case["H"]
        if H == H_hi:
            plot_branch(ax, c.fr.freq_hz, c.fr.transmissibility, c.fr.stable,
                        color=colors[n0], lw=1.4,
                        label=f"n0 = {n0:g} N" if n0 else "no friction")
        else:
            ax.plot(c.fr.freq_hz, c.fr.transmissibility, color=colors[n0], lw=0.8,
                    ls=":")
    for H in hs[1:]:
        ax.plot([], [], color="0.3", ls=":", lw=0.8, label=f"same, H = {H}")
    log_axes(ax, ylabel=spec.ylabel,
             title=f"{spec.title}, {mount} mount, HBM H = {H_hi} "
                   f"(cf. thesis Fig. {fig_no})")
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    name = f"{spec.stem}_{mount}.png"
    save_fig(fig, out / name)
    return name


def _plot_family(spec: FamilySpec, curves, forces, hs, best, out: Path) -> list[str]:
    colors = n0_colors(forces)
    H_hi = hs[0]
    names = [_plot_mount(spec, curves, colors, hs, mount, fig_no, out)
             for mount, fig_no in (("original", spec.figs[0]),
                                   ("halved", spec.figs[1]))]
    fig = new_figure(figsize=(7, 4.5))
    ax = fig.add_subplot()
    cref = _find(curves, "original", 0.0, H_hi)
    cbest = _find(curves, "halved", best["n0_N"], H_hi)
    for c, label, color in ((cref, "original mount, no friction", "black"),
                            (cbest, f"halved mount, n0 = {best['n0_N']:g} N",
                             "tab:red")):
        plot_branch(ax, c.fr.freq_hz, c.fr.transmissibility, c.fr.stable, color=color,
                    lw=1.6, label=label)
    ax.axvline(spec.high_hz, color="0.7", lw=0.8, ls="-.")
    log_axes(ax, ylabel=spec.ylabel,
             title=f"{spec.title}: original against the best halved design "
                   f"(cf. thesis Fig. {spec.figs[2]})")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_fig(fig, out / f"{spec.stem}_best.png")
    names.append(f"{spec.stem}_best.png")
    return names


def _summary_family(spec: FamilySpec, r: dict, figs) -> str:
    rows = [[x["mount"], x["n0_N"], x["H"], x["peak"], x["peak_freq_hz"], x["t_high"],
             x["e_fr_max_J"], "yes" if x["success"] else "NO"] for x in r["cases"]]
    best, ref = r["best_halved"], r["reference"]
    lines = [
        f"# Study {spec.study}: {spec.title} against the normal force n0",
        "",
        f"{spec.description} from harmonic balance over {r['band_hz'][0]:g}-"
        f"{r['band_hz'][1]:g} Hz with H = {r['harmonics']} (AFT); other harmonic "
        "orders dotted in the plots. n0 = 0 is the mount without friction element.",
        "",
        "Systems: " + "; ".join(f"**{m}**: {v}" for m, v in r["systems"].items()),
        "",
        md_table(["mount", "n0 [N]", "H", "peak T [-]", "at [Hz]",
                  f"T at {r['high_hz']:g} Hz", "max E_fr/cycle [J]", "converged"],
                 rows),
        "",
        f"- Reference (original mount, no friction): peak {ref['peak']:.4g} at "
        f"{ref['peak_freq_hz']:.3g} Hz; T at {r['high_hz']:g} Hz = "
        f"{ref['t_high']:.3g}.",
        f"- Good halved design of the list (lowest peak with T at {r['high_hz']:g} Hz "
        f"not above the reference): n0 = {best['n0_N']:g} N, peak "
        f"{best['peak']:.4g} at {best['peak_freq_hz']:.3g} Hz, "
        f"{100 * r['best_halved_peak_reduction']:.1f} % below the reference; lower "
        f"than the reference on {100 * r['best_halved_lower_fraction']:.0f} % of the "
        f"band (log grid), higher on {r['best_halved_higher_hz'] or 'no interval'} Hz.",
        f"- Smallest friction energy per cycle over all points: "
        f"{r['e_fr_min_J']:.3g} J (must be >= 0).",
    ]
    lines += notes_md(r)
    lines += [""] + [f"![{f}]({f})" for f in figs] + [""]
    return "\n".join(lines)
