"""Where designs run: serially, on local processes, or on a Dask cluster.

A :class:`Runner` takes chunks of designs (:class:`~drymount.design.evaluate.Task`)
and yields each chunk's results as soon as it is done
(:meth:`Runner.as_completed`). Backends:

- ``serial``: in this process;
- ``processes``: ``concurrent.futures.ProcessPoolExecutor`` with the ``spawn`` start
  method (``--workers N``). The workers ignore SIGINT (the parent handles it), exit
  within a second of their parent's death, and are terminated when the run stops
  early (a signal or an error): no worker outlives the run (docs/cli.md);
- ``dask``: ``dask.distributed``: ``--dask local[:N]`` starts a ``LocalCluster`` of N
  single-threaded worker processes, ``--dask tcp://host:8786`` connects to a running
  scheduler (docs/explore.md: starting ``dask scheduler`` and ``dask worker``).

The work is the same function on the same inputs everywhere, so every backend gives
the same numbers.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from enum import Enum

__all__ = ["BackendKind", "BackendSpec", "BackendError", "Runner", "parse_backend",
           "DASK_INSTALL", "MAX_WORKERS", "CONNECT_TIMEOUT_S"]

DASK_INSTALL = "pip install 'drymount[dask]'  (or: pip install 'dask[distributed]')"
#: Most local processes of ``--workers N`` and ``--dask local:N`` (each one is a
#: Python interpreter with NumPy and SciPy loaded, about 100 MB).
MAX_WORKERS = 256
#: Seconds to reach a Dask scheduler's port (a refused connection fails at once).
CONNECT_TIMEOUT_S = 10.0


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
        if not 1 <= workers <= MAX_WORKERS:
            raise BackendError(f"--workers must be an integer in 1..{MAX_WORKERS}, "
                               f"got {workers}")
        return BackendSpec(BackendKind.PROCESSES if workers > 1 else BackendKind.SERIAL,
                           workers)
    if workers != 1:
        raise BackendError("give either --workers or --dask, not both (with --dask "
                           "the workers are the cluster's: local:N)")
    if dask == "local" or dask.startswith("local:"):
        n = dask.partition(":")[2] or str(os.cpu_count() or 1)
        if not n.isdigit() or not 1 <= int(n) <= MAX_WORKERS:
            raise BackendError(f"--dask local:N needs an integer N in "
                               f"1..{MAX_WORKERS}, "
                               f"got {dask!r}")
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


def _check_reachable(address: str) -> None:
    """BackendError at once if nothing listens at a ``tcp://host:port`` address
    (``distributed.Client`` would retry a refused connection for its whole timeout)."""
    import socket
    from urllib.parse import urlsplit

    parts = urlsplit(address)
    if parts.scheme != "tcp":
        return
    try:
        port = parts.port
    except ValueError:
        port = None
    if not parts.hostname or port is None:
        raise BackendError(f"--dask: {address!r} must read tcp://HOST:PORT, e.g. "
                           f"tcp://10.0.0.5:8786")
    try:
        socket.create_connection((parts.hostname, port), CONNECT_TIMEOUT_S).close()
    except OSError as exc:
        raise BackendError(f"cannot reach the Dask scheduler {address}: "
                           f"{exc.strerror or exc} (start it with `dask scheduler`, "
                           f"docs/explore.md)") from None


def _quiet_dask() -> None:
    """No Dask WARNING lines while a stopped run closes its cluster."""
    import logging

    for name in ("distributed", "tornado", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL)


def _init_design_worker() -> None:
    """A design worker's set-up: the sweep's (SIGINT ignored, exit when the parent
    dies), and tqdm's write lock a thread lock. tqdm's default lock holds a
    multiprocessing RLock, a named semaphore registered with the parent's resource
    tracker: a worker terminated when the run stops (or exiting on its parent's
    death) never unregisters it, and the tracker prints 'There appear to be 1 leaked
    semaphore objects' after the run. A spawned worker's bars share no lock with
    other processes anyway (each process would create its own)."""
    import threading

    from tqdm import tqdm

    from drymount.vehicle.sweep import _init_worker

    _init_worker(None)
    tqdm.set_lock(threading.RLock())


class Runner:
    """Context manager running chunks on a backend (see the module docstring)."""

    def __init__(self, spec: BackendSpec):
        self.spec = spec
        self._pool = self._client = self._cluster = None

    def __enter__(self) -> Runner:
        kind = self.spec.kind
        if kind is BackendKind.PROCESSES:
            import multiprocessing  # here: the CLI's parser reads MAX_WORKERS
            from concurrent.futures import ProcessPoolExecutor

            self._pool = ProcessPoolExecutor(
                max_workers=self.spec.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_init_design_worker)
        elif kind is BackendKind.DASK:
            distributed = _import_distributed()
            if self.spec.address is None:
                self._cluster = distributed.LocalCluster(
                    n_workers=self.spec.workers, threads_per_worker=1, processes=True,
                    # ':0' = a free port: a fixed 8787 fails the start (a warning,
                    # an error under -W error) while another cluster holds it
                    dashboard_address=":0", silence_logs=logging.ERROR)
                self._client = distributed.Client(self._cluster)
            else:
                _check_reachable(self.spec.address)
                try:
                    self._client = distributed.Client(self.spec.address, timeout=30)
                except OSError as exc:
                    raise BackendError(f"cannot reach the Dask scheduler "
                                       f"{self.spec.address}: {exc}") from None
        return self

    def __exit__(self, *exc) -> None:
        if self._pool is not None:
            if exc[0] is None:
                self._pool.shutdown(wait=True)
            else:  # a signal or an error: a running chunk can take minutes
                from drymount.vehicle.sweep import _stop_pool

                _stop_pool(self._pool)  # terminated and reaped, as the sweep's
        if exc[0] is not None and self._client is not None:
            _quiet_dask()
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()

    def as_completed(self, fn: Callable, items: Sequence) -> Iterator:
        """``fn(item)`` for every item, yielded as each finishes (any order)."""
        if self._pool is not None:
            from concurrent.futures import as_completed as futures_completed

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
