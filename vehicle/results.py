"""Result objects of the vehicle harness and atomic file writing.

:class:`TimeHistory` (from :func:`vehicle.simulate`) lives here; ``SteadyState`` and
``SweepResult`` are in :mod:`vehicle.steady` and :mod:`vehicle.sweep`. Files are
written atomically through :mod:`hbm.io` (a temporary file in the destination folder,
then ``os.replace``), so a reader never sees a partial file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drymount.hbm import io as _io
from drymount.hbm.io import atomic_path

__all__ = ["TimeHistory", "atomic_path", "dof_unit", "write_csv"]

_ROTATIONS = ("alpha", "beta", "gamma")


def dof_unit(name: str) -> str:
    """Unit of a DOF: rad for the rotations alpha, beta, gamma, else m."""
    return "rad" if name in _ROTATIONS else "m"


def write_csv(path, header: list[str], columns: list[np.ndarray], comment: str) -> Path:
    """Write columns (each shape (n_rows,)) as CSV with a ``# `` comment first line."""
    data = np.column_stack([np.asarray(c, dtype=float) for c in columns]) \
        if columns else np.zeros((0, 0))
    return _io.write_csv(path, header, data.tolist(), comment.replace("\n", " "))


@dataclass
class TimeHistory:
    """Time histories of a co-simulation (:func:`vehicle.simulate`).

    Attributes
    ----------
    t : ndarray, shape (n_t,)
        Time, s (from the start of the run, ``k * dt``).
    q : ndarray, shape (n_t, n_dof)
        DOFs, m (translations) or rad (rotations).
    qd : ndarray, shape (n_t, n_dof)
        DOF rates, m/s or rad/s (the master's second-order velocity estimate).
    forces : ndarray, shape (n_t, n_axes)
        Total force of every active mount axis, N (positive = tension).
    friction_forces : ndarray, shape (n_t, n_axes)
        Friction force of every active mount axis, N.
    deflections : ndarray, shape (n_t, n_axes)
        Mount deflections u (engine minus chassis side), m.
    friction_energy : ndarray, shape (n_t,)
        Cumulative energy dissipated by friction in all mounts, J.
    dof_names, force_names : tuple of str
        DOF names; ``<mount>_<axis>`` of every active axis.
    dt : float
        Step, s.
    backend, system_name : str
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    forces: np.ndarray
    friction_forces: np.ndarray
    deflections: np.ndarray
    friction_energy: np.ndarray
    dof_names: tuple[str, ...]
    force_names: tuple[str, ...]
    dt: float
    backend: str = ""
    system_name: str = ""

    def to_csv(self, path) -> Path:
        """Write ``time``, every DOF, every active mount-axis force ``F_<mount>_<axis>``
        (first line a ``# `` comment with the units)."""
        units = ", ".join(f"{d} [{dof_unit(d)}]" for d in self.dof_names)
        comment = (f"drymount co-simulation of {self.system_name} ({self.backend} "
                   f"backend, dt = {self.dt:.6g} s); units: time [s], {units}, "
                   "F_* [N] mount force, positive = tension")
        header = (["time"] + list(self.dof_names)
                  + [f"F_{n}" for n in self.force_names])
        cols = [self.t] + [self.q[:, i] for i in range(self.q.shape[1])] \
            + [self.forces[:, i] for i in range(self.forces.shape[1])]
        return write_csv(path, header, cols, comment)

    def plot(self, path=None, dofs=None):
        """Plot the DOFs against time; saved atomically to ``path`` if given.
        Returns the matplotlib Figure."""
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8, 4.5))
        ax = fig.add_subplot()
        names = list(self.dof_names) if dofs is None else list(dofs)
        for name in names:
            i = self.dof_names.index(name)
            ax.plot(self.t, self.q[:, i], label=f"{name} [{dof_unit(name)}]")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("displacement [m] / rotation [rad]")
        ax.set_title(f"{self.system_name or 'co-simulation'}: time history "
                     f"({self.backend} backend, dt = {self.dt:.3g} s)", fontsize=10)
        ax.legend()
        ax.grid(True, alpha=0.3)
        if path is not None:
            with atomic_path(path) as tmp:
                fig.savefig(tmp, dpi=120)
        return fig
