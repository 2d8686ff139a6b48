"""Where designs run: serially, on local processes, or on a Dask cluster.

A :class:`Runner` takes chunks of designs (:class:`~drymount.design.evaluate.Task`)
and yields each chunk's results as soon as it is done
(:meth:`Runner.as_completed`). Backends:

- ``serial``: in this process;
- ``processes``: ``concurrent.futures.ProcessPoolExecutor`` with the ``spawn`` start
  method (``--workers N``);
- ``dask``: ``dask.distributed``: ``--dask local[:N]`` starts a ``LocalCluster`` of N
  single-threaded worker processes, ``--dask tcp://host:8786`` connects to a running
  scheduler (docs/explore.md: starting ``dask scheduler`` and ``dask worker``).

The work is the same function on the same inputs everywhere, so every backend gives
the same numbers.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures import as_completed as futures_completed
from dataclasses import dataclass
from enum import Enum

__all__ = ["BackendKind", "BackendSpec", "BackendError", "Runner", "parse_backend",
           "DASK_INSTALL"]

DASK_INSTALL = "pip install 'drymount[dask]'  (or: pip install 'dask[distributed]')"


class BackendError(ValueError):
    """A backend that cannot be used (bad option, dask not installed, no scheduler)."""


class BackendKind(str, Enum):
    SERIAL = "serial"
    PROCESSES = "processes"
    DASK = "dask"


@dataclass(frozen=True)
class BackendSpec:
    """Where to run: ``kind``; ``workers`` (processes or LocalCluster workers);
    ``address`` of a running Dask scheduler (None: start a LocalCluster)."""

    kind: BackendKind = BackendKind.SERIAL
    workers: int = 1
    address: str | None = None

    def describe(self) -> str:
        if self.kind is BackendKind.SERIAL:
            return "serial"
        if self.kind is BackendKind.PROCESSES:
            return f"{self.workers} local processes"
        return (f"Dask scheduler {self.address}" if self.address
                else f"Dask LocalCluster with {self.workers} workers")


def parse_backend(workers: int = 1, dask: str | None = None) -> BackendSpec:
    """The backend of ``--workers N`` and ``--dask local[:N]|tcp://host:port``."""
    if dask is None:
        if workers < 1:
            raise BackendError(f"--workers must be an integer >= 1, got {workers}")
        return BackendSpec(BackendKind.PROCESSES if workers > 1 else BackendKind.SERIAL,
                           workers)
    if workers != 1:
        raise BackendError("give either --workers or --dask, not both (with --dask "
                           "the workers are the cluster's: local:N)")
    if dask == "local" or dask.startswith("local:"):
        n = dask.partition(":")[2] or str(os.cpu_count() or 1)
        if not n.isdigit() or int(n) < 1:
            raise BackendError(f"--dask local:N needs an integer N >= 1, got {dask!r}")
        return BackendSpec(BackendKind.DASK, int(n))
    if "://" in dask:
        return BackendSpec(BackendKind.DASK, 0, dask)
    raise BackendError(f"--dask must be local, local:N or a scheduler address such as "
                       f"tcp://host:8786, got {dask!r}")


def _import_distributed():
    try:
        import distributed
    except ModuleNotFoundError:
        raise BackendError(f"--dask needs dask.distributed, which is not installed: "
                           f"{DASK_INSTALL}") from None
    return distributed


class Runner:
    """Context manager running chunks on a backend (see the module docstring)."""

    def __init__(self, spec: BackendSpec):
        self.spec = spec
        self._pool = self._client = self._cluster = None

    def __enter__(self) -> Runner:
        kind = self.spec.kind
        if kind is BackendKind.PROCESSES:
            self._pool = ProcessPoolExecutor(
                max_workers=self.spec.workers,
                mp_context=multiprocessing.get_context("spawn"))
        elif kind is BackendKind.DASK:
            distributed = _import_distributed()
            if self.spec.address is None:
                self._cluster = distributed.LocalCluster(
                    n_workers=self.spec.workers, threads_per_worker=1, processes=True,
                    # ':0' = a free port: a fixed 8787 fails the start (a warning,
                    # an error under -W error) while another cluster holds it
                    dashboard_address=":0")
                self._client = distributed.Client(self._cluster)
            else:
                try:
                    self._client = distributed.Client(self.spec.address, timeout=30)
                except OSError as exc:
                    raise BackendError(f"cannot reach the Dask scheduler "
                                       f"{self.spec.address}: {exc}") from None
        return self

    def __exit__(self, *exc) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=exc[0] is None, cancel_futures=True)
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()

    def as_completed(self, fn: Callable, items: Sequence) -> Iterator:
        """``fn(item)`` for every item, yielded as each finishes (any order)."""
        if self._pool is not None:
            futures = [self._pool.submit(fn, it) for it in items]
            for fut in futures_completed(futures):
                yield fut.result()
        elif self._client is not None:
            distributed = _import_distributed()
            futures = [self._client.submit(fn, it, pure=False) for it in items]
            for fut in distributed.as_completed(futures):
                yield fut.result()
        else:
            for it in items:
                yield fn(it)
