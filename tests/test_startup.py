"""Start-up (issue 27 item 1): ``drymount --help``, ``presets list``, every command's
``--help``, the usage errors found by the parser and a CONFIG that names neither a
file nor a preset load nothing heavy.

Guarded by the modules a fresh CLI process imported (``sys.modules``), not by a timer
(CPU times belong in ``bench/bench_startup.py``): no NumPy, SciPy, Matplotlib, numba,
fmpy, threadpoolctl, process pools, and no ``importlib.metadata`` (``--version`` looks
the version up only when asked). One fresh process per case: what one case imports
must not hide what the next imports.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from drymount.cli_parser import build_parser

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
           PYTHONPATH=str(ROOT))
#: Top-level packages none of these commands may import.
HEAVY = ("numpy", "scipy", "matplotlib", "numba", "fmpy", "threadpoolctl",
         "concurrent", "multiprocessing")
#: Runs drymount's main in a fresh process; prints the exit status and what loaded.
_DRIVER = """
import contextlib, io, json, sys
from drymount.cli import main
err = io.StringIO()
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
    code = main(sys.argv[1:])
print(json.dumps({"code": code, "err": err.getvalue(), "modules": sorted(sys.modules)}))
"""


def _commands() -> list[str]:
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    return sorted(sub.choices)


def _run(args, cwd) -> tuple[int, str, list]:
    p = subprocess.run([sys.executable, "-c", _DRIVER, *args], cwd=cwd, env=ENV,
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout.splitlines()[-1])
    return r["code"], r["err"], r["modules"]


def _heavy(modules) -> list[str]:
    return sorted(m for m in modules if m.split(".")[0] in HEAVY
                  or m == "importlib.metadata")


def test_every_command_is_guarded():
    # the parametrisation below reads the parser: a new command is guarded too
    assert {"hbm", "sweep", "cosim", "presets", "explore", "modes"} <= set(_commands())


@pytest.mark.parametrize("args", [["--help"], ["presets", "list"]]
                         + [[c, "--help"] for c in _commands()])
def test_help_and_presets_list_load_nothing_heavy(tmp_path, args):
    code, err, modules = _run(args, tmp_path)
    assert code == 0, err
    assert "drymount.cli_parser" in modules
    assert not _heavy(modules), _heavy(modules)


@pytest.mark.parametrize("args, word", [
    (["hbm", "sdof_halved", "--harmonics", "0"], "--harmonics"),
    (["hbm", "sdof_halved", "--bogus"], "--bogus"),
    (["sweep", "sdof_halved", "--points", "x"], "--points"),
    (["cosim"], "CONFIG"),
    (["nosuchcommand"], "nosuchcommand"),
    (["hbm", "sdof_halvd"], "did you mean preset `sdof_halved`"),
    (["sweep", "no/such/file.toml"], "neither a file nor a preset"),
    (["cosim", "no/such/file.toml"], "neither a file nor a preset"),
    (["explore", "sdof_halvd"], "did you mean preset `sdof_halved`"),
    (["modes", "sdof_halvd"], "did you mean preset `sdof_halved`"),
])
def test_usage_errors_load_nothing_heavy(tmp_path, args, word):
    code, err, modules = _run(args, tmp_path)
    assert code == 2, err
    assert word in err, err
    assert "Traceback" not in err
    assert not _heavy(modules), _heavy(modules)


def test_presets_list_describes_as_the_loaded_presets(capsys):
    """The descriptions read from the files are those of the loaded models."""
    from drymount import cli
    from drymount.config import list_presets, load_preset

    assert cli.main(["presets", "list"]) == 0
    out = capsys.readouterr().out.splitlines()
    names = list_presets()
    assert len(out) == len(names) == 17   # 14 + the three hydraulic presets
    width = max(map(len, names))
    assert out == [f"{n:<{width}}  {load_preset(n).description}" for n in names]


def test_version_still_printed(capsys):
    from importlib.metadata import version

    from drymount import cli

    assert cli.main(["--version"]) == 0
    assert capsys.readouterr().out == f"drymount {version('drymount')}\n"


@pytest.mark.parametrize("args", [
    ["sweep", "sdof_halved", "--out", "."],
    ["hbm", "sdof_halved", "--out", "."],
    ["cosim", "sdof_halved", "--out", "."],
    ["modes", "sdof_halved", "--out", "."],
    ["hbm", "sdof_halved", "--plot", "curve.bogus"],
])
def test_bad_output_path_is_told_before_the_configuration_loads(tmp_path, args):
    """``--out`` naming a folder (or ``--plot`` naming no format) is checked before
    the configuration loads: nothing heavy, NumPy included."""
    code, err, modules = _run(args, tmp_path)
    assert code == 2, err
    option = args[-2]
    assert f"drymount: error: {option}: " in err, err
    assert ("is a directory" in err) if option == "--out" else ("bogus" in err)
    assert "Traceback" not in err
    assert not _heavy(modules), _heavy(modules)
    assert "drymount.config.loading" not in modules


#: What a bad --set value may load: the configuration check needs the law's own
#: checks (fmu_src.mount_law, hence NumPy), nothing of the solvers, plots or FMI.
SET_HEAVY = tuple(h for h in HEAVY if h != "numpy")


@pytest.mark.parametrize("command", ["hbm", "cosim", "sweep", "modes"])
def test_bad_set_value_loads_no_solver(tmp_path, command):
    code, err, modules = _run([command, "sdof_halved", "--set", "mount.k1=-1"],
                              tmp_path)
    assert code == 2, err
    assert "`mount.k1` must be finite and >= 0, got -1.0" in err, err
    assert "Traceback" not in err
    heavy = sorted(m for m in modules if m.split(".")[0] in SET_HEAVY)
    assert not heavy, heavy
    solvers = sorted(m for m in modules if m in (
        "drymount.api", "drymount.hbm.analysis", "drymount.hbm.continuation",
        "drymount.hbm.folds", "drymount.vehicle.master", "drymount.vehicle.sweep"))
    assert not solvers, solvers


def test_an_hbm_curve_loads_no_scipy_optimize(tmp_path):
    """A frequency-response curve (and the fold and peak location it runs) loads no
    ``scipy.optimize`` (0.15 s of every curve's start: ``hbm.roots`` is its
    Brent)."""
    out = tmp_path / "c.csv"
    code, err, modules = _run(["hbm", "sdof_halved", "--harmonics", "3",
                               "--n-samples", "64", "--quiet", "--out", str(out)],
                              tmp_path)
    assert code == 0, err
    assert "drymount.hbm.folds" in modules and "scipy.linalg" in modules
    assert not [m for m in modules if m.startswith("scipy.optimize")]
