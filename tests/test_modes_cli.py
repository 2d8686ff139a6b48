"""``drymount modes`` and ``drymount.modes``: outputs, bad input (exit 2 before any
work), the API equal to the CLI's computation."""

import numpy as np
import pytest

import drymount
from drymount import cli
from drymount.hbm.modes import nonlinear_modes
from drymount.paths import load_with_overrides


def run(argv, capsys):
    code = cli.main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_help_lists_modes_with_an_example(capsys):
    code, out, _ = run(["--help"], capsys)
    assert code == 0 and "    modes " in out
    code, out, _ = run(["modes", "--help"], capsys)
    assert code == 0
    assert out.split("examples:")[1].split()[0:2] == ["drymount", "modes"]
    for flag in ("--mode", "--amplitude-range", "--out", "--plot", "--harmonics"):
        assert flag in out


def test_modes_writes_csv_plot_and_summary(tmp_path, capsys):
    out, png = tmp_path / "m.csv", tmp_path / "m.png"
    code, text, err = run(["modes", "sdof_halved", "-H", "1", "--out", str(out),
                           "--plot", str(png)], capsys)
    assert code == 0, err
    assert f"wrote {out} (1 mode(s)" in err
    assert "mode 1 (x): 6.191 Hz at a =" in text   # stuck: sqrt((k1+kf)/m)/(2 pi)
    assert "mount_axial slips from a =" in text
    lines = out.read_text().splitlines()
    assert lines[0].startswith("# drymount modes sdof_halved: EPMC, H=1 (closed forms)")
    assert lines[1].startswith("mode,label,dominant,amplitude,freq_hz,damping_ratio,"
                               "xi,x_amp")
    f0 = float(lines[2].split(",")[4])
    assert f0 == pytest.approx(np.sqrt((45935.0 + 60000.0) / 70.0) / (2 * np.pi),
                               rel=1e-10)
    assert png.stat().st_size > 1000


@pytest.mark.parametrize("argv, message", [
    (["--mode", "q"], "--mode: `mode` must be 'all', 1..1 or a DOF name"),
    (["--mode", "2"], "--mode: `mode` must be 'all', 1..1"),
    (["--amplitude-range", "1", "0.1"], "--amplitude-range must satisfy A0 < A1"),
    (["--amplitude-range", "0", "0.1"], "must be a finite number > 0"),
    (["-H", "3", "--n-samples", "5"], "--n-samples must be an integer in 7..8192 "
                                      "(>= 2H + 1 = 7 for H = 3), got 5"),
])
def test_bad_input_exits_2_before_writing(argv, message, tmp_path, capsys):
    out = tmp_path / "m.csv"
    code, _, err = run(["modes", "sdof_halved", *argv, "--out", str(out)], capsys)
    assert code == 2
    assert message in err
    assert not out.exists()


def test_api_equals_the_module():
    r = drymount.modes("six_dof_halved", "z", (1e-3, 3e-2), harmonics=1)
    system = load_with_overrides("six_dof_halved", []).system
    ref = nonlinear_modes(system, "z", (1e-3, 3e-2), harmonics=1)
    assert r.success and [m.label for m in r.modes] == ["z"]
    np.testing.assert_array_equal(r.modes[0].freq_hz, ref.modes[0].freq_hz)
    np.testing.assert_array_equal(r.modes[0].damping_ratio, ref.modes[0].damping_ratio)
    with pytest.raises(ValueError, match="`harmonics` must be an integer in"):
        drymount.modes("sdof_halved", harmonics=0)


def test_interrupt_writes_the_points_so_far(tmp_path, capsys, monkeypatch):
    """Ctrl-C during the continuation: exit 130 and the points computed so far in
    the CSV, marked partial."""
    import drymount.hbm.modes as modes_mod

    real = modes_mod.continue_branch

    def interrupted_after_5(*args, **kw):
        calls = []

        def callback(lam):
            calls.append(lam)
            if len(calls) == 5:
                raise KeyboardInterrupt
        return real(*args, callback=callback, **kw)

    monkeypatch.setattr(modes_mod, "continue_branch", interrupted_after_5)
    out = tmp_path / "m.csv"
    code, _, err = run(["modes", "sdof_halved", "-H", "1", "--out", str(out)], capsys)
    assert code == 130, err
    lines = out.read_text().splitlines()
    assert lines[0].startswith("# partial: ") and "6 points computed" in lines[0]
    assert lines[1].startswith("# drymount modes sdof_halved")
    assert len(lines) == 3 + 6   # the start point and the 5 accepted steps
