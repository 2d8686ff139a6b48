"""Report of ``drymount optimize``: the optimum against the configuration as written.

``summary.md`` gives the best design, the ``--set`` options that reproduce it, each
constraint's margin, and per DOF the peak fundamental amplitude of the starting
(file) design and of the optimum over the design band, from one HBM curve each;
``convergence.png`` the best feasible objective against the evaluation number and
``response.png`` the amplitude of every DOF before and after.
"""

from __future__ import annotations

import math

import numpy as np

from drymount.design.space import ROTATIONS, apply_values

__all__ = ["write_report", "compare_designs", "reproduce_options"]


def compare_designs(cfg, space, values):
    """HBM curves of the configuration as written and with ``values``:
    ``(before, after)`` frequency responses over the design band."""
    import drymount.hbm as hbm
    from drymount.config import config_from_dict

    after_cfg = config_from_dict(apply_values(cfg.data, space.variables, values),
                                 source=cfg.source, name=cfg.name)
    curves = []
    for c in (cfg, after_cfg):
        curves.append(hbm.frequency_response(c.system, *space.band_hz,
                                             harmonics=space.harmonics))
    return curves


def _unit(dof: str) -> str:
    return "rad" if dof in ROTATIONS else "m"


def _plot_response(before, after, path, title: str) -> None:
    from matplotlib.figure import Figure

    from drymount.io import save_figure

    dofs = before.dof_names
    fig = Figure(figsize=(9, 2.4 * ((len(dofs) + 1) // 2) + 0.6))
    for k, d in enumerate(dofs):
        ax = fig.add_subplot((len(dofs) + 1) // 2, 2 if len(dofs) > 1 else 1, k + 1)
        for fr, label, color in ((before, "as written", "0.3"),
                                 (after, "optimum", "tab:red")):
            ax.semilogy(fr.freq_hz, fr.amplitude[:, k], color=color, lw=1.2,
                        label=label)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"{d} amplitude [{_unit(d)}]")
        ax.grid(True, which="both", alpha=0.3)
        if k == 0:
            ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)


def _plot_convergence(res, j_sign, path, title: str, unit: str) -> None:
    from matplotlib.figure import Figure

    from drymount.io import save_figure

    best, ys = math.inf, []
    for _, r in res.history:
        if r.feasible and np.isfinite(r.objectives[res.j]):
            best = min(best, j_sign * r.objectives[res.j])
        ys.append(j_sign * best if math.isfinite(best) else np.nan)
    fig = Figure(figsize=(7, 4))
    ax = fig.add_subplot()
    ax.plot(np.arange(1, len(ys) + 1), ys, color="tab:blue")
    ax.set_xlabel("evaluation [-]")
    ax.set_ylabel(f"best feasible {res.objective} [{unit}]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)


def reproduce_options(doc: dict, space, values) -> str:
    """``--set`` options giving the design ``values`` (a rotation variable as the
    turned ``orientation`` rows, rounded to 9 digits)."""
    from drymount.paths import expand, format_parts, get_value

    new = apply_values(doc, space.variables, values)
    opts = {}
    for v in space.variables:
        for parts in (p for path in v.paths for p in expand(new, path)):
            if v.rotate_about is None:
                opts[format_parts(parts)] = f"{float(get_value(new, parts)):.9g}"
            else:
                rows = np.round(np.asarray(get_value(new, parts)), 9) + 0.0
                opts[format_parts(parts)] = "[" + ", ".join(
                    "[" + ", ".join(f"{a:.9g}" for a in r) + "]" for r in rows) + "]"
    return " ".join(f"--set '{k}={val}'" for k, val in opts.items())


def _dof_scale(system) -> tuple[float, str]:
    """Divisor and label making amplitudes transmissibilities: the base amplitude
    (m) for a base input; 1 otherwise (amplitudes in m or rad)."""
    if system.excitation.kind == "base":
        return float(np.linalg.norm(system.excitation.amplitude)), "transmissibility"
    return 1.0, "amplitude"


def _table_dofs(before, after, system) -> list[str]:
    scale, what = _dof_scale(system)
    unit = {True: {"m": "-", "rad": "rad/m"}, False: {"m": "m", "rad": "rad"}}[
        what == "transmissibility"]
    lines = [f"Peak {what} per DOF over the band (fundamental, HBM):", "",
             "| DOF | as written | optimum | change |", "|---|---|---|---|"]
    for k, d in enumerate(before.dof_names):
        a = float(np.max(before.amplitude[:, k])) / scale
        b = float(np.max(after.amplitude[:, k])) / scale
        u = unit[_unit(d)]
        lines.append(f"| {d} | {a:.4g} {u} | {b:.4g} {u} | "
                     f"{100 * (b / a - 1):+.1f} % |")
    return lines


def _table_before_after(space, base, best) -> list[str]:
    lines = ["| | as written | optimum |", "|---|---|---|"]
    for v, a, b in zip(space.variables, base.values, best.values, strict=True):
        lines.append(f"| `{v.name}` | {a:.5g} | {b:.5g} |")
    for o, a, b in zip(space.objectives, base.objectives, best.objectives, strict=True):
        lines.append(f"| objective `{o.name}` [{o.unit}] | {a:.5g} | {b:.5g} |")
    for c, a, b in zip(space.constraints, base.margins, best.margins, strict=True):
        lines.append(f"| margin `{c.name}` [{c.unit}] (>= 0 ok) | {a:.4g} | {b:.4g} |")
    lines.append(f"| feasible | {base.feasible} | {best.feasible} |")
    return lines


#: A variable within this fraction of its range from a bound counts as on the bound.
BOUND_RTOL = 1e-3


def bound_notices(space, values) -> list[str]:
    """One sentence per continuous variable whose optimum sits on a bound of its range:
    the optimum there is the bound's, not the objective's (widen the range)."""
    out = []
    for v, x in zip(space.variables, values, strict=True):
        if getattr(v, "is_list", False):
            continue
        tol = BOUND_RTOL * (v.upper - v.lower)
        for side, bound in (("lower", v.lower), ("upper", v.upper)):
            if abs(x - bound) <= tol:
                out.append(f"**On a bound**: `{v.name}` = {x:.5g} is at its {side} "
                           f"bound {bound:g} (within {BOUND_RTOL:g} of its range): the "
                           f"objective may improve beyond it; widen `bounds` if the "
                           f"design allows.")
    return out


def write_report(cfg, space, res, out, backend) -> None:
    """Write ``summary.md``, ``convergence.png`` and ``response.png`` into ``out``."""
    from drymount.design.evaluate import evaluate_design
    from drymount.design.space import current_values
    from drymount.io import atomic_write_text

    o = space.objectives[res.j]
    sign = -1.0 if o.sense == "max" else 1.0
    _plot_convergence(res, sign, out / "convergence.png",
                      f"{cfg.name}: differential evolution + polish", o.unit)
    base = evaluate_design(cfg.data, space, -1, current_values(cfg.data,
                                                               space.variables))
    before, after = compare_designs(cfg, space, res.best.values)
    _plot_response(before, after, out / "response.png",
                   f"{cfg.name}: fundamental amplitude per DOF, as written vs "
                   f"optimum (HBM, H = {space.harmonics})")
    sets = reproduce_options(cfg.data, space, res.best.values)
    lines = [f"# Optimisation: {cfg.name}", "",
             f"Minimised `{o.name}` ({o.sense}, {o.quantity.value}, {o.measure.value}"
             f" over {o.band_hz[0]:g}-{o.band_hz[1]:g} Hz) by differential evolution "
             f"and a Powell polish; {res.n_evaluations} designs in {res.seconds:.0f} s "
             f"on {backend.describe()}. DE: {res.de_message} Polish: "
             f"{res.polish_message}", "",
             f"Best: evaluation {res.best.index} ({res.best.status.value}, feasible "
             f"{res.best.feasible}), `{o.name}` = {res.value:.5g} [{o.unit}]. "
             f"\"As written\" is the configuration without the design changes.", ""]
    notices = bound_notices(space, res.best.values)
    lines += [*notices, ""] if notices else []
    lines += _table_before_after(space, base, res.best) + [""]
    lines += _table_dofs(before, after, cfg.system)
    if sets:
        lines += ["", "Reproduce (a turned mount's orientation as its three rows):", "",
                  f"    drymount hbm {cfg.source} {sets}"]
    lines += ["", "![convergence](convergence.png)", "",
              "![response](response.png)", ""]
    atomic_write_text(out / "summary.md", "\n".join(lines))
