"""Which Jenkins march runs under ``"auto"``: NumPy until the compiled one pays.

numba (the ``fast`` extra) marches 3-15x faster per call, but a fresh process pays
about 1 s CPU to import it and load its cached kernels, and several seconds to compile
them where no cache exists yet (a new machine or a new numba). One small curve marches
for less than that in total (issue 27: 0.51 s end to end with NumPy against 1.12 s
with numba at N = 64). The choice is therefore made by the work done, as in the
ski-rental problem:

- every call runs the NumPy march and adds its CPU time to :attr:`AutoMarch.spent_s`;
- once ``spent_s`` reaches what numba's start costs with a warm cache (the larger of
  :data:`WARM_START_S` and :data:`START_RATIO` times the process's start-up CPU time,
  which a loaded machine inflates alike) and the cache is warm, numba is imported and
  every later call is compiled; a process whose marches cost less never imports
  numba, so the ``fast`` extra never makes it slower
  (``bench/bench_numba_start.py``), and a long one pays at most about twice the best
  choice;
- a big march (:data:`BIG_MARCH` samples x columns or more: a 6-DOF problem at
  N = 1024) goes compiled at once when the cache is warm; such a problem's curve
  repays numba's start many times over (issue 27, item 3);
- a cold cache (no compiled kernels beside :mod:`hbm.friction_march_numba`, or under
  ``$NUMBA_CACHE_DIR``) is warmed in the background: once ``spent_s`` reaches
  :data:`WARMUP_AFTER_S`, one detached low-priority process compiles the kernels into
  the cache while this one goes on with NumPy, and switches when the cache is warm.

Both marches give the same numbers bit for bit (``tests/test_hbm_friction_march.py``),
so the switch changes no result. numba already imported in the process (its start
paid) is used at once.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

__all__ = ["AutoMarch", "WARM_START_S", "WARMUP_AFTER_S", "cache_is_warm",
           "start_warmup"]

#: NumPy march time (s) after which numba's start (warm cache) has paid for itself,
#: on an idle machine (0.7-1.0 s measured, issue 27) ...
WARM_START_S = 1.0
#: ... and as a multiple of the process's own CPU time before its first march (its
#: imports of NumPy, SciPy and drymount, about 0.6 s idle): numba's start is imports
#: too, and a busy machine slows both alike. The larger of the two counts, at most
#: MAX_START_S (a long-lived process, a notebook, has spent much more before).
START_RATIO = 1.5
MAX_START_S = 5.0
#: NumPy march time (s) after which a cold cache is compiled in the background.
WARMUP_AFTER_S = 0.25
#: A march of at least this many samples x columns (x batch) takes the compiled path
#: at once when the cache is warm (and starts the background compile when it is
#: not): at that size a NumPy march costs 8-10x the compiled one (6-DOF, N = 1024:
#: 200-250 us against 24 us), the compiled AFT also saves the elastic remainders and
#: the slip memory (0.3 ms per residual in all), and numba's start (0.5 s CPU with a
#: warm cache) is repaid within 1500-2500 residuals, a fraction of any curve of
#: such a problem (4100 on the 6-DOF curve at H = 7; issue 27, item 3).
BIG_MARCH = 2048
#: The compiled entry points whose cache indices make a warm cache.
KERNELS = ("_march", "_samples", "_march_samples", "_aft_samples", "_slip_memory")
_SOURCE = Path(__file__).resolve().parent / "friction_march_numba.py"
_MODULE = "drymount.hbm.friction_march_numba"


def _cache_dirs() -> list[Path]:
    """Where numba keeps the kernels: under ``$NUMBA_CACHE_DIR`` when it is set
    (numba then looks nowhere else), else beside the source."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if root:
        return sorted({p.parent for p in Path(root).rglob(f"{_SOURCE.stem}.*.nbi")})
    return [_SOURCE.parent / "__pycache__"]


def cache_is_warm() -> bool:
    """Whether numba's cache holds every kernel, newer than their source."""
    stamp = _SOURCE.stat().st_mtime
    for name in KERNELS:
        found = [p for d in _cache_dirs()
                 for p in d.glob(f"{_SOURCE.stem}.{name}-*.nbi")]
        if not any(p.stat().st_mtime >= stamp for p in found):
            return False
    return True


def start_warmup() -> subprocess.Popen | None:
    """Compile the kernels into numba's cache in a detached low-priority process
    (its output discarded); None if it could not start."""
    code = f"import os; os.nice(10); import {_MODULE} as m; m.warm()"
    try:
        return subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)
    except OSError:
        return None


class AutoMarch:
    """The per-process choice of ``"auto"``: :meth:`choose` before a march,
    :meth:`spent` after a NumPy one."""

    def __init__(self, have_numba: bool, warm_start_s: float = WARM_START_S,
                 warmup_after_s: float = WARMUP_AFTER_S, warmup: bool = True,
                 scale_by_start: bool = True):
        self.have_numba = have_numba
        self.scaled = None if scale_by_start else False
        self.warm_start_s = warm_start_s
        self.warmup_after_s = warmup_after_s
        self.warmup = warmup
        self.spent_s = 0.0
        self.compiled = False
        self.warming: subprocess.Popen | None = None
        self._next_check = warm_start_s
        #: whether big marches go compiled at once (None: not asked yet)
        self.big: bool | None = None
        #: the cache was found warm (no warm-up to start)
        self.found_warm = False

    def choose(self, size: int = 0) -> str:
        """``"numba"`` once it pays (or is loaded already, or the march of ``size``
        samples x columns is at least :data:`BIG_MARCH` and the cache warm), else
        ``"numpy"``."""
        if self.compiled:
            return "numba"
        if not self.have_numba:
            return "numpy"
        if size >= BIG_MARCH and self.big is not False:
            if self.big is None:   # decided once: the cache's state at the first one
                self.big = cache_is_warm()
                if not self.big and self.warmup and self.warming is None:
                    self.warming = start_warmup() or False
            if self.big:
                self.compiled = True
                return "numba"
        if self.scaled is None:  # the first march: scale by the start-up's cost
            self.scaled = True
            start = min(START_RATIO * self.clock(), MAX_START_S)
            self.warm_start_s = max(self.warm_start_s, start)
            self._next_check = self.warm_start_s
        if _MODULE in sys.modules:  # its start is paid
            self.compiled = True
            return "numba"
        if self.spent_s >= self._next_check:
            self._next_check = self.spent_s + 0.25 * self.warm_start_s
            if self.spent_s >= self.warm_start_s and self._warm():
                self.compiled = True
                return "numba"
        return "numpy"

    def spent(self, seconds: float) -> None:
        """Add the time of one NumPy march; start the warm-up when it is due."""
        self.spent_s += seconds
        if (self.warmup and self.warming is None and self.have_numba
                and self.spent_s >= self.warmup_after_s and not self.compiled
                and not self.found_warm):
            # asked once: a warm cache was globbed for at every later march
            # (8000 times, 2-4 s CPU of a default 6-DOF curve)
            if cache_is_warm():
                self.found_warm = True
            else:
                self.warming = start_warmup() or False

    def _warm(self) -> bool:
        if self.warming:  # the background compile still running: not yet
            if self.warming.poll() is None:
                return False
        return cache_is_warm()

    @staticmethod
    def clock() -> float:
        """CPU seconds of this process (a busy machine inflates them less than
        wall time)."""
        return time.process_time()
