"""``drymount validate``: co-simulation through the FMU against harmonic balance.

The quick mode runs real sweeps (fewer frequencies) and must pass; a deliberately wrong
mount parameter on the HBM side must make it fail with exit status 1 and a report that
says so. The full-size run is marked ``slow``.
"""

from __future__ import annotations

import argparse
import csv

import pytest

from drymount import validation
from drymount.cli import main as cli_main

# Injected error: n0 x 1.5 on the HBM side changes the slip force by 50 %; the
# single-DOF friction response then differs by several % of its peak, far above the
# 1 % tolerance (measured: the quick sweep passes at 0.05 %).
INJECTED = "n0=1.5"


def _read_points(path):
    with open(path, newline="") as fh:
        lines = [line for line in fh if not line.startswith("#")]
    return list(csv.DictReader(lines))


def test_quick_validation_passes_and_writes_report(tmp_path):
    results = validation.run_validation(quick=True, out=tmp_path, progress=False)
    assert [r.case.name for r in results] == [c.name for c in validation.CASES]
    for r in results:
        assert r.passed, (r.case.name, r.max_err, r.message)
        assert r.max_err <= validation.TOL_REL_PEAK
    md = (tmp_path / "validation.md").read_text()
    assert "FAIL" not in md
    rows = _read_points(tmp_path / "points.csv")
    systems = {row["system"] for row in rows}
    assert systems == {c.name for c in validation.CASES}
    # every compared point is within the tolerance, recomputed from the CSV
    for row in rows:
        if row["compared"] == "1":
            assert float(row["err_rel_peak"]) <= validation.TOL_REL_PEAK
    for c in validation.CASES:
        assert (tmp_path / f"{c.name}.png").stat().st_size > 10_000
    # the cubic case visits the upper branch on the way up (the jump band), so the
    # comparison covers both stable branches, not only the small-amplitude one
    cubic = next(r for r in results if r.case.name == "sdof_cubic")
    up = cubic.curves["up"]
    assert up["cosim"][:, 0].max() > 5 * up["cosim"][-1, 0]


def test_wrong_parameter_makes_validation_fail(tmp_path, capsys):
    code = cli_main(["validate", "--quick", "--systems", "sdof_friction",
                     "--inject", INJECTED, "--out", str(tmp_path)])
    assert code == 1
    out = capsys.readouterr().out
    assert "FAIL" in out
    md = (tmp_path / "validation.md").read_text()
    assert "FAIL" in md and INJECTED in md


@pytest.mark.parametrize("spec", ["n0", "bogus=2", "n0=-1", "n0=nan"])
def test_bad_inject_is_a_usage_error(tmp_path, spec, capsys):
    code = cli_main(["validate", "--quick", "--systems", "sdof_friction",
                     "--inject", spec, "--out", str(tmp_path)])
    assert code == 2
    assert "--inject" in capsys.readouterr().err


def test_unknown_system_is_a_usage_error(tmp_path, capsys):
    ns = argparse.Namespace(quick=True, out=tmp_path, systems=["nope"], inject=None)
    assert validation.main(ns) == 2
    assert "nope" in capsys.readouterr().err


@pytest.mark.slow
def test_full_validation_passes(tmp_path):
    results = validation.run_validation(quick=False, out=tmp_path, progress=False)
    for r in results:
        assert r.passed, (r.case.name, r.max_err, r.message)


def _hydraulic_T(freqs):
    """Reference written here: the engine's amplitude |f0 w^2| / |K* - w^2 m| on the
    mount of sdof_hydraulic.toml (read with tomllib), K* = k1 + j w c + Ap^2 (1 + j w
    C2 Z) / (C1 + C2 + j w C1 C2 Z), Z the inertia track parallel to the decoupler."""
    import math
    import tomllib
    from importlib import resources

    doc = tomllib.loads(resources.files("drymount.presets").joinpath(
        "sdof_hydraulic.toml").read_text())
    m, mt = doc["sdof"]["mass"], doc["mount"]
    h, f0 = mt["hydraulic"], doc["excitation"]["amplitude"]
    out = []
    for f in freqs:
        w = 2 * math.pi * f
        zi, zd = h["R_i"] + 1j * w * h["I_i"], h["R_d"] + 1j * w * h["I_d"]
        z = zi * zd / (zi + zd)
        k = (mt["k1"] + 1j * w * mt["c"] + h["Ap"] ** 2 * (1 + 1j * w * h["C2"] * z)
             / (h["C1"] + h["C2"] + 1j * w * h["C1"] * h["C2"] * z))
        out.append(f0 * w * w / abs(k - w * w * m))
    return out


def test_hydraulic_case_checks_the_exact_frf(tmp_path, capsys):
    """The hydraulic case compares three columns: HBM, co-simulation and the exact
    FRF; its amp_exact equals the FRF written here to 1e-10, HBM equals it to 1e-8
    of peak (the issue's target; measured 1.5e-16) and the co-simulation within the
    1 % tolerance (measured 1.3e-4 of peak in quick mode); a wrong HBM-side k1 fails
    against the exact column too."""
    case = next(c for c in validation.CASES if c.name == "sdof_hydraulic")
    assert case.exact
    (r,) = validation.run_validation(quick=True, out=tmp_path, cases=(case,),
                                     progress=False)
    assert r.passed and r.max_err_exact_hbm <= 1e-8
    assert r.max_err_exact_cosim <= validation.TOL_REL_PEAK
    rows = [p for p in _read_points(tmp_path / "points.csv")
            if p["direction"] == "up"]
    ref = _hydraulic_T([float(p["freq_hz"]) for p in rows])
    for p, a in zip(rows, ref, strict=True):
        assert abs(float(p["amp_exact"]) - a) <= 1e-10 * a
    assert "Exact FRF" in (tmp_path / "validation.md").read_text()
    code = cli_main(["validate", "--quick", "--systems", "sdof_hydraulic",
                     "--inject", "k1=1.02", "--out", str(tmp_path / "bad")])
    assert code == 1
    out = capsys.readouterr().out
    assert "exact FRF: HBM" in out and "FAIL" in out
