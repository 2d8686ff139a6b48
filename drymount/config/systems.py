"""Model tables, excitation and run settings of a configuration, and the system
builders (:mod:`hbm.systems`) they call."""

from __future__ import annotations


import warnings

import numpy as np

from drymount.hbm import systems as models
from drymount.hbm.options import CountError, check_harmonics, check_samples
from drymount.hbm.system import System
from drymount.config.checks import (
    _Checker,
    _show,
    _type_name,
)
from drymount.config.mounts import (
    _rigid_mount,
    _single_mount,
)
from drymount.config.schema import (
    ALLOWED_KEYS,
    BACKENDS,
    CosimSettings,
    DIRECTIONS,
    EXCITATION_KINDS,
    HBMSettings,
    MAX_POINTS,
    RENAMED_BACKENDS,
    SINGULAR_RTOL,
    SPACINGS,
    SweepSettings,
)


def _count(ck: _Checker, hb: dict, key: str, check, default=None):
    """``[hbm] key`` checked by ``check`` (hbm.options' one check of H or N), its
    problem added to ``ck``; ``default`` when absent, None when invalid."""
    if key not in hb:
        return default
    try:
        return check(hb[key], f"hbm.{key}")
    except CountError as exc:
        ck.add(str(exc))
        return None


# -- model tables ------------------------------------------------------------


def _excitation(ck: _Checker, data: dict, model: str, n_vec: dict):
    tbl = ck.table(data, "excitation", "", what="(kind, amplitude) ")
    if tbl is None:
        return None
    ck.keys(tbl, "excitation", ALLOWED_KEYS["excitation"])
    kinds = EXCITATION_KINDS[model]
    kind = ck.choice(tbl, "kind", "excitation", kinds,
                     extra=f" for model \"{model}\"")
    units = {"unbalance": "kg m (f0 of f = f0 omega^2 sin(omega t))",
             "force": "N", "base": "m"}
    if kind is None:
        if "amplitude" not in tbl:
            ck.add("`excitation.amplitude` is missing")
        return None
    if model == "rigid_engine":
        n = n_vec[kind]
        unit = {"base": "m (chassis x, y, z)",
                "unbalance": "kg m / kg m^2 (x, y, z, alpha, beta, gamma)",
                "force": "N / N m (x, y, z, alpha, beta, gamma)"}[kind]
        amp = ck.vector(tbl, "amplitude", "excitation", n, unit=unit)
        if amp is not None and not any(a != 0 for a in amp):
            ck.add(f"`excitation.amplitude` must not be all zero (the "
                   f"transmissibility divides by it), got {amp}")
            return None
        return (kind, amp) if amp is not None else None
    amp = ck.number(tbl, "amplitude", "excitation", rule=">0", unit=units[kind])
    return (kind, amp) if amp is not None else None


def _settings(ck: _Checker, data: dict):
    sw = ck.table(data, "sweep", "", required=False) or {}
    ck.keys(sw, "sweep", ALLOWED_KEYS["sweep"])
    d = SweepSettings()
    fmin = ck.number(sw, "fmin_hz", "sweep", rule=">0", unit="Hz", required=False,
                     default=d.fmin_hz)
    fmax = ck.number(sw, "fmax_hz", "sweep", rule=">0", unit="Hz", required=False,
                     default=d.fmax_hz)
    if fmin is not None and fmax is not None and not fmax > fmin:
        what = "empty" if fmax == fmin else "reversed"
        ck.add(f"`sweep.fmax_hz` must be > `sweep.fmin_hz` = {fmin:g} Hz, got "
               f"{fmax:g} Hz: the frequency range is {what}")
    points = ck.integer(sw, "points", "sweep", minimum=2, maximum=MAX_POINTS,
                        default=d.points)
    direction = ck.choice(sw, "direction", "sweep", DIRECTIONS, required=False,
                          default=d.direction)
    spacing = ck.choice(sw, "spacing", "sweep", SPACINGS, required=False,
                        default=d.spacing)
    hb = ck.table(data, "hbm", "", required=False) or {}
    ck.keys(hb, "hbm", ALLOWED_KEYS["hbm"])
    harmonics = _count(ck, hb, "harmonics", check_harmonics,
                       default=HBMSettings.harmonics)
    n_samples = None
    if harmonics is not None:
        n_samples = _count(ck, hb, "n_samples",
                           lambda v, f: check_samples(v, harmonics, f))
    hbm_extra = {k: ck.number(hb, k, "hbm", rule=">0", required=False)
                 for k in ("tol", "ds_initial", "ds_min", "ds_max", "max_angle")}
    if hbm_extra["tol"] is not None and not hbm_extra["tol"] < 0.5:
        ck.add(f"`hbm.tol` must be a number > 0 and < 0.5 (relative to the peak), "
               f"got {hbm_extra['tol']}")
    hbm_extra["max_harmonics"] = _count(ck, hb, "max_harmonics", check_harmonics)
    cs = ck.table(data, "cosim", "", required=False) or {}
    ck.keys(cs, "cosim", ALLOWED_KEYS["cosim"])
    if isinstance(cs.get("backend"), str) and cs["backend"] in RENAMED_BACKENDS:
        old = cs["backend"]
        cs = {**cs, "backend": RENAMED_BACKENDS[old]}
        warnings.warn(f"`cosim.backend` = {old!r} is deprecated: use "
                      f"{cs['backend']!r} (the law in-process; {old!r} now names "
                      f"only the C FMU)", FutureWarning, stacklevel=2)
    backend = ck.choice(cs, "backend", "cosim", BACKENDS, required=False,
                        default=CosimSettings.backend)
    freq = ck.number(cs, "freq_hz", "cosim", rule=">0", unit="Hz", required=False)
    duration = ck.number(cs, "duration", "cosim", rule=">0", unit="s", required=False)
    spp = ck.integer(cs, "steps_per_period", "cosim", minimum=8)
    _check_cosim_input(ck, cs)
    if None in (fmin, fmax, points, direction, spacing, harmonics, backend):
        return None
    return (SweepSettings(fmin, fmax, points, direction, spacing),
            HBMSettings(harmonics, n_samples, **hbm_extra),
            CosimSettings(backend, freq, duration, spp))


def _check_cosim_input(ck: _Checker, cs: dict) -> None:
    """``[cosim.input]``: the measured inputs of ``drymount cosim`` (CSV file names,
    relative to the configuration file; read by :mod:`drymount.measured`)."""
    from drymount.measured import UNITS

    inp = ck.table(cs, "input", "cosim", required=False)
    if inp is None:
        return
    ck.keys(inp, "cosim.input", ALLOWED_KEYS["cosim.input"])
    for key in ("road", "engine"):
        if key in inp and not ck.string(inp, key, "cosim.input").strip():
            ck.add(f"`cosim.input.{key}` must name a CSV file, got {inp[key]!r}")
    ck.number(inp, "speed", "cosim.input", rule=">0", unit="m/s", required=False)
    units = ck.table(inp, "units", "cosim.input", required=False) or {}
    for column, unit in units.items():
        if unit not in UNITS:
            ck.add(f"`cosim.input.units.{column}` must be one of "
                   f"{', '.join(UNITS)}, got {unit!r}")


def _check_support(ck: _Checker, system: System) -> None:
    """The mounts (with stuck friction) must hold every DOF: K positive definite."""
    K, _ = system.linearized(stuck=True)
    if not np.all(np.isfinite(K)):
        ck.add("the linearised stiffness is not finite: stiffness values are too large")
        return
    Mi = np.diag(1.0 / np.sqrt(np.diag(system.M)))
    ev = np.linalg.eigvalsh(Mi @ K @ Mi)
    if ev[0] <= SINGULAR_RTOL * max(abs(ev[-1]), 1e-300):
        mode = np.linalg.eigh(Mi @ K @ Mi)[1][:, 0]
        dof = system.dof_names[int(np.argmax(abs(mode)))]
        ck.add(f"the mounts do not hold the system: the linearised stiffness (k1 of "
               f"each axis, plus kf where friction sticks) is singular, a motion "
               f"mostly "
               f"along `{dof}` meets no spring; check the stiffnesses and, for "
               f"rigid_engine, that the mount positions are not collinear")


def _build(ck: _Checker, data: dict, model: str):

    if model == "sdof":
        t = ck.table(data, "sdof", "", what="(mass) ")
        mass = None
        if t is not None:
            ck.keys(t, "sdof", ALLOWED_KEYS["sdof"], hints={
                "m": "the key is `mass`", "m_e": "the key is `mass`"})
            mass = ck.number(t, "mass", "sdof", rule="mass", unit="kg")
        mount = _single_mount(ck, data)
        exc = _excitation(ck, data, model, {})
        if ck.problems:
            return None
        return lambda: models.sdof(mass, mount, excitation=exc[0], amplitude=exc[1])
    if model == "quarter_car":
        t = ck.table(data, "quarter_car", "",
                     what="(m_e, m_s, m_us, k_s, c_s, k_t, c_t) ")
        vals = {}
        if t is not None:
            ck.keys(t, "quarter_car", ALLOWED_KEYS["quarter_car"], hints={
                "mass": "the masses are `m_e`, `m_s`, `m_us`"})
            for name, rule, unit in (("m_e", "mass", "kg"), ("m_s", "mass", "kg"),
                                     ("m_us", "mass", "kg"), ("k_s", ">=0", "N/m"),
                                     ("c_s", ">=0", "N s/m"), ("k_t", ">0", "N/m"),
                                     ("c_t", ">=0", "N s/m")):
                vals[name] = ck.number(t, name, "quarter_car", rule=rule, unit=unit)
        mount = _single_mount(ck, data)
        exc = _excitation(ck, data, model, {})
        if ck.problems:
            return None
        return lambda: models.quarter_car(mount=mount, road_amplitude=exc[1], **vals)
    # rigid_engine
    t = ck.table(data, "rigid_engine", "", what="(mass, inertia) ")
    mass = inertia = None
    if t is not None:
        ck.keys(t, "rigid_engine", ALLOWED_KEYS["rigid_engine"], hints={
            "Ixx": "give `inertia = [Ixx, Iyy, Izz]`", "m": "the key is `mass`"})
        mass = ck.number(t, "mass", "rigid_engine", rule="mass", unit="kg")
        inertia = ck.vector(t, "inertia", "rigid_engine", 3, unit="kg m^2",
                            rule="inertia")
    mounts = []
    if "mounts" not in data:
        ck.add("`mounts` is missing: model \"rigid_engine\" needs at least 3 "
               "[[mounts]] tables")
    elif not isinstance(data["mounts"], list):
        ck.add(f"`mounts` must be an array of tables ([[mounts]] ...), got "
               f"{_type_name(data['mounts'])} {_show(data['mounts'])}")
    else:
        if len(data["mounts"]) < 3:
            ck.add(f"`mounts` must hold at least 3 mounts (a rigid engine on fewer is "
                   f"not held in 6 DOF), got {len(data['mounts'])}")
        for i, m in enumerate(data["mounts"]):
            mounts.append(_rigid_mount(ck, m, i))
        names = [m[0] for m in mounts if m is not None]
        for n in sorted({n for n in names if names.count(n) > 1}):
            ck.add(f"`mounts[].name` must be unique, got {n!r} {names.count(n)} times")
    exc = _excitation(ck, data, model, {"base": 3, "unbalance": 6, "force": 6})
    if ck.problems:
        return None
    orients = [m[2] if m[2] is not None else models.DEFAULT_ORIENTATION for m in mounts]
    return lambda: models.rigid_engine(
        mass, inertia, [m[1] for m in mounts], [m[3] for m in mounts],
        names=[m[0] for m in mounts], orientations=orients, excitation=exc[0],
        amplitude=exc[1])
