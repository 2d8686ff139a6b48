"""``drymount export-xc`` (drymount/crosscheck.py) and the FMI-LS-REF reference
experiment inside the native FMUs (fmu_build/extras.py), issue 30 item 6.

The cross-check folder passes fmpy's validation of an exported FMU
(``fmpy.cross_check.validate_vendor_repo.validate_test_fmu``: path layout, model
description, ``_ref.opt``, both CSVs); fmpy simulating the FMU with ``_in.csv`` gives
``_ref.csv`` (``fmpy.cross_check.validate_result``: no problem; and to 1e-12 of the
force scale); and ``_ref.csv`` equals the closed form of the default mount below its
knee, F = k1 u + c v of the inputs of the step before (outputs read after doStep).
"""

from __future__ import annotations

import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from native_helpers import build

pytest.importorskip("fmpy", reason="the cross-check test drives the FMU with fmpy")
from fmpy import simulate_fmu  # noqa: E402
from fmpy.cross_check import validate_result  # noqa: E402
from fmpy.cross_check.validate_vendor_repo import read_csv, validate_test_fmu  # noqa: E402

from drymount.crosscheck import export_xc  # noqa: E402
from drymount.fmu_build.extras import LS_REF_DIR, REFERENCE  # noqa: E402
from drymount.fmu_src.mount_law import AxisParameters  # noqa: E402

# the same law and floats through the FMU: equal to rounding (measured 0.0)
TOL_REL = 1e-12


@pytest.fixture(scope="module", params=[2, 3], ids=["native2", "native3"])
def native(request, tmp_path_factory):
    return build(tmp_path_factory.mktemp(f"xc{request.param}"), request.param)


def _closed_form(inp) -> dict[str, np.ndarray]:
    """F = k1 u + c v of the default axis (the amplitudes stay below the knee),
    sampled as a master reading after doStep: row 0 from the inputs of t_0, row
    k + 1 from those of t_k."""
    p = AxisParameters()
    out = {}
    for axis, (x, _) in REFERENCE["axes"].items():
        assert x < p.delta  # linear part of the piecewise law
        f = p.k1 * inp[f"u_{axis}"] + p.c * inp[f"v_{axis}"]
        out[f"F_{axis}"] = np.concatenate([f[:1], f[:-1]])
    return out


# fmpy 0.3.32's validate_signal imports from scipy.ndimage.filters (deprecated)
@pytest.mark.filterwarnings("ignore:Please import .* from the `scipy.ndimage` "
                            "namespace:DeprecationWarning")
def test_export_xc_folder_is_valid_and_reproduced_by_fmpy(native, tmp_path):
    exp = export_xc(native, tmp_path / "xc")
    fmi = "2.0" if native.name.startswith("native2") else "3.0"
    assert exp.fmi_version == fmi
    assert exp.folder.parts[-6:-3] == (fmi, "cs", exp.folder.parts[-4])
    assert exp.folder.parts[-3] == "drymount" and exp.folder.name == exp.model
    assert validate_test_fmu(str(exp.folder)) == []
    names = {p.name for p in exp.folder.iterdir()}
    m = exp.model
    assert names == {f"{m}.fmu", f"{m}_in.csv", f"{m}_ref.csv", f"{m}_ref.opt",
                     "ReadMe.txt"}
    inp = read_csv(str(exp.folder / f"{m}_in.csv"))
    ref = read_csv(str(exp.folder / f"{m}_ref.csv"))
    assert len(inp) == len(ref) == exp.rows == 1001
    closed = _closed_form(inp)
    scale = max(np.abs(ref[n]).max() for n in closed)
    for name, want in closed.items():
        assert np.abs(ref[name] - want).max() <= TOL_REL * scale, name
    opts = dict(line.split(", ") for line in
                (exp.folder / f"{m}_ref.opt").read_text().splitlines())
    result = simulate_fmu(str(exp.folder / f"{m}.fmu"),
                          start_time=float(opts["StartTime"]),
                          stop_time=float(opts["StopTime"]),
                          step_size=float(opts["StepSize"]),
                          output_interval=float(opts["StepSize"]), input=inp,
                          output=list(ref.dtype.names[1:]))
    assert not validate_result(result, ref, float(opts["StartTime"]),
                               float(opts["StopTime"]))
    assert len(result) == len(ref)
    for name in ref.dtype.names[1:]:
        assert np.abs(result[name] - ref[name]).max() <= TOL_REL * scale, name


def test_native_fmu_carries_the_reference_experiment(native, tmp_path):
    """extra/org.fmi-standard.fmi-ls-ref/: the manifest (FMI-LS-REF root attributes,
    one experiment whose files exist) and the same stimuli and results as the
    cross-check folder; documentation/licenses/ holds the licence."""
    z = zipfile.ZipFile(native)
    names = set(z.namelist())
    root = ET.fromstring(z.read(f"{LS_REF_DIR}/fmi-ls-manifest.xml"))
    ls = "{http://fmi-standard.org/fmi-ls-manifest}"
    assert root.tag == "fmiReferences"
    assert root.get(f"{ls}fmi-ls-name") == "org.fmi-standard.fmi-ls-ref"
    assert root.get(f"{ls}fmi-ls-description") == ("Layered Standard providing "
                                                   "reference stimuli and results "
                                                   "for an FMU.")
    (experiment,) = root.findall("Experiment")
    assert float(experiment.get("stepSize")) == REFERENCE["stepSize"]
    exp = export_xc(native, tmp_path / "xc")
    for tag, suffix in (("Stimuli", "_in.csv"), ("References", "_ref.csv")):
        source = experiment.find(tag).get("source")
        assert f"{LS_REF_DIR}/{source}" in names
        assert z.read(f"{LS_REF_DIR}/{source}") == \
            (exp.folder / f"{exp.model}{suffix}").read_bytes()
    licence = z.read("documentation/licenses/LICENSE.txt").decode()
    assert "MIT License" in licence and "Permission is hereby granted" in licence
    assert "PythonFMU" not in licence
    assert "documentation/fmi-ls-ref.txt" in names


def test_cli_export_xc(native, tmp_path, capsys):
    from drymount import cli

    assert cli.main(["export-xc", str(native), "--out", str(tmp_path / "xc")]) == 0
    assert "_ref.csv (1001 rows)" in capsys.readouterr().err
    bad = tmp_path / "bad.fmu"
    bad.write_bytes(b"not a zip")
    assert cli.main(["export-xc", str(bad), "--out", str(tmp_path / "xc2")]) == 2
    err = capsys.readouterr().err
    assert "is not an FMU" in err and str(bad) in err
    assert not (tmp_path / "xc2").exists()
