"""Study ``six-dof``: rigid engine on three mounts, the six responses against n0
(thesis Figs. 4.11-4.44): mount deflection input for lambda 1 and 1.2, the engine's
own excitation, and mount 3 relocated so that its friction element works."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import drymount.hbm as hbm
from drymount.io import atomic_write_text, write_csv
from drymount.studies.common import (
    ENGINE_EXCITATION,
    DesignResult,
    engine_excited,
    friction_axes,
    friction_energy,
    friction_template,
    hbm_curve,
    load_system,
    mount_position,
    peak,
    ratio,
    relocate_mount,
    with_friction_of,
    with_normal_force,
    with_stiffness_factor,
)
from drymount.studies.output import (
    DPI_SIX_PANEL,
    log_axes,
    md_table,
    md_text,
    n0_colors,
    new_figure,
    notes_md,
    plot_branch,
    progress_bar,
    save_fig,
    write_curves,
)
from drymount.fmu_src.mount_law import AXES
from drymount.hbm.system import Excitation, System

if TYPE_CHECKING:
    from matplotlib.figure import Figure

SIX_DOF_BAND_HZ = (2.0, 40.0)
SIX_DOF_ENGINE_BAND_HZ = (2.0, 60.0)
SIX_DOF_FORCES_N = (0.0, 100.0, 250.0, 500.0)
SIX_DOF_FORCES_QUICK_N = (0.0, 250.0)
SIX_DOF_HARMONICS = 3
SIX_DOF_HARMONICS_QUICK = 1
SIX_DOF_LAMBDAS = (1.0, 1.2)
#: The design the thesis recommends (Sec. 4.5: "250 N gives quite good results").
SIX_DOF_GOOD_N0 = 250.0
#: Mount moved so that its friction element (along z) sees the rotation beta: from
#: (0, -0.25, -0.5) m (Table 4.1) to x = +0.4 m. A point at a moves along z by
#: -beta * a_x under a rotation beta about y (t + theta x a, eq. 2.9), so at x = 0
#: beta cannot move the element; at x = 0.4 m it moves it by 0.4 m per rad.
#: Mount deflection input of the six-dof study, m: a sine along x, y and z at once, in
#: phase. The presets move the chassis along z only (0.0035 m, thesis Sec. 4.5); by
#: the symmetry of Table 4.1 that leaves x, beta and gamma at rest, while the
#: thesis's Figs. 4.11-4.34 show all six responses. With our assumed damping (3 %)
#: 3.5 mm along all three axes drives the rotations past 0.1 rad, outside the
#: small-rotation model (eq. 2.9), so we use 1 mm per axis.
SIX_DOF_BASE_AMPLITUDE = (0.001, 0.001, 0.001)
#: Normal forces under engine excitation, N: its mount deflections are about 0.5 mm
#: (kf u of about 30 N), so only n0 below about 30 N lets the contacts slip.
SIX_DOF_ENGINE_FORCES_N = (0.0, 2.0, 5.0, 10.0, 20.0)
SIX_DOF_ENGINE_FORCES_QUICK_N = (0.0, 10.0)
#: Normal force of the relocation comparison, N (slips under engine excitation).
RELOCATION_N0 = 2.0
RELOCATED_MOUNT = 2
RELOCATED_POSITION = (0.4, -0.25, -0.5)

DOF_UNITS = {"x": "m", "y": "m", "z": "m", "alpha": "rad", "beta": "rad",
             "gamma": "rad"}

MOUNTS = ("original", "halved")
POSITIONS = ("table_4_1", "relocated")


def _six_dof_systems() -> dict[tuple[float, str], System]:
    """(lambda, mount) -> base-excited 6-DOF system."""
    base = {1.0: load_system("six_dof_original"), 1.2: load_system("six_dof_lambda12")}
    halved_1 = load_system("six_dof_halved")
    template = friction_template([halved_1, *base.values()])
    exc = Excitation("base", np.array(SIX_DOF_BASE_AMPLITUDE))
    out = {}
    for lam, s in base.items():
        out[(lam, "original")] = with_friction_of(s, template).with_excitation(exc)
        # halved: the preset for lambda = 1; the same stiffness factor for 1.2
        out[(lam, "halved")] = with_friction_of(
            halved_1 if lam == 1.0 else with_stiffness_factor(s, 0.5), template
        ).with_excitation(exc)
    return out


@dataclass
class _Run:
    """Settings of one six-dof run and what its curves report."""

    H: int
    forces: tuple
    lambdas: tuple
    engine_forces: tuple
    systems: dict
    tick: object  # advances the progress bar by one curve
    failures: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    def curve(self, system: System, band, case: dict) -> DesignResult:
        self.tick()
        return hbm_curve(system, band, self.H, {**case, "H": self.H}, self.failures,
                         self.notes, ds_max=None)


def _base_curves(run: _Run) -> list[DesignResult]:
    """Part 1: mount deflection input, every lambda, mount and n0."""
    return [run.curve(with_normal_force(run.systems[(lam, m)], n0), SIX_DOF_BAND_HZ,
                      {"part": "base", "lambda": lam, "mount": m, "n0_N": n0})
            for lam in run.lambdas for m in MOUNTS for n0 in run.forces]


def _engine_curves(run: _Run) -> list[DesignResult]:
    """Part 2: engine excitation, lambda = 1, every mount and engine n0."""
    return [run.curve(with_normal_force(engine_excited(run.systems[(1.0, m)]), n0),
                      SIX_DOF_ENGINE_BAND_HZ,
                      {"part": "engine", "lambda": 1.0, "mount": m, "n0_N": n0})
            for m in MOUNTS for n0 in run.engine_forces]


def _relocated_system(run: _Run, position: str) -> System:
    s = engine_excited(run.systems[(1.0, "original")])
    if position == "relocated":
        s = relocate_mount(s, RELOCATED_MOUNT, RELOCATED_POSITION)
    return s


def _add_mount_work(c: DesignResult, system: System) -> None:
    """Friction energy per cycle and slip fraction of the relocated mount's element
    (zeros without one)."""
    for i, j in friction_axes(system):
        if i == RELOCATED_MOUNT:
            work = friction_energy(system, c.fr, i, j)
            c.extra["e_fr_mount_J"] = work.energy
            c.extra["slip_fraction"] = work.slip_fraction
    if "e_fr_mount_J" not in c.extra:
        zeros = np.zeros(len(c.fr.freq_hz))
        c.extra["e_fr_mount_J"], c.extra["slip_fraction"] = zeros, zeros


def _relocation_curves(run: _Run) -> tuple[list[DesignResult], dict]:
    """Part 3: mount 3 at Table 4.1 and relocated, n0 = 0 and RELOCATION_N0.
    Returns the curves and the undamped natural frequencies (Hz) per position."""
    curves, nat = [], {}
    for pos in POSITIONS:
        s = _relocated_system(run, pos)
        nat[pos] = hbm.natural_frequencies(s)[0].tolist()
        for n0 in (0.0, RELOCATION_N0):
            sn = with_normal_force(s, n0)
            c = run.curve(sn, SIX_DOF_ENGINE_BAND_HZ, {
                "part": "relocation", "lambda": 1.0, "mount": "original",
                "position": pos, "n0_N": n0})
            _add_mount_work(c, sn)
            curves.append(c)
    return curves, nat


def _curve_peaks(c: DesignResult, dof_names) -> dict:
    d = {}
    for j, name in enumerate(dof_names):
        pk = peak(c.fr.freq_hz, np.asarray(c.fr.amplitude)[:, j])
        d[f"{name}_peak"] = pk.value
        d[f"{name}_peak_hz"] = pk.freq_hz
    return d


def _cases(curves: list[DesignResult], dofs) -> list[dict]:
    return [{**c.case, **_curve_peaks(c, dofs), "success": bool(c.fr.success),
             "seconds": c.seconds, "n_points": len(c.fr.freq_hz)} for c in curves]


def _find(cases: list[dict], **kw) -> dict:
    return next(x for x in cases if all(x.get(k) == v for k, v in kw.items()))


def _peak_ratios(a: dict, b: dict, dofs) -> dict:
    """{dof: peak of a / peak of b}."""
    return {d: ratio(a[f"{d}_peak"], b[f"{d}_peak"]) for d in dofs}


def _base_effects(run: _Run, base_cases, dofs, good: float) -> tuple[dict, dict]:
    """Good design / original per lambda, and lambda 1.2 / lambda 1 per design."""
    good_ratio = {}
    for lam in run.lambdas:
        ref = _find(base_cases, **{"lambda": lam, "mount": "original", "n0_N": 0.0})
        g = _find(base_cases, **{"lambda": lam, "mount": "halved", "n0_N": good})
        good_ratio[lam] = _peak_ratios(g, ref, dofs)
    lam_effect = {}
    if 1.2 in run.lambdas:
        for m in MOUNTS:
            for n0 in run.forces:
                a = _find(base_cases, **{"lambda": 1.0, "mount": m, "n0_N": n0})
                b = _find(base_cases, **{"lambda": 1.2, "mount": m, "n0_N": n0})
                lam_effect[f"{m}/{n0:g}N"] = _peak_ratios(b, a, dofs)
    return good_ratio, lam_effect


def _engine_effects(run: _Run, engine_cases, dofs) -> dict:
    """Peak of each engine-excited design over the original mounts without friction."""
    eref = _find(engine_cases, mount="original", n0_N=0.0)
    return {f"{m}/{n0:g}N": _peak_ratios(_find(engine_cases, mount=m, n0_N=n0), eref,
                                         dofs)
            for m in MOUNTS for n0 in run.engine_forces}


def _relocation_effects(reloc_cases, reloc_curves) -> tuple[dict, dict]:
    """Per position: 1 - beta peak(RELOCATION_N0) / beta peak(0), and the largest
    friction energy per cycle of the relocated mount at RELOCATION_N0."""
    beta_red, e3 = {}, {}
    for pos in POSITIONS:
        b0 = _find(reloc_cases, position=pos, n0_N=0.0)["beta_peak"]
        b1 = _find(reloc_cases, position=pos, n0_N=RELOCATION_N0)["beta_peak"]
        beta_red[pos] = 1.0 - ratio(b1, b0)
        c = next(c for c in reloc_curves if c.case["position"] == pos
                 and c.case["n0_N"] == RELOCATION_N0)
        e3[pos] = float(np.nanmax(c.extra["e_fr_mount_J"]))
    return beta_red, e3


def _engine_values(engine=ENGINE_EXCITATION) -> dict:
    return {"u_z_kg_m": engine.unbalance_z, "u_beta_kg_m2": engine.unbalance_roll,
            "m_rec_kg": engine.m_rec, "crank_radius_m": engine.crank_radius,
            "rod_length_m": engine.rod_length}


def _write_tables(curves: list[DesignResult], cases: list[dict], dofs,
                 out: Path) -> None:
    write_curves(out / "six_dof_curves.csv",
                 "6-DOF HBM curves; part base: mount deflection input, amplitudes in "
                 "m and rad; part engine/relocation: engine excitation; n0 in N; "
                 "e_fr_mount_J: friction energy per cycle of the relocated mount (J)",
                 curves)
    keys = (["part", "lambda", "mount", "position", "n0_N", "H"]
            + [f"{d}_{k}" for d in dofs for k in ("peak", "peak_hz")]
            + ["success", "seconds", "n_points"])
    write_csv(out / "six_dof_peaks.csv", keys,
              [[x.get(k, "") for k in keys] for x in cases],
              comment="peak fundamental amplitude per DOF (m or rad) and its "
                      "frequency (Hz)")


def run_six_dof(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """6-DOF rigid engine: the six responses against n0 (thesis Figs. 4.11-4.44).

    Three parts, HBM with H = ``SIX_DOF_HARMONICS``:

    1. base excitation (presets ``six_dof_original``, ``six_dof_halved``,
       ``six_dof_lambda12`` and the latter with half stiffness, input
       ``SIX_DOF_BASE_AMPLITUDE``), n0 in ``SIX_DOF_FORCES_N``, lambda = 1 and 1.2
       (Figs. 4.11-4.34);
    2. engine excitation ``ENGINE_EXCITATION`` (second-order force along z and roll
       moment about y, ``hbm.crank``), original and halved mounts, lambda = 1, n0 in
       ``SIX_DOF_ENGINE_FORCES_N`` (Figs. 4.35-4.40);
    3. mount ``RELOCATED_MOUNT`` moved to ``RELOCATED_POSITION`` under engine
       excitation, original mounts, n0 = 0 and ``RELOCATION_N0``: the beta response
       and the friction energy per cycle of that mount (Figs. 4.41-4.44).

    Returns
    -------
    dict
        ``base_cases``, ``engine_cases``, ``relocation_cases`` (one dict per curve with
        the design and ``<dof>_peak``, ``<dof>_peak_hz``), ``good_design_ratio``
        {lambda: {dof: peak(halved, 250 N) / peak(original, 0 N)}},
        ``lambda_effect`` {mount/n0: {dof: peak(1.2) / peak(1.0)}},
        ``engine_ratio`` {mount/n0: {dof: peak / peak(original, 0 N)}},
        ``beta_reduction`` {position: 1 - beta peak(RELOCATION_N0) / beta peak(0)},
        ``mount3_energy_max_J`` {position: max energy per cycle at RELOCATION_N0},
        ``natural_frequencies_hz`` {position: (6,)}, ``notes`` (restarted curves),
        ``failures``, ``files``.
    """
    out = Path(out_dir)
    lambdas = (1.0,) if quick else SIX_DOF_LAMBDAS
    forces = SIX_DOF_FORCES_QUICK_N if quick else SIX_DOF_FORCES_N
    e_forces = SIX_DOF_ENGINE_FORCES_QUICK_N if quick else SIX_DOF_ENGINE_FORCES_N
    n_curves = (len(lambdas) * len(MOUNTS) * len(forces) + len(MOUNTS) * len(e_forces)
                + 2 * len(POSITIONS))
    bar = progress_bar(range(n_curves), "six-dof", progress)
    ticks = iter(bar)
    run = _Run(H=SIX_DOF_HARMONICS_QUICK if quick else SIX_DOF_HARMONICS,
               forces=forces, lambdas=lambdas, engine_forces=e_forces,
               systems=_six_dof_systems(), tick=lambda: next(ticks, None))
    base_curves, engine_curves = _base_curves(run), _engine_curves(run)
    reloc_curves, nat = _relocation_curves(run)
    bar.close()
    s0 = run.systems[(1.0, "original")]
    dofs = list(s0.dof_names)
    base_cases, engine_cases, reloc_cases = (
        _cases(base_curves, dofs), _cases(engine_curves, dofs),
        _cases(reloc_curves, dofs))
    good = SIX_DOF_GOOD_N0 if SIX_DOF_GOOD_N0 in forces else max(forces)
    good_ratio, lam_effect = _base_effects(run, base_cases, dofs, good)
    beta_red, e3 = _relocation_effects(reloc_cases, reloc_curves)
    result = {
        "study": "six-dof", "harmonics": run.H, "normal_forces_N": list(forces),
        "lambdas": list(lambdas), "good_n0_N": good,
        "base_cases": base_cases, "engine_cases": engine_cases,
        "relocation_cases": reloc_cases,
        "good_design_ratio": good_ratio, "lambda_effect": lam_effect,
        "engine_ratio": _engine_effects(run, engine_cases, dofs),
        "engine_forces_N": list(e_forces),
        "relocation_n0_N": RELOCATION_N0, "base_amplitude_m": SIX_DOF_BASE_AMPLITUDE,
        "notes": run.notes,
        "beta_reduction": beta_red, "mount3_energy_max_J": e3,
        "e_fr_min_J": min(float(np.nanmin(c.extra["e_fr_mount_J"]))
                          for c in reloc_curves),
        "natural_frequencies_hz": nat,
        "mount_positions_m": [mount_position(e).tolist() for e in s0.elements],
        "relocated_from_m": mount_position(s0.elements[RELOCATED_MOUNT]).tolist(),
        "relocated_to_m": list(RELOCATED_POSITION),
        "friction_axes": [(s0.elements[i].name, AXES[j]) for i, j in friction_axes(
            with_normal_force(s0, 1.0))],
        "engine_excitation": _engine_values(),
        "failures": run.failures,
    }
    _write_tables(base_curves + engine_curves + reloc_curves,
                  base_cases + engine_cases + reloc_cases, dofs, out)
    figs = _plot_six_dof(base_curves, engine_curves, reloc_curves, forces, lambdas,
                         dofs, out)
    atomic_write_text(out / "summary.md", _summary_six_dof(result, figs, dofs))
    result["files"] = sorted(p.name for p in out.iterdir())
    return result


def _six_panel(curves, forces, dofs, title, ref=None) -> Figure:
    colors = n0_colors(forces)
    fig = new_figure(figsize=(11, 6))
    axes = [fig.add_subplot(2, 3, k + 1) for k in range(6)]
    for j, (ax, d) in enumerate(zip(axes, dofs, strict=True)):
        if ref is not None:
            ax.plot(ref.fr.freq_hz, np.asarray(ref.fr.amplitude)[:, j], color="0.6",
                    lw=3, alpha=0.7, label="original, no friction")
        for c in curves:
            n0 = c.case["n0_N"]
            plot_branch(ax, c.fr.freq_hz, np.asarray(c.fr.amplitude)[:, j],
                         c.fr.stable, color=colors[n0], lw=1.2,
                         label=f"n0 = {n0:g} N" if n0 else "no friction")
        log_axes(ax, ylabel=f"{d} amplitude [{DOF_UNITS.get(d, '')}]")
        ax.set_title(d, fontsize=9)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


def _plot_six_dof(base_curves, engine_curves, reloc_curves, forces, lambdas, dofs,
                  out: Path) -> list[str]:
    names = []
    figs_no = {(1.0, "original"): "4.11-4.16", (1.0, "halved"): "4.17-4.22",
               (1.2, "original"): "4.23-4.28", (1.2, "halved"): "4.29-4.34"}
    for lam in lambdas:
        ref = next(c for c in base_curves if c.case["lambda"] == lam
                   and c.case["mount"] == "original" and c.case["n0_N"] == 0.0)
        for m in ("original", "halved"):
            cs = [c for c in base_curves if c.case["lambda"] == lam
                  and c.case["mount"] == m]
            fig = _six_panel(cs, forces, dofs,
                             f"6 DOF, mount deflection input, lambda = {lam:g}, {m} "
                             f"mounts, HBM H = {cs[0].case['H']} (cf. thesis Figs. "
                             f"{figs_no[(lam, m)]})",
                             ref=ref if m == "halved" else None)
            name = f"six_dof_base_lambda{str(lam).replace('.', '')}_{m}.png"
            save_fig(fig, out / name, dpi=DPI_SIX_PANEL)
            names.append(name)
    eref = next(c for c in engine_curves if c.case["mount"] == "original"
                and c.case["n0_N"] == 0.0)
    e_forces = sorted({c.case["n0_N"] for c in engine_curves})
    for m in ("original", "halved"):
        cs = [c for c in engine_curves if c.case["mount"] == m]
        fig = _six_panel(cs, e_forces, dofs,
                         f"6 DOF, engine excitation (2nd-order force z, roll moment "
                         f"about y), {m} mounts, lambda = 1 (cf. thesis Figs. "
                         "4.35-4.40)", ref=eref if m == "halved" else None)
        name = f"six_dof_engine_{m}.png"
        save_fig(fig, out / name, dpi=DPI_SIX_PANEL)
        names.append(name)
    fig = new_figure(figsize=(10, 4))
    ax1, ax2 = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    jb = dofs.index("beta")
    style = {"table_4_1": ("tab:blue", "mount 3 at Table 4.1"),
             "relocated": ("tab:red", f"mount 3 at {RELOCATED_POSITION}")}
    for c in reloc_curves:
        color, label = style[c.case["position"]]
        n0 = c.case["n0_N"]
        ls = "-" if n0 else ":"
        plot_branch(ax1, c.fr.freq_hz, np.asarray(c.fr.amplitude)[:, jb], c.fr.stable,
                     color=color, lw=1.4, ls=ls, label=f"{label}, n0 = {n0:g} N")
        if n0:
            ax2.plot(c.fr.freq_hz, c.extra["e_fr_mount_J"], color=color, lw=1.4,
                     label=f"{label}, n0 = {n0:g} N")
    log_axes(ax1, ylabel="beta amplitude [rad]",
              title="rotation beta under engine excitation (cf. Figs. 4.39, 4.43)")
    ax1.legend(fontsize=7)
    log_axes(ax2, ylabel="friction energy per cycle, mount 3 [J]", ylog=False,
              title="does mount 3's friction element work? (cf. Fig. 4.44)")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    save_fig(fig, out / "six_dof_relocation.png")
    names.append("six_dof_relocation.png")
    return names


def _summary_six_dof(r, figs, dofs) -> str:
    """The study's summary.md: one section per part, the table of all curves, the
    notes and the figures."""
    lines = [
        "# Study six-dof: rigid engine on three mounts",
        "",
        f"HBM with H = {r['harmonics']}; n0 in {md_text(r['normal_forces_N'])} N on "
        "every "
        f"friction element ({', '.join(f'{m} {a}' for m, a in r['friction_axes'])}); "
        f"mount positions {md_text(r['mount_positions_m'])} m (Table 4.1).",
        "",
    ]
    lines += _base_section(r, dofs) + _engine_section(r, dofs)
    lines += _relocation_section(r) + _cases_section(r, dofs)
    lines += notes_md(r)
    lines += [""] + [f"![{f}]({f})" for f in figs] + [""]
    return "\n".join(lines)


def _base_section(r, dofs) -> list[str]:
    """The mount deflection input: the good design's ratios, lambda's effect."""
    lines = [
        "## Mount deflection input (Figs. 4.11-4.34)",
        "",
        f"Chassis attachment points moved by {md_text(r['base_amplitude_m'])} m "
        "(x, y, z) "
        "sin(omega t), in phase.",
        "",
        f"Peak ratio of the good design (halved mounts, n0 = {r['good_n0_N']:g} N) to "
        "the original mounts without friction, per DOF (< 1: lower):",
        "",
        md_table(["lambda"] + dofs,
                  [[lam] + [v[d] for d in dofs]
                   for lam, v in r["good_design_ratio"].items()]),
        "",
    ]
    if r["lambda_effect"]:
        lines += ["Effect of lambda: peak(lambda = 1.2) / peak(lambda = 1) per DOF:",
                  "",
                  md_table(["design"] + dofs,
                            [[k] + [v[d] for d in dofs]
                             for k, v in r["lambda_effect"].items()]), ""]
    return lines


def _engine_section(r, dofs) -> list[str]:
    """The engine excitation: its unbalance vector and the designs' ratios."""
    ex = r["engine_excitation"]
    return [
        "## Engine excitation (Figs. 4.35-4.40)",
        "",
        f"Unbalance vector U = (0, 0, {ex['u_z_kg_m']:.4g} kg m, 0, "
        f"{ex['u_beta_kg_m2']:.4g} kg m^2, 0), force = U omega^2 sin(omega t): "
        f"second-order free force m_rec R^2 / L and inertia roll torque m_rec R^2 / 2 "
        f"of an inline four with m_rec = {ex['m_rec_kg']:g} kg, R = "
        f"{ex['crank_radius_m']:g} m, L = {ex['rod_length_m']:g} m, both in phase.",
        "",
        f"n0 in {r['engine_forces_N']} N (the engine excitation deflects the mounts "
        "by about 0.5 mm, kf u of about 30 N, so larger n0 would only stick). Peak "
        "ratio to the original mounts without friction, per DOF (< 1: lower):",
        "",
        md_table(["design"] + dofs, [[k] + [v[d] for d in dofs]
                                      for k, v in r["engine_ratio"].items()]),
        "",
    ]


def _relocation_section(r) -> list[str]:
    """Mount 3 relocated: the beta peak's reduction, energies, natural frequencies."""
    return [
        "## Relocating mount 3 (Figs. 4.41-4.44)",
        "",
        f"Mount 3 moved from ({md_text(r['relocated_from_m'])}) m to "
        f"({md_text(r['relocated_to_m'])}) m; "
        "original mounts, engine excitation.",
        "",
        md_table(["mount 3 at", "beta peak reduction by n0 = "
                   f"{r['relocation_n0_N']:g} N [%]", "max friction energy/cycle [J]",
                   "undamped natural frequencies [Hz]"],
                  [[pos, 100 * r["beta_reduction"][pos],
                    r["mount3_energy_max_J"][pos],
                    ", ".join(f"{f:.2f}" for f in r["natural_frequencies_hz"][pos])]
                   for pos in ("table_4_1", "relocated")]),
        "",
        f"Smallest friction energy per cycle: {r['e_fr_min_J']:.3g} J (must be >= 0).",
    ]


def _cases_section(r, dofs) -> list[str]:
    """Every curve of the study with its peak amplitudes."""
    rows = [[x.get("part"), x.get("lambda"), x.get("mount"), x.get("position", ""),
             x["n0_N"]] + [x[f"{d}_peak"] for d in dofs] + [
             "yes" if x["success"] else "NO"]
            for x in r["base_cases"] + r["engine_cases"] + r["relocation_cases"]]
    return ["", "## All curves: peak amplitudes (m, rad)", "",
            md_table(["part", "lambda", "mount", "position", "n0 [N]"] + dofs
                     + ["converged"], rows)]

