"""Design-space exploration and optimisation (drymount.design, issue 16).

References: the RMS measure against closed-form integrals; the Pareto mask against a
brute-force definition; the sample against the Latin-hypercube property; the
optimiser against the existing optimize-n0 study's own minimiser (grid scan then
bounded Brent, tightened to 0.01 N); the Dask and process backends against the
serial run of the same designs (identical tables).

Runtime (2 cores, shared): about 40 s in total, most of it the 64-design LocalCluster
run (~15 s with cluster start-up) and the optimiser (~6 s).
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from drymount import cli
from drymount.config import ConfigError, load_config, preset_text
from drymount.design import design_space, explore, parse_backend
from drymount.design.backends import (MAX_WORKERS, BackendError, BackendKind,
                                      _check_reachable)
from drymount.design.evaluate import band_rms
from drymount.design.optimize import OptimizeSettings, optimize
from drymount.design.report import pareto_mask
from drymount.design.sampling import sample
from drymount.design.table import TableError

#: The optimiser against the study's optimum n0 (issue 16: within 1 %). Measured
#: 1e-5 relative (27.2109 N against 27.2107 N).
RTOL_N0_OPTIMUM = 0.01
#: H = 1 against co-simulation for the best designs of the test space: the single
#: harmonic misses the higher harmonics of stick-slip (the validation with H = 1 shows
#: a few % on lightly damped friction systems). Measured 0.24 % of peak.
RTOL_H1_COSIM = 0.02
#: The trapezoid RMS of a straight line on the RMS grid against the exact integral:
#: the error of the trapezoid rule on f^2 with 400 intervals is ~1e-6 relative.
RTOL_RMS_LINE = 1e-5

DESIGN_SDOF = """
[design]
method = "lhs"
samples = {samples}
seed = 3
harmonics = 1
band_hz = [1.0, 60.0]
chunk = 4

[[design.variables]]
path = "mount.friction.n0"
name = "n0"
bounds = [0.5, 120.0]

[[design.variables]]
path = "mount.c"
name = "c"
values = [100.0, 150.0, 300.0]

[[design.objectives]]
name = "peak_T"
quantity = "transmissibility"

[[design.objectives]]
name = "rms_T"
quantity = "transmissibility"
measure = "rms"
band_hz = [20.0, 60.0]

[[design.constraints]]
name = "x_max"
quantity = "displacement"
dof = "x"
max = 0.002
"""


def sdof_config(samples: int = 64, design: str | None = None):
    text = preset_text("sdof_halved") + (design or DESIGN_SDOF.format(samples=samples))
    return load_config(text, name="sdof_design")


# ---------------------------------------------------------------------------------
# checking [design]
# ---------------------------------------------------------------------------------


def test_design_space_reads_the_section():
    space = design_space(sdof_config())
    assert space.names == {"variables": ["n0", "c"], "objectives": ["peak_T", "rms_T"],
                           "constraints": ["x_max"]}
    assert space.size() == 64 and space.objectives[1].band_hz == (20.0, 60.0)
    assert space.objectives[0].band_hz == (1.0, 60.0)  # the design band by default


BAD = [
    ('bounds = [0.5, 120.0]', 'bounds = [120.0, 0.5]',
     ["`design.variables[0].bounds`", "lower < upper"]),
    ('bounds = [0.5, 120.0]', 'bounds = [-5.0, 120.0]',
     ["`design.variables[0].bounds`: at -5 the configuration is invalid",
      "mount.friction.n0"]),
    ('bounds = [0.5, 120.0]', 'bounds = [0.5, 120.0]\nvalues = [1.0]',
     ["exactly one of `bounds", "got both"]),
    ('path = "mount.c"', 'path = "mounts[0].c"',
     ["`design.variables[1].path`", "mounts"]),
    ('path = "mount.c"', 'pth = "mount.c"',
     ["unknown key `design.variables[1].pth`", "did you mean `path`"]),
    ('quantity = "transmissibility"\n\n[[design.objectives]]',
     'quantity = "transmisibility"\n\n[[design.objectives]]',
     ["`design.objectives[0].quantity`", '"transmissibility"']),
    ('dof = "x"', 'dof = "z"', ["`design.constraints[0].dof` must be one of x"]),
    ('band_hz = [20.0, 60.0]', 'band_hz = [20.0, 90.0]',
     ["`design.objectives[1].band_hz`", "inside the design's HBM band"]),
    ('method = "lhs"', 'method = "sobol"', ["`design.samples`", "a power of 2"]),
    ('name = "rms_T"', 'name = "peak_T"', ["must be unique", "'peak_T' 2 times"]),
    ('max = 0.002', 'max = "small"', ["`design.constraints[0].max`"]),
]


@pytest.mark.parametrize("old, new, needles", BAD)
def test_bad_design_sections_name_the_field(old, new, needles):
    text = DESIGN_SDOF.format(samples=48)
    assert old in text
    with pytest.raises(ConfigError) as info:
        design_space(sdof_config(design=text.replace(old, new, 1)))
    msg = str(info.value)
    for needle in needles:
        assert needle in msg, msg


def test_force_objective_needs_a_force_transmissibility():
    text = preset_text("six_dof_halved") + """
[design]
[[design.variables]]
path = "mounts[0].position[0]"
bounds = [-0.6, -0.4]
[[design.objectives]]
quantity = "force"
"""
    with pytest.raises(ConfigError, match="needs a system whose transmissibility"):
        design_space(load_config(text))


@pytest.mark.parametrize("name, n_variables", [("sdof_n0.toml", 2),
                                               ("six_dof_layout.toml", 12)])
def test_the_shipped_examples_check(name, n_variables):
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "design" / name
    space = design_space(load_config(path))
    assert len(space.variables) == n_variables


@pytest.mark.slow
def test_six_dof_layout_optimisation_runs_from_the_cli(tmp_path, capsys):
    """A small 6-DOF layout run (48 designs, ~1 min): the CLI path of results.md."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "design" / \
        "six_dof_layout.toml"
    code = cli.main(["optimize", str(path), "--popsize", "2", "--maxiter", "1",
                     "--polish", "0", "--seed", "1", "-q", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code in (0, 1) and "best peak_T" in out
    summary = (tmp_path / "summary.md").read_text()
    for dof in ("x", "y", "z", "alpha", "beta", "gamma"):
        assert f"| {dof} |" in summary
    assert "margin `alpha_max`" in summary


def test_a_config_without_design_says_so():
    with pytest.raises(ConfigError, match="`design` must be a table"):
        design_space(load_config(preset_text("sdof_halved")))


# ---------------------------------------------------------------------------------
# sampling, measures, Pareto
# ---------------------------------------------------------------------------------


def test_lhs_sample_is_a_latin_hypercube_and_reproducible():
    space = design_space(sdof_config(samples=48))
    X = sample(space)
    assert X.shape == (48, 2)
    np.testing.assert_array_equal(X, sample(space))
    # one point per stratum of n0 (continuous), each list value 16 times
    strata = np.floor((X[:, 0] - 0.5) / (119.5 / 48)).astype(int)
    assert sorted(strata) == list(range(48))
    assert sorted(np.unique(X[:, 1], return_counts=True)[1]) == [16, 16, 16]


def test_grid_sample_is_every_combination():
    text = DESIGN_SDOF.format(samples=1).replace('method = "lhs"', 'method = "grid"')
    text = text.replace('bounds = [0.5, 120.0]', 'bounds = [1.0, 3.0]\npoints = 3')
    space = design_space(sdof_config(design=text))
    X = sample(space)
    assert space.size() == 9
    assert {tuple(x) for x in X} == {(a, b) for a in (1.0, 2.0, 3.0)
                                     for b in (100.0, 150.0, 300.0)}


def test_band_rms_of_a_line_is_the_exact_integral():
    f = np.linspace(0.0, 100.0, 7)
    a, band = 0.3, (10.0, 50.0)
    exact = math.sqrt(a**2 * (band[1]**3 - band[0]**3) / 3 / (band[1] - band[0]))
    assert band_rms(f, a * f, band) == pytest.approx(exact, rel=RTOL_RMS_LINE)


def test_band_rms_takes_the_upper_envelope_of_a_fold():
    # a curve going up to 40 Hz at value 1, back to 20 Hz at value 3, on to 60 at 3:
    # between 20 and 40 Hz the upper solution (3) counts, so the RMS is 3 on 20-60
    f = np.array([10.0, 40.0, 20.0, 60.0])
    v = np.array([1.0, 1.0, 3.0, 3.0])
    assert band_rms(f, v, (20.0, 60.0)) == pytest.approx(3.0, rel=1e-12)
    assert math.isnan(band_rms(f, v, (5.0, 60.0)))  # not covered below 10 Hz


def test_pareto_mask_matches_brute_force():
    rng = np.random.default_rng(0)
    F = rng.random((60, 2))
    feasible = rng.random(60) > 0.2
    mask = pareto_mask(F, feasible)
    for i in range(60):
        dominated = any(feasible[k] and np.all(F[k] <= F[i]) and np.any(F[k] < F[i])
                        for k in range(60))
        assert mask[i] == (feasible[i] and not dominated)


# ---------------------------------------------------------------------------------
# exploration: backends, streaming, resume
# ---------------------------------------------------------------------------------


# 64 designs (the exploration size) cost ~100 s of CI's 20 min: the default
# suite runs 16 (every design still a real HBM curve, both sides of the constraint),
# the slow marker the full 64
@pytest.mark.parametrize("samples", [
    16, pytest.param(64, marks=pytest.mark.slow)])
def test_designs_serial_and_localcluster_give_identical_tables(tmp_path, samples):
    pytest.importorskip("distributed")
    cfg = sdof_config(samples=samples)
    space = design_space(cfg)
    a = explore(cfg, space, tmp_path / "serial", parse_backend(1), progress=False)
    b = explore(cfg, space, tmp_path / "dask", parse_backend(1, "local:2"),
                progress=False)
    text = [(tmp_path / d / "designs.csv").read_text() for d in ("serial", "dask")]
    assert text[0] == text[1]
    assert len(a.results) == len(b.results) == samples
    assert all(r.status.value == "ok" for r in a.results)
    # both sides of the constraint occur, so the test sees feasibility decided
    assert 0 < sum(r.feasible for r in a.results) < samples
    for f in ("pareto.png", "summary.md"):
        assert (tmp_path / "dask" / f).stat().st_size > 0


def test_local_processes_give_the_same_table(tmp_path):
    cfg = sdof_config(samples=8)
    space = design_space(cfg)
    explore(cfg, space, tmp_path / "s", parse_backend(1), progress=False)
    explore(cfg, space, tmp_path / "p", parse_backend(2), progress=False)
    assert ((tmp_path / "s" / "designs.csv").read_text()
            == (tmp_path / "p" / "designs.csv").read_text())


def test_an_interrupted_table_resumes_to_the_same_result(tmp_path):
    cfg = sdof_config(samples=12)
    space = design_space(cfg)
    full = explore(cfg, space, tmp_path / "full", progress=False)
    path = tmp_path / "cut" / "designs.csv"
    path.parent.mkdir()
    lines = (tmp_path / "full" / "designs.csv").read_text().splitlines(keepends=True)
    # 5 rows out of order (as they arrive from workers), then half a row
    path.write_text("".join([lines[0], lines[1], *lines[7:12], lines[12][:20]]))
    res = explore(cfg, space, tmp_path / "cut", progress=False)
    assert res.resumed == 5 and len(res.results) == 12
    assert path.read_text() == (tmp_path / "full" / "designs.csv").read_text()
    assert [r.objectives for r in res.results] == [r.objectives for r in full.results]


def test_a_table_of_another_exploration_is_not_overwritten(tmp_path):
    cfg = sdof_config(samples=4)
    explore(cfg, design_space(cfg), tmp_path, progress=False)
    before = (tmp_path / "designs.csv").read_text()
    other = sdof_config(samples=6)
    with pytest.raises(TableError, match="not a table of this exploration"):
        explore(other, design_space(other), tmp_path, progress=False)
    assert (tmp_path / "designs.csv").read_text() == before


def test_invalid_designs_are_rows_with_the_reason(tmp_path):
    # n0 in bounds, but c from a list with a value the configuration rejects
    text = DESIGN_SDOF.format(samples=6)
    cfg = sdof_config(design=text)
    space = design_space(cfg)
    from dataclasses import replace

    bad = replace(space.variables[1], values=(150.0, float("inf")))
    space = replace(space, variables=(space.variables[0], bad))
    res = explore(cfg, space, tmp_path, progress=False)
    invalid = [r for r in res.results if r.status.value == "invalid"]
    assert invalid and all("mount.c" in r.message for r in invalid)
    assert all(math.isnan(r.objectives[0]) and not r.feasible for r in invalid)


# ---------------------------------------------------------------------------------
# backends
# ---------------------------------------------------------------------------------


def test_parse_backend():
    assert parse_backend(1).kind is BackendKind.SERIAL
    assert parse_backend(3).workers == 3
    assert parse_backend(1, "local:2").workers == 2
    assert parse_backend(1, "tcp://10.0.0.5:8786").address == "tcp://10.0.0.5:8786"
    for bad in ("local:x", "10.0.0.5"):
        with pytest.raises(BackendError, match="--dask"):
            parse_backend(1, bad)
    with pytest.raises(BackendError, match="not both"):
        parse_backend(2, "local:2")
    # bounded (issue 25: local:100000 was accepted)
    assert parse_backend(1, f"local:{MAX_WORKERS}").workers == MAX_WORKERS
    for bad in ("local:0", f"local:{MAX_WORKERS + 1}", "local:100000"):
        with pytest.raises(BackendError, match=rf"in 1\.\.{MAX_WORKERS}, got"):
            parse_backend(1, bad)
    with pytest.raises(BackendError, match=r"--workers must be an integer in 1\.\."):
        parse_backend(MAX_WORKERS + 1)


def test_a_refused_scheduler_address_fails_at_once():
    """A port nothing listens on is refused at the first connection attempt, not
    after distributed.Client's 30 s of retries (issue 25: tcp://127.0.0.1:9)."""
    import socket

    with socket.socket() as s:  # a port that is free now, so refused
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(BackendError, match="cannot reach the Dask scheduler"):
        _check_reachable(f"tcp://127.0.0.1:{port}")
    with pytest.raises(BackendError, match="must read tcp://HOST:PORT"):
        _check_reachable("tcp://127.0.0.1")


def test_dask_missing_says_how_to_install(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "distributed", None)
    design = tmp_path / "d.toml"
    design.write_text(preset_text("sdof_halved") + DESIGN_SDOF.format(samples=4))
    code = cli.main(["explore", str(design), "--dask", "local:2", "-q", "--out",
                     str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and "pip install 'drymount[dask]'" in err


# ---------------------------------------------------------------------------------
# optimisation
# ---------------------------------------------------------------------------------


def _study_optimum() -> tuple[float, float]:
    """The optimize-n0 study's minimiser (halved mount, peak objective, H = 1) with
    its bounded search tightened to 0.01 N."""
    from drymount.studies import load_system, optimize_n0, with_friction_of

    halved = load_system("sdof_halved")
    obj = optimize_n0._Objective(with_friction_of(halved, halved), "peak", 1, [])
    grid = np.linspace(*optimize_n0.OPT_N0_BOUNDS, optimize_n0.OPT_GRID_POINTS)
    best = optimize_n0._minimise(obj, grid, 0.01)
    return best.n0, best.value


def test_optimizer_recovers_the_study_n0_optimum(tmp_path):
    from drymount.studies import OPT_PEAK_BAND_HZ

    text = f"""
[design]
harmonics = 1
band_hz = [{OPT_PEAK_BAND_HZ[0]}, {OPT_PEAK_BAND_HZ[1]}]
seed = 2
[[design.variables]]
path = "mount.friction.n0"
bounds = [0.5, 120.0]
[[design.objectives]]
name = "peak_T"
quantity = "transmissibility"
"""
    cfg = sdof_config(design=text)
    settings = OptimizeSettings(popsize=6, maxiter=12, polish_maxfev=40)
    res = optimize(cfg, design_space(cfg), tmp_path, settings=settings,
                   progress=False)
    n0_ref, value_ref = _study_optimum()
    assert res.best.values[0] == pytest.approx(n0_ref, rel=RTOL_N0_OPTIMUM)
    assert res.value <= value_ref * (1 + 1e-6)
    history = (tmp_path / "history.csv").read_text().splitlines()
    assert len(history) == 2 + res.n_evaluations
    assert {ln.split(",")[0] for ln in history[2:]} == {"de", "polish"}
    assert "Reproduce" in (tmp_path / "summary.md").read_text()
    # the same seed on 2 local processes: the same history, row for row
    optimize(cfg, design_space(cfg), tmp_path / "w2", parse_backend(2),
             settings=settings, progress=False)
    assert (tmp_path / "w2" / "history.csv").read_text() == "\n".join(history) + "\n"


def test_optimize_progress_bar_ends_at_the_evaluations_done(tmp_path, capsys):
    """The bar's total is an estimate (DE may stop on its tolerance, the polish
    re-visits the DE's best, which is not evaluated again): a finished run's bar
    ends at n/n, n the evaluations of the history, not short of its estimate."""
    cfg = sdof_config(samples=4)
    settings = OptimizeSettings(popsize=2, maxiter=1, polish_maxfev=6)
    res = optimize(cfg, design_space(cfg), tmp_path, settings=settings,
                   progress=True)
    n = res.n_evaluations
    estimate = (settings.maxiter + 1) * settings.popsize * len(
        design_space(cfg).variables) + settings.polish_maxfev
    last = capsys.readouterr().err.replace("\r", "\n").strip().splitlines()[-1]
    assert f" {n}/{n} " in last, (last, n, estimate)
    assert "100%" in last


def test_cli_optimize_with_constraint_and_unknown_objective(tmp_path, capsys):
    design = tmp_path / "d.toml"
    design.write_text(preset_text("sdof_halved") + DESIGN_SDOF.format(samples=4))
    assert cli.main(["optimize", str(design), "--objective", "nope", "-q"]) == 2
    assert "--objective must be one of peak_T, rms_T" in capsys.readouterr().err
    code = cli.main(["optimize", str(design), "--maxiter", "2", "--popsize", "3",
                     "--polish", "0", "-q", "--out", str(tmp_path / "o")])
    out = capsys.readouterr().out
    assert code == 0 and "feasible True" in out
    summary = (tmp_path / "o" / "summary.md").read_text()
    assert "margin `x_max`" in summary


def test_every_command_checks_the_design_section(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(preset_text("sdof_halved") + DESIGN_SDOF.format(samples=4).replace(
        'dof = "x"', 'dof = "q"'))
    assert cli.main(["hbm", str(bad), "-H", "1", "-q"]) == 2
    assert "`design.constraints[0].dof` must be one of x" in capsys.readouterr().err


def test_cosim_check_of_the_best_designs(tmp_path):
    """The best H = 1 designs co-simulated (in-process law, stepped sweep): the HBM
    amplitude of the same branch agrees with the time-domain steady state within
    RTOL_H1_COSIM of the peak."""
    cfg = sdof_config(samples=8)
    res = explore(cfg, design_space(cfg), tmp_path, progress=False, check_best=1)
    import csv

    with open(tmp_path / "cosim_check.csv") as fh:
        rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
    assert len(rows) == 1
    for row in rows:
        assert row["converged"] == "1"
        assert 0 < float(row["max_error"]) < RTOL_H1_COSIM, row
    assert "Co-simulated check of the 1 best designs" in (
        tmp_path / "summary.md").read_text()
    best = sorted((r for r in res.results if r.feasible), key=lambda r: r.objectives[0])
    assert [int(r["index"]) for r in rows] == [r.index for r in best[:1]]


def test_stiffness_scale_variable_multiplies_the_file_values():
    """mode = "scale" over k1 and k2: 0.5 turns the original mount into the halved
    one of the thesis (Sec. 4.2; preset sdof_halved has k1, k2 = 91870/2, 513800/2)."""
    from drymount.config import config_from_dict, load_preset
    from drymount.design.space import apply_values, current_values

    text = preset_text("sdof_original") + """
[design]
[[design.variables]]
path = ["mount.k1", "mount.k2"]
mode = "scale"
bounds = [0.4, 1.2]
[[design.objectives]]
quantity = "transmissibility"
"""
    cfg = load_config(text)
    space = design_space(cfg)
    var = space.variables[0]
    assert var.scale and var.name == "mount.k1+mount.k2*scale"
    assert current_values(cfg.data, space.variables) == (1.0,)
    halved = config_from_dict(apply_values(cfg.data, space.variables, [0.5]))
    ref = load_preset("sdof_halved").system.elements[0].params.axial
    got = halved.system.elements[0].params.axial
    assert (got.k1, got.k2, got.delta) == (ref.k1, ref.k2, ref.delta)
    bad = text.replace('path = ["mount.k1", "mount.k2"]', 'path = ["mount.kc"]')
    with pytest.raises(ConfigError, match="`mount.kc` is not in the file"):
        design_space(load_config(bad))
    with pytest.raises(ConfigError, match="`design.variables\\[0\\].mode` must be"):
        design_space(load_config(text.replace('"scale"', '"times"')))


def test_explore_is_the_function_whatever_was_imported_first():
    """``drymount.design.explore`` is the function even after its module was imported
    (its module was once ``drymount.design.explore``: importing it, as ``drymount
    optimize`` does, bound the package's ``explore`` to the module, and ``from
    drymount.design import explore`` then gave a module: "'module' object is not
    callable")."""
    import subprocess
    code = ("import importlib, pkgutil, types\n"
            "import drymount.design as d\n"
            "for m in pkgutil.iter_modules(d.__path__):\n"
            "    importlib.import_module('drymount.design.' + m.name)\n"
            "for name in d.__all__:\n"
            "    assert not isinstance(getattr(d, name), types.ModuleType), name\n"
            "from drymount.design import explore\n"
            "assert explore.__name__ == 'explore'\n")
    subprocess.run([sys.executable, "-c", code], check=True)
