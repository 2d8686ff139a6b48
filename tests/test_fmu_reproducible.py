"""Reproducible FMU builds (issue 11): same sources and version -> same bytes and a
GUID derived from the content; another version or model -> another GUID.

Runtime: ~8 s (three builds).
"""

from __future__ import annotations

import time
import zipfile

import pytest

from drymount.fmu_build import build_fmu
from drymount.fmu_build.builder import ZIP_DATE_TIME, fmu_guid

pytest.importorskip("pythonfmu")


def _guid(path) -> str:
    import re

    with zipfile.ZipFile(path) as z:
        md = z.read("modelDescription.xml").decode()
    return re.search(r'\sguid="([^"]+)"', md).group(1)


def test_two_builds_are_byte_identical(tmp_path):
    a = build_fmu(tmp_path / "a" / "FrictionMount.fmu")
    time.sleep(1.1)  # a timestamp anywhere would now differ
    b = build_fmu(tmp_path / "b" / "FrictionMount.fmu")
    assert a.read_bytes() == b.read_bytes()
    with zipfile.ZipFile(a) as z:
        infos = z.infolist()
        md = z.read("modelDescription.xml").decode()
    names = [i.filename for i in infos]
    assert names == sorted(names)
    assert {i.date_time for i in infos} == {ZIP_DATE_TIME}
    assert "generationDateAndTime" not in md
    modes = {i.filename: (i.external_attr >> 16) & 0o777 for i in infos}
    assert modes["binaries/linux64/FrictionMount.so"] == 0o755
    assert modes["modelDescription.xml"] == 0o644


def test_guid_follows_the_content(tmp_path):
    a = build_fmu(tmp_path / "a.fmu")
    c = build_fmu(tmp_path / "c.fmu", version="9.9.9")
    assert _guid(a) != _guid(c)
    with zipfile.ZipFile(a) as z:
        md = z.read("modelDescription.xml").decode()
        res = {n: z.read(n) for n in z.namelist() if n.startswith("resources/")}
    # the GUID is the documented function of the content ...
    assert fmu_guid(md, res, _version(a)) == _guid(a)
    # ... and changes with any byte of the model code or of the description
    name = next(n for n in res if n.endswith("/friction_mount.py"))
    changed = dict(res, **{name: res[name] + b"\n# changed\n"})
    assert fmu_guid(md, changed, _version(a)) != _guid(a)
    assert fmu_guid(md.replace('version="', 'version="x', 1), res, _version(a)) \
        != _guid(a)


def _version(path) -> str:
    import re

    with zipfile.ZipFile(path) as z:
        md = z.read("modelDescription.xml").decode()
    return re.search(r'<fmiModelDescription[^>]*\sversion="([^"]+)"', md).group(1)
