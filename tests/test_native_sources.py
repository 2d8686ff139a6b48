"""The native FMUs as source-code FMUs (issue 30 item 3, FMI 2.0.5 sec. 2.1.1, FMI 3.0.2
sec. 2.2.1): ``sources/drymount_fmu.c`` compiled with ``FMI2_FUNCTION_PREFIX`` /
``FMI3_FUNCTION_PREFIX`` defines only the prefixed FMI functions (every internal
function and element static), so two copies with different prefixes link into one
program and run side by side (forces equal to the Python law); the headers compile
as C++ (``extern "C"`` guards); the binaries keep the standard names.
"""

from __future__ import annotations

import shutil
import zipfile

import numpy as np
import pytest
from native_helpers import ROOT, Trajectory, build, reference_run, run

from drymount.fmu_src.mount_law import AxisParameters

fmpy = pytest.importorskip("fmpy", reason="pip install -e .[fmu] installs fmpy")

STEPS = 3000
N0 = 300.0
#: C and Python agree to this, relative to the force scale (measured: 0.0).
TOL_REL = 1e-12


@pytest.fixture(scope="module")
def sources(tmp_path_factory):
    if shutil.which("gcc") is None:
        pytest.skip("gcc compiles the sources")
    folder = tmp_path_factory.mktemp("src")
    out = {}
    for fmi in (2, 3):
        path = build(folder, fmi)
        zipfile.ZipFile(path).extractall(folder / f"fmu{fmi}")
        out[fmi] = (path, folder / f"fmu{fmi}" / "sources")
    return out


def _compile_prefixed(src, fmi: int, prefix: str, obj):
    proc = run(["gcc", "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                f"-DFMI{fmi}_FUNCTION_PREFIX={prefix}", "-c", "-o", obj,
                src / "drymount_fmu.c"])
    assert proc.returncode == 0, proc.stderr


def _globals(obj) -> set[str]:
    text = run(["nm", "-g", "--defined-only", obj]).stdout
    return {line.split()[-1] for line in text.splitlines() if line.strip()}


@pytest.mark.parametrize("fmi", [2, 3])
def test_prefixed_object_defines_only_prefixed_fmi_functions(sources, tmp_path, fmi):
    if shutil.which("nm") is None:
        pytest.skip("nm (binutils) lists the object's symbols")
    _, src = sources[fmi]
    _compile_prefixed(src, fmi, "A_", tmp_path / "a.o")
    names = _globals(tmp_path / "a.o")
    assert f"A_fmi{fmi}DoStep" in names and len(names) > 30
    assert all(n.startswith(f"A_fmi{fmi}") for n in names), sorted(
        n for n in names if not n.startswith(f"A_fmi{fmi}"))


def test_two_prefixed_copies_run_in_one_program(sources, tmp_path):
    """Copies A_ and B_ of the FMI 2.0 sources, one instance each, 3000 steps of
    sines of 10 and 20 mm with friction on: each equals the Python law."""
    from fmpy import read_model_description

    path, src = sources[2]
    for prefix in ("A_", "B_"):
        _compile_prefixed(src, 2, prefix, tmp_path / f"{prefix}.o")
    exe = tmp_path / "prefix_host"
    proc = run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-o", exe,
                ROOT / "tests" / "c_host" / "prefix_host.c", tmp_path / "A_.o",
                tmp_path / "B_.o", "-lm"])
    assert proc.returncode == 0, proc.stderr
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    proc = run([exe, md.guid, STEPS, vr["u_axial"], vr["v_axial"], vr["F_axial"],
                vr["axial_friction"], vr["axial_n0"], N0])
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[-1] == "DONE"
    rows = np.array([[float(x) for x in line.split()] for line in lines[:-1]])
    assert rows.shape == (STEPS, 7)
    axes = (AxisParameters(friction=True, n0=N0), AxisParameters(), AxisParameters())
    slipped = 0
    for col in (1, 4):  # copy A, copy B
        u = np.zeros((STEPS, 3))
        v = np.zeros((STEPS, 3))
        u[:, 0], v[:, 0] = rows[:, col], rows[:, col + 1]
        n = np.zeros((STEPS, 3))
        n[:, 0] = N0
        ref = reference_run(axes, Trajectory(u, v, n))
        scale = np.abs(ref.F[:, 0]).max()
        assert np.abs(rows[:, col + 2] - ref.F[:, 0]).max() <= TOL_REL * scale
        slipped += int(ref.slip[:, 0].sum())
    assert slipped > 0  # the friction element slipped in the run


@pytest.mark.parametrize("fmi", [2, 3])
def test_headers_compile_as_cpp(sources, tmp_path, fmi):
    """Every header of sources/ included from C++ (the extern "C" guards)."""
    if shutil.which("g++") is None:
        pytest.skip("g++ compiles the C++ check")
    _, src = sources[fmi]
    cpp = tmp_path / "check.cpp"
    cpp.write_text(f'#include "fmi{fmi}_api.h"\n#include "model.h"\n'
                   'extern "C" int probe(void) { return sizeof(md_instance) > 0; }\n')
    proc = run(["g++", "-std=c++11", "-Wall", "-Werror", "-c", "-I", src, "-o",
                tmp_path / "check.o", cpp])
    assert proc.returncode == 0, proc.stderr
