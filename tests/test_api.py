"""The public API (``import drymount``): its names, the README's script, the CLI's
defaults and meanings, and field overrides. Runtime about 10 s."""

import ast
import importlib.util
import inspect
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import drymount
from drymount import CosimResult, Curve, Model, Peak, cosim, hbm, load, sweep

REPO = Path(__file__).resolve().parents[1]
PUBLIC = {"Model", "Peak", "Curve", "CosimResult", "load", "hbm", "sweep", "cosim",
          "modes"}
#: The API and the CLI run the same computation: the printed peak (4 significant
#: digits) must match the API's value to its rounding.
PRINT_RTOL = 5e-4


def test_exports_exactly_the_public_names():
    assert set(drymount.__all__) == PUBLIC
    assert set(dir(drymount)) == PUBLIC
    with pytest.raises(AttributeError, match="no attribute 'config_from_dict'"):
        drymount.config_from_dict  # noqa: B018


def _documented(obj, name):
    doc = inspect.getdoc(obj) or ""
    assert len(doc) > 20, f"{name} has no docstring"
    return doc


def test_every_public_name_and_member_is_documented_with_units():
    for name in PUBLIC:
        doc = _documented(getattr(drymount, name), name)
        if inspect.isfunction(getattr(drymount, name)) and name != "load":
            assert re.search(r"\b(Hz|s|m|N)\b", doc), f"{name}: no units in its doc"
    for cls in (Model, Curve, CosimResult):
        for mname, member in vars(cls).items():
            if not mname.startswith("_"):
                _documented(member.fget if isinstance(member, property) else member,
                            f"{cls.__name__}.{mname}")


def test_import_is_light():
    """``import drymount`` loads neither the API nor numpy (the CLI stays fast)."""
    code = ("import sys, drymount; print('drymount.api' in sys.modules, "
            "'numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                         text=True, check=True).stdout.split()
    assert out == ["False", "False"]


def test_readme_script_runs(tmp_path, monkeypatch):
    text = (REPO / "README.md").read_text(encoding="utf-8")
    code = re.search(r"## Python API.*?```python\n(.*?)```", text, re.S).group(1)
    assert len(code.strip().splitlines()) <= 10
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    rows = (tmp_path / "sdof_n0_hbm.csv").read_text().splitlines()
    assert rows[1].startswith("freq_hz") and len(rows) > 20
    spectra = (tmp_path / "sdof_spectra.csv").read_text().splitlines()
    assert "N^2/Hz" in spectra[0] and spectra[1].startswith("freq_hz,F_")


def test_hbm_defaults_and_peak_match_the_cli(tmp_path, capsys):
    """``drymount.hbm(name)`` with no options is ``drymount hbm name``: same band,
    harmonics and curve; ``Curve.peak()`` is the peak transmissibility it prints."""
    from drymount.cli import main

    out = tmp_path / "cli.csv"
    assert main(["hbm", "sdof_halved", "--quiet", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    t_cli, f_cli = map(float, re.search(r"peak transmissibility (\S+) at (\S+) Hz",
                                        printed).groups())
    curve = hbm("sdof_halved", progress=False)
    p = curve.peak()
    assert isinstance(curve, Curve) and isinstance(p, Peak)
    assert p.quantity == "transmissibility" and p.unit == ""
    assert p.value == pytest.approx(t_cli, rel=PRINT_RTOL)
    assert p.freq_hz == pytest.approx(f_cli, rel=PRINT_RTOL)
    api_csv = tmp_path / "api.csv"
    curve.to_csv(api_csv)
    strip = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")]
    assert [ln for ln in api_csv.read_text().splitlines()
            if not ln.startswith("#")] == strip
    # peak(dof): the largest per-point max |q(t)| of that DOF, in m
    px = curve.peak("x")
    peaks = np.asarray(curve.result.peak)[:, 0]
    assert px.value == np.nanmax(peaks) and px.unit == "m"
    with pytest.raises(ValueError, match="`dof` must be one of"):
        curve.peak("z")


def test_hbm_progress_bar_ends_full(capsys):
    """The bar counts Hz by the continuation's steps: a curve that reaches fmax ends
    at 100 % with a full bar (its steps' sum fell short by round-off: 13 of 13 Hz
    shown with a bar one ninth of a cell short)."""
    hbm(load("sdof_halved"), 2.0, 15.0, harmonics=5, n_samples=64)
    last = capsys.readouterr().err.replace("\r", "\n").strip().splitlines()[-1]
    assert re.search(r"100%\|[#\u2588]{10}\| 13\.00/13\.00 Hz", last), last


def test_sweep_and_cosim_default_to_the_configured_backend(monkeypatch):
    """Like the CLI, the backend comes from ``[cosim] backend`` (default ``fmu``),
    not from ``vehicle.sweep``'s own default."""
    import drymount.vehicle as vehicle

    seen = {}

    def fake_sweep(system, freqs, **kw):
        seen.update(kw)
        raise RuntimeError("stop")

    monkeypatch.setattr(vehicle, "sweep", fake_sweep)
    monkeypatch.setattr("drymount.api._fmu_kw", lambda backend, path: {})
    with pytest.raises(RuntimeError, match="stop"):
        sweep("sdof_halved", points=3, progress=False)
    assert seen["backend"] == "fmu"
    with pytest.raises(RuntimeError, match="stop"):
        sweep(load("sdof_halved", "cosim.backend=inproc"), points=3, progress=False)
    assert seen["backend"] == "inproc"


def test_sweep_inproc_runs_and_gives_a_curve():
    m = load("sdof_halved").replace("cosim.backend", "inproc")
    curve = sweep(m, 3.0, 6.0, points=3, progress=False)
    assert curve.kind == "sweep" and curve.success
    assert curve.result.backend == "inproc"
    assert curve.freq_hz.tolist() == [3.0, 4.5, 6.0]
    assert curve.peak().value == np.max(curve.transmissibility)


def test_cosim_matches_the_harness_and_the_cli_step():
    import drymount.vehicle as vehicle

    m = load("sdof_halved")
    run = cosim(m, 5.0, duration=0.5, backend="inproc", steps_per_period=200)
    ref = vehicle.simulate(m.system, 5.0, 0.5, backend="inproc", dt=1.0 / 1000.0)
    assert isinstance(run, CosimResult)
    assert np.array_equal(run.q, ref.q)
    assert run.peak("x").value == np.max(np.abs(ref.q[:, 0]))
    from drymount.config import config_from_dict

    data = {k: v for k, v in m.config.data.items() if k != "cosim"}
    with pytest.raises(ValueError, match="give `freq_hz`"):
        cosim(Model(config_from_dict(data)))


def test_replace_and_with_go_through_the_config_check():
    m = load("six_dof_halved")
    m2 = m.replace("mounts[2].axial.friction.n0", 180.0)
    assert isinstance(m2, Model) and m2.name == m.name
    assert m2.config.data["mounts"][2]["axial"]["friction"]["n0"] == 180.0
    assert m.config.data["mounts"][2]["axial"]["friction"]["n0"] != 180.0
    m3 = m.with_({"mounts[*].axial.friction.n0": 50.0}, "sweep.points=7")
    with_friction = [mt for mt in m3.config.data["mounts"] if "friction" in mt["axial"]]
    assert with_friction and all(mt["axial"]["friction"]["n0"] == 50.0
                                 for mt in with_friction)
    assert m3.config.sweep.points == 7
    from drymount.config import ConfigError

    with pytest.raises(ConfigError, match=r"mounts\[2\].axial.friction.n0.*>= 0"):
        m.replace("mounts[2].axial.friction.n0", -1.0)
    with pytest.raises(ConfigError, match=r"mounts\[9\]"):
        m.replace("mounts[9].axial.friction.n0", 1.0)


def test_api_reference_builds_offline_with_every_public_name(tmp_path):
    """``docs/build_api.py`` (pdoc, the ``docs`` extra) documents every public name."""
    pytest.importorskip("pdoc", reason="the `docs` extra installs pdoc")
    proc = subprocess.run([sys.executable, str(REPO / "docs" / "build_api.py"),
                           str(tmp_path / "api")], cwd=REPO, capture_output=True,
                          text=True, check=True)
    assert "wrote" in proc.stdout
    page = (tmp_path / "api" / "drymount.html").read_text(encoding="utf-8")
    for name in PUBLIC:
        assert f'id="{name}"' in page, name
    _same_as_committed(tmp_path / "api", REPO / "docs" / "api")


def _build_api():
    """docs/build_api.py as a module (it is a script, not in a package)."""
    spec = importlib.util.spec_from_file_location("build_api",
                                                  REPO / "docs" / "build_api.py")
    build_api = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build_api)
    return build_api


def _same_as_committed(built: Path, committed: Path) -> None:
    """The rebuilt reference equals the committed docs/api/, page by page (it was
    stale: 7 of 10 pages changed, issue 23 item 5). Pages that differ where the
    renderer's versions differ too (docs/api/renderer.json) skip: CI took markdown2
    2.5.6 the day it came out, which renders differently from 2.5.5."""
    build_api = _build_api()
    pages = sorted(p.relative_to(built).as_posix() for p in built.rglob("*.html"))
    old = sorted(p.relative_to(committed).as_posix() for p in committed.rglob("*.html"))
    assert pages == old, "pages added or removed: run python docs/build_api.py"
    stale = [p for p in pages
             if (built / p).read_bytes() != (committed / p).read_bytes()]
    record = json.loads((committed / "renderer.json").read_text(encoding="utf-8"))
    here = build_api.renderer_versions()
    assert json.loads((built / "renderer.json").read_text(encoding="utf-8")) == here
    moved = {k: (record.get(k), v) for k, v in here.items() if record.get(k) != v}
    if stale and moved:
        pytest.skip(f"docs/api/ differs in {stale}, rendered by other versions "
                    f"(committed, here): {moved}")
    assert not stale, f"docs/api/ is stale ({stale}): run python docs/build_api.py"


def test_no_inline_literal_of_the_reference_spans_a_line_break():
    """An inline literal across a line break renders as raw backticks with markdown2
    2.5.6 (CI failed on it); so none of the documented modules' docstrings has one,
    whatever markdown2 renders the reference."""
    build_api = _build_api()
    broken = []
    for name in build_api.MODULES:
        origin = Path(importlib.util.find_spec(name).origin)
        for node in ast.walk(ast.parse(origin.read_text(encoding="utf-8"))):
            if not isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef,
                                     ast.AsyncFunctionDef)):
                continue
            doc = ast.get_docstring(node, clean=False) or ""
            where = f"{origin.name}:{getattr(node, 'name', '<module>')}"
            broken += [f"{where}: {m.group(0)!r}"
                       for m in re.finditer(r"``(.+?)``", doc, re.S)
                       if "\n" in m.group(1)]
    assert broken == []


@pytest.mark.parametrize("kw", [{"harmonics": 999}, {"harmonics": 0},
                                {"n_samples": 10**9}, {"harmonics": 2.5}])
def test_hbm_counts_are_bounded_like_the_cli(kw):
    """H and N outside the CLI's limits fail at once, naming the argument."""
    name = next(iter(kw))
    with pytest.raises(ValueError, match=rf"`{name}` must be an integer in"):
        drymount.hbm("sdof_halved", 1, 20, progress=False, **kw)
