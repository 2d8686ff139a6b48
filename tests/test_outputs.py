"""Nothing lost, nothing overwritten (issue 11): output paths, file modes, the user's
FMU, usage errors before any computation, partial results, bounded options.

Runtime: ~15 s (one FMU build for the default-FMU case, a few short runs).
"""

from __future__ import annotations

import dataclasses
import os
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from drymount import cli, io
from drymount.config import (
    INERTIA_RANGE_KGM2,
    MASS_RANGE_KG,
    MAX_HARMONICS,
    MAX_N_SAMPLES,
    MAX_POINTS,
    ConfigError,
    load_config,
    preset_text,
)

ROOT = Path(__file__).resolve().parents[1]
#: A usage error must be reported before any computation, and the start-up must not
#: pay for the solvers (issue 27 item 1): guarded by what the CLI process imported
#: (``python -X importtime``), not by a timer (a CPU budget failed on a loaded
#: machine, issue 23 item 2). These packages (and their submodules) must not load.
HEAVY = ("scipy", "matplotlib", "numba")
ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
           PYTHONPATH=str(ROOT))


def run(argv, capsys):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# ======================================================================================
# drymount.io: modes, links, special files
# ======================================================================================


@pytest.mark.parametrize("mask", [0o022, 0o002, 0o077])
def test_new_file_mode_follows_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        io.write_csv(tmp_path / "a.csv", ["x"], [[1.0]], comment="x [m]")
        io.atomic_write_text(tmp_path / "b.txt", "b")
        with io.atomic_path(tmp_path / "c.png") as tmp:
            tmp.write_bytes(b"png")
    finally:
        os.umask(old)
    plain = tmp_path / "plain"
    old = os.umask(mask)
    try:
        open(plain, "w").close()  # what a plain open() gives
    finally:
        os.umask(old)
    want = stat.S_IMODE(os.stat(plain).st_mode)
    assert want == 0o666 & ~mask
    for name in ("a.csv", "b.txt", "c.png"):
        assert stat.S_IMODE(os.stat(tmp_path / name).st_mode) == want, name


def test_existing_file_keeps_its_mode(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("old\n")
    os.chmod(p, 0o640)
    io.atomic_write_text(p, "new\n")
    assert p.read_text() == "new\n"
    assert stat.S_IMODE(os.stat(p).st_mode) == 0o640


def test_symlink_is_followed(tmp_path):
    target = tmp_path / "data" / "real.csv"
    target.parent.mkdir()
    target.write_text("old\n")
    os.chmod(target, 0o664)
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    io.atomic_write_text(link, "new\n")
    assert link.is_symlink(), "the link was replaced by a file"
    assert target.read_text() == "new\n"
    assert stat.S_IMODE(os.stat(target).st_mode) == 0o664


def test_special_files_are_refused(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    for path, word in ((fifo, "FIFO"), ("/dev/null", "device"),
                       (tmp_path, "directory")):
        with pytest.raises(io.OutputPathError, match=word):
            io.atomic_write_text(path, "x")
    with pytest.raises(io.OutputPathError, match="empty"):
        io.check_output_path("", "--out")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    under_file = tmp_path / "f"
    under_file.write_text("keep")
    with pytest.raises(io.OutputPathError, match="not a directory"):
        io.check_output_path(under_file / "x.csv", "--out")
    assert under_file.read_text() == "keep"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_is_refused(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    os.chmod(ro, 0o555)
    try:
        with pytest.raises(io.OutputPathError, match="not writable"):
            io.check_output_path(ro / "x.csv", "--out")
    finally:
        os.chmod(ro, 0o755)


def test_failed_writer_leaves_old_file_and_no_temporary(tmp_path):
    p = tmp_path / "keep.csv"
    p.write_text("complete\n")
    with pytest.raises(RuntimeError):
        with io.atomic_path(p) as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer failed")
    assert p.read_text() == "complete\n"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["keep.csv"]


# ======================================================================================
# CLI: usage errors exit 2 before computing
# ======================================================================================


def _cli_imports(args, cwd) -> tuple[int, str, set]:
    """Exit status, stderr (without the import timings) and the modules imported by
    a CLI process (``-X importtime``)."""
    p = subprocess.run([sys.executable, "-X", "importtime", "-m", "drymount.cli",
                        *map(str, args)], cwd=cwd, env=ENV, capture_output=True,
                       text=True, timeout=120)
    lines = p.stderr.splitlines()
    modules = {ln.split("|")[-1].strip() for ln in lines
               if ln.startswith("import time:")}
    err = "\n".join(ln for ln in lines if not ln.startswith("import time:"))
    return p.returncode, err, modules


def _heavy(modules: set) -> list[str]:
    return sorted(m for m in modules if m.split(".")[0] in HEAVY)


@pytest.mark.parametrize("case", ["devnull", "dir", "empty", "under_file", "fifo",
                                  "plot_ext", "fmu_missing", "fmu_not_zip",
                                  "fmu_zip_not_fmu"])
def test_bad_paths_exit_2_before_computing(tmp_path, case):
    """The sweep asked for runs for minutes (2000 FMU points); a bad path must be
    reported before anything heavy is imported, naming the path, with nothing
    written."""
    (tmp_path / "d").mkdir()
    (tmp_path / "f").write_text("a file")
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "text.fmu").write_text("not a zip")
    with zipfile.ZipFile(tmp_path / "other.fmu", "w") as z:
        z.writestr("hello.txt", "a zip without modelDescription.xml")
    base = ["sweep", "sdof_halved", "--points", "2000", "--backend", "fmu", "-q"]
    extra, word = {
        "devnull": (["--out", "/dev/null"], "device"),
        "dir": (["--out", "d"], "directory"),
        "empty": (["--out", ""], "empty"),
        "under_file": (["--out", "f/x.csv"], "not a directory"),
        "fifo": (["--out", "fifo"], "FIFO"),
        "plot_ext": (["--out", "x.csv", "--plot", "x.xyz"], "x.xyz"),
        "fmu_missing": (["--fmu", "typo.fmu"], "typo.fmu"),
        "fmu_not_zip": (["--fmu", "text.fmu"], "text.fmu"),
        "fmu_zip_not_fmu": (["--fmu", "other.fmu"], "modelDescription.xml"),
    }[case]
    before = sorted(p.name for p in tmp_path.iterdir())
    code, err, modules = _cli_imports(base + extra, tmp_path)
    assert code == 2, err
    assert word in err, err
    assert "Traceback" not in err
    assert "drymount.cli" in modules or "drymount.cli_parser" in modules
    assert not _heavy(modules), _heavy(modules)
    assert sorted(p.name for p in tmp_path.iterdir()) == before, "something was written"
    assert not (tmp_path / "typo.fmu").exists()


def test_usage_errors_in_process_exit_2(tmp_path, capsys, monkeypatch):
    """In-process (no interpreter start): exit 2, nothing written (what they
    import is guarded in a fresh process: test_start_up_imports_no_solver)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d").mkdir()
    (tmp_path / "f").write_text("a file")
    for argv in (["hbm", "sdof_halved", "--out", "/dev/null"],
                 ["hbm", "sdof_halved", "--out", "d"],
                 ["hbm", "sdof_halved", "--plot", "p.xyz"],
                 ["build-fmu", "--out", "d"],
                 ["build-fmu", "--out", "model.zip"],
                 ["presets", "export", "sdof_halved", "d", "--force"],
                 ["study", "jump", "--quick", "--out", "f"],
                 ["demo", "--out", "/dev/null"],
                 ["validate", "--quick", "--out", "f/sub"]):
        code, _, err = run(argv, capsys)
        assert code == 2, (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d", "f"]


@pytest.mark.parametrize("argv, code", [
    (["--help"], 0), (["--version"], 0), (["presets", "list"], 0),
    *[([cmd, "--help"], 0) for cmd in (
        "presets", "build-fmu", "export-ssp", "hbm", "cosim", "sweep", "validate",
        "study", "demo", "fit", "characterise", "static", "explore", "optimize")],
    (["hbm"], 2),  # missing CONFIG
    (["hbm", "no_such_preset"], 2),
    (["hbm", "sdof_halved", "--set", "mount.k1=-1"], 2),
    (["hbm", "sdof_halved", "--harmonics", "200"], 2),
    (["hbm", "sdof_halved", "--out", "/dev/null"], 2),
    (["cosim", "sdof_halved", "--freq", "5", "--out", "/dev/null"], 2),
    (["sweep", "sdof_halved", "--fmin", "5", "--fmax", "2"], 2),
    (["demo", "--out", "/dev/null"], 2),
])
def test_start_up_imports_no_solver(argv, code, tmp_path):
    """Help, listings and usage or configuration errors: no scipy, matplotlib or
    numba loaded (issue 27 item 1; scipy.linalg came in through drymount.config ->
    hbm.options -> hbm.continuation and cost 1.2 of 1.4 s CPU)."""
    got, err, modules = _cli_imports(argv, tmp_path)
    assert got == code, err
    assert "Traceback" not in err
    assert not _heavy(modules), _heavy(modules)


@pytest.mark.parametrize("argv, limit", [
    (["hbm", "sdof_halved", "--harmonics", "200"], f"1..{MAX_HARMONICS}"),
    (["hbm", "sdof_halved", "--n-samples", str(10**9)], f"3..{MAX_N_SAMPLES}"),
    (["sweep", "sdof_halved", "--points", str(10**9)], f"2..{MAX_POINTS}"),
])
def test_cli_bounds_match_config(argv, limit, capsys):
    code, _, err = run(argv, capsys)
    assert code == 2
    assert limit in err, err
    assert cli.main([argv[0], "--help"]) == 0
    assert limit.split("..")[1] in capsys.readouterr().out


def test_config_bounds(tmp_path):
    text = preset_text("sdof_halved")
    for table, key, value, word in (("hbm", "harmonics", MAX_HARMONICS + 1, "1..50"),
                                    ("hbm", "n_samples", MAX_N_SAMPLES + 1, "8192"),
                                    ("sweep", "points", MAX_POINTS + 1, "10000")):
        p = tmp_path / f"{key}.toml"
        p.write_text(_set(text, table, key, value))
        with pytest.raises(ConfigError, match=word):
            load_config(p)


def _set(text: str, table: str, key: str, value) -> str:
    """``text`` with ``[table] key = value`` (table appended or extended)."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip() == f"[{table}]":
            lines = [ln for ln in lines if not ln.strip().startswith(f"{key} ")]
            lines.insert(lines.index(f"[{table}]") + 1, f"{key} = {value}")
            return "\n".join(lines) + "\n"
        del i
    return text + f"\n[{table}]\n{key} = {value}\n"


@pytest.mark.parametrize("field, value", [("mass", 1e-300), ("mass", 1e30),
                                          ("inertia", [1e-300, 1.0, 1.0]),
                                          ("inertia", [10.0, 1e30, 10.0])])
def test_rigid_engine_mass_range(tmp_path, field, value):
    text = preset_text("six_dof_halved")
    lines = []
    for line in text.splitlines():
        if line.split("=")[0].strip() == field:
            line = f"{field} = {value}"
        lines.append(line)
    p = tmp_path / "engine.toml"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(ConfigError) as info:
        load_config(p)
    msg = str(info.value)
    lo, hi = MASS_RANGE_KG if field == "mass" else INERTIA_RANGE_KGM2
    assert f"rigid_engine.{field}" in msg and f"{lo:g}..{hi:g}" in msg, msg
    assert "do not hold" not in msg, msg


def test_config_name_cannot_leave_the_working_dir(tmp_path, capsys, monkeypatch):
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    cfg = work / "evil.toml"
    cfg.write_text(_set(preset_text("sdof_linear"), "sweep", "points", 3)
                   .replace('name = "sdof_linear"', 'name = "../../x"'))
    assert 'name = "../../x"' in cfg.read_text()
    code, _, err = run(["hbm", cfg, "-q", "--harmonics", "1"], capsys)
    assert code == 0, err
    written = sorted(tmp_path.rglob("*.csv"))
    # the curve and its folds-and-peaks sidecar, both in the working directory
    assert written == [work / "x_hbm.csv", work / "x_hbm_events.csv"], written


# ======================================================================================
# The user's FMU is never modified
# ======================================================================================


def test_user_fmu_is_never_rebuilt(tmp_path, capsys, monkeypatch):
    """An FMU older than drymount's sources given with --fmu is used as it is."""
    from drymount.fmu_build import build_fmu

    monkeypatch.chdir(tmp_path)
    mine = build_fmu(tmp_path / "mine" / "Mine.fmu")
    os.utime(mine, (1e9, 1e9))  # 2001: older than every source
    before = (mine.read_bytes(), os.stat(mine).st_mtime)
    code, _, err = run(["sweep", "sdof_halved", "--points", "2", "--fmin", "4",
                        "--fmax", "5", "--backend", "fmu", "--fmu", mine, "-q",
                        "--out", "s.csv"], capsys)
    assert code == 0, err
    assert "building" not in err
    assert (mine.read_bytes(), os.stat(mine).st_mtime) == before
    assert not (tmp_path / "dist").exists(), "the default FMU was built"


def test_default_fmu_is_built_and_said(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(["cosim", "sdof_halved", "--freq", "5", "--duration", "0.2",
                        "--backend", "fmu", "--out", "c.csv"], capsys)
    assert code == 0, err
    assert "building the default FMU" in err and "does not exist" in err, err
    code, _, err = run(["cosim", "sdof_halved", "--freq", "5", "--duration", "0.2",
                        "--backend", "fmu", "--out", "c.csv"], capsys)
    assert code == 0 and "building" not in err, err


# ======================================================================================
# Failed runs write what was computed, marked partial
# ======================================================================================


def test_fmu_error_mid_sweep_writes_partial(tmp_path, capsys, monkeypatch):
    """An FMU failure at the 3rd frequency: exit 1, the first two rows written under
    a '# partial:' line, the previous complete file replaced only by that."""
    import drymount.vehicle.steady as steady

    monkeypatch.chdir(tmp_path)
    real = steady.run_steady
    calls = []

    def failing(m, f, **kw):
        calls.append(f)
        if len(calls) == 3:
            from drymount.vehicle.backends import FMUError
            raise FMUError("mount", 1.25, "fmi2DoStep failed (injected)")
        return real(m, f, **kw)

    monkeypatch.setattr(sys.modules["drymount.vehicle.sweep"], "run_steady", failing)
    code, _, err = run(["sweep", "sdof_halved", "--points", "5", "--backend",
                        "inproc", "-q", "--out", "s.csv"], capsys)
    assert code == 1, err
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert lines[0].startswith("# partial: FMUError") and "2 frequencies" in lines[0]
    assert lines[1].startswith("# drymount stepped-sine sweep")
    data = np.array([r.split(",") for r in lines[3:]], dtype=float)
    assert data.shape[0] == 2
    np.testing.assert_array_equal(data[:, 0], calls[:2])


def test_hbm_numerical_failure_is_marked_partial(tmp_path, capsys, monkeypatch):
    import drymount.hbm as hbm

    monkeypatch.chdir(tmp_path)
    real = hbm.frequency_response

    def stalled(*a, **kw):
        r = real(*a, **kw)
        n = len(r.freq_hz)
        keep = n // 2
        for f in dataclasses.fields(r):  # every per-point array
            value = getattr(r, f.name)
            if isinstance(value, np.ndarray) and value.ndim and len(value) == n:
                setattr(r, f.name, value[:keep])
        r.success, r.message = False, "step size below ds_min (injected)"
        return r

    monkeypatch.setattr(hbm, "frequency_response", stalled)
    code, _, err = run(["hbm", "sdof_halved", "-q", "--out", "h.csv"], capsys)
    assert code == 1
    first = (tmp_path / "h.csv").read_text().splitlines()[0]
    assert first == ("# partial: numerical failure: step size below ds_min "
                     "(injected)"), first


def test_cosim_failure_writes_the_steps_computed(tmp_path, capsys, monkeypatch):
    """A divergence in the 2nd block of rows: exit 1, the 1st block written under a
    '# partial:' line (same rows as a complete run)."""
    from drymount.vehicle import master

    monkeypatch.chdir(tmp_path)
    argv = ["cosim", "sdof_halved", "--freq", "5", "--backend", "inproc",
            "--duration", "2", "--steps-per-period", "2000", "--out", "c.csv"]
    assert run(argv, capsys)[0] == 0
    complete = (tmp_path / "c.csv").read_text().splitlines()
    real = master.Master._check_finite
    calls = []

    def diverge(self, row, t):
        calls.append(t)
        if len(calls) == 2:
            raise master.DivergenceError(f"injected at t = {t}")
        return real(self, row, t)

    monkeypatch.setattr(master.Master, "_check_finite", diverge)
    code, _, err = run(argv, capsys)
    assert code == 1, err
    lines = (tmp_path / "c.csv").read_text().splitlines()
    assert lines[0].startswith("# partial: DivergenceError: injected"), lines[0]
    n = master.BLOCK_ROWS
    assert f"{n} time steps" in lines[0]
    assert lines[1:] == complete[:n + 2]


def test_default_output_never_replaces_a_users_file(tmp_path, capsys, monkeypatch):
    """Without --out, ``<name>_hbm.csv`` is replaced only if drymount wrote it."""
    monkeypatch.chdir(tmp_path)
    mine = tmp_path / "sdof_linear_hbm.csv"
    mine.write_text("my own measurements\n1,2,3\n")
    code, _, err = run(["hbm", "sdof_linear", "-q", "--harmonics", "1"], capsys)
    assert code == 2, err
    assert "sdof_linear_hbm.csv" in err and "--out" in err, err
    assert mine.read_text() == "my own measurements\n1,2,3\n"
    mine.unlink()
    code, _, err = run(["hbm", "sdof_linear", "-q", "--harmonics", "1"], capsys)
    assert code == 0, err
    first = mine.read_text().splitlines()[0]
    assert first.startswith("# drymount HBM"), first
    code, _, err = run(["hbm", "sdof_linear", "--harmonics", "1"], capsys)
    assert code == 0 and "replacing sdof_linear_hbm.csv" in err, err


DESIGN = str(Path(__file__).resolve().parents[1] / "examples" / "design" /
             "sdof_n0.toml")
#: the commands that wrote into --out only after computing (issue 25 item 10)
LATE_OUT = {"fit": ["fit", "elastic", "{data}"],
            "explore": ["explore", DESIGN], "optimize": ["optimize", DESIGN],
            "characterise": ["characterise", "sdof_halved"],
            "static": ["static", "sdof_halved"]}


@pytest.mark.parametrize("command", sorted(LATE_OUT))
@pytest.mark.parametrize("where", ["under_file", "read_only"])
def test_output_folders_checked_before_computing(tmp_path, capsys, command, where,
                                                 monkeypatch):
    from drymount import cli

    data = tmp_path / "curve.csv"
    data.write_text("deflection [mm],force [N]\n0,0\n1,90\n2,185\n3,290\n")
    (tmp_path / "f").write_text("a file")
    ro = tmp_path / "ro"
    ro.mkdir()
    if where == "read_only":
        if os.geteuid() == 0:
            pytest.skip("root writes into read-only folders")
        os.chmod(ro, 0o555)
    out = tmp_path / ("f" if where == "under_file" else "ro") / (
        "x.csv" if command == "static" else "x")
    argv = [a.format(data=data) for a in LATE_OUT[command]] + ["--out", str(out)]
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    try:
        code = cli.main(argv)
    finally:
        os.chmod(ro, 0o755)
    err = capsys.readouterr().err
    assert code == 2, err
    assert "--out" in err and str(out.parent.name) in err and "OSError" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
