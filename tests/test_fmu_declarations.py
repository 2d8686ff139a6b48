"""What the three builds declare alike (issue 30 item 6, small items): the ranges of
the micro-slip parameters (``<axis>_sliders`` 1..64, ``<axis>_spread`` in [0, 1)) and
the default experiment, tolerance included (the PythonFMU build had none)."""

from __future__ import annotations

import math
import zipfile
from xml.etree import ElementTree as ET

import pytest
from native_helpers import build

from drymount.fmu_src.interface import DEFAULT_EXPERIMENT
from drymount.fmu_src.jenkins import MAX_SLIDERS
from drymount.fmu_src.mount_law import AXES


@pytest.fixture(scope="module")
def descriptions(tmp_path_factory):
    pytest.importorskip("pythonfmu", reason="the PythonFMU build needs pythonfmu")
    from drymount.fmu_build import build_fmu

    tmp = tmp_path_factory.mktemp("decl")
    paths = {"pythonfmu": build_fmu(tmp / "FrictionMount.fmu"),
             "native2": build(tmp, 2), "native3": build(tmp, 3)}
    return {k: ET.fromstring(zipfile.ZipFile(p).read("modelDescription.xml"))
            for k, p in paths.items()}


def _attributes(root, name: str) -> dict[str, str]:
    for el in root.iter():
        if el.get("name") == name:
            typed = list(el)  # FMI 2.0: the type element; FMI 3.0: on the variable
            return dict(typed[0].attrib if el.tag == "ScalarVariable" else el.attrib)
    raise AssertionError(f"no variable {name}")


def test_micro_slip_ranges_are_declared_in_every_build(descriptions):
    below_one = math.nextafter(1.0, 0.0)
    for build_name, root in descriptions.items():
        for axis in AXES:
            sliders = _attributes(root, f"{axis}_sliders")
            assert (int(sliders["min"]), int(sliders["max"])) == (1, MAX_SLIDERS), \
                build_name
            spread = _attributes(root, f"{axis}_spread")
            assert float(spread["min"]) == 0.0, build_name
            assert float(spread["max"]) == below_one, build_name  # [0, 1): 1 excluded


def test_default_experiment_is_the_same_in_every_build(descriptions):
    want = {k: float(v) for k, v in DEFAULT_EXPERIMENT.items()}
    assert set(want) == {"startTime", "stopTime", "stepSize", "tolerance"}
    for build_name, root in descriptions.items():
        got = {k: float(v) for k, v in root.find("DefaultExperiment").attrib.items()}
        assert got == want, build_name
