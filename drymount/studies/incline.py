"""Design study of the inclined friction mount (thesis Ch. 5): `drymount study incline`.

Sweeps the surface angle theta, the stiffness k of the elastic pieces and their preload.
For each design: the static deflection and normal forces under the engine's weight (the
element's own quasi-static law, loaded monotonically from the assembled state at x = 0,
solved by bisection: the static working point of branch `design` is not used here), and
the force transmissibility of the SDOF (engine mass on the elastomer plus the element,
harmonic force on the mass around the static point) by HBM with the normal force
varying over the period (:mod:`hbm.inclined`). Designs that self-lock or lose contact
are reported as such. Writes ``incline.csv``, ``summary.md`` and two plots. At 90
degrees the second
surface is bonded (the thesis's Fig. 5.3 design).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drymount.studies.output import md_table, new_figure, progress_bar, save_fig
from fmu_src.inclined import ContactLost, InclinedParameters, inclined_update
from hbm.aft import FourierBasis, default_n_samples
from hbm.inclined import InclinedSDOF, solve_inclined_hbm

__all__ = ["run_incline", "InclineDesign", "static_point"]

G = 9.81
MASS = 70.0          # kg, the thesis's engine mass (Sec. 2.1.1)
K1 = 45935.0         # N/m, the halved elastomer of the SDOF presets
C = 150.0            # N s/m
FORCE_AMP = 150.0    # N, harmonic force on the mass
HARMONICS = 7


@dataclass
class InclineDesign:
    """One design's results; ``status`` is "ok", "self-locks", "loses contact under
    the weight" or "loses contact at f1-f2 Hz" (the steady state asks for N < 0 or
    N2 < 0 there; NaN transmissibility at those frequencies)."""

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
    unconverged: int = 0


def static_point(p: InclinedParameters, weight: float, k1: float = K1):
    """Deflection (m) and ``InclinedStep`` where ``k1 x + F(x) = weight`` on first
    loading from the assembled state (x = 0, relaxed sliders); bisection (the loading
    curve is monotone: every regime's tangent is >= 0 for a non-self-locking wedge)."""
    def net(x):
        st = inclined_update(x, 0.0, 0.0, 0.0, p)
        return k1 * x + st.force - weight, st
    lo, hi = 0.0, weight / k1
    if net(lo)[0] >= 0:
        return 0.0, net(0.0)[1]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if net(mid)[0] > 0:
            hi = mid
        else:
            lo = mid
        if hi - lo < 1e-13:
            break
    return hi, net(hi)[1]


def _transmissibility(sysm: InclinedSDOF, freqs):
    """Fundamental of (elastomer + damper + element force) / force amplitude per
    frequency (NaN where HBM fails), the range of N, and the frequencies where the
    steady state loses contact."""
    out, nmin, nmax, x0, lost, failed = [], math.inf, -math.inf, None, [], 0
    b = FourierBasis(HARMONICS, default_n_samples(HARMONICS))
    for f in freqs:
        try:
            r = solve_inclined_hbm(sysm, f, HARMONICS, x0=x0)
            if not r.success and x0 is not None:     # retry from the stuck linear start
                r = solve_inclined_hbm(sysm, f, HARMONICS)
        except ContactLost:
            lost.append(float(f))
            out.append(math.nan)
            continue
        if not r.success:
            failed += 1
            out.append(math.nan)
            continue
        x0 = r.X
        w = 2 * math.pi * f
        Fel = b.P @ r.element.force
        c1 = K1 * r.X[1] + C * w * r.X[2] + Fel[1]
        s1 = K1 * r.X[2] - C * w * r.X[1] + Fel[2]
        out.append(math.hypot(c1, s1) / sysm.force_amp)
        nmin, nmax = min(nmin, r.element.n1.min()), max(nmax, r.element.n1.max())
    return np.array(out), nmin, nmax, lost, failed


def _design(theta, k, preload, freqs) -> InclineDesign:
    d = InclineDesign(theta, k, preload, "ok")
    # at 90 degrees the second surface carries no load (a = 0) and N2 = f1 changes
    # sign: the thesis's 90-degree design (Fig. 5.3) holds the pieces, so bond it
    mu2 = math.inf if theta == 90.0 else 0.3
    try:
        p = InclinedParameters(theta_deg=theta, k=k, preload=preload, mu2=mu2)
    except ValueError:
        d.status = "self-locks"
        return d
    try:
        x, st = static_point(p, MASS * G)
        d.x_static, d.n_static, d.n2_static = x, st.n1, st.n2
    except ContactLost:
        d.status = "loses contact under the weight"
        return d
    sysm = InclinedSDOF(MASS, K1, C, p, FORCE_AMP, MASS * G)
    d.trans, d.n_min, d.n_max, lost, d.unconverged = _transmissibility(sysm, freqs)
    d.freqs = np.asarray(freqs)
    if lost:
        span = f"{min(lost):g}" if len(lost) == 1 else f"{min(lost):g}-{max(lost):g}"
        d.status = f"loses contact at {span} Hz"
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
          f"harmonic force {FORCE_AMP:g} N; HBM H = {HARMONICS}.", "",
          md_table(["theta [deg]", "k [N/m]", "preload [N]", "status",
                    "static x [mm]", "static N [N]", "N min [N]", "N max [N]",
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
            label="static deflection [mm]")
    ax.plot([d.theta_deg for d in ok], [d.n_static / 100 for d in ok], "s",
            label="static normal force N [100 N]")
    ax.set_xlabel("surface angle theta [deg]")
    ax.set_ylabel("static deflection [mm] / N [100 N]")
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
                f"HBM did not converge at {d.unconverged} frequencies"
                for d in designs if d.unconverged]
    files = [out / n for n in ("incline.csv", "summary.md",
                               "incline_transmissibility.png", "incline_static.png")]
    return {"files": files, "failures": failures, "designs": len(designs),
            "ok": sum(d.status == "ok" for d in designs),
            "statuses": {f"{d.theta_deg:g}/{d.k:g}/{d.preload:g}": d.status
                         for d in designs}}
