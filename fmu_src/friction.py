"""The friction-element contract of a mount axis and its registry.

Every friction element of an axis (``AxisParameters.friction_kind``) is one
:class:`FrictionElement`, declared once in its own module and registered in
:mod:`fmu_src.friction_elements`. The declaration is all a consumer reads:

- ``fields``: the axis parameters the element reads (:class:`Field`: name, FMI type,
  unit, default, rule, description). ``AxisParameters``, the FMU's parameter rows
  (:mod:`fmu_src.interface`), the configuration's friction table and its ``--set``
  paths are generated from them. Elements may share a field (``kf``, ``mu``, ``n0``)
  if they declare it alike.
- the internal state: ``state_size(p)`` floats (a state of size 1 is a float, a
  larger one a tuple of floats), ``start(p, w)`` the element relaxed at deflection
  ``w``, ``position(state)`` the one number the FMU shows as ``w_<axis>`` (setting it
  relaxes the element there: ``position(start(p, w)) == w``);
- ``rate_dependent``: whether the force depends on the deflection rate or the time
  step (the HBM then gives its generic march the velocity samples and the step);
- ``bind(p)``: the step of the element with the parameters of axis ``p``:
  ``step(state, u, v, n, dt) -> ElementStep`` (force, new state, dF/du, dF/dv,
  slipping, dissipated energy) for the deflection ``u`` (m) and rate ``v`` (m/s) at the
  end of an increment of ``dt`` seconds from the committed ``state``, under the
  normal-force input ``n`` (N; ignored unless ``uses_normal_input``). It commits
  nothing.

and a few views of the element for the static working point (``relaxed_force``), the
linearised stiffness (``stuck_stiffness``), the FMU's normal-force outputs
(``normal_forces``) and checks that go beyond one field's rule (``problems``).

The FMU's integer ``<axis>_friction_kind`` is the position of the element in the
registry (:func:`friction_kind_code`); append new elements at the end. Standard
library only: this module ships inside the FMU.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

__all__ = ["Field", "ElementStep", "FrictionElement", "FRICTION_ELEMENTS",
           "FRICTION_KINDS", "register_element", "friction_kind_code",
           "friction_kind_name", "element_fields", "finite_rule", "flat_state"]


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and not math.isnan(x)


def finite_rule(rule: str) -> Callable[[Any], bool]:
    """The check of a finite number against ``rule`` (``">= 0"``, ``"> 0"``)."""
    if rule == "> 0":
        return lambda x: _finite(x) and x > 0
    if rule == ">= 0":
        return lambda x: _finite(x) and x >= 0
    raise ValueError(f"unknown rule {rule!r}")


@dataclass(frozen=True)
class Field:
    """One parameter an element reads, as an axis field (``AxisParameters.<name>``),
    an FMU parameter ``<axis>_<name>`` and a key of a configuration's friction table.

    Attributes
    ----------
    name : str
    type : str
        FMI type: ``"Real"`` or ``"Integer"``.
    unit : str or None
        FMI unit (a key of ``fmu_src.interface.BASE_UNITS``); None for integers.
    default : float or int
    rule : str
        What is allowed, as written in messages (``"finite and > 0"``).
    check : callable
        ``check(value) -> bool``: whether ``value`` satisfies ``rule``.
    description : str
        One line for the FMU's model description and the docs tables.
    required : bool
        Whether a configuration's friction table must give it (else ``default``).
    always : bool
        Checked on every axis, with ``rule_off`` / ``check_off`` where friction is
        off or another element is chosen (the fields every axis has carried since
        the first FMU; other fields are checked only where their element is on).
    rule_off, check_off : str, callable or None
        The rule of an ``always`` field off its element (None: ``rule``).
    """

    name: str
    type: str
    unit: str | None
    default: float | int
    rule: str
    check: Callable[[Any], bool]
    description: str
    required: bool = False
    always: bool = False
    rule_off: str | None = None
    check_off: Callable[[Any], bool] | None = None

    def problem(self, value, prefix: str = "", on: bool = True) -> str | None:
        """The message naming field, value and rule if ``value`` breaks the rule
        (``on``: the field's element is the axis's, with friction on)."""
        check, rule = self.check, self.rule
        if not on and self.check_off is not None:
            check, rule = self.check_off, self.rule_off
        if check(value):
            return None
        return f"`{prefix}{self.name}` must be {rule}, got {value!r}"


class ElementStep(NamedTuple):
    """One increment of a friction element (:attr:`FrictionElement.bind`).

    Attributes
    ----------
    force : float
        Friction force along the axis at the end of the increment, N.
    state : float or tuple
        The element's state after the increment (commit it to go on).
    df_du, df_dv : float
        Consistent tangents dF/du (N/m) and dF/dv (N s/m).
    slipping : bool
        Whether the contact slips.
    dissipated : float
        Energy dissipated in the increment, J (>= 0).
    """

    force: float
    state: Any
    df_du: float
    df_dv: float
    slipping: bool
    dissipated: float


def _no_problems(p, prefix: str) -> list[str]:
    return []


def _no_fast_form(p) -> None:
    return None


def _no_static_force(u: float, p) -> tuple[float, float]:
    return 0.0, 0.0


def _no_slots(p) -> tuple[int, ...]:
    return ()


def flat_state(state) -> tuple[float, ...]:
    """The floats of a friction state (a float or a tuple of floats), in order."""
    return (float(state),) if isinstance(state, (int, float)) else tuple(
        float(x) for x in state)


@dataclass(frozen=True)
class FrictionElement:
    """One friction element of a mount axis (see the module docstring).

    Attributes
    ----------
    name : str
        The value of ``AxisParameters.friction_kind`` and of a friction table's
        ``kind``.
    summary : str
        One line for documentation and messages.
    fields : tuple of Field
        The axis parameters it reads, in FMU order.
    bind : callable
        ``bind(p) -> step``, ``step(state, u, v, n, dt) -> ElementStep``.
    state_size : callable
        ``state_size(p) -> int`` (floats of the state).
    start : callable
        ``start(p, w) -> state``: relaxed at deflection ``w`` (m).
    position : callable
        ``position(state) -> float`` (m), the FMU's ``w_<axis>``.
    stuck_stiffness : callable
        ``stuck_stiffness(p) -> float``: its stiffest tangent, N/m (linearised
        start, step-size bounds).
    normal_forces : callable
        ``normal_forces(p, state, n) -> (N, N2)``: the FMU's outputs N_ and N2_.
    uses_normal_input : bool
        Whether the input ``n_<axis>`` scales its force (semi-active control acts
        on it); its slip force is then ``mu * max(n, 0)``.
    rate_dependent : bool
        Whether the force depends on ``v`` or ``dt`` (not only on the path of u).
    problems : callable
        ``problems(p, prefix) -> list of str``: checks beyond one field's rule (run
        when every field is valid).
    relaxed_force : callable
        ``relaxed_force(u, p) -> (F, dF/du)`` at rest at ``u`` with the element
        relaxed (static working point); default: none.
    fast_form : callable
        ``fast_form(p) -> str or None``: the name of a faster implementation of
        the element with these parameters that a consumer may hold (the HBM's
        vectorised AFT forms, the batched harness's vector law); None: consumers
        march the step.
    c_port : str or None
        The name of its ``const ml_element`` in ``fmu_src/native/`` (the C port the
        native FMU is built with; None: none, the native build refuses the element).
    slider_slots : callable
        ``slider_slots(p) -> tuple of int``: the indices in the flat state (the
        ``state_size(p)`` floats) of the sliders a master may set to start from
        (:meth:`with_sliders`; the FMU's ``w1_<axis>``, ``w2_<axis>`` are the first
        two; the C port's ``slider_index``); default: none.
    params : callable or None
        ``params(p)``: the element's own parameter object, built once per checked
        axis and kept as ``p.element_params`` (None: the axis itself).
    """

    name: str
    summary: str
    fields: tuple[Field, ...]
    bind: Callable
    state_size: Callable
    start: Callable
    position: Callable
    stuck_stiffness: Callable
    normal_forces: Callable
    uses_normal_input: bool = True
    rate_dependent: bool = False
    problems: Callable = _no_problems
    relaxed_force: Callable = _no_static_force
    params: Callable | None = None
    fast_form: Callable = _no_fast_form
    c_port: str | None = None
    slider_slots: Callable = _no_slots

    def slider_values(self, p, state) -> tuple[float, ...]:
        """The positions (m, the element's own coordinates) of the settable sliders
        of ``state`` (:attr:`slider_slots`), in slot order."""
        flat = flat_state(state)
        return tuple(flat[i] for i in self.slider_slots(p))

    def with_sliders(self, p, state, values) -> Any:
        """``state`` with its sliders started at ``values`` (``{slot: position}``,
        m; slot 0 is the first of :attr:`slider_slots`): the general "start with
        these slider positions" of every element. ValueError naming the slot and
        the settable ones if the element has no such slider."""
        slots = self.slider_slots(p)
        flat = list(flat_state(state))
        for slot, value in dict(values).items():
            if isinstance(slot, bool) or not isinstance(slot, int) \
                    or not 0 <= slot < len(slots):
                raise ValueError(f"slider {slot!r}: the {self.name} element has "
                                 f"{len(slots)} settable slider(s) (slots 0.."
                                 f"{len(slots) - 1})" if slots else
                                 f"slider {slot!r}: the {self.name} element has no "
                                 f"settable slider")
            if not _finite(value):
                raise ValueError(f"slider {slot}: the position must be finite, got "
                                 f"{value!r}")
            flat[slots[slot]] = float(value)
        out = self.from_flat(p, flat)
        return out

    def field_problems(self, p, prefix: str = "") -> list[str]:
        """Every rule broken by the element's fields of ``p`` that are not checked
        on every axis (``Field.always``); then, if none is, its own
        :attr:`problems`."""
        out = [m for f in self.fields if not f.always
               and (m := f.problem(getattr(p, f.name), prefix)) is not None]
        return out or self.problems(p, prefix)

    def from_flat(self, p, values) -> Any:
        """A state of axis ``p`` from a flat sequence of floats (a restored FMU
        state), or None if its length is not ``state_size(p)``."""
        values = tuple(float(x) for x in values)
        n = self.state_size(p)
        if len(values) != n:
            return None
        if n == 1:
            return values[0]
        cls = type(self.start(p, 0.0))   # a NamedTuple state keeps its class
        return values if cls is tuple else cls(*values)


#: The registered friction elements by name, in FMU code order.
FRICTION_ELEMENTS: dict[str, FrictionElement] = {}
#: Names of the friction elements, in FMU code order.
FRICTION_KINDS: tuple[str, ...] = ()
_FIELDS: dict[str, Field] = {}


def register_element(element: FrictionElement) -> FrictionElement:
    """Add ``element`` to :data:`FRICTION_ELEMENTS` (its FMU code is the next
    integer). A field it shares with an element registered before must be declared
    alike (type, unit, default)."""
    global FRICTION_KINDS
    if element.name in FRICTION_ELEMENTS:
        raise ValueError(f"friction element {element.name!r} is registered already")
    for f in element.fields:
        old = _FIELDS.get(f.name)
        if old is not None and (old.type, old.unit, old.default) != (
                f.type, f.unit, f.default):
            raise ValueError(f"field {f.name!r} of friction element {element.name!r} "
                             f"differs from the one already registered")
    for f in element.fields:
        _FIELDS.setdefault(f.name, f)
    FRICTION_ELEMENTS[element.name] = element
    FRICTION_KINDS = tuple(FRICTION_ELEMENTS)
    return element


def element_fields() -> tuple[Field, ...]:
    """Every field of every registered element, once, in registration order."""
    return tuple(_FIELDS.values())


def friction_kind_code(name: str) -> int:
    """The FMU's integer ``<axis>_friction_kind`` of ``name``."""
    return FRICTION_KINDS.index(name)


def friction_kind_name(code) -> str | None:
    """The friction kind of the FMU's integer code; None if invalid."""
    if isinstance(code, int) and not isinstance(code, bool) \
            and 0 <= code < len(FRICTION_KINDS):
        return FRICTION_KINDS[code]
    return None
