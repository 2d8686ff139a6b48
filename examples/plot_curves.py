"""Overlay transmissibility curves of ``drymount hbm`` (docs/design-your-own-mount.md).

    python examples/plot_curves.py OUT.png CURVE.csv=LABEL [CURVE.csv=LABEL ...]

Each CSV is a ``drymount hbm`` output (columns ``freq_hz``, ``transmissibility``,
``stable``) or a ``drymount sweep`` output (``converged`` instead of ``stable``);
unstable (HBM) or not converged (sweep) points are marked with x.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

from matplotlib.figure import Figure


def read(path):
    lines = [ln for ln in Path(path).read_text().splitlines() if not ln.startswith("#")]
    rows = list(csv.DictReader(lines))
    return ([float(r["freq_hz"]) for r in rows],
            [float(r["transmissibility"]) for r in rows],
            [r.get("stable", r.get("converged", "1")) in ("1", "1.0") for r in rows])


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    fig = Figure(figsize=(7.5, 4.5), layout="constrained")
    ax = fig.subplots()
    for spec in argv[1:]:
        path, _, label = spec.partition("=")
        f, t, stable = read(path)
        line, = ax.plot(f, t, label=label or Path(path).stem)
        ax.plot([x for x, s in zip(f, stable) if not s],
                [y for y, s in zip(t, stable) if not s], "x", ms=3,
                color=line.get_color())
    ax.set(yscale="log", xlabel="frequency [Hz]", ylabel="transmissibility [-]",
           title="Transmissibility (x: unstable or not converged)")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.savefig(argv[0], dpi=120)
    print(f"wrote {argv[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
