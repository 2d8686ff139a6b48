"""Pareto front, its plot and the Markdown summary of an exploration."""

from __future__ import annotations

import numpy as np

from drymount.design.evaluate import DesignResult, DesignStatus
from drymount.design.space import DesignSpace

__all__ = ["pareto_mask", "plot_front", "summary_markdown", "oriented"]

#: Rows of the Pareto table in the summary.
SUMMARY_ROWS = 20


def oriented(space: DesignSpace, results) -> np.ndarray:
    """Objectives (n, n_obj) turned into quantities to minimise (``max`` negated)."""
    sign = np.array([-1.0 if o.sense == "max" else 1.0 for o in space.objectives])
    return np.array([r.objectives for r in results], dtype=float).reshape(
        len(results), -1) * sign


def pareto_mask(F: np.ndarray, feasible) -> np.ndarray:
    """Non-dominated rows of ``F`` (minimised) among the ``feasible`` ones with
    finite values: no other feasible row is <= in every objective and < in one."""
    F = np.asarray(F, dtype=float)
    ok = np.asarray(feasible, bool) & np.all(np.isfinite(F), axis=1)
    mask = np.zeros(len(F), dtype=bool)
    idx = np.flatnonzero(ok)
    for i in idx:
        other = F[idx]
        dominated = np.any(np.all(other <= F[i], axis=1) & np.any(other < F[i], axis=1))
        mask[i] = not dominated
    return mask


def _label(metric) -> str:
    return f"{metric.name} [{metric.unit}]"


def plot_front(space: DesignSpace, results, path, title: str) -> None:
    """Scatter of the designs in the plane of the first two objectives (or the first
    objective against the first variable), the Pareto front highlighted."""
    from matplotlib.figure import Figure

    from drymount.io import save_figure

    F = np.array([r.objectives for r in results], dtype=float).reshape(
        len(results), -1)
    feas = np.array([r.feasible for r in results], dtype=bool)
    front = pareto_mask(oriented(space, results), feas)
    fig = Figure(figsize=(7, 5))
    ax = fig.add_subplot()
    if F.shape[1] >= 2:
        x, y = F[:, 0], F[:, 1]
        ax.set_xlabel(_label(space.objectives[0]))
        ax.set_ylabel(_label(space.objectives[1]))
    else:
        x = np.array([r.values[0] for r in results], dtype=float)
        y = F[:, 0]
        ax.set_xlabel(space.variables[0].name)
        ax.set_ylabel(_label(space.objectives[0]))
    ax.plot(x[~feas], y[~feas], "x", color="0.6", ms=5, label="infeasible or failed")
    ax.plot(x[feas], y[feas], ".", color="tab:blue", ms=6, label="feasible")
    order = np.argsort(x[front])
    ax.plot(x[front][order], y[front][order], "o-", color="tab:red", ms=7, mfc="none",
            label=f"Pareto front ({int(front.sum())} designs)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)


def _md_table(header, rows) -> str:
    def cell(v):
        return f"{v:.5g}" if isinstance(v, float) else str(v)

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in r) + " |" for r in rows]
    return "\n".join(lines)


def _checks_markdown(checks, space: DesignSpace) -> list[str]:
    if not checks:
        return []
    o = space.objectives[0]
    rows = [[c.index, c.objective, 100 * c.max_error, c.worst, c.converged,
             c.seconds] for c in checks]
    return ["", f"## Co-simulated check of the {len(checks)} best designs", "",
            f"Stepped-sine sweep (in-process mount law) over {o.band_hz[0]:g}-"
            f"{o.band_hz[1]:g} Hz against the HBM solution of the same branch (H = "
            f"{space.harmonics}); error = |co-simulated - HBM| fundamental amplitude "
            f"over the DOF's HBM peak, on stable points.", "",
            _md_table(["design", f"{o.name} [{o.unit}]", "max error [%]", "where",
                       "converged", "seconds"], rows)]


def summary_markdown(space: DesignSpace, results: list[DesignResult], info: dict
                     ) -> str:
    """The Markdown summary: the space, counts by status, best design per objective
    and the Pareto designs."""
    counts = {s.value: sum(r.status is s for r in results) for s in DesignStatus}
    feas = [r for r in results if r.feasible]
    front = pareto_mask(oriented(space, results), [r.feasible for r in results])
    names = space.names
    head = ["design", *names["variables"], *[_label(o) for o in space.objectives],
            *[f"{c.name} margin [{c.unit}]" for c in space.constraints]]

    def row(r):
        return [r.index, *r.values, *r.objectives, *r.margins]

    lines = [f"# Design exploration: {info['name']}", "",
             f"Configuration `{info['source']}`; {space.method.value} sample of "
             f"{len(results)} designs (seed {space.seed}); HBM with H = "
             f"{space.harmonics} over {space.band_hz[0]:g}-{space.band_hz[1]:g} Hz per "
             f"design; backend: {info['backend']}; {info['seconds']:.1f} s "
             f"({info['rate']:.3g} designs/s this run, after the backend's "
             f"start-up).", "",
             "Variables: " + "; ".join(
                 f"`{v.name}` in " + (str(list(v.values)) if v.is_list
                                      else f"[{v.lower:g}, {v.upper:g}]")
                 for v in space.variables) + ".", "",
             "Designs by status: " + ", ".join(f"{k} {n}" for k, n in counts.items())
             + f"; feasible {len(feas)}.", ""]
    for j, o in enumerate(space.objectives):
        cands = [r for r in feas if np.isfinite(r.objectives[j])]
        if cands:
            pick = (max if o.sense == "max" else min)(cands,
                                                      key=lambda r: r.objectives[j])
            unit = "" if o.unit == "-" else f" {o.unit}"
            lines.append(f"- best `{o.name}` ({o.sense}): {pick.objectives[j]:.5g}"
                         f"{unit} at design {pick.index}: " + ", ".join(
                             f"{n} = {v:.5g}" for n, v in
                             zip(names["variables"], pick.values, strict=True)))
    lines += _checks_markdown(info.get("checks", []), space)
    shown = [r for r, m in zip(results, front, strict=True) if m][:SUMMARY_ROWS]
    lines += ["", f"## Pareto front ({int(front.sum())} designs)", "",
              _md_table(head, [row(r) for r in shown]), "",
              f"Files: `{info['table']}` (every design), `{info['plot']}`.", "",
              f"![Pareto front]({info['plot']})", ""]
    return "\n".join(lines)
