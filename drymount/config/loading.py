"""Loading configurations: from a dict, a TOML file or text, a preset."""

from __future__ import annotations

import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from drymount.config.catalog import check_spec, preset_text
from drymount.config.checks import (
    _Checker,
    _type_name,
)
from drymount.config.control import parse_control
from drymount.config.schema import (
    _MODEL_TABLES,
    ALLOWED_KEYS,
    MODELS,
    Config,
    ConfigError,
)
from drymount.config.static import static_load, static_settings
from drymount.config.systems import (
    _build,
    _check_support,
    _settings,
)
from drymount.hbm.static import StaticStatus, static_equilibrium

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def config_from_dict(data, source: str = "<dict>", name: str | None = None) -> Config:
    """Check a parsed TOML document and build its :class:`Config`.

    Parameters
    ----------
    data : dict
        The document, as :func:`tomllib.loads` returns it.
    source : str
        Shown in error messages and kept in ``Config.source``.
    name : str, optional
        Name used when the document has no ``name`` key.

    Raises
    ------
    ConfigError
        Listing every problem found (never another exception for bad input).
    """
    ck = _Checker()
    if not isinstance(data, dict):
        raise ConfigError(
            [f"the document must be a TOML table, got {_type_name(data)}"], source)
    model = ck.choice(data, "model", "", MODELS)
    hints = {}
    if model is not None:
        for key, owner in _MODEL_TABLES.items():
            owners = owner if isinstance(owner, tuple) else (owner,)
            if model not in owners:
                use = {"sdof": "[sdof]", "quarter_car": "[quarter_car]",
                       "rigid_engine": "[rigid_engine]"}[model]
                alt = "[[mounts]]" if model == "rigid_engine" else "[mount]"
                hints[key] = (f"[{key}] belongs to model "
                              f"{' or '.join(repr(o) for o in owners)}; model "
                              f"{model!r} uses {use} and {alt}")
        allowed = [k for k in ALLOWED_KEYS[""] if k not in hints]
    else:
        allowed = ALLOWED_KEYS[""]
    ck.keys(data, "", allowed, hints=hints)
    cfg_name = ck.string(data, "name", "", default=name or "config")
    description = ck.string(data, "description", "", default="")
    build = _build(ck, data, model) if model is not None else None
    settings = _settings(ck, data)
    control = parse_control(ck, data)
    if ck.problems or build is None or settings is None:
        raise ConfigError(ck.problems or ["invalid configuration"], source)
    try:
        with np.errstate(all="raise"), warnings.catch_warnings():
            warnings.simplefilter("error")
            system = build()
            _check_support(ck, system)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError, RuntimeWarning) as exc:
        ck.add(f"the model cannot be built from these values: {exc}")
    if ck.problems:
        raise ConfigError(ck.problems, source)
    static = static_settings(ck, data, system.dof_names)
    load = static_load(static, model, system) if static is not None else None
    _check_working_point(ck, system, load)
    if ck.problems:
        raise ConfigError(ck.problems, source)
    # labels of CSV provenance lines and plot titles: the configuration's name
    system = replace(system, name=cfg_name,
                     description=description or system.description,
                     notes={"config_name": cfg_name, "model": model, "source": source},
                     static_load=load,
                     static_reading=static.reading if static is not None
                     else "lowered")
    sweep, hbm_settings, cosim = settings
    cfg = Config(cfg_name, description, model, system, sweep, hbm_settings, cosim,
                 source, data, static, control)
    if control is not None:
        try:
            control.targets(system)
        except ValueError as exc:
            raise ConfigError([str(exc)], source) from None
    return cfg


def _check_working_point(ck: _Checker, system, load) -> None:
    """A static load needs a static equilibrium of the elastic laws."""
    if load is None:
        return
    with np.errstate(all="ignore"):  # an overflow is refused below
        point = static_equilibrium(system, load)
    finite = all(np.isfinite(a).all() for a in (point.q, point.deflection, point.force))
    if not finite:
        ck.add(f"[static]: the static equilibrium under the load {load.tolist()} is "
               f"not finite (the mounts' elastic laws overflow); check the loads")
    elif point.status is not StaticStatus.CONVERGED:
        ck.add(f"[static]: the mounts' elastic laws find no static equilibrium under "
               f"the load {load.tolist()} ({point.status.value}, largest residual "
               f"{point.residual:.3g}); check the stiffnesses and loads")


def load_config(path_or_text, name: str | None = None) -> Config:
    """Load a configuration from a TOML file or from TOML text.

    Parameters
    ----------
    path_or_text : str or Path
        A :class:`~pathlib.Path`, or a string: TOML text if it contains a newline or
        ``=``, else a file name.
    name : str, optional
        Name used when the document has no ``name`` key (default: the file stem).

    Returns
    -------
    Config

    Raises
    ------
    ConfigError
        For a missing or unreadable file, a TOML syntax error, or any invalid field;
        lists every problem found.

    Examples
    --------
    >>> cfg = load_config('''
    ... model = "sdof"
    ... [sdof]
    ... mass = 70.0
    ... [mount]
    ... law = "linear"
    ... k1 = 91870.0
    ... c = 150.0
    ... [excitation]
    ... kind = "force"
    ... amplitude = 40.0
    ... ''')
    >>> cfg.system.dof_names
    ('x',)
    """
    if isinstance(path_or_text, Path) or (
            isinstance(path_or_text, str) and "\n" not in path_or_text
            and "=" not in path_or_text):
        path = Path(path_or_text)
        source = str(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise ConfigError([f"no such file: {source}"], source) from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError([f"cannot read the file: {exc}"], source) from None
        name = name or path.stem
    elif isinstance(path_or_text, str):
        text, source = path_or_text, "<text>"
    else:
        raise ConfigError([f"expected a file path or TOML text, got "
                           f"{_type_name(path_or_text)}"], "<input>")
    return config_from_dict(parse_toml(text, source), source=source, name=name)


#: Deepest nesting of tables and arrays a configuration may have (the deepest
#: shipped one nests 5: ``[[mounts]]`` > ``axial`` > ``friction`` > an array).
MAX_NESTING = 32


def parse_toml(text: str, source: str) -> dict:
    """The TOML document ``text``; ConfigError naming ``source`` on a syntax error
    or on tables and arrays nested deeper than :data:`MAX_NESTING`."""
    allowed = (f"at most {MAX_NESTING} levels are allowed (the shipped configurations "
               f"nest 5)")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError([f"TOML syntax error: {exc}"], source) from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise ConfigError([f"arrays or inline tables nested hundreds of levels deep; "
                           f"{allowed}"], source) from None
    depth = nesting_depth(data)  # dotted keys and [a.b.c] headers: no recursion
    if depth > MAX_NESTING:
        raise ConfigError([f"tables and arrays nested {depth} levels deep; {allowed}"],
                          source)
    return data


def nesting_depth(value) -> int:
    """Levels of tables and arrays in ``value`` (0 for a scalar), without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        node, level = stack.pop()
        if isinstance(node, dict):
            node = node.values()
        elif not isinstance(node, list):
            deepest = max(deepest, level)
            continue
        deepest = max(deepest, level + 1)
        stack.extend((child, level + 1) for child in node)
    return deepest


# ======================================================================================
# Presets
# ======================================================================================


def load_preset(name: str) -> Config:
    """The :class:`Config` of preset ``name`` (see :func:`list_presets`)."""
    data = parse_toml(preset_text(name), f"preset:{name}")
    return config_from_dict(data, source=f"preset:{name}", name=name)


def resolve_config(spec) -> Config:
    """A configuration from a file path or a preset name (the CLI's CONFIG argument).

    An existing file wins; else a preset of that name; else a :class:`ConfigError`
    that suggests the closest preset.
    """
    spec = str(spec)
    if check_spec(spec) == "file":
        return load_config(Path(spec))
    return load_preset(spec)
