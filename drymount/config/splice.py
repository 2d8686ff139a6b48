"""A configuration's ``[mount]`` table replaced by another one, in TOML text.

``drymount presets export NAME PATH --mount FILE`` uses it to put a fitted mount
(``mount.toml`` of ``drymount fit``) into a preset: the preset's ``[mount]`` table and
its sub-tables (``[mount.friction]``, ...) are replaced by the file's, every other line
(comments included) is kept, and the result is checked as a whole configuration.
"""

from __future__ import annotations

import re
from pathlib import Path

from drymount.config.loading import load_config, parse_toml
from drymount.config.schema import ConfigError

#: a table header line ``[mount]`` or ``[mount.friction]`` (not ``[[mounts]]``)
_MOUNT_HEADER = re.compile(r"^\[mount(\.[^\]\[]+)?\]\s*(#.*)?$")
_ANY_HEADER = re.compile(r"^\[")
_COMMENT_OR_BLANK = re.compile(r"^\s*(#.*)?$")


def with_mount(text: str, mount_path: Path) -> str:
    """``text`` (a configuration) with its ``[mount]`` tables replaced by those of the
    file ``mount_path`` (TOML holding only a ``[mount]`` table).

    Raises ConfigError if the file cannot be read or has keys besides ``[mount]``, if
    ``text`` has no ``[mount]`` table (the multi-mount models use ``[[mounts]]``), or if
    the result is not a valid configuration (every problem listed, as ``load_config``
    does).
    """
    mount_source = str(mount_path)
    try:
        mount_text = Path(mount_path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError([f"--mount: cannot read the file: {exc}"],
                          mount_source) from None
    data = parse_toml(mount_text, mount_source)
    extra = sorted(k for k in data if k != "mount")
    if not isinstance(data.get("mount"), dict) or extra:
        raise ConfigError([f"--mount must hold a [mount] table and nothing else "
                           f"(`drymount fit` writes one), got top-level keys "
                           f"{', '.join(sorted(data)) or 'none'}"], mount_source)
    lines = text.splitlines()
    start, end = _mount_span(lines)
    gap = [""] if end < len(lines) and lines[end].strip() else []
    spliced = lines[:start] + mount_text.strip("\n").splitlines() + gap + lines[end:]
    result = "\n".join(spliced) + "\n"
    try:
        load_config(result)
    except ConfigError as exc:  # every problem, named for the file they came from
        raise ConfigError(exc.problems, f"(the configuration with the [mount] of "
                                        f"{mount_source})") from None
    return result


def _mount_span(lines: list[str]) -> tuple[int, int]:
    """Lines ``[start, end)`` of the ``[mount]`` tables; the comments and blank lines
    just above the next table header stay with that table."""
    heads = [i for i, line in enumerate(lines) if _ANY_HEADER.match(line)]
    mine = [i for i in heads if _MOUNT_HEADER.match(lines[i].strip())]
    if not mine:
        raise ConfigError(["the configuration has no [mount] table (a multi-mount "
                           "model lists [[mounts]]: edit the mount you mean by hand "
                           "or use --set)"], "--mount")
    after = [i for i in heads if i > mine[-1] and i not in mine]
    if any(mine[0] < i < mine[-1] for i in heads if i not in mine):
        raise ConfigError(["the [mount] tables of the configuration are not "
                           "consecutive; cannot replace them"], "--mount")
    end = after[0] if after else len(lines)
    while end > mine[-1] + 1 and _COMMENT_OR_BLANK.match(lines[end - 1]):
        end -= 1
    start = mine[0]
    while start > 0 and lines[start - 1].lstrip().startswith("#"):
        start -= 1  # the [mount] table's own comment goes with it
    return start, end
