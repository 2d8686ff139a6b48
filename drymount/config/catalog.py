"""The presets shipped in ``drymount/presets``: their names, texts and descriptions,
read without building a model (``drymount presets list`` imports no NumPy)."""

from __future__ import annotations

import difflib
from importlib import resources
from pathlib import Path

from drymount.config.errors import ConfigError

__all__ = ["list_presets", "preset_text", "preset_description", "check_spec"]


def list_presets() -> list[str]:
    """Names of the presets shipped in ``drymount/presets`` (sorted)."""
    root = resources.files("drymount.presets")
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def preset_text(name: str) -> str:
    """The TOML text of preset ``name`` (with its comments)."""
    names = list_presets()
    if name not in names:
        close = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
        hint = f" (did you mean `{close[0]}`?)" if close else ""
        raise ConfigError(
            [f"unknown preset `{name}`{hint}; presets: {', '.join(names)}"],
            f"preset:{name}")
    return resources.files("drymount.presets").joinpath(f"{name}.toml").read_text(
        encoding="utf-8")


def preset_description(name: str) -> str:
    """The ``description`` of preset ``name`` as written in its TOML ("" if it has
    none: :func:`drymount.config.load_preset` then describes the system)."""
    import sys

    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    text = preset_text(name)
    try:
        value = tomllib.loads(text).get("description", "")
    except tomllib.TOMLDecodeError:  # a broken package file: load_preset says why
        return ""
    return value if isinstance(value, str) else ""


def check_spec(spec) -> str:
    """``"file"`` if ``spec`` (the CLI's CONFIG argument) names an existing file (a
    file wins), ``"preset"`` if a preset; else a :class:`ConfigError` that suggests
    the closest preset (found without loading NumPy)."""
    spec = str(spec)
    if Path(spec).is_file():
        return "file"
    names = list_presets()
    if spec in names:
        return "preset"
    close = difflib.get_close_matches(spec, names, n=1, cutoff=0.5)
    hint = f"; did you mean preset `{close[0]}`?" if close else ""
    raise ConfigError([f"`{spec}` is neither a file nor a preset{hint} (presets: "
                       f"{', '.join(names)})"], spec)
