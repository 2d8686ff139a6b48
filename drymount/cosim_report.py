"""What ``drymount cosim`` and ``drymount sweep`` draw and read beside their runs: the
time-history plot, an HBM curve read back from the CSV of ``drymount hbm`` (the
sweep's ``--hbm`` overlay, with the located peak of its ``_events.csv``) and the hint
to refine a stepped sweep that misses the curve's peak. Split from
:mod:`drymount.cli` (one job: the commands' plumbing there, these reports here).
"""

from __future__ import annotations

from pathlib import Path

from drymount.cli_guard import UsageError

__all__ = ["plot_time_history", "CurveCSV", "located_peak", "MISSED_PEAK",
           "missed_peak"]


def plot_time_history(th, cfg, freq, path) -> None:
    import numpy as np
    from matplotlib.figure import Figure

    q = np.asarray(th.q)
    names = cfg.system.dof_names
    fig = Figure(figsize=(8, 2.2 * len(names) if len(names) <= 3 else 9))
    for j, name in enumerate(names):
        ax = fig.add_subplot(len(names), 1, j + 1)
        ax.plot(th.t, q[:, j], lw=0.8)
        unit = "rad" if name in ("alpha", "beta", "gamma") else "m"
        ax.set_ylabel(f"{name} [{unit}]")
        ax.grid(True, alpha=0.3)
        if j == 0:
            how = f"at {freq:g} Hz" if freq is not None else "with measured inputs"
            ax.set_title(f"{cfg.name}: co-simulation {how}", fontsize=10)
    ax.set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


class CurveCSV:
    """An HBM curve read back from the CSV of ``drymount hbm``, for the sweep plot.

    Carries the attributes a plot needs: ``freq_hz``, ``amplitude`` (n, n_dof),
    ``peak``, ``transmissibility``, ``stable``, ``dof_names``, ``harmonics`` (None).
    """

    def __init__(self, path: Path):
        import csv

        import numpy as np

        import re

        try:
            with open(path, encoding="utf-8") as fh:
                text = fh.readlines()
        except OSError as exc:
            raise UsageError(f"--hbm: cannot read {path}: {exc}") from None
        lines = [ln for ln in text if not ln.startswith("#")]
        #: the system the header names ("" for a CSV that names none)
        self.system_name = next((m.group(1) for ln in text if ln.startswith("#")
                                 for m in [re.match(r"# drymount HBM (.*?): ", ln)]
                                 if m), "")
        rows = list(csv.reader(lines))
        if len(rows) < 2 or "freq_hz" not in rows[0]:
            raise UsageError(f"--hbm: {path} is not a curve CSV of `drymount hbm` "
                             f"(needs a header with freq_hz and data rows)")
        header = rows[0]
        try:
            data = np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)
        except ValueError as exc:
            raise UsageError(f"--hbm: {path}: {exc}") from None
        col = {h: data[:, i] for i, h in enumerate(header)}
        self.freq_hz = col["freq_hz"]
        self.dof_names = tuple(h[:-4] for h in header if h.endswith("_amp"))
        self.amplitude = np.column_stack([col[f"{d}_amp"] for d in self.dof_names])
        self.peak = np.column_stack([col.get(f"{d}_peak", col[f"{d}_amp"])
                                     for d in self.dof_names])
        n = len(self.freq_hz)
        self.transmissibility = col.get("transmissibility", np.full(n, np.nan))
        self.stable = (col["stable"].astype(bool) if "stable" in col
                       else np.ones(n, bool))
        self.harmonics = None
        self.turning_points = ()
        self.success = True
        self.peak_located = located_peak(path)

    def transmissibility_max(self) -> tuple[float, float]:
        """``(freq_hz, transmissibility)`` of the peak: the located one of the
        ``_events.csv`` beside the curve if there is one, else the largest row."""
        import numpy as np

        if self.peak_located is not None:
            return self.peak_located
        t = self.transmissibility
        if not np.any(np.isfinite(t)):
            return float("nan"), float("nan")
        i = int(np.nanargmax(t))
        return float(self.freq_hz[i]), float(t[i])


def located_peak(path: Path):
    """``(freq_hz, transmissibility)`` of the ``peak,transmissibility`` row of the
    curve's ``_events.csv`` (written by ``drymount hbm``), None without one."""
    import csv

    events = path.with_name(path.stem + "_events.csv")
    try:
        with open(events, encoding="utf-8") as fh:
            rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
        row = next(r for r in rows if r["kind"] == "peak"
                   and r["dof"] == "transmissibility")
        return float(row["freq_hz"]), float(row["transmissibility"])
    except (OSError, StopIteration, KeyError, ValueError):
        return None


#: A stepped sweep whose peak is this much below the HBM curve's is told to refine.
MISSED_PEAK = 0.05


def missed_peak(transmissibility, overlay) -> str:
    """A hint to use ``--refine`` when the stepped sweep's largest transmissibility
    is more than MISSED_PEAK below the ``--hbm`` curve's peak ("" otherwise)."""
    import numpy as np

    t = np.asarray(transmissibility, float)
    f_hbm, t_hbm = overlay.transmissibility_max()
    if not (np.any(np.isfinite(t)) and t_hbm == t_hbm) or \
            np.nanmax(t) >= (1 - MISSED_PEAK) * t_hbm:
        return ""
    return (f"  the sweep's steps miss the peak: {np.nanmax(t):.4g} against "
            f"{t_hbm:.4g} at {f_hbm:.4g} Hz on the --hbm curve; `--refine N` adds "
            f"frequencies there")
