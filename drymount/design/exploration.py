"""``drymount explore``: evaluate a sample of the design space, stream a table.

:func:`explore` samples the space (:mod:`drymount.design.sampling`), leaves out the
designs a resumed table already holds, sends the rest in chunks to a backend
(:mod:`drymount.design.backends`), appends each chunk's rows to ``designs.csv`` as it
arrives, and finally writes the table ordered by design, ``pareto.png`` and
``summary.md`` into the output folder.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path

from drymount.design.backends import BackendKind, BackendSpec, Runner
from drymount.design.evaluate import DesignResult, Task, evaluate_chunk
from drymount.design.report import plot_front, summary_markdown
from drymount.design.sampling import sample
from drymount.design.space import DesignSpace
from drymount.design.table import ResultsTable, fingerprint, read_table

__all__ = ["ExploreResult", "explore", "TABLE_NAME", "PLOT_NAME", "SUMMARY_NAME"]

TABLE_NAME = "designs.csv"
PLOT_NAME = "pareto.png"
SUMMARY_NAME = "summary.md"
CHECK_NAME = "cosim_check.csv"


@dataclass(frozen=True)
class ExploreResult:
    """What :func:`explore` did.

    Attributes
    ----------
    results : list of DesignResult
        Every design, ordered by number (resumed ones included).
    resumed : int
        Designs read back from an existing table.
    seconds : float
        Wall time of this run's designs, from the moment the backend was up (process
        pool or cluster start-up excluded).
    files : tuple of Path
    """

    results: list
    resumed: int
    seconds: float
    files: tuple

    @property
    def rate(self) -> float:
        """Designs evaluated per second in this run."""
        n = len(self.results) - self.resumed
        return n / self.seconds if self.seconds > 0 else float("nan")


def chunks(space: DesignSpace, doc: dict, source: str, name: str, todo) -> list[Task]:
    """``todo`` ((index, values) pairs) cut into tasks of ``space.chunk`` designs."""
    todo = list(todo)
    return [Task(doc, source, name, space, tuple(todo[i:i + space.chunk]))
            for i in range(0, len(todo), space.chunk)]


def explore(cfg, space: DesignSpace, out_dir, backend: BackendSpec | None = None,
            progress: bool = True, check_best: int = 0) -> ExploreResult:
    """Evaluate every design of ``space`` for configuration ``cfg`` (module docstring).

    An existing ``designs.csv`` of the same configuration and space is resumed: its
    rows are kept and only the missing designs run. A table of another exploration
    raises :class:`drymount.design.table.TableError` (nothing is overwritten).
    ``check_best`` > 0 co-simulates that many of the best feasible designs
    (:mod:`drymount.design.cosim_check`) into ``cosim_check.csv`` and the summary.
    """
    backend = backend or BackendSpec()
    out = Path(out_dir)
    table_path = out / TABLE_NAME
    fp = fingerprint(cfg.data, space)
    done = read_table(table_path, space, fp) if table_path.exists() else []
    have = {r.index for r in done}
    X = sample(space)
    todo = [(i, tuple(x)) for i, x in enumerate(X) if i not in have]
    table = ResultsTable(table_path, space, cfg.source, fp, done)
    t0 = time.perf_counter()
    try:
        if todo:  # a complete table needs no pool or cluster
            with Runner(backend) as runner, _bar(len(X), len(done), progress) as bar:
                t0 = time.perf_counter()  # after the pool / cluster started
                tasks = chunks(space, cfg.data, cfg.source, cfg.name, todo)
                for k, results in enumerate(runner.as_completed(evaluate_chunk, tasks)):
                    table.add(results)
                    bar.update(len(results))
                    if k == 0:  # the first chunk measures the cost of a design
                        bar.write(expected_duration(
                            time.perf_counter() - t0, len(results), len(todo),
                            backend), file=sys.stderr)
    finally:
        table.close()
    seconds = time.perf_counter() - t0
    results: list[DesignResult] = table.finish()
    res = ExploreResult(results, len(done), seconds, ())
    plot = out / PLOT_NAME
    plot_front(space, results, plot, f"{cfg.name}: {len(results)} designs, "
                                     f"{space.method.value} sample")
    info = {"name": cfg.name, "source": cfg.source, "backend": backend.describe(),
            "seconds": seconds, "rate": res.rate, "table": TABLE_NAME,
            "plot": PLOT_NAME, "checks": []}
    files = [table_path, plot, out / SUMMARY_NAME]
    if check_best > 0:
        info["checks"] = _checks(cfg, space, results, check_best, out, progress)
        files.append(out / CHECK_NAME)
    from drymount.io import atomic_write_text

    atomic_write_text(out / SUMMARY_NAME, summary_markdown(space, results, info))
    return ExploreResult(results, len(done), seconds, tuple(files))


def expected_duration(seconds: float, n_first: int, n_todo: int,
                      backend: BackendSpec) -> str:
    """The line announcing how long the run takes, from its first chunk: ``n_first``
    designs took ``seconds`` on one worker, the ``n_todo`` designs share the
    backend's workers (a remote Dask cluster's are unknown: one worker's pace)."""
    per_design = seconds / max(n_first, 1)
    remote = backend.kind is BackendKind.DASK and backend.address is not None
    parallel = 1 if remote or backend.kind is BackendKind.SERIAL else backend.workers
    total = seconds + per_design * max(n_todo - n_first, 0) / parallel
    pace = ("at one worker's pace; divide by the cluster's workers" if remote
            else f"on {backend.describe()}")
    return (f"explore: expected duration at most about {_human(total)} for {n_todo} "
            f"designs ({per_design:.3g} s per design, measured on the first "
            f"{n_first}, start-up included; {pace})")


def _human(seconds: float) -> str:
    """``42 s``, ``3.5 min``, ``2.1 h``, ``4.3 days``."""
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.2g} {unit}" if seconds < 10 * size else \
                f"{seconds / size:.0f} {unit}"
    return f"{seconds:.2g} s" if seconds < 10 else f"{seconds:.0f} s"


def _checks(cfg, space, results, k: int, out: Path, progress: bool) -> list:
    from dataclasses import astuple, fields

    from drymount.design.cosim_check import CheckResult, cosim_check
    from drymount.io import write_csv

    checks = cosim_check(cfg, space, results, k, progress)
    write_csv(out / CHECK_NAME, [f.name for f in fields(CheckResult)],
              [astuple(c) for c in checks],
              comment="co-simulated check of the best designs: max_error = largest "
                      "|cosim - HBM| fundamental amplitude / the DOF's HBM peak [-]")
    return checks


def _bar(total: int, initial: int, progress: bool):
    """A tqdm bar of designs done with the estimated time left."""
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, unit="design", desc="explore",
                disable=not progress, file=sys.stderr, smoothing=0.1)
