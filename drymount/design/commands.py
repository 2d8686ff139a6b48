"""The ``explore`` and ``optimize`` commands of the ``drymount`` CLI.

:func:`add_commands` adds both subparsers (called by :func:`drymount.cli.build_parser`);
:func:`cmd_explore` and :func:`cmd_optimize` run them.
"""

from __future__ import annotations

import sys
from pathlib import Path

from drymount.cli_guard import check_out_dir

#: Bounds of optimize's --maxiter and --popsize (listed in its --help).
MAX_MAXITER = 10_000
MAX_POPSIZE = 1_000

__all__ = ["add_commands", "cmd_explore", "cmd_optimize"]


def _backend_args(p, int_at_least) -> None:
    from drymount.design.backends import MAX_WORKERS

    p.add_argument("--workers", type=int_at_least(1, MAX_WORKERS), default=1,
                   help=f"local processes evaluating designs, 1..{MAX_WORKERS}")
    p.add_argument("--dask", default=None, metavar="local[:N]|tcp://HOST:PORT",
                   help=f"run on Dask: `local:N` starts a LocalCluster of N workers "
                        f"(1..{MAX_WORKERS}), "
                        "an address uses a running `dask scheduler` (docs/explore.md); "
                        "needs pip install 'drymount[dask]'")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")


def add_commands(sub, add, config_arg, int_at_least) -> None:
    """Add ``explore`` and ``optimize`` to the subparsers ``sub`` (``add`` and
    ``config_arg`` are the CLI's helpers)."""
    p = add(sub, "explore", "sample the [design] space: one HBM curve per design",
            """\
            Evaluate a grid, Latin hypercube or Sobol sample of the [design] section
            of CONFIG (docs/explore.md): one harmonic-balance curve per design, its
            objectives and constraint margins. Writes OUT/designs.csv (every design,
            rows appended as they finish), OUT/pareto.png and OUT/summary.md. Run it
            again with the same OUT to resume an interrupted exploration.""",
            ["drymount explore examples/design/sdof_n0.toml --out sdof-n0",
             "drymount explore examples/design/sdof_n0.toml --out sdof-n0 --workers 2",
             "drymount explore my_engine.toml --dask tcp://10.0.0.5:8786 --out big"])
    config_arg(p)
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: explore-<name>)")
    p.add_argument("--cosim-check", type=int_at_least(0), default=0, metavar="K",
                   help="co-simulate the K best feasible designs against their HBM "
                        "curves (OUT/cosim_check.csv)")
    _backend_args(p, int_at_least)
    p = add(sub, "optimize", "differential evolution on the [design] space",
            """\
            Minimise one objective of the [design] section of CONFIG under its
            constraints: scipy differential evolution over the variables' bounds
            (list variables as integers), then a bounded Powell polish. Writes
            OUT/history.csv (every evaluation, as it comes), OUT/summary.md (the
            optimum, its constraint margins, per-DOF peaks before and after, the
            --set options that reproduce it) and plots.""",
            ["drymount optimize examples/design/sdof_n0.toml --objective peak_T",
             "drymount optimize examples/design/six_dof_layout.toml --workers 2 "
             "--out layout"])
    config_arg(p)
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default: optimize-<name>)")
    p.add_argument("--objective", default=None,
                   help="name of the objective to minimise (default: the first)")
    p.add_argument("--maxiter", type=int_at_least(1, MAX_MAXITER), default=30,
                   help=f"differential-evolution generations, 1..{MAX_MAXITER}")
    p.add_argument("--popsize", type=int_at_least(2, MAX_POPSIZE), default=10,
                   help=f"population per variable (scipy's popsize), 2..{MAX_POPSIZE}")
    p.add_argument("--seed", type=int_at_least(0), default=None,
                   help="random seed (default: [design] seed)")
    p.add_argument("--polish", type=int_at_least(0), default=60, metavar="MAXFEV",
                   help="evaluations of the Powell polish (0: none)")
    _backend_args(p, int_at_least)


def _setup(args, load, usage_error):
    from drymount.design.backends import BackendError, parse_backend
    from drymount.design.check import design_space

    cfg = load(args.config, args.overrides)
    space = design_space(cfg)
    try:
        backend = parse_backend(args.workers, args.dask)
    except BackendError as exc:
        raise usage_error(str(exc)) from None
    return cfg, space, backend


def cmd_explore(args, load, usage_error) -> int:
    cfg, space, backend = _setup(args, load, usage_error)
    out = args.out or Path(f"explore-{cfg.name}")
    check_out_dir(out, "--out")
    from drymount.design.backends import BackendError  # scipy.stats: after the checks
    from drymount.design.exploration import explore
    from drymount.design.table import TableError

    print(f"{cfg.name}: {space.size()} designs ({space.method.value}), "
          f"{len(space.variables)} variables, on {backend.describe()}", file=sys.stderr)
    try:
        res = explore(cfg, space, out, backend, progress=not args.quiet,
                      check_best=args.cosim_check)
    except (BackendError, TableError) as exc:
        raise usage_error(str(exc)) from None
    n_ok = sum(r.status.value == "ok" for r in res.results)
    n_feas = sum(r.feasible for r in res.results)
    print(f"{len(res.results)} designs ({res.resumed} resumed), {n_ok} ok, {n_feas} "
          f"feasible; {res.rate:.3g} designs/s; wrote "
          + ", ".join(str(f) for f in res.files))
    return 0


def cmd_optimize(args, load, usage_error) -> int:
    cfg, space, backend = _setup(args, load, usage_error)
    out = args.out or Path(f"optimize-{cfg.name}")
    check_out_dir(out, "--out")
    names = [o.name for o in space.objectives]
    if args.objective is not None and args.objective not in names:
        raise usage_error(f"--objective must be one of {', '.join(names)} (the "
                          f"objectives of [design]), got {args.objective!r}")
    from drymount.design.backends import BackendError  # scipy: after the checks
    from drymount.design.optimize import OptimizeSettings, optimize
    from drymount.design.table import TableError

    s = OptimizeSettings(objective=args.objective, maxiter=args.maxiter,
                         popsize=args.popsize, seed=args.seed,
                         polish_maxfev=args.polish)
    try:
        res = optimize(cfg, space, out, backend, s, progress=not args.quiet)
    except (BackendError, TableError) as exc:
        raise usage_error(str(exc)) from None
    vals = ", ".join(f"{v.name} = {x:.6g}" for v, x in
                     zip(space.variables, res.best.values, strict=True))
    print(f"{cfg.name}: best {res.objective} = {res.value:.5g} "
          f"(feasible {res.best.feasible}) at {vals}; {res.n_evaluations} designs "
          f"({res.resumed} resumed); "
          f"wrote {out}/summary.md")
    return 0 if res.best.feasible else 1
