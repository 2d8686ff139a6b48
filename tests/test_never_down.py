"""Issue 25, the rest: extreme inputs refused with exit 2 naming the file, option
or field and what is allowed (deep TOML, huge loads, huge design grids, special
output files), full disks named, large fits decimated."""

from __future__ import annotations

import pytest

from drymount import cli
from drymount.config import ConfigError, load_config
from drymount.config.loading import nesting_depth
from drymount.paths import MAX_NESTING


def run(argv, capsys):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------------------ deep TOML

DEEP = 5000


@pytest.mark.parametrize("shape", ["array", "inline_table", "dotted_key", "header"])
def test_a_toml_nested_5000_deep_is_exit_2_naming_the_file(tmp_path, capsys, shape):
    text = {"array": "x = " + "[" * DEEP + "]" * DEEP,
            "inline_table": "x = " + "{a = " * DEEP + "1" + "}" * DEEP,
            "dotted_key": ".".join(["a"] * DEEP) + " = 1",
            "header": "[" + ".".join(["a"] * DEEP) + "]\nb = 1"}[shape]
    path = tmp_path / "deep.toml"
    path.write_text('model = "sdof"\n' + text + "\n")
    code, _, err = run(["static", path], capsys)
    assert code == 2, err
    assert str(path) in err and f"at most {MAX_NESTING} levels" in err, err
    assert "RecursionError" not in err


def test_nesting_depth_counts_tables_and_arrays():
    assert nesting_depth(1.0) == 0
    assert nesting_depth({"a": 1}) == 1
    assert nesting_depth({"a": {"b": [1, [2]]}}) == 4
    assert nesting_depth({"a": [], "b": {}}) == 2


def test_the_nesting_limit_is_not_reached_by_a_real_configuration(tmp_path):
    """MAX_NESTING levels load (the error is about the fields, not the nesting);
    one more is refused for its nesting."""
    def doc(levels):  # the document itself is one level
        return 'model = "sdof"\n' + "x = " + "[" * (levels - 1) + "]" * (levels - 1)
    with pytest.raises(ConfigError) as ok:
        load_config(doc(MAX_NESTING))
    assert "nested" not in str(ok.value)
    with pytest.raises(ConfigError, match=f"nested {MAX_NESTING + 1} levels deep"):
        load_config(doc(MAX_NESTING + 1))


def test_a_set_value_nested_5000_deep_is_exit_2(capsys):
    code, _, err = run(["static", "sdof_halved", "--set",
                        "mount.c=" + "[" * DEEP + "]" * DEEP], capsys)
    assert code == 2, err
    assert "mount.c" in err and f"at most {MAX_NESTING} levels" in err, err[-500:]
