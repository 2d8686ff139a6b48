"""``drymount demo``: the main job of the README, end to end in seconds.

1. Builds the mount FMU (``dist/FrictionMount.fmu``) and validates it with fmpy.
2. Computes the harmonic-balance displacement transmissibility (engine / sprung mass,
   thesis eq. 4.3) of the quarter car with the original mount and with the halved,
   friction-damped mount (thesis Sec. 4.3, Figs. 4.6-4.9).
3. Co-simulates the friction-damped quarter car at a few frequencies through the FMU
   (fmpy, one FMU instance for the mount) and overlays the steady states on the curve.
4. Writes ``demo.md`` (key numbers), ``hbm_original.csv``, ``hbm_friction.csv``,
   ``cosim_friction.csv`` and ``transmissibility.png`` into ``--out``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from drymount.io import atomic_write_text, save_figure, shown_path

__all__ = ["run_demo", "main"]

#: Band of the demo curves, Hz: the quarter car's body and engine-mount modes.
FMIN_HZ, FMAX_HZ = 0.5, 25.0
#: Harmonics of the demo's HBM curves (multi-harmonic AFT).
HARMONICS = 5
#: Frequencies co-simulated through the FMU, Hz (below, near and above the peaks).
COSIM_FREQS_HZ = (2.0, 5.0, 8.0, 12.0, 20.0)


def _log(msg: str) -> None:
    print(f"demo: {msg}", file=sys.stderr, flush=True)


def run_demo(out="demo", *, progress: bool = True) -> dict:
    """Run the demo; returns the key numbers (also written to ``demo.md``)."""
    import drymount.hbm as hbm
    import drymount.vehicle as vehicle
    from drymount.config import load_preset
    from drymount.fmu_build import build_fmu

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()

    _log("1/4 building the mount FMU")
    from fmpy.validation import validate_fmu

    fmu = build_fmu()
    problems = validate_fmu(str(fmu))
    _log(f"    {shown_path(fmu)} ("
         f"{'fmpy validate: no problem' if not problems else problems})")

    _log("2/4 harmonic balance: original mount and halved mount with friction")
    original = load_preset("quarter_car_original").system
    friction = load_preset("quarter_car_halved").system
    c_orig = hbm.frequency_response(original, FMIN_HZ, FMAX_HZ, harmonics=HARMONICS,
                                    progress=progress)
    c_fric = hbm.frequency_response(friction, FMIN_HZ, FMAX_HZ, harmonics=HARMONICS,
                                    progress=progress)
    c_orig.to_csv(out / "hbm_original.csv")
    c_fric.to_csv(out / "hbm_friction.csv")

    _log("3/4 co-simulating the friction-damped quarter car through the FMU")
    sw = vehicle.sweep(friction, np.array(COSIM_FREQS_HZ), direction="up",
                       backend="fmu", fmu_path=fmu, progress=progress)
    sw.to_csv(out / "cosim_friction.csv")

    _log("4/4 plots and report")
    _plot(c_orig, c_fric, sw, out / "transmissibility.png")
    numbers = _numbers(fmu, problems, c_orig, c_fric, sw, friction, t_start)
    atomic_write_text(out / "demo.md", _report(numbers, fmu, problems, c_orig, c_fric,
                                               friction))
    _log(f"done in {numbers['seconds']:.1f} s: report {out / 'demo.md'}")
    return numbers


def _plot(c_orig, c_fric, sw, path: Path) -> None:
    """Transmissibility of both HBM curves with the co-simulated points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    for curve, label, color in ((c_orig, "original mount (HBM)", "C0"),
                                (c_fric, "halved mount + friction (HBM)", "C3")):
        st = np.asarray(curve.stable, dtype=bool)
        tr = np.asarray(curve.transmissibility, dtype=float)
        ax.plot(curve.freq_hz, np.where(st, tr, np.nan), "-", color=color, label=label)
        if not st.all():
            ax.plot(curve.freq_hz, np.where(~st, tr, np.nan), "--", color=color,
                    label=f"{label}, unstable")
    ax.plot(sw.freq_hz, sw.transmissibility, "o", mfc="none", color="k",
            label="halved + friction, co-simulated through the FMU")
    ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("displacement transmissibility engine/sprung [-]")
    ax.set_title("Engine on a quarter car: road input")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def _numbers(fmu, problems, c_orig, c_fric, sw, friction, t_start: float) -> dict:
    """The demo's key numbers: peaks, their reduction, co-simulation vs HBM."""
    import drymount.hbm as hbm

    f_o, t_o = c_orig.transmissibility_max()
    f_f, t_f = c_fric.transmissibility_max()
    # co-simulation vs HBM at the co-simulated frequencies (same H, same system)
    hb = hbm.solve_frequencies(friction, np.array(COSIM_FREQS_HZ), harmonics=HARMONICS)
    err = np.abs(np.asarray(sw.transmissibility) - np.asarray(hb.transmissibility))
    rel = err / t_f
    return dict(
        fmu=str(fmu),
        fmu_problems=len(problems),
        peak_original=t_o, peak_original_hz=f_o,
        peak_friction=t_f, peak_friction_hz=f_f,
        peak_reduction=float(1.0 - t_f / t_o),
        cosim_max_err_rel_peak=float(np.nanmax(rel)),
        seconds=time.perf_counter() - t_start,
    )


def _report(numbers: dict, fmu, problems, c_orig, c_fric, friction) -> str:
    """``demo.md``."""
    n0 = [a.n0 for e in friction.elements for a in e.params.axes if a.friction]
    lines = [
        "# drymount demo: engine on a quarter car, original vs friction-damped mount",
        "",
        f"- FMU: `{shown_path(fmu)}`; `fmpy validate`: "
        f"{'no problem' if not problems else '; '.join(problems)}",
        f"- Original mount (preset `quarter_car_original`): peak transmissibility "
        f"{numbers['peak_original']:.3f} at {numbers['peak_original_hz']:.2f} Hz",
        f"- Halved mount with friction, n0 = {', '.join(f'{v:g}' for v in n0)} N "
        f"(preset `quarter_car_halved`): peak {numbers['peak_friction']:.3f} at "
        f"{numbers['peak_friction_hz']:.2f} Hz, "
        f"{100 * numbers['peak_reduction']:.1f} % lower",
        f"- Co-simulation through the FMU at {len(COSIM_FREQS_HZ)} frequencies vs HBM "
        f"(H = {HARMONICS}): largest transmissibility difference "
        f"{100 * numbers['cosim_max_err_rel_peak']:.3f} % of the peak",
        f"- HBM: {c_orig.n_newton + c_fric.n_newton} Newton iterations over "
        f"{len(c_orig.freq_hz) + len(c_fric.freq_hz)} curve points; "
        f"total run time {numbers['seconds']:.1f} s",
        "",
        "![transmissibility](transmissibility.png)",
        "",
        "Files: `hbm_original.csv`, `hbm_friction.csv` (HBM curves), "
        "`cosim_friction.csv` (co-simulated steady states).",
    ]
    return "\n".join(lines) + "\n"


def main(args: argparse.Namespace) -> int:
    """CLI entry: ``drymount demo [--out DIR]``."""
    run_demo(args.out, progress=not getattr(args, "quiet", False))
    print(f"report: {Path(args.out) / 'demo.md'}")
    return 0
