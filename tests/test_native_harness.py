"""The vehicle harness and the CLI with the native FMU (FrictionMountNative.fmu).

The harness's ``fmu`` backend drives any FMU with the FrictionMount variables; with
the native build its results equal the in-process law (``native`` backend) as with the
PythonFMU build. Runtime about 10 s (``drymount validate --quick`` with the native FMU
is behind ``@pytest.mark.slow``, about 15 s).
"""

from __future__ import annotations

import subprocess
import sys
import zipfile

import numpy as np
import pytest
from native_helpers import ROOT, build

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.vehicle.master import Master
from drymount.hbm.systems import rigid_engine
from drymount.vehicle.steady import run_steady

pytest.importorskip("fmpy", reason="pip install -e .[fmu] installs fmpy")

#: The harness through the native FMU against the in-process law: the same
#: arithmetic, measured bit-identical; 1e-12 relative allows nothing more.
RTOL = 1e-12


@pytest.fixture(scope="module")
def native_fmu(tmp_path_factory):
    return build(tmp_path_factory.mktemp("native"), 2)


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def any_native_fmu(request, native_fmu, tmp_path_factory):
    """The FMI 2.0 and the FMI 3.0 native FMU (the harness's backend adapts to 3.0)."""
    if request.param == 2:
        return native_fmu
    return build(tmp_path_factory.mktemp("native3"), 3)


def six_dof():
    ax = AxisParameters(law="piecewise", friction=True, n0=10.0)
    mounts = [MountParameters.from_axial(ax, 1.0, friction_axes=f)
              for f in (("radial1",), ("radial2",), ("axial",))]
    return rigid_engine(140.8, [8.63, 10.02, 10.22],
                        [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)],
                        mounts)


def test_steady_state_through_native_fmu_equals_in_process_law(any_native_fmu):
    native_fmu = any_native_fmu
    system = six_dof()
    with Master(system, "inproc") as m:
        a = run_steady(m, 6.0, start="linear")
        b = run_steady(m, 6.5)
    assert np.any(a.sliders != 0.0)
    with Master(system, "fmu", fmu_path=native_fmu) as m:
        c = run_steady(m, 6.0, start="linear")
        d = run_steady(m, 6.5)
    for x, y in ((a, c), (b, d)):
        np.testing.assert_allclose(y.amplitude, x.amplitude, rtol=RTOL)
        np.testing.assert_allclose(y.sliders, x.sliders, rtol=RTOL, atol=1e-15)
    # restart from the native master's end: slider positions set between steps
    with Master(system, "fmu", fmu_path=native_fmu) as m:
        e = run_steady(m, 6.5, start=a)
    np.testing.assert_allclose(e.amplitude, b.amplitude, rtol=RTOL)


def test_cli_fmu_option_uses_a_native_fmu_as_is(native_fmu):
    """``--fmu`` with a native FMU never rebuilds it (it is not a PythonFMU build)."""
    from drymount.cli import _fmu_path
    from drymount.fmu_build.native import is_native_fmu

    before = native_fmu.read_bytes()
    assert is_native_fmu(native_fmu)
    assert _fmu_path(native_fmu) == native_fmu.resolve()
    assert native_fmu.read_bytes() == before


def test_build_commands_write_distinct_native_fmus(tmp_path):
    py = [sys.executable]
    out2, out3 = tmp_path / "n2.fmu", tmp_path / "n3.fmu"
    r2 = subprocess.run(py + ["build_fmu.py", str(out2), "--native"], cwd=ROOT,
                        capture_output=True, text=True)
    r3 = subprocess.run(py + ["-m", "drymount.cli", "build-fmu", "--native", "--fmi",
                              "3", "--out", str(out3)], cwd=ROOT, capture_output=True,
                        text=True)
    assert r2.returncode == 0 and r3.returncode == 0, r2.stderr + r3.stderr
    md2 = zipfile.ZipFile(out2).read("modelDescription.xml").decode()
    md3 = zipfile.ZipFile(out3).read("modelDescription.xml").decode()
    assert 'fmiVersion="2.0"' in md2 and 'modelIdentifier="FrictionMountNative"' in md2
    assert 'fmiVersion="3.0"' in md3 and 'modelIdentifier="FrictionMountNative3"' in md3
    bad = subprocess.run(py + ["-m", "drymount.cli", "build-fmu", "--fmi", "3"],
                         cwd=ROOT, capture_output=True, text=True)
    assert bad.returncode != 0 and "needs --native" in bad.stderr


@pytest.mark.slow
def test_validate_quick_passes_with_native_fmu(native_fmu, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "drymount.cli", "validate", "--quick",
                           "--fmu", str(native_fmu), "--out", str(tmp_path / "v")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    # every case passes, the micro-slip one (Iwan, 8 sliders, fs_ratio) through the
    # native FMU too (measured 0.061 % of peak, as with the PythonFMU build)
    from drymount.validation import CASES

    assert proc.stdout.count("PASS") == len(CASES) and "FAIL" not in proc.stdout
    assert any(line.startswith("sdof_microslip") and line.endswith("PASS")
               for line in proc.stdout.splitlines())
