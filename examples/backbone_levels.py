"""Forced curves of the cubic mount at three unbalance levels and the backbone of its
mode: the resonance peaks lie on the backbone (docs/physics.md, section 7).

Run: ``python examples/backbone_levels.py [OUT.png]`` (default
``backbone_levels.png``); prints, per level, the located peak and the backbone's
frequency at the peak's amplitude.
"""

from __future__ import annotations

import sys

import numpy as np

import drymount
from drymount.backbone import backbones
from drymount.hbm.plot import plain_log_ticks

LEVELS = (0.02, 0.035, 0.0552)  # unbalance f0, kg m (0.0552: the preset)


def main(out: str = "backbone_levels.png") -> int:
    from matplotlib.figure import Figure

    base = drymount.load("sdof_cubic")
    curves = [drymount.hbm(base.with_({"excitation.amplitude": f0}), 1.0, 12.0,
                           progress=False).result for f0 in LEVELS]
    modes = backbones(base.system, curves[-1])
    mode = modes.modes[0]
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.add_subplot()
    print("f0 [kg m]  peak [Hz]   x [mm]   backbone at that amplitude [Hz]  rel. diff")
    for f0, fr in zip(LEVELS, curves, strict=True):
        line, = ax.plot(fr.freq_hz, fr.amplitude[:, 0] * 1e3, lw=1.2,
                        label=f"forced, f0 = {f0} kg m")
        pk = max(fr.peaks, key=lambda p: p.amplitude[0])
        ax.plot([pk.freq_hz], [pk.amplitude[0] * 1e3], "o", color=line.get_color())
        f_bb = float(np.interp(pk.amplitude[0], mode.dof_amplitude[:, 0],
                               mode.freq_hz))
        print(f"{f0:9.4f}  {pk.freq_hz:9.5f}  {pk.amplitude[0] * 1e3:7.3f}   "
              f"{f_bb:9.5f}                        {(pk.freq_hz - f_bb) / f_bb:+.2e}")
    keep = mode.freq_hz <= 12.0
    ax.plot(mode.freq_hz[keep], mode.dof_amplitude[keep, 0] * 1e3, "k-.",
            label=f"backbone, mode {mode.index} ({mode.label}), EPMC")
    ax.set_yscale("log")
    ax.set_ylim(0.05, 40)
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("x fundamental amplitude [mm]")
    ax.set_title("sdof_cubic: forced curves (H = 7) and the backbone;\n"
                 "dots: the located resonance peaks")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    plain_log_ticks(ax)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(*sys.argv[1:2]))
