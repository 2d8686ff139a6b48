"""The exported six_dof_halved archive (``drymount export-ssp six_dof_halved --native``)
in OMSimulator, OpenModelica's SSP/FMI importer, against fmpy driving the same FMU with
the same inputs.

OMSimulator is found through ``$DRYMOUNT_OMSIMULATOR`` (its install prefix: ``include/
OMSimulator/OMSimulator.h`` and ``lib*/libOMSimulator.so``) or an ``OMSimulator`` on
PATH (the prefix above its ``bin/``); without one, or without gcc, the module is
skipped. (The PyPI package ``OMSimulator`` downloads a prebuilt binary at build time;
built from the public source, github.com/OpenModelica/OMSimulator, ``cmake`` and
``make OMSimulator install``, it needs only Debian packages.) The host,
``tests/importers/oms_host.c``, is compiled here against that install: it imports the
archive (its ``oms:FixedStepMaster`` annotation makes the system a weakly coupled one
with OMSimulator's fixed-step master ``oms-ma`` at h = 1e-4 s), sets ``u_/v_/n_<axis>``
of the three mounts with ``oms_setReal``, advances and reads ``F_<axis>`` and ``E_fr``
with ``oms_getReal``: 1500 steps of the random motion of ``tests/test_ssp.py``.

Found: every force and ``E_fr`` equals fmpy's bit for bit when the host advances with
``oms_doStep`` (one master step per call) or with ``oms_stepUntil`` at the master's own
sums (t += h), with the native and with the PythonFMU build inside. Advanced with
``oms_stepUntil((k + 1) * h)``, 5 of the 13 500 forces differ (up to 27.6 N, from host
step 49) and ``E_fr`` of all three mounts: OMSimulator's
master keeps its time as a sum (``tNext = time + h``, SystemWC::doStep) and steps
``while (time < stopTime)`` (SystemWC::stepUntil); where the sum falls an ulp short of
(k + 1) h it takes a second ``doStep`` with the same inputs, where it runs an ulp ahead
it takes none and the inputs set for that host step never reach a ``doStep`` (at
h = 1e-4: two at host steps 23, 92, 1482, none at 48 and 357). The FMU is not at fault:
fmpy making the same calls (the FMI call log of ``tests/importers/fmi2_call_log.c``,
replayed) gives OMSimulator's outputs bit for bit.
Runtime about 30 s (one host compile, seven OMSimulator runs).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

import call_log
from native_helpers import build, random_trajectory

from drymount.config import load_preset
from drymount.fmu_src.mount_law import AXES
from drymount.ssp import SSV, export_ssp

fmpy = pytest.importorskip("fmpy", reason="pip install -e .[fmu] installs fmpy")

ENV = "DRYMOUNT_OMSIMULATOR"
HOST_SOURCE = Path(__file__).parent / "importers" / "oms_host.c"
STEPS = 1500
H = 1e-4
#: OMSimulator against fmpy, every force and E_fr: the same FMU binary making the same
#: arithmetic on the same inputs, so bit-identical (measured: 0.0 for all 13 500).
TOL = 0.0


def omsimulator_prefix() -> Path:
    """The OMSimulator install to test, or skip saying why there is none."""
    if os.environ.get(ENV):
        prefix = Path(os.environ[ENV])
    elif shutil.which("OMSimulator"):
        prefix = Path(shutil.which("OMSimulator")).resolve().parent.parent
    else:
        pytest.skip(f"no OMSimulator: set {ENV} to its install prefix or put "
                    "OMSimulator on PATH (build it from github.com/OpenModelica/"
                    "OMSimulator: cmake, make OMSimulator install)")
    if not (prefix / "include" / "OMSimulator" / "OMSimulator.h").is_file():
        pytest.skip(f"{prefix} has no include/OMSimulator/OMSimulator.h")
    return prefix


def library_dir(prefix: Path) -> Path:
    for lib in sorted(prefix.glob("lib*/**/libOMSimulator.so")):
        return lib.parent
    pytest.skip(f"{prefix} has no lib*/libOMSimulator.so")


@pytest.fixture(scope="module")
def host(tmp_path_factory) -> Path:
    """oms_host compiled against the OMSimulator install."""
    prefix = omsimulator_prefix()
    lib = library_dir(prefix)
    if shutil.which("gcc") is None:
        pytest.skip("gcc compiles the OMSimulator host")
    exe = tmp_path_factory.mktemp("oms_host") / "oms_host"
    proc = subprocess.run(["gcc", "-O1", "-o", str(exe), str(HOST_SOURCE),
                           f"-I{prefix / 'include'}", f"-L{lib}", "-lOMSimulator",
                           f"-Wl,-rpath,{lib}"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return exe


@pytest.fixture(scope="module")
def cfg():
    return load_preset("six_dof_halved")


@pytest.fixture(scope="module")
def mounts(cfg) -> list[str]:
    return [el.name for el in cfg.system.elements]


@pytest.fixture(scope="module")
def archive(cfg, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("oms_ssp")
    return export_ssp(cfg, folder / "six_dof.ssp", fmu_path=build(folder, 2)).path


@pytest.fixture(scope="module")
def fmu(archive, tmp_path_factory) -> Path:
    """The FMU inside the archive (the one OMSimulator runs)."""
    with zipfile.ZipFile(archive) as z:
        (name,) = [n for n in z.namelist() if n.endswith(".fmu")]
        path = tmp_path_factory.mktemp("oms_fmu") / Path(name).name
        path.write_bytes(z.read(name))
    return path


@pytest.fixture(scope="module")
def trajectories(cfg):
    """The random motion of tests/test_ssp.py's Ecos run (seed 31, n around 300 N)."""
    rng = np.random.default_rng(31)
    return {el.name: random_trajectory(rng, STEPS, n0=300.0)
            for el in cfg.system.elements}


def _inputs(traj) -> np.ndarray:
    """Rows of (u, v, n) per axis, the order of the host's input file."""
    return np.stack([traj.u, traj.v, traj.n], axis=2).reshape(STEPS, 9)


def _run_host(host, ssp, mode, rows: np.ndarray, mounts, folder: Path,
              log: Path | None = None) -> subprocess.CompletedProcess:
    folder.mkdir(parents=True, exist_ok=True)
    rows.astype("<f8").tofile(folder / "in.bin")
    env = dict(os.environ)
    if log is not None:
        env["FMI_CALL_LOG"] = str(log)
    return subprocess.run([str(host), str(ssp), str(folder / "tmp"),
                           str(folder / "in.bin"), str(folder / "out.bin"),
                           str(rows.shape[0]), repr(H), mode, *mounts],
                          capture_output=True, text=True, env=env, timeout=300)


def warnings(proc) -> list[str]:
    """OMSimulator's warnings, through the host's logging callback."""
    return [line for line in proc.stderr.splitlines() if line.startswith("[oms 1]")]


#: OMSimulator's installed layout puts its schemas in lib/<arch>/OMSimulator/schema,
#: the library looks for lib/<arch>/schema (XercesValidator.cpp): without a link there
#: it warns this and imports the archive unvalidated.
NO_SCHEMA = "could not load the ssd schema file"


def run_omsimulator(host, ssp, mode, mounts, trajectories, folder: Path,
                    log: Path | None = None) -> dict[str, np.ndarray]:
    """oms_host on ``ssp`` advancing by ``mode``: per mount (STEPS, 4) of F_<axis>,
    E_fr. No OMSimulator error, and no warning but a missing schema."""
    rows = np.concatenate([_inputs(trajectories[m]) for m in mounts], axis=1)
    proc = _run_host(host, ssp, mode, rows, mounts, folder, log)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "[oms 2]" not in proc.stderr, proc.stderr
    assert all(NO_SCHEMA in w for w in warnings(proc)), warnings(proc)
    out = np.fromfile(folder / "out.bin", "<f8").reshape(STEPS, len(mounts), 4)
    return {m: out[:, i, :] for i, m in enumerate(mounts)}


def _parameters(ssp: Path, mount: str) -> dict[str, tuple[str, str]]:
    """The archive's parameter set of ``mount``: name -> (type, value)."""
    from xml.etree import ElementTree as ET

    root = ET.fromstring(zipfile.ZipFile(ssp).read(f"resources/{mount}.ssv"))
    return {p.get("name"): (list(p)[0].tag.split("}")[1], list(p)[0].get("value"))
            for p in root.find(f"{{{SSV}}}Parameters")}


def run_fmpy(fmu, ssp, mounts, trajectories) -> dict[str, np.ndarray]:
    """fmpy's FMU2Slave on the same FMU with the archive's parameters: per step the
    inputs of step k, doStep(k h, h), then F_<axis> and E_fr."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    ins = [vr[f"{q}_{a}"] for a in AXES for q in ("u", "v", "n")]
    outs = [vr[f"F_{a}"] for a in AXES] + [vr["E_fr"]]
    folder = extract(str(fmu))
    got = {}
    try:
        for m in mounts:
            s = FMU2Slave(guid=md.guid, unzipDirectory=folder, instanceName=m,
                          modelIdentifier=md.coSimulation.modelIdentifier)
            s.instantiate()
            s.setupExperiment(startTime=0.0)
            s.enterInitializationMode()
            for name, (kind, value) in _parameters(ssp, m).items():
                if kind == "Real":
                    s.setReal([vr[name]], [float(value)])
                elif kind == "Integer":
                    s.setInteger([vr[name]], [int(value)])
                else:
                    s.setBoolean([vr[name]], [value == "true"])
            s.exitInitializationMode()
            x, res = _inputs(trajectories[m]), np.zeros((STEPS, 4))
            for k in range(STEPS):
                s.setReal(ins, [float(v) for v in x[k]])
                s.doStep(k * H, H)
                res[k] = s.getReal(outs)
            s.terminate()
            s.freeInstance()
            got[m] = res
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return got


@pytest.fixture(scope="module")
def reference(fmu, archive, mounts, trajectories):
    return run_fmpy(fmu, archive, mounts, trajectories)


@pytest.mark.parametrize("mode", ["dostep", "until-acc"])
def test_forces_equal_fmpy_bit_for_bit(host, archive, mounts, trajectories, reference,
                                       cfg, mode, tmp_path):
    """One master step per host step (oms_doStep, or oms_stepUntil at the master's own
    sums): every F_<axis> and E_fr of the 1500 steps equals fmpy's, and fmpy's equal
    the mount law's (the post-step reference of tests/test_ssp.py)."""
    from test_ssp import _post_commit_reference

    got = run_omsimulator(host, archive, mode, mounts, trajectories, tmp_path)
    for el in cfg.system.elements:
        ref, F = reference[el.name], got[el.name]
        assert np.abs(F - ref).max() <= TOL, (mode, el.name)
        F_law, E_law = _post_commit_reference(el.params.axes, trajectories[el.name])
        assert np.array_equal(ref[:, :3], F_law) and np.array_equal(ref[:, 3], E_law)
    assert any(p.friction for el in cfg.system.elements for p in el.params.axes)


class HostStep(NamedTuple):
    """One host step in an instance's call log: the value references set (a run of
    setReal) and the doStep calls that follow before the next run."""

    inputs: list[int]
    do_steps: list[call_log.Call]


def host_steps(calls: list[call_log.Call]) -> list[HostStep]:
    """An instance's calls after initialization, cut into host steps."""
    start = next(i for i, c in enumerate(calls) if c.name == "exitInitializationMode")
    steps: list[HostStep] = []
    previous = None
    for c in calls[start + 1:]:
        if c.name == "setReal":
            if previous != "setReal":
                steps.append(HostStep([], []))
            steps[-1].inputs.extend(c.reals()[0])
        elif c.name == "doStep":
            steps[-1].do_steps.append(c)
        previous = c.name
    return steps


def master_steps(targets) -> list[int]:
    """doSteps OMSimulator's fixed-step master takes per oms_stepUntil(T) call: its
    time is a sum of h and it steps while time < T (SystemWC::stepUntil)."""
    t, counts = 0.0, []
    for target in targets:
        n = 0
        while t < target:
            t, n = t + H, n + 1
        counts.append(n)
    return counts


def test_pythonfmu_archive_forces_equal_fmpy(host, cfg, mounts, trajectories,
                                            tmp_path):
    """The archive with the PythonFMU build inside (``drymount export-ssp
    six_dof_halved``) under oms_doStep: every F_<axis> and E_fr equals fmpy's on the
    same FMU bit for bit, and the host exits cleanly (0) after oms_delete."""
    pytest.importorskip("pythonfmu", reason="the PythonFMU build needs pythonfmu")
    from drymount.fmu_build import build_fmu

    fmu = build_fmu(tmp_path / "FrictionMount.fmu")
    ssp = export_ssp(cfg, tmp_path / "six_dof.ssp", fmu_path=fmu).path
    got = run_omsimulator(host, ssp, "dostep", mounts, trajectories, tmp_path / "run")
    reference = run_fmpy(fmu, ssp, mounts, trajectories)
    for m in mounts:
        assert np.abs(got[m] - reference[m]).max() <= TOL, m


@pytest.fixture(scope="module")
def logging_archive(archive, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("oms_log")
    return call_log.logging_ssp(archive, folder / "logged.ssp",
                                call_log.build_shim(folder))


def test_one_doStep_per_host_step_at_the_masters_sums(host, logging_archive, fmu,
                                                      mounts, trajectories, reference,
                                                      tmp_path):
    """The FMI calls under oms_doStep (call log): each mount a Co-Simulation instance;
    per host step its nine inputs u_/v_/n_<axis>, then one doStep at the master's time
    t_k (t_k+1 = t_k + h) with communicationStepSize t_k+1 - t_k; the forces through
    the logger equal fmpy's."""
    md = fmpy.read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    inputs = sorted(vr[f"{q}_{a}"] for a in AXES for q in ("u", "v", "n"))
    log = tmp_path / "calls.log"
    got = run_omsimulator(host, logging_archive, "dostep", mounts, trajectories,
                          tmp_path, log)
    calls = call_log.parse(log)
    assert sorted(calls) == sorted(mounts)
    t = 0.0
    times = []
    for _ in range(STEPS):
        times.append((t, (t + H) - t))
        t += H
    for m in mounts:
        assert (calls[m][0].name, calls[m][0].arg("type")) == ("instantiate", "1"), m
        steps = host_steps(calls[m])
        assert len(steps) == STEPS, m
        for k, step in enumerate(steps):
            assert sorted(step.inputs) == inputs, (m, k)
            assert [(float(c.arg("t")), float(c.arg("h")))
                    for c in step.do_steps] == [times[k]], (m, k)
        assert np.abs(got[m] - reference[m]).max() <= TOL, m


def test_stepuntil_at_products_of_h_doubles_and_skips_steps(host, logging_archive, fmu,
                                                            mounts, trajectories,
                                                            reference, tmp_path):
    """oms_stepUntil((k + 1) h): the master takes two doSteps (the same inputs) where
    its sum of h falls short of (k + 1) h and none where it runs ahead (the inputs of
    that host step never reach a doStep), as the summation predicts; fmpy replaying the
    logged calls gets OMSimulator's outputs bit for bit (the FMU is not at fault), and
    the forces read after those host steps differ from the one-step-per-step run."""
    log = tmp_path / "calls.log"
    got = run_omsimulator(host, logging_archive, "until-mul", mounts, trajectories,
                          tmp_path, log)
    calls = call_log.parse(log)
    predicted = master_steps([(k + 1) * H for k in range(STEPS)])
    odd = {k: n for k, n in enumerate(predicted) if n != 1}
    assert 0 in odd.values() and 2 in odd.values()
    forces = energies = 0
    largest = 0.0
    for m in mounts:
        assert [len(s.do_steps) for s in host_steps(calls[m])] == predicted, m
        logged = [c.reals()[1] for c in calls[m] if c.name == "getReal"]
        assert call_log.replay(fmu, m, calls[m]) == logged, m
        diff = np.abs(got[m] - reference[m])
        assert not diff[:min(odd)].any(), m  # equal until the first odd host step
        forces += int((diff[:, :3] > 0).sum())
        largest = max(largest, diff[:, :3].max())
        energies += int(diff[:, 3].max() > 0)
    print(f"\nhost steps with other than one doStep: {odd}; differing from fmpy: "
          f"{forces} of {STEPS * len(mounts) * 3} forces (largest {largest:.4g} N), "
          f"E_fr of {energies} of {len(mounts)} mounts")
    assert forces > 0


def test_omsimulator_validates_the_archive_against_its_schemas(host, archive, mounts,
                                                              tmp_path):
    """With its schemas found, OMSimulator validates the imported SSD (Xerces, the SSP
    1.0 schemas it ships): no warning for the exported archive, and its validation is
    not a no-op: the same SSD with a component's ParameterBindings before its
    Connectors (the schema's order broken) is reported."""
    row = np.zeros((1, 9 * len(mounts)))
    proc = _run_host(host, archive, "dostep", row, mounts, tmp_path / "good")
    if any(NO_SCHEMA in w for w in warnings(proc)):
        pytest.skip("this OMSimulator install does not find its schemas (link "
                    "lib/<arch>/schema to lib/<arch>/OMSimulator/schema)")
    assert proc.returncode == 0 and warnings(proc) == [], proc.stderr
    with zipfile.ZipFile(archive) as z:
        text = z.read("SystemStructure.ssd").decode()
        head, rest = text.split("<ssd:Connectors>", 1)
        connectors, tail = rest.split("</ssd:Connectors>", 1)
        end = "</ssd:ParameterBindings>"
        start, stop = tail.index("<ssd:ParameterBindings>"), tail.index(end) + len(end)
        bad = (head + tail[start:stop] + "<ssd:Connectors>" + connectors
               + "</ssd:Connectors>" + tail[:start] + tail[stop:])
        path = tmp_path / "bad.ssp"
        with zipfile.ZipFile(path, "w") as out:
            for name in z.namelist():
                ssd = name == "SystemStructure.ssd"
                out.writestr(name, bad if ssd else z.read(name))
    proc = _run_host(host, path, "dostep", row, mounts, tmp_path / "bad")
    assert any("does not conform to the SSP standard schema" in w
               for w in warnings(proc)), proc.stderr
