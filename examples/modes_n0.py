"""The halved single-DOF mount's nonlinear mode at several normal forces: frequency
and modal damping ratio against vibration amplitude (docs/results.md, "Nonlinear
modes").

Run: ``python examples/modes_n0.py [OUT.png]`` (default ``modes_n0.png``); prints, per
n0, the stuck and fully slipped frequencies and the largest damping ratio with the
displacement amplitude where it occurs.
"""

from __future__ import annotations

import sys

import numpy as np

import drymount
from drymount.hbm.plot import plain_log_ticks

N0 = (5.0, 10.0, 20.0, 40.0)  # N; 10 N: the preset
#: modal amplitudes a = sqrt(m) X, kg^0.5 m: X from 0.012 to 12 mm on 70 kg
#: (below the knee at 12.25 mm)
RANGE = (1e-4, 0.1)


def main(out: str = "modes_n0.png") -> int:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 6), layout="constrained")
    ax_f, ax_d = fig.subplots(2, 1, sharex=True)
    print("n0 [N]  f at 0.012 mm [Hz]  f at 12 mm [Hz]  max D   at X [mm]")
    for n0 in N0:
        model = drymount.load("sdof_halved", f"mount.friction.n0={n0}")
        mode = drymount.modes(model, 1, RANGE).modes[0]
        x_mm = mode.dof_amplitude[:, 0] * 1e3
        ax_f.plot(x_mm, mode.freq_hz, label=f"n0 = {n0:g} N")
        ax_d.plot(x_mm, mode.damping_ratio * 100, label=f"n0 = {n0:g} N")
        k = int(np.argmax(mode.damping_ratio))
        print(f"{n0:6.1f}  {mode.freq_hz[0]:18.4f}  {mode.freq_hz[-1]:16.4f}  "
              f"{mode.damping_ratio[k]:.4f}  {x_mm[k]:9.3f}")
    ax_f.set_ylabel("frequency [Hz]")
    ax_d.set_ylabel("modal damping ratio [%]")
    ax_d.set_xlabel("displacement amplitude X (fundamental) [mm]")
    for ax in (ax_f, ax_d):
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize="small")
        plain_log_ticks(ax)
    ax_f.set_title("sdof_halved: nonlinear mode (EPMC, H = 7) against amplitude")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(*sys.argv[1:2]))
