"""``drymount optimize``: differential evolution on the design space, then a polish.

One objective of ``[design]`` (the first, or the one named) is minimised (``sense =
"max"``: maximised) over the variables' bounds; list variables are integer indices
into their lists (``integrality``). Constraints enter as a penalty that puts every
infeasible design behind every feasible one (Deb's feasibility rule, as a scalar):

    f(x) = objective                          (status ok, every margin >= 0)
    f(x) = PENALTY + sum(max(0, -margin_k) / scale_k)   (violated constraints;
                                            scale = |max|, 1 mm for a box)
    f(x) = 2 PENALTY                          (invalid configuration, failed curve)

so that :func:`scipy.optimize.differential_evolution` can evaluate a whole generation
on a backend at once (``workers=`` a map over chunks, ``updating="deferred"``). The
best design is then polished by :func:`scipy.optimize.minimize` (Powell, bounded,
derivative-free: the HBM peak is not smooth to finite-difference accuracy) over the
continuous variables. Every evaluation is appended to ``history.csv`` as it comes.
"""

from __future__ import annotations

import csv
import inspect
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution, minimize

from drymount.design.backends import BackendSpec, Runner
from drymount.design.evaluate import DesignResult, DesignStatus, evaluate_chunk
from drymount.design.exploration import chunks
from drymount.design.space import DesignSpace
from drymount.design.table import (TableError, columns, fingerprint, parse_row,
                                   table_row)

__all__ = ["OptimizeResult", "OptimizeSettings", "optimize", "PENALTY"]

#: Penalty base of an infeasible design (above any objective value of a mount).
PENALTY = 1e6
HISTORY_NAME = "history.csv"


@dataclass(frozen=True)
class OptimizeSettings:
    """Settings of :func:`optimize` (scipy's names).

    ``popsize`` is per variable (scipy's multiplier); ``maxiter`` generations; ``tol``
    relative convergence of the population; ``polish_maxfev`` evaluations of the Powell
    polish (0: no polish); ``xtol`` its step tolerance as a fraction of each range."""

    objective: str | None = None
    maxiter: int = 30
    popsize: int = 10
    tol: float = 1e-3
    seed: int | None = None
    polish_maxfev: int = 60
    xtol: float = 1e-3


@dataclass(frozen=True)
class OptimizeResult:
    """Best design, the history, what stopped the search.

    Attributes
    ----------
    best : DesignResult
    objective : str
    j : int
        Index of the objective in ``DesignSpace.objectives``.
    value : float
        Best objective value (in its own sense).
    history : list of (phase, DesignResult)
    de_message, polish_message : str
    n_evaluations : int
    seconds : float
    files : tuple of Path
    resumed : int
        Evaluations read back from an earlier (interrupted) run's history.
    """

    best: DesignResult
    objective: str
    j: int
    value: float
    history: list
    de_message: str
    polish_message: str
    n_evaluations: int
    seconds: float
    files: tuple
    resumed: int = 0


class _Problem:
    """x -> penalised objective, evaluated on a backend, recorded in the history."""

    def __init__(self, cfg, space: DesignSpace, j: int, runner: Runner, path: Path,
                 progress: bool, total: int):
        self.cfg, self.space, self.j, self.runner = cfg, space, j, runner
        self.sign = -1.0 if space.objectives[j].sense == "max" else 1.0
        self.history: list = []
        fp = fingerprint(cfg.data, space)
        #: evaluations of an earlier run of this configuration and space, by values
        self.resumed = read_history(path, space, fp) if path.exists() else {}
        self.cache: dict = {}
        self.phase = "de"
        self.scale = [max(abs(getattr(c, "limit", 0.0)), 1e-12) if math.isfinite(
            getattr(c, "limit", math.nan)) else 1e-3 for c in space.constraints]
        self.path = path
        self._head = (f"# drymount optimize of {cfg.source}; fingerprint {fp}: every "
                      f"evaluation; "
                      f"objective {space.objectives[j].name} "
                      f"({space.objectives[j].sense}); design = evaluation number\n")
        self._fh = open(path, "w", encoding="utf-8", newline="")
        self._w = csv.writer(self._fh, lineterminator="\n")
        self._fh.write(self._head)
        self._w.writerow(["phase", *columns(space)])
        from tqdm import tqdm

        self.bar = tqdm(total=total, unit="design", desc="optimize",
                        disable=not progress, file=sys.stderr)
        self.n_resumed = 0

    def decode(self, x) -> tuple:
        out = []
        for v, xi in zip(self.space.variables, x, strict=True):
            out.append(float(v.values[int(round(xi))]) if v.is_list else float(xi))
        return tuple(out)

    def penalised(self, r: DesignResult) -> float:
        if r.status is not DesignStatus.OK or not np.isfinite(r.objectives[self.j]):
            return 2 * PENALTY
        viol = [max(0.0, -m) / s for m, s in zip(r.margins, self.scale, strict=True)]
        if any(v > 0 or not np.isfinite(v) for v in viol):
            return PENALTY + float(np.nansum(viol))
        return self.sign * r.objectives[self.j]

    def evaluate(self, xs) -> list[float]:
        todo, arrived = [], []
        keys = [self.decode(x) for x in xs]
        for k in dict.fromkeys(keys):
            if k in self.cache:
                continue
            if k in self.resumed:  # evaluated by the interrupted run: replayed
                _, r = self.resumed.pop(k)
                self.cache[k] = r
                self._w.writerow([self.phase, *table_row(r)])
                arrived.append(r)
                self.n_resumed += 1
                continue
            todo.append((len(self.history) + len(arrived) + len(todo), k))
        self.bar.update(len(arrived))
        tasks = chunks(self.space, self.cfg.data, self.cfg.source, self.cfg.name, todo)
        for results in self.runner.as_completed(evaluate_chunk, tasks):
            for r in results:
                self.cache[r.values] = r
                self._w.writerow([self.phase, *table_row(r)])
            arrived += results
            self._fh.flush()
            self.bar.update(len(results))
        self.history += [(self.phase, r) for r in sorted(arrived,
                                                          key=lambda r: r.index)]
        return [self.penalised(self.cache[k]) for k in keys]

    def map(self, func, xs):  # differential_evolution's ``workers``
        return self.evaluate(list(xs))

    def close(self, partial: str | None = None) -> None:
        """Close the history and rewrite it ordered by evaluation number (rows of a
        generation arrive in any order from parallel workers); with ``partial`` (why
        the run stopped) its first line is ``# partial: <partial>``. Evaluations of
        an earlier run that this one did not replay are kept at the end."""
        import io

        from drymount.io import PARTIAL_PREFIX, atomic_write_text

        self._fh.close()
        buf = io.StringIO()
        if partial is not None:
            buf.write(f"{PARTIAL_PREFIX}{partial}\n")
        buf.write(self._head)
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["phase", *columns(self.space)])
        for phase, r in self.history:
            w.writerow([phase, *table_row(r)])
        for phase, r in self.resumed.values():
            w.writerow([phase, *table_row(r)])
        atomic_write_text(self.path, buf.getvalue())
        if partial is None:  # the total was an estimate: the run ends at 100 %
            self.bar.total = self.bar.n
            self.bar.refresh()
        self.bar.close()


def read_history(path: Path, space: DesignSpace, fp: str) -> dict:
    """``values -> (phase, DesignResult)`` of the complete rows of an earlier
    ``history.csv`` of the same configuration and space (fingerprint ``fp``);
    TableError if it is another optimization's."""
    import io

    lines = Path(path).read_text(encoding="utf-8").splitlines(keepends=True)
    if lines and lines[0].startswith("# partial: "):
        lines = lines[1:]
    if not lines or f"fingerprint {fp}:" not in lines[0]:
        raise TableError(f"{path} is not a history of this optimization (another "
                         f"configuration or [design], or not written by drymount "
                         f"optimize); choose another --out folder")
    rows = list(csv.reader(io.StringIO("".join(ln for ln in lines[1:]
                                               if ln.endswith("\n")))))
    head = ["phase", *columns(space)]
    if not rows or rows[0] != head:
        raise TableError(f"{path}: its columns differ from this design space's")
    out = {}
    for row in rows[1:]:
        if len(row) == len(head):  # not a row cut by an interruption
            r = parse_row(space, row[1:])
            out.setdefault(r.values, (row[0], r))
    return out


def _de_kwargs(seed) -> dict:
    params = inspect.signature(differential_evolution).parameters
    return {"rng": seed} if "rng" in params else {"seed": seed}


def _run(prob: _Problem, space: DesignSpace, s: OptimizeSettings):
    bounds, integrality = [], []
    for v in space.variables:
        bounds.append((0, len(v.values) - 1) if v.is_list else (v.lower, v.upper))
        integrality.append(v.is_list)
    seed = space.seed if s.seed is None else s.seed
    de = differential_evolution(
        lambda x: prob.evaluate([x])[0], bounds, maxiter=s.maxiter, popsize=s.popsize,
        tol=s.tol, polish=False, workers=prob.map, updating="deferred",
        integrality=integrality if any(integrality) else None,
        init="latinhypercube", **_de_kwargs(seed))
    x_best = np.asarray(de.x, dtype=float)
    cont = [i for i, v in enumerate(space.variables) if not v.is_list]
    polish_msg = "no polish (no continuous variable or polish_maxfev = 0)"
    if cont and s.polish_maxfev > 0:
        prob.phase = "polish"

        def g(z):
            x = x_best.copy()
            x[cont] = z
            return prob.evaluate([x])[0]

        lo = np.array([bounds[i][0] for i in cont])
        hi = np.array([bounds[i][1] for i in cont])
        pol = minimize(g, x_best[cont], method="Powell", bounds=list(zip(lo, hi,
                                                                         strict=True)),
                       options={"xtol": s.xtol, "ftol": 1e-6,
                                "maxfev": s.polish_maxfev})
        polish_msg = str(pol.message)
    return de, polish_msg


def optimize(cfg, space: DesignSpace, out_dir, backend: BackendSpec | None = None,
             settings: OptimizeSettings | None = None,
             progress: bool = True) -> OptimizeResult:
    """Minimise one objective of ``space`` for ``cfg`` (see the module docstring).

    Writes ``history.csv`` (every evaluation, as it comes) and ``summary.md`` into
    ``out_dir``. Raises ValueError for an unknown objective name.
    """
    backend = backend or BackendSpec()
    settings = settings or OptimizeSettings()
    names = [o.name for o in space.objectives]
    name = settings.objective or names[0]
    if name not in names:
        raise ValueError(f"--objective must be one of {', '.join(names)}, got {name!r}")
    j = names.index(name)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    with Runner(backend) as runner:
        n = len(space.variables)
        total = (settings.maxiter + 1) * settings.popsize * n + settings.polish_maxfev
        prob = _Problem(cfg, space, j, runner, out / HISTORY_NAME, progress, total)
        try:
            de, polish_msg = _run(prob, space, settings)
        except BaseException as exc:
            from drymount.cli_guard import stop_reason

            prob.close(partial=f"{stop_reason(exc)}; {len(prob.history)} "
                               f"evaluations before the run stopped (run again with "
                               f"the same --out to resume)")
            raise
        prob.close()
    seconds = time.perf_counter() - t0
    best = min((r for _, r in prob.history), key=prob.penalised)
    res = OptimizeResult(best, name, j, best.objectives[j], prob.history,
                         str(de.message), polish_msg, len(prob.history), seconds,
                         (out / HISTORY_NAME, out / "summary.md"), prob.n_resumed)
    from drymount.design.report_optimize import write_report

    write_report(cfg, space, res, out, backend)
    return res
