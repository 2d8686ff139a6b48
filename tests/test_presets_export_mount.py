"""``drymount presets export NAME PATH --mount FILE``: a fitted ``[mount]`` put into a
preset (issue 23 item 7)."""

from __future__ import annotations

from pathlib import Path

import pytest

from drymount import cli
from drymount.config import load_config, load_preset, preset_text

FITTED = """\
# Fitted by `drymount fit loops ...`
[mount]
law = "piecewise"
k1 = 45968.4                  # N/m
k2 = 257174.7                 # N/m
delta = 0.012257              # m
c = 149.925629                # N s/m

[mount.friction]
kf = 59881.41979              # N/m
mu = 1.0
n0 = 9.999663494              # N
"""


def run(argv, capsys):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("preset", ["sdof_halved", "quarter_car_halved"])
def test_the_fitted_mount_replaces_the_presets_and_nothing_else(tmp_path, capsys,
                                                                preset):
    fit = tmp_path / "mount.toml"
    fit.write_text(FITTED)
    path = tmp_path / "mine.toml"
    assert run(["presets", "export", preset, str(path), "--mount", str(fit)],
               capsys)[0] == 0
    got, ref = load_config(path), load_preset(preset)
    (axis,) = {el.params.axial for el in got.system.elements}
    assert (axis.k1, axis.k2, axis.delta, axis.c) == (45968.4, 257174.7, 0.012257,
                                                    149.925629)
    assert (axis.kf, axis.mu, axis.n0) == (59881.41979, 1.0, 9.999663494)
    assert got.name == "mine"
    assert got.system.dof_names == ref.system.dof_names
    assert (got.sweep, got.hbm) == (ref.sweep, ref.hbm)
    # every line outside the preset's [mount] tables is kept, in order
    text = path.read_text()
    kept = [ln for ln in preset_text(preset).splitlines()
            if ln.startswith(("[sdof]", "[excitation]", "[sweep]", "[hbm]", "[cosim]",
                              "[quarter_car]", "model ="))]
    assert [ln for ln in text.splitlines() if ln in kept] == kept
    assert text.count("[mount]") == 1 and "\n\n\n" not in text


def test_bad_mount_files_exit_2_and_write_nothing(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    whole = tmp_path / "whole.toml"
    whole.write_text(preset_text("sdof_halved"))
    bad_k = tmp_path / "bad.toml"
    bad_k.write_text(FITTED.replace("k1 = 45968.4", "k1 = -1.0"))
    fit = tmp_path / "mount.toml"
    fit.write_text(FITTED)
    cases = [
        ("sdof_halved", tmp_path / "nope.toml", "cannot read the file"),
        ("sdof_halved", whole, "must hold a [mount] table and nothing else"),
        ("sdof_halved", bad_k, "k1"),
        ("six_dof_halved", fit, "has no [mount] table"),
    ]
    for preset, mount, message in cases:
        code, _, err = run(["presets", "export", preset, str(path), "--mount",
                            str(mount)], capsys)
        assert code == 2 and message in err, err
        assert not path.exists()


def test_fit_elastic_without_c_leaves_it_out_and_says_so(tmp_path, capsys):
    """A quasi-static curve does not identify c: without ``--c`` the proposed mount
    has no ``c`` (a comment says it is unknown), so it cannot enter a configuration
    unnoticed, while ``fit loops`` (which fits c) still takes it as its elastic law."""
    data = Path(__file__).resolve().parent.parent / "examples" / "data"
    el = tmp_path / "el"
    assert run(["fit", "elastic", str(data / "rig_piecewise.csv"), "--out", str(el),
                "--no-plot"], capsys)[0] == 0
    text = (el / "mount.toml").read_text()
    assert "# c (N s/m) unknown" in text
    assert not [ln for ln in text.splitlines() if ln.startswith("c =")]
    code, _, err = run(["presets", "export", "sdof_halved", str(tmp_path / "x.toml"),
                        "--mount", str(el / "mount.toml")], capsys)
    assert code == 2 and "`mount.c` is missing" in err
    assert run(["fit", "loops", str(data / "rig_loops.csv"), "--mount",
                str(el / "mount.toml"), "--out", str(tmp_path / "lo"), "--no-plot"],
               capsys)[0] == 0
    code, _, err = run(["fit", "loops", str(data / "rig_loops.csv"), "--mount",
                        str(el / "mount.toml"), "--fix-c", "--out",
                        str(tmp_path / "lo2")], capsys)
    assert code == 2 and "`mount.c` is missing" in err
