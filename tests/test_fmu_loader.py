"""The linux64 loader of the PythonFMU build (fmu_src/fmu_loader.c, issue 30 item 5).

A C importer without Python runs FrictionMount.fmu through the loader, which starts
a libpython itself. Checked here: a Python of another minor version than the building
one under DRYMOUNT_LIBPYTHON / DRYMOUNT_PYTHONHOME (forces equal to the in-process law
and to the run with the building Python), DRYMOUNT_PYTHONHOME taken as given (a
prefix of another version or without a standard library is refused with a message,
never started: the importer died with "Fatal Python error: init_fs_encoding"), no
crash at exit with an instance alive (OMSimulator's order: the host frees it in an
exit handler), and the glibc floor read from the loader's symbol versions.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

fmpy = pytest.importorskip("fmpy",
                           reason="the FMU tests need fmpy (pip install -e .[test])")
from fmpy import read_model_description  # noqa: E402

from drymount.fmu_build import build_fmu  # noqa: E402
from drymount.fmu_build import builder  # noqa: E402
from drymount.fmu_src.mount_law import AxisParameters, axis_force  # noqa: E402

HERE = Path(__file__).parent
# pythonfmu 0.7.0's own linux64 binary needs GLIBC_2.32 (its symbol versions); the
# loader must not need more. RHEL 8 has glibc 2.28, Debian 11 2.31, Ubuntu 20.04 2.31.
GLIBC_RHEL8 = (2, 28)
# same floats through the same scalar law: exact equality expected, 1e-12 the bound
RTOL_FMU_VS_LAW = 1e-12


def _building_libpython() -> Path | None:
    loc = builder.libpython_location()
    return Path(loc[0]) if loc else None


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    """(unzipped folder, GUID, value references) of a fresh FrictionMount.fmu."""
    if not sys.platform.startswith("linux"):
        pytest.skip("the loader is linux64 only")
    tmp = tmp_path_factory.mktemp("loader_fmu")
    path = build_fmu(tmp / "FrictionMount.fmu")
    unzipdir = tmp / "unzipped"
    zipfile.ZipFile(path).extractall(unzipdir)
    if not (unzipdir / "binaries" / "linux64" / builder.REAL_BINARY).exists():
        pytest.skip("this FMU was built without the linux64 loader: "
                    + (unzipdir / "documentation" / "build.txt").read_text())
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return unzipdir, md.guid, vr


def _compile(tmp_path_factory, source: str) -> Path:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip(f"gcc not found: cannot compile tests/c_host/{source}")
    exe = tmp_path_factory.mktemp("c_host") / Path(source).stem
    headers = Path(fmpy.__file__).parent / "c-code"  # the FMI 2.0 headers
    subprocess.run([gcc, "-std=c11", "-D_GNU_SOURCE", "-O1", "-Wall", "-Werror",
                    f"-I{headers}", "-o", str(exe), str(HERE / "c_host" / source),
                    "-ldl", "-lm"], check=True, timeout=120)
    return exe


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    return _compile(tmp_path_factory, "host.c")


@pytest.fixture(scope="module")
def exit_host(tmp_path_factory):
    return _compile(tmp_path_factory, "exit_host.c")


def _python_info(exe: str) -> dict | None:
    code = ("import json, sys, sysconfig; g = sysconfig.get_config_var; "
            "print(json.dumps({'shared': bool(g('Py_ENABLE_SHARED')), "
            "'lib': str(g('LIBDIR') or '') + '/' + str(g('INSTSONAME') or ''), "
            "'prefix': sys.base_prefix, 'ver': '%d.%d' % sys.version_info[:2]}))")
    try:
        out = subprocess.run([exe, "-c", code], capture_output=True, text=True,
                             timeout=60, env={"PATH": os.environ.get("PATH", "")})
        info = json.loads(out.stdout)
    except (OSError, ValueError, subprocess.TimeoutExpired):
        return None
    return info if info["shared"] and Path(info["lib"]).is_file() else None


def _other_python() -> dict | None:
    """A shared-library CPython 3 of another minor version than this one: python3.N
    on PATH, under pyenv's versions/ or uv's python installs."""
    here = "{}.{}".format(*sys.version_info[:2])
    candidates = [shutil.which(f"python3.{n}") for n in range(8, 16)]
    pyenv = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv"))
    uv = Path.home() / ".local" / "share" / "uv" / "python"
    for root in (pyenv / "versions", uv):
        candidates += [str(p) for p in sorted(root.glob("*/bin/python3.*"))
                       if re.fullmatch(r"python3\.\d+", p.name)]
    for exe in filter(None, candidates):
        info = _python_info(exe)
        if info is not None and info["ver"] != here:
            return info
    return None


@pytest.fixture(scope="module")
def other_python():
    info = _other_python()
    if info is None:
        pytest.skip("no shared-library CPython of another minor version than "
                    f"{sys.version_info[0]}.{sys.version_info[1]} found (python3.N on "
                    "PATH, pyenv, uv); `uv python install 3.12` provides one. The "
                    "clean refusal is tested without one by "
                    "test_drymount_pythonhome_is_taken_as_given")
    return info


SINE = (2000, 1e-4, 0.005, 10.0)  # steps, h, amplitude, frequency


def _run_host(host, fmu, env, params=True):
    unzipdir, guid, vr = fmu
    args = [*SINE, vr["u_axial"], vr["v_axial"], vr["F_axial"], vr["Ffr_axial"],
            vr["E_fr"]]
    if params:
        args += [f"B{vr['axial_friction']}=1", f"R{vr['axial_n0']}=100",
                 f"R{vr['axial_kf']}=80000", f"I{vr['axial_law']}=1",
                 f"R{vr['axial_kc']}=5.708e8"]
    return subprocess.run([str(host), str(unzipdir)] + [str(a) for a in args],
                          env={"PATH": "/usr/bin:/bin", "FMU_GUID": guid, **env},
                          capture_output=True, text=True, timeout=300)


def _rows(out) -> list[list[float]]:
    return [[float(x) for x in line.split()[2:]] for line in out.stdout.splitlines()
            if line.startswith("STEP ")]


def _law_rows(rows) -> list[list[float]]:
    p = AxisParameters(law="cubic", friction=True, n0=100.0, kf=80000.0,
                       kc=5.708e8)
    w, e, ref = 0.0, 0.0, []
    for u, v, *_ in rows:
        f, ffr, w, _, _, diss = axis_force(u, v, w, p)
        e += diss
        ref.append([f, ffr, e])
    return ref


def test_loader_runs_a_python_of_another_minor_version(host, fmu, other_python):
    """DRYMOUNT_LIBPYTHON / DRYMOUNT_PYTHONHOME of another minor version (what
    externalDependencies.txt advises on another machine): that library is the one
    loaded (LD_DEBUG), the building one is not, and the forces equal the in-process
    law to 1e-12 and the run with the building Python bit for bit."""
    env = {"DRYMOUNT_LIBPYTHON": other_python["lib"],
           "DRYMOUNT_PYTHONHOME": other_python["prefix"], "LD_DEBUG": "files"}
    out = _run_host(host, fmu, env)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    assert "Fatal Python error" not in out.stderr
    lines = out.stdout.splitlines()
    assert "REPLAY identical" in lines and "TWIN identical" in lines
    assert lines[-1] == "DONE"
    loaded = set(re.findall(r"file=(\S*libpython\S*)", out.stderr))
    assert other_python["lib"] in loaded, loaded
    assert not any(f"libpython{sys.version_info[0]}.{sys.version_info[1]}" in f
                   for f in loaded), loaded
    rows = _rows(out)
    assert len(rows) == SINE[0]
    ref = _law_rows(rows)
    for got, want in zip(rows, ref):
        for g, w in zip(got[2:], want):
            assert abs(g - w) <= RTOL_FMU_VS_LAW * abs(w), (got, want)
    assert rows[-1][4] > 0.0  # it slipped
    same = _run_host(host, fmu, {})
    assert same.returncode == 0, same.stdout[-2000:] + same.stderr[-2000:]
    assert _rows(same) == rows


def test_loader_refuses_a_pythonhome_of_another_version(host, fmu, other_python):
    """DRYMOUNT_LIBPYTHON of version X.Y with DRYMOUNT_PYTHONHOME holding another
    version's standard library: refused with the reason, nothing started (before the
    fix: PYTHONHOME=/ on a merged-/usr system and "Fatal Python error")."""
    here = sys.base_prefix
    env = {"DRYMOUNT_LIBPYTHON": other_python["lib"], "DRYMOUNT_PYTHONHOME": here}
    out = _run_host(host, fmu, env)
    assert out.returncode == 3, out.stdout[-2000:] + out.stderr[-2000:]
    assert "FAILED fmi2Instantiate" in out.stdout
    ver = other_python["ver"]
    assert (f"{other_python['lib']} (DRYMOUNT_PYTHONHOME={here} holds no "
            f"lib/python{ver}/os.py and encodings/ (the library is Python {ver}))"
            in out.stdout), out.stdout
    assert "Fatal Python error" not in out.stderr


def test_drymount_pythonhome_is_taken_as_given(host, fmu, tmp_path):
    """A DRYMOUNT_PYTHONHOME without a standard library is never replaced by one
    found elsewhere (above the library, /): every candidate is refused naming it."""
    out = _run_host(host, fmu, {"DRYMOUNT_PYTHONHOME": str(tmp_path)})
    assert out.returncode == 3, out.stdout[-2000:] + out.stderr[-2000:]
    assert "FAILED fmi2Instantiate" in out.stdout
    lib = _building_libpython()
    ver = "{}.{}".format(*sys.version_info[:2])
    assert (f"{lib} (DRYMOUNT_PYTHONHOME={tmp_path} holds no lib/python{ver}/os.py"
            in out.stdout), out.stdout
    assert "Fatal Python error" not in out.stderr


@pytest.mark.parametrize("mode", ["free-at-exit", "leak"])
def test_instance_alive_at_exit_does_not_crash(exit_host, fmu, mode):
    """The host frees its instance in an exit handler registered before the FMU was
    loaded (OMSimulator), or never: exit code 0 (before the fix: 139, pythonfmu had
    finalised Python in its own exit handler first)."""
    unzipdir, guid, vr = fmu
    out = subprocess.run([str(exit_host), str(unzipdir), guid, str(vr["u_axial"]),
                          str(vr["F_axial"]), mode], env={"PATH": "/usr/bin:/bin"},
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    lines = out.stdout.splitlines()
    assert "MAIN DONE" in lines
    assert ("FREED AT EXIT" in lines) == (mode == "free-at-exit")
    w, f = 0.0, None
    for k in range(1, 11):
        f, _, w, *_ = axis_force(1e-3 * k, 0.0, w, AxisParameters())
    force = float(next(x for x in lines if x.startswith("F ")).split()[1])
    assert force == pytest.approx(f, rel=RTOL_FMU_VS_LAW, abs=0.0)


def _glibc_versions(binary: Path) -> list[tuple[int, ...]]:
    readelf = shutil.which("readelf")
    if readelf is None:
        pytest.skip("readelf (binutils) not found: cannot read symbol versions")
    out = subprocess.run([readelf, "-V", "-W", str(binary)], capture_output=True,
                         text=True, check=True, timeout=60).stdout
    need = out[out.index("Version needs section"):] if "Version needs section" in out \
        else ""
    return sorted({tuple(int(x) for x in m.split("."))
                   for m in re.findall(r"Name: GLIBC_([0-9.]+)", need)})


def test_loader_glibc_floor(fmu):
    """The loader needs no glibc newer than pythonfmu's own binary (2.32), and none
    newer than RHEL 8's 2.28: its highest GLIBC_ symbol version, read from the
    binary. libdl.so.2 and libpthread.so.0, where glibc < 2.34 keeps dlopen & co.,
    are linked."""
    binaries = fmu[0] / "binaries" / "linux64"
    loader = _glibc_versions(binaries / "FrictionMount.so")
    real = _glibc_versions(binaries / builder.REAL_BINARY)
    assert loader and real
    assert loader[-1] <= real[-1], (loader, real)
    assert loader[-1] <= GLIBC_RHEL8, loader
    needed = subprocess.run(["readelf", "-d", str(binaries / "FrictionMount.so")],
                            capture_output=True, text=True, check=True).stdout
    for lib in ("libdl.so.2", "libpthread.so.0"):
        assert f"[{lib}]" in needed, needed
