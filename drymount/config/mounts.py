"""The mount tables of a configuration -> ``AxisParameters`` / ``MountParameters``
(the laws' parameters and units come from ``fmu_src``)."""

from __future__ import annotations

import difflib
import math
from dataclasses import fields, replace

import numpy as np

from drymount.fmu_src.friction import FRICTION_ELEMENTS, FRICTION_KINDS, element_fields
from drymount.fmu_src.interface import parameter_unit
from drymount.fmu_src.linear_branches import HYDRAULIC_FIELDS
from drymount.fmu_src.mount_law import (AXES, ELASTIC_LAWS, LAWS, MAX_MAXWELL,
                                        AxisParameters, MountParameters)
from drymount.config.checks import (
    _as_float,
    _Checker,
    _join,
    _show,
    _type_name,
)
from drymount.config.schema import (
    ALLOWED_KEYS,
    ConfigError,
    _AXIS_LAW_KEYS,
    _FRICTION_KEYS,
)


# -- mount law ------------------------------------------------------------


def readable_unit(fmi_unit: str | None) -> str:
    """An FMU unit name (``fmu_src.interface``) as written in messages and
    docs/config.md: ``N/m3`` -> ``N/m^3``, ``N.s/m`` -> ``N s/m``, ``1`` -> ``[-]``."""
    if fmi_unit in (None, "1"):
        return "[-]"
    return fmi_unit.replace("m3", "m^3").replace(".", " ")


def _unchecked_axis(**kw) -> AxisParameters:
    """An AxisParameters without its ``__post_init__`` check (to call ``problems``)."""
    obj = object.__new__(AxisParameters)
    defaults = AxisParameters.__dataclass_fields__
    for f in fields(AxisParameters):
        object.__setattr__(obj, f.name, kw.get(f.name, defaults[f.name].default))
    return obj


def _law_problems(axis: AxisParameters, path: str) -> list[str]:
    """``AxisParameters.problems``, friction fields under ``<path>.friction``."""
    prefix = path + "."
    out = []
    for msg in axis.problems(prefix):
        msg = msg.replace(f"`{prefix}friction_kind`", f"`{prefix}friction.kind`")
        for name in _FRICTION_KEYS:
            msg = msg.replace(f"`{prefix}{name}`", f"`{prefix}friction.{name}`")
        out.append(msg)
    return out


#: Hints for keys a friction table of no element has.
_FRICTION_HINTS = {
    "normal_force": "the normal force is `n0`", "N": "the normal force is `n0`",
    "fs": "give the normal force `n0` and `mu` (Fs = mu * n0)",
    "theta": "the angle is `theta_deg` (degrees)",
    "enabled": "the table's presence switches friction on; remove the table to "
               "switch it off"}


def _kinds_text() -> str:
    return "; ".join(f"{name!r}: {el.summary}"
                     for name, el in FRICTION_ELEMENTS.items())


def _friction(ck: _Checker, data: dict, path: str) -> dict | None:
    """The friction sub-table of an axis -> AxisParameters keywords, or None (off).

    Its ``kind`` (default: the first registered element) names the element; the
    other keys are that element's fields (``fmu_src.friction.Field``): the required
    ones must be given, the rest default; their ranges are checked by
    ``AxisParameters``."""
    if "friction" not in data:
        return {"friction": False}
    p = _join(path, "friction")
    fr = data["friction"]
    if not isinstance(fr, dict):
        ck.add(f"`{p}` must be a table with the fields of a friction element (remove "
               f"it for a mount without friction), got {_type_name(fr)} {_show(fr)}")
        return None
    kind = fr.get("kind", FRICTION_KINDS[0])
    el = FRICTION_ELEMENTS.get(kind) if isinstance(kind, str) else None
    if el is None:
        ck.add(f"`{p}.kind` must be one of {', '.join(map(repr, FRICTION_KINDS))} "
               f"({_kinds_text()}), got {_type_name(kind)} {_show(kind)}")
        return None
    mine = tuple(f.name for f in el.fields)
    owners = {f.name: [n for n, e in FRICTION_ELEMENTS.items() if f in e.fields]
              for f in element_fields() if f.name not in mine}
    ck.keys(fr, p, ("kind", *mine), hints={
        **{k: f"`{k}` belongs to the friction element "
              f"{' or '.join(repr(n) for n in names)} (`kind`), not to {kind!r}"
           for k, names in owners.items()}, **_FRICTION_HINTS})
    kw = {"friction": True, "friction_kind": kind}
    ok = True
    for f in el.fields:
        if f.name in fr:
            ok = _field_into(ck, fr, p, f, kw) and ok
        elif f.required:
            unit = readable_unit(f.unit)
            ck.add(f"`{p}.{f.name}` is missing: the friction element {kind!r} needs "
                   f"{f.description} (a number in {unit}, {f.rule})")
            ok = False
    if not ok:
        return None
    if el.uses_normal_input:  # Fs = mu * n0 = 0: the element carries no force
        for name in ("n0", "mu"):
            x = kw.get(name)
            if x is not None and math.isfinite(x) and x == 0:
                unit = readable_unit(parameter_unit(name))
                ck.add(f"`{p}.{name}` must be > 0 in a friction table ({unit}), got "
                       f"{_show(fr[name])}: with mu * n0 = 0 the element does "
                       f"nothing; remove the [{p}] table instead")
    return kw


def _field_into(ck: _Checker, fr: dict, p: str, f, kw: dict) -> bool:
    """``kw[f.name]`` = the value of field ``f`` in table ``p`` (an integer for an
    Integer field, else a number); False (and the problem) if it is not one."""
    if f.type != "Integer":
        return _number_into(ck, fr, p, f.name, kw)
    n = fr[f.name]
    if isinstance(n, int) and not isinstance(n, bool):
        kw[f.name] = n
        return True
    ck.add(f"`{p}.{f.name}` must be an integer ({f.description}), got "
           f"{_type_name(n)} {_show(n)}")
    return False


def _number_into(ck: _Checker, fr: dict, p: str, name: str, kw: dict) -> bool:
    """``kw[name]`` = the number ``fr[name]`` of table ``p``; False (and the problem,
    with the field's unit) if it is not a number."""
    x = _as_float(fr[name])
    if x is None:
        unit = readable_unit(parameter_unit(name))
        ck.add(f"`{p}.{name}` must be a number ({unit}), got "
               f"{_type_name(fr[name])} {_show(fr[name])}")
        return False
    kw[name] = x
    return True


def _axis(ck: _Checker, data, path: str) -> AxisParameters | None:
    """One full axis table (law fields + optional friction) -> AxisParameters."""
    if not isinstance(data, dict):
        ck.add(f"`{path}` must be a table of mount-law fields, got {_type_name(data)} "
               f"{_show(data)}")
        return None
    n_before = len(ck.problems)
    ck.keys(data, path, ALLOWED_KEYS["mount"], hints={
        "kf": "friction fields go in the sub-table "
              f"[{path}.friction]", "mu": f"friction fields go in [{path}.friction]",
        "n0": f"friction fields go in [{path}.friction]",
        "k": "the small-deflection stiffness is `k1`",
        "stiffness": "the small-deflection stiffness is `k1`",
        "damping": "the viscous damping is `c`"})
    law = ck.choice(data, "law", path, LAWS)
    needed = {"k1", "c"}
    if law in ELASTIC_LAWS:
        needed |= set(ELASTIC_LAWS[law].uses)
    units = {name: readable_unit(parameter_unit(name)) for name in _AXIS_LAW_KEYS[1:]}
    kw = {}
    for name in ("k1", "kc", "k2", "delta", "delta_neg", "c"):
        if name in data:
            x = ck.number(data, name, path, rule="any", unit=units[name], finite=False)
            if x is not None:
                kw[name] = x
        elif name in needed:
            why = f" (law \"{law}\")" if name not in ("k1", "c") else ""
            typo = [k for k in data if k not in ALLOWED_KEYS["mount"]
                    and difflib.get_close_matches(str(k), [name], n=1, cutoff=0.6)]
            if typo:
                why += f"; is `{typo[0]}` a misspelling of it?"
            ck.add(f"`{_join(path, name)}` is missing: a number in {units[name]} is "
                   f"required{why}")
    fr = _friction(ck, data, path)
    mx = _maxwell(ck, data, path)
    hy = _hydraulic(ck, data, path, kw)
    if len(ck.problems) > n_before or law is None or fr is None or mx is None \
            or hy is None:
        return None
    # fields the law does not use get neutral values (kept for the FMU's parameters)
    kw.setdefault("kc", 0.0)
    kw.setdefault("k2", kw["k1"])
    kw.setdefault("delta", AxisParameters.delta)
    kw.setdefault("delta_neg", kw["delta"])
    kw.update(fr)
    kw.update(mx)
    kw.update(hy)
    axis = _unchecked_axis(law=law, **kw)
    problems = _law_problems(axis, path)
    if problems:
        ck.problems.extend(problems)
        return None
    return AxisParameters(**axis.to_dict())


def _maxwell(ck: _Checker, data: dict, path: str) -> dict | None:
    """The ``maxwell`` sub-table of an axis (``k = [...]`` N/m, ``c = [...]`` N s/m,
    one entry per branch, at most MAX_MAXWELL) -> AxisParameters keywords
    (``maxwell_k<i>``, ``maxwell_c<i>``); {} without it, None after a problem."""
    if "maxwell" not in data:
        return {}
    p = _join(path, "maxwell")
    mx = data["maxwell"]
    if not isinstance(mx, dict):
        ck.add(f"`{p}` must be a table with `k = [...]` (N/m) and `c = [...]` (N s/m), "
               f"one entry per Maxwell branch, got {_type_name(mx)} {_show(mx)}")
        return None
    ck.keys(mx, p, ALLOWED_KEYS["mount.maxwell"], hints={
        "stiffness": "the branches' stiffnesses are `k`",
        "damping": "the branches' dampings are `c`"})
    lists = {}
    for key, unit in (("k", "N/m"), ("c", "N s/m")):
        v = mx.get(key)
        if key not in mx:
            ck.add(f"`{p}.{key}` is missing: an array of 1 to {MAX_MAXWELL} numbers "
                   f"in {unit} >= 0 is required (one per Maxwell branch)")
            continue
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            v = [v]
        if not isinstance(v, list) or not 1 <= len(v) <= MAX_MAXWELL:
            ck.add(f"`{p}.{key}` must be an array of 1 to {MAX_MAXWELL} numbers in "
                   f"{unit} >= 0 (one per Maxwell branch; the FMU holds at most "
                   f"{MAX_MAXWELL}), got {_type_name(v)} {_show(v)}")
            continue
        got = ck.vector({key: v}, key, p, len(v), unit=unit, rule=">=0")
        if got is not None:
            lists[key] = got
    if len(lists) < 2:
        return None
    if len(lists["k"]) != len(lists["c"]):
        ck.add(f"`{p}`: `k` has {len(lists['k'])} entries and `c` has "
               f"{len(lists['c'])}: one (k, c) pair per Maxwell branch")
        return None
    out = {}
    for i in range(MAX_MAXWELL):
        out[f"maxwell_k{i + 1}"] = lists["k"][i] if i < len(lists["k"]) else 0.0
        out[f"maxwell_c{i + 1}"] = lists["c"][i] if i < len(lists["c"]) else 0.0
    return out


#: The ``hydraulic`` sub-table's keys after the rubber (the fields of
#: linear_branches.HydraulicParameters after kr, br) -> AxisParameters ``hyd_<key>``.
_HYD_KEYS = tuple(name for name, _u, _d in HYDRAULIC_FIELDS[2:])


def _hydraulic(ck: _Checker, data: dict, path: str, kw: dict) -> dict | None:
    """The ``hydraulic`` sub-table of an axis (the fluid path of a hydraulic mount:
    ``Ap`` m^2, ``C1``, ``C2`` m^5/N, ``I_i``, ``I_d`` kg/m^4, ``R_i``, ``R_d`` N s/m^5;
    ``kr``, ``br`` optional: the rubber is the axis's own ``k1`` and ``c``, a
    different value is an error) -> AxisParameters keywords (``hyd_<key>``); {}
    without it, None after a problem. The values are checked by
    :func:`linear_branches.check_hydraulic`'s rules."""
    if "hydraulic" not in data:
        return {}
    p = _join(path, "hydraulic")
    hy = data["hydraulic"]
    units = {name: unit for name, unit, _d in HYDRAULIC_FIELDS}
    if not isinstance(hy, dict):
        ck.add(f"`{p}` must be a table of the fluid path ("
               + ", ".join(f"`{k}` {units[k]}" for k in _HYD_KEYS)
               + f"), got {_type_name(hy)} {_show(hy)}")
        return None
    ck.keys(hy, p, ALLOWED_KEYS["mount.hydraulic"])
    n_before = len(ck.problems)
    out = {}
    for key in _HYD_KEYS:
        positive = key in ("Ap", "C1", "C2", "I_i")
        x = ck.number(hy, key, p, rule=">0" if positive else ">=0", unit=units[key],
                      required=positive, default=0.0)
        if x is not None:
            out[f"hyd_{key}"] = x
    for key, axis_key in (("kr", "k1"), ("br", "c")):
        if key in hy:
            x = ck.number(hy, key, p, rule=">=0", unit=units[key])
            if x is not None and axis_key in kw and x != kw[axis_key]:
                ck.add(f"`{p}.{key}` = {_show(hy[key])} differs from "
                       f"`{_join(path, axis_key)}` = {_show(kw[axis_key])}: the "
                       f"rubber of a hydraulic mount is the axis's own `{axis_key}`; "
                       f"give it once, as `{_join(path, axis_key)}`")
    return None if len(ck.problems) > n_before else out


def _single_mount(ck: _Checker, data: dict) -> MountParameters | None:
    """``[mount]`` of the sdof and quarter-car models (its axial axis is used)."""
    tbl = ck.table(data, "mount", "", what="with the mount law (law, k1, c, ...) ")
    if tbl is None:
        return None
    axis = _axis(ck, tbl, "mount")
    if axis is None:
        return None
    # only the axial axis deflects in these models; the unused radial axes carry the
    # same elastic law without a friction element (so that nothing reports friction
    # on an axis that never moves)
    radial = replace(axis, friction=False)
    return MountParameters(axis, radial, radial)


def _orientation(ck: _Checker, m: dict, path: str):
    """``[[mounts]].orientation`` -> a rotation matrix (rows: the local axes in body
    axes), re-orthonormalised; None after a problem."""
    o = m["orientation"]
    rows = o if isinstance(o, list) and len(o) == 3 else None
    if rows is None:
        ck.add(f"`{path}.orientation` must be 3 rows of 3 numbers (the axial, "
               f"radial1 and radial2 unit vectors in body axes), got "
               f"{_type_name(o)} {_show(o)}")
        return None
    R = [ck.vector({"r": r}, "r", f"{path}.orientation[{j}]", 3)
         for j, r in enumerate(rows)]
    if not all(r is not None for r in R):
        return None
    R = np.array(R)
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-6):
        ck.add(f"`{path}.orientation` must be a rotation: orthonormal rows "
               f"(axial, radial1, radial2 unit vectors), got "
               f"{R.tolist()}")
    elif np.linalg.det(R) < 0:
        ck.add(f"`{path}.orientation` must be a right-handed rotation "
               f"(determinant +1), got determinant -1: swap radial1 and "
               f"radial2")
    else:
        # re-orthonormalise the rounding of hand-typed values
        u, _, vt = np.linalg.svd(R)
        return u @ vt
    return None


def _scaled_radial(ck: _Checker, m: dict, path: str, name_ax: str, axial, lam):
    """A radial axis of a ``[[mounts]]`` entry with ``lambda``: lambda times the
    axial law, with only its own friction table allowed; None after a problem."""
    p = f"{path}.{name_ax}"
    r = m.get(name_ax, {})
    if not isinstance(r, dict):
        ck.add(f"`{p}` must be a table, got {_type_name(r)} {_show(r)}")
        return None
    law_keys = [k for k in r if k != "friction"]
    for k in law_keys:
        if k in _AXIS_LAW_KEYS:
            ck.add(f"`{p}.{k}` conflicts with `{path}.lambda`: with lambda "
                   f"the radial law is lambda times the axial one (thesis "
                   f"eq. 4.4); "
                   f"remove `{p}.{k}`, or remove `lambda` and give the whole "
                   f"[{p}] table")
        else:
            ck.keys({k: r[k]}, p, ("friction",))
    fr = _friction(ck, r, p)
    if axial is None or lam is None or fr is None:
        return None
    base = axial.scaled(lam).to_dict()
    base.update(friction=False)
    base.update(fr)
    ax = _unchecked_axis(**base)
    probs = _law_problems(ax, p)
    if probs:
        ck.problems.extend(probs)
        return None
    return AxisParameters(**ax.to_dict())


def _rigid_mount(ck: _Checker, m, i: int):
    """One ``[[mounts]]`` entry -> (name, position, orientation, MountParameters)."""
    path = f"mounts[{i}]"
    if not isinstance(m, dict):
        ck.add(f"`{path}` must be a table ([[mounts]] ...), got {_type_name(m)} "
               f"{_show(m)}")
        return None
    n_before = len(ck.problems)
    ck.keys(m, path, ALLOWED_KEYS["mounts[]"], hints={
        "x": "give `position = [x, y, z]`", "pos": "the key is `position`",
        "lam": "the key is `lambda`", "law": f"law fields go in [{path}.axial]",
        "k1": f"law fields go in [{path}.axial]",
        "friction": f"friction goes in the table of its axis, e.g. "
                    f"[{path}.radial1.friction]"})
    name = ck.string(m, "name", path, default=f"mount{i + 1}")
    position = ck.vector(m, "position", path, 3, unit="m")
    orientation = _orientation(ck, m, path) if "orientation" in m else None
    lam = None
    if "lambda" in m:
        lam = ck.number(m, "lambda", path, rule=">0", unit="")
    axial = None
    if "axial" not in m:
        ck.add(f"`{path}.axial` is missing: a table with the mount law (law, k1, c, "
               f"...) is required")
    else:
        axial = _axis(ck, m["axial"], f"{path}.axial")
    axes = {"axial": axial}
    for name_ax in ("radial1", "radial2"):
        p = f"{path}.{name_ax}"
        if "lambda" in m:
            axes[name_ax] = _scaled_radial(ck, m, path, name_ax, axial, lam)
        elif name_ax not in m:
            ck.add(f"`{p}` is missing: give the [{p}] table, or `lambda` in "
                   f"[[mounts]] to derive it from the axial law (radial = lambda * "
                   f"axial, thesis eq. 4.4)")
        else:
            axes[name_ax] = _axis(ck, m[name_ax], p)
    if len(ck.problems) > n_before or any(axes.get(a) is None for a in AXES):
        return None
    return name, position, orientation, MountParameters(**axes)


def mount_from_table(table, source: str = "<dict>") -> AxisParameters:
    """The law of one ``[mount]`` table (law fields and optional ``friction``).

    Checked exactly as a configuration's ``[mount]``; :class:`ConfigError` lists every
    problem. Used by ``drymount fit`` to read a fitted or hand-written mount.
    """
    ck = _Checker()
    axis = _axis(ck, table, "mount")
    if ck.problems or axis is None:
        raise ConfigError(ck.problems or ["invalid [mount] table"], source)
    return axis

