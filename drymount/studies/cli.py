"""The command ``drymount study NAME --out DIR [--quick]`` (and
``python -m drymount.studies NAME``)."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from enum import IntEnum
from pathlib import Path

from drymount.studies.hydraulic import run_hydraulic
from drymount.studies.incline import run_incline
from drymount.studies.jump import run_jump
from drymount.studies.laws import run_laws
from drymount.studies.normal_force import run_normal_force
from drymount.studies.optimize_n0 import run_optimize_n0
from drymount.studies.quarter_car import run_quarter_car
from drymount.studies.semi_active import run_semi_active
from drymount.studies.six_dof import run_six_dof
from drymount.studies.six_dof_75 import run_six_dof_75

STUDIES: dict[str, Callable[..., dict]] = {
    "normal-force": run_normal_force,
    "optimize-n0": run_optimize_n0,
    "quarter-car": run_quarter_car,
    "six-dof": run_six_dof,
    "jump": run_jump,
    "laws": run_laws,
    "six-dof-75": run_six_dof_75,
    "incline": run_incline,
    "semi-active": run_semi_active,
    "hydraulic": run_hydraulic,
}


class ExitStatus(IntEnum):
    """Exit status of ``drymount study``."""

    OK = 0
    #: a curve did not complete (what was computed is written anyway)
    INCOMPLETE = 1
    #: unknown study name
    USAGE = 2


def main(args) -> int:
    """Run study ``args.name`` into ``args.out``: ``drymount study NAME --out DIR``.

    ``args.quick`` (optional, default False) selects quick mode. Prints where the
    summary is. Returns an :class:`ExitStatus`.
    """
    name = args.name
    if name not in STUDIES:
        print(f"error: unknown study {name!r}; choose one of {', '.join(STUDIES)}",
              file=sys.stderr)
        return ExitStatus.USAGE
    out = Path(args.out if getattr(args, "out", None) else f"study-{name}")
    quick = bool(getattr(args, "quick", False))
    t0 = time.perf_counter()
    result = STUDIES[name](out, quick=quick)
    dt = time.perf_counter() - t0
    print(f"study {name}: {len(result['files'])} files in {out} ({dt:.1f} s); "
          f"summary: {out / 'summary.md'}")
    if result["failures"]:
        print(f"study {name}: {len(result['failures'])} curve(s) did not complete:",
              file=sys.stderr)
        for f in result["failures"]:
            print(f"  {f}", file=sys.stderr)
        return ExitStatus.INCOMPLETE
    return ExitStatus.OK


def parser() -> argparse.ArgumentParser:
    """Arguments of ``python -m drymount.studies``."""
    p = argparse.ArgumentParser(prog="python -m drymount.studies",
                                description="the thesis's design studies (Chapter 4)")
    p.add_argument("name", choices=list(STUDIES))
    p.add_argument("--out", default=None)
    p.add_argument("--quick", action="store_true")
    return p
