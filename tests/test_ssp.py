"""SSP export (drymount/ssp.py): the archive's structure against the FMU's interface,
and the archive run in an independent SSP importer (Ecos, ``pip install ecospy``; needs
the Debian package libtbb12) against the mount law with the configuration's parameters.

Every exported archive is validated against the SSP 1.0 XML schemas fmpy ships
(``fmpy/ssp/schema``: ``read_ssd(..., validate=True)`` for the SSD, ``validate_tree``
with SystemStructureParameterValues.xsd for each ``.ssv``); the structure test checks
the archive's consistency with the FMU, and OMSimulator's system annotation (it
refuses an SSP without it). Runtime about 10 s.
"""

from __future__ import annotations

import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from native_helpers import build, random_trajectory

from drymount.config import load_preset
from drymount.ssp import OMS, OSP, SSC, SSD, SSV, export_ssp
from drymount.fmu_src import interface
from drymount.fmu_src.mount_law import AXES, axis_force, law_code

#: Ecos's forces against the law, relative to the force scale. The arithmetic is the
#: same (measured: 0.0 for every mount, native and PythonFMU FMU); the energy sum's
#: order differs by rounding only.
TOL_REL = 1e-12
STEPS = 1500
H = 1e-4


@pytest.fixture(scope="module")
def cfg():
    return load_preset("six_dof_halved")


@pytest.fixture(scope="module", params=["native", "pythonfmu"])
def ssp(request, cfg, tmp_path_factory):
    """The archive with the native FMI 2.0 FMU or the PythonFMU build inside."""
    folder = tmp_path_factory.mktemp("ssp")
    if request.param == "native":
        fmu = build(folder, 2)
    else:
        from drymount.fmu_build import build_fmu

        fmu = build_fmu(folder / "FrictionMount.fmu")
    return export_ssp(cfg, folder / "six_dof.ssp", fmu_path=fmu)


def validate_archive(path) -> int:
    """Validate an SSP archive against fmpy's SSP 1.0 schemas: the SSD through
    ``fmpy.ssp.ssd.read_ssd(validate=True)``, every ``.ssv`` with
    SystemStructureParameterValues.xsd. Raises on the first invalid file; returns
    the number of files validated."""
    ssd = pytest.importorskip("fmpy.ssp.ssd", reason="fmpy ships the SSP schemas")
    etree = pytest.importorskip("lxml.etree", reason="fmpy's SSP validation uses lxml")
    ssd.read_ssd(str(path), validate=True)
    z = zipfile.ZipFile(path)
    ssvs = [n for n in z.namelist() if n.endswith(".ssv")]
    for name in ssvs:
        ssd.validate_tree(etree.fromstring(z.read(name)),
                          "SystemStructureParameterValues.xsd")
    return 1 + len(ssvs)


def test_every_archive_is_valid_against_the_ssp_schemas(cfg, ssp):
    assert validate_archive(ssp.path) == 1 + len(cfg.system.elements)


def test_schema_validation_rejects_an_invalid_archive(ssp, tmp_path):
    """The validator is not a no-op: the same SSD with its Elements before the
    Connectors of a component (the schema's order broken) is refused."""
    z = zipfile.ZipFile(ssp.path)
    text = z.read("SystemStructure.ssd").decode()
    head, rest = text.split("<ssd:Connectors>", 1)
    connectors, tail = rest.split("</ssd:Connectors>", 1)
    bindings_start = tail.index("<ssd:ParameterBindings>")
    end_tag = "</ssd:ParameterBindings>"
    bindings_end = tail.index(end_tag) + len(end_tag)
    bad = (head + tail[bindings_start:bindings_end] + "<ssd:Connectors>" + connectors
           + "</ssd:Connectors>" + tail[:bindings_start] + tail[bindings_end:])
    path = tmp_path / "bad.ssp"
    with zipfile.ZipFile(path, "w") as out:
        for name in z.namelist():
            out.writestr(name, bad if name == "SystemStructure.ssd" else z.read(name))
    with pytest.raises(Exception, match="Failed to validate SystemStructure.ssd"):
        validate_archive(path)


def _xml(ssp, name):
    return ET.fromstring(zipfile.ZipFile(ssp.path).read(name))


def test_structure_matches_the_fmu_interface(cfg, ssp):
    names = set(zipfile.ZipFile(ssp.path).namelist())
    root = _xml(ssp, "SystemStructure.ssd")
    assert root.tag == f"{{{SSD}}}SystemStructureDescription"
    assert root.get("version") == "1.0" and root.get("name")
    assert [c.tag.split("}")[1] for c in root] == ["System", "Units",
                                                    "DefaultExperiment"]
    units = {u.get("name"): u for u in root.find(f"{{{SSD}}}Units")}
    comps = root.findall(f"{{{SSD}}}System/{{{SSD}}}Elements/{{{SSD}}}Component")
    assert [c.get("name") for c in comps] == [el.name for el in cfg.system.elements]
    for comp in comps:
        assert comp.get("type") == "application/x-fmu-sharedlibrary"
        assert comp.get("source") in names
        for con in comp.find(f"{{{SSD}}}Connectors"):
            var = interface.variable(con.get("name"))
            assert con.get("kind") == var.causality
            real = con.find(f"{{{SSC}}}Real")
            assert real.get("unit") == var.unit and var.unit in units
        binding = comp.find(f"{{{SSD}}}ParameterBindings/{{{SSD}}}ParameterBinding")
        assert binding.get("source") == f"resources/{comp.get('name')}.ssv"
        assert binding.get("source") in names
    assert "documentation/README.txt" in names
    # the default experiment: the FMU's, with libcosim's algorithm on no worker
    # thread (an FMU error at initialization then reaches the host, docs/fmu.md 4a)
    exp = root.find(f"{{{SSD}}}DefaultExperiment")
    assert float(exp.get("startTime")) == interface.DEFAULT_EXPERIMENT["startTime"]
    ann = exp.find(f"{{{SSD}}}Annotations/{{{SSC}}}Annotation")
    assert ann.get("type") == "com.opensimulationplatform"
    algo = ann.find(f"{{{OSP}}}Algorithm/{{{OSP}}}FixedStepAlgorithm")
    assert algo.get("numWorkerThreads") == "0"
    assert float(algo.get("baseStepSize")) == interface.DEFAULT_EXPERIMENT["stepSize"]
    # OMSimulator's system annotation: read by element name with the oms: prefix
    system = root.find(f"{{{SSD}}}System")
    assert [c.tag.split("}")[1] for c in system] == ["Elements", "Annotations"]
    ann = system.find(f"{{{SSD}}}Annotations/{{{SSC}}}Annotation")
    assert ann.get("type") == "org.openmodelica"
    master = ann.find(f"{{{OMS}}}Annotations/{{{OMS}}}SimulationInformation/"
                      f"{{{OMS}}}FixedStepMaster")
    assert master.get("description") == "oms-ma"
    assert float(master.get("stepSize")) == interface.DEFAULT_EXPERIMENT["stepSize"]
    text = zipfile.ZipFile(ssp.path).read("SystemStructure.ssd").decode()
    assert f'xmlns:oms="{OMS}"' in text and "<oms:FixedStepMaster " in text


def test_parameter_sets_hold_the_configuration(cfg, ssp):
    for el in cfg.system.elements:
        root = _xml(ssp, f"resources/{el.name}.ssv")
        assert root.tag == f"{{{SSV}}}ParameterSet" and root.get("version") == "1.0"
        assert root.get("name") == ssp.parameter_set
        assert [c.tag.split("}")[1] for c in root] == ["Parameters", "Units"]
        units = {u.get("name") for u in root.find(f"{{{SSV}}}Units")}
        got = {}
        for p in root.find(f"{{{SSV}}}Parameters"):
            (typed,) = list(p)
            var = interface.variable(p.get("name"))
            assert var.causality == "parameter"
            assert typed.tag == f"{{{SSV}}}{var.type}"
            assert typed.get("unit") == var.unit and (var.unit is None
                                                       or var.unit in units)
            got[var.name] = typed.get("value")
        assert len(got) == len(interface.by_causality("parameter"))
        for axis, p in zip(AXES, el.params.axes, strict=True):
            assert got[f"{axis}_law"] == str(law_code(p.law))
            assert got[f"{axis}_friction"] == ("true" if p.friction else "false")
            for field in ("k1", "kc", "k2", "delta", "delta_neg", "c", "kf", "mu",
                          "n0"):
                assert float(got[f"{axis}_{field}"]) == getattr(p, field)


def _post_commit_reference(axes, traj):
    """Forces an importer reads after ``doStep``: the trial at u_k with the slider
    committed at u_k (Ecos reads outputs after stepping)."""
    steps = traj.u.shape[0]
    F, E = np.zeros((steps, 3)), np.zeros(steps)
    e_total = 0.0
    for j, p in enumerate(axes):
        w = e = 0.0
        for k in range(steps):
            u, v, n = traj.u[k, j], traj.v[k, j], traj.n[k, j]
            r = axis_force(u, v, w, p, n)
            w, e = r.w_new, e + r.dissipated
            after = axis_force(u, v, w, p, n)
            F[k, j] = after.force
            E[k] += e + after.dissipated
        e_total += e
    return F, E


def test_ecos_runs_the_archive_forces_equal_the_law(cfg, ssp):
    ecospy = pytest.importorskip("ecospy", reason="pip install ecospy (and apt-get "
                                                  "install libtbb12)")
    rng = np.random.default_rng(31)
    trajs = {el.name: random_trajectory(rng, STEPS, n0=300.0)
             for el in cfg.system.elements}
    got = {el.name: (np.zeros((STEPS, 3)), np.zeros(STEPS))
           for el in cfg.system.elements}
    sim = ecospy.EcosSimulation(step_size=H, ssp_path=str(ssp.path))
    try:
        sim.init(parameter_set=ssp.parameter_set)
        for k in range(STEPS):
            for name, traj in trajs.items():
                for j, a in enumerate(AXES):
                    sim.set_real(f"{name}::u_{a}", float(traj.u[k, j]))
                    sim.set_real(f"{name}::v_{a}", float(traj.v[k, j]))
                    sim.set_real(f"{name}::n_{a}", float(traj.n[k, j]))
            sim.step()
            for name in trajs:
                F, E = got[name]
                F[k] = [sim.get_real(f"{name}::F_{a}") for a in AXES]
                E[k] = sim.get_real(f"{name}::E_fr")
    finally:
        sim.terminate()
    for el in cfg.system.elements:
        F_ref, E_ref = _post_commit_reference(el.params.axes, trajs[el.name])
        F, E = got[el.name]
        scale = np.abs(F_ref).max()
        assert np.abs(F - F_ref).max() <= TOL_REL * scale, el.name
        assert np.abs(E - E_ref).max() <= TOL_REL * max(1.0, E_ref.max()), el.name
    assert any(p.friction for el in cfg.system.elements for p in el.params.axes)


def test_cli_export_ssp(tmp_path):
    import subprocess
    import sys

    from native_helpers import ROOT

    fmu = build(tmp_path, 2)
    out = tmp_path / "sdof.ssp"
    proc = subprocess.run([sys.executable, "-m", "drymount.cli", "export-ssp",
                           "sdof_halved", "--out", str(out), "--fmu", str(fmu)],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "1 mount components" in proc.stderr
    names = zipfile.ZipFile(out).namelist()
    assert f"resources/{fmu.name}" in names and "SystemStructure.ssd" in names
    assert validate_archive(out) == 2


def _zip(path, files: dict):
    with zipfile.ZipFile(path, "w") as z:
        for name, data in files.items():
            z.writestr(name, data)
    return path


def test_cli_export_ssp_refuses_what_ssp_1_cannot_carry(tmp_path, capsys):
    """Issue 25 item 8: a non-zip, garbage XML, an unrelated FMU or an FMI 3.0 FMU
    was packed with exit 0; now exit 2 naming --fmu, nothing written."""
    from drymount import cli

    fmu3 = build(tmp_path / "b3", 3)
    other = ('<?xml version="1.0"?><fmiModelDescription fmiVersion="2.0" '
             'modelName="Other"><ModelVariables><ScalarVariable name="x"/>'
             '</ModelVariables></fmiModelDescription>')
    cases = {
        "not a zip": (tmp_path / "a.fmu", "is not an FMU (not a zip file)"),
        "garbage XML": (_zip(tmp_path / "b.fmu", {"modelDescription.xml": "<a><"}),
                        "modelDescription.xml"),  # cli_guard reads it first
        "unrelated": (_zip(tmp_path / "c.fmu", {"modelDescription.xml": other}),
                      # cli_guard validates the description first (no ModelStructure)
                      "has an invalid modelDescription.xml"),
        "FMI 3.0": (fmu3, "is an FMI 3.0 FMU; an SSP 1.0 archive carries FMI 2.0"),
    }
    cases["not a zip"][0].write_bytes(b"not a zip at all")
    for what, (fmu, needle) in cases.items():
        out = tmp_path / f"{what}.ssp"
        code = cli.main(["export-ssp", "sdof_halved", "--out", str(out), "--fmu",
                         str(fmu)])
        err = capsys.readouterr().err
        assert code == 2 and "--fmu" in err and needle in err, (what, err)
        assert not out.exists(), what
