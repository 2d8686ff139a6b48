"""Checking ``[design]``: every problem with its field path, value and what is allowed.

:func:`design_space` reads ``config.data["design"]`` of a checked
:class:`drymount.config.Config` and returns a
:class:`~drymount.design.space.DesignSpace` or raises
:class:`drymount.config.ConfigError` listing every problem. Each variable is also set
to both ends of its range and the configuration rebuilt, so that a bound the
configuration would reject (a negative stiffness, a position that leaves the engine
unsupported) is reported before any design runs.
"""

from __future__ import annotations

import difflib
import math

from drymount.config import Config, ConfigError, config_from_dict
from drymount.hbm.options import CountError, check_harmonics
from drymount.design.space import (
    AXES,
    DEFAULT_CHUNK,
    DEFAULT_GRID_POINTS,
    DEFAULT_SAMPLES,
    DESIGN_KEYS,
    MAX_DESIGNS,
    ROTATIONS,
    BoxConstraint,
    DesignSpace,
    Measure,
    Method,
    Metric,
    Quantity,
    Variable,
    apply_values,
)
from drymount.paths import PathError, expand, format_parts, get_value, parse_path

__all__ = ["design_space"]


def _show(v) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _num(v) -> float | None:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    x = float(v)
    return x if math.isfinite(x) else None


class _Reader:
    """Reads one table of ``[design]``, collecting problems."""

    def __init__(self, problems: list, table: dict, path: str, allowed):
        self.problems, self.t, self.path = problems, table, path
        for k in table:
            if k not in allowed:
                close = difflib.get_close_matches(str(k), allowed, n=1, cutoff=0.6)
                hint = f": did you mean `{close[0]}`?" if close else ""
                problems.append(f"unknown key `{path}.{k}` (value {_show(table[k])})"
                                f"{hint}; allowed here: {', '.join(allowed)}")

    def add(self, key: str, v, what: str) -> None:
        self.problems.append(f"`{self.path}.{key}` must be {what}, got {_show(v)}")

    def integer(self, key, default, minimum, maximum=None):
        if key not in self.t:
            return default
        v = self.t[key]
        rng = f">= {minimum}" if maximum is None else f"in {minimum}..{maximum}"
        if isinstance(v, bool) or not isinstance(v, int) or v < minimum or (
                maximum is not None and v > maximum):
            self.add(key, v, f"an integer {rng}")
            return None
        return v

    def harmonics(self, key, default):
        """A harmonic count, by hbm.options' one check of H."""
        if key not in self.t:
            return default
        try:
            return check_harmonics(self.t[key], f"{self.path}.{key}")
        except CountError as exc:
            self.problems.append(str(exc))
            return None

    def choice(self, key, enum, default=None):
        if key not in self.t:
            if default is None:
                self.problems.append(f"`{self.path}.{key}` is missing: one of "
                                     f"{_choices(enum)} is required")
            return default
        v = self.t[key]
        try:
            return enum(v)
        except ValueError:
            self.add(key, v, f"one of {_choices(enum)}")
            return None

    def numbers(self, key, n: int | None, what: str, required=True):
        """A list of finite numbers (length n if given); None after a problem."""
        if key not in self.t:
            if required:
                self.problems.append(f"`{self.path}.{key}` is missing: {what} is "
                                     f"required")
            return None
        v = self.t[key]
        xs = [_num(x) for x in v] if isinstance(v, list) else None
        if xs is None or None in xs or (n is not None and len(xs) != n) or not xs:
            self.add(key, v, what)
            return None
        return tuple(xs)

    def band(self, key, default, within=None):
        b = self.numbers(key, 2, "[fmin, fmax] in Hz, 0 < fmin < fmax",
                         required=False)
        if b is None:
            return default if key not in self.t else None
        if not 0 < b[0] < b[1]:
            self.add(key, list(b), "[fmin, fmax] in Hz with 0 < fmin < fmax")
            return None
        if within is not None and not (within[0] <= b[0] and b[1] <= within[1]):
            self.add(key, list(b), f"inside the design's HBM band `design.band_hz` = "
                                   f"[{within[0]:g}, {within[1]:g}] Hz")
            return None
        return b


def _choices(enum) -> str:
    return ", ".join(f'"{e.value}"' for e in enum)


def _tables(problems, design: dict, key: str, required: bool) -> list:
    v = design.get(key, [])
    if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
        problems.append(f"`design.{key}` must be an array of tables "
                        f"([[design.{key}]] ...), got {_show(v)}")
        return []
    if required and not v:
        problems.append(f"`design.{key}` is missing: at least one [[design.{key}]] "
                        f"table is required")
    return v


def _variable(problems, t: dict, i: int, cfg: Config) -> Variable | None:
    p = f"design.variables[{i}]"
    r = _Reader(problems, t, p, DESIGN_KEYS["variables[]"])
    n0 = len(problems)
    rot = t.get("rotate_about")
    if rot is not None and rot not in AXES:
        r.add("rotate_about", rot, 'one of "x", "y", "z" (a body axis)')
    paths = _paths(problems, t, p, cfg, rot, t.get("mode", "set"))
    if paths is None:
        return None
    has_b, has_v = "bounds" in t, "values" in t
    if has_b == has_v:
        problems.append(f"`{p}` needs exactly one of `bounds = [lower, upper]` or "
                        f"`values = [...]`, got {'both' if has_b else 'neither'}")
    lower = upper = math.nan
    values = ()
    if has_b:
        b = r.numbers("bounds", 2, "[lower, upper], two finite numbers")
        if b is not None and not b[0] < b[1]:
            r.add("bounds", list(b), "[lower, upper] with lower < upper")
        elif b is not None:
            lower, upper = b
    elif has_v:
        values = r.numbers("values", None, "a non-empty array of finite numbers") or ()
    points = r.integer("points", DEFAULT_GRID_POINTS, 2, MAX_DESIGNS)
    if len(problems) > n0:
        return None
    text = "+".join(str(q) for q in paths)
    scale = t.get("mode") == "scale"
    name = t.get("name") or (f"{text}.rot_{rot}_deg" if rot else
                             f"{text}*scale" if scale else text)
    if not isinstance(name, str):
        r.add("name", name, "a string")
        return None
    return Variable(name, paths, lower, upper, tuple(values), points, rot, scale)


def _paths(problems, t: dict, p: str, cfg: Config, rot, mode) -> tuple | None:
    """The checked ``path`` (a path or an array of paths) of a variable."""
    if mode not in ("set", "scale"):
        problems.append(f"`{p}.mode` must be \"set\" (the value replaces the "
                        f"fields) or \"scale\" (it multiplies them), got {_show(mode)}")
        return None
    raw = t.get("path")
    texts = raw if isinstance(raw, list) and raw else [raw]
    try:
        paths = tuple(parse_path(x) for x in texts)
        matches = [m for q in paths for m in expand(cfg.data, q)]
    except PathError as exc:
        problems.append(f"`{p}.path`: {exc}")
        return None
    if rot is not None:
        if (cfg.model != "rigid_engine" or len(paths) != 1 or mode != "set"
                or paths[0].parts[-1] != "orientation"):
            problems.append(f"`{p}.rotate_about` turns a mount: `{p}.path` must be one "
                            f"`mounts[i].orientation` of model \"rigid_engine\" "
                            f"(mode \"set\"), got {_show(raw)} of model "
                            f"\"{cfg.model}\"")
        return paths
    for parts in matches:
        try:
            v = get_value(cfg.data, parts)
        except PathError:
            if mode == "scale":
                problems.append(f"`{p}.path`: `{format_parts(parts)}` is not in the "
                                f"file; mode \"scale\" multiplies the file's value")
            continue  # a new key: the configuration check judges it
        if _num(v) is None:
            hint = (f"; address one item, e.g. `{format_parts(parts)}[0]`"
                    if isinstance(v, list) else "")
            problems.append(f"`{p}.path` must address numbers, but "
                            f"`{format_parts(parts)}` is {_show(v)}{hint}")
    return paths


def _metric(problems, t: dict, i: int, kind: str, band, cfg: Config) -> Metric | None:
    p = f"design.{kind}[{i}]"
    r = _Reader(problems, t, p, DESIGN_KEYS[f"{kind}[]"])
    n0 = len(problems)
    q = r.choice("quantity", Quantity)
    m = r.choice("measure", Measure, Measure.PEAK)
    b = r.band("band_hz", band, within=band)
    dof = t.get("dof")
    dofs = cfg.system.dof_names
    if q is Quantity.DISPLACEMENT and dof not in dofs:
        problems.append(f"`{p}.dof` must be one of {', '.join(dofs)} (model "
                        f"\"{cfg.model}\") for a displacement, got {_show(dof)}")
    elif q is not None and q is not Quantity.DISPLACEMENT and dof is not None:
        problems.append(f"`{p}.dof` is only for quantity \"displacement\" (the "
                        f"{q.value} is the system's), got {_show(dof)}")
    if q is Quantity.FORCE and cfg.system.transmissibility.kind != "force":
        problems.append(f"`{p}.quantity` = \"force\" needs a system whose "
                        f"transmissibility is a force ratio (model \"sdof\" with "
                        f"unbalance or force excitation); this one's is a "
                        f"{cfg.system.transmissibility.kind} ratio: use "
                        f"\"transmissibility\"")
    sense, limit = "min", math.nan
    if kind == "objectives":
        sense = t.get("sense", "min")
        if sense not in ("min", "max"):
            r.add("sense", sense, '"min" or "max"')
    else:
        limit = _num(t.get("max"))
        if limit is None:
            r.add("max", t.get("max"), "a finite number: the largest allowed value")
    if len(problems) > n0:
        return None
    unit = {"transmissibility": "-", "force": "N"}.get(q.value) or (
        "rad" if dof in ROTATIONS else "m")
    name = t.get("name") or "_".join(x for x in (m.value, q.value, dof) if x)
    return Metric(str(name), q, m, tuple(b), dof, sense, float(limit), unit)


def _box(problems, t: dict, i: int, cfg: Config) -> BoxConstraint | None:
    p = f"design.constraints[{i}]"
    r = _Reader(problems, t, p, DESIGN_KEYS["constraints[]"])
    n0 = len(problems)
    try:
        path = parse_path(t.get("path"))
        for parts in expand(cfg.data, path):
            v = get_value(cfg.data, parts)
            if not (isinstance(v, list) and len(v) == 3):
                problems.append(f"`{p}.path` = `{path}` must address positions (3 "
                                f"numbers in m), got {_show(v)}")
                break
    except PathError as exc:
        problems.append(f"`{p}.path`: {exc}")
    lo = r.numbers("min", 3, "[x, y, z], 3 finite numbers in m")
    hi = r.numbers("max", 3, "[x, y, z], 3 finite numbers in m")
    if lo and hi and not all(a < b for a, b in zip(lo, hi, strict=True)):
        r.add("max", list(hi), f"above `{p}.min` = {list(lo)} on every axis")
    if len(problems) > n0:
        return None
    return BoxConstraint(str(t.get("name") or f"box_{path}"), path, lo, hi)


def _check_ranges(problems, cfg: Config, variables) -> None:
    """Each variable at both ends of its range, the others as in the file."""
    for i, v in enumerate(variables):
        ends = (v.values[0], v.values[-1]) if v.is_list else (v.lower, v.upper)
        key = "values" if v.is_list else "bounds"
        for x in dict.fromkeys(ends):
            try:
                doc = apply_values(cfg.data, [v], [x])
                config_from_dict(doc, source=cfg.source, name=cfg.name)
            except PathError as exc:
                problems.append(f"`design.variables[{i}].path`: {exc}")
            except ConfigError as exc:
                for msg in exc.problems:
                    problems.append(f"`design.variables[{i}].{key}`: at {x:g} the "
                                    f"configuration is invalid: {msg}")


def _check_grid_size(problems, variables) -> None:
    """A grid's designs (the product of the variables' grid sizes) <= MAX_DESIGNS."""
    sizes = [len(v.grid()) for v in variables]
    n = math.prod(sizes)
    if n > MAX_DESIGNS:
        what = " x ".join(f"{k} ({v.name})" for k, v in zip(sizes, variables,
                                                           strict=True))
        problems.append(f"`design.variables[*].points`: the grid has {n:,} designs "
                        f"({what}); at most {MAX_DESIGNS:,} are allowed (fewer "
                        f"points or values, or method \"lhs\" with `samples`)")


def _settings(problems, d: dict, cfg: Config):
    r = _Reader(problems, d, "design", DESIGN_KEYS["design"])
    method = r.choice("method", Method, Method.LHS)
    samples = r.integer("samples", DEFAULT_SAMPLES, 1, MAX_DESIGNS)
    if method is Method.SOBOL and samples and samples & (samples - 1):
        r.add("samples", samples, "a power of 2 for method \"sobol\" (its balance "
                                  "properties need it), e.g. 64")
    seed = r.integer("seed", 0, 0)
    H = r.harmonics("harmonics", cfg.hbm.harmonics)
    band = r.band("band_hz", (cfg.sweep.fmin_hz, cfg.sweep.fmax_hz))
    chunk = r.integer("chunk", DEFAULT_CHUNK, 1)
    return method, samples, seed, H, band, chunk


def design_space(cfg: Config) -> DesignSpace:
    """The checked ``[design]`` section of ``cfg``.

    Raises
    ------
    ConfigError
        No ``[design]`` section, or every problem found in it.
    """
    d = cfg.data.get("design")
    if not isinstance(d, dict):
        raise ConfigError([f"`design` must be a table ([design] with variables, "
                           f"objectives and constraints, docs/explore.md), got "
                           f"{_show(d) if d is not None else 'nothing'}"], cfg.source)
    problems: list[str] = []
    method, samples, seed, H, band, chunk = _settings(problems, d, cfg)
    variables = [_variable(problems, t, i, cfg)
                 for i, t in enumerate(_tables(problems, d, "variables", True))]
    objectives = [_metric(problems, t, i, "objectives", band, cfg) for i, t in
                  enumerate(_tables(problems, d, "objectives", True))] if band else []
    constraints = []
    for i, t in enumerate(_tables(problems, d, "constraints", False)):
        kind = t.get("kind", "response")
        if kind == "box":
            constraints.append(_box(problems, t, i, cfg))
        elif kind == "response":
            constraints.append(_metric(problems, t, i, "constraints", band, cfg)
                               if band else None)
        else:
            problems.append(f"`design.constraints[{i}].kind` must be \"response\" "
                            f"(default) or \"box\", got {_show(kind)}")
    if method is Method.GRID and not problems:
        _check_grid_size(problems, variables)
    if not problems:
        _check_ranges(problems, cfg, variables)
    names = [x.name for x in (*variables, *objectives, *constraints) if x is not None]
    for n in sorted({n for n in names if names.count(n) > 1}):
        problems.append(f"names of design variables, objectives and constraints must "
                        f"be unique (they are table columns), got {n!r} "
                        f"{names.count(n)} times; give `name = ...`")
    if problems:
        raise ConfigError(problems, cfg.source)
    return DesignSpace(method, samples, seed, H, band, chunk, tuple(variables),
                       tuple(objectives), tuple(constraints))
