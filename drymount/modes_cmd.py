"""``drymount modes``: nonlinear modes (EPMC) of a configuration, frequency and modal
damping ratio against modal amplitude (:mod:`hbm.modes`)."""

from __future__ import annotations

import argparse
import sys

__all__ = ["add_command", "cmd_modes"]


def _mode_spec(text: str) -> str | int:
    """``all``, a 1-based mode number or a DOF name (checked against CONFIG later)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must be 'all', a mode number or a DOF name")
    return int(text) if text.strip().isdigit() else text.strip()


def add_command(sub, add, config_arg, int_at_least, positive_float, path, *,
                harmonics_arg) -> None:
    """Add ``modes`` to the subparsers ``sub`` (the other arguments are the CLI's
    helpers of :mod:`drymount.cli_parser`)."""
    from drymount.config import MAX_HARMONICS, MAX_N_SAMPLES

    p = add(sub, "modes", "nonlinear modes: frequency and damping against amplitude",
            """\
            Nonlinear modal analysis by the extended periodic motion concept (EPMC,
            Krack 2015): the free motion with an artificial negative damping xi M q'
            that makes it periodic, by the harmonic balance and AFT of `drymount hbm`,
            continued in log modal amplitude a = sqrt(Q1^H M Q1) (kg^0.5 m). Per mode
            (numbered by ascending linearised frequency, contacts stuck, labelled by
            the DOF that dominates its kinetic energy) and amplitude: frequency, modal
            damping ratio xi/(2 omega), the harmonics of the motion, and per friction
            contact its slip ratio (> 1: slips). Writes a CSV and optionally a plot
            (frequency and damping ratio against amplitude, log axis).""",
            ["drymount modes sdof_halved --out modes.csv --plot modes.png",
             "drymount modes six_dof_halved --mode z --amplitude-range 1e-4 0.1",
             "drymount modes six_dof_halved --mode all -H 5 --plot six.png"])
    config_arg(p)
    p.add_argument("--mode", type=_mode_spec, default="all",
                   help="'all', a mode number 1..n (ascending linearised frequency) or "
                        "the DOF that dominates the mode, e.g. z")
    p.add_argument("--amplitude-range", type=positive_float, nargs=2, default=None,
                   metavar=("A0", "A1"),
                   help="modal amplitudes a, kg^0.5 m, A0 < A1 (default per mode: from "
                        "0.1 to 10 times the deflections where the nonlinearities act: "
                        "slip displacement, knee, cubic scale)")
    p.add_argument("--harmonics", "-H", type=harmonics_arg,
                   default=None,
                   help=f"number of harmonics H, 1..{MAX_HARMONICS} (default: [hbm] "
                        f"harmonics of CONFIG, 7)")
    p.add_argument("--n-samples", type=int_at_least(3, MAX_N_SAMPLES), default=None,
                   help="AFT samples per period, >= 2H+1 (default: [hbm] n_samples, "
                        "else max(64, 8H) to a power of 2)")
    p.add_argument("--out", type=path, default=None,
                   help="CSV file to write (default: <name>_modes.csv)")
    p.add_argument("--plot", type=path, default=None,
                   help="plot file to write (.png, .pdf, .svg)")


def _summary(res) -> list[str]:
    """One line per mode: frequency span, largest damping ratio, slip onset."""
    lines = []
    for m in res.modes:
        if not len(m.amplitude):
            lines.append(f"  mode {m.index} ({m.label}): no points ({m.message})")
            continue
        k = int(m.damping_ratio.argmax())
        text = (f"  mode {m.index} ({m.label}): {m.freq_hz[0]:.4g} Hz at a = "
                f"{m.amplitude[0]:.3g} to {m.freq_hz[-1]:.4g} Hz at "
                f"{m.amplitude[-1]:.3g}; damping ratio {m.damping_ratio[0]:.4g} to "
                f"{m.damping_ratio[-1]:.4g}, largest {m.damping_ratio[k]:.4g} at a = "
                f"{m.amplitude[k]:.3g}")
        dom = list(dict.fromkeys(res.dominant(m)))
        if dom != [m.label]:
            text += (f"; dominated by {' then '.join(dom)} along the branch (the "
                     f"mode changes character or interacts with another)")
        for c, name in enumerate(m.contacts):
            slip = m.slipping[:, c]
            if slip.any():
                text += f"; {name} slips from a = {m.amplitude[slip.argmax()]:.3g}"
        lines.append(text)
    return lines


def cmd_modes(args, load, usage_error) -> int:
    """Run ``drymount modes`` (``load``: the CLI's configuration loader)."""
    cfg = load(args.config, args.overrides)  # a bad --set: told before the solver
    from drymount.cli_guard import outputs, partial_on_stop, write_with
    from drymount.hbm.modes import nonlinear_modes, select_modes
    from drymount.hbm.options import CountError, check_samples

    H = args.harmonics if args.harmonics is not None else cfg.hbm.harmonics
    N = args.n_samples if args.n_samples is not None else cfg.hbm.n_samples
    if N is not None:
        try:
            check_samples(N, H)
        except CountError as exc:
            raise usage_error(exc.named("--n-samples")) from None
    rng = args.amplitude_range
    if rng is not None and not rng[0] < rng[1]:
        raise usage_error(f"--amplitude-range must satisfy A0 < A1, got A0 = "
                          f"{rng[0]:g}, A1 = {rng[1]:g} (kg^0.5 m)")
    try:
        select_modes(cfg.system, args.mode)
    except ValueError as exc:
        raise usage_error(f"--mode: {exc}") from None
    out = outputs(args, cfg, "modes")
    with partial_on_stop(out, "points"):
        res = nonlinear_modes(cfg.system, args.mode, rng, harmonics=H, n_samples=N,
                              options=cfg.hbm.options())
    write_with(out, res.to_csv,
               partial=None if res.success else f"numerical failure: {res.message}")
    n = sum(len(m.amplitude) for m in res.modes)
    print(f"wrote {out} ({len(res.modes)} mode(s), {n} points, H = {res.harmonics}, "
          f"N = {res.n_samples or 'closed forms'})", file=sys.stderr)
    if args.plot is not None:
        write_with(args.plot, lambda p: res.plot(path=p))
        print(f"wrote {args.plot}", file=sys.stderr)
    print(f"{cfg.name}: nonlinear modes (EPMC; amplitude a = sqrt(Q1^H M Q1) in "
          f"kg^0.5 m, damping ratio xi/(2 omega))")
    for line in _summary(res):
        print(line)
    if not res.success:
        print(f"drymount: error: a mode did not complete: {res.message}; the points "
              f"computed so far are in {out}", file=sys.stderr)
        return 1
    return 0
