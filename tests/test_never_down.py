"""Issue 25, the rest: extreme inputs refused with exit 2 naming the file, option
or field and what is allowed (deep TOML, huge loads, huge design grids, special
output files), full disks named, large fits decimated."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from drymount import cli
from drymount.design.backends import BackendKind, BackendSpec
from drymount.design.exploration import expected_duration
from drymount.design.space import MAX_DESIGNS
from drymount.fit import bin_means
from drymount.config import ConfigError, load_config
from drymount.config.loading import nesting_depth
from drymount.config.loading import MAX_NESTING

ROOT = Path(__file__).resolve().parents[1]


def run(argv, capsys):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------------------ deep TOML

DEEP = 5000


@pytest.mark.parametrize("shape", ["array", "inline_table", "dotted_key", "header"])
def test_a_toml_nested_5000_deep_is_exit_2_naming_the_file(tmp_path, capsys, shape):
    text = {"array": "x = " + "[" * DEEP + "]" * DEEP,
            "inline_table": "x = " + "{a = " * DEEP + "1" + "}" * DEEP,
            "dotted_key": ".".join(["a"] * DEEP) + " = 1",
            "header": "[" + ".".join(["a"] * DEEP) + "]\nb = 1"}[shape]
    path = tmp_path / "deep.toml"
    path.write_text('model = "sdof"\n' + text + "\n")
    code, _, err = run(["static", path], capsys)
    assert code == 2, err
    assert str(path) in err and f"at most {MAX_NESTING} levels" in err, err
    assert "RecursionError" not in err


def test_nesting_depth_counts_tables_and_arrays():
    assert nesting_depth(1.0) == 0
    assert nesting_depth({"a": 1}) == 1
    assert nesting_depth({"a": {"b": [1, [2]]}}) == 4
    assert nesting_depth({"a": [], "b": {}}) == 2


def test_the_nesting_limit_is_not_reached_by_a_real_configuration(tmp_path):
    """MAX_NESTING levels load (the error is about the fields, not the nesting);
    one more is refused for its nesting."""
    def doc(levels):  # the document itself is one level
        return 'model = "sdof"\n' + "x = " + "[" * (levels - 1) + "]" * (levels - 1)
    with pytest.raises(ConfigError) as ok:
        load_config(doc(MAX_NESTING))
    assert "nested" not in str(ok.value)
    with pytest.raises(ConfigError, match=f"nested {MAX_NESTING + 1} levels deep"):
        load_config(doc(MAX_NESTING + 1))


def test_a_set_value_nested_5000_deep_is_exit_2(capsys):
    code, _, err = run(["static", "sdof_halved", "--set",
                        "mount.c=" + "[" * DEEP + "]" * DEEP], capsys)
    assert code == 2, err
    assert "mount.c" in err and f"at most {MAX_NESTING} levels" in err, err[-500:]


# ------------------------------------------------------------- static extremes


@pytest.mark.parametrize(("args", "word"), [
    (["--load", "x=1e308"], "--load"), (["--load", "x=-1.5e9"], "--load"),
    (["--load", "x=inf"], "--load"), (["--g", "1e308"], "--g")])
def test_static_bounds_the_load_and_g(tmp_path, capsys, args, word):
    out = tmp_path / "s.csv"
    code, _, err = run(["static", "sdof_halved", *args, "--out", out], capsys)
    assert code == 2, err
    assert word in err and ("1e+09" in err or "1000" in err), err
    assert not out.exists()


def test_static_at_the_load_limit_is_the_linear_sag(tmp_path, capsys):
    """1e9 N on sdof_halved: past the knee, on the k2 branch. Reference written
    here: u = delta + (F - k1 delta) / k2 with F = 1e9 - m g (gravity down)."""
    out = tmp_path / "s.csv"
    code, stdout, err = run(["static", "sdof_halved", "--load", "x=1e9", "--out", out],
                            capsys)
    assert code == 0, err
    from drymount.config import load_preset

    cfg = load_preset("sdof_halved")
    e = cfg.system.elements[0]
    p = e.params.axes[e.active_axes[0]]
    weight = cfg.system.M[0, 0] * cfg.static.g
    u_ref = p.delta + (1e9 - weight - p.k1 * p.delta) / p.k2
    rows = [ln.split(",") for ln in out.read_text().splitlines()
            if not ln.startswith("#")]
    u = float(rows[1][2])
    assert abs(u - u_ref) <= 1e-9 * abs(u_ref), (u, u_ref)


def test_a_static_load_that_overflows_the_laws_is_refused(capsys):
    """[static] loads are not bounded by themselves: an equilibrium that is not
    finite is refused (it converged with an infinite force before), no numpy
    warning printed."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # an overflow warning fails
        code, _, err = run(["static", "sdof_halved", "--set", "static.loads.x=1e308"],
                           capsys)
    assert code == 2, err
    assert "not finite" in err, err


def test_static_to_dev_null_is_exit_2_like_the_other_commands(capsys):
    code, _, err = run(["static", "six_dof_halved", "--out", "/dev/null"], capsys)
    assert code == 2, err
    assert "/dev/null" in err and "device" in err, err


# ------------------------------------------------------------ design sizes

DESIGN = ROOT / "examples" / "design" / "sdof_n0.toml"


@pytest.mark.parametrize(("sets", "word"), [
    (["design.samples=1000000000000"], "`design.samples` must be an integer in "
                                       "1..100000"),
    (["design.method=grid", "design.variables[*].points=1000"],
     "the grid has 1,000,000 designs (1000 (n0) x 1000 (c)); at most 100,000"),
    (["design.method=grid", "design.variables[0].points=200000"], "2..100000"),
])
def test_a_design_space_beyond_the_limit_is_exit_2_naming_the_field(capsys, sets,
                                                                    word):
    argv = ["explore", DESIGN, "-q", "--out", "never-written"]
    for s in sets:
        argv += ["--set", s]
    code, _, err = run(argv, capsys)
    assert code == 2, err
    assert word in err, err
    assert MAX_DESIGNS == 100_000


def test_the_grid_limit_itself_is_accepted():
    from drymount.config import load_config
    from drymount.design import design_space
    from drymount.paths import override_config

    cfg = override_config(load_config(DESIGN), ["design.method=grid",
                                                 "design.variables[0].points=1000",
                                                 "design.variables[1].points=100"])
    assert design_space(cfg).size() == MAX_DESIGNS


def test_expected_duration_from_the_first_chunk():
    """4 designs in 10 s on one of 2 workers: 2.5 s each, the 96 others on 2 workers
    take 96 * 2.5 / 2 = 120 s more: 130 s = 2.2 min in all."""
    line = expected_duration(10.0, 4, 100, BackendSpec(BackendKind.PROCESSES, 2))
    assert "about 2.2 min for 100 designs" in line and "2.5 s per design" in line, line
    line = expected_duration(10.0, 4, 100, BackendSpec(BackendKind.SERIAL))
    assert "about 4.2 min" in line, line  # 10 + 96 * 2.5 = 250 s
    line = expected_duration(3.0, 8, 1_000_000, BackendSpec(BackendKind.DASK,
                                                            address="tcp://h:1"))
    assert "about 4.3 days" in line and "one worker's pace" in line, line


def test_explore_announces_its_duration(tmp_path, capsys):
    code, _, err = run(["explore", DESIGN, "-q", "--set", "design.samples=4",
                        "--set", "design.chunk=2", "--out", tmp_path / "ex"], capsys)
    assert code == 0, err
    assert "explore: expected duration at most about" in err, err
    assert "for 4 designs" in err and "measured on the first 2" in err, err


@pytest.mark.parametrize("command", ["explore", "optimize"])
def test_a_bad_design_config_fails_before_scipy_loads(tmp_path, command):
    """The error comes before the heavy imports (explore's scipy.stats, optimize's
    scipy.optimize), guarded by what the process imported (-X importtime)."""
    p = subprocess.run([sys.executable, "-X", "importtime", "-m", "drymount.cli",
                        command, str(DESIGN), "--set", "mount.k1=-5", "-q", "--out",
                        str(tmp_path / "x")], cwd=tmp_path, capture_output=True,
                       text=True, timeout=120,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)))
    lines = p.stderr.splitlines()
    modules = {ln.split("|")[-1].strip() for ln in lines
               if ln.startswith("import time:")}
    assert p.returncode == 2, p.stderr[-2000:]
    assert any("mount.k1" in ln for ln in lines)
    heavy = sorted(m for m in modules if m.split(".")[0] in ("scipy", "matplotlib"))
    assert not heavy, heavy[:5]
    assert not (tmp_path / "x").exists()


# ------------------------------------------------------------ large fits


def _piecewise_curve(path: Path, n: int, seed: int = 5) -> tuple[float, float, float]:
    k1, k2, delta = 45935.0, 256900.0, 0.01225
    rng = np.random.default_rng(seed)
    u = np.linspace(-0.02, 0.02, n)
    F = np.where(np.abs(u) <= delta, k1 * u,
                 np.sign(u) * (k1 * delta + k2 * (np.abs(u) - delta)))
    F = F + rng.normal(0.0, 5.0, n)
    with open(path, "w") as f:
        f.write("# synthetic piecewise curve\ndeflection [m],force [N]\n")
        np.savetxt(f, np.c_[u, F], delimiter=",", fmt="%.10g")
    return k1, k2, delta


def test_fit_bins_a_curve_of_200000_rows(tmp_path, capsys):
    """2e5 rows -> 5000 means of 40 points; the piecewise law is chosen and its
    parameters are the generating ones within 4 standard errors (noise 5 N)."""
    data = tmp_path / "big.csv"
    k1, k2, delta = _piecewise_curve(data, 200_000)
    code, out, err = run(["fit", "elastic", data, "--out", tmp_path / "fit",
                          "--no-plot"], capsys)
    assert code == 0, err
    assert "200000 points binned to 5000 means of 40 consecutive points" in out, out
    assert "fit elastic" in err  # the progress bar
    chosen = [ln for ln in (tmp_path / "fit" / "fit.csv").read_text().splitlines()
              if ",yes," in ln]
    got = {r.split(",")[2]: (float(r.split(",")[3]), float(r.split(",")[4]))
           for r in chosen}
    assert set(got) >= {"k1", "k2", "delta"}, got
    for name, ref in (("k1", k1), ("k2", k2), ("delta", delta)):
        value, se = got[name]
        assert 0 < se < 1e-3 * ref and abs(value - ref) <= 4 * se, (name, value, se)


def test_bin_means_keep_equal_runs():
    u = np.arange(10.0)
    ub, Fb = bin_means(u, 2 * u, 3)  # runs of 3, 3, 4
    np.testing.assert_allclose(ub, [1.0, 4.0, 7.5], rtol=0, atol=1e-15)
    np.testing.assert_allclose(Fb, 2 * ub, rtol=0, atol=1e-15)


def test_the_fast_reader_equals_the_line_reader(tmp_path, monkeypatch):
    from drymount import rigdata

    data = tmp_path / "c.csv"
    _piecewise_curve(data, 1000)
    fast = rigdata.read_table(data, ("deflection", "force"))
    monkeypatch.setattr(rigdata, "_numeric_table", lambda *a: None)
    slow = rigdata.read_table(data, ("deflection", "force"))
    assert fast.lines == slow.lines and fast.lines[0] == 3
    for q in ("deflection", "force"):
        assert np.array_equal(fast.columns[q], slow.columns[q])


# ------------------------------------------------------------ full disk


def _limited(limit_bytes: int):
    """A child process whose files may not grow beyond ``limit_bytes`` (a write past
    it fails with EFBIG, as a full disk fails with ENOSPC)."""
    import resource
    import signal

    def set_limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # an OSError, not a signal
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return set_limit


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE semantics")
@pytest.mark.parametrize("command", ["static", "fit", "explore"])
def test_a_write_that_fails_names_the_file_and_the_reason(tmp_path, command):
    argv = {"static": ["static", "sdof_halved", "--out", "s.csv"],
            "fit": ["fit", "elastic", str(ROOT / "examples/data/rig_piecewise.csv"),
                    "--out", "fit", "--no-plot"],
            "explore": ["explore", str(DESIGN), "-q", "--set", "design.samples=2",
                        "--out", "ex"]}[command]
    (tmp_path / "s.csv").write_text("# drymount an earlier result\n")
    p = subprocess.run([sys.executable, "-m", "drymount.cli", *argv], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)),
                       preexec_fn=_limited(100))
    assert p.returncode == 1, p.stderr
    last = p.stderr.strip().splitlines()[-1]
    assert last.startswith("drymount: error: cannot write "), p.stderr
    assert "File too large" in last and "Traceback" not in p.stderr, p.stderr
    named = {"static": "s.csv", "fit": "fit.csv", "explore": "designs.csv"}[command]
    assert named in last, last
    if command == "static":  # the file it would have replaced is untouched
        assert (tmp_path / "s.csv").read_text() == "# drymount an earlier result\n"
    assert not [f for f in tmp_path.rglob(".*") if f.is_file()], "a temporary left"


def test_enospc_while_writing_a_csv_names_it(tmp_path, monkeypatch, capsys):
    """A full disk (ENOSPC) in the middle of the CSV writer: exit 1 naming the file."""
    import errno

    from drymount.hbm import io as hbm_io

    real = hbm_io.format_value

    def full(v):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(hbm_io, "format_value", full)
    out = tmp_path / "s.csv"
    code, _, err = run(["static", "sdof_halved", "--out", out], capsys)
    monkeypatch.setattr(hbm_io, "format_value", real)
    assert code == 1, err
    assert f"cannot write {out}: No space left on device" in err, err
    assert not out.exists()
