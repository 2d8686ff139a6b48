"""Config fields by path and ``--set PATH=VALUE`` (drymount.paths, issue 18 item 2).

An override must give exactly the configuration of the same value typed into the
file (the reference: the preset text edited and loaded), and a bad override must be
rejected with the field path, the value and what is allowed.
"""

from __future__ import annotations

import numpy as np
import pytest

from drymount import cli
from drymount.config import ConfigError, load_config, load_preset, preset_text
from drymount.design.space import Variable, apply_values
from drymount.paths import (
    WILDCARD,
    PathError,
    apply_overrides,
    expand,
    get_value,
    load_with_overrides,
    parse_assignment,
    parse_path,
)

CONFIG_COMMANDS = ("hbm", "cosim", "sweep", "explore", "optimize")


@pytest.mark.parametrize("text, parts", [
    ("mount.friction.n0", ("mount", "friction", "n0")),
    ("mounts[2].axial.friction.n0", ("mounts", 2, "axial", "friction", "n0")),
    ("mounts[*].position[2]", ("mounts", WILDCARD, "position", 2)),
    ("excitation.amplitude[0]", ("excitation", "amplitude", 0)),
])
def test_parse_good_paths(text, parts):
    assert parse_path(text).parts == parts


@pytest.mark.parametrize("text", ["", "foo..bar", "mounts[x].k1", "1abc", "a.[0]",
                                  "mounts[-1].k1", "a b"])
def test_parse_bad_paths_say_what_a_path_is(text):
    with pytest.raises(PathError, match="path"):
        parse_path(text)


def test_wildcard_expands_to_the_fields_that_exist():
    doc = load_preset("six_dof_halved").data
    # only mount 3 (index 2) has an axial friction element in this preset
    assert expand(doc, parse_path("mounts[*].axial.friction.n0")) == [
        ("mounts", 2, "axial", "friction", "n0")]
    got = expand(doc, parse_path("mounts[*].position[2]"))
    assert [get_value(doc, p) for p in got] == [0.0, 0.0, -0.5]
    with pytest.raises(PathError, match="matches no field"):
        expand(doc, parse_path("mounts[*].radial9.k1"))


def test_override_equals_the_same_value_in_the_file():
    cfg = load_with_overrides("sdof_halved", ["mount.friction.n0=20", "mount.c=200"])
    ref = load_config(preset_text("sdof_halved").replace("n0 = 10.0", "n0 = 20.0")
                      .replace("c = 150.0", "c = 200.0"), name="sdof_halved")
    assert cfg.system.elements[0].params == ref.system.elements[0].params
    np.testing.assert_array_equal(cfg.system.C, ref.system.C)
    assert "--set mount.friction.n0=20" in cfg.source


def test_wildcard_override_on_six_dof():
    cfg = load_with_overrides("six_dof_halved", ["mounts[*].position[2]=0.05",
                                                 "mounts[*].axial.c=300"])
    assert [m["position"][2] for m in cfg.data["mounts"]] == [0.05] * 3
    assert all(e.params.axial.c == 300.0 for e in cfg.system.elements)
    # the preset file is not changed by an override
    assert load_preset("six_dof_halved").data["mounts"][0]["position"][0] == -0.5


@pytest.mark.parametrize("override, needles", [
    ("mounts[5].axial.k1=1", ["`mounts[5]` does not exist", "indices 0-2"]),
    ("mounts[0].axial.k1=-5", ["mounts[0].axial.k1", "-5"]),
    ("mounts[0].axial.friction.n00=3", ["unknown key `mounts[0].axial.friction.n00`",
                                        "did you mean `n0`"]),
    ("mounts[*].axial.n0=3", ["unknown key `mounts[0].axial.n0`",
                              "friction fields go in"]),
    ("rigid_engine.mass=heavy stuff", ["not a TOML value"]),
    ("rigid_engine.mass", ["PATH=VALUE"]),
    ("mounts[*].radial9.k1=1", ["matches no field"]),
    ("mounts.axial=1", ["`mounts` is an array, not a table"]),
])
def test_bad_overrides_name_path_value_and_what_is_allowed(override, needles):
    with pytest.raises(ConfigError) as info:
        load_with_overrides("six_dof_halved", [override])
    text = str(info.value)
    for needle in needles:
        assert needle in text, text


def test_every_bad_override_is_listed_at_once():
    _, problems = apply_overrides(load_preset("sdof_halved").data,
                                  ["sdof.mass=1", "nope[3]=1", "a..b=2"])
    assert len(problems) == 2 and problems[0].startswith("--set nope[3]=1")


def test_values_parse_as_toml():
    assert parse_assignment("a=180")[1] == 180
    assert parse_assignment("a=1.5e3")[1] == 1500.0
    assert parse_assignment("a=[0, 0.1, 0]")[1] == [0, 0.1, 0]
    assert parse_assignment("a=native")[1] == "native"
    assert parse_assignment('a="native"')[1] == "native"


@pytest.mark.parametrize("command", CONFIG_COMMANDS)
def test_every_config_command_takes_set(command):
    args = cli.build_parser().parse_args([command, "sdof_halved", "--set", "a=1",
                                          "--set", "b.c=2"])
    assert args.overrides == ["a=1", "b.c=2"]


def test_cli_hbm_with_set_equals_the_edited_file(tmp_path, capsys):
    edited = tmp_path / "edited.toml"
    edited.write_text(preset_text("sdof_halved").replace("n0 = 10.0", "n0 = 30.0"))
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert cli.main(["hbm", "sdof_halved", "-H", "1", "-q", "--out", str(a),
                     "--set", "mount.friction.n0=30"]) == 0
    assert cli.main(["hbm", str(edited), "-H", "1", "-q", "--out", str(b)]) == 0
    body = [p.read_text().splitlines()[1:] for p in (a, b)]  # past the provenance
    assert body[0] == body[1]


def test_cli_bad_set_exit_2(capsys):
    assert cli.main(["hbm", "sdof_halved", "--set", "mount.k1=-1"]) == 2
    err = capsys.readouterr().err
    assert "mount.k1" in err and "-1" in err and "Traceback" not in err


def test_rotation_variable_turns_the_mount_axes():
    doc = load_preset("six_dof_halved").data
    var = Variable("t", (parse_path("mounts[0].orientation"),), -90.0, 90.0,
                   rotate_about="y")
    new = apply_values(doc, [var], [90.0])
    rows = np.array(new["mounts"][0]["orientation"])
    # default rows: axial z, radial1 x, radial2 y; +90 deg about y takes z -> x and
    # x -> -z (right-handed rotation), y stays
    np.testing.assert_allclose(rows, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-15)
    assert "orientation" not in doc["mounts"][0]


def test_path_and_value_problems_are_listed_together():
    with pytest.raises(ConfigError) as info:
        load_with_overrides("six_dof_halved", ["mounts[5].axial.k1=1",
                                               "rigid_engine.mass=-3"])
    assert len(info.value.problems) == 2
    assert "mounts[5]" in info.value.problems[0]
    assert "rigid_engine.mass" in info.value.problems[1]
