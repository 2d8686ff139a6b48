"""``drymount static CONFIG``: the static working point under the engine's weight.

Gravity acts on every body (downwards: ``-g`` along the vertical translation DOFs of the
model, :data:`drymount.config.static.VERTICAL`), plus the static loads of the
configuration's ``[static]`` table and of ``--load`` (e.g. the engine's drive
torque). :func:`hbm.static.static_equilibrium` solves the equilibrium with the
nonlinear elastic laws, friction sliders relaxed (its module docstring says why).
Writes the static deflection and force of every mount axis to CSV and warns when an
axis works past a knee of its law or beyond ``--travel-mm``.

With ``[static] gravity = true`` in the configuration, ``drymount hbm``, ``cosim`` and
``sweep`` run about this working point; without it they run about the unloaded point,
and this command tells whether that is where the mounts work.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from drymount.io import write_csv
from drymount.fmu_src.mount_law import AXES, ELASTIC_LAWS
from drymount.hbm.static import (StaticStatus, gravity_load, knee_warnings,
                                 static_equilibrium)

__all__ = ["main", "MAX_LOAD", "MAX_G"]

#: Largest ``--load`` magnitude, N or N m (a thousand times the weight of a
#: 100-tonne body: beyond it the elastic laws' forces overflow long before).
MAX_LOAD = 1e9
#: Largest ``--g``, m/s^2 (100 g).
MAX_G = 1e3


def _loads(specs, dof_names) -> np.ndarray:
    """The generalised load of ``--load DOF=VALUE`` items; ValueError if malformed."""
    f = np.zeros(len(dof_names))
    for spec in specs or ():
        name, _, value = spec.partition("=")
        try:
            x = float(value)
        except ValueError:
            x = None
        if (name not in dof_names or x is None or not np.isfinite(x)
                or abs(x) > MAX_LOAD):
            raise ValueError(f"--load must be DOF=VALUE with DOF one of "
                             f"{', '.join(dof_names)} and a number (N or N m) within "
                             f"+-{MAX_LOAD:g}, got {spec!r}")
        f[dof_names.index(name)] += x
    return f


def _print_inclined_readings(system, load, relaxed) -> None:
    """With inclined elements: both readings of the working point (relaxed, the
    one written to the CSV, and lowered onto the assembled mount, the one the runs
    start from unless ``[static] reading = "relaxed"``) and the
    admissible range of each inclined axis (hbm.static; docs/physics.md)."""
    from drymount.fmu_src.inclined import axis_normal_forces, relaxed_state
    from drymount.hbm.static import admissible_range, lowered_equilibrium

    ranges = admissible_range(system, load)
    if not ranges:
        return
    lowered = lowered_equilibrium(system, load)
    print(f"  inclined element: two readings of the working point (the HBM and "
          f"co-simulation start from the {system.static_reading} one, [static] "
          f"reading); lowered {lowered.status.value} in {lowered.iterations} "
          f"Newton steps")
    for r in ranges:
        e = system.elements[r.element]
        p = e.params.axes[r.axis]
        q = p.element_params
        for name, pt, state in (
                ("relaxed", relaxed, relaxed_state(q, relaxed.deflection[r.element,
                                                                          r.axis])),
                ("lowered", lowered, None if lowered.states is None else
                 lowered.states.get((r.element, r.axis)))):
            u = pt.deflection[r.element, r.axis]
            f_el = pt.force[r.element, r.axis] - p.elastic_force(u, p)[0]
            n1 = "" if state is None else \
                f", N = {axis_normal_forces(state, q)[0]:.2f} N"
            print(f"  {e.name:<8} {AXES[r.axis]:<8} {name:<7} deflection "
                  f"{u * 1e3:9.4f} mm  element force {f_el:9.2f} N{n1}")
        print(f"  {e.name:<8} {AXES[r.axis]:<8} admissible static deflections "
              f"{r.low * 1e3:.4f} to {r.high * 1e3:.4f} mm (each surface within its "
              f"friction limit; the history decides)")


def _axis_rows(system, point, travel) -> list[tuple]:
    """Per active mount axis at the working point ``point``: its CSV row ``(mount,
    axis, deflection, force, past a knee, beyond the travel)``, printed as it goes."""
    rows = []
    for ie, e in enumerate(system.elements):
        for j in e.active_axes:
            p = e.params.axes[j]
            u, F = point.deflection[ie, j], point.force[ie, j]
            knees = ELASTIC_LAWS[p.law].knees(p)
            past = any((k > 0 and u > k) or (k < 0 and u < k) for k in knees)
            beyond = travel is not None and abs(u) > travel
            rows.append((e.name, AXES[j], u, F, past, beyond))
            print(f"  {e.name:<8} {AXES[j]:<8} deflection {u * 1e3:9.4f} mm  force "
                  f"{F:10.2f} N")
    return rows


def main(args) -> int:
    """Run ``drymount static`` (CLI arguments in ``args``); the exit status."""
    from drymount.paths import load_with_overrides
    from drymount.config.static import vertical_dofs

    cfg = load_with_overrides(args.config, getattr(args, "overrides", None) or ())
    system, st = cfg.system, cfg.static
    names = list(system.dof_names)
    try:
        load = _loads(args.load, names)
    except ValueError as exc:
        print(f"drymount: error: {exc}", file=sys.stderr)
        return 2
    for name, x in st.loads.items():  # the configuration's [static] loads
        load[names.index(name)] += x
    g = st.g if args.g is None else args.g
    if args.g is not None and not args.g <= MAX_G:
        print(f"drymount: error: --g must be <= {MAX_G:g} m/s^2, got {args.g:g}",
              file=sys.stderr)
        return 2
    if not args.no_gravity:
        load += gravity_load(system, vertical_dofs(cfg.model, names), g)
    travel = st.travel if args.travel_mm is None else args.travel_mm * 1e-3
    from drymount.cli_guard import check_out

    out = check_out(Path(args.out or f"{cfg.name}_static.csv"), "--out")
    with np.errstate(all="ignore"):  # refused below if not finite
        point = static_equilibrium(system, load)
    if not all(np.isfinite(a).all() for a in (point.q, point.deflection, point.force)):
        print(f"drymount: error: the static equilibrium under the load "
              f"{np.array2string(load, precision=4)} is not finite (the elastic laws "
              f"overflow); nothing written to {out}", file=sys.stderr)
        return 1
    what = "no gravity" if args.no_gravity else f"g = {g:g} m/s^2"
    if args.load:
        what += ", loads " + ", ".join(args.load)
    print(f"{cfg.name}: static working point ({what}): {point.status.value} in "
          f"{point.iterations} Newton steps")
    print("  " + ", ".join(f"{n} = {v:.6g}"
                           for n, v in zip(names, point.q, strict=True)))
    rows = _axis_rows(system, point, travel)
    _print_inclined_readings(system, load, point)
    warnings = knee_warnings(system, point, travel)
    for w in warnings:
        print(f"  warning: {w}")
    write_csv(out, ["mount", "axis", "deflection_m", "force_N", "past_knee",
                    "beyond_travel"], rows,
              comment=f"static working point of {cfg.source}: deflection [m] (engine "
                      f"minus chassis side), elastic force [N] (positive = tension); "
                      f"sliders relaxed; q = {np.array2string(point.q, precision=6)}")
    print(f"wrote {out}")
    if point.status is not StaticStatus.CONVERGED:
        print(f"drymount: error: the static equilibrium {point.status.value} "
              f"(largest residual {point.residual:.3g})", file=sys.stderr)
        return 1
    return 0
