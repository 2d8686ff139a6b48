"""Configuration files and presets (drymount.config).

References: thesis Table 4.1/4.2 (6-DOF layout and natural frequencies), Sec. 2.4 (mount
law fit), Sec. 2.1.2 (quarter car), PHYSICS.md section 3 (values we chose).
"""

from __future__ import annotations

import copy
import math
import sys

import numpy as np
import pytest
import scipy.linalg
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drymount.config import (
    ALLOWED_KEYS,
    Config,
    ConfigError,
    config_from_dict,
    list_presets,
    load_config,
    load_preset,
    preset_text,
    resolve_config,
)
from drymount.hbm.system import System

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

#: Undamped natural frequencies of thesis Table 4.2 (x, y, z, alpha, beta, gamma), Hz.
TABLE_4_2_HZ = (6.10, 5.82, 7.07, 12.03, 11.59, 14.05)
#: Issue 4 target for the 6-DOF preset: each within 2 %. Measured 0.67 % (largest;
#: the mode labels are checked in test_presets_modes.py).
RTOL_TABLE_4_2 = 0.02
#: Thesis fit of the original mount (Sec. 2.4).
K1, K2, DELTA = 91870.0, 513800.0, 0.01225

EXPECTED_PRESETS = {
    "sdof_original", "sdof_halved", "sdof_cubic", "sdof_linear", "sdof_microslip",
    "sdof_inclined", "quarter_car_original", "quarter_car_inclined",
    "quarter_car_halved", "sdof_maxwell",
    "six_dof_original", "six_dof_halved", "six_dof_lambda12", "six_dof_4mount",
    "sdof_hydraulic", "quarter_car_hydraulic", "six_dof_hydraulic",
}

SDOF = """
model = "sdof"
name = "t"
[sdof]
mass = 70.0
[mount]
law = "piecewise"
k1 = 45935.0
k2 = 256900.0
delta = 0.01225
c = 150.0
[mount.friction]
kf = 60000.0
mu = 1.0
n0 = 10.0
[excitation]
kind = "unbalance"
amplitude = 0.03
[sweep]
fmin_hz = 1.0
fmax_hz = 30.0
points = 20
[hbm]
harmonics = 7
"""


def _problems(text: str) -> list[str]:
    with pytest.raises(ConfigError) as info:
        load_config(text)
    assert info.value.problems, "a ConfigError must list its problems"
    return info.value.problems


def _one(problems: list[str], *needles: str) -> str:
    """The single problem containing every needle."""
    hits = [p for p in problems if all(n in p for n in needles)]
    assert len(hits) == 1, f"expected one problem with {needles}, got {problems}"
    return hits[0]


# ======================================================================================
# Presets
# ======================================================================================


def test_list_presets():
    assert set(list_presets()) == EXPECTED_PRESETS


@pytest.mark.parametrize("name", sorted(EXPECTED_PRESETS))
def test_every_preset_loads(name):
    cfg = load_preset(name)
    assert isinstance(cfg, Config) and isinstance(cfg.system, System)
    assert cfg.name == name
    assert cfg.description
    assert cfg.sweep.fmin_hz < cfg.sweep.fmax_hz
    # every value the thesis does not give is stated in the file with its reason
    assert "CHOSEN" in preset_text(name)
    # the mounts hold the system: positive definite linearised stiffness
    K, C = cfg.system.linearized()
    assert np.all(np.linalg.eigvalsh(K) > 0)
    assert np.all(np.linalg.eigvalsh(C) >= -1e-9)


def test_six_dof_original_reproduces_table_4_2():
    """Undamped natural frequencies, k = 91870 N/m, lambda = 1, Table 4.1 layout."""
    system = load_preset("six_dof_original").system
    K, _ = system.linearized()
    w2 = scipy.linalg.eigh(K, system.M, eigvals_only=True)
    f = np.sort(np.sqrt(w2) / (2 * np.pi))
    ref = np.sort(TABLE_4_2_HZ)
    np.testing.assert_allclose(f, ref, rtol=RTOL_TABLE_4_2)


def test_six_dof_layout_is_table_4_1():
    from drymount.studies import mount_position

    system = load_preset("six_dof_original").system
    positions = [mount_position(e) for e in system.elements]
    np.testing.assert_allclose(positions, [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0),
                                           (0.0, -0.25, -0.5)], atol=1e-12)
    for e in system.elements:
        for p in e.params.axes:
            assert (p.k1, p.k2, p.delta, p.friction) == (K1, K2, DELTA, False)


def test_six_dof_halved_friction_directions():
    """Friction along x on mount 1, y on mount 2, z on mount 3 (Sec. 4.5), n0 250 N."""
    system = load_preset("six_dof_halved").system
    for e, direction in zip(system.elements, np.eye(3), strict=True):
        fr = [j for j, p in enumerate(e.params.axes) if p.friction]
        assert len(fr) == 1
        # row j of B[:, :3] is the local axis j in body axes
        np.testing.assert_allclose(np.asarray(e.B)[fr[0], :3], direction)
        p = e.params.axes[fr[0]]
        assert (p.n0, p.kf, p.mu) == (250.0, 60000.0, 1.0)
        assert all(a.k1 == K1 / 2 and a.k2 == K2 / 2 for a in e.params.axes)


def test_lambda12_scales_radial_stiffness():
    system = load_preset("six_dof_lambda12").system
    for e in system.elements:
        assert e.params.axial.k1 == K1
        for r in (e.params.radial1, e.params.radial2):
            assert r.k1 == pytest.approx(1.2 * K1) and r.k2 == pytest.approx(1.2 * K2)


def test_sdof_presets_values():
    orig = load_preset("sdof_original").system
    half = load_preset("sdof_halved").system
    a, h = orig.elements[0].params.axial, half.elements[0].params.axial
    assert (a.law, a.k1, a.k2, a.delta, a.friction) == ("piecewise", K1, K2, DELTA,
                                                        False)
    assert (h.k1, h.k2, h.delta) == (K1 / 2, K2 / 2, DELTA)
    assert h.friction and (h.kf, h.mu, h.n0) == (60000.0, 1.0, 10.0)
    # f0 is chosen so that the engine force is 40 N at the linear resonance k1/m
    f0 = orig.excitation.amplitude[0]
    assert f0 * K1 / orig.M[0, 0] == pytest.approx(40.0, rel=1e-4)
    cubic = load_preset("sdof_cubic").system.elements[0].params.axial
    assert (cubic.law, cubic.k1, cubic.kc) == ("cubic", 34770.0, 5.708e8)
    assert load_preset("sdof_linear").system.is_linear()


def test_quarter_car_presets_values():
    for name, n0 in (("quarter_car_original", None), ("quarter_car_halved", 30.0)):
        s = load_preset(name).system
        np.testing.assert_array_equal(np.diag(s.M), [70.0, 230.0, 30.0])
        # suspension k_s = 15000 between sprung and unsprung, tyre k_t = 200000
        assert s.K[1, 2] == -15000.0 and s.K[2, 2] == 215000.0
        assert s.C[1, 2] == -1000.0 and s.Kb[2, 0] == 200000.0
        p = s.elements[0].params.axial
        assert (p.n0 if p.friction else None) == n0


def test_preset_text_and_unknown_preset():
    assert preset_text("sdof_original").startswith("#")
    with pytest.raises(ConfigError) as info:
        load_preset("sdof_orignal")
    assert "did you mean `sdof_original`" in str(info.value)


def test_resolve_config_file_or_preset(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text(SDOF)
    assert resolve_config(path).source == str(path)
    assert resolve_config("sdof_halved").source == "preset:sdof_halved"
    with pytest.raises(ConfigError, match="neither a file nor a preset"):
        resolve_config("no_such_thing")


def test_text_and_file_give_the_same_system(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(SDOF)
    a, b = load_config(SDOF).system, load_config(path).system
    np.testing.assert_array_equal(a.linearized()[0], b.linearized()[0])
    assert a.elements[0].params == b.elements[0].params


# ======================================================================================
# Error cases: one ConfigError listing every problem with path, value and rule
# ======================================================================================


def test_unknown_key_suggests_closest():
    p = _one(_problems(SDOF.replace("k1 = 45935.0", "k_1 = 45935.0")), "`mount.k_1`")
    assert "did you mean `k1`?" in p and "45935.0" in p and "allowed here" in p


def test_missing_field():
    p = _one(_problems(SDOF.replace("c = 150.0\n", "")), "`mount.c`")
    assert "missing" in p and "N s/m" in p


def test_wrong_type():
    p = _one(_problems(SDOF.replace("k2 = 256900.0", 'k2 = "stiff"')), "`mount.k2`")
    assert "a string 'stiff'" in p and "number" in p


def test_negative_mass_and_stiffness():
    text = SDOF.replace("mass = 70.0", "mass = -70.0").replace("k1 = 45935.0",
                                                               "k1 = -1.0")
    problems = _problems(text)
    assert "in 0.001..1e+06" in _one(problems, "`sdof.mass`", "-70.0")
    assert ">= 0" in _one(problems, "`mount.k1`", "-1.0")
    assert len(problems) == 2


def test_friction_without_normal_force():
    p = _one(_problems(SDOF.replace("n0 = 10.0\n", "")), "`mount.friction.n0`")
    assert "missing" in p and "normal force" in p


def test_friction_with_zero_normal_force():
    p = _one(_problems(SDOF.replace("n0 = 10.0", "n0 = 0.0")), "`mount.friction.n0`")
    assert "> 0" in p


def test_nan_and_inf():
    problems = _problems(SDOF.replace("k1 = 45935.0", "k1 = nan")
                         .replace("amplitude = 0.03", "amplitude = inf"))
    assert "finite" in _one(problems, "`mount.k1`", "nan")
    assert "finite" in _one(problems, "`excitation.amplitude`", "inf")


@pytest.mark.parametrize("fmax, word", [("1.0", "empty"), ("0.5", "reversed")])
def test_empty_or_reversed_frequency_range(fmax, word):
    p = _one(_problems(SDOF.replace("fmax_hz = 30.0", f"fmax_hz = {fmax}")),
             "`sweep.fmax_hz`")
    assert word in p


@pytest.mark.parametrize("value", ["0", "-3", "7.5", "true", '"seven"', "51"])
def test_bad_harmonics(value):
    p = _one(_problems(SDOF.replace("harmonics = 7", f"harmonics = {value}")),
             "`hbm.harmonics`")
    assert "integer in 1..50" in p


def test_every_problem_in_one_error():
    text = (SDOF.replace("mass = 70.0", "mass = -70.0")
            .replace("k1 = 45935.0", "k1 = nan")
            .replace("n0 = 10.0\n", "")
            .replace("fmax_hz = 30.0", "fmax_hz = 1.0")
            .replace('law = "piecewise"', 'law = "piecwise"')
            .replace("points = 20", "pionts = 20"))
    with pytest.raises(ConfigError) as info:
        load_config(text)
    problems = info.value.problems
    for needle in ("`sdof.mass`", "`mount.law`", "`mount.friction.n0`",
                   "`sweep.fmax_hz`", "`sweep.pionts`"):
        _one(problems, needle)
    assert 'did you mean "piecewise"' in _one(problems, "`mount.law`")
    assert "did you mean `points`" in _one(problems, "`sweep.pionts`")
    # the message lists them one per line, after a count
    message = str(info.value)
    assert message.splitlines()[0].endswith(f"{len(problems)} problems:")
    assert all(f"  - {p}" in message for p in problems)


def test_toml_syntax_error():
    problems = _problems(SDOF.replace("mass = 70.0", "mass = = 70"))
    assert problems[0].startswith("TOML syntax error")


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="no such file"):
        load_config(tmp_path / "nope.toml")


def test_wrong_model_tables_get_a_hint():
    text = SDOF.replace("[mount]\n", "[[mounts]]\n")
    p = _one(_problems(text), "unknown key `mounts`")
    assert "rigid_engine" in p and "[mount]" in p


def test_bad_model_name():
    p = _one(_problems(SDOF.replace('model = "sdof"', 'model = "sdf"')), "`model`")
    assert 'did you mean "sdof"' in p


def _six_dof_text() -> str:
    return preset_text("six_dof_halved")


def test_six_dof_paths_name_the_mount_index():
    text = _six_dof_text().replace("n0 = 250.0", "n0 = -1.0", 3)
    problems = _problems(text)
    for i, axis in enumerate(("radial1", "radial2", "axial")):
        _one(problems, f"`mounts[{i}].{axis}.friction.n0`", "-1.0")


def test_six_dof_lambda_conflict_and_position():
    data = tomllib.loads(_six_dof_text())
    data["mounts"][1]["radial1"] = {"k1": 5.0}
    data["mounts"][2]["position"] = [0.0, 1.0]
    with pytest.raises(ConfigError) as info:
        config_from_dict(data)
    _one(info.value.problems, "`mounts[1].radial1.k1`", "lambda")
    _one(info.value.problems, "`mounts[2].position`", "3 numbers")


def test_six_dof_collinear_mounts_are_singular():
    data = tomllib.loads(_six_dof_text())
    for i, m in enumerate(data["mounts"]):
        m["position"] = [0.5 * i, 0.0, 0.0]
    with pytest.raises(ConfigError) as info:
        config_from_dict(data)
    _one(info.value.problems, "singular")


def test_six_dof_orientation_must_be_a_rotation():
    data = tomllib.loads(_six_dof_text())
    data["mounts"][0]["orientation"] = [[1, 0, 0], [1, 0, 0], [0, 0, 1]]
    with pytest.raises(ConfigError) as info:
        config_from_dict(data)
    _one(info.value.problems, "`mounts[0].orientation`", "rotation")


def test_orientation_rotates_the_local_axes():
    data = tomllib.loads(preset_text("six_dof_original"))
    R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]  # axial along x
    data["mounts"][0]["orientation"] = R
    e = config_from_dict(data).system.elements[0]
    np.testing.assert_allclose(np.asarray(e.B)[:, :3], R)


def test_allowed_keys_are_documented():
    """docs/config.md names every key the checker accepts."""
    from pathlib import Path

    doc = (Path(__file__).parents[1] / "docs" / "config.md").read_text()
    for table, keys in ALLOWED_KEYS.items():
        for k in keys:
            assert any(f in doc for f in (f"`{k}`", f"`[{k}]`", f"`[[{k}]]`")), \
                f"docs/config.md does not document `{k}` (table {table!r})"


# ======================================================================================
# Property test: mutated presets give a Config or a clean ConfigError, nothing else
# ======================================================================================

_PRESET_DATA = {n: tomllib.loads(preset_text(n)) for n in sorted(EXPECTED_PRESETS)}


def _paths(node, prefix=()):
    """Every (path tuple) to a value inside nested dicts/lists."""
    out = []
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in items:
        out.append(prefix + (k,))
        if isinstance(v, (dict, list)):
            out.extend(_paths(v, prefix + (k,)))
    return out


def _get(node, path):
    for k in path:
        node = node[k]
    return node


_scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**30, max_value=10**30),
    st.sampled_from([10**400, -(10**400), 0, -1]),  # beyond float range; edges
    st.booleans(),
    st.text(max_size=8),
    st.sampled_from(["linear", "cubic", "piecewise", "base", "unbalance", "up", "fmu",
                     "sdof", "rigid_engine"]),
)
_values = st.one_of(
    _scalars,
    st.lists(_scalars, max_size=4),
    st.dictionaries(st.sampled_from(["kf", "mu", "n0", "k1", "zz"]), _scalars,
                    max_size=3),
)


@st.composite
def mutated_presets(draw):
    data = copy.deepcopy(_PRESET_DATA[draw(st.sampled_from(sorted(_PRESET_DATA)))])
    for _ in range(draw(st.integers(min_value=1, max_value=3))):
        paths = _paths(data)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent, key = _get(data, path[:-1]), path[-1]
        op = draw(st.sampled_from(["delete", "replace", "negate", "nan", "insert"]))
        value = parent[key]
        if op == "delete":
            del parent[key]
        elif op == "replace":
            parent[key] = draw(_values)
        elif op == "negate" and isinstance(value, (int, float)) \
                and not isinstance(value, bool):
            parent[key] = -value
        elif op == "nan" and isinstance(value, float):
            parent[key] = math.nan
        elif op == "insert" and isinstance(value, dict):
            value[draw(st.text(min_size=1, max_size=6))] = draw(_values)
        else:
            parent[key] = draw(_values)
    return data


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(mutated_presets())
def test_mutated_presets_give_config_or_config_error(data):
    try:
        cfg = config_from_dict(data, source="<mutated>")
    except ConfigError as exc:
        assert exc.problems and all(isinstance(p, str) and p for p in exc.problems)
        assert str(exc).startswith("invalid configuration <mutated>")
        return
    assert isinstance(cfg.system, System)
    K, _ = cfg.system.linearized(stuck=True)
    assert np.all(np.isfinite(K))
    assert cfg.sweep.fmin_hz < cfg.sweep.fmax_hz


def test_examples_in_docs_load():
    """Every ```toml example of docs/config.md is a valid configuration."""
    import re
    from pathlib import Path

    doc = (Path(__file__).parents[1] / "docs" / "config.md").read_text()
    blocks = re.findall(r"```toml\n(.*?)```", doc, re.S)
    assert len(blocks) >= 2
    for text in blocks:
        assert isinstance(load_config(text), Config)


def test_micro_slip_keys_load_and_bad_values_name_the_path():
    p = load_preset("sdof_microslip").system.elements[0].params.axial
    assert (p.sliders, p.spread, p.fs_ratio, p.micro_slip) == (8, 0.6, 0.7, True)
    text = preset_text("sdof_halved").replace(
        "n0 = 10.0", 'n0 = 10.0\nsliders = 2.5\nspread = 1.0\nfs_ratio = "x"')
    with pytest.raises(ConfigError) as err:
        load_config(text)
    problems = err.value.problems
    assert any("`mount.friction.sliders` must be an integer" in q and "2.5" in q
               for q in problems), problems
    assert any("`mount.friction.fs_ratio` must be a number" in q for q in problems)
    text = text.replace("sliders = 2.5", "sliders = 65").replace('fs_ratio = "x"',
                                                                 "fs_ratio = 1.0")
    with pytest.raises(ConfigError) as err:
        load_config(text)
    problems = err.value.problems
    assert any("`mount.friction.sliders` must be an integer from 1 to 64" in q
               for q in problems), problems
    assert any("`mount.friction.spread` must be finite and in [0, 1)" in q
               for q in problems), problems
