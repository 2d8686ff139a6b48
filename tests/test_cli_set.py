"""`--set` on every command that lists it (issue 26 item 6, issue 25 item 8).

The commands are taken from the parser, so a new command that lists `--set` is tested
here without being named. An invalid override must stop it with exit 2 naming the
field before any work (the override reached the configuration the command uses);
`static` and `characterise` are also checked against the overridden value's numbers.
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import pytest

from drymount import cli

ROOT = Path(__file__).resolve().parents[1]
DESIGN = str(ROOT / "examples" / "design" / "sdof_n0.toml")
#: sdof_linear: 70 kg on k1 = 91 870 N/m, c = 150 N s/m (the preset)
MASS, G = 70.0, 9.81


def _commands_with_set() -> list[str]:
    sub = next(a for a in cli.build_parser()._actions
               if isinstance(a, argparse._SubParsersAction))
    return sorted(name for name, p in sub.choices.items()
                  if any(a.dest == "overrides" for a in p._actions))


#: what each command needs besides CONFIG to get past its own argument checks
EXTRA = {"export-ssp": ["--out", "{tmp}/x.ssp"]}


def test_the_commands_with_set_include_the_ones_that_dropped_it():
    names = _commands_with_set()
    assert {"static", "characterise", "export-ssp", "hbm", "cosim", "sweep",
            "explore", "optimize"} <= set(names), names


@pytest.mark.parametrize("command", _commands_with_set())
def test_every_command_listing_set_applies_it(command, tmp_path, capsys):
    config = DESIGN if command in ("explore", "optimize") else "sdof_linear"
    extra = [a.format(tmp=tmp_path) for a in EXTRA.get(command, [])]
    code = cli.main([command, config, "--set", "mount.c=-1", *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "with --set mount.c=-1" in err and "`mount.c` must be finite and >= 0, " \
        "got -1.0" in err, err
    assert not list(tmp_path.iterdir()), "nothing is written for a refused override"


def test_static_uses_the_overridden_stiffness(tmp_path, capsys):
    out = tmp_path / "st.csv"
    assert cli.main(["static", "sdof_linear", "--set", "mount.k1=50000",
                     "--out", str(out)]) == 0
    sag = MASS * G / 50000.0  # m g / k1 = 13.734 mm
    assert f"deflection {-sag * 1e3:9.4f} mm" in capsys.readouterr().out
    rows = list(csv.DictReader(ln for ln in out.read_text().splitlines()
                               if not ln.startswith("#")))
    assert math.isclose(float(rows[0]["deflection_m"]), -sag, rel_tol=1e-9)


def test_characterise_uses_the_overridden_law(tmp_path, capsys):
    out = tmp_path / "ch"
    assert cli.main(["characterise", "sdof_linear", "--set", "mount.k1=50000",
                     "--set", "mount.c=0", "--points", "2", "--fmin", "1", "--fmax",
                     "2", "--amplitudes-mm", "1", "--check", "law", "-q",
                     "--out", str(out)]) == 0
    # linear law without damping: K* = k1 at every frequency and amplitude
    assert "|K*| 5e+04 to 5e+04 N/m" in capsys.readouterr().out
