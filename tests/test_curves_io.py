"""Curves read back and plotted (issue 23 items 4 and 5): ``sweep --hbm`` refuses a
curve of another system, ``examples/plot_curves.py`` reads sweep CSVs as well as HBM
ones, ``drymount.Curve.plot`` returns a Figure for both kinds."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import drymount
from drymount import cli

Figure = pytest.importorskip("matplotlib.figure").Figure

ROOT = Path(__file__).resolve().parents[1]


def _curve_csv(path: Path, system: str) -> Path:
    path.write_text(f"# drymount HBM {system}: H=7 (AFT N=64); success=True (done)\n"
                    "freq_hz,x_amp,x_peak,transmissibility,stable,err_truncation,"
                    "err_sampling\n2,1e-3,1e-3,1.5,1,1e-4,1e-4\n3,2e-3,2e-3,2.5,0,"
                    "1e-4,1e-4\n", encoding="utf-8")
    return path


def test_sweep_refuses_a_curve_of_another_system(tmp_path, capsys):
    curve = _curve_csv(tmp_path / "other.csv", "quarter_car_halved")
    code = cli.main(["sweep", "sdof_halved", "--points", "3", "--backend", "inproc",
                     "-q", "--hbm", str(curve), "--out", str(tmp_path / "s.csv")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "'quarter_car_halved'" in err and "'sdof_halved'" in err, err
    assert not (tmp_path / "s.csv").exists()


def test_sweep_reads_a_curve_of_its_own_system(tmp_path):
    curve = cli._CurveCSV(_curve_csv(tmp_path / "own.csv", "sdof_halved"))
    assert curve.system_name == "sdof_halved"
    np.testing.assert_array_equal(curve.freq_hz, [2.0, 3.0])
    np.testing.assert_array_equal(curve.stable, [True, False])


def _plot_curves():
    spec = importlib.util.spec_from_file_location(
        "plot_curves", ROOT / "examples" / "plot_curves.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_plot_curves_reads_sweep_and_hbm_csvs(tmp_path):
    mod = _plot_curves()
    sweep = tmp_path / "sweep.csv"
    sweep.write_text("# drymount sweep sdof_halved: ...\nfreq_hz,x_amp,"
                     "transmissibility,converged\n2,1e-3,1.2,1\n3,2e-3,2.2,0\n",
                     encoding="utf-8")
    f, t, ok = mod.read(sweep)
    assert (f, t, ok) == ([2.0, 3.0], [1.2, 2.2], [True, False])
    f, t, ok = mod.read(_curve_csv(tmp_path / "hbm.csv", "sdof_halved"))
    assert (f, t, ok) == ([2.0, 3.0], [1.5, 2.5], [True, False])
    out = tmp_path / "both.png"
    assert mod.main([str(out), f"{sweep}=sweep", f"{tmp_path / 'hbm.csv'}=hbm"]) == 0
    assert out.stat().st_size > 1000


@pytest.mark.parametrize("kind", ["hbm", "sweep"])
def test_curve_plot_returns_a_figure(kind, tmp_path):
    model = drymount.load("sdof_linear")
    if kind == "hbm":
        curve = drymount.hbm(model, 2.0, 15.0, harmonics=1, progress=False)
    else:
        curve = drymount.sweep(model, 2.0, 15.0, points=3, backend="inproc",
                               progress=False)
    assert isinstance(curve.plot(), Figure)
    fig = curve.plot(tmp_path / "c.png")
    assert isinstance(fig, Figure) and (tmp_path / "c.png").stat().st_size > 1000


def test_a_sweep_that_misses_the_hbm_peak_suggests_refine(tmp_path):
    curve = cli._CurveCSV(_curve_csv(tmp_path / "own.csv", "sdof_halved"))
    assert curve.transmissibility_max() == (3.0, 2.5)  # no events: the largest row
    (tmp_path / "own_events.csv").write_text(
        "# events\nkind,dof,freq_hz,after_row,converged,x_amp,x_peak,"
        "transmissibility\npeak,x,2.9,0,1,2e-3,2e-3,2.6\n"
        "peak,transmissibility,2.95,0,1,2e-3,2e-3,3.08\n", encoding="utf-8")
    curve = cli._CurveCSV(tmp_path / "own.csv")
    assert curve.transmissibility_max() == (2.95, 3.08)
    hint = cli._missed_peak([1.0, 2.75, 1.5], curve)
    assert "2.75 against 3.08 at 2.95 Hz" in hint and "--refine" in hint
    assert cli._missed_peak([1.0, 3.0, 1.5], curve) == ""  # within 5 %
