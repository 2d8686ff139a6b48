"""The harmonic count H and the AFT sample count N are checked once, at the edge
(issue 24): ``drymount.hbm.options.check_harmonics`` / ``check_samples`` with the one
bound ``MAX_HARMONICS`` / ``MAX_N_SAMPLES``, called by the CLI's parser and commands,
the configuration, ``[design]``, the API and ``HBMOptions``; every message names the
field, the value and the allowed range (the expected texts are written out here).
``drymount hbm`` calls ``drymount.api.hbm`` and writes what it returns."""

from __future__ import annotations

from pathlib import Path

import pytest

import drymount
from drymount import cli
from drymount.config import ConfigError, load_config, preset_text
from drymount.hbm.options import (
    MAX_HARMONICS,
    MAX_N_SAMPLES,
    CountError,
    HBMOptions,
    check_harmonics,
    check_samples,
)

ROOT = Path(__file__).resolve().parents[1]


def run(argv, capsys):
    code = cli.main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_the_bounds():
    assert (MAX_HARMONICS, MAX_N_SAMPLES) == (50, 8192)
    import drymount.config as config

    assert config.MAX_HARMONICS is MAX_HARMONICS  # re-exported, not a second one
    assert config.MAX_N_SAMPLES is MAX_N_SAMPLES


@pytest.mark.parametrize("value", [0, 51, -3, 2.5, True, "7", None])
def test_check_harmonics_refuses(value):
    with pytest.raises(CountError) as info:
        check_harmonics(value, "hbm.harmonics")
    assert str(info.value) == (f"`hbm.harmonics` must be an integer in 1..50, got "
                               f"{value!r}")
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("value", [1, 7, 50])
def test_check_harmonics_accepts(value):
    assert check_harmonics(value) == value


def test_check_samples():
    assert check_samples(7, 3) == 7 and check_samples(8192, 50) == 8192
    for n in (6, 8193, 7.0):
        with pytest.raises(CountError) as info:
            check_samples(n, 3)
        assert info.value.named("--n-samples") == (
            f"--n-samples must be an integer in 7..8192 (>= 2H + 1 = 7 for H = 3), "
            f"got {n!r}")


# -- the edges ---------------------------------------------------------------------


@pytest.mark.parametrize("command", ["hbm", "modes"])
@pytest.mark.parametrize("option", ["--harmonics", "-H"])
def test_cli_harmonics(command, option, capsys):
    code, _, err = run([command, "sdof_halved", option, "51"], capsys)
    assert code == 2
    assert "--harmonics/-H: must be an integer in 1..50, got 51" in err, err


def test_cli_max_harmonics(capsys):
    code, _, err = run(["hbm", "sdof_halved", "--max-harmonics", "x"], capsys)
    assert code == 2
    assert "argument --max-harmonics: must be an integer in 1..50, got 'x'" in err


@pytest.mark.parametrize("command", ["hbm", "modes"])
def test_cli_samples_against_harmonics(command, tmp_path, capsys):
    out = tmp_path / "c.csv"
    code, _, err = run([command, "sdof_halved", "-H", "3", "--n-samples", "5",
                        "--out", str(out)], capsys)
    assert code == 2
    assert ("--n-samples must be an integer in 7..8192 (>= 2H + 1 = 7 for H = 3), "
            "got 5") in err, err
    assert not out.exists()


def test_cli_samples_from_the_configuration(tmp_path, capsys):
    """N from [hbm] too small for the H of --harmonics: the message names the
    configuration's field, where the value came from."""
    code, _, err = run(["hbm", "sdof_halved", "--set", "hbm.n_samples=16", "-H", "9",
                        "--out", str(tmp_path / "c.csv")], capsys)
    assert code == 2
    assert ("`hbm.n_samples` must be an integer in 19..8192 (>= 2H + 1 = 19 for "
            "H = 9), got 16") in err, err


def _config(tmp_path, table: str):
    """sdof_halved with ``[hbm]`` replaced by ``table``."""
    text = preset_text("sdof_halved")
    assert text.count("[hbm]\nharmonics = 7\n") == 1
    p = tmp_path / "c.toml"
    p.write_text(text.replace("[hbm]\nharmonics = 7\n", "[hbm]\n" + table + "\n"),
                 encoding="utf-8")
    return p


@pytest.mark.parametrize("table, message", [
    ("harmonics = 51", "`hbm.harmonics` must be an integer in 1..50, got 51"),
    ("max_harmonics = 0", "`hbm.max_harmonics` must be an integer in 1..50, got 0"),
    ("harmonics = 4.0", "`hbm.harmonics` must be an integer in 1..50, got 4.0"),
    ("harmonics = 5\nn_samples = 10",
     "`hbm.n_samples` must be an integer in 11..8192 (>= 2H + 1 = 11 for H = 5), got "
     "10"),
])
def test_config(table, message, tmp_path):
    with pytest.raises(ConfigError) as info:
        load_config(_config(tmp_path, table))
    assert message in info.value.problems, info.value.problems


def test_design_harmonics(tmp_path):
    from drymount.design.check import design_space

    text = (ROOT / "examples/design/sdof_n0.toml").read_text(encoding="utf-8")
    assert text.count("\nharmonics = 1 ") == 1
    p = tmp_path / "d.toml"
    p.write_text(text.replace("\nharmonics = 1 ", "\nharmonics = 60 "),
                 encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        design_space(load_config(p))
    assert "`design.harmonics` must be an integer in 1..50, got 60" in \
        info.value.problems


@pytest.mark.parametrize("kw, message", [
    ({"harmonics": 51}, "`harmonics` must be an integer in 1..50, got 51"),
    ({"harmonics": 2.5}, "`harmonics` must be an integer in 1..50, got 2.5"),
    ({"max_harmonics": 0}, "`max_harmonics` must be an integer in 1..50, got 0"),
    ({"harmonics": 3, "n_samples": 6},
     "`n_samples` must be an integer in 7..8192 (>= 2H + 1 = 7 for H = 3), got 6"),
    ({"n_samples": 10**9},
     "`n_samples` must be an integer in 15..8192 (>= 2H + 1 = 15 for H = 7), got "
     "1000000000"),
])
def test_api(kw, message):
    for call in (drymount.hbm, drymount.modes):
        if "max_harmonics" in kw and call is drymount.modes:
            continue
        with pytest.raises(CountError) as info:
            call("sdof_halved", **kw)
        assert str(info.value) == message


def test_hbm_options():
    with pytest.raises(ValueError) as info:
        HBMOptions(harmonics=51, max_harmonics=0)
    assert str(info.value) == (
        "invalid HBMOptions: `harmonics` must be an integer in 1..50, got 51; "
        "`max_harmonics` must be an integer in 1..50, got 0")
    with pytest.raises(ValueError, match=r"`n_samples` must be an integer in 7\.\."):
        HBMOptions(harmonics=3, n_samples=6)
    assert HBMOptions(harmonics=50, n_samples=101).harmonics == 50


# -- drymount hbm through the API ---------------------------------------------------


def test_cli_hbm_calls_the_api(tmp_path, capsys, monkeypatch):
    """`drymount hbm` passes its options to drymount.api.hbm and writes the curve it
    returns: the CSV equals the API's own to the byte."""
    import drymount.api as api

    calls = []
    real = api.hbm

    def spy(*a, **kw):
        calls.append((a, kw))
        return real(*a, **kw)

    monkeypatch.setattr(api, "hbm", spy)
    out = tmp_path / "cli.csv"
    code, stdout, _ = run(["hbm", "sdof_cubic", "-q", "-H", "3", "--n-samples", "32",
                           "--fmin", "2", "--fmax", "14", "--tol", "0.01",
                           "--ds-max", "0.08", "--out", str(out)], capsys)
    assert code == 0
    (model, fmin, fmax), kw = calls[0]
    assert (model.name, fmin, fmax) == ("sdof_cubic", 2.0, 14.0)
    assert kw == {"harmonics": 3, "n_samples": 32, "progress": False, "tol": 0.01,
                  "max_harmonics": None, "ds_initial": None, "ds_min": None,
                  "ds_max": 0.08, "max_angle": None}
    curve = real("sdof_cubic", 2, 14, harmonics=3, n_samples=32, tol=0.01,
                 ds_max=0.08, progress=False)
    curve.to_csv(tmp_path / "api.csv")
    assert out.read_bytes() == (tmp_path / "api.csv").read_bytes()
    p = curve.peak()
    assert f"sdof_cubic: peak transmissibility {p.value:.4g} at {p.freq_hz:.4g} Hz" \
        in stdout
