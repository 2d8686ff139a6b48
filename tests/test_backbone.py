"""``drymount hbm --backbone`` (issue 29, item 2): the nonlinear mode traced over the
forced curve's amplitudes passes through its resonance peak.

For a linear oscillator under unbalance the amplitude peaks at
``omega_0 / sqrt(1 - 2 D^2)``, off the undamped frequency by about ``D^2``; along the
peak of ``sdof_cubic`` the damping ratio is about 0.02 (c = 150 N s/m on 70 kg at
8.9 Hz), so the located peak sits within ``D^2`` = 4e-4 of the backbone at its
amplitude; the bar is 1e-3 (the Duffing check at D = 0.002 in tests/test_modes.py
holds 1e-4).
"""

from __future__ import annotations

import numpy as np

from drymount.cli import main

REL_TOL = 1e-3


def _backbone(path):
    lines = path.read_text(encoding="utf-8").splitlines()
    assert lines[0].startswith("# drymount modes")
    cols = lines[1].split(",")
    data = np.array([[float(v) for v in ln.split(",")[3:]] for ln in lines[2:]])
    return {c: data[:, k] for k, c in enumerate(cols[3:])}


def test_the_peak_lies_on_the_backbone(tmp_path, capsys):
    out = tmp_path / "c.csv"
    assert main(["hbm", "sdof_cubic", "--quiet", "--backbone", "--out", str(out),
                 "--plot", str(tmp_path / "c.png")]) == 0
    assert "backbones of mode(s) 1 (x)" in capsys.readouterr().err
    bb = _backbone(tmp_path / "c_backbone.csv")
    rows = [ln.split(",") for ln in (tmp_path / "c_events.csv").read_text(
        encoding="utf-8").splitlines()[2:]]
    peak = next(r for r in rows if r[0] == "peak" and r[1] == "x")
    f_peak, x_peak = float(peak[2]), float(peak[5])
    order = np.argsort(bb["x_amp"])
    f_bb = float(np.interp(x_peak, bb["x_amp"][order], bb["freq_hz"][order]))
    assert abs(f_peak - f_bb) / f_bb < REL_TOL, (f_peak, f_bb)
    assert (tmp_path / "c.png").stat().st_size > 0


def test_a_users_file_beside_the_output_is_refused_before_computing(tmp_path):
    mine = tmp_path / "c_backbone.csv"
    mine.write_text("my data\n", encoding="utf-8")
    assert main(["hbm", "sdof_cubic", "--quiet", "--backbone", "--out",
                 str(tmp_path / "c.csv")]) == 2
    assert mine.read_text(encoding="utf-8") == "my data\n"
    assert not (tmp_path / "c.csv").exists()


def test_the_plot_draws_the_backbone_on_the_amplitude_panel():
    import drymount
    from drymount.backbone import backbones
    from drymount.hbm.plot import plot_figure

    fr = drymount.hbm("sdof_linear", 3.0, 9.0, harmonics=1, progress=False).result
    modes = backbones(drymount.load("sdof_linear").system, fr)
    fig = plot_figure(fr, backbones=modes)
    labels = [ln.get_label() for ln in fig.axes[1].get_lines()]
    assert any(lb.startswith("backbone, mode 1") for lb in labels)
    # linear: the backbone is the vertical line at the undamped natural frequency
    f = modes.modes[0].freq_hz
    assert np.ptp(f) < 1e-9 * f[0]
