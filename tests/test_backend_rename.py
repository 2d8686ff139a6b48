"""The in-process backend is called ``inproc``; ``native``, its old name, now means
only the C FMU and is accepted as a deprecated alias with a one-line FutureWarning
wherever a user passes it (API, configuration, CLI), with the same numbers."""

from __future__ import annotations

import numpy as np
import pytest

from drymount import cli
from drymount.config import config_from_dict, load_preset
from drymount.vehicle import Master, simulate, sweep
from drymount.vehicle.backends import BACKENDS, backend_name

OLD = "deprecated: it is called 'inproc' now"


def test_backend_names():
    assert sorted(BACKENDS) == ["fmu", "inproc"]
    assert backend_name("inproc") == "inproc" and backend_name("fmu") == "fmu"
    with pytest.warns(FutureWarning, match=OLD) as rec:
        assert backend_name("native") == "inproc"
    assert len(rec) == 1 and "\n" not in str(rec[0].message)


def test_api_alias_gives_the_same_numbers():
    s = load_preset("sdof_halved").system
    a = simulate(s, 6.0, 0.3, backend="inproc")
    with pytest.warns(FutureWarning, match=OLD):
        b = simulate(s, 6.0, 0.3, backend="native")
    assert b.backend == "inproc"
    np.testing.assert_array_equal(a.q, b.q)
    with pytest.warns(FutureWarning, match=OLD):
        with Master(s, "native") as m:
            assert m.backend_name == "inproc"
    with pytest.warns(FutureWarning, match=OLD) as rec:
        r = sweep(s, [5.0, 6.0], backend="native", progress=False)
    assert len(rec) == 1  # said once, where the user passed it
    ref = sweep(s, [5.0, 6.0], backend="inproc", progress=False)
    np.testing.assert_array_equal(r.transmissibility, ref.transmissibility)


def test_config_alias():
    data = dict(load_preset("sdof_halved").data)
    data["cosim"] = {**data["cosim"], "backend": "native"}
    with pytest.warns(FutureWarning, match="`cosim.backend` = 'native' is deprecated"):
        cfg = config_from_dict(data)
    assert cfg.cosim.backend == "inproc"
    data["cosim"]["backend"] = "c"
    with pytest.raises(Exception, match="cosim.backend"):
        config_from_dict(data)


def test_cli_alias_one_line_warning_same_csv(tmp_path, capsys):
    outs = {}
    for name in ("inproc", "native"):
        outs[name] = tmp_path / f"{name}.csv"
        code = cli.main(["sweep", "sdof_linear", "--fmin", "3", "--fmax", "9",
                         "--points", "2", "--backend", name, "--out",
                         str(outs[name]), "-q"])
        err = capsys.readouterr().err
        assert code == 0, err
        warned = [ln for ln in err.splitlines() if "deprecated" in ln]
        assert warned == ([] if name == "inproc" else [
            "drymount: warning: --backend backend 'native' is deprecated: it is called "
            "'inproc' now (the law in-process); the native C FMU is the fmu backend "
            "with dist/FrictionMountNative.fmu"])
    rows = [p.read_text().splitlines() for p in outs.values()]
    assert [r for r in rows[0] if not r.startswith("#")] == \
        [r for r in rows[1] if not r.startswith("#")]


def test_cli_config_alias_one_line(tmp_path, capsys):
    code = cli.main(["sweep", "sdof_linear", "--fmin", "3", "--fmax", "9", "--points",
                     "2", "--set", "cosim.backend=native", "--out",
                     str(tmp_path / "s.csv"), "-q"])
    err = capsys.readouterr().err
    assert code == 0, err
    assert [ln for ln in err.splitlines() if "deprecated" in ln] == [
        "drymount: warning: `cosim.backend` = 'native' is deprecated: use 'inproc' "
        "(the law in-process; 'native' now names only the C FMU)"]
