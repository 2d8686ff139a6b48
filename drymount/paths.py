"""Config fields by path: ``mounts[2].axial.friction.n0``, ``mounts[*].position[2]``.

A *field path* addresses a value of the parsed TOML document of a configuration,
before it becomes a :class:`drymount.config.Config`: keys separated by ``.``, array
items by ``[i]`` (from 0) and every item of an array by ``[*]``. Changing the document
and then checking it with :func:`drymount.config.config_from_dict` checks an override
exactly like a value typed into the file (field path, value, what is allowed).

Used by ``--set PATH=VALUE`` on every command that takes a configuration and by the
design variables of ``[design]`` (:mod:`drymount.design`).

Public: :class:`FieldPath`, :class:`PathError`, :func:`parse_path`, :func:`expand`,
:func:`get_value`, :func:`set_value`, :func:`parse_assignment`,
:func:`apply_overrides`, :func:`load_with_overrides`, :func:`override_config`.
"""

from __future__ import annotations

import copy
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["WILDCARD", "FieldPath", "PathError", "parse_path", "expand", "get_value",
           "set_value", "format_parts", "parse_assignment", "apply_overrides",
           "load_with_overrides", "override_config"]

#: The ``[*]`` part of a path: every item of an array.
WILDCARD = "*"

_KEY = r"[A-Za-z_][A-Za-z0-9_]*"
_SEGMENT = re.compile(rf"({_KEY})((?:\[(?:\d+|\*)\])*)$")
_INDEX = re.compile(r"\[(\d+|\*)\]")


class PathError(ValueError):
    """A path that does not parse or does not lead to a field of the document."""


@dataclass(frozen=True)
class FieldPath:
    """A parsed field path.

    Attributes
    ----------
    text : str
        The path as written, e.g. ``"mounts[*].axial.friction.n0"``.
    parts : tuple
        Keys (str), indices (int) and :data:`WILDCARD`, in order.
    """

    text: str
    parts: tuple

    @property
    def has_wildcard(self) -> bool:
        return WILDCARD in self.parts

    def __str__(self) -> str:
        return self.text


def format_parts(parts) -> str:
    """The path text of concrete ``parts`` (``("mounts", 2, "axial")`` ->
    ``mounts[2].axial``)."""
    out = ""
    for p in parts:
        if isinstance(p, int) or p == WILDCARD:
            out += f"[{p}]"
        else:
            out += f".{p}" if out else p
    return out


def parse_path(text) -> FieldPath:
    """Parse ``text`` into a :class:`FieldPath`; :class:`PathError` if malformed."""
    if not isinstance(text, str) or not text.strip():
        raise PathError(f"a field path must be a non-empty string such as "
                        f"`mounts[2].axial.friction.n0`, got {text!r}")
    parts: list = []
    for seg in text.strip().split("."):
        m = _SEGMENT.match(seg)
        if m is None:
            raise PathError(
                f"`{text}` is not a field path: part {seg!r} must be a key "
                f"(letters, digits, _) optionally followed by [index] or [*], e.g. "
                f"`mounts[2].axial.friction.n0` or `mounts[*].position[2]`")
        parts.append(m.group(1))
        for idx in _INDEX.findall(m.group(2)):
            parts.append(WILDCARD if idx == WILDCARD else int(idx))
    return FieldPath(text.strip(), tuple(parts))


def _step(node, part, done: tuple, create: bool):
    """The child ``part`` of ``node`` (``done`` is the path so far), or PathError."""
    where = format_parts(done) or "the document"
    if isinstance(part, int):
        if not isinstance(node, list):
            raise PathError(f"`{where}` is not an array (it is {_kind(node)}), so "
                            f"`[{part}]` cannot index it")
        if part >= len(node):
            have = (f"indices 0-{len(node) - 1}" if node else "no entries")
            raise PathError(f"`{format_parts(done + (part,))}` does not exist: "
                            f"`{where}` has {len(node)} entries ({have})")
        return node[part]
    if not isinstance(node, dict):
        raise PathError(f"`{where}` is {_kind(node)}, not a table, so it has no key "
                        f"`{part}`")
    if part not in node:
        if not create:
            keys = ", ".join(node) or "none"
            raise PathError(f"`{format_parts(done + (part,))}` does not exist "
                            f"(keys of `{where}`: {keys})")
        node[part] = {}
    return node[part]


def _kind(v) -> str:
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return "an array"
    return f"the value {v!r}"


def expand(doc: dict, path: FieldPath) -> list[tuple]:
    """The concrete parts of every field ``path`` addresses in ``doc``.

    ``[*]`` expands to the items of the array it follows that have the rest of the
    path (up to the last key, which may be new): ``mounts[*].axial.friction.n0``
    addresses the axial friction elements there are. Raises :class:`PathError` when
    nothing matches. A path without ``[*]`` is returned as it is: setting it creates
    missing tables (:func:`set_value`).
    """
    if not path.has_wildcard:
        return [path.parts]
    prefixes: list[tuple] = [()]
    nodes = [doc]
    first_error = None
    for k, part in enumerate(path.parts):
        last = k == len(path.parts) - 1
        nxt_p, nxt_n = [], []
        for pre, node in zip(prefixes, nodes, strict=True):
            if part == WILDCARD:
                if not isinstance(node, list):
                    raise PathError(f"`{format_parts(pre) or 'the document'}` is "
                                    f"{_kind(node)}, not an array, so `[*]` cannot "
                                    f"follow it (in `{path}`)")
                nxt_p += [pre + (i,) for i in range(len(node))]
                nxt_n += list(node)
            elif last and isinstance(part, str) and isinstance(node, dict):
                nxt_p.append(pre + (part,))
                nxt_n.append(node.get(part))
            else:
                try:
                    nxt_n.append(_step(node, part, pre, create=False))
                    nxt_p.append(pre + (part,))
                except PathError as exc:  # this item of a [*] lacks the field
                    first_error = first_error or exc
        prefixes, nodes = nxt_p, nxt_n
    if not prefixes:
        why = f": {first_error}" if first_error else " (an array it expands is empty)"
        raise PathError(f"`{path}` matches no field{why}")
    return prefixes


def get_value(doc: dict, parts: Sequence):
    """The value at concrete ``parts`` of ``doc`` (PathError if absent)."""
    node = doc
    for k, part in enumerate(parts):
        node = _step(node, part, tuple(parts[:k]), create=False)
    return node


def set_value(doc: dict, parts: Sequence, value) -> None:
    """Set the value at concrete ``parts`` of ``doc`` in place.

    Missing tables on the way are created (``mount.friction.n0`` on a mount without
    friction adds a ``[mount.friction]`` table; the configuration check then asks for
    its other fields); missing array items are an error.
    """
    if not parts:
        raise PathError("an empty path addresses the whole document")
    node = doc
    for k, part in enumerate(parts[:-1]):
        node = _step(node, part, tuple(parts[:k]), create=True)
    last = parts[-1]
    if isinstance(last, int):
        _step(node, last, tuple(parts[:-1]), create=False)  # range check
        node[last] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise PathError(f"`{format_parts(parts[:-1])}` is {_kind(node)}, not a table, "
                        f"so it has no key `{last}`")


def parse_value(text: str):
    """A ``--set`` value: a TOML value (``180``, ``1e3``, ``[0, 0.1, 0]``,
    ``"native"``), or a bare word taken as a string (``native``)."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except RecursionError:  # arrays or inline tables nested thousands deep
        raise PathError(f"value {text[:40]!r}... nests arrays or tables hundreds of "
                        f"levels deep; a configuration value nests a few (the "
                        f"configuration at most 32 levels)") from None
    except tomllib.TOMLDecodeError:
        if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.:/-]*", text.strip()):
            return text.strip()
        raise PathError(f"value {text!r} is not a TOML value (a number such as 180 or "
                        f"1.5e3, a string, true/false, or an array such as "
                        f"[0.0, 0.1, 0.0])") from None


def parse_assignment(text: str) -> tuple[FieldPath, object]:
    """``"PATH=VALUE"`` -> (FieldPath, value); PathError if malformed."""
    if not isinstance(text, str) or "=" not in text:
        raise PathError(f"expected PATH=VALUE (e.g. mounts[2].axial.friction.n0=180), "
                        f"got {text!r}")
    path, _, value = text.partition("=")
    return parse_path(path), parse_value(value)


def apply_overrides(doc: dict, overrides: Sequence) -> tuple[dict, list[str]]:
    """A deep copy of ``doc`` with every override applied, and the problems found.

    Parameters
    ----------
    doc : dict
        The parsed TOML document (left unchanged).
    overrides : sequence
        ``"PATH=VALUE"`` strings or ``(path, value)`` pairs, applied in order.

    Returns
    -------
    (dict, list of str)
        The new document and one message per override that could not be applied
        (naming the override and why); values themselves are checked later by the
        configuration check.
    """
    new = copy.deepcopy(doc)
    problems = []
    for ov in overrides:
        label = ov if isinstance(ov, str) else f"{ov[0]}={ov[1]!r}"
        try:
            if isinstance(ov, str):
                path, value = parse_assignment(ov)
            else:
                path, value = (ov[0] if isinstance(ov[0], FieldPath)
                               else parse_path(ov[0])), ov[1]
            for parts in expand(new, path):
                set_value(new, parts, copy.deepcopy(value))
        except PathError as exc:
            problems.append(f"--set {label}: {exc}")
    return new, problems


def load_with_overrides(spec, overrides: Sequence = ()):
    """The configuration of ``spec`` (file or preset name) with ``overrides`` applied.

    The overridden document goes through the same check as a file
    (:func:`drymount.config.config_from_dict`); its ``source`` names the overrides.

    Raises
    ------
    drymount.config.ConfigError
        A bad path (every one is listed) or an invalid resulting configuration.
    """
    from drymount.config import resolve_config

    return override_config(resolve_config(spec), overrides)


def override_config(cfg, overrides: Sequence = ()):
    """A checked :class:`drymount.config.Config`: ``cfg`` with ``overrides`` applied
    (``"PATH=VALUE"`` strings or ``(path, value)`` pairs); ``cfg`` itself is left
    unchanged. Raises :class:`drymount.config.ConfigError` like
    :func:`load_with_overrides`."""
    from drymount.config import ConfigError, config_from_dict

    if not overrides:
        return cfg
    data, problems = apply_overrides(cfg.data, overrides)
    source = f"{cfg.source} with --set " + " ".join(
        o if isinstance(o, str) else f"{o[0]}={o[1]!r}" for o in overrides)
    try:
        out = config_from_dict(data, source=source, name=cfg.name)
    except ConfigError as exc:  # every problem at once: the paths' and the values'
        raise ConfigError(problems + exc.problems, source) from None
    if problems:
        raise ConfigError(problems, source)
    return out
