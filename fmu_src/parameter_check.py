"""The FrictionMount FMU's parameters, checked: from the values of its
``<axis>_<field>`` variables to one :class:`~mount_law.AxisParameters` per axis, or
every problem of every axis named by its FMU variable (the integer codes of
``<axis>_law`` and ``<axis>_friction_kind`` with the codes allowed). Standard library
only.
"""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace

from .interface import ALL_PARAMETER_FIELDS
from .mount_law import (AXES, FRICTION_KINDS, LAWS, AxisParameters,
                        friction_kind_code, friction_kind_name, law_code, law_name)

__all__ = ["ParameterError", "checked_axes"]

_PARAMETER_NAMES = tuple(name for name, *_ in ALL_PARAMETER_FIELDS)


class ParameterError(ValueError):
    """The parameters are invalid; the message names every problem."""


def checked_axes(value_of: Callable[[str], object]) -> list[AxisParameters]:
    """The checked parameters of each axis in ``AXES`` order, from ``value_of(name)``,
    the value of the FMU variable ``name``.

    Raises
    ------
    ParameterError
        ``"invalid parameters: "`` and every problem, ``; ``-separated.
    """
    problems, axes = [], []
    for axis in AXES:
        values = {name: value_of(f"{axis}_{name}") for name in _PARAMETER_NAMES}
        problems += _decode(values, axis, "law", law_name, law_code, LAWS)
        problems += _decode(values, axis, "friction_kind", friction_kind_name,
                            friction_kind_code, FRICTION_KINDS)
        # problems() only reads attributes: run it on the raw values so that every
        # problem of every axis is reported with the FMU variable name.
        problems += AxisParameters.problems(SimpleNamespace(**values), f"{axis}_")
        if not problems:
            axes.append(AxisParameters(**values))
    if problems:
        raise ParameterError("invalid parameters: " + "; ".join(problems))
    return axes


def _decode(values: dict, axis: str, field: str, name_of, code_of, names) -> list[str]:
    """Replace the integer code ``values[field]`` by its name (the first name where
    it is unknown, so that the other checks still run); the problem, if any."""
    code = values[field]
    values[field] = name_of(code)
    if values[field] is not None:
        return []
    values[field] = names[0]
    allowed = ", ".join(f"{code_of(name)} = {name}" for name in names)
    return [f"`{axis}_{field}` must be one of {allowed}, got {code!r}"]
