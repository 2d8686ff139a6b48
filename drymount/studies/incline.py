"""Design study of the inclined friction mount (thesis Ch. 5): `drymount study incline`.

Sweeps the surface angle theta, the stiffness k of the elastic pieces and their preload.
Each design is the SDOF of the general route (:func:`hbm.systems.sdof`: the engine mass
on a mount axis with the elastomer ``k1``, ``c`` and the inclined friction element,
``friction_kind = "inclined"``, the axis pointing up) under the engine's weight
(``static_load``) and a harmonic force on the mass. For each design: the static working
point under the weight (:func:`hbm.static.working_point`, the element relaxed there)
with its deflection and normal forces, and the force transmissibility by the general
:func:`hbm.frequency_response` (arc-length continuation, H = 7, the normal forces
varying over the period, :mod:`hbm.inclined`), each study frequency solved exactly on
the curve (:func:`hbm.branches.solutions_at`). Designs that self-lock or lose contact
are reported as such. Writes ``incline.csv``, ``summary.md`` and two plots. At 90
degrees the second surface is bonded (the thesis's Fig. 5.3 design).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from drymount.studies.output import md_table, new_figure, progress_bar, save_fig
from drymount.fmu_src.inclined import axis_normal_forces, relaxed_state
from drymount.fmu_src.mount_law import AxisParameters, MountParameters, ParameterError
from drymount.hbm import frequency_response
from drymount.hbm.branches import solutions_at
from drymount.hbm.inclined import normal_force_range
from drymount.hbm.options import HBMOptions
from drymount.hbm.problem import build_problem
from drymount.hbm.static import working_point
from drymount.hbm.systems import sdof

__all__ = ["run_incline", "InclineDesign", "incline_system"]

G = 9.81
MASS = 70.0          # kg, the thesis's engine mass (Sec. 2.1.1)
K1 = 45935.0         # N/m, the halved elastomer of the SDOF presets
C = 150.0            # N s/m
FORCE_AMP = 150.0    # N, harmonic force on the mass
HARMONICS = 7
#: HBM options of the study: H = 7 with the default 64 samples, no adaptation (the
#: validate case sdof_inclined_60deg checks this H against co-simulation)
OPTIONS = HBMOptions(harmonics=HARMONICS, tol=None)
#: the static working point of every design: the element relaxed there (the reading
#: docs/results.md's tables were computed on; hbm.static's default, and what
#: drymount hbm / cosim start from, is the engine lowered onto the mount)
STATIC_READING = "relaxed"


@dataclass
class InclineDesign:
    """One design's results; ``status`` is "ok", "self-locks", "loses contact under
    the weight" or "loses contact at f1-f2 Hz" (the steady state asks for N < 0 or
    N2 < 0 there; NaN transmissibility at those frequencies). ``x_static`` is the
    static compression (m, > 0 downwards), ``missing`` the study frequencies without
    an HBM solution."""

    theta_deg: float
    k: float
    preload: float
    status: str
    x_static: float = math.nan
    n_static: float = math.nan
    n2_static: float = math.nan
    freqs: np.ndarray | None = None
    trans: np.ndarray | None = None
    n_min: float = math.nan
    n_max: float = math.nan
    peak_trans: float = math.nan
    missing: int = 0


def incline_system(theta: float, k: float, preload: float):
    """The SDOF of one design: ``MASS`` on ``K1``, ``C`` and the inclined element
    (kf = kf2 = 60 000 N/m, mu1 = mu2 = 0.3; the flat surface bonded at 90 degrees),
    weight as the static load, ``FORCE_AMP`` on the mass. Raises ParameterError when
    the wedge self-locks."""
    mu2 = math.inf if theta == 90.0 else 0.3
    axis = AxisParameters(law="linear", k1=K1, k2=K1, c=C, friction=True,
                          friction_kind="inclined", theta_deg=theta, k=k, kf=6e4,
                          kf2=6e4, mu1=0.3, mu2=mu2, preload=preload)
    bare = AxisParameters(law="linear", k1=K1, k2=K1, c=C)
    system = sdof(MASS, MountParameters(axis, bare, bare), "force", FORCE_AMP)
    # x points up; the study's published numbers are on the relaxed reading
    # (STATIC_READING), not the lowered default of hbm.static
    return replace(system, static_load=np.array([-MASS * G]),
                   static_reading=STATIC_READING)


def _covers(curve, f: float) -> bool:
    fr = np.asarray(curve.freq_hz)
    return fr.size > 1 and fr.min() <= f <= fr.max()


def _curves_and_solutions(system, freqs):
    """Per study frequency the HBM solution ``(prob, y)``, ``"lost"`` (the element
    loses contact: no solution keeps N, N2 >= 0, e.g. load stepping from the working
    point ends with N2 -> 0) or None (no solution found). Arc-length curves
    (:func:`hbm.frequency_response`) start at the first frequency not yet covered and
    run to the band's end; each frequency is solved on its curve."""
    out, curve, prob = [], None, None
    for f in freqs:
        f = float(f)
        if curve is None or not _covers(curve, f):
            curve = frequency_response(system, f, float(freqs[-1]) + 1e-9 * f,
                                       options=OPTIONS)
            prob = build_problem(system, f, float(freqs[-1]) + 1e-9 * f, HARMONICS,
                                 curve.n_samples, False)
            if len(curve.freq_hz) == 0:
                out.append("lost" if "loses contact" in curve.message else None)
                curve = None
                continue
        sols = solutions_at(system, curve, f, prob, OPTIONS)
        if not sols:
            out.append(None)
            continue
        out.append((prob, next((y for y, stable, _ in sols if stable), sols[0][0])))
    return out


def _solve_at(system, freqs, p, u0):
    """Transmissibility (fundamental of the mount force / force amplitude), the range
    of N, the frequencies where contact is lost and the number of missing ones."""
    trans, nmin, nmax, lost, missing = [], math.inf, -math.inf, [], 0
    for f, sol in zip(freqs, _curves_and_solutions(system, freqs)):
        if not isinstance(sol, tuple):
            trans.append(math.nan)
            if sol == "lost":
                lost.append(float(f))
            else:
                missing += 1
            continue
        prob, y = sol
        hb = prob.hb
        X, w = prob.x_of(y)
        c1, s1 = hb.axis_force_fundamental(X, w, [(0, 0)])
        trans.append(math.hypot(c1, s1) / FORCE_AMP)
        lo, hi, _, _ = normal_force_range(hb.time_samples(X, hb.n_samples)[:, 0], p, u0)
        nmin, nmax = min(nmin, lo), max(nmax, hi)
    return np.array(trans), nmin, nmax, lost, missing


def _design(theta, k, preload, freqs) -> InclineDesign:
    d = InclineDesign(theta, k, preload, "ok")
    try:
        system = incline_system(theta, k, preload)
    except ParameterError:
        d.status = "self-locks"
        return d
    p = system.elements[0].params.axial.inclined
    point = working_point(system)
    u0 = float(point.deflection[0, 0])
    d.x_static = -u0
    d.n_static, d.n2_static = axis_normal_forces(relaxed_state(p, u0), p)
    if min(d.n_static, d.n2_static) < 0:
        d.status = "loses contact under the weight"
        return d
    d.trans, d.n_min, d.n_max, lost, d.missing = _solve_at(system, freqs, p, u0)
    if lost:
        span = f"{min(lost):g}" if len(lost) == 1 else f"{min(lost):g}-{max(lost):g}"
        d.status = f"loses contact at {span} Hz"
    d.freqs = np.asarray(freqs)
    if not np.all(np.isnan(d.trans)):
        d.peak_trans = float(np.nanmax(d.trans))
    return d


def _grid(quick: bool):
    if quick:
        return (30.0, 60.0, 90.0), (2e4,), (200.0,), np.linspace(3.0, 15.0, 5)
    return ((30.0, 45.0, 60.0, 75.0, 90.0), (5e3, 2e4, 8e4), (100.0, 200.0, 400.0),
            np.linspace(2.0, 20.0, 19))


def _write(out: Path, designs, freqs) -> str:
    with open(out / "incline.csv", "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(["theta_deg", "k_N_per_m", "preload_N", "status", "x_static_m",
                     "N_static_N", "N2_static_N", "N_min_N", "N_max_N",
                     "peak_transmissibility"] + [f"T_{f:g}Hz" for f in freqs])
        for d in designs:
            tr = list(d.trans) if d.trans is not None else [math.nan] * len(freqs)
            wr.writerow([d.theta_deg, d.k, d.preload, d.status, d.x_static,
                         d.n_static, d.n2_static, d.n_min, d.n_max, d.peak_trans] + tr)
    rows = [[d.theta_deg, d.k, d.preload, d.status, 1e3 * d.x_static, d.n_static,
             d.n_min, d.n_max, d.peak_trans] for d in designs]
    md = ["# Inclined friction mount (thesis Ch. 5)", "",
          f"Engine {MASS} kg (weight {MASS * G:.1f} N) on k1 = {K1:g} N/m, c = {C:g} "
          f"N s/m and the inclined element (kf = kf2 = 60 000 N/m, mu1 = mu2 = 0.3); "
          f"harmonic force {FORCE_AMP:g} N; HBM H = {HARMONICS} (general route: "
          f"arc-length "
          f"continuation, each frequency solved on the curve); the element relaxed at "
          f"the static working point; static x = compression under the weight.", "",
          md_table(["theta [deg]", "k [N/m]", "preload [N]", "status",
                    "static compression [mm]", "static N [N]", "N min [N]", "N max [N]",
                    "peak T [-]"], rows), "",
          "![transmissibility](incline_transmissibility.png)", "",
          "![static](incline_static.png)", ""]
    text = "\n".join(md)
    (out / "summary.md").write_text(text)
    return text


def _plot(out: Path, designs) -> None:
    fig = new_figure(figsize=(7, 4.5))
    ax = fig.add_subplot()
    for d in designs:
        if d.trans is not None and d.k == 2e4 and d.preload == 200.0:
            ax.semilogy(d.freqs, d.trans, marker=".",
                        label=f"theta = {d.theta_deg:g} deg")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("force transmissibility [-]")
    ax.set_title("Inclined friction mount, k = 20 000 N/m, preload 200 N:\n"
                 "force transmissibility (HBM H = 7, N varying over the period)")
    ax.legend(fontsize=6)
    save_fig(fig, out / "incline_transmissibility.png")
    fig = new_figure(figsize=(7, 4.5))
    ax = fig.add_subplot()
    ok = [d for d in designs if not math.isnan(d.x_static)]
    ax.plot([d.theta_deg for d in ok], [1e3 * d.x_static for d in ok], "o",
            label="static compression [mm]")
    ax.plot([d.theta_deg for d in ok], [d.n_static / 100 for d in ok], "s",
            label="static normal force N [100 N]")
    ax.set_xlabel("surface angle theta [deg]")
    ax.set_ylabel("static compression [mm] / N [100 N]")
    ax.set_title(f"Inclined mount under the engine's weight ({MASS * G:.0f} N)")
    ax.legend()
    save_fig(fig, out / "incline_static.png")


def run_incline(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """Run the sweep, write CSV, Markdown and plots into ``out_dir``; key numbers."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    thetas, ks, preloads, freqs = _grid(quick)
    combos = [(t, k, p) for t in thetas for k in ks for p in preloads]
    designs = [_design(t, k, p, freqs)
               for t, k, p in progress_bar(combos, "incline", progress)]
    _write(out, designs, freqs)
    _plot(out, designs)
    failures = [f"theta {d.theta_deg:g} deg, k {d.k:g} N/m, preload {d.preload:g} N: "
                f"no HBM solution at {d.missing} of {len(freqs)} frequencies"
                for d in designs if d.missing]
    files = [out / n for n in ("incline.csv", "summary.md",
                               "incline_transmissibility.png", "incline_static.png")]
    return {"files": files, "failures": failures, "designs": len(designs),
            "ok": sum(d.status == "ok" for d in designs),
            "missing": sum(d.missing for d in designs),
            "statuses": {f"{d.theta_deg:g}/{d.k:g}/{d.preload:g}": d.status
                         for d in designs}}
