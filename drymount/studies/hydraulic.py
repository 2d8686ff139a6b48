"""Study ``hydraulic``: the comparison the thesis argues (issue 28 item 5).

In the single-DOF, quarter-car and 6-DOF systems, side by side:

(a) ``original``: the original elastomer mount (preset ``*_original``, no friction);
(b) ``friction``: the softened friction-damped mount (preset ``*_halved``) at the
    thesis design with the best n0 (single DOF and quarter car: the rule of the
    n0 family studies, :func:`drymount.studies.family._best_halved`, over their
    normal forces; 6 DOF: the thesis's 250 N, ``six_dof.SIX_DOF_GOOD_N0``);
(c) ``hydraulic``: the linear inertia-track + decoupler mount of the presets
    ``sdof_hydraulic``, ``quarter_car_hydraulic``, ``six_dof_hydraulic`` (their values
    in ONE place, ``sdof_hydraulic.toml``; :func:`hydraulic_mount_for` reads them) on
    every axial mount axis, and ``hydraulic_closed``: the same preset with its
    decoupler closed (inertia track only: ``--set ...hydraulic.I_d=0``, the law's
    "no decoupler", :data:`DECOUPLER_CLOSED`). Colgate et al. (J. Sound Vib. 184(3),
    1995) model a production mount by exactly these two linear models: decoupler
    open for small (engine-induced) amplitudes, closed for large (road-induced,
    resonant) ones; the decoupler's gap limit that switches between them is nonlinear.

(a) and (b) are harmonic-balance curves (continuation, then read on a common log
grid). (c) are the HBM of the loaded hydraulic presets solved on the grid
(:func:`hbm_transmissibility`; the fluid enters the HBM exactly per harmonic and the
mount is linear, so one harmonic is the exact steady state), cross-checked against
the exact linear FRF of the original system with the mount's complex stiffness
``K*(omega)`` (``fmu_src.linear_branches.hydraulic_complex_stiffness``) in place of
the axial ``k1 + i omega c`` (:func:`complex_frf`; the largest difference, relative
to the peak, is in the summary). Outputs: the
transmissibility over the band, |K*| and loss angle over frequency of one mount
axis, the static sag under the engine's weight; CSV, plots and ``summary.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from drymount.fmu_src.mount_law import AXES
from drymount.fmu_src.linear_branches import (HydraulicParameters,
                                              hydraulic_complex_stiffness,
                                              hydraulic_notch_peak)
from drymount.hbm.system import System
from drymount.io import atomic_write_text, write_csv
from drymount.studies.common import (StudyError, friction_axes, friction_template,
                                     hbm_curve, load_system, peak, value_at,
                                     with_friction_of, with_normal_force)
from drymount.studies.family import _best_halved
from drymount.studies.normal_force import NORMAL_FORCE_SPEC
from drymount.studies.output import log_axes, md_table, new_figure, save_fig
from drymount.studies.quarter_car import QUARTER_CAR_SPEC
from drymount.studies.six_dof import SIX_DOF_GOOD_N0

#: Common band of the comparison, Hz (engine orders up to 60 Hz).
BAND_HZ = (1.0, 60.0)
GRID_POINTS, GRID_POINTS_QUICK = 2000, 400
HARMONICS, HARMONICS_QUICK = 5, 1
#: Engine orders read off the curves, Hz: the second order at 900 rpm idle and the
#: fourth order at idle (= second order at 1800 rpm).
ORDERS_HZ = {"idle (2nd order, 900 rpm)": 30.0, "4th order at idle": 60.0}
#: Deflection amplitudes of the dynamic-stiffness curves, m.
DS_AMPLITUDES_M = (1e-4, 1e-3)
GRAVITY = 9.81
MOUNTS = ("original", "friction", "hydraulic", "hydraulic_closed")
HYDRAULIC_MOUNTS = ("hydraulic", "hydraulic_closed")


@dataclass(frozen=True)
class SystemSpec:
    """One system of the study: its presets and how the best n0 is found."""

    key: str
    original: str
    halved: str
    model: str                      # config model name (VERTICAL of drymount.config)
    forces: tuple | None            # n0 candidates (None: fixed n0)
    forces_quick: tuple | None
    fixed_n0: float | None = None
    hydraulic: str = ""             # the hydraulic preset (decoupler open)


#: The ``--set`` overrides that close the decoupler of a hydraulic preset (``I_d =
#: 0``: no decoupler, the law's convention; its ``R_d`` is then unused), per model.
DECOUPLER_CLOSED = {"sdof": ("mount.hydraulic.I_d=0",),
                    "quarter_car": ("mount.hydraulic.I_d=0",),
                    "rigid_engine": ("mounts[*].axial.hydraulic.I_d=0",)}

SYSTEMS = (
    SystemSpec("sdof", "sdof_original", "sdof_halved", "sdof",
               NORMAL_FORCE_SPEC.forces, NORMAL_FORCE_SPEC.forces_quick,
               hydraulic="sdof_hydraulic"),
    SystemSpec("quarter_car", "quarter_car_original", "quarter_car_halved",
               "quarter_car", QUARTER_CAR_SPEC.forces, QUARTER_CAR_SPEC.forces_quick,
               hydraulic="quarter_car_hydraulic"),
    SystemSpec("six_dof", "six_dof_original", "six_dof_halved", "rigid_engine",
               None, None, fixed_n0=SIX_DOF_GOOD_N0, hydraulic="six_dof_hydraulic"),
)

def _spec(system: str) -> SystemSpec:
    spec = {s.key: s for s in SYSTEMS}.get(system)
    if spec is None:
        raise StudyError(f"system = {system!r}: must be one of "
                         f"{', '.join(s.key for s in SYSTEMS)}")
    return spec


def hydraulic_systems(system: str) -> dict:
    """{"hydraulic": System, "hydraulic_closed": System} of ``system`` (``"sdof"``,
    ``"quarter_car"`` or ``"six_dof"``): its hydraulic preset loaded by
    ``drymount.config.load_preset``, and the same with :data:`DECOUPLER_CLOSED`
    applied by the ``--set`` mechanism (``drymount.paths.override_config``)."""
    from drymount.config import load_preset
    from drymount.paths import override_config

    spec = _spec(system)
    cfg = load_preset(spec.hydraulic)
    closed = override_config(cfg, DECOUPLER_CLOSED[cfg.model])
    return {"hydraulic": cfg.system, "hydraulic_closed": closed.system}


def mount_parameters(system: System) -> HydraulicParameters:
    """The hydraulic mount of ``system`` as :class:`HydraulicParameters` (rubber
    ``kr, br`` = the axis's ``k1, c``): that of every axis with the fluid path, which
    must all be the same linear mount (one design per system)."""
    found = {}
    for i, e in enumerate(system.elements):
        for j in e.active_axes:
            p = e.params.axes[j]
            if p.has_hydraulic:
                if p.law != "linear" or p.friction or p.has_maxwell:
                    raise StudyError(f"mount {i + 1} {AXES[j]} axis: the hydraulic "
                                     f"mount must be linear without friction or "
                                     f"Maxwell branches, got law {p.law!r}")
                found[(i, j)] = p.hydraulic._replace(kr=p.k1, br=p.c)
    if not found or len(set(found.values())) != 1:
        raise StudyError(f"{len(set(found.values()))} different hydraulic mounts on "
                         f"the axes {sorted(found)}: the study needs exactly one")
    return next(iter(found.values()))


def hydraulic_mount_for(system: str) -> HydraulicParameters:
    """The hydraulic mount (decoupler open) of ``system`` (``"sdof"``,
    ``"quarter_car"`` or ``"six_dof"``), read from its preset (values: the ONE place
    ``drymount/presets/sdof_hydraulic.toml``, copied into the other two; see its
    header for their source and the notch and peak they give)."""
    return mount_parameters(hydraulic_systems(system)["hydraulic"])


def decoupler_closed(p: HydraulicParameters) -> HydraulicParameters:
    """``p`` with the decoupler closed (``I_d = 0``: the inertia track only; ``R_d``
    unused), the large-amplitude linear model of Colgate et al. (1995); what
    :data:`DECOUPLER_CLOSED` does to a preset."""
    return p._replace(I_d=0.0)


# ======================================================================================
# The exact linear FRF with complex mount stiffnesses
# ======================================================================================


def axis_stiffness(system: System, hydraulic: HydraulicParameters | None,
                   omega: float) -> np.ndarray:
    """Complex stiffness (n_el, 3), N/m, of every mount axis at ``omega``: the
    linearised ``k1 + i omega c`` (friction free), the axial axis (index 0) replaced
    by the hydraulic mount's K* when ``hydraulic`` is given."""
    out = np.array([[p.k1 + 1j * omega * p.c for p in e.params.axes]
                    for e in system.elements], dtype=complex)
    if hydraulic is not None:
        out[:, 0] = hydraulic_complex_stiffness(hydraulic, omega)
    return out


@dataclass(frozen=True)
class LinearResponse:
    """Exact linear response on a frequency grid.

    ``Q`` (n_f, n_dof) complex amplitudes (m, rad); ``transmissibility`` (n_f,) as
    the system's ``Transmissibility`` defines it."""

    freq_hz: np.ndarray
    Q: np.ndarray
    transmissibility: np.ndarray


def _one_point(system: System, ks: np.ndarray, w: float):
    A = system.K - w * w * system.M + 1j * w * system.C
    exc = system.excitation
    y = np.asarray(exc.amplitude, dtype=complex) if exc.kind == "base" else None
    rhs = (np.zeros(system.n_dof, complex) if y is None
           else (system.Kb + 1j * w * system.Cb) @ y)
    for ie, e in enumerate(system.elements):
        A = A + e.B.T @ (ks[ie][:, None] * e.B)
        if y is not None:
            rhs = rhs + e.B.T @ (ks[ie] * (e.G @ y))
    if exc.kind != "base":
        rhs = rhs + exc.force_amplitude(w)
    q = np.linalg.solve(A, rhs)
    return q, y


def _scalar_t(system: System, ks, q, y, w: float) -> float:
    t = system.transmissibility
    if t.kind == "force":
        f = sum(ks[i][j] * (system.elements[i].B[j] @ q
                            - (0 if y is None else system.elements[i].G[j] @ y))
                for i, j in t.forces)
        return float(abs(f) / system.excitation.scalar_amplitude(w))
    ref = (np.linalg.norm(system.excitation.amplitude) if t.reference is None
           else abs(q[t.reference]))
    return float(abs(q[t.dof]) / ref)


def complex_frf(system: System, freqs_hz, hydraulic: HydraulicParameters | None
                ) -> LinearResponse:
    """``(K - w^2 M + i w C + sum B^T diag(K*_e(w)) B) Q = F(w)`` (force, unbalance)
    or ``(Kb + i w Cb) Y + sum B^T diag(K*_e) G Y`` (base), solved per frequency;
    the mounts' complex stiffness from :func:`axis_stiffness`."""
    f = np.asarray(freqs_hz, dtype=float)
    Q = np.empty((f.size, system.n_dof), complex)
    T = np.empty(f.size)
    for i, fi in enumerate(f):
        w = 2.0 * np.pi * fi
        ks = axis_stiffness(system, hydraulic, w)
        Q[i], y = _one_point(system, ks, w)
        T[i] = _scalar_t(system, ks, Q[i], y, w)
    return LinearResponse(f, Q, T)


# ======================================================================================
# The three mounts of one system
# ======================================================================================


@dataclass
class SystemCase:
    """One system's three mounts: systems, best n0, curves on the common grid."""

    spec: SystemSpec
    original: System
    friction: System
    hydraulic: dict               # hydraulic mount -> HydraulicParameters (presets')
    hydraulic_systems: dict       # hydraulic mount -> System (the loaded presets)
    frf_check: dict               # hydraulic mount -> max |T_hbm - T_frf| / max T_frf
    n0: float
    n0_rule: str
    freq_hz: np.ndarray
    transmissibility: dict        # mount -> (n_f,) on freq_hz
    peaks: dict                   # mount -> common.Peak (of the curve itself)
    failures: list
    hbm_curves: dict              # original/friction -> (freq_hz, T) as computed


def _systems(spec: SystemSpec) -> tuple[System, System]:
    orig, halved = load_system(spec.original), load_system(spec.halved)
    template = friction_template([halved, orig])
    return with_friction_of(orig, template), with_friction_of(halved, template)


def _curve_numbers(system, H, failures, case) -> dict:
    c = hbm_curve(system, BAND_HZ, H, case, failures, ds_max=None)
    pk = peak(c.fr.freq_hz, c.fr.transmissibility)
    return {**case, "peak": pk.value, "peak_freq_hz": pk.freq_hz,
            "t_high": value_at(c.fr.freq_hz, c.fr.transmissibility,
                               NORMAL_FORCE_SPEC.high_hz), "fr": c.fr}


def _best_n0(spec, orig, halved, H, quick, failures):
    """(n0, rule, {mount: curve numbers}) for the friction design."""
    ref = _curve_numbers(with_normal_force(orig, 0.0), H, failures,
                         {"mount": "original", "n0_N": 0.0, "H": H})
    if spec.fixed_n0 is not None:
        n0 = spec.fixed_n0
        best = _curve_numbers(with_normal_force(halved, n0), H, failures,
                              {"mount": "halved", "n0_N": n0, "H": H})
        return n0, "the thesis's recommended design (Sec. 4.5)", ref, best
    forces = spec.forces_quick if quick else spec.forces
    cases = [_curve_numbers(with_normal_force(halved, n0), H, failures,
                            {"mount": "halved", "n0_N": n0, "H": H})
             for n0 in forces if n0 > 0]
    best = _best_halved(cases, ref, H)
    rule = (f"lowest peak over n0 in {', '.join(f'{x:g}' for x in forces if x > 0)}"
            f" N keeping T at {NORMAL_FORCE_SPEC.high_hz:g} Hz at or below the "
            "original's (the n0 family studies' rule)")
    return best["n0_N"], rule, ref, best


def hbm_transmissibility(system: System, freqs_hz) -> np.ndarray:
    """Transmissibility (the system's definition) of the linear ``system`` at
    ``freqs_hz`` by :func:`drymount.hbm.solve_frequencies` with one harmonic: the
    hydraulic fluid enters the HBM exactly per harmonic, and a linear system's
    steady state under a sine is that sine, so H = 1 is the exact response."""
    import drymount.hbm as hbm

    r = hbm.solve_frequencies(system, freqs_hz, harmonics=1)
    if not r.success or r.n_points != len(freqs_hz):
        raise StudyError(f"HBM of the hydraulic system stopped after {r.n_points} "
                         f"of {len(freqs_hz)} frequencies: {r.message}")
    return np.asarray(r.transmissibility, dtype=float)


def _hydraulic_curves(spec: SystemSpec, orig: System, f: np.ndarray):
    """({mount: T}, {mount: params}, {mount: System}, {mount: check}) of (c), (c')."""
    systems = hydraulic_systems(spec.key)
    params = {m: mount_parameters(s) for m, s in systems.items()}
    T = {m: hbm_transmissibility(s, f) for m, s in systems.items()}
    lin = {m: complex_frf(with_normal_force(orig, 0.0), f, p).transmissibility
           for m, p in params.items()}
    check = {m: float(np.max(np.abs(T[m] - lin[m])) / np.max(lin[m])) for m in T}
    return T, params, systems, check


def run_system(spec: SystemSpec, quick: bool) -> SystemCase:
    """HBM curves of (a) and (b), the HBM of the hydraulic presets (c) on the
    common grid (checked against the exact FRF, :func:`complex_frf`)."""
    orig, halved = _systems(spec)
    H = HARMONICS_QUICK if quick else HARMONICS
    failures: list[str] = []
    n0, rule, ref, best = _best_n0(spec, orig, halved, H, quick, failures)
    f = np.geomspace(*BAND_HZ, GRID_POINTS_QUICK if quick else GRID_POINTS)
    T_hyd, params, systems, check = _hydraulic_curves(spec, orig, f)
    T = {"original": np.array([value_at(ref["fr"].freq_hz,
                                        ref["fr"].transmissibility, x) for x in f]),
         "friction": np.array([value_at(best["fr"].freq_hz,
                                        best["fr"].transmissibility, x) for x in f]),
         **T_hyd}
    peaks = {"original": peak(ref["fr"].freq_hz, ref["fr"].transmissibility),
             "friction": peak(best["fr"].freq_hz, best["fr"].transmissibility),
             **{m: peak(f, v) for m, v in T_hyd.items()}}
    curves = {m: (np.asarray(c["fr"].freq_hz), np.asarray(c["fr"].transmissibility))
              for m, c in (("original", ref), ("friction", best))}
    return SystemCase(spec, orig, with_normal_force(halved, n0), params, systems,
                      check, float(n0), rule, f, T, peaks, failures, curves)


def _characterised_axis(case: SystemCase) -> tuple[int, int]:
    """(mount, axis) of the dynamic-stiffness curves: the first axial friction axis
    (the first friction axis when none is axial)."""
    axes = friction_axes(case.friction)
    return next(((i, j) for i, j in axes if j == 0), axes[0])


@dataclass(frozen=True)
class StiffnessCurves:
    """|K*| (N/m) and loss angle (deg) over ``freq_hz`` per (mount, amplitude m)."""

    element: int
    axis: int
    freq_hz: np.ndarray
    K: dict          # (mount, amplitude) -> complex (n_f,)


def stiffness_curves(case: SystemCase) -> StiffnessCurves:
    """K* of the characterised axis: (a), (b) by ``hbm.characterise`` at
    :data:`DS_AMPLITUDES_M`, (c) in closed form (amplitude independent)."""
    from drymount.hbm.characterise import dynamic_stiffness

    i, j = _characterised_axis(case)
    f = case.freq_hz
    K = {}
    for mount, sys_ in (("original", case.original), ("friction", case.friction)):
        axis = sys_.elements[i].params.axes[j]
        if mount == "original":
            axis = replace(axis, friction=False, n0=0.0)
        m = dynamic_stiffness(axis, f, DS_AMPLITUDES_M)
        for a, X in enumerate(DS_AMPLITUDES_M):
            K[(mount, X)] = m.K[0, a]
    for m, p in case.hydraulic.items():
        kh = np.array(hydraulic_complex_stiffness(p, (2 * np.pi * f).tolist()))
        for X in DS_AMPLITUDES_M:
            K[(m, X)] = kh
    return StiffnessCurves(i, j, f, K)


def static_sag(case: SystemCase) -> dict:
    """Largest axial mount deflection (m, positive = compressed) under the engine's
    weight (g = :data:`GRAVITY`) per mount by ``hbm.static``: (a), (b) friction
    sliders relaxed (they carry no static force), (c) the hydraulic presets (the
    fluid's static stiffness ``Ap^2 / (C1 + C2)`` on the axial axes)."""
    from drymount.config.static import vertical_dofs
    from drymount.hbm.static import gravity_load, static_equilibrium

    load = gravity_load(case.original,
                        vertical_dofs(case.spec.model, case.original.dof_names),
                        GRAVITY)
    out = {}
    for mount, sys_ in (("original", case.original), ("friction", case.friction)):
        pt = static_equilibrium(with_normal_force(sys_, 0.0), load)
        out[mount] = float(np.max(np.abs(pt.deflection[:, 0])))
    for m, sys_ in case.hydraulic_systems.items():
        load_h = gravity_load(sys_, vertical_dofs(case.spec.model, sys_.dof_names),
                              GRAVITY)
        pt = static_equilibrium(sys_, load_h)
        out[m] = float(np.max(np.abs(pt.deflection[:, 0])))
    return out


def order_values(case: SystemCase) -> dict:
    """{order label: {mount: T}} at :data:`ORDERS_HZ`."""
    return {lab: {m: value_at(case.freq_hz, case.transmissibility[m], f)
                  for m in MOUNTS} for lab, f in ORDERS_HZ.items()}


def loss_extremes(sc: StiffnessCurves, case: SystemCase) -> dict:
    """Each hydraulic variant's notch and peak (lossless formulas, Hz), and every
    mount's loss angle (deg, at the larger amplitude) there and at its maximum
    (on the grid; a frequency outside the band reads the band's edge value)."""
    X = DS_AMPLITUDES_M[-1]
    marks = {}
    for m, p in case.hydraulic.items():
        wn, wp = hydraulic_notch_peak(p)
        marks[f"{m} notch"], marks[f"{m} peak"] = wn / (2 * np.pi), wp / (2 * np.pi)
    out = {"marks_hz": marks}
    for m in MOUNTS:
        ang = np.degrees(np.angle(sc.K[(m, X)]))
        out[m] = {"at": {k: value_at(sc.freq_hz, ang, f) for k, f in marks.items()},
                  "max": float(np.max(ang)),
                  "max_hz": float(sc.freq_hz[int(np.argmax(ang))])}
    return out


# ======================================================================================
# Files: CSV, plots, summary
# ======================================================================================

LABELS = {"original": "(a) original elastomer", "friction": "(b) halved + friction",
          "hydraulic": "(c) hydraulic, decoupler open",
          "hydraulic_closed": "(c') hydraulic, decoupler closed"}
COLORS = {"original": "black", "friction": "tab:red", "hydraulic": "tab:blue",
          "hydraulic_closed": "tab:green"}


def _write_csvs(case: SystemCase, sc: StiffnessCurves, out: Path) -> list[str]:
    k = case.spec.key
    write_csv(out / f"hydraulic_{k}_transmissibility.csv",
              ["freq_hz", *(f"T_{m}" for m in MOUNTS)],
              [[f, *(case.transmissibility[m][i] for m in MOUNTS)]
               for i, f in enumerate(case.freq_hz)],
              comment=f"{k}: transmissibility [-] (preset definition) of (a) "
                      f"original, (b) halved + friction n0 = {case.n0:g} N (HBM), (c) "
                      "hydraulic presets (HBM, H = 1: exact, the mount is linear); "
                      "freq in Hz")
    write_csv(out / f"hydraulic_{k}_hbm_curves.csv", ["mount", "freq_hz", "T"],
              [[m, fi, ti] for m, (fr, tr) in case.hbm_curves.items()
               for fi, ti in zip(fr, tr)],
              comment=f"{k}: the HBM continuation curves of (a), (b) as computed "
                      "(freq in Hz, T [-]; nan rows: gaps between restarted "
                      "segments); their peaks are summary.md's")
    cols = ["freq_hz"] + [f"{q}_{m}_{X * 1e3:g}mm" for m in MOUNTS
                          for X in DS_AMPLITUDES_M for q in ("absK_N_per_m",
                                                             "loss_deg")]
    rows = [[f] + [v for m in MOUNTS for X in DS_AMPLITUDES_M
                   for v in (abs(sc.K[(m, X)][i]),
                             float(np.degrees(np.angle(sc.K[(m, X)][i]))))]
            for i, f in enumerate(sc.freq_hz)]
    write_csv(out / f"hydraulic_{k}_stiffness.csv", cols, rows,
              comment=f"{k}: dynamic stiffness |K*| (N/m) and loss angle (deg) of "
                      f"mount {sc.element + 1} {AXES[sc.axis]} axis at deflection "
                      "amplitudes in mm; freq in Hz")
    return [f"hydraulic_{k}_{x}.csv" for x in ("transmissibility", "hbm_curves",
                                                "stiffness")]


def _plot(case: SystemCase, sc: StiffnessCurves, out: Path) -> str:
    fig = new_figure(figsize=(12, 4))
    ax = fig.add_subplot(1, 3, 1)
    for m in MOUNTS:
        ax.plot(case.freq_hz, case.transmissibility[m], color=COLORS[m],
                label=LABELS[m] + (f", n0 = {case.n0:g} N" if m == "friction" else ""))
    log_axes(ax, ylabel="transmissibility [-]",
             title=f"{case.spec.key}: transmissibility [-] (preset definition)")
    ax.legend(fontsize=7)
    for p, (q, unit) in enumerate((("|K*|", "N/m"), ("loss angle", "deg"))):
        ax = fig.add_subplot(1, 3, p + 2)
        for m in MOUNTS:
            amps = DS_AMPLITUDES_M[:1] if m in HYDRAULIC_MOUNTS else DS_AMPLITUDES_M
            for X, ls in zip(amps, ("-", "--")):
                K = sc.K[(m, X)]
                ax.plot(sc.freq_hz, np.abs(K) if p == 0 else np.degrees(np.angle(K)),
                        color=COLORS[m], ls=ls,
                        label=(m if m in HYDRAULIC_MOUNTS
                               else f"{m}, X = {X * 1e3:g} mm"))
        ax.set_xscale("log")
        if p == 0:
            ax.set_yscale("log")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"{q} [{unit}]")
        ax.set_title(f"{case.spec.key}: {q} [{unit}], mount {sc.element + 1} "
                     f"{AXES[sc.axis]} axis", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    name = f"hydraulic_{case.spec.key}.png"
    save_fig(fig, out / name)
    return name


def system_summary(case: SystemCase, sc: StiffnessCurves) -> dict:
    """The key numbers of one system (all also in, or read from, its CSVs)."""
    return {"system": case.spec.key, "n0_N": case.n0, "n0_rule": case.n0_rule,
            "peak": {m: case.peaks[m].value for m in MOUNTS},
            "peak_hz": {m: case.peaks[m].freq_hz for m in MOUNTS},
            "orders": order_values(case), "loss": loss_extremes(sc, case),
            "sag_m": static_sag(case),
            "hydraulic": case.hydraulic["hydraulic"]._asdict(),
            "hydraulic_presets": {"hydraulic": case.spec.hydraulic,
                                  "hydraulic_closed": f"{case.spec.hydraulic} --set "
                                  + " ".join(DECOUPLER_CLOSED[case.spec.model])},
            "frf_check": case.frf_check, "failures": case.failures}


def _verdict(a: float, b: float, tol: float = 0.2) -> str:
    """'matches' when friction ``a`` and hydraulic ``b`` are within ``tol``
    relative, else lower/higher, with the ratio."""
    r = a / b if b else float("nan")
    return (f"matches ({r:.2f}x)" if abs(r - 1) <= tol else
            f"{'lower' if r < 1 else 'higher'} ({r:.2f}x)")


def _row(label: str, values: dict, compare: bool = True) -> list:
    return [label, *(values[m] for m in MOUNTS),
            *((_verdict(values["friction"], values[h]) if compare else "")
              for h in HYDRAULIC_MOUNTS)]


def _system_md(s: dict) -> list[str]:
    L = s["loss"]
    rows = [_row("peak T [-]", s["peak"]),
            _row("peak at [Hz]", s["peak_hz"], compare=False)]
    rows += [_row(f"T at {lab}, {ORDERS_HZ[lab]:g} Hz [-]", v)
             for lab, v in s["orders"].items()]
    rows += [_row(f"loss angle at the {k} {f:.1f} Hz"
                  + (f" (beyond the band: at {BAND_HZ[1]:g} Hz)" if f > BAND_HZ[1]
                     else "") + " [deg]",
                  {m: L[m]["at"][k] for m in MOUNTS}, compare=False)
             for k, f in L["marks_hz"].items()]
    rows += [_row("largest loss angle in the band [deg]",
                  {m: L[m]["max"] for m in MOUNTS}),
             _row("static sag [mm]", {m: 1e3 * v for m, v in s["sag_m"].items()})]
    check = ", ".join(f"{m} {v:.1e}" for m, v in s["frf_check"].items())
    presets = "; ".join(f"{m}: `{v}`" for m, v in s["hydraulic_presets"].items())
    return [f"## {s['system']}: friction n0 = {s['n0_N']:g} N ({s['n0_rule']})", "",
            f"Hydraulic presets: {presets}. HBM against the exact FRF, largest "
            f"difference over the grid relative to the peak: {check}.", "",
            md_table(["quantity", *MOUNTS, "friction vs hydraulic",
                      "friction vs hydraulic_closed"], rows), ""]


def _summary_md(results: list[dict], figs: list[str], quick: bool) -> str:
    H = HARMONICS_QUICK if quick else HARMONICS
    lines = ["# Study hydraulic: friction-damped elastomer mount against a hydraulic "
             "mount", "",
             f"Band {BAND_HZ[0]:g}-{BAND_HZ[1]:g} Hz. (a), (b): HBM H = {H} "
             "(continuation, read on the log grid); (c) decoupler open, (c') closed "
             "(inertia track only): HBM (H = 1, exact: the mount is linear) of the "
             "hydraulic presets (`*_hydraulic`, values in `sdof_hydraulic.toml`; "
             "closed: `--set ...hydraulic.I_d=0`), checked against the exact "
             "linear FRF with the mount's K*(omega) on the axial axes (largest "
             "difference per system below). |K*| and loss angle of (a), (b) at "
             + ", ".join(f"{X * 1e3:g} mm" for X in DS_AMPLITUDES_M)
             + " (loss angles in the table at the larger). Sag: largest axial "
             f"mount deflection under the engine's weight (g = {GRAVITY:g} m/s^2, "
             "friction sliders relaxed). 'matches': friction within 20 % of "
             "hydraulic.", ""]
    for s in results:
        lines += _system_md(s)
    fails = [f for s in results for f in s["failures"]]
    if fails:
        lines += ["**Curves that did not complete:**", ""] + [f"- {f}" for f in fails]
    lines += [""] + [f"![{f}]({f})" for f in figs] + [""]
    return "\n".join(lines)


def key_rows(s: dict) -> list[list]:
    """Rows ``[system, quantity, mount, value, unit]`` of the key numbers of one
    system (``hydraulic_key_numbers.csv``)."""
    rows = []
    for m in MOUNTS:
        rows += [[s["system"], "peak_T", m, s["peak"][m], "-"],
                 [s["system"], "peak_freq", m, s["peak_hz"][m], "Hz"],
                 [s["system"], "sag", m, s["sag_m"][m], "m"],
                 [s["system"], "loss_angle_max", m, s["loss"][m]["max"], "deg"]]
        rows += [[s["system"], f"T_at_{ORDERS_HZ[lab]:g}Hz", m, v[m], "-"]
                 for lab, v in s["orders"].items()]
        rows += [[s["system"], f"loss_angle_at_{k.replace(' ', '_')}", m, v, "deg"]
                 for k, v in s["loss"][m]["at"].items()]
    return rows


def printed_summary(results: list[dict]) -> str:
    """Short text the command prints: per system, friction vs hydraulic."""
    out = []
    for s in results:
        o = s["orders"]
        out.append(f"{s['system']} (n0 {s['n0_N']:g} N; values original/friction/"
                   "hydraulic/hydraulic_closed): peak T "
                   + "/".join(f"{s['peak'][m]:.3g}" for m in MOUNTS) + "; "
                   + "; ".join(f"T at {ORDERS_HZ[lab]:g} Hz "
                               + "/".join(f"{v[m]:.3g}" for m in MOUNTS)
                               for lab, v in o.items())
                   + "; sag mm " + "/".join(f"{1e3 * s['sag_m'][m]:.2f}"
                                           for m in MOUNTS))
    return "\n".join(out)


def run_hydraulic(out_dir, quick: bool = False, progress: bool = True,
                  systems: tuple[str, ...] | None = None) -> dict:
    """The three mounts in each system (module docstring).

    Parameters
    ----------
    out_dir : path
    quick : bool
        The n0 families' quick forces, H = 1, 60 grid points.
    progress : bool
        Print one line per system.
    systems : tuple of str, optional
        A subset of ``sdof``, ``quarter_car``, ``six_dof`` (default all).

    Returns
    -------
    dict
        ``systems``: one dict per system (n0_N, peak, peak_hz, orders, loss, sag_m,
        hydraulic, failures), ``failures``, ``files``, ``printed``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results, figs = [], []
    for spec in SYSTEMS:
        if systems is not None and spec.key not in systems:
            continue
        case = run_system(spec, quick)
        sc = stiffness_curves(case)
        _write_csvs(case, sc, out)
        figs.append(_plot(case, sc, out))
        results.append(system_summary(case, sc))
        if progress:
            print(printed_summary(results[-1:]), flush=True)
    write_csv(out / "hydraulic_key_numbers.csv",
              ["system", "quantity", "mount", "value", "unit"],
              [r for s in results for r in key_rows(s)],
              comment="key numbers of summary.md; peak_T of original/friction from "
                      "the HBM continuation curve, of the hydraulic mounts on the log "
                      "grid; T_at_* and loss angles read off the curve CSVs")
    atomic_write_text(out / "summary.md", _summary_md(results, figs, quick))
    return {"study": "hydraulic", "systems": results,
            "failures": [f for s in results for f in s["failures"]],
            "printed": printed_summary(results),
            "files": sorted(p.name for p in out.iterdir())}
