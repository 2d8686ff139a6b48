"""The three FMU builds unzipped under folders whose names fmpy percent-escapes in the
resource URI (issue 25, item 1), the GUID check of the PythonFMU build (item 6), and
``drymount cosim`` with such a ``TMPDIR``.

Before the fix the PythonFMU build crashed its host in fmi2Instantiate (SIGSEGV) for
every folder below but the one with a space: pythonfmu 0.7.0 decodes only ``%20`` and
its loader dereferences a NULL class when the resources folder does not exist. Each
instance runs in its own process (tests/importers/fmi_sequence_drive.py), so a crash
is a failed assertion, not a dead test run.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("fmpy", reason="pip install fmpy (the test extra)")

from native_helpers import need_gcc  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
DRIVER = REPO / "tests" / "importers" / "fmu_fuzz_drive.py"
#: every character fmpy escapes in a file URI, a literal "%20", a space
#: the drymount command, as the console script runs it
CLI = "import sys; from drymount.cli import main; sys.exit(main())"
ODD_FOLDERS = ("ünï cødé", "pct%20x", "hash#q?x", "semi;colon", 'quote"x',
               "dir with space")
#: a valid run: friction on, initialization, steps that slip, one rejected call
CALLS = [["setReal", "axial_n0", 50.0], ["setBoolean", "axial_friction", True],
         ["setup", 0.0], ["enter",], ["exit",],
         ["setReal", "u_axial", 0.004], ["getReal", "F_axial", "E_fr"],
         ["doStep", 0.0, 1e-4], ["setReal", "u_axial", -0.004],
         ["doStep", 1e-4, 1e-4], ["getReal", "F_axial", "E_fr"],
         ["doStep", 5.0, 1e-4]]  # refused: the time does not continue


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    from drymount.fmu_build import build_fmu
    from drymount.fmu_build.native import build_native_fmu

    need_gcc()
    folder = tmp_path_factory.mktemp("builds")
    return {"pythonfmu": build_fmu(folder / "FrictionMount.fmu"),
            "native2": build_native_fmu(folder / "N2.fmu").path,
            "native3": build_native_fmu(folder / "N3.fmu", fmi=3).path}


def _drive(unzipdir: Path, calls: list) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(DRIVER), str(unzipdir)],
                          input=json.dumps(calls) + "\n", capture_output=True,
                          text=True, timeout=120, env={**os.environ,
                                                       "PYTHONPATH": str(REPO)})


@pytest.mark.parametrize("folder", ODD_FOLDERS)
@pytest.mark.parametrize("build", ["pythonfmu", "native2", "native3"])
def test_instantiate_and_step_from_odd_folder(builds, tmp_path, build, folder):
    from fmpy import extract

    unzipdir = tmp_path / folder / "unzipped"
    unzipdir.parent.mkdir()
    extract(str(builds[build]), unzipdir=str(unzipdir))
    out = _drive(unzipdir, CALLS)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])
    res = json.loads(out.stdout.splitlines()[-1])
    statuses = [a[0] for a in res["answers"]]
    assert statuses == [0] * 11 + [3], statuses  # the bad time: error, not fatal
    force = res["answers"][6][1][0]
    assert force == pytest.approx(91870.0 * 0.004 + 50.0, rel=1e-12)  # k1 u + Fs
    # the slider slipped both ways: E = Fs (|dw1| + |dw2|), dw1 = u1 - Fs/kf,
    # dw2 = 2 Fs / kf - 2 u1 ... independent reference: Fs |w_new - w| per step
    fs, kf, u1 = 50.0, 60000.0, 0.004
    w1 = u1 - fs / kf
    w2 = -u1 + fs / kf
    assert res["answers"][10][1][1] == pytest.approx(fs * (w1 + (w1 - w2)), rel=1e-12)
    assert res["answers"][11][2] == 1  # the refusal logged one message
    assert res["usable"]


def test_wrong_guid_is_refused_by_every_build(builds, tmp_path):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    for build in ("pythonfmu", "native2"):
        unzipdir = extract(str(builds[build]), unzipdir=str(tmp_path / build))
        md = read_model_description(unzipdir)
        code = (f"from fmpy.fmi2 import FMU2Slave\n"
                f"s = FMU2Slave(guid='{{00000000-0000-0000-0000-000000000000}}', "
                f"unzipDirectory={str(unzipdir)!r}, "
                f"modelIdentifier={md.coSimulation.modelIdentifier!r}, "
                f"instanceName='x')\n"
                f"try:\n    s.instantiate(loggingOn=True)\n"
                f"except Exception as exc:\n    print('refused', exc)\n"
                f"else:\n    print('accepted')\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True,
                             text=True, timeout=120)
        assert out.returncode == 0, out.stderr[-2000:]
        assert "refused" in out.stdout, (build, out.stdout)
        assert "GUID" in out.stdout + out.stderr, (build, out.stdout, out.stderr)
    assert FMU2Slave  # the right GUID works: test_instantiate_and_step_from_odd_folder


@pytest.mark.parametrize("folder", ["ünï cødé", "pct%20x"])
def test_cosim_with_odd_tmpdir(builds, tmp_path, folder):
    tmpdir = tmp_path / folder
    tmpdir.mkdir()
    out = tmp_path / "run.csv"
    proc = subprocess.run(
        [sys.executable, "-c", CLI, "cosim", "sdof_halved", "--freq", "5",
         "--duration", "0.2", "--steps-per-period", "32", "--backend", "fmu",
         "--fmu", str(builds["pythonfmu"]), "--out", str(out)],
        capture_output=True, text=True, timeout=300,
        env={**os.environ, "TMPDIR": str(tmpdir), "MPLBACKEND": "Agg"})
    assert proc.returncode == 0, (proc.returncode, proc.stderr[-2000:])
    rows = [line for line in out.read_text(encoding="utf-8").splitlines()
            if not line.startswith("#")]
    assert len(rows) > 30  # header + 0.2 s at 160 steps/s


def test_fmu_without_binaries_is_a_usage_error(builds, tmp_path):
    import zipfile

    stripped = tmp_path / "stripped.fmu"
    with zipfile.ZipFile(builds["native2"]) as zin, \
            zipfile.ZipFile(stripped, "w") as zout:
        for info in zin.infolist():
            if not info.filename.startswith("binaries/"):
                zout.writestr(info, zin.read(info.filename))
    proc = subprocess.run(
        [sys.executable, "-c", CLI, "cosim", "sdof_halved", "--duration", "0.1",
         "--backend", "fmu", "--fmu", str(stripped), "--out", str(tmp_path / "r.csv")],
        capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    assert "--fmu" in proc.stderr and "binaries/linux64/" in proc.stderr, proc.stderr
    assert not (tmp_path / "r.csv").exists()
