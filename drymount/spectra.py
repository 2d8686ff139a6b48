"""Power spectral densities of a co-simulation: mount forces, engine accelerations.

Welch's method (``scipy.signal.welch``: Hann window, 50 % overlap, mean of the
periodograms, one-sided density) on the time histories of
:class:`vehicle.TimeHistory`, after dropping a start-up transient ``skip`` s:

- the force of every active mount axis (the force transmitted through the mount),
  PSD in N^2/Hz;
- the acceleration of every DOF (the central difference of the master's velocity,
  ``numpy.gradient``), PSD in (m/s^2)^2/Hz or (rad/s^2)^2/Hz.

Public: :class:`Spectra`, :func:`spectra`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Spectra", "spectra"]

_ROTATIONS = ("alpha", "beta", "gamma")


#: Decades below each panel's largest PSD that the plot shows (a Welch PSD of a
#: co-simulation reaches round-off 15-20 decades down; that is not information).
PLOT_DECADES = 8


def _acc_unit(dof: str) -> str:
    return "rad/s^2" if dof in _ROTATIONS else "m/s^2"


@dataclass(frozen=True)
class Spectra:
    """PSDs of a co-simulation (:func:`spectra`).

    Attributes
    ----------
    freq_hz : ndarray, shape (n_f,)
        Frequencies, Hz (0 to the Nyquist frequency 1 / (2 dt)).
    force_psd : ndarray, shape (n_f, n_axes)
        PSD of the force of each mount axis, N^2/Hz.
    acceleration_psd : ndarray, shape (n_f, n_dof)
        PSD of the acceleration of each DOF, (m/s^2)^2/Hz or (rad/s^2)^2/Hz.
    force_names, dof_names : tuple of str
    segment_s : float
        Length of the Welch segments, s (frequency resolution 1 / segment_s Hz).
    title : str
    """

    freq_hz: np.ndarray
    force_psd: np.ndarray
    acceleration_psd: np.ndarray
    force_names: tuple
    dof_names: tuple
    segment_s: float
    title: str = ""

    def to_csv(self, path):
        """Write ``freq_hz``, ``F_<axis>_psd`` (N^2/Hz) and ``<dof>_acc_psd``
        ((m/s^2)^2/Hz or (rad/s^2)^2/Hz); the first line is a ``# `` comment with the
        units."""
        from drymount.vehicle.results import write_csv

        units = ", ".join(f"{d}_acc_psd [({_acc_unit(d)})^2/Hz]"
                          for d in self.dof_names)
        comment = (f"drymount spectra (Welch, Hann, segments {self.segment_s:.6g} s) "
                   f"of {self.title}; units: freq_hz [Hz], F_*_psd [N^2/Hz], {units}")
        header = (["freq_hz"] + [f"F_{n}_psd" for n in self.force_names]
                  + [f"{d}_acc_psd" for d in self.dof_names])
        cols = ([self.freq_hz] + list(self.force_psd.T) + list(self.acceleration_psd.T))
        return write_csv(path, header, cols, comment)

    def plot(self, path=None):
        """Log-log panels against frequency: the force PSDs, then the acceleration
        PSDs, one panel per unit ((m/s^2)^2/Hz for translations, (rad/s^2)^2/Hz for
        rotations); each y axis spans the panel's largest value down
        :data:`PLOT_DECADES` decades. Saved atomically to ``path`` if given. Returns
        the matplotlib Figure."""
        from matplotlib.figure import Figure

        from drymount.hbm.plot import plain_log_ticks
        from drymount.io import atomic_path

        groups = [(f"{self.title}: PSD of transmitted mount forces",
                   "force PSD [N^2/Hz]",
                   [(f"F {n}", self.force_psd[:, j])
                    for j, n in enumerate(self.force_names)])]
        for unit, what in (("m/s^2", "translations"), ("rad/s^2", "rotations")):
            curves = [(d, self.acceleration_psd[:, j])
                      for j, d in enumerate(self.dof_names) if _acc_unit(d) == unit]
            if curves:
                groups.append((f"{self.title}: PSD of engine accelerations, {what}",
                               f"acceleration PSD [({unit})^2/Hz]", curves))
        fig = Figure(figsize=(8, 3.1 * len(groups) + 0.5), layout="constrained")
        f = self.freq_hz[1:]  # 0 Hz has no place on a log axis
        for k, (title, ylabel, curves) in enumerate(groups):
            ax = fig.add_subplot(len(groups), 1, k + 1)
            top = max((float(np.max(y[1:])) for _, y in curves), default=0.0)
            for label, y in curves:
                ax.loglog(f, np.where(y[1:] > 0, y[1:], np.nan), lw=0.8, label=label)
            if top > 0:
                ax.set_ylim(top * 10.0 ** -PLOT_DECADES, top * 3.0)
            ax.set_title(title, fontsize=10)
            ax.set_ylabel(ylabel)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7, ncol=3)
            plain_log_ticks(ax)
        ax.set_xlabel("frequency [Hz]")
        if path is not None:
            with atomic_path(path) as tmp:
                fig.savefig(tmp, dpi=120)
        return fig


def spectra(th, *, skip: float = 0.0, segment_s: float | None = None) -> Spectra:
    """PSDs of the mount forces and DOF accelerations of a time history.

    Parameters
    ----------
    th : vehicle.TimeHistory
    skip : float
        Start-up transient dropped before the analysis, s (>= 0).
    segment_s : float, optional
        Welch segment length, s (default: a quarter of the analysed record, i.e. 7
        segments with 50 % overlap).
    """
    from scipy.signal import welch

    if not (np.isfinite(skip) and skip >= 0):
        raise ValueError(f"`skip` must be >= 0 s, got {skip!r}")
    keep = np.asarray(th.t) >= float(skip) - 0.5 * th.dt
    n = int(np.sum(keep))
    if n < 16:
        raise ValueError(f"`skip` = {skip:g} s leaves {n} samples of the "
                         f"{th.t[-1]:g} s record; Welch needs at least 16")
    nper = n // 4 if segment_s is None else int(round(segment_s / th.dt))
    if not 8 <= nper <= n:
        raise ValueError(f"`segment_s` must be 8 steps ({8 * th.dt:g} s) to the "
                         f"record ({n * th.dt:g} s), got {segment_s!r}")
    fs = 1.0 / th.dt
    acc = np.gradient(np.asarray(th.qd)[keep], th.dt, axis=0)
    f, pf = welch(np.asarray(th.forces)[keep], fs=fs, nperseg=nper, axis=0)
    _, pa = welch(acc, fs=fs, nperseg=nper, axis=0)
    return Spectra(f, pf, pa, tuple(th.force_names), tuple(th.dof_names),
                   nper * th.dt, th.system_name or "co-simulation")
