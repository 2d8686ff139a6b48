"""Study ``jump``: cubic single DOF, the HBM fold with its unstable branch and the
time-domain jumps of stepped sweeps and of a frequency step (thesis Figs. 3.5, 3.7)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drymount.io import atomic_write_text, write_csv
from drymount.studies.common import DesignResult, hbm_curve, load_system, peak
from drymount.studies.output import (
    log_axes,
    new_figure,
    plot_branch,
    progress_bar,
    save_fig,
    system_values,
    write_curves,
)
from drymount.hbm.system import System

JUMP_PRESET = "sdof_cubic"
JUMP_BAND_HZ = (1.0, 20.0)
JUMP_HARMONICS = 7
JUMP_HARMONICS_QUICK = 3
#: Time-domain stepped sweep: frequency step (Hz; the thesis's Fig. 3.7 steps by
#: 0.1 Hz) and the margin on each side of the two turning points as a fraction of
#: their distance. A step moves the state off the upper branch before the fold once
#: the branch's basin of attraction gets narrower than the step: 0.05 Hz steps keep
#: the up sweep on it to within about 0.1 Hz of the fold.
JUMP_STEP_HZ = 0.05
JUMP_STEP_QUICK_HZ = 0.2
JUMP_MARGIN = 0.3


#: Fig. 3.7 analog: a slow ramp from below the lower fold onto the upper branch up to
#: ``JUMP_STEP_BELOW_HZ`` under the up sweep's last upper-branch frequency, a hold, then
#: a step to ``JUMP_STEP_ABOVE_HZ`` past its jump. Ramp, hold and after-step times, s.
JUMP_STEP_BELOW_HZ = 0.2
JUMP_STEP_ABOVE_HZ = 0.15
JUMP_RAMP_S = 120.0
JUMP_HOLD_S = 4.0
JUMP_AFTER_S = 10.0


class _FrequencyStep:
    """Unbalance excitation ``U omega(t)^2 sin(phi(t))`` (thesis eq. 4.2): the
    frequency ramps linearly from ``f_a`` to ``f1`` over ``t_ramp``, holds ``f1`` until
    ``t_step``, then steps to ``f2``; the phase ``phi = 2 pi int f dt`` is continuous.

    A :class:`vehicle.inputs.Input` (built by :func:`_frequency_step_input`).
    """

    def __init__(self, f_a, f1, f2, t_ramp, t_step):
        self.f_a, self.f1, self.f2 = f_a, f1, f2
        self.t_ramp, self.t_step = t_ramp, t_step

    def freq(self, t):
        t = np.asarray(t, dtype=float)
        ramp = self.f_a + (self.f1 - self.f_a) * t / self.t_ramp
        return np.where(t < self.t_ramp, ramp, np.where(t < self.t_step, self.f1,
                                                         self.f2))

    def cycles(self, t):
        t = np.asarray(t, dtype=float)
        tr, ts = self.t_ramp, self.t_step
        c_ramp = self.f_a * t + 0.5 * (self.f1 - self.f_a) * t**2 / tr
        c_tr = 0.5 * (self.f_a + self.f1) * tr
        c_ts = c_tr + self.f1 * (ts - tr)
        return np.where(t < tr, c_ramp, np.where(t < ts, c_tr + self.f1 * (t - tr),
                                                 c_ts + self.f2 * (t - ts)))


def _frequency_step_input(system: System, profile: _FrequencyStep):
    from drymount.vehicle.inputs import Input

    U = np.asarray(system.excitation.amplitude, dtype=float)

    class FrequencyStepInput(Input):
        def _force(self, t):
            w = 2.0 * math.pi * profile.freq(t)
            return (w**2 * np.sin(2.0 * math.pi * profile.cycles(t)))[:, None] * U

    return FrequencyStepInput(system)


@dataclass(frozen=True)
class Jump:
    """Where a stepped sweep jumps: the last frequency before and the first after the
    jump (Hz, in sweep order) and the change of the amplitude there (m)."""

    f_before_hz: float
    f_after_hz: float
    change_m: float


def _jump_location(freq_hz, amplitude, direction: str) -> Jump:
    """The largest drop (up sweep) or rise (down sweep) of the amplitude between
    neighbouring steps, the points taken in sweep order."""
    f = np.asarray(freq_hz, dtype=float)
    a = np.asarray(amplitude, dtype=float)
    order = np.argsort(f) if direction == "up" else np.argsort(-f)
    f, a = f[order], a[order]
    d = np.diff(a)
    i = int(np.argmin(d)) if direction == "up" else int(np.argmax(d))
    return Jump(float(f[i]), float(f[i + 1]), float(d[i]))


@dataclass(frozen=True)
class _Fold:
    """Turning points of the HBM curve (indices, Hz, m) and the fold's band (Hz)."""

    indices: list
    freq_hz: list
    amp_m: list
    f_lo: float
    f_hi: float


def _fold(fr, amp, failures: list) -> _Fold:
    """The fold of the HBM curve; without two turning points, +-20 % about the peak
    (a failure)."""
    tps = [int(i) for i in fr.turning_points]
    tp_f = [float(fr.freq_hz[i]) for i in tps]
    tp_a = [float(amp[i]) for i in tps]
    if len(tps) >= 2:
        return _Fold(tps, tp_f, tp_a, min(tp_f), max(tp_f))
    failures.append(f"HBM found {len(tps)} turning points, expected 2: no fold "
                    "in the band")
    fpk = peak(fr.freq_hz, amp).freq_hz
    return _Fold(tps, tp_f, tp_a, 0.8 * fpk, 1.2 * fpk)


def _sweep_grid(fold: _Fold, step: float) -> np.ndarray:
    """Frequencies of the stepped sweeps: the fold plus ``JUMP_MARGIN`` of its width on
    each side, every ``step`` Hz."""
    w = fold.f_hi - fold.f_lo
    f_start = max(fold.f_lo - JUMP_MARGIN * w, step)
    return f_start + step * np.arange(
        int((fold.f_hi + JUMP_MARGIN * w - f_start) / step) + 1)


def _sweeps(system: System, freqs, progress: bool, failures: list) -> dict:
    """direction -> ``vehicle.sweep`` result (native backend), up and down."""
    import drymount.vehicle as vehicle

    sweeps = {}
    for direction in progress_bar(("up", "down"), "jump sweeps", progress):
        grid = freqs if direction == "up" else freqs[::-1]
        sw = vehicle.sweep(system, grid, direction=direction, backend="inproc",
                           progress=progress)
        if not np.all(sw.converged):
            failures.append(f"sweep {direction}: "
                            f"{int(np.sum(~np.asarray(sw.converged)))} steps did not "
                            "reach a steady state")
        sweeps[direction] = sw
    return sweeps


@dataclass
class _StepRun:
    """The Fig. 3.7 frequency step: its profile, time history and key numbers."""

    profile: _FrequencyStep
    t: np.ndarray
    x: np.ndarray
    summary: dict


def _frequency_step(system: System, jump_up: Jump, f_lo: float, step: float
                    ) -> _StepRun:
    """Ramp onto the upper branch, hold, step the frequency past the fold."""
    import drymount.vehicle as vehicle

    f1 = jump_up.f_before_hz - JUMP_STEP_BELOW_HZ
    f2 = jump_up.f_after_hz + JUMP_STEP_ABOVE_HZ
    f_a = max(0.9 * f_lo, step)
    t_step = JUMP_RAMP_S + JUMP_HOLD_S
    profile = _FrequencyStep(f_a, f1, f2, JUMP_RAMP_S, t_step)
    th = vehicle.simulate(system, duration=t_step + JUMP_AFTER_S, backend="inproc",
                          inputs=_frequency_step_input(system, profile),
                          dt=1.0 / (f2 * 128))
    t, x = np.asarray(th.t), np.asarray(th.q)[:, 0]

    def window_amp(a, b):
        m = (t >= a) & (t < b)
        return float(np.max(np.abs(x[m])))

    summary = {"f_ramp_start_hz": f_a, "f_before_hz": f1, "f_after_hz": f2,
               "t_step_s": t_step,
               "amp_before_m": window_amp(t_step - 1.0, t_step),
               "amp_after_m": window_amp(t_step + JUMP_AFTER_S - 1.0,
                                         t_step + JUMP_AFTER_S)}
    return _StepRun(profile, t, x, summary)


def _hysteresis(sweeps: dict, jumps: dict) -> list[float]:
    """Up minus down amplitude (m) at the up sweep's frequencies between both jumps
    (where the up sweep rides the upper branch)."""
    f_up = np.asarray(sweeps["up"].freq_hz, dtype=float)
    a_up = np.asarray(sweeps["up"].amplitude)[:, 0]
    f_dn = np.asarray(sweeps["down"].freq_hz, dtype=float)
    a_dn = np.asarray(sweeps["down"].amplitude)[:, 0]
    inside = ((f_up > jumps["down"].f_after_hz)
              & (f_up < jumps["up"].f_before_hz + 1e-12))
    return [float(a - float(np.interp(f, np.sort(f_dn), a_dn[np.argsort(f_dn)])))
            for f, a in zip(f_up[inside], a_up[inside], strict=True)]


def _branch_values(freq_hz, values, stable, f) -> list[float]:
    """Values of every stable segment of a (possibly folded) curve at frequency f."""
    fq = np.asarray(freq_hz, dtype=float)
    v = np.asarray(values, dtype=float)
    st = np.asarray(stable, dtype=bool)
    out = []
    for i in range(len(fq) - 1):
        if st[i] and st[i + 1] and min(fq[i], fq[i + 1]) <= f <= max(fq[i], fq[i + 1]):
            if fq[i + 1] == fq[i]:
                out.append(float(v[i]))
            else:
                t = (f - fq[i]) / (fq[i + 1] - fq[i])
                out.append(float(v[i] + t * (v[i + 1] - v[i])))
    return out


def _sweep_vs_hbm(sweeps: dict, fr, amp) -> float:
    """Largest difference of a sweep amplitude from the nearest HBM stable amplitude
    at the same frequency, relative to the HBM peak (NaN if none is comparable)."""
    rel = []
    for sw in sweeps.values():
        for f, a in zip(sw.freq_hz, np.asarray(sw.amplitude)[:, 0], strict=True):
            cand = _branch_values(fr.freq_hz, amp, fr.stable, float(f))
            if cand:
                ref = min(cand, key=lambda x: abs(x - a))
                rel.append(abs(a - ref) / max(amp))
    return float(max(rel)) if rel else float("nan")


def run_jump(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """Cubic single DOF: HBM fold with its unstable branch and the time-domain jump.

    The preset ``sdof_cubic`` (hardening spring, thesis Sec. 2.3) traced by arc-length
    continuation with H = ``JUMP_HARMONICS``; unstable points (``stable`` False) are
    dashed, turning points marked. Stepped sine sweeps up and down in the time domain
    (``vehicle.sweep``, native backend, each step starting from the previous steady
    state) across the fold show the jumps (thesis Figs. 3.5 and 3.7).

    Returns
    -------
    dict
        ``turning_points_hz``, ``turning_points_amp_m``, ``jump_up`` and
        ``jump_down`` (:class:`Jump`), ``hysteresis_m`` (the up-sweep amplitude minus
        the down-sweep amplitude at the frequencies between both jumps, m),
        ``sweep_vs_hbm_max_rel`` (largest relative difference of the sweep amplitudes
        from the HBM stable branch that the sweep is on), ``frequency_step``,
        ``failures``, ``files``.
    """
    out = Path(out_dir)
    system = load_system(JUMP_PRESET)
    H = JUMP_HARMONICS_QUICK if quick else JUMP_HARMONICS
    failures: list[str] = []
    c = hbm_curve(system, JUMP_BAND_HZ, H, {"H": H}, failures)
    amp = np.asarray(c.fr.amplitude)[:, 0]
    fold = _fold(c.fr, amp, failures)
    step = JUMP_STEP_QUICK_HZ if quick else JUMP_STEP_HZ
    freqs = _sweep_grid(fold, step)
    t0 = time.perf_counter()
    sweeps = _sweeps(system, freqs, progress, failures)
    t_sweep = time.perf_counter() - t0
    jumps = {d: _jump_location(sw.freq_hz, np.asarray(sw.amplitude)[:, 0], d)
             for d, sw in sweeps.items()}
    step_run = _frequency_step(system, jumps["up"], fold.f_lo, step)
    result = {
        "study": "jump", "harmonics": H, "band_hz": JUMP_BAND_HZ,
        "sweep_step_hz": step, "sweep_range_hz": (float(freqs[0]), float(freqs[-1])),
        "turning_points_hz": fold.freq_hz, "turning_points_amp_m": fold.amp_m,
        "jump_up": jumps["up"], "jump_down": jumps["down"],
        "hysteresis_m": _hysteresis(sweeps, jumps),
        "sweep_vs_hbm_max_rel": _sweep_vs_hbm(sweeps, c.fr, amp),
        "sweep_seconds": t_sweep, "hbm_seconds": c.seconds,
        "hbm_unstable_points": int(np.sum(~np.asarray(c.fr.stable, dtype=bool))),
        "frequency_step": step_run.summary,
        "system": system_values(system), "failures": failures,
    }
    _write_tables(c, sweeps, out)
    figs = [_plot_jump(c, amp, fold, sweeps, freqs, step_run, out)]
    atomic_write_text(out / "summary.md", _summary_jump(result, figs))
    result["files"] = sorted(p.name for p in out.iterdir())
    return result


def _write_tables(c: DesignResult, sweeps: dict, out: Path) -> None:
    write_curves(out / "jump_hbm.csv", "cubic single DOF, HBM: freq in Hz, x_amp in "
                 "m (fundamental amplitude), stable 1/0", [c])
    rows = [[d, f, a, bool(cv)] for d, sw in sweeps.items()
            for f, a, cv in zip(sw.freq_hz, np.asarray(sw.amplitude)[:, 0],
                                sw.converged, strict=True)]
    write_csv(out / "jump_sweeps.csv", ["direction", "freq_hz", "x_amp", "converged"],
              rows, comment="time-domain stepped sweeps (vehicle.sweep, native "
                            "backend): freq in Hz, x_amp in m (fundamental amplitude)")


def _plot_jump(c: DesignResult, amp, fold: _Fold, sweeps: dict, freqs,
               step_run: _StepRun, out: Path) -> str:
    fr, H = c.fr, c.case["H"]
    fig = new_figure(figsize=(11, 4.2))
    ax = fig.add_subplot(1, 2, 1)
    plot_branch(ax, fr.freq_hz, amp, fr.stable, color="black", lw=1.4,
                label=f"HBM H = {H} (unstable dashed)")
    ax.plot(fold.freq_hz, fold.amp_m, "o", mfc="none", color="black", ms=8,
            label="turning points")
    for d, marker, color in (("up", "^", "tab:red"), ("down", "v", "tab:blue")):
        ax.plot(sweeps[d].freq_hz, np.asarray(sweeps[d].amplitude)[:, 0], marker,
                color=color, ms=4, mfc="none", label=f"time domain, sweep {d}")
    log_axes(ax, ylabel="engine amplitude x [m]",
             title="cubic mount: fold and jumps (cf. thesis Figs. 3.5, 3.7)")
    ax.set_xlim(freqs[0] / 1.6, freqs[-1] * 1.6)
    ax.legend(fontsize=8)
    ax2 = fig.add_subplot(1, 2, 2)
    t_step, t, x = step_run.profile.t_step, step_run.t, step_run.x
    m = t >= t_step - JUMP_HOLD_S
    ax2.plot(t[m] - t_step, x[m] * 1e3, color="black", lw=0.6)
    ax2.axvline(0.0, color="tab:red", lw=1.0, ls="--")
    ax2.set_xlabel(f"time from the frequency step [s] (step at t = {t_step:g} s)")
    ax2.set_ylabel("engine displacement x [mm]")
    ax2.set_title(f"frequency step {step_run.profile.f1:.2f} -> "
                  f"{step_run.profile.f2:.2f} Hz after a {JUMP_RAMP_S:g} s "
                  "ramp (cf. Fig. 3.7)", fontsize=9)
    ax2.grid(True, alpha=0.3)
    fig.tight_layout()
    save_fig(fig, out / "jump.png")
    return "jump.png"


def _summary_jump(r, figs) -> str:
    tp = ", ".join(f"{f:.3f} Hz ({a * 1e3:.2f} mm)" for f, a in
                   zip(r["turning_points_hz"], r["turning_points_amp_m"], strict=True))
    up, dn = r["jump_up"], r["jump_down"]
    lines = [
        "# Study jump: cubic single DOF, fold and jump",
        "",
        f"System: {r['system']}.",
        "",
        f"- HBM (H = {r['harmonics']}, {r['hbm_seconds']:.2f} s): turning points at "
        f"{tp or 'none'}; {r['hbm_unstable_points']} points flagged unstable.",
        f"- Time domain (`vehicle.sweep`, native backend, steps of "
        f"{r['sweep_step_hz']:g} Hz from {r['sweep_range_hz'][0]:.2f} to "
        f"{r['sweep_range_hz'][1]:.2f} Hz, each step starting from the previous "
        f"steady state), sweep up: the amplitude drops by {-up.change_m * 1e3:.2f} mm "
        f"between {up.f_before_hz:.3f} and {up.f_after_hz:.3f} Hz.",
        f"- Time domain, sweep down: the amplitude rises by {dn.change_m * 1e3:.2f} mm "
        f"between {dn.f_before_hz:.3f} and {dn.f_after_hz:.3f} Hz.",
        f"- Between the jumps the up sweep stays on the upper branch: up minus down "
        f"amplitude {min(r['hysteresis_m'], default=float('nan')) * 1e3:.2f} to "
        f"{max(r['hysteresis_m'], default=float('nan')) * 1e3:.2f} mm at "
        f"{len(r['hysteresis_m'])} frequencies.",
        f"- Frequency step (Fig. 3.7): after a {JUMP_RAMP_S:g} s ramp from "
        f"{r['frequency_step']['f_ramp_start_hz']:.2f} Hz onto the upper branch, "
        f"{r['frequency_step']['f_before_hz']:.2f} Hz held (amplitude "
        f"{r['frequency_step']['amp_before_m'] * 1e3:.2f} mm), then "
        f"{r['frequency_step']['f_after_hz']:.2f} Hz: {JUMP_AFTER_S:g} s later the "
        f"amplitude is {r['frequency_step']['amp_after_m'] * 1e3:.2f} mm.",
        f"- Largest difference of a sweep amplitude from the HBM stable branch it is "
        f"on: {100 * r['sweep_vs_hbm_max_rel']:.2f} % of the HBM peak "
        f"({r['sweep_seconds']:.1f} s of time integration).",
        "",
        "The thesis (Fig. 3.7) steps the frequency from 8.8 to 8.9 Hz with its "
        "values and sees the amplitude drop; our preset's fold lies where its "
        "values put it (above).",
    ]
    if r["failures"]:
        lines += ["", "**Problems:**", ""] + [f"- {f}" for f in r["failures"]]
    lines += [""] + [f"![{f}]({f})" for f in figs] + [""]
    return "\n".join(lines)
